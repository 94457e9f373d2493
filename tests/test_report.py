"""``bendpam report``: raw files -> one self-contained HTML page, checked as text and in headless Chromium.

Two pages are built once through the CLI from the same simulated BE-PAM tests: with the right
preset (``be-pam``) and with the wrong one (``bc-pam``, the README's old example, which must warn).
The browser test needs Debian's ``chromium`` (/usr/bin/chromium) and the Python ``playwright``
package (its own browser download is not used); outside CI it is skipped with a reason when either
is missing.  It also prints the page to PDF with ``chromium --headless --print-to-pdf``.
"""

import contextlib
import io
import json
import os
import re
import shutil
import subprocess
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest

import bendpam
import bendpam.cli
from bendpam import presets
from bendpam.identify.fitting import fit
from bendpam.identify.result import HYST_PARAMETERS, PARAMETERS
from bendpam.lab import read_test
from bendpam.lab.processing import process_tests
from bendpam.lab.simulate import SimulationSettings, simulate_tests
from bendpam.present.report import Report, alpha0_profile, build_report, fmt_pct, fmt_value, table2_rows, table3_rows

CHROMIUM = Path("/usr/bin/chromium")
CHROMIUM_ARGS = ["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync"]
PRESSURES = [100, 150, 200]
BASE_FIGURES = {"fig-figure4", "fig-figure7-energy", "fig-figure7-force_balance", "fig-stresses", "fig-hysteresis"}
#: Names that belong to the code, not to a page for people (the symbols are shown instead).
_ACT = presets.be_pam()
CODE_NAMES = sorted({*(k for k in _ACT.to_dict() if k not in ("name", "model")), *_ACT.derived(),
                     *PARAMETERS, *(f for f, _ in PARAMETERS.values()), *HYST_PARAMETERS,
                     *(f for f, _ in HYST_PARAMETERS.values()), "bend_sign", "gtol", "xtol", "ftol",
                     "nrmse_cycles", "termination condition"}, key=len, reverse=True)


def _quiet_terminal(mp):
    """No progress bar in captured output, whatever the environment says about colour."""
    mp.delenv("FORCE_COLOR", raising=False)
    mp.setenv("TTY_COMPATIBLE", "0")


def _cli(*args):
    mp = pytest.MonkeyPatch()
    _quiet_terminal(mp)
    so, se = io.StringIO(), io.StringIO()
    try:
        with contextlib.redirect_stdout(so), contextlib.redirect_stderr(se):
            code = bendpam.cli.main([str(a) for a in args])
    finally:
        mp.undo()
    return code, so.getvalue(), se.getvalue()


@pytest.fixture(scope="module")
def raw_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("raw")
    simulate_tests(presets.be_pam("energy"), PRESSURES, out, "energy", dialect="csv",
                   settings=SimulationSettings(seed=11, cycles=2))
    return out


@pytest.fixture(scope="module")
def built(raw_dir, tmp_path_factory):
    """The report of the right preset, built through the CLI once: (html path, exit code, stdout, stderr)."""
    html_path = tmp_path_factory.mktemp("report") / "report.html"
    code, out, err = _cli("report", raw_dir, "--preset", "be-pam", "--out", html_path, "--quiet")
    return html_path, code, out, err


@pytest.fixture(scope="module")
def audit(raw_dir, tmp_path_factory):
    """The README's old example: BE-PAM tests reported with the BC-PAM preset."""
    html_path = tmp_path_factory.mktemp("audit") / "audit.html"
    code, out, err = _cli("report", raw_dir, "--preset", "bc-pam", "--out", html_path, "--quiet")
    return html_path, code, out, err


@pytest.fixture(scope="module")
def expected(raw_dir):
    """The same pipeline through the library, independently of the report."""
    act = presets.be_pam("energy")
    tests = [read_test(f) for f in sorted(raw_dir.glob("*.csv"))]
    processed = process_tests(tests)
    fits = {m: fit(processed, act, m, free=("alpha0", "C10", "C01")) for m in ("energy", "force_balance")}
    return processed, fits


