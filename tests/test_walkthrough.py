"""The README's walkthrough (examples/walkthrough.sh) runs in order in an empty folder."""

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parent.parent / "examples" / "walkthrough.sh"


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("bash") is None, reason="needs bash")
def test_walkthrough_runs_in_order(tmp_path):
    env = dict(os.environ)
    env["PATH"] = str(Path(sys.executable).parent) + os.pathsep + env.get("PATH", "")
    r = subprocess.run(["bash", str(SCRIPT)], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-2000:]
    assert "Traceback" not in r.stderr
    for folder in ("raw-be", "processed-be", "fit-be", "raw-loop", "processed-loop", "fit-loop"):
        manifest = json.loads((tmp_path / folder / "manifest.json").read_text())
        listed = {f["path"] for f in manifest["files"]}
        on_disk = {p.name for p in (tmp_path / folder).iterdir()} - {"manifest.json"}
        assert listed == on_disk, folder
    fit = json.loads((tmp_path / "fit-be" / "fit.json").read_text())
    assert abs(fit["parameters"]["alpha0_deg"]["value"] - 69.7) < 0.5
    assert fit["nrmse"]["cycles"] < 0.05
    loop = json.loads((tmp_path / "fit-loop" / "fit.json").read_text())["hysteresis"]
    assert abs(loop["parameters"]["theta_h_deg"]["value"] - 12.0) < 1.0
    assert (tmp_path / "report-be.html").stat().st_size > 10_000
    for f in ("finger.png", "sweep.nc", "sweep.png"):
        assert (tmp_path / f).stat().st_size > 1000
    assert "energy-loss ratio" in r.stdout and "wrote sweep.nc" in r.stdout
    design = json.loads((tmp_path / "design-be" / "design.json").read_text())
    assert design["feasible"] is True
    assert {t["quantity"]: round(t["achieved"], 1) for t in design["targets"]} == {
        "blocked_moment_nmm": 400.0, "free_angle_deg": 90.0}
    assert (tmp_path / "design-be" / "design.toml").is_file()
