"""Record the calibration study's coverage of the shape C01/(C10 + C01) for the fit to read (issue 23 item 4).

    python tools/shape_coverage.py [STUDY_JSON] [--out src/bendpam/identify/shape_coverage.json]

``STUDY_JSON`` is what ``tools/calibration_study.py`` writes (default
``benchmarks/results/calibration.json``).  For every case (and processing variant) of the study it
counts the runs whose shape interval was narrow (``MaterialFit.shape_narrow``; the study's
``shape_narrow`` record, or its ``shape_determined`` for a study made before the gate existed) and
how many of those covered the truth within 2 SE.  :func:`bendpam.identify.diagnose.study_coverage`
reads the file: a fit of bending curves alone calls a narrow shape "determined" only when that
coverage reaches 85 % in every case.  Regenerate it whenever the study is run again.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from bendpam.infra.atomic import atomic_write_text  # noqa: E402


def coverage_record(study: dict) -> dict:
    """The per-case counts of narrow shape intervals and of those that covered the truth.

    >>> rec = coverage_record({"meta": {"commit": "abc", "date": "d", "seeds": 2}, "runs": [
    ...     {"case": "none", "variant": "none", "shape_determined": True, "shape": 0.5, "se_shape": 0.05,
    ...      "truth": {"shape": 0.55}},
    ...     {"case": "none", "variant": "none", "shape_narrow": True, "shape": 0.5, "se_shape": 0.01,
    ...      "truth": {"shape": 0.55}}]})
    >>> rec["cases"]
    {'none': {'narrow': 2, 'covered': 1}}
    """
    cases: dict[str, dict[str, int]] = {}
    for r in study.get("runs", []):
        if r.get("failed"):
            continue
        key = r["case"] if r.get("variant", "none") == "none" else f"{r['case']} ({r['variant']})"
        c = cases.setdefault(key, {"narrow": 0, "covered": 0})
        if not r.get("shape_narrow", r.get("shape_determined", False)):
            continue
        c["narrow"] += 1
        se, est, truth = r.get("se_shape"), r.get("shape"), r.get("truth", {}).get("shape")
        if se is not None and est is not None and truth is not None and abs(est - truth) <= 2.0 * se:
            c["covered"] += 1
    meta = study.get("meta", {})
    return {"source": "tools/calibration_study.py, recorded by tools/shape_coverage.py",
            "commit": meta.get("commit"), "date": meta.get("date"), "seeds": meta.get("seeds"), "cases": cases}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("study", nargs="?", type=Path, default=ROOT / "benchmarks" / "results" / "calibration.json")
    ap.add_argument("--out", type=Path, default=ROOT / "src" / "bendpam" / "identify" / "shape_coverage.json")
    a = ap.parse_args(argv)
    rec = coverage_record(json.loads(a.study.read_text(encoding="utf-8")))
    atomic_write_text(a.out, json.dumps(rec, indent=1) + "\n")
    for k, v in rec["cases"].items():
        print(f"{k}: {v['covered']} of {v['narrow']} narrow intervals covered the truth")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
