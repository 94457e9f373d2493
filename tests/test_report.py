"""``bendpam report``: raw files -> one self-contained HTML page, checked in headless Chromium.

The browser test needs Debian's ``chromium`` (/usr/bin/chromium) and the Python ``playwright``
package (its own browser download is not used); it is skipped with a reason when either is missing.
"""

import contextlib
import html
import io
import os
import re
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest

import bendpam
import bendpam.cli
from bendpam import presets
from bendpam.identify import fit
from bendpam.lab import read_test
from bendpam.lab.processing import process_tests
from bendpam.lab.simulate import SimulationSettings, simulate_tests
from bendpam.report import Report, build_report, fmt_num, fmt_pct, fmt_pm, fmt_se, table2_rows, table3_rows

CHROMIUM = Path("/usr/bin/chromium")
CHROMIUM_ARGS = ["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync"]
PRESSURES = [100, 150, 200]
FIGURE_IDS = {"fig-figure4", "fig-figure7-energy", "fig-figure7-force_balance", "fig-stresses"}


def _quiet_terminal(mp):
    """No progress bar in captured output, whatever the environment says about colour."""
    mp.delenv("FORCE_COLOR", raising=False)
    mp.setenv("TTY_COMPATIBLE", "0")


@pytest.fixture(scope="module")
def raw_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("raw")
    simulate_tests(presets.be_pam("energy"), PRESSURES, out, "energy", dialect="csv",
                   settings=SimulationSettings(seed=11, cycles=2))
    return out


@pytest.fixture(scope="module")
def built(raw_dir, tmp_path_factory):
    """The report built through the CLI, once: (html path, exit code, stdout, stderr)."""
    out_dir = tmp_path_factory.mktemp("report")
    html_path = out_dir / "report.html"
    mp = pytest.MonkeyPatch()
    _quiet_terminal(mp)
    so, se = io.StringIO(), io.StringIO()
    try:
        with contextlib.redirect_stdout(so), contextlib.redirect_stderr(se):
            code = bendpam.cli.main(["report", str(raw_dir), "--preset", "be-pam", "--out", str(html_path)])
    finally:
        mp.undo()
    return html_path, code, so.getvalue(), se.getvalue()


@pytest.fixture(scope="module")
def expected(raw_dir):
    """The same pipeline through the library, independently of the report."""
    act = presets.be_pam("energy")
    tests = [read_test(f) for f in sorted(raw_dir.glob("*.csv"))]
    processed = process_tests(tests)
    fits = {m: fit(processed, act, m, free=("alpha0", "C10", "C01")) for m in ("energy", "force_balance")}
    return processed, fits


class _Scan(HTMLParser):
    """Every tag with its attributes, and the text of each table cell by table id."""

    def __init__(self):
        super().__init__()
        self.tags: list[tuple[str, dict]] = []
        self.tables: dict[str, list[list[str]]] = {}
        self._table = None
        self._cell = None
        self._section = None

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        self.tags.append((tag, a))
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


def _scan(text):
    s = _Scan()
    s.feed(text)
    return s


# ------------------------------------------------------------------------------------------------
# the page, without a browser
# ------------------------------------------------------------------------------------------------
def test_cli_writes_report(built):
    html_path, code, out, err = built
    assert code == 0, err
    assert err == ""  # no progress bar when stderr is not a terminal
    assert f"wrote {html_path}" in out and "4 figures" in out
    assert "energy model: alpha0" in out and "force-balance model: alpha0" in out


def test_self_contained_and_atomic(built):
    html_path, code, _, _ = built
    assert code == 0
    text = html_path.read_text(encoding="utf-8")
    assert text.startswith("<!DOCTYPE html>")
    assert not re.search(r"https?://", text, re.IGNORECASE)
    assert "<script" not in text.lower()
    scan = _scan(text)
    for tag, a in scan.tags:
        for attr in ("src", "href"):
            if attr in a:
                v = a[attr]
                assert v.startswith(("data:", "#")), f"<{tag} {attr}={v[:60]!r}> is not self-contained"
    imgs = [a for tag, a in scan.tags if tag == "img"]
    assert {a["id"] for a in imgs} == FIGURE_IDS
    for a in imgs:
        assert a["alt"].strip() and a["src"].startswith("data:image/png;base64,")
    tables = [a.get("id") for tag, a in scan.tags if tag == "table"]
    assert all(tables) and len(set(tables)) == len(tables)
    assert {"table2", "table3", "actuator", "inputs", "settings"} <= set(tables)
    # written atomically: the page and nothing else (no temporary file left behind)
    assert sorted(p.name for p in html_path.parent.iterdir()) == ["report.html"]
    assert f"bendpam {bendpam.__version__}" in text


