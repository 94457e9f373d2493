"""All-or-nothing outputs that replace only what bendpam wrote.

Writing each output file atomically is not enough: a run killed between two files leaves
a new ``curves.nc`` beside an old ``summary.json``, two runs into one folder mix their
outputs, ``process RAW --out RAW`` writes into its own input, and a folder named by mistake
(``--out ~/Documents``) must never be emptied.  This module makes the *set* the unit:

* :class:`OutputSet` -- a command that writes a folder.  Files go to a staging folder
  beside the target; on success a ``manifest.json`` (:mod:`bendpam.infra.manifest`) is
  added and the staging folder replaces the target in one step (:mod:`bendpam.infra.fsops`).
  An existing target is replaced only when it is empty or a set of the same producer
  whose files all match its manifest; anything else is refused in one line naming the
  file at fault, and with ``force=True`` it is moved aside, never deleted.
* :class:`OutputFile` -- a command whose output is one file: the same guarantees without
  a manifest.
* :class:`OutputGroup` -- several outputs of one run that are committed together: each is
  put in place when its block ends (so the run may read it back), the old versions are
  kept, and they are dropped only when the group ends; an error or a signal before that
  puts every old version back.

The rules on the target itself (``~``, symbolic links, inputs, the home folder) are in
:mod:`bendpam.infra.targets`; the lock that keeps a second run off a target being written
is :class:`bendpam.infra.locks.TargetLock`.  Temporaries left by a run killed with
``SIGKILL`` (or a power cut) are cleaned by the next run on the same target, sets and single
files alike, while it holds the lock (any temporary a lock holder finds is stale).

Signals: inside :func:`~bendpam.infra.signals.interrupts`, SIGINT and SIGTERM raise
:class:`~bendpam.infra.signals.Interrupted`; the blocks remove their temporaries and leave
their targets as they were; the swaps hold the signals for their few system calls, and every
committed output is recorded (:func:`~bendpam.infra.signals.record_written`) so that the line
printed for an interruption says what was written.
"""

from __future__ import annotations

import contextvars
import datetime as _dt
import os
import shlex
import shutil
import sys
import tempfile
from collections.abc import Iterable, Sequence
from pathlib import Path, PurePath
from types import TracebackType
from typing import Any, Literal

from bendpam.errors import InputError
from bendpam.infra import fsops
from bendpam.infra.atomic import UMASK, json_safe
from bendpam.infra.locks import OutputBusy, TargetLock
from bendpam.infra.manifest import (
    MANIFEST_NAME,
    build_manifest,
    now_utc,
    ownership_problem,
    read_manifest,
    to_json,
    verify_input,
)
from bendpam.infra.registry import record_file, written_by_bendpam
from bendpam.infra.signals import (
    HeldSignals,
    Interrupted,
    interrupts,
    is_interruption,
    raise_pending,
    record_written,
)
from bendpam.infra.targets import (
    OutputRefused,
    check_against_inputs,
    check_not_precious,
    resolve_inputs,
    resolve_target,
)

__all__ = [
    "MANIFEST_NAME",
    "Interrupted",
    "OutputBusy",
    "OutputFile",
    "OutputGroup",
    "OutputRefused",
    "OutputSet",
    "current_group",
    "interrupts",
    "json_safe",
    "to_json",
]

_GROUP: contextvars.ContextVar[OutputGroup | None] = contextvars.ContextVar("bendpam_output_group", default=None)
_State = Literal["new", "open", "swapped", "done", "failed"]


def current_group() -> OutputGroup | None:
    """The :class:`OutputGroup` whose block is running here, if any.

    Examples
    --------
    >>> current_group() is None
    True
    >>> with OutputGroup() as g:
    ...     current_group() is g
    True
    """
    return _GROUP.get()


def _command_list(command: str | Sequence[str] | None) -> list[str]:
    if command is None:
        return [str(a) for a in sys.argv]
    if isinstance(command, str):
        return shlex.split(command)
    return [str(a) for a in command]


def _aside_name(target: Path) -> Path:
    stamp = _dt.datetime.now(_dt.UTC).strftime("%Y%m%dT%H%M%SZ")
    base = target.parent / f"{target.name}.moved-aside-{stamp}"
    p, n = base, 1
    while os.path.lexists(p):
        n += 1
        p = base.with_name(f"{base.name}-{n}")
    return p


