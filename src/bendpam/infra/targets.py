"""Where an output may go: the rules checked before anything is written.

* ``~`` at the start of the path given is expanded (``./~`` is a folder named ``~``);
* a symbolic link is followed; a link (anywhere on the path) to nothing is refused, since
  following it would create the output somewhere the user did not name;
* the file-system root, the home folder (or a folder holding it) and the current folder (or a
  folder holding it) are never an output folder;
* an output equal to, inside, or containing one of the inputs is refused, for folders and single
  files alike.

Each refusal is one line naming the paths, raised as :class:`OutputRefused` (an
:class:`~bendpam.errors.InputError`).
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterable
from pathlib import Path

from bendpam.errors import InputError

__all__ = ["OutputRefused", "check_against_inputs", "check_not_precious", "resolve_inputs", "resolve_target"]


class OutputRefused(InputError):
    """An output that bendpam will not write (one line naming the paths).

    Attributes
    ----------
    forceable : bool
        True when forcing the replacement would be allowed (the old content is then moved
        aside, never deleted); false for refusals that nothing overrides.
    reason : str
        The message without its closing advice (a caller may give its own).

    Examples
    --------
    >>> exc = OutputRefused("output folder 'x' holds 'x/a.txt', which bendpam did not write", forceable=True)
    >>> exc.forceable, isinstance(exc, InputError)
    (True, True)
    """

    def __init__(self, message: str, *, forceable: bool = False, reason: str | None = None) -> None:
        super().__init__(message)
        self.forceable = forceable
        self.reason = message if reason is None else reason


def _dangling_link(p: Path) -> Path | None:
    for q in (p, *p.parents):
        if q.is_symlink() and not q.exists():
            return q
    return None


def resolve_target(given: str | os.PathLike[str], kind: str = "folder") -> Path:
    """The absolute target of an output named ``given`` (``~`` expanded, links followed).

    Raises
    ------
    OutputRefused
        A link to nothing on the path, or the file-system root.
    TypeError
        ``given`` is not a path.

    Examples
    --------
    >>> import os, tempfile
    >>> resolve_target("~") == Path.home().resolve()
    True
    >>> with tempfile.TemporaryDirectory() as d:
    ...     (Path(d) / "link").symlink_to(Path(d) / "nowhere")
    ...     resolve_target(Path(d) / "link")
    Traceback (most recent call last):
    ...
    bendpam.infra.targets.OutputRefused: output folder '.../link' is a symbolic link to '.../nowhere', which ...
    """
    if not isinstance(given, str | os.PathLike):
        raise TypeError(f"expected a path, got {type(given).__name__}")
    text = os.fspath(given)
    if not isinstance(text, str):
        raise TypeError("output paths are str or os.PathLike[str]")
    p = Path(os.path.expanduser(text) if text.startswith("~") else text)
    link = _dangling_link(p)
    if link is not None:
        where = os.readlink(link)
        raise OutputRefused(f"output {kind} {text!r} is a symbolic link to {where!r}, which does not exist"
                            if link == p else
                            f"output {kind} {text!r}: {str(link)!r} is a symbolic link to {where!r}, "
                            "which does not exist")
    target = p.resolve()
    if target == Path(target.anchor):
        raise OutputRefused(f"output {kind} {text!r} is the file-system root")
    return target


def resolve_inputs(inputs: Iterable[str | os.PathLike[str]]) -> list[tuple[Path, Path]]:
    """``(as given, resolved)`` for each input; a missing input is refused.

    Examples
    --------
    >>> resolve_inputs(["no-such-input.csv"])
    Traceback (most recent call last):
    ...
    bendpam.errors.InputError: input 'no-such-input.csv' does not exist
    """
    if isinstance(inputs, str | os.PathLike):
        inputs = [inputs]
    out = []
    for given in inputs:
        g = Path(given)
        r = Path(os.path.expanduser(os.fspath(given)) if os.fspath(given).startswith("~") else g).resolve()
        if not r.exists():
            raise InputError(f"input {str(given)!r} does not exist")
        out.append((g, r))
    return out


def _same(a: Path, b: Path) -> bool:
    if a == b:
        return True
    with contextlib.suppress(OSError):
        return a.exists() and b.exists() and os.path.samefile(a, b)
    return False


def check_against_inputs(target: Path, shown: str, inputs: list[tuple[Path, Path]], kind: str = "folder") -> None:
    """Refuse an output equal to, inside or containing an input.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     raw = Path(d).resolve() / "raw"; raw.mkdir()
    ...     check_against_inputs(raw / "report.html", "raw/report.html", [(Path("raw"), raw)], kind="file")
    Traceback (most recent call last):
    ...
    bendpam.infra.targets.OutputRefused: output file 'raw/report.html' is inside the input folder 'raw'; ...
    """
    for given, inp in inputs:
        if _same(target, inp):
            what = "input folder" if inp.is_dir() else "input"
            raise OutputRefused(f"output {kind} {shown!r} is the {what} {str(given)!r}; choose another "
                                + ("folder" if kind == "folder" else "name"))
        if inp.is_dir() and target.is_relative_to(inp):
            raise OutputRefused(f"output {kind} {shown!r} is inside the input folder {str(given)!r}; "
                                "choose another place")
        if kind == "folder" and inp.is_relative_to(target):
            raise OutputRefused(f"input {str(given)!r} is inside the output folder {shown!r}, which would be "
                                "replaced; choose another folder")


def check_not_precious(target: Path, shown: str) -> None:
    """Refuse the home folder, the current folder, or a folder holding either, as an output folder.

    Examples
    --------
    >>> check_not_precious(Path.home().resolve(), "~")
    Traceback (most recent call last):
    ...
    bendpam.infra.targets.OutputRefused: output folder '~' is your home folder; bendpam never replaces it
    """
    try:
        home: Path | None = Path.home().resolve()
    except (RuntimeError, OSError, KeyError):
        home = None
    if home is not None and (home == target or home.is_relative_to(target)):
        what = "is your home folder" if home == target else f"holds your home folder {str(home)!r}"
        raise OutputRefused(f"output folder {shown!r} {what}; bendpam never replaces it")
    if target.is_dir():
        try:
            cwd: Path | None = Path.cwd().resolve()
        except OSError:
            cwd = None
        if cwd is not None and (cwd == target or cwd.is_relative_to(target)):
            raise OutputRefused(f"output folder {shown!r} is (or contains) the current folder, which would be "
                                "replaced; run elsewhere or choose another folder")
