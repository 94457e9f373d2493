"""Channel names and units of testing-machine exports, in many languages.

A column of an export is a *channel*: a name as the machine wrote it (``Standardweg``,
``Extension``, ``Ch 1 Kraft``, ``Position (mm)``, ``位移``, ``試験力``) and a unit (from a units
row, from the name, or none).  :func:`classify_column` says which role a column can play for a
four-point-bending test (``"time"``, ``"stroke"``, ``"force"``) or whether it is a machine cycle
counter, with a rank and the kind of channel; :func:`choose_channels` picks one column per role
and says why.

Stroke ranking, for the four-point fixture (eq 6 wants the crosshead stroke counted from the
blocked state): an explicit *relative crosshead travel* (``Standardweg``, ``Machine
Displacement``, ``Crosshead``, ``Stroke``) beats a generic displacement (``Extension``,
``Displacement``, ``Position``, ``Weg``), which beats a digital position and an absolute
crosshead position (``Traverse abs.``); extensometer channels come last.
"""

from __future__ import annotations

import re
import unicodedata
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

__all__ = [
    "ACCEPTED_NAMES",
    "DEFAULT_UNIT",
    "FORCE_UNITS",
    "LENGTH_UNITS",
    "ROLES",
    "TIME_UNITS",
    "UNIT_HINT",
    "Candidate",
    "ChannelChoice",
    "ColumnInfo",
    "canonical_unit",
    "choose_channels",
    "classify_column",
    "is_unit_token",
    "looks_like_summary",
    "normalize_name",
    "split_name_unit",
    "unit_cell",
    "unit_factor",
]

ROLES: tuple[str, str, str] = ("time", "stroke", "force")

# Unit -> factor to s, mm, N.  Keys are lower case; "mn" is milli-newton (never mega-newton).
TIME_UNITS: dict[str, float] = {
    "s": 1.0, "sec": 1.0, "secs": 1.0, "second": 1.0, "seconds": 1.0, "sek": 1.0, "seg": 1.0,
    "秒": 1.0, "\u0441": 1.0,  # Cyrillic es
    "ms": 1e-3, "msec": 1e-3,
    "us": 1e-6, "µs": 1e-6, "μs": 1e-6,
    "min": 60.0, "mins": 60.0, "minute": 60.0, "minutes": 60.0, "分": 60.0,
    "h": 3600.0, "hr": 3600.0, "hrs": 3600.0, "hour": 3600.0, "hours": 3600.0,
}  # fmt: skip
LENGTH_UNITS: dict[str, float] = {
    "m": 1000.0, "cm": 10.0, "mm": 1.0,
    "µm": 1e-3, "μm": 1e-3, "um": 1e-3, "micron": 1e-3, "microns": 1e-3,
    "in": 25.4, "inch": 25.4, "inches": 25.4, "毫米": 1.0, "мм": 1.0,
}  # fmt: skip
FORCE_UNITS: dict[str, float] = {
    "n": 1.0, "newton": 1.0, "newtons": 1.0, "牛": 1.0, "н": 1.0,
    "kn": 1000.0, "千牛": 1000.0, "кн": 1000.0, "mn": 1e-3, "un": 1e-6, "µn": 1e-6, "μn": 1e-6, "dan": 10.0,
    "lbf": 4.4482216152605, "lb": 4.4482216152605, "lbs": 4.4482216152605,
    "kgf": 9.80665, "kp": 9.80665, "gf": 9.80665e-3,
}  # fmt: skip
_UNIT_TABLES = {"time": TIME_UNITS, "stroke": LENGTH_UNITS, "force": FORCE_UNITS}
UNIT_HINT = {
    "time": "s, sec, ms, us, min or h",
    "stroke": "m, cm, mm, µm/um or in",
    "force": "N, kN, mN, µN/uN, daN, kgf, gf or lbf",
}
DEFAULT_UNIT = {"time": "s", "stroke": "mm", "force": "N"}
# Units of other quantities seen in exports (so that a units row is recognised as one).
_OTHER_UNITS = {
    "%", "mpa", "kpa", "gpa", "pa", "psi", "ksi", "bar", "deg", "°", "rad", "hz", "khz", "v", "mv", "a",
    "ma", "°c", "cel", "k", "n/mm2", "n/mm²", "mm/mm", "mm/s", "mm/min", "n/s", "kn/s", "1/s", "s-1",
    "-", "1", "d", "nm", "n·m", "n m", "nmm", "n·mm", "j", "mj", "w", "mm2", "mm²", "m/m", "in/in",
    "ε", "µε", "με", "count", "counts", "cycles", "cyc", "no", "nr", "#", "mm/s²", "g", "kg", "ue",
}  # fmt: skip
_ALL_UNITS = set(TIME_UNITS) | set(LENGTH_UNITS) | set(FORCE_UNITS) | _OTHER_UNITS

