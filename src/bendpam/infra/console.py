"""Words for a console that cannot show every character bendpam prints.

bendpam's messages use a few symbols (θ, α0, μ, −, ≤, ·).  A terminal with UTF-8 shows them; but
where standard output is a pipe or a file on Windows, Python writes it in the ANSI code page
(cp1252), which has ``±`` and ``°`` and no Greek letters, and a single ``θ`` would end the command
with a ``UnicodeEncodeError``.  :func:`plain_streams` makes the command line's standard output and
error, when their encoding is not a Unicode one, write each character they cannot encode in ASCII
words instead (:data:`ASCII_WORDS`: ``θ`` as ``theta``, ``≤`` as ``<=``), and anything else as its
closest ASCII letter or ``?``.  Nothing changes where the encoding is UTF-8.
"""

from __future__ import annotations

import codecs
import sys
import unicodedata

__all__ = ["ASCII_WORDS", "ERRORS", "ascii_words", "plain_streams"]

#: The name of the codec error handler :func:`plain_streams` installs.
ERRORS = "bendpam-ascii"

#: Characters bendpam prints, in ASCII words.
ASCII_WORDS: dict[str, str] = {
    "α": "alpha", "β": "beta", "γ": "gamma", "δ": "delta", "Δ": "Delta", "ε": "eps", "θ": "theta", "κ": "kappa",
    "λ": "lambda", "μ": "mu", "µ": "u", "ν": "nu", "π": "pi", "ρ": "rho", "σ": "sigma", "Σ": "Sum", "τ": "tau",
    "φ": "phi", "ψ": "psi", "ω": "omega", "Ω": "Ohm", "χ": "chi",
    "−": "-", "–": "-", "—": "-", "‒": "-", "≤": "<=", "≥": ">=", "≈": "~", "≃": "~", "≠": "!=", "±": "+-",
    "×": "x", "·": "*", "⋅": "*", "→": "->", "←": "<-", "↔": "<->", "…": "...", "√": "sqrt", "∞": "inf",
    "°": " deg", "²": "^2", "³": "^3", "⁻": "^-", "¹": "1", "’": "'", "‘": "'", "“": '"', "”": '"', "′": "'",
    "✓": "ok", "✗": "x", "•": "*", "│": "|", "─": "-",
}


def ascii_words(text: str) -> str:
    """``text`` in ASCII: :data:`ASCII_WORDS`, then the letter under an accent, then ``?``.

    >>> ascii_words("θ = 12° ± 0.3, α0 ≤ 70, Zürich")
    'theta = 12 deg +- 0.3, alpha0 <= 70, Zurich'
    """
    out = []
    for c in text:
        if c.isascii():
            out.append(c)
        elif c in ASCII_WORDS:
            out.append(ASCII_WORDS[c])
        else:
            base = unicodedata.normalize("NFKD", c).encode("ascii", "ignore").decode("ascii")
            out.append(base or "?")
    return "".join(out)


def _handler(exc: UnicodeError) -> tuple[str, int]:
    """The codec error handler: the characters the encoding could not take, in :func:`ascii_words`."""
    if not isinstance(exc, UnicodeEncodeError):
        raise exc
    return ascii_words(exc.object[exc.start:exc.end]), exc.end


codecs.register_error(ERRORS, _handler)


def _unicode(encoding: str | None) -> bool:
    try:
        return codecs.lookup(encoding or "ascii").name.startswith(("utf-8", "utf-16", "utf-32", "gb18030"))
    except LookupError:
        return False


def plain_streams(streams=None) -> list:
    """Let ``streams`` (default standard output and error) write what their encoding lacks in ASCII words.

    Only text streams that can be reconfigured, whose encoding is not a Unicode one and whose errors
    are ``"strict"``, are changed; returns those.

    >>> import io
    >>> raw = io.BytesIO()
    >>> s = io.TextIOWrapper(raw, encoding="cp1252")
    >>> len(plain_streams([s]))
    1
    >>> _ = s.write("θ = 12° ± 0.3 N·mm, μ = 600 kPa"); s.flush()
    >>> raw.getvalue().decode("cp1252")
    'theta = 12° ± 0.3 N·mm, mu = 600 kPa'
    """
    changed = []
    for s in (sys.stdout, sys.stderr) if streams is None else streams:
        reconfigure = getattr(s, "reconfigure", None)
        if reconfigure is None or getattr(s, "errors", None) != "strict" or _unicode(getattr(s, "encoding", None)):
            continue
        try:
            reconfigure(errors=ERRORS)
        except (ValueError, OSError):  # a closed or detached stream
            continue
        changed.append(s)
    return changed
