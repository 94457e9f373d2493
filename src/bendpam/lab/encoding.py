"""Bytes to text for testing-machine exports.

Exports are written in the encoding of the machine's PC: UTF-8 (with or without BOM), UTF-16
(Bluehill "Unicode" exports), or a legacy code page: cp1252 (Western Europe, Zwick testXpert,
MTS 793 "ansi"), cp1250 (Central Europe: Polish Bluehill), GB18030 (Chinese), Shift-JIS
(Japanese, Shimadzu Trapezium) or latin-1.  :func:`detect_encoding` tries, in this order, a BOM,
strict UTF-8 and then every legacy code page, keeping the one under which the lines that hold
non-ASCII characters make the most sense: recognised channel names first (``Obciążenie``,
``时间``, ``試験力``), then no mojibake (``Obci¹¿enie``, Latin letters glued to CJK ideographs).
``charset-normalizer`` breaks remaining ties when there is enough text for it (otherwise the
order of preference does).
"""

from __future__ import annotations

import codecs
import re
import unicodedata

from bendpam.lab.channels import ColumnInfo, classify_column, split_name_unit

__all__ = [
    "LEGACY_ENCODINGS",
    "container_kind",
    "detect_encoding",
    "mojibake_score",
]

#: Legacy code pages tried when a file is not UTF-8, in order of preference.
LEGACY_ENCODINGS: tuple[str, ...] = ("cp1252", "cp1250", "gb18030", "shift_jis", "latin-1")

_ODD = set(
    "\u00b9\u00bf\u00a1\u00a4\u00a6\u00a8\u00af\u00b4\u00b8\u00d7\u00f7\u00b1\u00bc\u00bd\u00be\u00aa\u00ab\u00bb\u00a7\u00b6\u00b7\u00ac\u00ae\u00a9\u00a2\u00a3\u00a5\u00c3\u201a\u0192\u201e\u2020\u2021\u02c6\u2030\u2039\u0152\u2018\u2019\u201c\u201d\u2022\u2013\u2014\u02dc\u2122\u203a\u0153\u0178"
)  # symbols that mojibake glues to letters ("Obci¹¿enie")
_CJK = re.compile(r"[\u3040-\u30ff\u3400-\u9fff\uac00-\ud7af\uf900-\ufaff\uff66-\uff9f]")
_LATIN_CJK = re.compile(
    r"[A-Za-zÀ-ɏ][\u3040-\u30ff\u3400-\u9fff\uac00-\ud7af\uff66-\uff9f]"
    r"|[\u3040-\u30ff\u3400-\u9fff\uac00-\ud7af\uff66-\uff9f][A-Za-zÀ-ɏ]"
)
_SPLIT = re.compile(r"[\t;,]")


def container_kind(head: bytes) -> str | None:
    """Kind of a binary container from its first bytes.

    Returns
    -------
    str or None
        ``"zip"`` (``.xlsx``/``.ods``), ``"ole2"`` (``.xls``), ``"gzip"`` (Zwick ``.zs2``) or
        None for anything else.

    Examples
    --------
    >>> container_kind(bytes([0x50, 0x4B, 3, 4, 20, 0])), container_kind(bytes([0x1F, 0x8B, 8]))
    ('zip', 'gzip')
    >>> container_kind(b"time_s,stroke_mm,force_n") is None
    True
    """
    if head.startswith(b"PK\x03\x04"):
        return "zip"
    if head.startswith(b"\xd0\xcf\x11\xe0\xa1\xb1\x1a\xe1"):
        return "ole2"
    if head.startswith(b"\x1f\x8b"):
        return "gzip"
    return None


def _bom(head: bytes) -> str | None:
    if head.startswith(codecs.BOM_UTF8):
        return "utf-8-sig"
    if head.startswith((codecs.BOM_UTF32_LE, codecs.BOM_UTF32_BE)):
        return "utf-32"
    if head.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
        return "utf-16"
    return None


def _utf16_without_bom(head: bytes) -> str | None:
    """``utf-16-le``/``utf-16-be`` for ASCII-ish UTF-16 text without a BOM, else None."""
    n = min(len(head), 4096) & ~1
    if n < 8:
        return None
    even = head[0:n:2].count(0)
    odd = head[1:n:2].count(0)
    half = n // 2
    if odd > 0.6 * half and even < 0.05 * half:
        return "utf-16-le"
    if even > 0.6 * half and odd < 0.05 * half:
        return "utf-16-be"
    return None