ACCEPTED_NAMES = (
    "time: 'time', 'zeit', 'temps', 'tempo', 'tiempo', 'czas', '时间', '時間' (e.g. 'Time (s)', "
    "'Prüfzeit', 'Laufzeit'); stroke: 'stroke', 'travel', 'displacement', 'extension', "
    "'position', 'crosshead', 'deflection', 'weg', 'déplacement', 'spostamento', "
    "'desplazamiento', 'przemieszczenie', '位移', 'ストローク' (e.g. 'Standardweg'); force: "
    "'force', 'load', 'kraft', 'charge', 'carico', 'fuerza', 'obciążenie', '载荷', '試験力' "
    "(e.g. 'Load (kN)', 'Standardkraft')"
)

# ------------------------------------------------------------------------------------------------
# vocabulary: (pattern, rank, kind).  Patterns are searched in the normalised name (lower case,
# punctuation -> spaces); Latin words match at word boundaries, CJK as substrings.
# ------------------------------------------------------------------------------------------------
_W = r"(?<![^\W\d_])"  # start of a word (letters only count)
_E = r"(?![^\W\d_])"  # end of a word


def _words(*ws: str) -> str:
    return _W + "(?:" + "|".join(re.escape(w) for w in ws) + ")" + _E


@dataclass(frozen=True)
class _Entry:
    pattern: re.Pattern[str]
    rank: int
    kind: str
    words: tuple[str, ...]


def _entry(rank: int, kind: str, latin: Sequence[str] = (), cjk: Sequence[str] = (),
           extra: str = "") -> _Entry:
    parts = []
    if latin:
        parts.append(_words(*latin))
    if cjk:
        parts.append("|".join(re.escape(w) for w in cjk))
    if extra:
        parts.append(extra)
    return _Entry(re.compile("|".join(parts)), rank, kind, (*latin, *cjk))


_TIME_VOCAB: list[_Entry] = [
    _entry(3, "test time",
           ["total time", "test time", "running time", "run time", "prüfzeit", "pruefzeit",
            "laufzeit", "versuchszeit", "messzeit", "gesamtzeit", "versuchsdauer", "test duration",
            "temps total", "temps d essai",
            "tempo totale", "tempo di prova", "tiempo total", "tiempo de ensayo", "czas testu",
            "czas badania"],
           ["试验时间", "测试时间", "经过时间", "経過時間", "試験時間"]),
    _entry(2, "time",
           ["time", "zeit", "temps", "tempo", "tiempo", "czas", "tijd", "tid", "t",
            "elapsed time", "durée", "duree", "čas", "cas", "время", "zaman", "aika", "idő"],
           ["时间", "時間", "時刻", "时刻"], extra=r"\w+zeit" + _E),
    _entry(1, "time", ["godzina", "point", "punkt", "points"]),
]  # fmt: skip
_TIME_EXCLUDE = re.compile(
    _words("cycle", "cycles", "step", "segment", "start", "end", "uhrzeit", "clock", "date",
           "datum", "stamp", "timestamp", "rate", "hold", "dwell", "zyklus", "zyklen", "stufe",
           "ciclo", "heure", "ora", "hora", "data", "fecha", "max", "min",
           "maximum", "minimum", "peak", "mean", "average", "at", "bei", "à", "al")
    + r"|循环|周期|日期|サイクル|日付|開始|开始"
)  # fmt: skip

