"""Native Zwick testXpert ``.zs2`` and ``.zp2`` files, read through ``zs2decode`` (extra ``zwick``).

A ``.zs2`` file is a gzip-compressed stream of *chunks* that form a tree of sections (the format
as documented by zs2decode, "The zs2 file format"): a 4-byte signature ``0xDEADBEAF``, then
chunks, each a named value or the start (data type ``0xDD``) or end (``0xFF``) of a section.
``zs2decode`` splits the stream into chunks; this module builds the tree and takes from it

* the channel list of the test program (``ChannelManager``: each channel's ``ID`` and ``Name``),
* the series of specimens (``Body/batch/Series/SeriesElements``: one ``Elem`` per specimen, named by
  its parameter 48154, the specimen name, as zs2decode's example reads it), and
* for each specimen its measured channels (``SingleGroupDataBlock``: ``IndexTimeChannel`` and
  ``DataChannels``, each a ``TrsChannelId`` and a ``DataArray`` of single or double floats).

testXpert stores values in SI base units (s, m, N; the display units are factors of these in the
file's unit tables): each specimen is handed to the reader as a table whose units row says so, and
the usual channel classification (:mod:`bendpam.lab.channels`) picks time, crosshead travel and
standard force and converts them to s, mm, N.  A file whose tree lacks one of these parts is
refused in one line naming the part.  Specimens without measured data (created in the series but
not tested) are left out and listed in the metadata.
"""

from __future__ import annotations

import os
import re
import zlib
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from bendpam.lab.channels import ColumnInfo, classify_column
from bendpam.lab.read_error import ReadError

__all__ = ["ZS2_SUFFIXES", "ZWICK_EXTRA_HINT", "Zs2Specimen", "read_zs2", "zs2_sheets"]

#: File name endings of native testXpert files.
ZS2_SUFFIXES: tuple[str, str] = (".zs2", ".zp2")
#: How to get the optional decoder.
ZWICK_EXTRA_HINT = "install the optional package zs2decode (pip install 'bendpam[zwick]')"

_SPECIMEN_NAME_ID = 48154  # parameter ID of the specimen name in testXpert II series
_SI_UNIT = {"time": "s", "stroke": "m", "force": "N"}
_ELEM = re.compile(r"Elem(\d+)")
_cache: dict[tuple[str, int, int], list[Zs2Specimen]] = {}


@dataclass
class Zs2Specimen:
    """The measured channels of one specimen of a ``.zs2`` series.

    Attributes
    ----------
    name : str
        The specimen's name (``"specimen k"`` when the series gives none).
    channels : list of (str, numpy.ndarray)
        Channel name and values as stored (SI base units; single or double floats as in the
        file), in the file's order.
    time_channel : int or None
        Index in :attr:`channels` of the channel the file marks as its time base.
    notes : list of str
        What was odd (other data blocks, unnamed channels).

    Examples
    --------
    >>> import numpy as np
    >>> s = Zs2Specimen("P1", [("Prüfzeit", np.array([0.0, 0.1])), ("Standardkraft", np.array([1.0, 2.0]))], 0)
    >>> s.name, len(s), s.time_channel
    ('P1', 2, 0)
    """

    name: str
    channels: list[tuple[str, np.ndarray]]
    time_channel: int | None = None
    notes: list[str] = field(default_factory=list)

    def __len__(self) -> int:
        return len(self.channels[0][1]) if self.channels else 0


class _Node:
    __slots__ = ("children", "kind", "name", "value")

    def __init__(self, name: str, kind: str, value: Any) -> None:
        self.name, self.kind, self.value = name, kind, value
        self.children: list[_Node] = []

    def child(self, name: str) -> _Node | None:
        return next((c for c in self.children if c.name == name), None)

    def path(self, *names: str) -> _Node | None:
        node: _Node | None = self
        for n in names:
            node = node.child(n) if node is not None else None
        return node

    def elems(self) -> list[_Node]:
        return [c for c in self.children if _ELEM.fullmatch(c.name)]

    def find_all(self, name: str) -> list[_Node]:
        out, stack = [], [self]
        while stack:
            node = stack.pop()
            if node.name == name and node is not self:
                out.append(node)
            stack.extend(reversed(node.children))
        return out


