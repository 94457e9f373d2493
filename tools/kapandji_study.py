"""How the Kapandji test of the soft hand moves with the thumb's geometry (the study quoted in docs/hand.md).

The paper gives no dimensions of its hand, so bendpam's default hand is an assumption (adult
proportions, the thumb at 35 deg from the index at rest).  This runs the test for the default and
a few other thumbs (rest direction, base position) and prints, per point, what touches it and the
tip's (and the thumb's) closest distance.  Run ``python tools/kapandji_study.py [--grid 9]``; the
test suite runs the default hand's test at a small grid (tests/test_hand.py).  Units: mm, deg.
"""

from __future__ import annotations

import argparse
import dataclasses

from bendpam.design.hand import default_hand
from bendpam.design.kapandji import kapandji

#: the thumbs compared: a label and the Hand fields that differ from the default
VARIANTS = (
    ("default (35 deg, base 52, 45 mm)", {}),
    ("rest direction 10 deg", {"thumb_direction_deg": 10.0}),
    ("parallel to the index, base 45, 50 mm", {"thumb_direction_deg": 0.0, "thumb_base_mm": (45.0, 50.0)}),
    ("15 deg, base 42, 60 mm", {"thumb_direction_deg": 15.0, "thumb_base_mm": (42.0, 60.0)}),
)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--grid", type=int, default=6, help="grid points per freedom of the starting grid")
    parser.add_argument("--starts", type=int, default=2, help="local optimisations per point")
    args = parser.parse_args(argv)
    base = default_hand()
    for label, changes in VARIANTS:
        res = kapandji(dataclasses.replace(base, **changes), grid=args.grid, starts=args.starts)
        cells = [f"{p.number}:{p.touched_by}({p.distance_mm:.1f}/{p.thumb_distance_mm:.1f})" for p in res.points]
        print(f"{label:<40} score {res.score}  " + " ".join(cells))
    print("cells: point:touched_by(tip distance / closest thumb distance), mm")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