_STROKE_VOCAB: list[_Entry] = [
    _entry(4, "crosshead travel",
           ["standardweg", "standard travel", "machine displacement", "machine extension",
            "crosshead", "cross head", "stroke", "actuator", "traverse", "traversenweg",
            "traversenposition", "querhaupt", "querhauptweg", "kolbenweg", "zylinderweg",
            "maschinenweg", "course", "corsa", "traversa", "carrera", "travesaño", "trawersa",
            "skok", "ram", "piston", "axial displacement", "travel", "weg maschine", "maschine",
            "machine", "course traverse", "course standard", "traversenweg", "crosshead position",
            "position machine", "déplacement traverse"],
           ["ストローク", "クロスヘッド", "行程", "横梁位移", "横梁", "活塞位移"]),
    _entry(2, "digital position", ["digital position", "digitale position", "encoder"]),
    _entry(1, "extensometer",
           ["extensometer", "extensometers", "ave", "video", "clip on", "clip", "feindehnung",
            "dehnungsaufnehmer", "makroxtens", "extensomètre", "estensimetro", "extensómetro",
            "ekstensometr", "lvdt", "dic", "strain gauge", "laser", "extenso", "iwa", "clip gauge",
            "wegaufnehmer", "capteur", "déform", "poti", "potentiometer"],
           ["引伸计", "引伸計", "伸び計"]),
    _entry(4, "position (actuator)", ["position", "posizione", "posición", "posicion", "pozycja"],
           ["位置"]),
    _entry(3, "displacement",
           ["displacement", "extension", "deflection", "position", "weg", "verschiebung",
            "durchbiegung", "verformung", "verlängerung", "déplacement", "deplacement", "flèche", "distance", "disp",
            "dl", "δl", "delta l", "change in length", "längenänderung",
            "fleche", "allongement", "spostamento", "estensione", "posizione", "freccia",
            "allungamento", "abbassamento", "desplazamiento", "extensión", "posición",
            "posicion", "deflexión", "flecha", "alargamiento", "przemieszczenie", "wydłużenie",
            "wydluzenie", "pozycja", "ugięcie", "ugiecie", "elongation", "verplaatsing",
            "deformation", "deformación", "deformazione", "deslocamento", "posição", "posicao",
            "förskjutning", "forskjutning", "posunutí", "posunuti", "dráha", "перемещение",
            "удлинение", "деформация", "uzama", "deplasman", "siirtymä"],
           ["位移", "变形", "伸长", "変位", "伸び", "たわみ", "位置", "挠度", "撓み", "拉伸", "压缩", "延伸"],
           extra=r"\w+weg" + _E),
]  # fmt: skip
_STROKE_EXCLUDE = re.compile(
    _words("max", "min", "maximum", "minimum", "peak", "mean", "average", "amplitude", "rms",
           "sollwert", "soll", "setpoint", "set point", "command", "target", "demand", "limit",
           "consigne", "riferimento", "consigna", "zadana", "at", "bei", "à", "rate", "speed",
           "velocity", "geschwindigkeit", "vitesse", "velocità", "velocidad", "prędkość",
           "after", "nach", "break", "bruch", "strain", "dehnung", "rotation", "angle", "kraft", "force",
           "load", "charge")
    + r"|速度|最大|最小|平均|目標|目标|指令|设定|应变|應變|ひずみ|歪み"
)  # fmt: skip
_STRAIN_WORD = re.compile(_words("strain", "dehnung", "nominal strain", "nominale dehnung"))
_ABSOLUTE = re.compile(_words("abs", "absolute", "absolut", "absolue", "assoluta", "absoluta",
                              "bezwzględna") + r"|绝对|絶対")  # fmt: skip