def _figure_ids(fits):
    ids = set(BASE_FIGURES)
    for m, res in fits.items():
        if alpha0_profile(res) is not None:
            ids.add(f"fig-alpha0-{m}")
        if callable(getattr(res, "band", None)):
            ids.add(f"fig-band-{m}")
    return ids


class _Scan(HTMLParser):
    """Every tag with its attributes, the text of each table cell by table id, and the page's visible text."""

    HIDDEN = frozenset({"style", "script", "title", "code"})

    def __init__(self):
        super().__init__()
        self.tags: list[tuple[str, dict]] = []
        self.tables: dict[str, list[list[str]]] = {}
        self.text: list[str] = []  # text nodes a reader sees (not in <code>: command-line input)
        self._table = None
        self._cell = None
        self._section = None
        self._hidden = 0

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        self.tags.append((tag, a))
        if tag in self.HIDDEN:
            self._hidden += 1
        if tag == "table":
            self._table = a.get("id")
            self.tables[self._table] = []
        elif tag in ("thead", "tbody", "tfoot"):
            self._section = tag
        elif tag == "tr" and self._table and self._section == "tbody":
            self.tables[self._table].append([])
        elif tag in ("td", "th") and self._table and self._section == "tbody":
            self._cell = []

    def handle_endtag(self, tag):
        if tag in self.HIDDEN:
            self._hidden -= 1
        if tag in ("td", "th") and self._cell is not None:
            self.tables[self._table][-1].append("".join(self._cell).strip())
            self._cell = None
        elif tag == "table":
            self._table = None
        elif tag in ("thead", "tbody", "tfoot"):
            self._section = None

    def handle_data(self, data):
        if self._cell is not None:
            self._cell.append(data)
        if not self._hidden:
            self.text.append(data)


def _scan(path):
    s = _Scan()
    s.feed(Path(path).read_text(encoding="utf-8"))
    return s


def _kinds(scan):
    return [a["data-kind"] for tag, a in scan.tags if tag == "div" and "data-kind" in a]


# ------------------------------------------------------------------------------------------------
# the page, without a browser
# ------------------------------------------------------------------------------------------------
@pytest.mark.slow
def test_cli_writes_report(built):
    html_path, code, out, err = built
    assert code == 0, err
    # --quiet: no progress; the warning box's titles go to stderr (only a caution here)
    assert all(line.startswith("bendpam: caution: ") for line in err.splitlines()), err
    assert f"wrote {html_path}" in out and "figures" in out
    assert "energy model: α₀ (°) " in out and "force-balance model: α₀ (°) " in out
    assert "gtol" not in out + err and "C10_kpa" not in out + err


@pytest.mark.slow
def test_self_contained_and_atomic(built, expected):
    html_path, code, _, _ = built
    assert code == 0
    text = html_path.read_text(encoding="utf-8")
    assert text.startswith("<!DOCTYPE html>")
    assert not re.search(r"https?://", text, re.IGNORECASE)
    assert "<script" not in text.lower()
    scan = _scan(html_path)
    for tag, a in scan.tags:
        for attr in ("src", "href"):
            if attr in a:
                v = a[attr]
                assert v.startswith(("data:", "#")), f"<{tag} {attr}={v[:60]!r}> is not self-contained"
    imgs = [a for tag, a in scan.tags if tag == "img"]
    assert {a["id"] for a in imgs} == _figure_ids(expected[1])
    for a in imgs:
        assert a["alt"].strip() and a["src"].startswith("data:image/png;base64,")
    tables = [a.get("id") for tag, a in scan.tags if tag == "table"]
    assert all(tables) and len(set(tables)) == len(tables)
    assert {"table2", "table3", "actuator", "inputs", "settings", "hysteresis-loss"} <= set(tables)
    # written atomically: the page and nothing else (no temporary file left behind)
    # the page, and bendpam's record that it wrote it (nothing else: no temporaries, no lock)
    assert sorted(p.name for p in html_path.parent.iterdir()) == [".bendpam-files.json", "report.html"]
    assert f"bendpam {bendpam.__version__}" in text
    assert "@media print" in text and "@page" in text