# --------------------------------------------------------------------------------------
# shared machinery
# --------------------------------------------------------------------------------------
class _Output:
    """What :class:`OutputSet` and :class:`OutputFile` share: target, inputs, lock, state."""

    _kind: Literal["folder", "file"]

    def __init__(self, target: str | os.PathLike[str], *, inputs: Iterable[str | os.PathLike[str]] = (),
                 command: str | Sequence[str] | None = None, lock_timeout_s: float = 0.0,
                 force: bool = False) -> None:
        self.target: Path = resolve_target(target, self._kind)
        """The absolute target path (``~`` expanded, symbolic links resolved)."""
        self._given = Path(target)
        self._shown = os.fspath(target)
        if isinstance(inputs, str | os.PathLike):
            inputs = [inputs]
        self.inputs: list[Path] = [Path(p) for p in inputs]
        """The inputs as given."""
        self.command: list[str] = _command_list(command)
        """The command line recorded for the run (``command`` or ``sys.argv``)."""
        self.lock_timeout_s = float(lock_timeout_s)
        self.force = bool(force)
        self.moved_aside: Path | None = None
        """Where the old content of the target was moved (a forced replacement), else None."""
        self._lock = TargetLock(self.target)
        self._state: _State = "new"
        self._group: OutputGroup | None = None
        self._old: Path | None = None

    @property
    def shown(self) -> str:
        """The target as the user named it (for messages)."""
        return self._shown

    # -- steps the subclasses provide --------------------------------------------------------
    def _prepare(self) -> None:
        """Checks before the lock (inputs, target)."""
        raise NotImplementedError

    def _open(self) -> None:
        """Setup under the lock (stale temporaries, the staging place)."""
        raise NotImplementedError

    def _stage(self) -> None:
        """Make the written output ready to be put in place (flush, hash, manifest)."""
        raise NotImplementedError

    def _swap(self) -> None:
        """Put the new output in place, keeping the old version at ``self._old``."""
        raise NotImplementedError

    def _roll_back(self) -> None:
        """Undo :meth:`_swap`."""
        raise NotImplementedError

    def _discard(self) -> None:
        """Remove what was staged."""
        raise NotImplementedError

    # -- the life cycle ----------------------------------------------------------------------
    def _enter(self) -> Any:
        if self._state != "new":
            raise RuntimeError(f"an {type(self).__name__} can be entered only once")
        self._prepare()
        try:  # everything after the lock is taken: a signal anywhere here still releases it (no __exit__ yet)
            self._lock.acquire(self.lock_timeout_s)
            self._open()
            self._state = "open"
            self._group = current_group()
            if self._group is not None:
                self._group._join(self)
        except BaseException as exc:
            self._abort(exc)
            raise
        return self

    def _exit(self, exc: BaseException | None) -> Literal[False]:
        """Commit on success (or, in a group, put in place), else clean up; never swallows."""
        if self._state != "open":
            return False
        if exc is None:
            try:
                raise_pending()  # a signal Python could not raise inside a finalizer
            except Interrupted as pending:
                exc = pending
                self._abort(exc)
                raise
        if exc is not None:
            self._abort(exc)
            return False
        try:
            self._stage()
            with HeldSignals():
                self._swap()
                self._state = "swapped"
                if self._group is None:
                    self._finish()
        except BaseException as err:
            self._abort(err)
            raise
        return False

    def _finish(self) -> None:
        """Drop the old version (or leave it moved aside), release the lock, record the output."""
        old, self._old = self._old, None
        if old is not None and old != self.moved_aside:
            if ".bendpam-old-" in old.name:  # a half-removed old set must never be restored
                trash = old.parent / fsops.temp_name(self.target.name, "del")
                os.rename(old, trash)
                old = trash
            fsops.remove_path(old)
        self._state = "done"
        self._lock.release()
        record_written(self._shown)

    def _abort(self, exc: BaseException | None) -> None:
        """Put the old version back if needed, remove what was staged, release the lock."""
        with HeldSignals(drop=is_interruption(exc)):
            try:
                if self._state == "swapped":
                    self._roll_back()
                if self._state != "done":  # (a signal held during the swap comes after it)
                    self._state = "failed"
                    self._discard()
            finally:
                self._lock.release()

    def _require_open(self) -> None:
        if self._state != "open":
            raise RuntimeError(f"output {self._kind} {str(self.target)!r} is not open for writing "
                               "(use it in a with block)")


