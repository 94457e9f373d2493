"""bendpam.infra.progress.Progress: plain lines off a terminal, a rich bar on one, silence when quiet."""

import io
import subprocess
import sys
import threading
import time

import pytest

from bendpam.infra.progress import Progress, format_duration


class FakeClock:
    def __init__(self):
        self.t = 100.0

    def __call__(self):
        return self.t


def test_a_line_every_interval_and_at_the_end():
    out, clock = io.StringIO(), FakeClock()
    with Progress(4000, "sweep", stream=out, interval_s=5.0, clock=clock) as bar:
        for _ in range(40):
            clock.t += 0.5
            bar.advance(100)
    # 20 s of work, a line every 5 s while unfinished (at 5, 10 and 15 s), then the end
    assert out.getvalue().splitlines() == [
        "bendpam: sweep: 1000/4000 (25 %), 5 s elapsed, ~15 s left",
        "bendpam: sweep: 2000/4000 (50 %), 10 s elapsed, ~10 s left",
        "bendpam: sweep: 3000/4000 (75 %), 15 s elapsed, ~5 s left",
        "bendpam: sweep: 4000/4000 (100 %), finished in 20 s",
    ]


def test_short_work_writes_nothing():
    out, clock = io.StringIO(), FakeClock()
    with Progress(10, "fit", stream=out, interval_s=5.0, clock=clock) as bar:
        for _ in range(10):
            clock.t += 0.1
            bar.advance()
    assert out.getvalue() == ""  # done within the first interval: no line at all


def test_interval_zero_reports_every_step():
    out = io.StringIO()
    with Progress(3, "process", stream=out, interval_s=0) as bar:
        for _ in range(3):
            bar.advance()
    assert [line.split(",")[0] for line in out.getvalue().splitlines()] == [
        "bendpam: process: 1/3 (33 %)",  # rounded down: 100 % only when done
        "bendpam: process: 2/3 (66 %)",
        "bendpam: process: 3/3 (100 %)",
    ]


def test_interval_from_the_environment(monkeypatch):
    monkeypatch.setenv("BENDPAM_PROGRESS_INTERVAL_S", "0")
    assert Progress(1, "x").interval_s == 0.0
    monkeypatch.setenv("BENDPAM_PROGRESS_INTERVAL_S", "nonsense")
    assert Progress(1, "x").interval_s == 5.0
    assert Progress(1, "x", interval_s=2).interval_s == 2.0


def wait_for_lines(out, n, timeout_s=60.0):
    """Wait until ``out`` holds ``n`` lines (written by another thread); the timeout only guards a hang."""
    deadline = time.monotonic() + timeout_s
    while out.getvalue().count("\n") < n:
        assert time.monotonic() < deadline, out.getvalue()
        time.sleep(0.005)


def test_timer_reports_a_long_single_step():
    # the timer wakes every 0.05 s of real time but writes only when the (fake) clock has moved on by
    # the interval: each line comes when the test moves the clock, however slowly the machine runs
    out, clock = io.StringIO(), FakeClock()
    with Progress(None, "fit", stream=out, interval_s=0.05, clock=clock) as bar:
        for n in (1, 2):  # one long step without advance(): the background timer still reports
            clock.t += 0.1  # more than the interval (0.05 s)
            wait_for_lines(out, n)
        bar.advance()
    lines = out.getvalue().splitlines()
    assert len(lines) >= 3
    assert lines[0] == "bendpam: fit: 0 s elapsed"  # unknown total, nothing counted yet: the time only
    assert lines[-1] == "bendpam: fit: 1 done, finished in 0 s"


def test_unknown_total_and_description_change():
    out, clock = io.StringIO(), FakeClock()
    with Progress(None, "process", stream=out, interval_s=1.0, clock=clock) as bar:
        clock.t += 2
        bar.advance(3, description="process a.csv")
    assert out.getvalue().splitlines() == [
        "bendpam: process a.csv: 3 done, 2 s elapsed",
        "bendpam: process a.csv: 3 done, finished in 2 s",
    ]


