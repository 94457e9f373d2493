"""Score bendpam's reader against the hand-written truth entries of tests/data/real.

Usage::

    python tools/score_corpus.py [--split dev|holdout|all] [--json] [-v]

``dev`` (default) is ``tests/data/real/truth.toml`` (the original 7) and
``tests/data/real/dev/truth.toml``; ``holdout`` is ``tests/data/real/holdout/truth.toml`` and is
scored ONCE, by the integrator, when all reader work is merged (never tune on it).

A file scores 1 when:

- verdict "refuse" and the reader refuses it (a ReadError / InputError); or
- verdict "read" and it reads, and
  - rows match: the sum over the tests :func:`bendpam.lab.read_tests` returns equals ``rows``
    (several blocks of one test concatenated or returned block by block both count); with
    ``per_specimen``, one test per specimen with that specimen's rows;
  - the time, stroke and force columns chosen are the truth's ``column`` or one of its
    ``alternatives`` (no time column in the truth, i.e. first/last time nan: a time made from a
    sampling rate or the sample index is fine);
  - first/last values match to 1e-6 relative + 1e-9 absolute, for each role whose chosen
    column is the truth's own column (an alternative column has other values); nan in the
    truth is not compared.  With ``per_specimen`` every specimen's first/last are compared;
    with ``specimens > 1`` and no ``per_specimen``, first/last are those of the first test.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import tomllib
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
REAL = ROOT / "tests" / "data" / "real"
#: (truth file, folder of the files) of each split.  The third round's files are not committed: they
#: are scored when ``BENDPAM_CORPUS3`` names the folder holding their ``dev/`` and ``holdout/``.
_C3 = os.environ.get("BENDPAM_CORPUS3")
SPLITS: dict[str, list[tuple[Path, Path]]] = {
    "dev": [(REAL / "truth.toml", REAL), (REAL / "dev" / "truth.toml", REAL / "dev")]
    + ([(REAL / "corpus3" / "dev" / "truth.toml", Path(_C3) / "dev")] if _C3 else []),
    "holdout": [(REAL / "holdout" / "truth.toml", REAL / "holdout")]
    + ([(REAL / "corpus3" / "holdout" / "truth.toml", Path(_C3) / "holdout")] if _C3 else []),
}
SPLITS["all"] = SPLITS["dev"] + SPLITS["holdout"]
ROLES = ("time", "stroke", "force")
KEYS = {"time": "time_s", "stroke": "stroke_mm", "force": "force_n"}


def _norm(name: Any) -> str:
    return " ".join(str(name).split()).casefold() if name is not None else ""


def _close(got: float, want: float) -> bool:
    return math.isfinite(got) and abs(got - want) <= 1e-6 * abs(want) + 1e-9


def _check_values(raw: Any, truth_first: dict, truth_last: dict, use: dict[str, bool], label: str) -> str | None:
    d = raw.data
    if len(d) == 0:
        return f"{label}: no rows"
    for which, row, want in (("first", 0, truth_first), ("last", len(d) - 1, truth_last)):
        for role in ROLES:
            w = float(want.get(KEYS[role], math.nan))
            if math.isnan(w) or not use[role]:
                continue
            g = float(d[KEYS[role]].iat[row])
            if not _close(g, w):
                return f"{label}: {which} {KEYS[role]} = {g!r}, truth {w!r}"
    return None


def _check_columns(raw: Any, entry: dict) -> tuple[str | None, dict[str, bool]]:
    """Whether each chosen column is allowed; and which roles use the truth's own column."""
    use: dict[str, bool] = {}
    for role in ROLES:
        t = entry.get(role, {})
        own = _norm(t.get("column", ""))
        allowed = {own} | {_norm(a) for a in t.get("alternatives", [])}
        src = raw.channels.get(role, {}).get("source") if raw.channels else None
        got = _norm(src)
        no_time = role == "time" and math.isnan(float(entry.get("first", {}).get("time_s", math.nan)))
        if role == "time" and (src is None or no_time):
            if own and src is None and not no_time:
                return f"time made from a rate, truth column {t.get('column')!r}", use
            use[role] = src is not None and got == own
            continue
        if got not in allowed - {""}:
            return f"{role} column {src!r}, truth {t.get('column')!r} (alternatives {t.get('alternatives', [])})", use
        use[role] = got == own
    return None, use


def score_entry(path: Path, entry: dict) -> tuple[bool, str]:
    """Score one file against its truth entry: (passed, reason)."""
    from bendpam.errors import BendpamError
    from bendpam.lab import read_tests

    try:
        tests = read_tests(path)
    except (BendpamError, ValueError) as exc:
        if entry["verdict"] == "refuse":
            return True, f"refused: {str(exc)[:160]}"
        return False, f"refused: {str(exc)[:200]}"
    except Exception as exc:  # a crash is a failure, not a refusal
        return False, f"CRASH {type(exc).__name__}: {str(exc)[:200]}"
    if entry["verdict"] == "refuse":
        n = sum(len(t) for t in tests)
        return False, f"read {n} rows in {len(tests)} test(s); truth: refuse ({entry.get('refuse_reason', '')})"
    per = entry.get("per_specimen")
    if per:
        if len(tests) != len(per):
            return False, f"{len(tests)} test(s) read, truth {len(per)} specimens"
        for raw, spec in zip(tests, per, strict=True):
            why, use = _check_columns(raw, entry)
            if why:
                return False, f"{spec['name']}: {why}"
            if len(raw) != spec["rows"]:
                return False, f"{spec['name']}: {len(raw)} rows, truth {spec['rows']}"
            why = _check_values(raw, spec["first"], spec["last"], use, spec["name"])
            if why:
                return False, why
        return True, f"{len(per)} specimens"
    rows = sum(len(t) for t in tests)
    for raw in tests:
        why, use = _check_columns(raw, entry)
        if why:
            return False, why
    if rows != entry["rows"]:
        return False, f"{rows} rows in {len(tests)} test(s), truth {entry['rows']}"
    _why, use_first = _check_columns(tests[0], entry)
    why = _check_values(tests[0], entry["first"], {}, use_first, "first test")
    # several specimens without per_specimen: first/last are those of the first specimen (README)
    last = tests[0] if int(entry.get("specimens", 1)) > 1 else tests[-1]
    if why is None:
        _why, use_last = _check_columns(last, entry)
        why = _check_values(last, {}, entry["last"], use_last, "last test")
    if why:
        return False, why
    return True, f"{rows} rows in {len(tests)} test(s)"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--split", choices=sorted(SPLITS), default="dev")
    ap.add_argument("--json", action="store_true", help="print the results as JSON")
    ap.add_argument("-v", "--verbose", action="store_true", help="print the reason of passes too")
    args = ap.parse_args(argv)
    results = []
    for truth, folder in SPLITS[args.split]:
        table = tomllib.loads(truth.read_text(encoding="utf-8"))
        label = truth.parent.relative_to(REAL)
        for name, entry in table.items():
            ok, why = score_entry(folder / name, entry)
            results.append({"file": str(label / name), "pass": ok, "reason": why})
    n_ok = sum(r["pass"] for r in results)
    if args.json:
        print(json.dumps({"split": args.split, "score": n_ok, "total": len(results), "files": results}, indent=1))
    else:
        for r in results:
            if not r["pass"] or args.verbose:
                print(f"{'PASS' if r['pass'] else 'FAIL'}  {r['file']}: {r['reason']}")
        print(f"{args.split}: {n_ok}/{len(results)} ({100.0 * n_ok / max(1, len(results)):.1f} %)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
