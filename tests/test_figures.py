"""Figures for papers (issue 16): journal sizes and fonts, PNG/PDF/SVG everywhere, readable labels.

Every command that writes a figure takes ``--format png|pdf|svg`` or infers it from the file name
(a conflict exits 2); the internal-stress figure has no overlapping labels (checked on the text
bounding boxes); the wrist figure tells its actuators apart.
"""

import itertools
import os
import subprocess
import sys
from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt  # closes the figures the design modules draw with pyplot
import numpy as np
import pandas as pd
import pytest

from bendpam import presets
from bendpam.cli import main
from bendpam.errors import InputError
from bendpam.present.figures import (
    DOUBLE_COLUMN_IN,
    SINGLE_COLUMN_IN,
    demo_figure,
    figure_format,
    figure_style,
    moment_curvature_figure,
    plot_internal_stresses,
    save_figure,
    styled_figure,
    sweep_figure,
)

MAGIC = {"png": b"\x89PNG\r\n\x1a\n", "pdf": b"%PDF-", "svg": b"<?xml"}


def assert_format(path, fmt):
    data = path.read_bytes()
    assert data.startswith(MAGIC[fmt]), (path, data[:20])
    if fmt == "svg":
        assert b"<svg" in data[:2000]
    if fmt == "pdf":
        assert data.rstrip().endswith(b"%%EOF")


# ------------------------------------------------------------------------------------------------
# text bounding boxes
# ------------------------------------------------------------------------------------------------
def visible_texts(fig):
    """(text, window extent) of every visible, non-empty text: titles, axis and tick labels, legends."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    candidates = [fig._suptitle, *fig.texts]
    for ax in fig.axes:
        if not ax.get_visible():
            continue
        candidates += [ax.title, ax._left_title, ax._right_title, ax.xaxis.label, ax.yaxis.label, *ax.texts]
        for axis in (ax.xaxis, ax.yaxis):
            if not axis.get_visible():
                continue
            lo, hi = sorted(axis.get_view_interval())
            tol = 1e-9 * (hi - lo)
            for tick in axis.get_major_ticks():
                if tick.get_loc() is not None and lo - tol <= tick.get_loc() <= hi + tol:  # drawn ticks only
                    candidates += [tick.label1, tick.label2]
        legend = ax.get_legend()
        if legend is not None:
            candidates += [*legend.get_texts(), legend.get_title()]
    out, seen = [], set()
    for t in candidates:
        if t is None or id(t) in seen or not t.get_visible() or not t.get_text().strip():
            continue
        seen.add(id(t))
        box = t.get_window_extent(renderer)
        if box.width > 0 and box.height > 0:
            out.append((t, box))
    return out


def overlapping_labels(fig):
    items = visible_texts(fig)
    return [(a.get_text(), b.get_text()) for (a, ba), (b, bb) in itertools.combinations(items, 2) if ba.overlaps(bb)]


def outside_figure(fig):
    """Texts that stick out of the figure (cut off when saved)."""
    w, h = fig.canvas.get_width_height()
    return [t.get_text() for t, b in visible_texts(fig) if b.x0 < -1 or b.y0 < -1 or b.x1 > w + 1 or b.y1 > h + 1]


def test_overlap_check_finds_an_overlap():
    """The check itself: two labels drawn on top of each other are found."""
    with figure_style():
        fig = styled_figure(lambda ax: (ax.text(0.5, 0.5, "first label"), ax.text(0.5, 0.5, "second label")))
    assert ("first label", "second label") in overlapping_labels(fig)
    plt.close(fig)


@pytest.mark.parametrize("name,pressure,curvature", [("be-pam", 200.0, 0.0), ("be-pam", 200.0, 0.008),
                                                     ("bc-pam", 120.0, -0.004), ("bc-pam", 40.0, 0.0)])
def test_internal_stress_labels_do_not_overlap(name, pressure, curvature):
    act = presets.get(name, "force_balance")
    fig = plot_internal_stresses(act, pressure, curvature)
    assert overlapping_labels(fig) == []
    assert outside_figure(fig) == []
    assert fig.get_size_inches()[0] == pytest.approx(DOUBLE_COLUMN_IN)
    plt.close(fig)


def test_demo_and_curve_labels_do_not_overlap():
    items = [(presets.get(n, m), np.array(P, dtype=float), m)
             for n, P in (("be-pam", [100, 150, 200]), ("bc-pam", [40, 80, 120, 140])) for m in ("energy",)]
    fig = demo_figure(items)  # BC-PAM above its fold: the note is in the legend's title
    assert overlapping_labels(fig) == [] and outside_figure(fig) == []
    plt.close(fig)
    fig = moment_curvature_figure(presets.get("bc-pam"), [40, 60, 80, 100, 120, 140])
    assert overlapping_labels(fig) == [] and outside_figure(fig) == []
    assert fig.get_size_inches()[0] == pytest.approx(SINGLE_COLUMN_IN)
    plt.close(fig)


# ------------------------------------------------------------------------------------------------
# the backend is the caller's (issue 25)
# ------------------------------------------------------------------------------------------------
def _fresh_python(code):
    """Run ``code`` in a fresh interpreter that imports this tree's bendpam, without MPLBACKEND."""
    import bendpam

    env = {k: v for k, v in os.environ.items() if k != "MPLBACKEND"}
    env["PYTHONPATH"] = os.pathsep.join([str(Path(bendpam.__file__).parents[1]), env.get("PYTHONPATH", "")])
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120)
    assert r.returncode == 0, r.stderr
    return r.stdout.split()