# --------------------------------------------------------------------------------------
# OutputGroup
# --------------------------------------------------------------------------------------
class OutputGroup:
    """Commit several outputs of one run together, or none of them.

    Every :class:`OutputSet` and :class:`OutputFile` entered inside the block joins the
    group.  When its own ``with`` block ends, an output is put in place (so the run can
    read it back) but its old version is kept and its lock held; when the group's block
    ends normally, the old versions are dropped and the locks released in one step with
    SIGINT/SIGTERM held.  If the group's block ends with an exception (an error, a
    signal), every output already put in place is rolled back to its old version: the
    targets are as they were before the run.

    A ``SIGKILL`` between two outputs cannot be rolled back (the next run cleans the kept
    old versions up); SIGINT and SIGTERM can.

    Attributes
    ----------
    members : list
        The outputs that joined, in order.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     data, fig = Path(d) / "sweep.csv", Path(d) / "sweep.png"
    ...     try:
    ...         with OutputGroup():
    ...             with OutputFile(data) as f:
    ...                 _ = f.write_text("a\\n1\\n")
    ...             print(data.read_text().split())            # in place, readable
    ...             raise KeyboardInterrupt                    # before the figure
    ...     except KeyboardInterrupt:
    ...         pass
    ...     print(data.exists(), fig.exists())                 # neither was written
    ['a', '1']
    False False
    """

    def __init__(self) -> None:
        self.members: list[_Output] = []
        self._token: contextvars.Token[OutputGroup | None] | None = None

    def _join(self, output: _Output) -> None:
        self.members.append(output)

    def __enter__(self) -> OutputGroup:
        self._token = _GROUP.set(self)
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> Literal[False]:
        if self._token is not None:
            _GROUP.reset(self._token)
            self._token = None
        if exc is not None:
            self.abort(exc)
        else:
            self.commit()
        return False

    def commit(self) -> None:
        """Make every member final (members still open are aborted: their block never ended)."""
        try:
            with HeldSignals():
                for m in self.members:
                    if m._state == "swapped":
                        m._finish()
        finally:
            for m in self.members:
                if m._state in ("open", "swapped"):
                    m._abort(None)

    def abort(self, exc: BaseException | None = None) -> None:
        """Roll every member back to the old version of its target."""
        for m in reversed(self.members):
            m._abort(exc)