def mojibake_score(text: str) -> int:
    """How garbled ``text`` looks: symbols glued to letters, Latin glued to CJK, controls.

    0 for clean text.  Used to compare decodings of the same bytes.

    >>> mojibake_score("Obciążenie"), mojibake_score("Obciążenie".encode("cp1250").decode("cp1252"))
    (0, 2)
    """
    bad = 0
    prev = " "
    for ch in text:
        if ch in _ODD and (prev.isalpha()):
            bad += 1
        elif prev in _ODD and ch.isalpha():
            bad += 1
        cat = unicodedata.category(ch)
        if cat in ("Cc", "Co", "Cn") and ch not in "\t\r\n":
            bad += 2
        if ch == "\ufffd":
            bad += 2
        prev = ch
    bad += 2 * len(_LATIN_CJK.findall(text))
    return bad


def _role_hits(lines: list[str]) -> int:
    hits = 0
    for line in lines:
        for cell in _SPLIT.split(line):
            cell = cell.strip().strip('"').strip()
            if not cell or len(cell) > 60 or mojibake_score(cell):  # a garbled name is no evidence
                continue
            name, unit = split_name_unit(cell)
            if any(c.role in ("time", "stroke", "force", "counter")
                   for c in classify_column(ColumnInfo(0, cell, name, unit))):  # fmt: skip
                hits += 1
    return hits


def _trim_to_line(head: bytes, complete: bool) -> bytes:
    if complete:
        return head
    cut = max(head.rfind(b"\n"), head.rfind(b"\r"))
    return head[: cut + 1] if cut > 0 else head


def detect_encoding(head: bytes, complete: bool = True) -> str:
    """Encoding of an export, from its first bytes.

    Parameters
    ----------
    head : bytes
        The first bytes of the file (a few hundred kB are plenty).
    complete : bool
        True if ``head`` is the whole file; otherwise a last partial line is ignored.

    Returns
    -------
    str
        A Python codec name: ``"utf-8-sig"``, ``"utf-16"``, ``"utf-16-le"``, ``"utf-8"``, or one
        of :data:`LEGACY_ENCODINGS`.

    Examples
    --------
    >>> detect_encoding("Prüfzeit;Standardkraft".encode("utf-8"))
    'utf-8'
    >>> detect_encoding("Prüfzeit;Standardkraft".encode("cp1252")), detect_encoding("Czas;Obciążenie".encode("cp1250"))
    ('cp1252', 'cp1250')
    """
    bom = _bom(head)
    if bom is not None:
        return bom
    if b"\x00" in head[:4096]:
        wide = _utf16_without_bom(head)
        if wide is not None:
            return wide
    body = _trim_to_line(head, complete)
    try:
        body.decode("utf-8")
        return "utf-8"
    except UnicodeDecodeError as exc:
        if not complete and exc.start >= len(body) - 3 and exc.reason == "unexpected end of data":
            return "utf-8"
    # lines holding non-ASCII bytes are where the code pages differ
    raw_lines = [ln for ln in re.split(rb"\r\n|\r|\n", body) if any(b > 127 for b in ln)][:400]
    scored: list[tuple[int, int, int, str]] = []
    for order, enc in enumerate(LEGACY_ENCODINGS):
        try:
            lines = [ln.decode(enc) for ln in raw_lines]
        except UnicodeDecodeError:
            continue
        hits = _role_hits(lines)
        mess = sum(mojibake_score(ln) for ln in lines)
        scored.append((-hits, mess, order, enc))
    if not scored:
        return "latin-1"
    scored.sort()
    best = scored[0]
    tied = [s[3] for s in scored if s[:2] == best[:2]]
    if len(tied) > 1 and sum(len(ln) for ln in raw_lines) >= 2000:  # too little text misleads it
        texts = {enc: b"\n".join(raw_lines).decode(enc) for enc in tied}
        if len(set(texts.values())) > 1:
            guess = _charset_normalizer_guess(b"\n".join(raw_lines), tied)
            if guess is not None:
                return guess
    return best[3]


def _charset_normalizer_guess(data: bytes, candidates: list[str]) -> str | None:
    try:
        from charset_normalizer import from_bytes
    except ImportError:  # pragma: no cover - a declared dependency
        return None
    names = {codecs.lookup(c).name: c for c in candidates}
    try:
        result = from_bytes(data, cp_isolation=list(names)).best()
    except Exception:  # a helper only: fall back to the order of preference
        return None
    if result is None:
        return None
    return names.get(codecs.lookup(result.encoding).name)
