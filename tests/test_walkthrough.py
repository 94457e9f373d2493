"""The README's walkthrough (examples/walkthrough.sh) runs in order in an empty folder."""

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
SCRIPT = ROOT / "examples" / "walkthrough.sh"
QUOTED = re.compile(r"<!-- walkthrough-output: start.*?-->(.*?)<!-- walkthrough-output: end -->", re.S)
NUMBER = re.compile(r"-?\d+\.\d+")


@pytest.fixture(scope="module")
def walkthrough(tmp_path_factory):
    """Run the walkthrough once in an empty folder: (folder, completed process)."""
    if shutil.which("bash") is None:
        pytest.skip("needs bash")
    folder = tmp_path_factory.mktemp("walkthrough")
    env = dict(os.environ)
    env["PATH"] = str(Path(sys.executable).parent) + os.pathsep + env.get("PATH", "")
    r = subprocess.run(["bash", str(SCRIPT)], cwd=folder, env=env, capture_output=True, text=True, timeout=900)
    return folder, r


def quoted_sections(path: Path) -> list[str]:
    """The sections of a page that quote the walkthrough's output (between the walkthrough-output markers)."""
    return QUOTED.findall(path.read_text(encoding="utf-8"))


def test_pages_quote_the_walkthrough():
    for page in (ROOT / "README.md", ROOT / "docs" / "tutorial.md"):
        sections = quoted_sections(page)
        assert sections and all("```text" in s for s in sections), page


@pytest.mark.slow
@pytest.mark.parametrize("page", ["README.md", "docs/tutorial.md"])
def test_quoted_numbers_are_what_the_walkthrough_prints(walkthrough, page):
    """Every line of a quoted block is a line the walkthrough prints; every number of the text around it
    is in the block or is one of the paper's Table 3 values (the BE-PAM's, which step 2 simulates)."""
    _, r = walkthrough
    assert r.returncode == 0, r.stderr[-2000:]
    printed = {line.strip() for line in r.stdout.splitlines()}
    be = __import__("bendpam").physics.presets.be_pam()
    table3 = {f"{be.alpha0_deg:g}", f"{be.C10_kpa:g}", f"{be.C01_kpa:g}", f"{2 * (be.C10_kpa + be.C01_kpa):.1f}"}
    for section in quoted_sections(ROOT / page):
        blocks = re.findall(r"```text\n(.*?)```", section, re.S)
        lines = [ln.strip() for b in blocks for ln in b.splitlines() if ln.strip() and not ln.startswith("#")]
        assert lines
        for line in lines:
            assert line in printed, f"{page} quotes a line the walkthrough does not print: {line!r}"
        prose = re.sub(r"```text\n.*?```", "", section, flags=re.S)
        in_blocks = set(NUMBER.findall("\n".join(lines)))
        for number in NUMBER.findall(prose):
            assert number in in_blocks or number in table3, f"{page}: {number} is neither printed nor Table 3's"


@pytest.mark.slow
def test_walkthrough_runs_in_order(walkthrough):
    tmp_path, r = walkthrough
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
    # the "pronounced friction loop" loses more energy than the default test, at every pressure
    ratios = {f: [p["energy_loss_ratio"] for p in json.loads((tmp_path / f / "summary.json").read_text())["pressures"]]
              for f in ("processed-be", "processed-loop")}
    assert all(b > a for a, b in zip(ratios["processed-be"], ratios["processed-loop"], strict=True)), ratios
    assert (tmp_path / "report-be.html").stat().st_size > 10_000
    for f in ("finger.png", "sweep.nc", "sweep.png"):
        assert (tmp_path / f).stat().st_size > 1000
    assert "energy-loss ratio" in r.stdout and "wrote sweep.nc" in r.stdout
    design = json.loads((tmp_path / "design-be" / "design.json").read_text())
    assert design["feasible"] is True
    assert {t["quantity"]: round(t["achieved"], 1) for t in design["targets"]} == {
        "blocked_moment_nmm": 400.0, "free_angle_deg": 90.0}
    assert (tmp_path / "design-be" / "design.toml").is_file()
    hand = json.loads((tmp_path / "hand" / "hand.json").read_text())
    assert [p["number"] for p in hand["kapandji"]["points"]] == list(range(1, 9))
    assert (tmp_path / "hand" / "kapandji.png").stat().st_size > 1000
    assert "30 deg needs" in r.stdout