@pytest.mark.slow
def test_tables_hold_the_numbers(built, expected):
    html_path, _, _, _ = built
    processed, fits = expected
    scan = _scan(html_path)
    summ = processed.summary()
    # Table 2 against processed.summary(), written by the one number format
    rows = scan.tables["table2"]
    assert len(rows) == len(PRESSURES)
    for row, r in zip(rows, summ["pressures"]):
        assert row == [
            f"{r['pressure_kpa']:g}", str(r["cycles"]),
            fmt_value(r["blocked_moment_nmm"], r["blocked_moment_se_nmm"]),
            fmt_value(r["free_curvature_per_mm"], r["free_curvature_se_per_mm"]),
            fmt_pct(r["energy_loss_ratio"]),
        ]
    # Table 3 against an independent fit
    rows = scan.tables["table3"]
    assert [r[0] for r in rows] == ["energy model", "force-balance model"]
    for row, res in zip(rows, fits.values()):
        p = res.parameters
        assert row[1] == fmt_value(p["alpha0"].value, p["alpha0"].stderr)
        assert row[2] == fmt_value(p["C10"].value, p["C10"].stderr)
        mt = res.metrics
        assert row[5:] == [fmt_pct(mt.nrmse_cycles), fmt_pct(mt.nrmse_blocked_moment), fmt_pct(mt.nrmse_free_curvature)]
        # value ± SE: the SE with two significant digits, the value to the same decimal place
        for cell in row[1:5]:
            v, s = cell.split(" ± ")
            assert len(s.replace("\u202f", "").replace(".", "").lstrip("0")) == 2, cell
            assert len(v.rpartition(".")[2]) == len(s.rpartition(".")[2]) if "." in s else "." not in v, cell
    assert rows == [list(r.values()) for r in table3_rows(fits)]
    # the unformatted numbers ride along in data-value
    tds = [a for tag, a in scan.tags if tag == "td" and "data-value" in a]
    values = [float(a["data-value"]) for a in tds if a["data-value"]]
    for res in fits.values():
        for name in ("alpha0", "C10", "C01"):
            assert any(np.isclose(v, res.parameters[name].value, rtol=1e-9) for v in values)
    dead = next(a for tag, a in scan.tags if a.get("id") == "deadband")
    assert float(dead["data-value"]) == pytest.approx(summ["deadband_kpa"], rel=1e-9)
    for m in fits:
        assert any(a.get("id") == f"flags-{m}" for _, a in scan.tags)
        assert any(a.get("id") == f"diagnosis-{m}" for _, a in scan.tags)


@pytest.mark.slow
def test_hysteresis_section(built, expected):
    html_path, _, _, _ = built
    processed, fits = expected
    scan = _scan(html_path)
    assert any(a.get("id") == "hysteresis" for _, a in scan.tags)
    rows = scan.tables["hysteresis-loss"]
    loops = {m: r for m, r in fits.items() if r.hysteresis is not None}
    assert loops, "the simulated tests have a 20 % loop: the fits model it"
    assert [r[0] for r in rows] == [f"{p:g}" for p in PRESSURES]
    for i, (row, pr) in enumerate(zip(rows, processed.results)):
        assert row[1] == fmt_pct(pr.energy_loss_ratio)
        assert row[2:] == [fmt_pct(r.hysteresis.energy_loss_ratio[i].predicted) for r in loops.values()]
        # the loop model reproduces the measured loss within a few percentage points
        for r in loops.values():
            assert abs(r.hysteresis.energy_loss_ratio[i].predicted - pr.energy_loss_ratio) < 0.05
    for m in loops:
        params = scan.tables[f"hysteresis-params-{m}"]
        assert sorted(r[0] for r in params) == ["a0", "a1", "θh"]  # the symbols, not a0_nmm ...


@pytest.mark.slow
def test_inputs_and_actuator_tables(built, raw_dir):
    html_path, _, _, _ = built
    scan = _scan(html_path)
    rows = scan.tables["inputs"]
    assert [Path(r[0]).name for r in rows] == sorted(p.name for p in raw_dir.glob("*.csv"))
    assert all(r[1] == "csv" and r[3] == "metadata" for r in rows)
    assert [float(r[2]) for r in rows] == sorted(PRESSURES)
    act = {r[0]: r[1:] for r in scan.tables["actuator"]}
    assert act["L0"][1] == "145.0" and len(act["α0"]) == 5  # meaning, nominal, two fitted, unit
    assert act["α0"][-1] == "°" and act["C10"][-1] == "kPa" and act["Type"][1].startswith("BE-PAM")