_FORCE_VOCAB: list[_Entry] = [
    _entry(4, "force",
           ["standardkraft", "standard force", "axial force", "axial load", "prüfkraft",
            "pruefkraft"],
           ["試験力", "试验力"]),
    _entry(3, "force",
           ["force", "load", "kraft", "charge", "effort", "forza", "carico", "fuerza", "carga",
            "obciążenie", "obciazenie", "siła", "sila", "kracht", "belasting", "wägezelle", "waegezelle",
            "load cell", "loadcell", "kraftaufnehmer", "kraftsensor", "cellule de charge", "cella di carico",
            "célula de carga", "kraft maschine", "maschinenkraft", "força", "forca", "síla", "sila",
            "сила", "нагрузка", "kuvvet", "yük", "yuk", "voima", "erő"],
           ["载荷", "荷载", "负荷", "负载", "荷重", "力值", "拉力"],
           extra=r"\w+kraft" + _E + r"|^力$"),
]  # fmt: skip
_FORCE_EXCLUDE = re.compile(
    _words("max", "min", "maximum", "minimum", "peak", "mean", "average", "amplitude", "rms",
           "sollwert", "soll", "setpoint", "set point", "command", "target", "demand", "limit",
           "consigne", "riferimento", "consigna", "zadana", "at", "bei", "à", "rate",
           "geschwindigkeit", "vitesse", "velocidad", "bruch", "break", "after", "nach",
           "moment", "torque", "drehmoment", "stress", "spannung", "contrainte", "sforzo",
           "tensión", "naprężenie", "strain", "dehnung", "preload", "vorkraft")
    + r"|速度|最大|最小|平均|目標|目标|指令|设定|应力|応力|压力|圧力|应变|應變|ひずみ"
)  # fmt: skip

_COUNTER_VOCAB: list[_Entry] = [
    _entry(4, "cycle counter", ["total cycle count", "total cycles", "total cycle"]),
    _entry(3, "cycle counter",
           ["cycle count", "cycle counter", "cycle number", "cycle no", "cycle nr", "zykluszahl",
            "zyklenzahl", "zykluszähler", "nombre de cycles", "numero di cicli",
            "número de ciclos", "liczba cykli"],
           ["循环计数", "循环次数", "総サイクル", "サイクル数", "サイクル回数"]),
    _entry(2, "cycle counter",
           ["cycles", "cycle", "zyklus", "zyklen", "cicli", "ciclo", "ciclos", "cykl", "cykle"],
           ["循环", "サイクル"]),
]  # fmt: skip
_COUNTER_EXCLUDE = re.compile(
    _words("elapsed", "time", "zeit", "start", "frequency", "max", "min", "maximum", "minimum",
           "rate", "step", "segment")
    + r"|时间|時間"
)  # fmt: skip
_COUNTER_UNITS = {"", "-", "1", "#", "count", "counts", "cycles", "cyc", "no", "nr", "n/a"}

# Columns that make a table a summary (one row per cycle or per specimen), not a time series.
_SUMMARY = re.compile(
    _words("max", "min", "maximum", "minimum", "peak", "mean", "average", "amplitude",
           "cycle start time", "fmax", "rm", "rp0.2", "e-modul", "modulus", "young",
           "at break", "bei bruch", "bei fmax", "width", "thickness", "breite", "dicke",
           "diameter", "durchmesser", "specimen", "probe", "elongation at break")
)  # fmt: skip

_PUNCT = re.compile(r"[\s_:;,.()\[\]{}/\\|=*+\"'`<>!?-]+")
_BRACKET_UNIT = re.compile(r"(.*?)\s*[(\[]\s*([^()\[\]]*?)\s*[)\]]\s*")
_SUFFIX_UNIT = re.compile(r"(.+?)_([^\W\d_]+)")
_IN_UNIT = re.compile(r"(.+?)\s+(?:in|en|w|/)\s+(\S+)")


def normalize_name(name: str) -> str:
    """Lower-case, NFKC-normalised name with punctuation runs turned into single spaces.

    >>> normalize_name("_Time "), normalize_name("Traverse abs."), normalize_name("Position:Maximum (mm)")
    ('time', 'traverse abs', 'position maximum mm')
    """
    s = unicodedata.normalize("NFKC", str(name)).casefold().replace("\ufeff", "")
    return " ".join(_PUNCT.sub(" ", s).split())