# --------------------------------------------------------------------------------------
# OutputSet
# --------------------------------------------------------------------------------------
class OutputSet(_Output):
    """Write a folder of outputs as one unit: the old set or the new set, never a mix.

    ::

        with OutputSet(out_dir, inputs=[raw_dir], producer="process") as out:
            out.write_json("summary.json", summary)
            ds.to_netcdf(out.path("curves.nc"))
        # here out_dir holds exactly the files written above plus manifest.json

    Files are written to a staging folder ``.<name>.bendpam-tmp-<pid>-<random>`` beside
    the target (same file system, so the final move is a rename).  On a normal exit
    ``manifest.json`` is added and the staging folder *replaces the target whole*.  On an
    exception -- including :class:`KeyboardInterrupt` and :class:`Interrupted` -- the
    staging folder is removed, the target is left exactly as it was and the exception
    propagates.

    An existing target is replaced only when it is empty, or a bendpam set of the same
    ``producer`` whose every file is listed in its manifest and unchanged.  Anything else
    (a folder with other content, a foreign ``manifest.json``, a file the manifest does
    not list or one changed since, a set of another producer) is refused with
    :class:`OutputRefused` naming the file; with ``force`` it is *moved aside* to
    ``<name>.moved-aside-<UTC time>`` (see :attr:`moved_aside`), never deleted.  The home
    folder, the current folder, the root, inputs and links to nothing are refused always.

    Parameters
    ----------
    target_dir : path
        The output folder (``~`` expanded).  Its parent folders are created if needed.
    inputs : iterable of paths, optional
        The files and folders the run reads.  The target may not be, lie inside or
        contain one of them; every input must exist, and one that is (or lies in) a
        bendpam set must match that set's manifest
        (:func:`~bendpam.infra.manifest.verify_input`).  They are listed, with size and
        sha256, in the manifest.
    command : str or sequence of str, optional
        The command line to record (default ``sys.argv``).
    lock_timeout_s : float, optional
        How long to wait for another run writing the same target; 0 refuses at once.
    force : bool, optional
        Replace a target that is not a set of this producer, moving it aside.
    producer : str, optional
        The name of what writes the set (a command name: ``"process"``); a set of one
        producer is not replaced by another without ``force``.
    resume_key : str, optional
        Make the set *resumable*: a fingerprint of the run's inputs and options.  The staging
        folder is then ``.<name>.bendpam-part`` beside the target and is *kept* when the block
        ends with an exception (an error, a signal); the next set entered on the same target
        with the same key reuses it (:attr:`resumed` is True and the files written so far are
        still there), while a set with another key, or without one, removes it under the lock.
        The key is kept in :attr:`resume_dir` (``.bendpam-resume/`` in the staging folder,
        where the writer may keep its own progress markers), which is removed before the
        manifest is written: the committed set is the same as one written in a single run.

    Raises
    ------
    OutputRefused
        On entering, for the refusals above (an :class:`~bendpam.errors.InputError`).
    OutputBusy
        On entering, when another run holds the target's lock.

    Attributes
    ----------
    target : Path
        The absolute target folder.
    staging : Path
        The staging folder being written (inside the ``with`` block).
    files : list of str
        The names given to :meth:`path` and the ``write_*`` methods, in order.
    manifest : dict or None
        The manifest written, once the set is complete.
    resumed : bool
        The staging folder was kept by an interrupted run with the same ``resume_key``.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     with OutputSet(Path(d) / "out", producer="demo", command=["demo"]) as out:
    ...         _ = out.write_text("a.txt", "a")
    ...     print(sorted(p.name for p in (Path(d) / "out").iterdir()), out.manifest["producer"])
    ['a.txt', 'manifest.json'] demo

    A resumable set keeps what an interrupted run wrote, for the next run with the same key:

    >>> with tempfile.TemporaryDirectory() as d:
    ...     try:
    ...         with OutputSet(Path(d) / "out", command=["demo"], resume_key="k1") as out:
    ...             _ = out.write_text("part-1.txt", "1")
    ...             raise KeyboardInterrupt
    ...     except KeyboardInterrupt:
    ...         pass
    ...     with OutputSet(Path(d) / "out", command=["demo"], resume_key="k1") as out:
    ...         print(out.resumed, sorted(p.name for p in out.staging.iterdir() if p.is_file()))
    ...         _ = out.write_text("part-2.txt", "2")
    ...     print(sorted(p.name for p in (Path(d) / "out").iterdir()))
    True ['part-1.txt']
    ['manifest.json', 'part-1.txt', 'part-2.txt']
    """

    _kind = "folder"

    def __init__(self, target_dir: str | os.PathLike[str], *, inputs: Iterable[str | os.PathLike[str]] = (),
                 command: str | Sequence[str] | None = None, lock_timeout_s: float = 0.0, force: bool = False,
                 producer: str | None = None, resume_key: str | None = None) -> None:
        super().__init__(target_dir, inputs=inputs, command=command, lock_timeout_s=lock_timeout_s, force=force)
        self.producer = producer
        if resume_key is not None and (not isinstance(resume_key, str) or not resume_key
                                       or not resume_key.isprintable()):
            raise InputError(f"resume_key = {resume_key!r} must be a non-empty printable string")
        self.resume_key = resume_key
        self.resumed = False
        self.files: list[str] = []
        self.manifest: dict[str, Any] | None = None
        self._staging: Path | None = None
        self._inputs_resolved: list[Path] = []
        self._started = ""
        self._aside: Path | None = None

    # -- entering ----------------------------------------------------------------------
    def _check_target(self) -> None:
        t = self.target
        if os.path.lexists(t) and not t.is_dir():
            raise OutputRefused(f"output folder {self.shown!r} exists and is not a folder")
        check_not_precious(t, self.shown)

    def _check_replaceable(self) -> None:
        if not self.target.is_dir():
            return
        problem = ownership_problem(self.target, self.producer, self.shown)
        if problem is None:
            return
        reason = f"output folder {self.shown!r} not replaced: {problem[0]}"
        if not self.force:
            raise OutputRefused(f"{reason}; choose another folder, or force the replacement (the old folder is "
                                "then moved aside, not deleted)", forceable=True, reason=reason)
        self._aside = _aside_name(self.target)

    def _prepare(self) -> None:
        self._started = now_utc()
        resolved = resolve_inputs(self.inputs)
        self._inputs_resolved = [r for _, r in resolved]
        check_against_inputs(self.target, self.shown, resolved, "folder")
        for _, r in resolved:
            verify_input(r)  # a set read back must match its manifest
        self._check_target()
        try:
            self.target.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise InputError(f"cannot create the folder {str(self.target.parent)!r}: {exc.strerror or exc}") from exc

    def _open(self) -> None:
        fsops.restore_or_remove_stale(self.target)
        self._check_target()  # again, under the lock
        self._check_replaceable()
        part = self.target.parent / fsops.part_name(self.target.name)
        with HeldSignals():
            if self.resume_key is None:
                if os.path.lexists(part):  # an interrupted resumable run of another command
                    fsops.remove_path(part)
                self._staging = Path(tempfile.mkdtemp(prefix=f".{self.target.name}.bendpam-tmp-{os.getpid()}-",
                                                      dir=self.target.parent))
                return
            self.resumed = _resume_key_of(part) == self.resume_key
            if not self.resumed:
                fsops.remove_path(part)
                (part / RESUME_DIR).mkdir(parents=True)
                key_file = part / RESUME_DIR / "key"
                key_file.write_text(self.resume_key, encoding="utf-8")
            self._staging = part

    @property
    def resume_dir(self) -> Path:
        """The folder of a resumable set's own state (its key, the writer's markers); removed before the commit."""
        if self.resume_key is None:
            raise RuntimeError("resume_dir is kept only by a set with a resume_key")
        return self.staging / RESUME_DIR

    def __enter__(self) -> OutputSet:
        return self._enter()

    # -- writing -----------------------------------------------------------------------
    @property
    def staging(self) -> Path:
        """The staging folder (inside the ``with`` block only)."""
        self._require_open()
        assert self._staging is not None
        return self._staging

    def path(self, name: str | os.PathLike[str]) -> Path:
        """The staging path of output ``name`` (recorded; parent folders created).

        ``name`` is relative, may contain subfolders (``"figures/fig4.png"``) and may
        not contain ``..``; ``manifest.json`` is reserved.  Write the file there (any
        writer will do); it is moved into the target with the rest of the set.
        """
        self._require_open()
        rel = self._check_name(name)
        p = self.staging.joinpath(*rel.parts)
        p.parent.mkdir(parents=True, exist_ok=True)
        key = rel.as_posix()
        if key not in self.files:
            self.files.append(key)
        return p

    def _check_name(self, name: str | os.PathLike[str]) -> PurePath:
        text = os.fspath(name)
        if not isinstance(text, str):
            raise TypeError("output names are str or os.PathLike[str]")
        rel = PurePath(text)
        parts = [p for p in rel.parts if p != "."]
        if not text or "\0" in text or rel.is_absolute() or rel.anchor or not parts:
            raise InputError(f"output name {text!r} is not a relative file name inside the output folder")
        if ".." in parts:
            raise InputError(f"output name {text!r} contains '..'; names must stay inside the output folder")
        rel = PurePath(*parts)
        if rel.as_posix() == MANIFEST_NAME:
            raise InputError(f"output name {MANIFEST_NAME!r} is reserved for the manifest")
        return rel

    def write_text(self, name: str | os.PathLike[str], text: str, *, encoding: str = "utf-8") -> Path:
        """Write ``text`` to output ``name``; returns the staging path."""
        p = self.path(name)
        p.write_text(text, encoding=encoding)
        return p

    def write_bytes(self, name: str | os.PathLike[str], data: bytes) -> Path:
        """Write ``data`` to output ``name``; returns the staging path."""
        p = self.path(name)
        p.write_bytes(data)
        return p

    def write_json(self, name: str | os.PathLike[str], obj: Any, *, indent: int | None = 2) -> Path:
        """Write ``obj`` as strict JSON (see :func:`to_json`; NaN becomes null, +-inf "inf"/"-inf")."""
        return self.write_text(name, to_json(obj, indent=indent))

    # -- leaving -----------------------------------------------------------------------
    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> Literal[False]:
        """Commit the set on success, else remove the staging folder; never swallows.

        The commit hashes every file (flushing it to disk), writes ``manifest.json`` and
        moves the set into place (:func:`bendpam.infra.fsops.swap_in`: one
        ``renameat2(RENAME_EXCHANGE)`` on Linux, two renames with recovery elsewhere),
        then removes the old set -- or, for a forced replacement, leaves it moved aside.
        """
        return self._exit(exc)

    def _stage(self) -> None:
        staging = self.staging
        if self.resume_key is not None:
            fsops.remove_path(staging / RESUME_DIR)  # the committed set is as one written in one run
        manifest = build_manifest(staging, producer=self.producer, command=self.command, target=self.target,
                                  inputs=self._inputs_resolved, started_utc=self._started)
        (staging / MANIFEST_NAME).write_text(to_json(manifest), encoding="utf-8")
        fsops.fsync_file(staging / MANIFEST_NAME)
        for dirpath, _, _ in os.walk(staging, topdown=False):
            fsops.fsync_dir(Path(dirpath))
        try:
            mode = self.target.stat().st_mode & 0o7777 if self.target.is_dir() else 0o777 & ~UMASK
        except OSError:
            mode = 0o777 & ~UMASK
        os.chmod(staging, mode)
        self.manifest = manifest

    def _swap(self) -> None:
        staging = self.staging
        if self._aside is not None and os.path.lexists(self.target):
            os.rename(self.target, self._aside)  # the user's content: visible, never cleaned up
            self.moved_aside = self._aside
            try:
                os.rename(staging, self.target)
            except BaseException:
                os.rename(self._aside, self.target)
                self.moved_aside = None
                raise
            self._old = self._aside
        else:
            self._old = fsops.swap_in(staging, self.target)

    def _roll_back(self) -> None:
        assert self._staging is not None
        fsops.swap_back(self.target, self._old, self._staging)
        self._old = None
        self.moved_aside = None

    def _discard(self) -> None:
        staging, self._staging = self._staging, None
        if staging is not None and not (self.resume_key is not None and (staging / RESUME_DIR).is_dir()):
            fsops.remove_path(staging)  # (a resumable set keeps its staging folder for the next run)

    def _finish(self) -> None:
        self._staging = None
        super()._finish()