@pytest.mark.parametrize("value", ["inf", "1e300"])
def test_an_endless_interval_writes_no_line(monkeypatch, value):
    """``BENDPAM_PROGRESS_INTERVAL_S=inf`` (or more than a timer can wait): no line, however long the work."""
    monkeypatch.setenv("BENDPAM_PROGRESS_INTERVAL_S", value)
    out, clock = io.StringIO(), FakeClock()
    with Progress(10, "sweep", stream=out, clock=clock) as bar:
        assert bar._timer is None
        for _ in range(9):
            clock.t += 1e6
            bar.advance()
    assert bar.completed == 9 and out.getvalue() == ""


def test_quiet_writes_nothing_and_still_counts():
    out = io.StringIO()
    with Progress(5, "sweep", stream=out, quiet=True, interval_s=0.0) as bar:
        bar.advance(5)
    assert out.getvalue() == ""
    assert bar.completed == 5


def test_interrupt_stops_and_reraises():
    out = io.StringIO()
    with pytest.raises(KeyboardInterrupt), Progress(10, "sweep", stream=out, interval_s=0) as bar:
        bar.advance(4)
        raise KeyboardInterrupt
    assert out.getvalue().splitlines()[-1].startswith("bendpam: sweep: interrupted at 4/10 (40 %)")


def test_error_propagates_without_a_finished_line():
    out = io.StringIO()
    with pytest.raises(ValueError, match="boom"), Progress(3, "fit", stream=out, interval_s=0) as bar:
        bar.advance()
        raise ValueError("boom")
    assert out.getvalue().splitlines() == ["bendpam: fit: 1/3 (33 %), 0 s elapsed, ~0 s left"]


def test_early_error_writes_nothing():
    out = io.StringIO()
    with pytest.raises(ValueError), Progress(3, "fit", stream=out):
        raise ValueError("bad option")
    assert out.getvalue() == ""  # the command's one-line error stays the only line


def test_advance_is_thread_safe():
    out = io.StringIO()
    with Progress(8000, "sweep", stream=out, interval_s=0.0) as bar:
        threads = [threading.Thread(target=lambda: [bar.advance() for _ in range(1000)]) for _ in range(8)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
    assert bar.completed == 8000
    assert out.getvalue().splitlines()[-1].startswith("bendpam: sweep: 8000/8000 (100 %), finished")


def test_terminal_draws_a_rich_bar():
    from rich.console import Console

    buf = io.StringIO()
    console = Console(file=buf, force_terminal=True, width=100)
    with Progress(10, "sweep", stream=console) as bar:
        with Progress(3, "inner", stream=console) as inner:  # nested bars share one display
            inner.advance(3)
        bar.advance(10)
    text = buf.getvalue()
    assert "\x1b[" in text  # drawn with terminal control sequences
    assert "sweep" in text and "10/10" in text
    assert "bendpam: sweep:" not in text  # not the plain lines


def test_terminal_bar_stops_on_interrupt():
    from rich.console import Console

    from bendpam.infra import progress

    console = Console(file=io.StringIO(), force_terminal=True, width=80)
    with pytest.raises(KeyboardInterrupt), Progress(10, "sweep", stream=console):
        raise KeyboardInterrupt
    assert progress._LIVE["progress"] is None  # the live display is released
    with Progress(1, "again", stream=console) as bar:  # and a new one can start
        bar.advance()


def test_format_duration():
    assert [format_duration(s) for s in (0, 59.4, 60, 3599, 3600, float("nan"))] == [
        "0 s",
        "59 s",
        "1 min 00 s",
        "59 min 59 s",
        "1 h 00 min",
        "?",
    ]


def test_import_is_light():
    code = "import sys, bendpam.infra.progress; print('rich' in sys.modules)"
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert res.stdout.strip() == "False"