def test_importing_the_figures_leaves_the_backend_and_pyplot_alone():
    imports = "import bendpam.present.figures, bendpam.design, bendpam.identify"
    # a backend chosen before the import stays chosen, and pyplot is not imported
    assert _fresh_python(f"import sys, matplotlib\nmatplotlib.use('svg')\n{imports}\n"
                         "print('matplotlib.pyplot' in sys.modules, matplotlib.get_backend())") == ["False", "svg"]
    # without a choice, pyplot later picks the same backend as it would without bendpam
    plain = _fresh_python("import matplotlib.pyplot, matplotlib\nprint(matplotlib.get_backend())")
    assert _fresh_python(f"import sys\n{imports}\nprint('matplotlib.pyplot' in sys.modules)\n"
                         "import matplotlib.pyplot, matplotlib\nprint(matplotlib.get_backend())") == ["False", *plain]


# ------------------------------------------------------------------------------------------------
# style and sizes
# ------------------------------------------------------------------------------------------------
def test_style_is_local_and_fonts_fit_a_journal():
    before = dict(matplotlib.rcParams)
    fig = moment_curvature_figure(presets.get("be-pam"), [100, 200])
    assert dict(matplotlib.rcParams) == before  # an rc context, never a global change
    sizes = {t.get_fontsize() for t, _ in visible_texts(fig)}
    assert min(sizes) >= 6.5 and max(sizes) <= 9.0, sizes
    widths = {line.get_linewidth() for ax in fig.axes for line in ax.get_lines()}
    assert max(widths) <= 1.5
    plt.close(fig)


def test_sweep_figure_is_single_column():
    import bendpam

    ds = bendpam.sweep(presets.get("be-pam"), [100.0, 200.0], alpha0_deg=[66, 70, 74], t0_mm=[2.0, 2.5])
    fig = sweep_figure(ds)
    assert fig.get_size_inches()[0] == pytest.approx(SINGLE_COLUMN_IN)
    assert overlapping_labels(fig) == [] and outside_figure(fig) == []
    plt.close(fig)


# ------------------------------------------------------------------------------------------------
# save_figure
# ------------------------------------------------------------------------------------------------
def line_figure():
    return styled_figure(lambda ax: ax.plot([0, 1], [0, 1]))


