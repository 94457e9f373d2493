"""The manifest of an output set: how bendpam recognises, checks and describes what it wrote.

Every folder that :class:`bendpam.infra.outputs.OutputSet` writes holds ``manifest.json``::

    {
      "format": "bendpam-output-set",      # the marker: a manifest.json without it is not bendpam's
      "format_version": 1,
      "producer": "process",               # the command (or library name) that wrote the set
      "bendpam_version": "0.4.0",
      "command": ["bendpam", "process", "raw", "--out", "proc"],
      "cwd": "...", "target": "...", "started_utc": "...", "finished_utc": "...",
      "files": [{"path": "curves.nc", "size": 12345, "sha256": "..."}, ...],   # every file but itself
      "inputs": [{"path": "/abs/raw/a.csv", "size": 1, "sha256": "..."}, ...]
    }

Two uses:

* before a set is replaced, :func:`ownership_problem` says whether every file in the folder is one
  that bendpam wrote there, unchanged (a folder with other content, a foreign ``manifest.json``, a
  file the manifest does not list or one changed since, or a set of another producer is refused);
* when a set is read back, :func:`verify_set` / :func:`verify_file` check the files against the
  manifest's sizes and sha256 and refuse a mismatch in one line naming the file.
"""

from __future__ import annotations

import datetime as _dt
import json
import os
import re
import stat
from pathlib import Path, PurePosixPath
from typing import Any

from bendpam.errors import FileFormatError
from bendpam.infra.atomic import json_safe
from bendpam.infra.budgets import read_input_bytes
from bendpam.infra.fsops import ANY_TEMP, hash_file

__all__ = [
    "MANIFEST_FORMAT",
    "MANIFEST_NAME",
    "MANIFEST_VERSION",
    "bendpam_version",
    "build_manifest",
    "manifest_producer",
    "now_utc",
    "ownership_problem",
    "read_manifest",
    "to_json",
    "verify_file",
    "verify_input",
    "verify_set",
]

#: Name of the manifest that every output set holds.
MANIFEST_NAME = "manifest.json"
#: Format marker and version recorded in every manifest.
MANIFEST_FORMAT = "bendpam-output-set"
MANIFEST_VERSION = 1

_SHA256 = re.compile(r"[0-9a-f]{64}")
#: Files that file browsers add to any folder they show (not the user's data): replaced with the set.
OS_LITTER = re.compile(r"\.DS_Store|\._.*|Thumbs\.db|ehthumbs\.db|desktop\.ini|\.directory", re.IGNORECASE)


def to_json(obj: Any, *, indent: int | None = 2) -> str:
    """Strict JSON text of ``obj`` (after :func:`~bendpam.infra.atomic.json_safe`), ending in a newline.

    NaN becomes ``null`` (missing) and +-inf ``"inf"``/``"-inf"``; ``allow_nan=False`` guarantees that no ``NaN`` or
    ``Infinity`` token (which is not JSON) can reach a file.

    Examples
    --------
    >>> to_json({"x": float("nan"), "y": 1.5}, indent=None)
    '{"x": null, "y": 1.5}\\n'
    """
    return json.dumps(json_safe(obj), indent=indent, allow_nan=False) + "\n"


def bendpam_version() -> str:
    """The installed bendpam version (the source tree's when it is not installed).

    Examples
    --------
    >>> bendpam_version().count(".") >= 1
    True
    """
    import importlib.metadata  # (not at import: the command line's start-up does without it)

    try:
        return importlib.metadata.version("bendpam")
    except importlib.metadata.PackageNotFoundError:
        from bendpam.version import __version__

        return str(__version__)


def now_utc() -> str:
    """The time now, ISO 8601 in UTC to the millisecond.

    Examples
    --------
    >>> now_utc().endswith("+00:00")
    True
    """
    return _dt.datetime.now(_dt.UTC).isoformat(timespec="milliseconds")


# ----------------------------------------------------------------------------------------------
# writing
# ----------------------------------------------------------------------------------------------
def _set_files(folder: Path, *, fsync: bool = False) -> list[dict[str, Any]]:
    files = []
    for dirpath, dirnames, filenames in os.walk(folder):
        dirnames.sort()
        for fn in sorted(filenames):
            p = Path(dirpath) / fn
            rel = p.relative_to(folder).as_posix()
            if rel == MANIFEST_NAME or not p.is_file():
                continue
            size, digest = hash_file(p, fsync=fsync)
            files.append({"path": rel, "size": size, "sha256": digest})
    return files


