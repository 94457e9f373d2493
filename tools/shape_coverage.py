"""Record the calibration study's coverage of the shape C01/(C10 + C01) for the fit to read (issue 23 item 4).

    python tools/shape_coverage.py [STUDY_JSON ...] [--out src/bendpam/identify/shape_coverage.json]

``STUDY_JSON`` are what ``tools/calibration_study.py`` writes (default: every set it has written,
``benchmarks/results/calibration.json`` and ``calibration-holdout*.json``; the held-out sets count once
they have been scored, for a loop law the fit was not tuned on is what a user's data will have).
For every case (and processing variant) of every study it counts the runs whose shape interval was
narrow (``MaterialFit.shape_narrow``; the study's ``shape_narrow`` record, or its
``shape_determined`` for a study made before the gate existed) and how many of those covered the
truth within 2 SE; a case of a set other than ``main`` is named ``set: case``.
:func:`bendpam.identify.diagnose.study_coverage` reads the file: a fit of bending curves alone calls
a narrow shape "determined" only when that coverage reaches 85 % in every case.  Regenerate it
whenever the study is run again.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from bendpam.infra.atomic import atomic_write_text  # noqa: E402


def coverage_record(*studies: dict) -> dict:
    """The per-case counts of narrow shape intervals and of those that covered the truth, over ``studies``.

    >>> rec = coverage_record({"meta": {"commit": "abc", "date": "d", "seeds": 2}, "runs": [
    ...     {"case": "none", "variant": "none", "shape_determined": True, "shape": 0.5, "se_shape": 0.05,
    ...      "truth": {"shape": 0.55}},
    ...     {"case": "none", "variant": "none", "shape_narrow": True, "shape": 0.5, "se_shape": 0.01,
    ...      "truth": {"shape": 0.55}}]})
    >>> rec["cases"]
    {'none': {'narrow': 2, 'covered': 1}}
    """
    cases: dict[str, dict[str, int]] = {}
    for study in studies:
        _count(study, cases)
    metas = [s.get("meta", {}) for s in studies]
    return {"source": "tools/calibration_study.py, recorded by tools/shape_coverage.py",
            "sets": [m.get("set", "main") for m in metas], "commit": sorted({str(m.get("commit")) for m in metas}),
            "date": max((str(m.get("date")) for m in metas), default=None),
            "seeds": max((int(m.get("seeds") or 0) for m in metas), default=0), "cases": cases}


def _count(study: dict, cases: dict[str, dict[str, int]]) -> None:
    """Add one study's runs to ``cases``."""
    name = study.get("meta", {}).get("set", "main")
    for r in study.get("runs", []):
        if r.get("failed"):
            continue
        key = r["case"] if r.get("variant", "none") == "none" else f"{r['case']} ({r['variant']})"
        key = key if name == "main" else f"{name}: {key}"
        c = cases.setdefault(key, {"narrow": 0, "covered": 0})
        if not r.get("shape_narrow", r.get("shape_determined", False)):
            continue
        c["narrow"] += 1
        se, est, truth = r.get("se_shape"), r.get("shape"), r.get("truth", {}).get("shape")
        if se is not None and est is not None and truth is not None and abs(est - truth) <= 2.0 * se:
            c["covered"] += 1


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    results = ROOT / "benchmarks" / "results"
    ap.add_argument("study", nargs="*", type=Path,
                    default=[results / "calibration.json", *sorted(p for p in results.glob("calibration-holdout*.json")
                                                                    if p.stem.removeprefix("calibration-").isalnum())])
    ap.add_argument("--out", type=Path, default=ROOT / "src" / "bendpam" / "identify" / "shape_coverage.json")
    a = ap.parse_args(argv)
    rec = coverage_record(*(json.loads(p.read_text(encoding="utf-8")) for p in a.study))
    atomic_write_text(a.out, json.dumps(rec, indent=1) + "\n")
    for k, v in rec["cases"].items():
        print(f"{k}: {v['covered']} of {v['narrow']} narrow intervals covered the truth")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