def split_name_unit(cell: str) -> tuple[str, str | None]:
    """Split a header cell into its name and its unit.

    >>> split_name_unit("Time (s)"), split_name_unit("Kraft [kN]"), split_name_unit("force_kN")
    (('Time', 's'), ('Kraft', 'kN'), ('force', 'kN'))
    >>> split_name_unit("Zeit in s"), split_name_unit("Load")
    (('Zeit', 's'), ('Load', None))

    A bracket that is no unit stays in the name:

    >>> split_name_unit("Total Cycle Count(Linear Waveform)")
    ('Total Cycle Count(Linear Waveform)', None)
    """
    s = cell.strip().strip('"').strip()
    m = _BRACKET_UNIT.fullmatch(s)
    if m and m.group(1).strip():
        unit = m.group(2).strip()
        if not unit or is_unit_token(unit):
            return m.group(1).strip(), unit or None
        return s, None
    m = _IN_UNIT.fullmatch(s)
    if m and m.group(2).lower() in _ALL_UNITS:
        return m.group(1).strip(), m.group(2)
    m = _SUFFIX_UNIT.fullmatch(s)
    if m and m.group(2).lower() in _ALL_UNITS:
        return m.group(1).strip(), m.group(2)
    return s, None


def unit_cell(cell: str) -> str:
    """Unit text of a units-row cell: ``'(kN)'``, ``'[kN]'``, ``'in kN'`` -> ``'kN'``.

    >>> unit_cell("(kN)"), unit_cell("[kN]"), unit_cell("in kN"), unit_cell("kN")
    ('kN', 'kN', 'kN', 'kN')
    """
    s = cell.strip().strip('"').strip()
    m = re.fullmatch(r"[(\[]\s*(.*?)\s*[)\]]", s)
    if m:
        return m.group(1)
    m = re.fullmatch(r"(?:in|en|w)\s+(\S+)", s)
    if m:
        return m.group(1)
    return s


def is_unit_token(text: str) -> bool:
    """Does ``text`` (a units-row cell or a bracket in a name) read as a unit?

    >>> is_unit_token("kN"), is_unit_token("(mm/min)"), is_unit_token("Linear Waveform")
    (True, True, False)
    """
    u = unit_cell(text).strip().lower().rstrip(".")
    if not u:
        return True
    if u in _ALL_UNITS:
        return True
    if "·" in u or "/" in u or "^" in u:
        return len(u) <= 12 and not any(c.isspace() for c in u)
    return len(u) <= 4 and not any(c.isdigit() for c in u) and not any(c.isspace() for c in u)


def unit_factor(role: str, unit: str) -> float | None:
    """Factor from ``unit`` to the library unit of ``role`` (s, mm, N), or None if unknown.

    >>> unit_factor("force", "kN"), unit_factor("time", "min"), unit_factor("stroke", "furlong")
    (1000.0, 60.0, None)
    """
    table = _UNIT_TABLES[role]
    u = unit.strip().strip('"').strip()
    f = table.get(u.lower())
    if f is None and u.endswith("."):  # 'sec.'
        f = table.get(u[:-1].lower())
    if f is None and u in ("Sec", "SEC"):
        f = 1.0
    return f


_FORCE_SPELLING = {"n": "N", "kn": "kN", "mn": "mN", "dan": "daN", "newton": "N", "newtons": "N",
                   "lbf": "lbf", "kgf": "kgf"}  # fmt: skip


def canonical_unit(role: str, unit: str) -> str:
    """Unit as written, with the case fixed: ``'n'`` -> ``'N'``, ``'MM'`` -> ``'mm'``.

    >>> canonical_unit("force", "kn"), canonical_unit("stroke", "MM")
    ('kN', 'mm')
    """
    u = unit.strip()
    if role == "force":
        return _FORCE_SPELLING.get(u.lower(), u)
    return u.lower() if u.isascii() else u


def _damaged_match(words: Sequence[str], name: str) -> bool:
    """Match a name whose non-ASCII letters were lost (U+FFFD), e.g. ``'Pr\ufffdfzeit'``."""
    if "\ufffd" not in name:
        return False
    for token in name.split():
        if "\ufffd" not in token or sum(c != "\ufffd" for c in token) < 3:
            continue
        parts = [re.escape(p) for p in re.split("\ufffd+", token)]
        rx = re.compile(".{1,3}".join(parts))
        if any(rx.search(w) for w in words):
            return True
    return False