def _input_entries(inputs: list[Path]) -> list[dict[str, Any]]:
    entries: list[dict[str, Any]] = []
    seen: set[Path] = set()
    for inp in inputs:
        if inp.is_dir():
            members: list[Path] = []
            for dirpath, dirnames, filenames in os.walk(inp):
                dirnames[:] = sorted(d for d in dirnames if not ANY_TEMP.fullmatch(d))
                members.extend(Path(dirpath) / fn for fn in sorted(filenames) if not ANY_TEMP.fullmatch(fn))
        else:
            members = [inp]
        for p in members:
            if p in seen or not p.is_file():
                continue
            seen.add(p)
            size, digest = hash_file(p)
            entries.append({"path": str(p), "size": size, "sha256": digest})
    return entries


def build_manifest(folder: Path, *, producer: str | None, command: list[str], target: Path,
                   inputs: list[Path], started_utc: str, fsync: bool = True) -> dict[str, Any]:
    """The manifest of the set in ``folder`` (files hashed, and flushed to disk with ``fsync``).

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     _ = (Path(d) / "a.txt").write_text("a")
    ...     m = build_manifest(Path(d), producer="demo", command=["demo"], target=Path(d), inputs=[],
    ...                        started_utc=now_utc())
    >>> m["format"], m["producer"], [f["path"] for f in m["files"]]
    ('bendpam-output-set', 'demo', ['a.txt'])
    """
    manifest: dict[str, Any] = {
        "format": MANIFEST_FORMAT,
        "format_version": MANIFEST_VERSION,
        "producer": producer,
        "bendpam_version": bendpam_version(),
        "command": command,
        "cwd": os.getcwd(),
        "target": str(target),
        "started_utc": started_utc,
        "finished_utc": "",
        "files": _set_files(folder, fsync=fsync),
        "inputs": _input_entries(inputs),
    }
    manifest["finished_utc"] = now_utc()
    return manifest


# ----------------------------------------------------------------------------------------------
# reading
# ----------------------------------------------------------------------------------------------
def _valid_entry(entry: Any) -> bool:
    if not isinstance(entry, dict):
        return False
    path, size, digest = entry.get("path"), entry.get("size"), entry.get("sha256")
    if not isinstance(path, str) or not path or not isinstance(size, int) or size < 0:
        return False
    if not isinstance(digest, str) or not _SHA256.fullmatch(digest):
        return False
    parts = PurePosixPath(path).parts
    return not PurePosixPath(path).is_absolute() and ".." not in parts and path != MANIFEST_NAME


def read_manifest(folder: str | os.PathLike[str]) -> dict[str, Any] | None:
    """The bendpam manifest of ``folder``; None when it has no ``manifest.json``.

    Raises
    ------
    FileFormatError
        The folder holds a ``manifest.json`` that is not bendpam's (no format marker, a
        newer format version, or a malformed file list); the message names the file.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     print(read_manifest(d))
    ...     _ = (Path(d) / "manifest.json").write_text('{"name": "another tool"}')
    ...     read_manifest(d)
    Traceback (most recent call last):
    ...
    bendpam.errors.FileFormatError: .../manifest.json: not a bendpam manifest (no "format": "bendpam-output-set")
    """
    path = Path(folder) / MANIFEST_NAME
    if not path.exists():
        return None
    try:
        text = read_input_bytes(path, "manifest")
    except (FileNotFoundError, NotADirectoryError):
        return None
    except OSError as exc:
        raise FileFormatError(f"{path}: cannot be read ({exc.strerror or exc})") from exc
    try:
        m = json.loads(text)
    except (ValueError, UnicodeDecodeError):
        raise FileFormatError(f"{path}: not a bendpam manifest (not JSON)") from None
    if not isinstance(m, dict) or m.get("format") != MANIFEST_FORMAT:
        raise FileFormatError(f'{path}: not a bendpam manifest (no "format": "{MANIFEST_FORMAT}")')
    version = m.get("format_version")
    if not isinstance(version, int) or not 1 <= version <= MANIFEST_VERSION:
        raise FileFormatError(f"{path}: bendpam manifest format version {version!r}; this bendpam reads "
                              f"version {MANIFEST_VERSION} (a newer bendpam wrote it?)")
    files = m.get("files")
    if not isinstance(files, list) or not all(_valid_entry(e) for e in files):
        raise FileFormatError(f"{path}: bendpam manifest with a malformed file list")
    return m