@pytest.mark.slow
@pytest.mark.parametrize("which", ["built", "audit"])
def test_no_code_names_on_the_page(which, request):
    html_path, code, _, _ = request.getfixturevalue(which)
    assert code == 0
    text = " ".join(_scan(html_path).text)
    for name in CODE_NAMES:
        hit = re.search(rf"(?<![\w-]){re.escape(name)}(?![\w])", text)
        assert hit is None, f"{name!r} shown: …{text[max(hit.start() - 60, 0): hit.end() + 60]}…"
    assert "gtol" not in text and "±" in text and "α" in text


@pytest.mark.slow
def test_wrong_preset_warns(audit, built):
    html_path, code, out, err = audit
    assert code == 0, err
    scan = _scan(html_path)
    kinds = _kinds(scan)
    assert kinds[:2] == ["direction", "deadband"], kinds  # the data do not match: said first
    assert "poor-fit" in kinds and "at-bound" in kinds
    # the box is the first thing after the header
    ids = [a.get("id") for tag, a in scan.tags if tag in ("section", "nav")]
    assert ids[0] == "warnings"
    assert "bendpam: warning: The data look like a BE-PAM" in err
    assert "bendpam: warning: The measured deadband" in err and "warning(s) and" in out
    # the right preset: cautions at most
    good = _scan(built[0])
    assert [k for k in _kinds(good) if k != "correlated"] == []


# ------------------------------------------------------------------------------------------------
# the page in headless Chromium, and printed to PDF
# ------------------------------------------------------------------------------------------------
def _browser():
    if not CHROMIUM.exists():
        # CI installs Chromium (.ci/run): there a missing browser is a failure, not a skip
        if os.environ.get("CI"):
            pytest.fail(f"{CHROMIUM} is missing although CI should have installed it (.ci/run)")
        pytest.skip(f"{CHROMIUM} is missing: install Debian's package with `apt-get install -y chromium`")
    if os.environ.get("CI"):
        import playwright.sync_api as sync_api
    else:
        sync_api = pytest.importorskip("playwright.sync_api", reason="the Python package playwright is not installed")
    return sync_api


_ROWS = "rows => rows.map(r => Array.from(r.cells).map(c => c.textContent.trim()))"


