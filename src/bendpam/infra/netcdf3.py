"""NetCDF-3 files (the classic and 64-bit offset formats) read with NumPy alone.

bendpam writes its ``curves.nc`` through xarray's SciPy backend, in the NetCDF-3 64-bit offset
format.  Reading one back with :func:`read_netcdf3` spares ``bendpam fit`` importing xarray and
pandas, and :mod:`scipy.io` (whose package imports SciPy's sparse matrices and MATLAB readers, a
few tens of milliseconds for one small file).  The layout follows the format specification
(NetCDF Users Guide, "File Format Specifications"): a header of dimensions, global attributes and
variables, then each variable's values, big-endian; record variables (along the unlimited
dimension) are read too.  The values come back raw, as the file stores them, in native byte order:
no CF decoding (fill values, scale factors, character arrays stay as stored).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from bendpam.errors import FileFormatError

__all__ = ["read_netcdf3"]

#: nc_type codes of NetCDF-3 and their big-endian NumPy types.
_TYPES = {1: "i1", 2: "S1", 3: ">i2", 4: ">i4", 5: ">f4", 6: ">f8"}
_ABSENT, _DIMENSION, _VARIABLE, _ATTRIBUTE = 0, 10, 11, 12


class _Reader:
    """The header of a NetCDF-3 file, read field by field from its bytes."""

    def __init__(self, data: bytes, path: Path) -> None:
        self.data, self.pos, self.path = data, 0, path

    def fail(self, what: str) -> FileFormatError:
        return FileFormatError(f"{self.path}: not a NetCDF-3 file bendpam can read ({what}, at byte {self.pos})")

    def take(self, n: int) -> bytes:
        if n < 0 or self.pos + n > len(self.data):
            raise self.fail("the header ends early")
        out = self.data[self.pos:self.pos + n]
        self.pos += n
        return out

    def uint(self, size: int = 4) -> int:
        return int.from_bytes(self.take(size), "big")

    def name(self) -> str:
        n = self.uint()
        raw = self.take(n)
        self.take(-n % 4)
        try:
            return raw.decode("utf-8")
        except UnicodeDecodeError:
            raise self.fail("a name that is not UTF-8") from None

    def count(self, tag: int) -> int:
        """The length of a dimension, attribute or variable list (0 when the list is absent)."""
        kind, n = self.uint(), self.uint()
        if kind == _ABSENT and n == 0:
            return 0
        if kind != tag:
            raise self.fail(f"list tag {kind}, expected {tag}")
        return n

    def dtype(self) -> np.dtype:
        code = self.uint()
        if code not in _TYPES:
            raise self.fail(f"data type {code}")
        return np.dtype(_TYPES[code])

    def attributes(self) -> dict[str, Any]:
        out: dict[str, Any] = {}
        for _ in range(self.count(_ATTRIBUTE)):
            name, dtype, n = self.name(), self.dtype(), self.uint()
            size = n * dtype.itemsize
            raw = self.take(size)
            self.take(-size % 4)
            if dtype.kind == "S":  # text: bytes without the trailing NULs, as str
                out[name] = raw.rstrip(b"\x00").decode("utf-8", "replace")
            else:
                values = np.frombuffer(raw, dtype).astype(dtype.newbyteorder("="))
                out[name] = values[0] if n == 1 else values
        return out


def read_netcdf3(path: str | Path) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
    """The variables (``{name: array}``) and global attributes of a NetCDF-3 file.

    Text attributes come back as ``str``, one-value numeric attributes as NumPy scalars; a file
    that is not NetCDF-3 (NetCDF-4 is HDF5: read it with xarray) or is cut short raises
    :class:`~bendpam.errors.FileFormatError` naming the file.

    >>> import tempfile, xarray as xr
    >>> with tempfile.TemporaryDirectory() as d:
    ...     f = Path(d) / "x.nc"
    ...     ds = xr.Dataset({"m_nmm": ("p", [1.5, 2.5])}, attrs={"units": "kPa", "L0_mm": 145.0})
    ...     ds.to_netcdf(f, engine="scipy")
    ...     values, attrs = read_netcdf3(f)
    >>> values["m_nmm"].tolist(), attrs["units"], float(attrs["L0_mm"])
    ([1.5, 2.5], 'kPa', 145.0)
    """
    path = Path(path)
    data = path.read_bytes()
    r = _Reader(data, path)
    magic = r.take(4)
    if magic[:3] != b"CDF" or magic[3] not in (1, 2):
        raise r.fail("no 'CDF' signature of version 1 or 2")
    offset_size = 4 if magic[3] == 1 else 8
    numrecs = r.uint()
    dims = [(r.name(), r.uint()) for _ in range(r.count(_DIMENSION))]
    attrs = r.attributes()
    specs = []
    for _ in range(r.count(_VARIABLE)):
        name, ids = r.name(), [r.uint() for _ in range(r.uint())]
        if any(i >= len(dims) for i in ids):
            raise r.fail(f"variable {name!r} names a dimension that does not exist")
        r.attributes()  # the variable's attributes: raw values are returned, undecoded
        dtype, _vsize, begin = r.dtype(), r.uint(), r.uint(offset_size)
        shape = [dims[i][1] for i in ids]
        specs.append((name, dtype, shape, begin, bool(ids) and shape[0] == 0))
    records = [s for s in specs if s[4]]
    if records and numrecs == 0xFFFFFFFF:
        raise r.fail("the record count was never written (a file still being written)")
    # one record: every record variable's slice, each padded to 4 bytes unless it is the only one
    slices = [s[1].itemsize * math.prod(s[2][1:]) for s in records]
    recsize = slices[0] if len(records) == 1 else sum(n + (-n % 4) for n in slices)
    values = {}
    for name, dtype, shape, begin, is_record in specs:
        if is_record:
            n = dtype.itemsize * math.prod(shape[1:])
            end = begin + (numrecs - 1) * recsize + n if numrecs else begin
            shape = [numrecs, *shape[1:]]
        else:
            n = dtype.itemsize * math.prod(shape)
            end = begin + n
        if end > len(data):
            raise FileFormatError(f"{path}: the values of {name!r} run past the end of the file (cut short?)")
        if is_record:  # the records of one variable, strided through the file
            raw = np.ndarray((numrecs, n), np.uint8, data, begin, (recsize, 1)).copy()
        else:
            raw = np.frombuffer(data, np.uint8, n, begin)
        values[name] = raw.view(dtype).reshape(shape).astype(dtype.newbyteorder("="))
    return values, attrs