def manifest_producer(manifest: dict[str, Any]) -> str | None:
    """Who wrote a set: the manifest's ``producer``, or for older manifests the command's name.

    Examples
    --------
    >>> manifest_producer({"producer": "fit"})
    'fit'
    >>> manifest_producer({"command": ["/usr/bin/bendpam", "--debug", "simulate-test", "--out", "raw"]})
    'simulate-test'
    >>> manifest_producer({"command": ["python", "script.py"]}) is None
    True
    """
    if "producer" in manifest:
        p = manifest["producer"]
        return p if isinstance(p, str) else None
    cmd = manifest.get("command")
    if isinstance(cmd, list) and cmd and isinstance(cmd[0], str) and Path(cmd[0]).stem == "bendpam":
        return next((a for a in cmd[1:] if isinstance(a, str) and not a.startswith("-")), None)
    return None


def _entry_problem(folder: Path, entry: dict[str, Any]) -> str | None:
    p = folder.joinpath(*PurePosixPath(entry["path"]).parts)
    try:
        st = p.stat()
    except FileNotFoundError:
        return "missing"
    if not stat.S_ISREG(st.st_mode):  # a pipe or device in a file's place: never read it (it could hang)
        return "changed"
    try:
        size, digest = hash_file(p) if st.st_size == entry["size"] else (-1, "")
    except FileNotFoundError:
        return "missing"
    if size != entry["size"] or digest != entry["sha256"]:
        return "changed"
    return None


def verify_set(folder: str | os.PathLike[str], *, required: bool = False) -> dict[str, Any] | None:
    """Check every file that ``folder``'s manifest lists against its size and sha256.

    Returns the manifest (None when the folder has none and ``required`` is false: a set
    written without bendpam's output sets has nothing to check).

    Raises
    ------
    FileFormatError
        One line naming the first file that is missing or differs from the manifest (it
        was changed or damaged after bendpam wrote it), a manifest that is not bendpam's,
        or, with ``required``, a folder without a manifest.

    Examples
    --------
    >>> import tempfile
    >>> from bendpam.infra.outputs import OutputSet
    >>> with tempfile.TemporaryDirectory() as d:
    ...     with OutputSet(Path(d) / "out", command=["demo"]) as out:
    ...         _ = out.write_text("curves.csv", "a,b\\n1,2\\n")
    ...     _ = verify_set(Path(d) / "out")                        # fine
    ...     _ = (Path(d) / "out" / "curves.csv").write_text("a,b\\n1,3\\n")
    ...     verify_set(Path(d) / "out")
    Traceback (most recent call last):
    ...
    bendpam.errors.FileFormatError: .../out/curves.csv: does not match ... manifest.json ...
    """
    folder = Path(folder)
    m = read_manifest(folder)
    if m is None:
        if required:
            raise FileFormatError(f"{folder}: no {MANIFEST_NAME} (not an output folder written by bendpam)")
        return None
    for entry in m["files"]:
        why = _entry_problem(folder, entry)
        if why is not None:
            p = folder / entry["path"]
            raise FileFormatError(_mismatch(p, why))
    return m


def _mismatch(p: Path, why: str) -> str:
    if why == "missing":
        return f"{p}: listed in the {MANIFEST_NAME} of its folder but missing (the set is incomplete)"
    return (f"{p}: does not match the {MANIFEST_NAME} of its folder (size or sha256 differ: "
            "changed or damaged after bendpam wrote it)")


def verify_file(path: str | os.PathLike[str]) -> str | None:
    """Check one file of a set against the manifest of its folder, if the folder has one.

    A file that the manifest does not list, or a folder without a manifest, passes (there
    is nothing to check it against).  Returns the sha256 the file was checked against (None when
    it was not checked), so that a reader need not hash it again.

    Raises
    ------
    FileFormatError
        One line naming the file when it differs from the manifest, or the manifest when
        it is not bendpam's.

    Examples
    --------
    >>> import tempfile
    >>> from bendpam.infra.outputs import OutputSet
    >>> with tempfile.TemporaryDirectory() as d:
    ...     with OutputSet(Path(d) / "fit", command=["demo"]) as out:
    ...         _ = out.write_text("fit.json", "{}")
    ...     verify_file(Path(d) / "fit" / "fit.json")               # fine
    ...     _ = (Path(d) / "fit" / "fit.json").write_text("{ }")
    ...     verify_file(Path(d) / "fit" / "fit.json")
    Traceback (most recent call last):
    ...
    bendpam.errors.FileFormatError: .../fit/fit.json: does not match ... manifest.json ...
    """
    p = Path(path)
    folder = p.parent
    m = read_manifest(folder)
    if m is None:
        return None
    try:
        rel = p.resolve().relative_to(folder.resolve()).as_posix()
    except ValueError:
        return None
    for entry in m["files"]:
        if entry["path"] == rel:
            why = _entry_problem(folder, entry)
            if why is not None:
                raise FileFormatError(_mismatch(p, why))
            return str(entry["sha256"])
    return None