@pytest.mark.slow
def test_pages_in_headless_chromium(built, audit, expected):
    sync_api = _browser()
    processed, fits = expected
    errors, requests, seen = [], [], {}
    with sync_api.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS)
        try:
            page = browser.new_page(viewport={"width": 1280, "height": 900})
            page.on("console", lambda msg: errors.append(f"console {msg.type}: {msg.text}")
                    if msg.type in ("error", "warning") else None)
            page.on("pageerror", lambda exc: errors.append(f"page error: {exc}"))
            page.on("request", lambda req: requests.append(req.url))
            for name, (html_path, code, _, _) in (("built", built), ("audit", audit)):
                assert code == 0
                page.goto(html_path.as_uri(), wait_until="load")
                seen[name] = {
                    "imgs": page.eval_on_selector_all(
                        "img", "els => els.map(e => ({id: e.id, alt: e.alt, complete: e.complete, "
                        "w: e.naturalWidth, h: e.naturalHeight, shown: e.getBoundingClientRect().width}))"),
                    "t2": page.eval_on_selector_all("#table2 tbody tr", _ROWS),
                    "t3": page.eval_on_selector_all("#table3 tbody tr", _ROWS),
                    "t3_head": page.eval_on_selector_all("#table3 thead th", "els => els.map(e => e.innerHTML)"),
                    "title": page.title(),
                    "box": page.eval_on_selector(
                        "#warnings", "e => ({top: e.getBoundingClientRect().top, h: e.getBoundingClientRect().height, "
                        "bg: getComputedStyle(e).backgroundColor, cls: e.className, "
                        "kinds: Array.from(e.querySelectorAll('.warning')).map(w => w.dataset.kind)})"),
                    "first_section": page.eval_on_selector("#tests", "e => e.getBoundingClientRect().top"),
                    "hyst": page.eval_on_selector_all("#hysteresis", "els => els.length"),
                    "text": page.inner_text("body"),
                }
                page.emulate_media(media="print")
                seen[name]["print"] = page.evaluate(
                    "() => ({nav: getComputedStyle(document.querySelector('nav')).display, "
                    "color: getComputedStyle(document.body).color, "
                    "avoid: getComputedStyle(document.querySelector('table')).breakInside})")
                page.emulate_media(media="screen")
        finally:
            browser.close()
    assert errors == []
    pages = {h.as_uri() for h in (built[0], audit[0])}
    assert [u for u in requests if u not in pages and not u.startswith("data:")] == []
    good, bad = seen["built"], seen["audit"]
    assert {i["id"] for i in good["imgs"]} == _figure_ids(fits)
    for i in good["imgs"] + bad["imgs"]:
        assert i["complete"] and i["w"] > 0 and i["h"] > 0 and i["shown"] > 0, i
        assert i["alt"].strip()
    assert "BE-PAM" in good["title"] and "BC-PAM" in bad["title"]
    # the numbers as the library formats them; symbols with units in the headings
    assert good["t2"] == [list(r.values()) for r in table2_rows(processed.summary())]
    assert good["t3"] == [list(r.values()) for r in table3_rows(fits)]
    assert good["t3_head"][1] == "α<sub>0</sub> (°)" and good["t3_head"][2] == "C<sub>10</sub> (kPa)"
    assert all(re.fullmatch(r"−?[\d\u202f.]+ ± [\d\u202f.]+( \*)?", c) for row in good["t3"] for c in row[1:5])
    # the warning box: at the top, visible, styled; the wrong preset's names the mismatch
    for s in (good, bad):
        assert s["box"]["top"] < s["first_section"] and s["box"]["h"] > 20
        assert s["box"]["bg"] not in ("rgba(0, 0, 0, 0)", "transparent")
    assert bad["box"]["kinds"][:2] == ["direction", "deadband"]
    assert "far from the actuator's Pstart" in bad["text"] and "What to try" in bad["text"]
    # the hysteresis section, and the α0 profile when the fit has one
    assert good["hyst"] == 1 and "Hysteresis" in good["text"]
    if any(alpha0_profile(r) is not None for r in fits.values()):
        assert "Profile of α₀" in good["text"]
    # print: no navigation, black text, no break inside a table
    for s in (good, bad):
        assert s["print"] == {"nav": "none", "color": "rgb(0, 0, 0)", "avoid": "avoid"}


@pytest.mark.slow
def test_report_prints_to_pdf(audit, tmp_path):
    _browser()
    html_path, code, _, _ = audit
    assert code == 0
    pdf = tmp_path / "report.pdf"
    r = subprocess.run([str(CHROMIUM), *CHROMIUM_ARGS, "--no-pdf-header-footer", f"--print-to-pdf={pdf}",
                        html_path.as_uri()], capture_output=True, text=True, timeout=180)
    assert r.returncode == 0, r.stderr[-2000:]
    data = pdf.read_bytes()
    assert data.startswith(b"%PDF-")
    pages = len(re.findall(rb"/Type\s*/Page(?![s\w])", data))
    assert 3 <= pages <= 30, pages
    if shutil.which("pdftoppm"):  # the first page is drawn, and it is not blank
        subprocess.run(["pdftoppm", "-r", "40", "-png", "-f", "1", "-l", "1", str(pdf), str(tmp_path / "p")],
                       check=True, capture_output=True, timeout=120)
        png = next(tmp_path.glob("p-*1.png"))
        from PIL import Image

        img = np.asarray(Image.open(png).convert("L"), dtype=float)
        assert img.shape[0] > img.shape[1]  # portrait
        assert (img < 128).mean() > 0.01  # text on it
        red = np.asarray(Image.open(png).convert("RGB"), dtype=float)
        assert ((red[..., 0] - red[..., 2]) > 60).mean() > 0.001  # the warning box keeps its colour


