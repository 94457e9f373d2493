"""``curves.npz`` beside ``curves.nc`` (issue 24 item 6): the same set, read without a NetCDF library.

A processed set is written as ``curves.nc`` and ``curves.npz`` (the same variables and attributes,
plain arrays, the sha256 of the ``curves.nc`` written with it).  ``load_processed`` reads the npz
only beside that very ``curves.nc``; an old set (no npz), an npz of another ``curves.nc`` (the set
edited with xarray since) or a damaged one fall back to ``curves.nc``, the last two with a warning.
"""

import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest

import bendpam
import bendpam.lab.processed as processed_module
from bendpam.errors import FileFormatError
from bendpam.infra.outputs import OutputSet
from bendpam.lab import RawTest
from bendpam.lab.processed import load_processed, write_processed
from bendpam.lab.processing import process_tests
from bendpam.lab.simulate import SimulationSettings, simulate_test

FIELDS = ("curvature_grid", "branches", "blocked_moments", "free_curvatures", "energy_loss_ratios", "branch_times_s")


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """A processed set of 3 pressures (one a replicate), 2 cycles, written by ``write_processed``."""
    be, settings = bendpam.physics.presets.be_pam(), SimulationSettings(cycles=2, rate_hz=5.0, seed=3)
    raws = [RawTest(simulate_test(be, p, settings=settings)[0], Path(f"be_{p:g}kPa_{i}.csv"), "csv", pressure_kpa=p)
            for i, p in enumerate((100.0, 150.0, 150.0))]
    folder = tmp_path_factory.mktemp("npz") / "set"
    write_processed(process_tests(raws, keep_series=False), folder, figure=False)
    return folder


def copy_of(folder: Path, tmp_path: Path, name: str = "copy") -> Path:
    out = tmp_path / name
    shutil.copytree(folder, out)
    return out


def read(path, monkeypatch) -> tuple[object, list[str], list[str]]:
    """The set, the file(s) its arrays were read from, and the warnings raised."""
    sources: list[str] = []
    real = processed_module._read_curves

    def spy(path):
        sources.append(Path(path).name)
        return real(path)

    monkeypatch.setattr(processed_module, "_read_curves", spy)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        ps = load_processed(path)
    return ps, sources, [str(w.message) for w in caught if w.category is UserWarning]


def assert_same_set(a, b) -> None:
    assert a.fixture == b.fixture
    assert len(a.results) == len(b.results)
    for r0, r1 in zip(a.results, b.results, strict=True):
        assert (r0.pressure_kpa, r0.n_cycles, r0.replicate, r0.source, r0.specimen, r0.findings) == \
               (r1.pressure_kpa, r1.n_cycles, r1.replicate, r1.source, r1.specimen, r1.findings)
        assert (r0.drift.to_dict() if r0.drift else None) == (r1.drift.to_dict() if r1.drift else None)
        for f in FIELDS:
            np.testing.assert_array_equal(getattr(r1, f), getattr(r0, f), err_msg=f)  # identical, NaNs included


def test_the_npz_and_the_nc_give_the_same_set(written, tmp_path, monkeypatch):
    assert sorted(p.name for p in written.iterdir()) == ["curves.csv", "curves.nc", "curves.npz", "summary.json"]
    with np.load(written / "curves.npz", allow_pickle=False) as z:  # plain arrays only: no pickles to trust
        assert {"moment_nmm", "curvature_per_mm", "replicate", "time_s"} <= set(z.files)
    from_npz, sources, warned = read(written, monkeypatch)
    assert sources == ["curves.npz"] and warned == []
    old = copy_of(written, tmp_path)
    (old / "curves.npz").unlink()  # a set written before the npz: read from curves.nc, silently
    from_nc, sources, warned = read(old, monkeypatch)
    assert sources == ["curves.nc"] and warned == []
    assert_same_set(from_npz, from_nc)
    assert [r.replicate for r in from_npz.results] == [1, 1, 2]
    _, sources, _ = read(written / "curves.nc", monkeypatch)  # the file named: its npz is still the one beside it
    assert sources == ["curves.npz"]