def _decode(path: Path) -> _Node:
    try:
        from zs2decode import parser as zs2parser
    except ImportError:
        raise ReadError(f"native Zwick .zs2 file: reading it needs zs2decode; {ZWICK_EXTRA_HINT}, or export "
                        "the test as ASCII (TXT/TRA) from testXpert", path) from None  # fmt: skip
    try:
        stream = zs2parser.load(str(path))
    except ValueError as exc:
        raise ReadError(f"not a native Zwick .zs2/.zp2 file ({exc}); expected a file written by testXpert",
                        path) from None  # fmt: skip
    except (OSError, EOFError, zlib.error) as exc:
        raise ReadError(f"native Zwick .zs2 file with a broken gzip stream ({exc}); expected a file written "
                        "by testXpert", path) from None  # fmt: skip
    try:
        chunks = zs2parser.parse_chunks(zs2parser.data_stream_to_chunks(stream), level=1)
    except Exception as exc:  # zs2decode raises bare errors on a stream it cannot split
        raise ReadError("native Zwick .zs2 file whose chunk stream could not be decoded "
                        f"({type(exc).__name__}: {exc}); "
                        "expected a file written by testXpert", path) from None  # fmt: skip
    return _tree(chunks, path)


def _tree(chunks: list[list[Any]], path: Path) -> _Node:
    root = _Node("", "root", None)
    stack = [root]
    for _address, name, kind, value in chunks:
        if kind == "end":
            if len(stack) == 1:
                raise ReadError("native Zwick .zs2 file whose chunk stream ends more sections than it starts; "
                                "expected a file written by testXpert", path)  # fmt: skip
            stack.pop()
            continue
        node = _Node(name, kind, value)
        stack[-1].children.append(node)
        if kind == "DD":
            stack.append(node)
    if not root.children:
        raise ReadError("native Zwick .zs2 file without sections; expected a file written by testXpert", path)
    return root.children[0]


def _number(node: _Node | None) -> int | None:
    if node is None or isinstance(node.value, (bytes, bytearray, list, str)) or node.value is None:
        return None
    return int(node.value)


def _text(node: _Node | None) -> str | None:
    """A name: a string chunk, or a section holding one (``Name/Text``)."""
    if node is None:
        return None
    if isinstance(node.value, str) and node.kind in ("AA", "00"):
        return node.value
    for c in node.children:
        if c.kind in ("AA", "00") and isinstance(c.value, str):
            return c.value
    return None


def _array(node: _Node) -> np.ndarray | None:
    """A ``DataArray`` chunk (data type 0xEE, sub-type 4: single, 5: double floats), in its own precision."""
    raw = node.value
    if node.kind != "EE" or not isinstance(raw, (bytes, bytearray)) or len(raw) < 6:
        return None
    sub = int.from_bytes(raw[0:2], "little")
    n = int.from_bytes(raw[2:6], "little")
    dtype = {4: "<f4", 5: "<f8"}.get(sub)
    if dtype is None:
        return np.empty(0) if sub == 0 else None
    if len(raw) != 6 + n * np.dtype(dtype).itemsize:
        return None
    return np.frombuffer(bytes(raw), dtype=dtype, count=n, offset=6).astype(dtype[1:])


def _first_string(record: Any) -> str | None:
    """The first unicode string of a ``QS_TextPar`` record (0xEE sub-type 0x11: byte 1, then strings)."""
    if not isinstance(record, (bytes, bytearray)) or len(record) < 11:
        return None
    body = bytes(record[6:])
    n = int.from_bytes(body[1:5], "little")
    if not n & 0x80000000:
        return None
    n &= 0x7FFFFFFF
    text = body[5:5 + 2 * n]
    return text.decode("utf-16-le", errors="replace") if len(text) == 2 * n else None