def test_tables_hold_the_numbers(built, expected):
    html_path, _, _, _ = built
    processed, fits = expected
    scan = _scan(html_path.read_text(encoding="utf-8"))
    summ = processed.summary()
    # Table 2 against processed.summary()
    rows = scan.tables["table2"]
    assert len(rows) == len(PRESSURES)
    for row, r in zip(rows, summ["pressures"]):
        assert row == [
            f"{r['pressure_kpa']:g}", str(r["cycles"]),
            f"{r['blocked_moment_nmm']:.2f} ± {r['blocked_moment_se_nmm']:.2f}",
            f"{r['free_curvature_per_mm']:.5g} ± {fmt_se(r['free_curvature_se_per_mm'])}",
            f"{100 * r['energy_loss_ratio']:.2f}",
        ]
    # Table 3 against an independent fit
    rows = scan.tables["table3"]
    assert [r[0] for r in rows] == ["energy model", "force-balance model"]
    for row, res in zip(rows, fits.values()):
        p = res.parameters
        assert row[1] == f"{p['alpha0'].value:.2f} ± {fmt_se(p['alpha0'].stderr)}"
        assert row[2] == fmt_pm(p["C10"].value, p["C10"].stderr, ".1f")
        assert row[3] == fmt_pm(p["C01"].value, p["C01"].stderr, ".1f")
        mt = res.metrics
        assert row[4:] == [f"{100 * mt.nrmse_cycles:.2f}", f"{100 * mt.nrmse_blocked_moment:.2f}",
                           f"{100 * mt.nrmse_free_curvature:.2f}"]
    assert rows == [list(r.values()) for r in table3_rows(fits)]
    # the unformatted numbers ride along in data-value
    tds = [a for tag, a in scan.tags if tag == "td" and "data-value" in a]
    values = [float(a["data-value"]) for a in tds if a["data-value"]]
    for res in fits.values():
        for name in ("alpha0", "C10", "C01"):
            assert any(np.isclose(v, res.parameters[name].value, rtol=1e-9) for v in values)
    # deadband and fit notes
    dead = next(a for tag, a in scan.tags if a.get("id") == "deadband")
    assert float(dead["data-value"]) == pytest.approx(summ["deadband_kpa"], rel=1e-9)
    for m in fits:
        assert any(a.get("id") == f"flags-{m}" for _, a in scan.tags)
    text = html_path.read_text(encoding="utf-8")
    flags = [f for res in fits.values() for f in res.flags]
    assert flags  # C10 and C01 are strongly correlated here
    for flag in flags:
        assert html.escape(flag) in text


def test_inputs_and_actuator_tables(built, raw_dir):
    html_path, _, _, _ = built
    scan = _scan(html_path.read_text(encoding="utf-8"))
    rows = scan.tables["inputs"]
    assert [Path(r[0]).name for r in rows] == sorted(p.name for p in raw_dir.glob("*.csv"))
    assert all(r[1] == "csv" and r[3] == "metadata" for r in rows)
    assert [float(r[2]) for r in rows] == sorted(PRESSURES)
    act = {r[0]: r[1:] for r in scan.tables["actuator"]}
    assert act["L0_mm"][0] == "145" and len(act["alpha0_deg"]) == 3  # nominal + two fitted