#: The folder of a resumable set's own state inside its staging folder (see ``OutputSet(resume_key=...)``).
RESUME_DIR = ".bendpam-resume"


def _resume_key_of(part: Path) -> str | None:
    """The key of a kept staging folder, or None (none there, or unreadable: it is then started afresh)."""
    try:
        if part.is_symlink() or not part.is_dir():
            return None
        return (part / RESUME_DIR / "key").read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return None


# --------------------------------------------------------------------------------------
# OutputFile
# --------------------------------------------------------------------------------------
class OutputFile(_Output):
    """Write one output file all-or-nothing, under the same lock as :class:`OutputSet`.

    ::

        with OutputFile(out, inputs=[raw_dir]) as o:
            fig.savefig(o.path)        # a temporary file beside ``out``, same suffix
        # ``out`` is replaced in one os.replace

    The temporary file ``.<name>.bendpam-tmp-<pid>-<random><suffix>`` keeps the target's
    suffix so that writers choosing a format from the extension still work.  On success
    it is flushed and renamed onto the target (keeping the old file's permissions); on
    an exception it is removed, the target is untouched and the exception propagates.
    No manifest is written for a single file.

    Parameters
    ----------
    target_path : path
        The output file (``~`` expanded).  Its folder must exist.
    inputs : iterable of paths, optional
        Files and folders the run reads; the target may not be one of them nor lie
        inside an input folder.
    command : str or sequence of str, optional
        Kept as :attr:`command` for the caller's use (nothing is recorded on disk).
    lock_timeout_s : float, optional
        How long to wait for another run writing the same file; 0 refuses at once.
    force : bool, optional
        Write the file into a folder that is a bendpam output set (refused otherwise: the
        set would no longer match its manifest).

    Raises
    ------
    OutputRefused
        On entering: the target is or lies inside an input, is an existing folder, its
        folder does not exist, or is a bendpam output set.
    OutputBusy
        On entering, when another run holds the target's lock.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     with OutputFile(Path(d) / "curves.csv") as f:
    ...         _ = f.write_text("a,b\\n1,2\\n")
    ...     print((Path(d) / "curves.csv").read_text().split())
    ['a,b', '1,2']
    """

    _kind = "file"

    def __init__(self, target_path: str | os.PathLike[str], *, inputs: Iterable[str | os.PathLike[str]] = (),
                 command: str | Sequence[str] | None = None, lock_timeout_s: float = 0.0,
                 force: bool = False) -> None:
        super().__init__(target_path, inputs=inputs, command=command, lock_timeout_s=lock_timeout_s, force=force)
        self._tmp: Path | None = None
        self._foreign = False  # the target exists and bendpam did not write it

    def _prepare(self) -> None:
        t, shown = self.target, self.shown
        resolved = resolve_inputs(self.inputs)
        check_against_inputs(t, shown, resolved, "file")
        for _, r in resolved:
            verify_input(r)  # a set read back must match its manifest
        if t.is_dir():
            raise OutputRefused(f"output file {shown!r} is an existing folder")
        if not t.parent.is_dir():
            raise OutputRefused(f"output folder {str(self._given.parent)!r} does not exist (for {shown!r})")
        if not self.force and (t.parent / MANIFEST_NAME).is_file():
            try:
                in_set = read_manifest(t.parent) is not None
            except InputError:
                in_set = False
            if in_set:
                reason = (f"output file {shown!r} would go into the bendpam output set {str(t.parent)!r}, "
                          f"which would then no longer match its {MANIFEST_NAME}")
                raise OutputRefused(f"{reason}; choose another folder", forceable=True, reason=reason)

    def _open(self) -> None:
        # under the lock (a second write of the same target in one run is refused by the lock first)
        t, shown = self.target, self.shown
        self._foreign = t.is_file() and not written_by_bendpam(t)
        if self._foreign and not self.force:
            reason = f"output file {shown!r} exists and is not a file bendpam wrote (or it was changed since)"
            raise OutputRefused(f"{reason}; choose another name", forceable=True, reason=reason)
        for _, stale in fsops.stale_temporaries(self.target.parent, self.target.name):
            fsops.remove_path(stale)
        self._tmp = self.target.parent / fsops.temp_name(self.target.name, "tmp", self.target.suffix)

    def __enter__(self) -> OutputFile:
        return self._enter()

    @property
    def path(self) -> Path:
        """The temporary path to write (it becomes the target on success)."""
        self._require_open()
        assert self._tmp is not None
        return self._tmp

    def write_text(self, text: str, *, encoding: str = "utf-8") -> Path:
        """Write ``text`` to the temporary file; returns its path."""
        self.path.write_text(text, encoding=encoding)
        return self.path

    def write_bytes(self, data: bytes) -> Path:
        """Write ``data`` to the temporary file; returns its path."""
        self.path.write_bytes(data)
        return self.path

    def write_json(self, obj: Any, *, indent: int | None = 2) -> Path:
        """Write ``obj`` as strict JSON (see :func:`to_json`)."""
        return self.write_text(to_json(obj, indent=indent))

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> Literal[False]:
        """Rename the temporary file onto the target on success; otherwise remove it."""
        return self._exit(exc)

    def _stage(self) -> None:
        tmp = self.path
        if not tmp.is_file():
            raise RuntimeError(f"nothing was written for {str(self.target)!r} (expected a file at {str(tmp)!r})")
        fsops.fsync_file(tmp)
        try:
            mode = self.target.stat().st_mode & 0o7777
        except OSError:
            mode = 0o666 & ~UMASK
        os.chmod(tmp, mode)

    def _swap(self) -> None:
        tmp, target = self.path, self.target
        if self._foreign:  # forced over a file bendpam did not write: keep it, moved aside
            aside = _aside_name(target)
            os.rename(target, aside)
            self._old = self.moved_aside = aside
        elif self._group is not None and os.path.lexists(target):
            # keep the old file until the group ends (a hard link: the target never disappears)
            old = target.parent / fsops.temp_name(target.name, "old", target.suffix)
            try:
                os.link(target, old)
            except OSError:
                shutil.copy2(target, old)
            self._old = old
        os.replace(tmp, target)
        fsops.fsync_dir(target.parent)

    def _roll_back(self) -> None:
        old, self._old = self._old, None
        if old is not None:
            os.replace(old, self.target)
        else:
            self.target.unlink(missing_ok=True)
        fsops.fsync_dir(self.target.parent)

    def _discard(self) -> None:
        tmp, self._tmp = self._tmp, None
        if tmp is not None:
            fsops.remove_path(tmp)
            for _, nested in fsops.stale_temporaries(tmp.parent, tmp.name):  # a writer's own temporaries
                fsops.remove_path(nested)

    def _finish(self) -> None:
        self._tmp = None
        try:
            record_file(self.target, producer=" ".join(self.command[:2]) or None)
        except OSError:  # the file is in place; without its record a later run asks for force (safe)
            pass
        super()._finish()