def test_an_npz_of_another_curves_nc_is_not_used(written, tmp_path, monkeypatch):
    """curves.nc edited with xarray after the set was written: its numbers are read, and the warning says why."""
    import xarray as xr

    edited = copy_of(written, tmp_path)
    with xr.open_dataset(written / "curves.nc") as ds:
        ds = ds.load()
    ds["moment_nmm"] = ds["moment_nmm"] * 2.0
    ds.to_netcdf(edited / "curves.nc")
    ps, sources, warned = read(edited, monkeypatch)
    assert sources == ["curves.nc"]
    assert len(warned) == 1 and "curves.npz: not used, it was written with another curves.nc" in warned[0]
    original = load_processed(written)
    np.testing.assert_array_equal(ps.results[0].branches, 2.0 * original.results[0].branches)


@pytest.mark.parametrize("damage", ["junk", "truncated", "no hash"])
def test_a_damaged_npz_is_not_used(written, tmp_path, monkeypatch, damage):
    folder = copy_of(written, tmp_path)
    npz = folder / "curves.npz"
    if damage == "junk":
        npz.write_bytes(b"not a zip file")
    elif damage == "truncated":
        npz.write_bytes(npz.read_bytes()[:1000])
    else:  # an npz without the hash of its curves.nc (say, saved by hand from the arrays)
        with np.load(npz, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files if k != "_curves_nc_sha256"}
        with open(npz, "wb") as fh:
            np.savez(fh, **arrays)
    ps, sources, warned = read(folder, monkeypatch)
    assert sources == ["curves.nc"]
    assert len(warned) == 1 and "curves.npz: not used, it cannot be read" in warned[0]
    assert_same_set(ps, load_processed(written))


def test_an_npz_changed_in_a_set_with_a_manifest_is_refused(written, tmp_path):
    """As curves.nc: a set that bendpam wrote with a manifest is read only as it wrote it."""
    folder = tmp_path / "with-manifest"
    with OutputSet(folder, command=["test"], producer="process") as out:
        write_processed(load_processed(written), out.staging, figure=False)
    assert load_processed(folder).pressures_kpa.tolist() == [100.0, 150.0, 150.0]
    other = copy_of(written, tmp_path, "other")
    with np.load(other / "curves.npz", allow_pickle=False) as z:
        arrays = {k: z[k] for k in z.files}
    arrays["moment_nmm"] = arrays["moment_nmm"] * 2.0
    with open(folder / "curves.npz", "wb") as fh:
        np.savez(fh, **arrays)
    with pytest.raises(FileFormatError, match=r"curves\.npz: does not match"):
        load_processed(folder)


def test_a_set_with_a_manifest_hashes_its_curves_nc_once(written, tmp_path, monkeypatch):
    """The manifest's check of curves.nc gives the sha256 that the npz is compared with (not hashed again)."""
    import bendpam.infra.fsops as fsops
    import bendpam.infra.manifest as manifest

    folder = tmp_path / "with-manifest"
    with OutputSet(folder, command=["test"], producer="process") as out:
        write_processed(load_processed(written), out.staging, figure=False)
    seen: list[str] = []

    def counting(path, *args, **kwargs):
        seen.append(Path(path).name)
        return real(path, *args, **kwargs)

    real, plain = fsops.hash_file, load_processed(written)
    monkeypatch.setattr(fsops, "hash_file", counting)
    monkeypatch.setattr(manifest, "hash_file", counting)
    assert_same_set(plain, load_processed(folder))
    assert seen.count("curves.nc") == 1 and seen.count("curves.npz") == 1


def test_the_command_line_says_why_in_one_line(capsys):
    """A warning a bendpam function raises about its caller's input is one ``bendpam: warning:`` line."""
    import importlib

    app_module = importlib.import_module("bendpam.cli.app")  # the module (``bendpam.cli.app`` is the app itself)
    inside = str(Path(app_module.__file__).parent / "identify.py")
    app_module._show_warning(UserWarning("x/curves.npz: not used, why; reading x/curves.nc instead"), UserWarning,
                             inside, 1)
    assert capsys.readouterr().err == "bendpam: warning: x/curves.npz: not used, why; reading x/curves.nc instead\n"
