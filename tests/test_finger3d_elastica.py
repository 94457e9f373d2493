"""The spatial finger against an independent engine: PyElastica (a test extra), one out-of-plane load, run to rest.

The comparison (a linear-elastic equivalent rod at the operating point; see tools/elastica_crosscheck.py) is
within 1 % of the finger's length at the tip at 40 elements; the tool prints the convergence table.
"""

import importlib.util
from pathlib import Path

import pytest

pytest.importorskip("elastica", reason="PyElastica is not installed (pip install 'bendpam[elastica]')")

_TOOL = Path(__file__).resolve().parents[1] / "tools" / "elastica_crosscheck.py"
_spec = importlib.util.spec_from_file_location("bendpam_elastica_crosscheck", _TOOL)
crosscheck_tool = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(crosscheck_tool)


def test_out_of_plane_tip_force_agrees_with_pyelastica():
    r = crosscheck_tool.crosscheck(40, steps_per_element=600, final_time_ms=600.0)
    assert r["rest_speed_mm_per_ms"] < 1e-3  # run to rest
    assert r["tip_displacement_mm"] > 15.0  # a real out-of-plane deflection, not a trivial one
    assert r["difference_of_length"] < 0.01