# ------------------------------------------------------------------------------------------------
# the library function: another actuator, a BC-PAM's stress curvature, progress
# ------------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def bc_raw(tmp_path_factory):
    raw = tmp_path_factory.mktemp("bc") / "raw"
    simulate_tests(presets.bc_pam("force_balance"), [60, 100], raw, "force_balance", dialect="testxpert",
                   settings=SimulationSettings(seed=5, cycles=2))
    return raw


@pytest.mark.slow
def test_build_report_bc_pam(bc_raw, tmp_path, capsys):
    act = presets.bc_pam("force_balance")
    res = build_report(bc_raw, act, tmp_path / "bc.html", models=("force-balance",), progress=False)
    assert capsys.readouterr().err == ""  # progress=False: nothing on stderr
    assert isinstance(res, Report)
    assert res.html.exists() and {"fig-figure4", "fig-figure7-force_balance", "fig-stresses"} <= set(res.figures)
    assert [i["dialect"] for i in res.inputs] == ["testxpert", "testxpert"]
    assert list(res.fits) == ["force_balance"] and res.notes == [] and res.failed == {}
    assert [w for w in res.warnings if w.severity == "warning"] == [], [w.title for w in res.warnings]
    top = res.processed.results[-1]
    assert res.stresses["pressure_kpa"] == 100.0
    assert res.stresses["curvature_per_mm"] == pytest.approx(-0.5 * top.free_curvature[0])  # BC-PAM: k' < 0
    assert res.summary["deadband_kpa"] == pytest.approx(res.processed.summary()["deadband_kpa"])
    text = res.html.read_text(encoding="utf-8")
    assert 'id="table3"' in text and "energy model" not in text
    # with progress (not a terminal here): at most the plain progress lines on stderr
    res = build_report(bc_raw, act, tmp_path / "bc2.html", models=("energy",), progress=True)
    err = capsys.readouterr().err
    assert all(line.startswith("bendpam: report") for line in err.splitlines()), err
    assert res.progress_shown
    assert sorted(p.name for p in tmp_path.iterdir() if p.name != ".bendpam-files.json") == ["bc.html", "bc2.html"]


@pytest.mark.slow
def test_a_model_that_cannot_be_fitted_is_reported_not_raised(bc_raw, tmp_path):
    # BC-PAM tests from 60 kPa with the BE-PAM preset (P_start = 68 kPa): no fit is possible
    res = build_report(bc_raw, presets.be_pam(), tmp_path / "r.html", progress=False)
    assert res.fits == {} and set(res.failed) == {"energy", "force_balance"}
    kinds = [w.kind for w in res.warnings]
    assert kinds[:2] == ["direction", "deadband"] and kinds.count("fit-failed") == 2, kinds
    assert "P_start" in next(w for w in res.warnings if w.kind == "fit-failed").title
    assert res.figures == ["fig-figure4"] and res.stresses is None
    scan = _scan(res.html)
    assert [r[1].startswith("could not be fitted") for r in scan.tables["table3"]] == [True, True]
    assert any(a.get("id") == "stresses-none" for _, a in scan.tags)


# ------------------------------------------------------------------------------------------------
# bad input: exit code 2, one line, no page
# ------------------------------------------------------------------------------------------------
def _run_bad(capsys, monkeypatch, *args):
    _quiet_terminal(monkeypatch)
    code = bendpam.cli.main(["report", *map(str, args)])
    out, err = capsys.readouterr()
    return code, out, err


