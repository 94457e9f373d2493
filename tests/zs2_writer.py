"""A small, independent ENCODER of Zwick ``.zs2`` streams, for tests.

Written from the published description of the format (zs2decode's documentation, "The zs2 file
format"), not from any decoder: a gzip-compressed data stream that starts with the signature
``0xDEADBEAF`` (little endian), followed by chunks.  A chunk is a name (one length byte, then
ASCII), a data-type byte and data; a section starts with a chunk of type ``0xDD`` (data: an ASCII
string, usually empty) and ends with the single byte ``0xFF``.  Numbers are little endian:
``0x66`` a 2-byte integer, ``0x11`` a 4-byte integer, ``0xCC`` a double; ``0xAA`` a unicode
string (4-byte length in characters with bit 31 set, then UTF-16-LE); ``0xEE`` a list (2-byte
sub-type, 4-byte count, items: sub-type 4 single floats, 5 double floats, 0x11 the bytes of a
record).  Lists of sections are a ``Count`` chunk followed by ``Elem0``, ``Elem1``, ...

:func:`series` builds the part of a testXpert series file that the reader needs: the channel
list of the test program and one ``SeriesElements`` entry per specimen with its name (parameter
48154, a ``QS_TextPar`` record) and its measured ``DataChannels``.
"""

from __future__ import annotations

import gzip
import struct
from collections.abc import Sequence

import numpy as np

SPECIMEN_NAME_ID = 48154


def _name(name: str) -> bytes:
    raw = name.encode("ascii")
    assert 0 < len(raw) < 255
    return bytes([len(raw)]) + raw


def ustr(text: str) -> bytes:
    """A unicode string: length in UTF-16 code units with bit 31 set, then UTF-16-LE."""
    raw = text.encode("utf-16-le")
    return struct.pack("<I", (len(raw) // 2) | 0x80000000) + raw


def section(name: str, *body: bytes, descriptor: str = "") -> bytes:
    d = descriptor.encode("ascii")
    return _name(name) + b"\xdd" + bytes([len(d)]) + d + b"".join(body) + b"\xff"


def word(name: str, value: int) -> bytes:
    return _name(name) + b"\x66" + struct.pack("<H", value)


def long(name: str, value: int) -> bytes:
    return _name(name) + b"\x11" + struct.pack("<i", value)


def text(name: str, value: str) -> bytes:
    return _name(name) + b"\xaa" + ustr(value)


def floats(name: str, values: np.ndarray, double: bool = False) -> bytes:
    arr = np.asarray(values, dtype="<f8" if double else "<f4")
    return _name(name) + b"\xee" + struct.pack("<HI", 5 if double else 4, len(arr)) + arr.tobytes()


def record(name: str, payload: bytes) -> bytes:
    return _name(name) + b"\xee" + struct.pack("<HI", 0x11, len(payload)) + payload


def chunk_list(name: str, items: Sequence[bytes]) -> bytes:
    """A section holding ``Count`` and one ``ElemK`` section per item (each item: the Elem's body)."""
    elems = [section(f"Elem{k}", body) for k, body in enumerate(items)]
    return section(name, long("Count", len(items)), *elems)


def specimen(name: str | None, channels: Sequence[tuple[int, np.ndarray]], time_index: int | None = 0,
             double: bool = False) -> bytes:
    """The body of one ``SeriesElements`` entry: its name parameter and its measured channels."""
    params = []
    if name is not None:
        params.append(word("ID", SPECIMEN_NAME_ID)
                      + record("QS_TextPar", b"\x01" + ustr(name) + ustr("de") + ustr("") + ustr("")))
    params.append(word("ID", 1234) + long("Wert", 7))
    data = [long("TrsChannelId", cid) + floats("DataArray", arr, double) for cid, arr in channels]
    block_parts = [chunk_list("DataChannels", data)]
    if time_index is not None:
        block_parts.insert(0, long("IndexTimeChannel", time_index))
    block = section("SingleGroupDataBlock", *block_parts)
    capture = section("RealTimeCapture", section("Trs", block))
    return (section("EvalContext", section("ParamContext", chunk_list("ParameterListe", params)))
            + chunk_list("SeriesElements", [capture]))


def series(channel_names: dict[int, str], specimens: Sequence[bytes], *, with_channels: bool = True) -> bytes:
    """A whole ``.zs2`` file (gzip-compressed bytes)."""
    chans = [word("ID", cid) + section("Name", text("Text", name)) for cid, name in channel_names.items()]
    manager = section("ChannelManager", chunk_list("ChannelManager", chans))
    task = section("Elem0", manager) if with_channels else section("Elem0", long("Leer", 0))
    series_def = section("SeriesDef", section("TestTaskDefs", long("Count", 1), task))
    body = section("Body", section("batch", series_def, section("Series", chunk_list("SeriesElements", specimens))))
    header = section("Header", text("Name", "bendpam test series"))
    stream = struct.pack("<I", 0xDEADBEAF) + section("Document", header, body)
    return gzip.compress(stream, mtime=0)
