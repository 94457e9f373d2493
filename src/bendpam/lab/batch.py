"""Process many files at once (a folder of exports): every file read, every one reported.

:func:`process_files` reads each file (every specimen or block in it, through
:func:`bendpam.lab.readers.read_tests`), processes each test and records what became of every
file: ``read`` (how many tests, and their plausibility findings) or ``skipped`` and why.  By default
any bad file refuses the whole set with :class:`FilesRefused`, which names every bad file at once;
with ``keep_going=True`` the bad files are skipped and reported, and the rest is processed.
Several tests at one pressure are replicates (:meth:`~bendpam.lab.processed.ProcessedSet.replicates`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path

from bendpam.errors import BendpamError, ProcessingError
from bendpam.lab.processed import ProcessedSet, ProcessingOptions
from bendpam.lab.processing import NotABendingTest, number_replicates, process_one, warn_set
from bendpam.physics.fixture import PAPER_FIXTURE, Fixture

__all__ = ["FilesRefused", "file_line", "process_files"]


class FilesRefused(ProcessingError):
    """Some files could not be read or processed; :attr:`problems` holds one line per bad file.

    >>> exc = FilesRefused(["a.csv: no header", "b.csv: only 5 samples"])
    >>> str(exc)
    '2 files cannot be processed: a.csv: no header; b.csv: only 5 samples'
    >>> exc.problems[1]
    'b.csv: only 5 samples'
    """

    def __init__(self, problems: Sequence[str]):
        self.problems = list(problems)
        n = len(self.problems)
        super().__init__(f"{n} file{'s' * (n != 1)} cannot be processed: " + "; ".join(self.problems))


def file_line(info: dict) -> str:
    """One line for one file's entry of :attr:`ProcessedSet.files`: read (tests, warnings) or skipped and why.

    >>> file_line({"file": "a.csv", "status": "read", "tests": 1, "findings": []})
    'a.csv: read (1 test)'
    >>> file_line({"file": "z.csv", "status": "skipped", "reason": "z.csv: no table found", "findings": []})
    'z.csv: skipped: no table found'
    """
    name = info["file"]
    if info["status"] == "read":
        n = int(info.get("tests", 0))
        extra = f", {len(info['findings'])} plausibility warning(s)" if info.get("findings") else ""
        return f"{name}: read ({n} test{'s' * (n != 1)}{extra})"
    reason = str(info.get("reason", ""))
    if reason.startswith(f"{name}: "):
        reason = reason[len(name) + 2:]
    return f"{name}: skipped: {reason}"


def _one_file(path: Path, read_kw: dict, fixture: Fixture, options, keep_series: bool) -> tuple[dict, list]:
    """Read and process one file: ``(its entry, its results)``; a problem makes it ``skipped``."""
    from bendpam.lab.readers import read_tests

    info: dict = {"file": str(path), "status": "read", "tests": 0, "findings": []}
    results = []
    try:
        for rt in read_tests(path, **read_kw):
            results.append(process_one(rt, fixture=fixture, options=options, keep_series=keep_series))
    except NotABendingTest as exc:
        info.update(status="skipped", reason=str(exc))
        info["findings"] = [{"test": str(path), "pressure_kpa": None, "check": "not-bending", "value": None,
                             "bound": None, "unit": "", "message": str(exc)}]
        return info, []
    except BendpamError as exc:
        info.update(status="skipped", reason=str(exc).splitlines()[0] if str(exc) else type(exc).__name__)
        return info, []
    except OSError as exc:  # the file vanished or cannot be opened while the folder is read
        info.update(status="skipped", reason=f"{path}: cannot be read ({exc.strerror or type(exc).__name__})")
        return info, []
    info["tests"] = len(results)
    info["findings"] = [f for r in results for f in r.findings]
    return info, results


def process_files(paths, *, pressures_kpa: Sequence[float | None] | None = None, fixture: Fixture = PAPER_FIXTURE,
                  options: ProcessingOptions | None = None, keep_going: bool = False, keep_series: bool = True,
                  read_options: dict | None = None, on_file: Callable[[Path], None] | None = None) -> ProcessedSet:
    """Read and process every file of ``paths``; report each (:attr:`ProcessedSet.files`).

    Parameters
    ----------
    paths : files (a folder's files: :func:`bendpam.lab.files.collect_raw_files`).
    pressures_kpa : one pressure (kPa) or ``None`` per file; ``None`` takes it from the file.
    fixture, options, keep_series : as :func:`bendpam.lab.processing.process_tests`.
    keep_going : skip the files that cannot be read or processed (each reported with its reason)
        instead of refusing the set.
    read_options : keywords of :func:`bendpam.lab.read_test` (``columns``, ``rate_hz``, ``repair``...).
    on_file : called after each file (progress).

    Raises
    ------
    FilesRefused
        Without ``keep_going``, when any file is bad: every bad file, one line each.
    ProcessingError
        With ``keep_going``, when no file at all could be processed.

    Examples
    --------
    >>> import tempfile
    >>> import bendpam
    >>> from bendpam.lab.simulate import SimulationSettings, simulate_tests
    >>> be = bendpam.physics.presets.be_pam()
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     truth = simulate_tests(be, [100, 200], folder, settings=SimulationSettings(cycles=2, rate_hz=5.0, seed=1))
    ...     _ = (Path(folder) / "junk.csv").write_text("not a test\\n")
    ...     files = sorted(Path(folder).glob("*.csv"))
    ...     processed = process_files(files, keep_going=True, keep_series=False)
    ...     try:
    ...         process_files(files, keep_series=False)
    ...     except FilesRefused as exc:
    ...         problems = exc.problems
    >>> [file_line(f).split(": ")[1] for f in processed.files]
    ['read (1 test)', 'read (1 test)', 'skipped']
    >>> len(problems), problems[0].startswith(str(files[2]))
    (1, True)
    """
    files = [Path(p) for p in paths]
    if pressures_kpa is not None and len(pressures_kpa) != len(files):
        raise ProcessingError(f"{len(pressures_kpa)} pressure(s) for {len(files)} file(s); give one per file")
    entries, results = [], []
    for i, f in enumerate(files):
        kw = dict(read_options or {})
        if pressures_kpa is not None and pressures_kpa[i] is not None:
            kw["pressure_kpa"] = pressures_kpa[i]
        info, res = _one_file(f, kw, fixture, options, keep_series)
        entries.append(info)
        results.extend(res)
        if on_file is not None:
            on_file(f)
    bad = [e for e in entries if e["status"] == "skipped"]
    if bad and not keep_going:
        raise FilesRefused([str(e["reason"]) if str(e["reason"]).startswith(e["file"]) else f"{e['file']}: "
                            f"{e['reason']}" for e in bad])
    if not results:
        raise ProcessingError(f"none of the {len(files)} file(s) could be processed"
                              + (": " + "; ".join(str(e["reason"]) for e in bad) if bad else ""))
    warn_set(results)
    return ProcessedSet(results=number_replicates(results), fixture=fixture, options=options or ProcessingOptions(),
                        files=entries)