def _channel_names(root: _Node, path: Path) -> dict[int, str]:
    names: dict[int, str] = {}
    for manager in root.find_all("ChannelManager"):
        for elem in manager.elems():
            cid, name = _number(elem.child("ID")), _text(elem.child("Name"))
            if cid is not None and name is not None:
                names.setdefault(cid, name)
    if not names:
        raise ReadError("native Zwick .zs2 file of a layout not recognised: no channel list (ChannelManager "
                        "entries with ID and Name); expected a testXpert series file", path)  # fmt: skip
    return names


def _specimen_name(elem: _Node, k: int) -> str:
    for params in elem.find_all("ParameterListe"):
        for p in params.elems():
            if _number(p.child("ID")) == _SPECIMEN_NAME_ID:
                name = _first_string(getattr(p.child("QS_TextPar"), "value", None))
                if name and name.strip():
                    return name.strip()
    return f"specimen {k + 1}"


def _block(block: _Node, names: dict[int, str], label: str, path: Path) -> Zs2Specimen | None:
    channels: list[tuple[str, np.ndarray]] = []
    data = block.child("DataChannels")
    for ch in data.elems() if data is not None else []:
        cid, arr_node = _number(ch.child("TrsChannelId")), ch.child("DataArray")
        if arr_node is None:
            continue
        arr = _array(arr_node)
        if arr is None:
            raise ReadError(f"native Zwick .zs2 file, specimen {label!r}: a DataArray that is not a list of "
                            "single or double floats (or whose length does not match its count)", path)  # fmt: skip
        channels.append((names.get(cid, f"channel {cid}") if cid is not None else "channel ?", arr))
    lengths = {len(a) for _n, a in channels}
    if not channels or lengths == {0}:
        return None
    if len(lengths) > 1:
        shown = ", ".join(f"{n}: {len(a)}" for n, a in channels)
        raise ReadError(f"native Zwick .zs2 file, specimen {label!r}: its channels have unequal lengths "
                        f"({shown}); the samples cannot be aligned", path)  # fmt: skip
    index = _number(block.child("IndexTimeChannel"))
    time_channel = index if index is not None and 0 <= index < len(channels) else None
    return Zs2Specimen(label, channels, time_channel)


def _specimens(root: _Node, path: Path) -> list[Zs2Specimen]:
    names = _channel_names(root, path)
    series = root.path("Body", "batch", "Series", "SeriesElements")
    groups = ([(_specimen_name(e, k), e) for k, e in enumerate(series.elems())] if series is not None
              else [(f"data group {k + 1}", b) for k, b in enumerate(root.find_all("SingleGroupDataBlock"))])
    out, empty = [], []
    for label, node in groups:
        blocks = [node] if node.name == "SingleGroupDataBlock" else node.find_all("SingleGroupDataBlock")
        found = [s for s in (_block(b, names, label, path) for b in blocks) if s is not None]
        if not found:
            empty.append(label)
            continue
        spec = max(found, key=len)
        if len(found) > 1:
            spec.notes.append(f"{len(found)} data blocks; the longest ({len(spec)} samples) is read")
        out.append(spec)
    if not out:
        what = f"its {len(groups)} specimen(s) hold" if groups else "it holds"
        raise ReadError(f"native Zwick .zs2 file with no measured data: {what} no SingleGroupDataBlock with "
                        "DataChannels; expected a series with at least one tested specimen", path)  # fmt: skip
    seen: dict[str, int] = {}
    for spec in out:
        n = seen[spec.name] = seen.get(spec.name, 0) + 1
        if n > 1:
            spec.name = f"{spec.name} ({n})"
    if empty:
        out[0].notes.append(f"specimens without measured data left out: {', '.join(empty)}")
    return out