def _best(vocab: Sequence[_Entry], name: str) -> tuple[int, str] | None:
    for entry in vocab:
        if entry.pattern.search(name) or _damaged_match(entry.words, name):
            return entry.rank, entry.kind
    return None


@dataclass(frozen=True)
class ColumnInfo:
    """One column of a data block.

    Attributes
    ----------
    index : int
        0-based column index in the row.
    source : str
        The header cell as written (quotes and surrounding blanks removed).
    name : str
        The name without its unit.
    unit : str or None
        The unit (from the units row or the name), None if the file gives none.
    unit_line : int or None
        Line where the unit was written (units row or names row).

    Examples
    --------
    >>> col = ColumnInfo(1, "Standardweg [mm]", *split_name_unit("Standardweg [mm]"), unit_line=12)
    >>> col.name, col.unit
    ('Standardweg', 'mm')
    """

    index: int
    source: str
    name: str
    unit: str | None
    unit_line: int | None = None


@dataclass(frozen=True)
class Candidate:
    """A column that can play a role: rank (higher is better) and kind of channel.

    >>> (candidate,) = classify_column(ColumnInfo(0, "Prüfzeit", "Prüfzeit", "s"))
    >>> candidate.role, candidate.rank, candidate.kind, candidate.unit_ok
    ('time', 3, 'test time', True)
    """

    column: ColumnInfo
    role: str
    rank: int
    kind: str
    unit_ok: bool


#: A note on the sampling in a channel's name: a group in parentheses, or a tail after ' - ', that speaks of a
#: sampling (or measuring) rate.
_SAMPLING_NOTE = re.compile(r"\((?=[^()]*(?:rate|sampl|messrate|abtast))[^()]*\)"
                            r"|\s-\s(?=.*(?:rate|sampl|messrate|abtast)).*$", re.IGNORECASE)


def classify_column(col: ColumnInfo) -> list[Candidate]:
    """The roles (``time``, ``stroke``, ``force``, ``counter``) a column can play.

    Parameters
    ----------
    col : ColumnInfo
        The column.

    Returns
    -------
    list of Candidate
        Usually zero or one entry.  ``unit_ok`` is False when the name fits a role but the
        unit does not (``Extension (%)``).

    Examples
    --------
    >>> [(c.role, c.kind) for c in classify_column(ColumnInfo(2, "Traverse abs.", "Traverse abs.", "mm"))]
    [('stroke', 'crosshead position (absolute)')]
    >>> [(c.role, c.kind) for c in classify_column(ColumnInfo(3, "Total Cycles", "Total Cycles", None))]
    [('counter', 'cycle counter')]
    >>> name = "Time DEVICE_1 (Sample rate 1) CH=1"                  # HBM catman ASCII: the sampling is a note
    >>> [c.role for c in classify_column(ColumnInfo(0, name, name, "s"))]
    ['time']
    """
    # a note on how the channel is sampled is not what it measures: HBM catman names the time of a rate group
    # 'Time  1 - default sample rate' (Excel) or 'Time DEVICE_1 (Sample rate 1) CH=1' (ASCII)
    name = normalize_name(_SAMPLING_NOTE.sub(" ", col.name))
    unit = (col.unit or "").strip()
    if name and re.fullmatch(r"[\d\s.,+-]+", name) and unit and unit_factor("stroke", unit):
        return [Candidate(col, "stroke", 0, "length channel of unknown kind", True)]
    if not name or re.fullmatch(r"[\d\s.,+-]+", name):
        return []
    ulow = unit.lower().rstrip(".")
    out: list[Candidate] = []
    for role, vocab, exclude in (
        ("time", _TIME_VOCAB, _TIME_EXCLUDE),
        ("stroke", _STROKE_VOCAB, _STROKE_EXCLUDE),
        ("force", _FORCE_VOCAB, _FORCE_EXCLUDE),
    ):
        if exclude.search(name):
            continue
        hit = _best(vocab, name)
        if hit is None:
            continue
        rank, kind = hit
        unit_ok = not unit or unit_factor(role, unit) is not None
        if role == "stroke" and _ABSOLUTE.search(name):
            rank -= 2
            kind = "crosshead position (absolute)" if kind == "crosshead travel" else kind + " (absolute)"
        elif role == "stroke" and kind == "crosshead travel":
            kind = "crosshead travel (relative)"
        out.append(Candidate(col, role, rank, kind, unit_ok))
    if not out and ulow and unit_factor("stroke", unit) is not None and _STRAIN_WORD.search(name) \
            and not _STROKE_EXCLUDE.search(_STRAIN_WORD.sub(" ", name)):
        # 'Dehnung (mm)', 'Strain (mm)': Bluehill and testXpert name an extension in mm so
        out.append(Candidate(col, "stroke", 1, "extension (a strain channel in a length unit)", True))
    if not out and ulow and unit_factor("stroke", unit) is not None and not _STROKE_EXCLUDE.search(name):
        # a length channel with an unknown name (a sensor's serial number, '1944 B'): listed
        # among the alternatives, chosen only when it is the one length column of the block
        out.append(Candidate(col, "stroke", 0, "length channel of unknown kind", True))
    for role, exclude in (("time", _TIME_EXCLUDE), ("force", _FORCE_EXCLUDE)):
        if not out and ulow and ulow not in ("m", "-", "1") and unit_factor(role, unit) is not None \
                and not exclude.search(name):
            out.append(Candidate(col, role, 0, f"{role} channel of unknown kind (by its unit)", True))
    if not _COUNTER_EXCLUDE.search(name) and ulow in _COUNTER_UNITS:
        hit = _best(_COUNTER_VOCAB, name)
        if hit is not None:
            out = [c for c in out if c.role != "time"]
            out.append(Candidate(col, "counter", hit[0], hit[1], True))
    # a column named after two roles ('Load Position') stays ambiguous: keep the best rank only
    if len({c.role for c in out if c.role in ROLES}) > 1:
        best = max((c for c in out if c.role in ROLES), key=lambda c: c.rank)
        out = [c for c in out if c.role not in ROLES or c is best]
    return out


