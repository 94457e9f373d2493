"""Which single files in a folder bendpam wrote: the folder's ``.bendpam-files.json``.

An output set carries its own manifest; a single output file (``--out actuator.toml``,
``--plot sweep.png``, ``report.html``) cannot.  So that bendpam never overwrites a file it did
not write (a hand-edited actuator file, a figure a user made), every single file bendpam writes
is recorded, with its size and sha256, in a small registry beside it.  A later run may replace
the file only while it is still exactly what bendpam wrote; otherwise the replacement is refused
(and, when forced, the old file is moved aside, never deleted).

The registry is advisory and safe when wrong: a lost or damaged registry makes bendpam refuse to
overwrite (the user decides with ``force``), never overwrite something it should not.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

from bendpam.infra import fsops
from bendpam.infra.atomic import atomic_write_text

__all__ = ["REGISTRY_FORMAT", "REGISTRY_NAME", "record_file", "written_by_bendpam"]

#: The registry's file name (hidden: it is bookkeeping, not an output).
REGISTRY_NAME = ".bendpam-files.json"
#: Its format marker.
REGISTRY_FORMAT = "bendpam-file-registry"


def _entries(folder: Path) -> dict[str, Any]:
    try:
        data = json.loads((folder / REGISTRY_NAME).read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError):
        return {}
    if not isinstance(data, dict) or data.get("format") != REGISTRY_FORMAT or not isinstance(data.get("files"), dict):
        return {}
    return data["files"]


def written_by_bendpam(path: str | os.PathLike[str]) -> bool:
    """True when ``path`` is a file that bendpam wrote and nobody has changed since (size and sha256).

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = Path(d) / "a.toml"
    ...     _ = p.write_text("x = 1\\n")
    ...     before = written_by_bendpam(p)            # the user's file
    ...     record_file(p, producer="actuator")
    ...     after = written_by_bendpam(p)
    ...     _ = p.write_text("x = 2\\n")               # edited by hand since
    ...     edited = written_by_bendpam(p)
    >>> before, after, edited
    (False, True, False)
    """
    p = Path(path)
    entry = _entries(p.parent).get(p.name)
    if not isinstance(entry, dict) or not p.is_file():
        return False
    try:
        size, digest = fsops.hash_file(p)
    except OSError:
        return False
    return entry.get("size") == size and entry.get("sha256") == digest


def record_file(path: str | os.PathLike[str], *, producer: str | None = None) -> None:
    """Record ``path`` (as it is now) in its folder's registry as written by bendpam.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = Path(d) / "fig.png"
    ...     _ = p.write_bytes(b"png")
    ...     record_file(p, producer="sweep")
    ...     sorted(json.loads((Path(d) / REGISTRY_NAME).read_text())["files"])
    ['fig.png']
    """
    p = Path(path)
    files = dict(_entries(p.parent))
    size, digest = fsops.hash_file(p)
    files[p.name] = {"size": size, "sha256": digest, "producer": producer}
    text = json.dumps({"format": REGISTRY_FORMAT, "format_version": 1, "files": files}, indent=1, sort_keys=True)
    atomic_write_text(p.parent / REGISTRY_NAME, text + "\n")