@pytest.mark.parametrize("fmt", ["png", "pdf", "svg"])
def test_save_figure_infers_the_format_from_the_suffix(tmp_path, fmt):
    path = save_figure(line_figure(), tmp_path / f"f.{fmt.upper()}")
    assert_format(path, fmt)
    path = save_figure(line_figure(), tmp_path / "no-suffix", format=fmt)
    assert_format(path, fmt)


def test_save_figure_refuses_other_formats_and_conflicts(tmp_path):
    with pytest.raises(InputError, match="format"):
        save_figure(line_figure(), tmp_path / "f.png", format="pdf")
    with pytest.raises(InputError, match=r"\.jpg"):
        save_figure(line_figure(), tmp_path / "f.jpg")
    with pytest.raises(InputError, match="eps"):
        save_figure(line_figure(), tmp_path / "f", format="eps")
    assert list(tmp_path.iterdir()) == []  # nothing written
    assert figure_format("x") == "png" and figure_format("x.svg", "svg") == "svg"


@pytest.mark.parametrize("fmt", ["pdf", "svg"])
def test_vector_figures_are_reproducible(tmp_path, fmt):
    a = save_figure(line_figure(), tmp_path / f"a.{fmt}").read_bytes()
    b = save_figure(line_figure(), tmp_path / f"b.{fmt}").read_bytes()
    assert a == b  # no creation date, fixed SVG ids
    if fmt == "pdf":
        assert b"/FontFile2" in a  # TrueType fonts embedded (pdf.fonttype 42)


# ------------------------------------------------------------------------------------------------
# the wrist figure
# ------------------------------------------------------------------------------------------------
def legend_entries(fig):
    ax = fig.axes[0]
    handles, labels = ax.get_legend_handles_labels()
    return [(lab, h.get_color(), h.get_linestyle(), h.get_marker()) for h, lab in zip(handles, labels)
            if lab.startswith(("actuator", "pairs"))]


def test_wrist_symmetric_curves_are_drawn_once_and_say_so():
    from bendpam.design.wrist import Wrist, plot_wrist, wrist_sweep

    w = Wrist(presets.get("bc-pam"), "energy")
    table = wrist_sweep(w, [60.0, 100.0], [0.0, 90.0, 180.0, 270.0, 45.0])
    fig = plot_wrist(table)
    entries = legend_entries(fig)
    assert len(entries) == 2  # the four single actuators coincide; the pair differs
    single, pair = entries
    assert "0°, 90°, 180°, 270°" in single[0] and "symmetry" in single[0]
    assert "0+90°" in pair[0] and "toward 45°" in pair[0]
    assert single[1:] != pair[1:]  # colour, line style and marker differ
    assert overlapping_labels(fig) == [] and outside_figure(fig) == []
    plt.close(fig)


def test_wrist_distinct_curves_are_told_apart():
    from bendpam.design.wrist import plot_wrist

    P = [50.0, 100.0]
    table = pd.DataFrame([{"direction_deg": d, "pressure_kpa": p, "angle_deg": (1 + i) * p / 10}
                          for i, d in enumerate((0.0, 90.0, 180.0, 270.0)) for p in P])
    fig = plot_wrist(table)
    entries = legend_entries(fig)
    assert [e[0] for e in entries] == [f"actuator {d}° inflated (toward {d}°)" for d in (0, 90, 180, 270)]
    assert len({e[1] for e in entries}) == 4 and len({e[2] for e in entries}) == 4
    plt.close(fig)


# ------------------------------------------------------------------------------------------------
# every command that writes a figure
# ------------------------------------------------------------------------------------------------
def run(capsys, *args):
    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def figure_commands(tmp_path):
    """(name, args before the output, output option) of the quick figure commands."""
    return [
        ("curve", ["curve", "--preset", "be-pam", "--pressure-kpa", "100", "200"], "--out"),
        ("stresses", ["stresses", "--preset", "be-pam", "--pressure-kpa", "150"], "--out"),
        ("sweep", ["sweep", "--preset", "be-pam", "--param", "alpha0_deg=66,70,74", "--pressure-kpa", "100,200",
                   "-q"], "--plot"),
        ("finger", ["finger", "--preset", "be-pam", "--pressure-kpa", "100", "200"], "--plot"),
        ("grasp", ["grasp", "--preset", "be-pam", "--pressure-kpa", "150", "--diameter-mm", "80", "160"], "--plot"),
        ("wrist", ["wrist", "--preset", "bc-pam", "--pressure-kpa", "60", "100", "-q"], "--plot"),
    ]