def looks_like_summary(columns: Sequence[ColumnInfo]) -> list[str]:
    """Columns that mark a table as a summary (per cycle or per specimen), not a time series.

    >>> looks_like_summary([ColumnInfo(0, "Cycle", "Cycle", None), ColumnInfo(1, "Max Load (N)", "Max Load", "N")])
    ['Max Load (N)']
    """
    return [c.source for c in columns if c.source and _SUMMARY.search(normalize_name(c.source))]


@dataclass
class ChannelChoice:
    """The columns chosen for time, stroke and force (and the cycle counter).

    Attributes
    ----------
    chosen : dict
        role -> :class:`ColumnInfo` (``time`` may be missing: a rate supplies it).
    why : dict
        role -> reason, one sentence.
    counter : ColumnInfo or None
        The machine cycle counter.
    missing : list of str
        Roles without a column.
    bad_unit : dict
        role -> the best candidate whose unit does not fit (for the error message).

    Examples
    --------
    >>> choice = choose_channels([ColumnInfo(0, "Time (s)", "Time", "s"), ColumnInfo(1, "Load (%)", "Load", "%")])
    >>> sorted(choice.chosen), choice.missing, sorted(choice.bad_unit), choice.n_roles
    (['time'], ['stroke', 'force'], ['force'], 2)
    """

    chosen: dict[str, ColumnInfo] = field(default_factory=dict)
    why: dict[str, str] = field(default_factory=dict)
    counter: ColumnInfo | None = None
    missing: list[str] = field(default_factory=list)
    bad_unit: dict[str, ColumnInfo] = field(default_factory=dict)

    @property
    def n_roles(self) -> int:
        """Roles a column was found for (chosen, or named right with a unit that does not fit)."""
        return len(self.chosen) + len(self.bad_unit)


def _find_override(columns: Sequence[ColumnInfo], wanted: str) -> ColumnInfo | None:
    w = wanted.strip().strip('"').strip()
    for test in (
        lambda c: c.source == w,
        lambda c: c.name == w,
        lambda c: c.source.casefold() == w.casefold(),
        lambda c: c.name.casefold() == w.casefold(),
        lambda c: normalize_name(c.source) == normalize_name(w),
        lambda c: normalize_name(c.name) == normalize_name(w),
    ):
        hits = [c for c in columns if c.source and test(c)]
        if hits:
            return hits[0]
    return None