# ------------------------------------------------------------------------------------------------
# the page in headless Chromium
# ------------------------------------------------------------------------------------------------
def test_page_in_headless_chromium(built, expected):
    if not CHROMIUM.exists():
        # CI installs Chromium (.ci/run): there a missing browser is a failure, not a skip
        if os.environ.get("CI"):
            pytest.fail(f"{CHROMIUM} is missing although CI should have installed it (.ci/run)")
        pytest.skip(f"{CHROMIUM} is missing: install Debian's package with `apt-get install -y chromium`")
    if os.environ.get("CI"):
        import playwright.sync_api as sync_api
    else:
        sync_api = pytest.importorskip("playwright.sync_api", reason="the Python package playwright is not installed")
    html_path, code, _, _ = built
    assert code == 0
    processed, fits = expected
    errors, requests = [], []
    with sync_api.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS)
        try:
            page = browser.new_page(viewport={"width": 1280, "height": 900})
            page.on("console", lambda msg: errors.append(f"console {msg.type}: {msg.text}")
                    if msg.type in ("error", "warning") else None)
            page.on("pageerror", lambda exc: errors.append(f"page error: {exc}"))
            page.on("request", lambda req: requests.append(req.url))
            page.goto(html_path.as_uri(), wait_until="load")
            imgs = page.eval_on_selector_all(
                "img", "els => els.map(e => ({id: e.id, alt: e.alt, complete: e.complete, w: e.naturalWidth, "
                "h: e.naturalHeight, shown: e.getBoundingClientRect().width}))")
            t2 = page.eval_on_selector_all(
                "#table2 tbody tr", "rows => rows.map(r => Array.from(r.cells).map(c => c.textContent.trim()))")
            t3 = page.eval_on_selector_all(
                "#table3 tbody tr", "rows => rows.map(r => Array.from(r.cells).map(c => c.textContent.trim()))")
            title = page.title()
            dead = page.text_content("#deadband")
        finally:
            browser.close()
    assert errors == []
    assert [u for u in requests if u != html_path.as_uri() and not u.startswith("data:")] == []
    assert {i["id"] for i in imgs} == FIGURE_IDS
    for i in imgs:
        assert i["complete"] and i["w"] > 0 and i["h"] > 0 and i["shown"] > 0, i
        assert i["alt"].strip()
    assert "BE-PAM" in title
    summ = processed.summary()
    assert t2 == [list(r.values()) for r in table2_rows(summ)]
    assert [r[0] for r in t2] == [f"{p:g}" for p in PRESSURES]
    assert t3 == [list(r.values()) for r in table3_rows(fits)]
    e = fits["energy"]
    assert t3[0][1].startswith(f"{e.parameters['alpha0'].value:.2f} ± ")
    assert t3[0][4] == fmt_pct(e.metrics.nrmse_cycles)
    assert fmt_num(summ["deadband_kpa"], ".4g") in dead


# ------------------------------------------------------------------------------------------------
# the library function: another actuator, the sign of the stress curvature, the progress bar
# ------------------------------------------------------------------------------------------------
def test_build_report_bc_pam(tmp_path, monkeypatch, capsys):
    act = presets.bc_pam("force_balance")
    raw = tmp_path / "raw"
    simulate_tests(act, [60, 100], raw, "force_balance", dialect="testxpert",
                   settings=SimulationSettings(seed=5, cycles=2))
    monkeypatch.setenv("FORCE_COLOR", "1")  # pretend stderr is a terminal: the progress bar is drawn
    monkeypatch.delenv("TTY_COMPATIBLE", raising=False)
    res = build_report(raw, act, tmp_path / "bc.html", models=("force-balance",), progress=True)
    err = capsys.readouterr().err
    assert isinstance(res, Report)  # build_report returns a Report value (it returned a dict)
    assert res.progress_shown and "bendpam report" in err
    assert res.html.exists() and res.figures == ["fig-figure4", "fig-figure7-force_balance", "fig-stresses"]
    assert [i["dialect"] for i in res.inputs] == ["testxpert", "testxpert"]
    assert list(res.fits) == ["force_balance"] and res.notes == []
    top = res.processed.results[-1]
    assert res.stresses["pressure_kpa"] == 100.0
    assert res.stresses["curvature_per_mm"] == pytest.approx(-0.5 * top.free_curvature[0])  # BC-PAM: k' < 0
    assert res.summary["deadband_kpa"] == pytest.approx(res.processed.summary()["deadband_kpa"])
    text = res.html.read_text(encoding="utf-8")
    assert 'id="table3"' in text and "energy model" not in text
    # without a terminal: no bar
    monkeypatch.delenv("FORCE_COLOR")
    monkeypatch.setenv("TTY_COMPATIBLE", "0")
    res = build_report(raw, act, tmp_path / "bc2.html", models=("energy",), progress=True)
    assert not res.progress_shown and capsys.readouterr().err == ""
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bc.html", "bc2.html", "raw"]


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