@pytest.mark.parametrize("fmt", ["pdf", "svg"])
@pytest.mark.parametrize("command", ["curve", "stresses", "sweep", "finger", "grasp", "wrist"])
def test_figure_commands_write_every_format(tmp_path, capsys, command, fmt):
    name, args, opt = next(c for c in figure_commands(tmp_path) if c[0] == command)
    if fmt == "pdf":  # from --format, on a name without suffix
        target = tmp_path / "figure"
        code, out, err = run(capsys, *args, opt, target, "--format", fmt)
    else:  # from the suffix
        target = tmp_path / f"figure.{fmt}"
        code, out, err = run(capsys, *args, opt, target)
    assert code == 0, err
    assert_format(target, fmt)


@pytest.mark.parametrize("command", ["curve", "sweep", "finger", "wrist"])
def test_conflicting_suffix_and_format_exit_2(tmp_path, capsys, command):
    name, args, opt = next(c for c in figure_commands(tmp_path) if c[0] == command)
    code, out, err = run(capsys, *args, opt, tmp_path / "figure.png", "--format", "svg")
    assert code == 2
    assert err.count("\n") == 1 and "--format" in err and ".png" in err
    code, out, err = run(capsys, *args, opt, tmp_path / "figure.jpg")
    assert code == 2 and ".jpg" in err and err.count("\n") == 1
    assert list(tmp_path.iterdir()) == []


def test_format_without_a_figure_exits_2(tmp_path, capsys):
    code, out, err = run(capsys, "finger", "--preset", "be-pam", "--pressure-kpa", "100", "--format", "pdf")
    assert code == 2 and "--plot" in err
    code, out, err = run(capsys, "curve", "--preset", "be-pam", "--pressure-kpa", "100", "--out",
                         tmp_path / "c.csv", "--format", "pdf")
    assert code == 2 and ".csv" in err


def test_demo_default_name_follows_format(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, out, err = run(capsys, "demo", "--format", "svg")
    assert code == 0, err
    assert_format(tmp_path / "bendpam-demo" / "moment-curvature.svg", "svg")


@pytest.fixture(scope="module")
def processed(tmp_path_factory):
    """Raw virtual tests and their processed folder."""
    root = tmp_path_factory.mktemp("figures-lab")
    assert main(["simulate-test", "--preset", "be-pam", "--pressure-kpa", "100", "150", "200", "--out",
                 str(root / "raw"), "--seed", "3"]) == 0
    assert main(["process", str(root / "raw"), "--out", str(root / "proc"), "-q"]) == 0
    return root


def test_process_and_fit_figures_in_every_format(processed, tmp_path, capsys):
    capsys.readouterr()
    code, out, err = run(capsys, "process", processed / "raw", "--out", tmp_path / "p", "--format", "svg", "-q")
    assert code == 0, err
    assert_format(tmp_path / "p" / "figure4.svg", "svg")
    assert not (tmp_path / "p" / "figure4.png").exists() and "figure4.svg" in out
    code, out, err = run(capsys, "fit", processed / "proc", "--preset", "be-pam", "--out", tmp_path / "f",
                         "--format", "pdf", "-q")
    assert code == 0, err
    assert_format(tmp_path / "f" / "figure7.pdf", "pdf")
    assert "figure7.pdf" in out and err == ""
    code, out, err = run(capsys, "process", processed / "raw", "--out", tmp_path / "q", "--no-figure",
                         "--format", "pdf")
    assert code == 2 and "--no-figure" in err