def _by_unit(choice: ChannelChoice, role: str, pool: list[Candidate], used: set[int]) -> bool:
    """No column named for the role: choose the one column in the role's unit, if there is exactly one."""
    unknown = [c for c in pool if c.rank == 0]
    if len(unknown) != 1 or any(c.rank > 0 for c in pool):
        return False
    col = unknown[0].column
    choice.chosen[role] = col
    used.add(col.index)
    choice.why[role] = f"no column named as {role}: the only column in {col.unit}"
    return True


def _kind_word(c: Candidate) -> str:
    return f"{c.kind} {c.column.source!r}"


def choose_channels(
    columns: Sequence[ColumnInfo], overrides: Mapping[str, str] | None = None
) -> ChannelChoice:
    """Pick the time, stroke and force columns (and a cycle counter) of a data block.

    Parameters
    ----------
    columns : sequence of ColumnInfo
        The block's columns.
    overrides : mapping of str to str, optional
        role -> column name given by the user (the ``columns=`` argument of
        :func:`bendpam.lab.read_test`).  A name that is not in the block raises ``KeyError``
        with the name.

    Returns
    -------
    ChannelChoice

    Examples
    --------
    >>> names = ["Zeit (s)", "Standardweg (mm)", "Weg (mm)", "Standardkraft (N)"]
    >>> cols = [ColumnInfo(i, cell, *split_name_unit(cell)) for i, cell in enumerate(names)]
    >>> choice = choose_channels(cols)
    >>> {role: col.source for role, col in choice.chosen.items()}
    {'time': 'Zeit (s)', 'stroke': 'Standardweg (mm)', 'force': 'Standardkraft (N)'}
    >>> print(choice.why["stroke"])
    crosshead travel (relative) preferred over displacement 'Weg (mm)': eq 6 wants the crosshead stroke ...
    >>> choose_channels(cols, {"stroke": "Weg"}).chosen["stroke"].source
    'Weg (mm)'
    """
    choice = ChannelChoice()
    cands: dict[str, list[Candidate]] = {r: [] for r in (*ROLES, "counter")}
    for col in columns:
        for c in classify_column(col):
            cands[c.role].append(c)
    overrides = dict(overrides or {})
    used: set[int] = set()
    for role, wanted in overrides.items():
        found = _find_override(columns, wanted)
        if found is None:
            raise KeyError(wanted)
        choice.chosen[role] = found
        choice.why[role] = f"chosen by the columns option ({wanted!r})"
        used.add(found.index)
    for role in ROLES:
        if role in choice.chosen:
            continue
        pool = [c for c in cands[role] if c.column.index not in used]
        good = [c for c in pool if c.unit_ok and c.rank > 0]
        unknown = [c for c in pool if c.rank == 0]
        if not good and _by_unit(choice, role, pool, used):
            continue
        if not good:
            named = [c for c in pool if c.rank > 0]
            if named:
                choice.bad_unit[role] = max(named, key=lambda c: c.rank).column
            choice.missing.append(role)
            continue
        # best rank; among equals the first column (machines write the primary channel first)
        best = max(good, key=lambda c: (c.rank, -c.column.index))
        others = [c for c in good if c is not best] + unknown
        choice.chosen[role] = best.column
        used.add(best.column.index)
        if not others:
            choice.why[role] = f"the only {role} column ({best.kind})"
        else:
            beaten = ", ".join(_kind_word(c) for c in sorted(others, key=lambda c: -c.rank))
            reason = {
                "stroke": "eq 6 wants the crosshead stroke counted from the blocked state",
                "time": "the test time runs through the whole record",
                "force": "the measured force, not a setpoint or a secondary channel",
            }[role]
            same = [c for c in others if c.rank == best.rank]
            tie = " (same kind: the first column wins)" if same else ""
            choice.why[role] = f"{best.kind} preferred over {beaten}{tie}: {reason}"
    counters = [c for c in cands["counter"] if c.column.index not in used]
    if counters:
        choice.counter = max(counters, key=lambda c: (c.rank, -c.column.index)).column
    return choice