def read_zs2(path: str | os.PathLike) -> list[Zs2Specimen]:
    """The specimens of a native Zwick ``.zs2``/``.zp2`` file with measured data, in series order.

    Parameters
    ----------
    path : str or os.PathLike
        The file.

    Returns
    -------
    list of Zs2Specimen
        One per tested specimen; values as stored (SI base units).

    Raises
    ------
    ReadError
        One line naming the file: zs2decode missing, not a ``.zs2`` stream, or the part of the
        layout that was not found.

    Examples
    --------
    >>> import gzip, tempfile
    >>> from pathlib import Path
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = Path(folder) / "series.zs2"
    ...     _ = path.write_bytes(gzip.compress(b"not a testXpert stream"))
    ...     try:
    ...         read_zs2(path)
    ...     except ReadError as exc:
    ...         print(exc.message.split(" (")[0])
    not a native Zwick .zs2/.zp2 file
    """
    p = Path(path)
    try:
        st = p.stat()
    except OSError as exc:
        raise ReadError(f"cannot read the file ({exc.strerror or exc})", p) from None
    key = (str(p.resolve()), st.st_mtime_ns, st.st_size)
    if key not in _cache:
        specimens = _specimens(_decode(p), p)
        _cache.clear()  # one file at a time: read_tests reads each specimen of the same file in turn
        _cache[key] = specimens
    return _cache[key]


def _role(name: str) -> str | None:
    cands = [c for c in classify_column(ColumnInfo(0, name, name, None)) if c.role in _SI_UNIT]
    return max(cands, key=lambda c: c.rank).role if cands else None


def _cell(name: str) -> str:
    return re.sub(r"[\t\r\n]+", " ", name).strip() or "?"


def _lines(spec: Zs2Specimen) -> list[str]:
    units = []
    for k, (name, _a) in enumerate(spec.channels):
        role = "time" if k == spec.time_channel else _role(name)
        units.append(_SI_UNIT.get(role or "", "-"))
    head = [f"Specimen\t{_cell(spec.name)}",
            "Values\tas stored by testXpert, in SI base units (s, m, N)"]  # fmt: skip
    head += [f"Note\t{_cell(note)}" for note in spec.notes]
    head += ["\t".join(_cell(n) for n, _a in spec.channels), "\t".join(units)]
    return head + ["\t".join(row) for row in zip(*(_texts(a) for _n, a in spec.channels), strict=True)]


def _texts(values: np.ndarray) -> list[str]:
    """Each value as text that reads back to the stored value: 9 significant digits for a single float."""
    if values.dtype == np.float32:
        return list(map("{:.9g}".format, values.astype(np.float64).tolist()))
    return list(map(repr, values.astype(np.float64).tolist()))


class _Lines:
    """The lines of one specimen's table, written only when they are read (a series holds many specimens)."""

    def __init__(self, spec: Zs2Specimen) -> None:
        self.spec = spec
        self.first = f"Specimen\t{_cell(spec.name)}"

    def __iter__(self) -> Iterator[str]:
        return iter(_lines(self.spec))


def zs2_sheets(path: str | os.PathLike) -> list[tuple[str, Iterable[str]]]:
    """Each tested specimen of a ``.zs2`` file as ``(name, lines)``: a tab-separated table the reader reads.

    The lines are a ``Specimen`` line, a note that values are SI base units, a names row, a units
    row (``s``, ``m``, ``N`` for the channels that can be time, travel or force; ``-`` for the
    others) and one row per sample, every value written so that it reads back to the stored value
    (a single float with its 9 significant digits, a double exactly).  They are
    written when iterated, so reading one specimen does not write the others.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = Path(folder) / "series.zs2"
    ...     _ = path.write_bytes(b"")
    ...     try:
    ...         zs2_sheets(path)
    ...     except ReadError as exc:
    ...         print(exc.message.startswith("not a"))
    True
    """
    return [(spec.name, _Lines(spec)) for spec in read_zs2(path)]