# ----------------------------------------------------------------------------------------------
# may this folder be replaced?
# ----------------------------------------------------------------------------------------------
def _first_unlisted(folder: Path, listed: set[str]) -> Path | None:
    for dirpath, dirnames, filenames in os.walk(folder):
        dirnames.sort()
        names = sorted(filenames) + sorted(d for d in dirnames if os.path.islink(os.path.join(dirpath, d)))
        for fn in names:
            p = Path(dirpath) / fn
            rel = p.relative_to(folder).as_posix()
            if rel == MANIFEST_NAME or (rel not in listed and OS_LITTER.fullmatch(fn) and p.is_file()):
                continue
            if rel not in listed or p.is_symlink() or not p.is_file():
                return p
    return None


def ownership_problem(folder: Path, producer: str | None, shown: str | None = None) -> tuple[str, bool] | None:
    """Why the existing folder ``folder`` may not be replaced by a set of ``producer``; None if it may.

    Returns ``(reason, user_files)``: ``user_files`` is true when the folder holds content
    that bendpam did not write (or changed since), which must never be deleted -- only
    moved aside, and only when the caller forces the replacement.  An empty folder, and a
    set of the same producer whose files all match its manifest, may be replaced (files
    that file browsers add, such as ``.DS_Store`` or ``Thumbs.db``, go with it).  Paths
    in the reason start with ``shown`` (the folder as the user named it).

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     _ = (Path(d) / "thesis.tex").write_text("precious")
    ...     ownership_problem(Path(d), "process", shown="Documents")
    ("it holds 'Documents/thesis.tex', which bendpam did not write (no bendpam manifest.json there)", True)
    """
    def name(p: Path) -> str:
        return repr(os.path.join(shown, p.relative_to(folder)) if shown is not None else str(p))

    with os.scandir(folder) as entries:
        first = next(entries, None)
    if first is None:
        return None
    try:
        m = read_manifest(folder)
    except FileFormatError:
        return f"it holds a {MANIFEST_NAME} that bendpam did not write", True
    if m is None:
        stray = _first_unlisted(folder, set())
        if stray is None:  # nothing but empty folders and file-browser litter
            return None
        return f"it holds {name(stray)}, which bendpam did not write (no bendpam {MANIFEST_NAME} there)", True
    stray = _first_unlisted(folder, {e["path"] for e in m["files"]})
    if stray is not None:
        return f"it holds {name(stray)}, which its {MANIFEST_NAME} does not list (not written by bendpam)", True
    for entry in m["files"]:
        if _entry_problem(folder, entry) == "changed":
            return f"{name(folder / entry['path'])} was changed after bendpam wrote it", True
    old = manifest_producer(m)
    if old != producer:
        by = f"'bendpam {old}'" if old else "another bendpam program"
        new = f"'bendpam {producer}'" if producer else "this program"
        return f"it holds the output of {by}, which {new} would replace", False
    return None


def verify_input(path: str | os.PathLike[str]) -> str | None:
    """Check an input that is (or lies in) a bendpam output set against that set's manifest.

    A folder is checked whole (:func:`verify_set`), a file against the manifest of its
    folder (:func:`verify_file`, whose checked sha256 is returned; None otherwise).  A folder whose
    ``manifest.json`` is not bendpam's is someone else's data and passes unchecked, as does anything
    without a manifest.

    Raises
    ------
    FileFormatError
        One line naming the file that differs from the manifest.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     _ = (Path(d) / "manifest.json").write_text('{"tool": "not bendpam"}')
    ...     verify_input(d)                                        # someone else's: not checked
    """
    p = Path(path)
    folder = p if p.is_dir() else p.parent
    try:
        if read_manifest(folder) is None:
            return None
    except FileFormatError:
        return None
    if p.is_dir():
        verify_set(p)
        return None
    return verify_file(p)