def test_bad_inputs(tmp_path, raw_dir, capsys, monkeypatch):
    out = tmp_path / "out.html"
    empty = tmp_path / "empty"
    empty.mkdir()
    # a file without a pressure: no metadata line, no pressure token in the name
    data = read_test(next(raw_dir.glob("*.csv"))).data
    nopress = tmp_path / "nopress" / "test.csv"
    nopress.parent.mkdir()
    data.to_csv(nopress, index=False)
    garbage = tmp_path / "garbage_100kPa.csv"
    garbage.write_text("this is not a test export\n")
    cases = [
        ((empty, "--preset", "be-pam", "--out", out), "no raw test files"),
        ((nopress.parent, "--preset", "be-pam", "--out", out), "no pressure"),
        ((tmp_path / "missing", "--preset", "be-pam", "--out", out), "no such file"),
        ((garbage, "--preset", "be-pam", "--out", out), "garbage_100kPa.csv"),
        ((raw_dir, "--out", out), "--preset"),
        ((raw_dir, "--preset", "be-pam", "--out", tmp_path / "report.pdf"), ".html"),
        ((raw_dir, "--preset", "be-pam", "--out", out, "--pressure-kpa", "100,150"), "one per file"),
        ((raw_dir, "--preset", "be-pam", "--out", out, "--free", "alpha0,bogus"), "bogus"),
        ((raw_dir, "--preset", "be-pam", "--out", out, "--fixture", "35,2.5"), "--fixture"),
        ((raw_dir, "--preset", "be-pam", "--out", out, "--model", "springs"), "springs"),
    ]
    for args, needle in cases:
        code, stdout, err = _run_bad(capsys, monkeypatch, *args)
        assert code == 2, (args, stdout, err)
        assert err.count("\n") == 1 and err.startswith("bendpam: error: "), (args, err)
        assert needle in err, (args, err)
        assert "Traceback" not in err
    assert not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["empty", "garbage_100kPa.csv", "nopress"]


def test_missing_output_folder_is_refused(tmp_path, raw_dir, capsys, monkeypatch):
    code, stdout, err = _run_bad(capsys, monkeypatch, raw_dir, "--preset", "be-pam", "--out",
                                 tmp_path / "nodir" / "r.html")
    assert code == 2, (stdout, err)
    assert err.count("\n") == 1 and err.startswith("bendpam: error: ") and "does not exist" in err, err
    assert not (tmp_path / "nodir").exists()


@pytest.mark.slow
def test_the_report_reads_as_process_does(tmp_path, raw_dir):
    """``report`` takes the reader's options (--repair, --columns, --format-file, --rate-hz) and --drift, as
    ``process`` does: a file with a sample out of order is refused in one line naming --repair, which reads it; the
    drift is corrected when asked and the JSON says so."""
    src = sorted(raw_dir.glob("*.csv"))[0]
    lines = src.read_text(encoding="utf-8").splitlines(keepends=True)
    k = len(lines) // 2
    lines[k], lines[k + 1] = lines[k + 1], lines[k]  # two samples swapped in time
    bad = tmp_path / src.name
    bad.write_text("".join(lines), encoding="utf-8")
    out = tmp_path / "r.html"
    code, stdout, err = _cli("report", bad, "--preset", "be-pam", "--model", "energy", "--out", out, "--quiet")
    assert code == 2 and err.count("\n") == 1 and "read with --repair to drop" in err, err
    assert not out.exists()
    code, stdout, err = _cli("report", bad, "--preset", "be-pam", "--model", "energy", "--out", out, "--quiet",
                             "--repair", "--drift", "linear", "--columns", "time=time_s,stroke=stroke_mm,force=force_n",
                             "--json")
    assert code == 0, err
    rec = json.loads(stdout)
    (test,) = rec["table2"]["pressures"]
    assert test["drift"]["corrected"] is True
    assert any("out of order in time (1 sample(s), at line(s) " in n for n in test["notes"])
    assert out.exists()


@pytest.mark.slow
def test_a_drift_is_printed_once(tmp_path, raw_dir):
    """A test's drift is both a processing warning and a line of the page's warning box: the command prints it once."""
    raw = tmp_path / "raw"
    raw.mkdir()
    for src in sorted(raw_dir.glob("*.csv")):
        df = read_test(src).data
        t = df["time_s"].to_numpy()
        df["force_n"] += 0.05 * df["force_n"].max() * (t - t[0]) / (t[-1] - t[0])  # 5 % of the force over the test
        df.to_csv(raw / src.name, index=False)
    code, stdout, err = _cli("report", raw, "--preset", "be-pam", "--model", "energy", "--out",
                             tmp_path / "r.html", "--quiet")
    assert code == 0, err
    first = sorted(raw.glob("*.csv"))[0].name
    lines = [line for line in err.splitlines() if first in line and "drifts" in line]
    assert len(lines) == 1 and lines[0].startswith("bendpam: warning: Load-cell drift: "), err
