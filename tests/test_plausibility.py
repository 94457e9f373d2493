"""Physical plausibility at every entry (issue 21 item 4, docs/plausibility.md).

* Every public callable of ``bendpam.predict``, :class:`MomentLaw`, :class:`MomentTable`,
  :func:`limits`, :func:`curvature_limits`, :func:`kinematics` (and the actuator, the fixture and the
  tension fit), given a hostile value in any one argument (None, NaN, +-inf, +-1e308, a string, an
  empty list, a list of strings, a huge int, a million NaN), returns a finite result or raises
  :class:`InputError` with one line; never another exception.  Checked exhaustively (every callable x
  argument x hostile value) and as a Hypothesis property.
* With finite, plausible inputs the results are finite (NaN only where documented: no free-bending
  equilibrium past the fold).
* The plausible ranges accept the presets and refuse the audit's absurd values in one line that
  names the key, the value and the range; pressures above the burst limit are refused unless the
  actuator's ``max_pressure_kpa`` is raised; results beyond a plausibility bound warn.
"""

from __future__ import annotations

import dataclasses
import math
import re
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import bendpam
from bendpam import InputError, MomentLaw, MomentTable, PlausibilityWarning, presets
from bendpam.cli.app import main
from bendpam.identify.tension import fit_tension
from bendpam.physics import braid
from bendpam.physics import limits as limits_mod
from bendpam.physics.fixture import Fixture
from bendpam.physics.material import MooneyRivlin
from bendpam.validate import DEFAULT_MAX_PRESSURE_KPA, PLAUSIBLE
from strategies import actuators

DOCS = Path(__file__).resolve().parent.parent / "docs"

HOSTILE = {
    "None": None,
    "nan": math.nan,
    "inf": math.inf,
    "-inf": -math.inf,
    "1e308": 1e308,
    "-1e308": -1e308,
    "str": "x",
    "empty": [],
    "strings": ["a", "b"],
    "huge-int": 10**400,
    "nan-array": np.full(1_000_000, np.nan),
    "object": object(),
}

BE = presets.be_pam()
BE_FB = presets.be_pam("force_balance")
LAW = MomentLaw.of(BE)
TABLE = LAW.tabulated()
LIM = bendpam.curvature_limits(BE)


# (name, callable, valid positional arguments): each argument is replaced in turn by every hostile value
def _calls():
    P, K = 150.0, 0.01
    return [
        # bendpam.predict
        ("predict.active_pressure_kpa", bendpam.active_pressure_kpa, (BE, P)),
        ("predict.blocked_moment", bendpam.blocked_moment, (BE, P, "energy")),
        ("predict.free_branch", bendpam.free_branch, (BE, "energy")),
        ("predict.free_curvature", lambda a, p, m, x: bendpam.free_curvature(a, p, m, xtol=x),
         (BE, P, "energy", 1e-13)),
        ("predict.internal_stresses", lambda a, p, k, n: bendpam.internal_stresses(a, p, k, n_phi=n),
         (BE_FB, P, K, 181)),
        ("predict.kinematics", lambda a, k, o: bendpam.kinematics(a, k, order=o), (BE, K, 0)),
        ("predict.moment", lambda a, p, k, m, e: bendpam.moment(a, p, k, m, eq19_factor=e), (BE, P, K, "energy", True)),
        ("predict.moment_terms", bendpam.moment_terms, (BE, P, K, "force_balance")),
        ("predict.prediction_table", bendpam.prediction_table, (BE, [100.0, P], "energy")),
        ("predict.tangent_stiffness", bendpam.tangent_stiffness, (BE, P, K)),
        # MomentLaw
        ("MomentLaw()", lambda a, m, e, o: MomentLaw(a, m, eq19_factor=e, order=o), (BE, "energy", True, 0)),
        ("MomentLaw.of", lambda a, m, o: MomentLaw.of(a, m, order=o), (BE, "energy", 0)),
        ("MomentLaw.coefficients", LAW.coefficients, (K,)),
        ("MomentLaw.basis", LAW.basis, (K,)),
        ("MomentLaw.check_curvature", LAW.check_curvature, (K,)),
        ("MomentLaw.check_pressure", LAW.check_pressure, (P,)),
        ("MomentLaw.active_pressure_kpa", LAW.active_pressure_kpa, (P,)),
        ("MomentLaw.moment", LAW.moment, (P, K)),
        ("MomentLaw.blocked_moment", LAW.blocked_moment, (P,)),
        ("MomentLaw.terms", LAW.terms, (P, K)),
        ("MomentLaw.tangent_stiffness", LAW.tangent_stiffness, (P, K)),
        ("MomentLaw.branches", LAW.branches, (64,)),
        ("MomentLaw.free_curvature_array", lambda p, x: LAW.free_curvature_array(p, xtol=x), (P, 1e-13)),
        ("MomentLaw.free_state_array", lambda p, x: LAW.free_state_array(p, xtol=x), (P, 1e-13)),
        ("MomentLaw.free_curvature", lambda p, x: LAW.free_curvature(p, xtol=x), (P, 1e-13)),
        ("MomentLaw.stable_branch", LAW.stable_branch, (P, 0.0)),
        ("MomentLaw.tabulated", LAW.tabulated, (1e-6,)),
        # MomentTable
        ("MomentTable()", lambda law, n, t: MomentTable(law, knots=n, tol=t), (LAW, 65, 1e-3)),
        ("MomentTable.coefficients", TABLE.coefficients, (K,)),
        ("MomentTable.derivatives", TABLE.derivatives, (K,)),
        ("MomentTable.moment", TABLE.moment, (P, K)),
        ("MomentTable.tangent_stiffness", TABLE.tangent_stiffness, (P, K)),
        ("MomentTable.free_curvature", lambda p, n: TABLE.free_curvature(p, newton_steps=n), (P, 6)),
        # limits, lock-up limits, kinematics
        ("limits", lambda a, p, m, o: bendpam.limits(a, p, m, order=o), (BE, [100.0, P], "energy", 0)),
        ("section_limits", lambda a, p, k, f, lk: limits_mod.section_limits(
            a, p, k, external_axial_force_n=f, lockup_curvature_per_mm=lk), (BE, P, [0.0, K], 0.0, 0.1)),
        ("buckling_load", limits_mod.buckling_load, (353.96, 3.52, 145.0)),
        ("foundation_modulus", limits_mod.foundation_modulus, (BE.params, 1.0)),
        ("frame_width_mm", limits_mod.frame_width_mm, (BE.params,)),
        ("curvature_limits", bendpam.curvature_limits, (BE, 0)),
        ("braid.kinematics", braid.kinematics, (BE, K, 0)),
        ("CurvatureLimits.check", LIM.check, (K,)),
        # the entries of the inputs themselves
        ("Actuator", lambda *v: bendpam.Actuator(*v), tuple(getattr(BE, f) for f in (
            "alpha0_deg", "R0_mm", "t0_mm", "L0_mm", "frame_thickness_mm", "frame_width_mm", "frame_modulus_mpa",
            "C10_kpa", "C01_kpa", "P_start_kpa", "R0_start_mm", "braid_thickness_mm"))),
        ("Actuator.max_pressure_kpa", lambda v: BE.replace(max_pressure_kpa=v), (3000.0,)),
        ("Actuator.frame_strength_mpa", lambda v: BE.replace(frame_strength_mpa=v), (400.0,)),
        ("Actuator.bladder_stretch_limit", lambda v: BE.replace(bladder_stretch_limit=v), (3.0,)),
        ("Fixture", Fixture, (35.0, 2.5, 4.0, 145.0)),
        ("Fixture.convert", Fixture().convert, (10.0, 5.0, 0.0)),
        ("fit_tension", fit_tension, (np.linspace(1.0, 2.0, 11),
                                      MooneyRivlin(0.2, 0.1).uniaxial_nominal_stress(np.linspace(1.0, 2.0, 11)) * 1e3)),
    ]


CALLS = _calls()
CASES = [(name, i, h) for name, _, args in CALLS for i in range(len(args)) for h in HOSTILE]


def _numbers(obj, seen=None):
    """Every float array of a result (arrays, tuples, dicts, dataclasses, DataFrames, Datasets)."""
    seen = set() if seen is None else seen
    if id(obj) in seen:
        return
    seen.add(id(obj))
    if isinstance(obj, np.ndarray | np.floating | float) and np.asarray(obj).dtype.kind in "fc":
        yield np.asarray(obj)
    elif isinstance(obj, tuple | list):
        for x in obj:
            yield from _numbers(x, seen)
    elif isinstance(obj, dict):
        for x in obj.values():
            yield from _numbers(x, seen)
    elif dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        for f in dataclasses.fields(obj):
            yield from _numbers(getattr(obj, f.name), seen)
    elif hasattr(obj, "to_numpy") and hasattr(obj, "columns"):  # DataFrame
        for c in obj.columns:
            yield from _numbers(np.asarray(obj[c]), seen)
    elif hasattr(obj, "data_vars"):  # Dataset
        for v in obj.data_vars.values():
            yield from _numbers(np.asarray(v), seen)


def _call(name: str, i: int, value):
    """Call ``name`` with its ``i``-th argument replaced by ``value``: ``"ok"`` (a finite result), ``"refused"``
    (one InputError line), else the failure as text."""
    fn, args = next((f, a) for n, f, a in CALLS if n == name)
    args = list(args)
    args[i] = value
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # UnitWarning, PlausibilityWarning: not the subject here
            res = fn(*args)
    except InputError as exc:
        text = str(exc)
        return "refused" if text and "\n" not in text and len(text) < 600 else f"InputError not one line: {text!r}"
    except Exception as exc:  # the point: no other exception
        return f"{type(exc).__name__}: {exc}"
    # plain numbers must be finite; structured results (limits, branches) may hold inf margins ("no demand"), never NaN
    plain = isinstance(res, np.ndarray | float) or (isinstance(res, tuple)
                                                   and all(isinstance(x, np.ndarray) for x in res))
    bad = [a for a in _numbers(res) if a.size and not np.all(np.isfinite(a) if plain else ~np.isnan(a))]
    return "ok" if not bad else f"returned a non-finite number for {value!r:.40}"


def test_every_callable_argument_and_hostile_value():
    """The exhaustive table: every (callable, argument, hostile value) is refused in one line or answered finitely."""
    failures, counts = [], {"refused": 0, "ok": 0}
    for name, i, h in CASES:
        out = _call(name, i, HOSTILE[h])
        if out in counts:
            counts[out] += 1
        else:
            failures.append(f"{name} argument {i} = {h}: {out}")
    assert not failures, f"{len(failures)} of {len(CASES)} calls:\n" + "\n".join(failures)
    # the hostile values that are values at all (an empty list) may give an (empty) answer; the rest are refused
    assert counts["refused"] >= 0.9 * len(CASES), counts
    print(f"\n{len(CALLS)} callables, {len(CASES)} hostile calls: {counts}")


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(case=st.sampled_from(CALLS), data=st.data())
def test_property_hostile_values_are_refused_or_answered_finitely(case, data):
    name, _, args = case
    i = data.draw(st.integers(0, len(args) - 1), label="argument")
    value = data.draw(st.one_of(
        st.sampled_from(list(HOSTILE.values())),
        st.floats(allow_nan=True, allow_infinity=True).filter(lambda x: not math.isfinite(x) or abs(x) > 1e12),
        st.lists(st.sampled_from([math.nan, math.inf, -math.inf, None]), min_size=1, max_size=5),
        st.text(max_size=5),
    ), label="value")
    out = _call(name, i, value)
    assert out in ("refused", "ok"), f"{name} argument {i} = {value!r:.60}: {out}"


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(a=actuators(), frac=st.floats(0.0, 1.0), kfrac=st.floats(-1.0, 1.0),
       model=st.sampled_from(["energy", "force_balance"]))
def test_property_plausible_inputs_give_finite_results(a, frac, kfrac, model):
    """Finite, plausible inputs: finite moments, stiffness, kinematics and limits (NaN only past the branch's end)."""
    P = frac * DEFAULT_MAX_PRESSURE_KPA
    lim = bendpam.curvature_limits(a)
    k = kfrac * (lim.k_max if kfrac > 0 else -lim.k_min)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # UnitWarning (tiny pressures), PlausibilityWarning: not the subject here
        values = [bendpam.moment(a, P, k, model), bendpam.blocked_moment(a, P, model),
                  bendpam.tangent_stiffness(a, P, k, model), *bendpam.moment_terms(a, P, k, model).values()]
        kin = bendpam.kinematics(a, k)
        fb = bendpam.free_curvature(a, [0.5 * P, P], model)
        lm = bendpam.limits(a, [0.5 * P, P], model)
    assert all(np.all(np.isfinite(v)) for v in values)
    assert all(np.all(np.isfinite(x)) for x in _numbers(kin))
    ok = fb.status != "no-equilibrium"
    assert np.all(np.isfinite(fb.curvature_per_mm[ok])) and np.all(np.isnan(fb.curvature_per_mm[~ok]))
    for key, v in lm.blocked.items():
        assert not np.any(np.isnan(v)), key  # margins may be inf (no demand, no limit); never NaN
    assert not np.any(np.isnan(lm.frame_axial_force_n))


def _kernels():
    """The numerics under the validated entries (model units; NaN in, NaN out by design): wrong kinds are refused."""
    from bendpam.physics import actuator, branch, material, roots, sections, stable
    from bendpam.physics.models import energy, force_balance

    p, a0, k = BE.params, BE.params.alpha0, np.array([0.0, 0.01])
    return [
        ("energy.coefficients", energy.coefficients, (p, k)), ("energy.basis", energy.basis, (p, k)),
        ("energy.terms", energy.terms, (p, 0.1, k)), ("energy.bladder_energy", energy.bladder_energy, (p, k)),
        ("force_balance.coefficients", force_balance.coefficients, (p, k)),
        ("force_balance.basis", force_balance.basis, (p, k)), ("force_balance.terms", force_balance.terms, (p, 0.1, k)),
        ("force_balance.stress_state", force_balance.stress_state, (p, 0.1, k, np.array([0.0, 1.0]))),
        ("force_balance.axial_forces", force_balance.axial_forces, (p, 0.1, k, 10.0 + k)),
        ("braid.solve_u", braid.solve_u, (k, a0)), ("braid.radius_state", braid.radius_state, (k, a0, 10.1)),
        ("braid.radius_terms", braid.radius_terms, (k, a0, 10.1)),
        ("braid.circle_ibar", braid.circle_ibar, (k, math.cos(a0))),
        ("braid.ibar_closed_form", braid.ibar_closed_form, (k, math.cos(a0))),
        ("braid.radius_from_u", braid.radius_from_u, (k, np.ones(2), np.zeros(2), a0, 10.1)),
        ("braid.limits", braid.limits, (p,)), ("braid.braid_range", braid.braid_range, (p,)),
        ("actuator.t0_start_mm", actuator.t0_start_mm, (8.5, 2.5, 10.1)),
        ("actuator.bladder_area_mm2", actuator.bladder_area_mm2, (8.5, 2.5)),
        ("actuator.frame_inertia_mm4", actuator.frame_inertia_mm4, (5.0, 0.5)),
        ("material.MooneyRivlin", MooneyRivlin, (0.2, 0.1)), ("material.within", material.within, (0.5, 0.0, 1.0)),
        ("branch.branch_table", branch.branch_table, (LAW, 64)),
        ("branch.describe_branch", branch.describe_branch, (LAW, LAW.branches())),
        ("branch.solve_free", branch.solve_free, (LAW, LAW.branches(), np.array([[50.0]]))),
        ("sections.branch_path", sections.branch_path, (LAW,)),
        ("sections.SectionTables", sections.SectionTables, (energy, a0, 0)),
        ("stable.stable_branch", stable.stable_branch, (TABLE, 150.0, 0.0)),
        ("roots.illinois", lambda f, a, b: roots.illinois(f, a, b, 1e-12), (lambda x, idx: 0.5 - x, 0.0, 1.0)),
        ("roots.bracketed_newton", lambda f, x: roots.bracketed_newton(f, x, 0.0, 1.0, maxiter=20),
         (lambda x: (x - 0.5, np.ones_like(x)), 0.2)),
        ("hysteresis.loss_ratio", bendpam.hysteresis.loss_ratio, (k, np.ones(2), np.zeros(2), 145.0)),
    ]


@pytest.mark.parametrize("name, fn, args", _kernels(), ids=[c[0] for c in _kernels()])
def test_the_numerics_kernels_refuse_wrong_kinds(name, fn, args):
    fn(*args)  # the valid call works
    for i in range(len(args)):
        for bad in (None, "x", ["a"], object()):
            call = list(args)
            call[i] = bad
            with pytest.raises(InputError):
                fn(*call)


# ------------------------------------------------------------------------------------------------
# the audit's findings, one by one
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("change, words", [
    (dict(R0_start_mm=1e22), ["R0_start_mm = 1e+22 mm", "plausible range [R0_mm, 3 R0_mm] = [8.5, 25.5] mm"]),
    (dict(alpha0_deg=0.001), ["alpha0_deg = 0.001 deg", "[10, 88] deg", "braid"]),
    (dict(frame_thickness_mm=1e308), ["frame_thickness_mm = 1e+308 mm", "[0.005, 50] mm"]),
    (dict(frame_modulus_mpa=1e7), ["frame_modulus_mpa = 1e+07 MPa", "[0.5, 450000] MPa", "steel"]),
    (dict(C10_kpa=1.1e8), ["C10_kpa = 1.1e+08 kPa", "100 MPa"]),
    (dict(P_start_kpa=3000.0), ["P_start_kpa = 3000 kPa", "[0, max_pressure_kpa] = [0, 2000] kPa"]),
    (dict(L0_mm=10**400), ["L0_mm", "not finite"]),
    (dict(t0_mm=0.001), ["t0_mm = 0.001 mm", "[0.01, R0_mm) = [0.01, 8.5) mm"]),
    (dict(max_pressure_kpa=1e9), ["max_pressure_kpa = 1e+09 kPa", "[1, 100000] kPa"]),
])
def test_absurd_actuator_values_are_one_line_with_key_value_and_range(change, words):
    with pytest.raises(InputError) as exc:
        BE.replace(**change)
    msg = str(exc.value)
    assert "\n" not in msg
    for w in words:
        assert w in msg, msg


def test_the_ranges_accept_the_presets_and_every_field_has_a_documented_reason():
    for name in ("be-pam", "bc-pam"):
        for model in ("energy", "force_balance"):
            presets.get(name, model)  # no error
    page = (DOCS / "plausibility.md").read_text(encoding="utf-8")
    for key, bound in PLAUSIBLE.items():
        assert f"`{key}`" in page, key
        assert bound.reason and bound.lo < bound.hi, key
    assert "plausibility.md" in (DOCS.parent / "mkdocs.yml").read_text(encoding="utf-8")


def test_pressure_above_the_burst_limit_is_refused_unless_raised():
    with pytest.raises(InputError, match=r"1e\+06 kPa .* above the burst limit 2000 kPa.*max_pressure_kpa"):
        bendpam.blocked_moment(BE, 1e6)  # 1 GPa: the audit's 2.35e6 N*mm
    with pytest.raises(InputError, match="burst limit"):
        bendpam.limits(presets.bc_pam(), 1e6)  # was NaN
    with pytest.raises(InputError, match="burst limit"):
        LAW.stable_branch(2500.0)  # the finger's path
    with pytest.raises(InputError, match="burst limit"):
        bendpam.sweep(BE, [100.0, 2500.0], alpha0_deg=[65.0, 70.0])
    hyd = BE.replace(max_pressure_kpa=5000.0)
    # the blocked moment is pi R0_start^3 (1 - 2 cot^2 alpha0) P_a: linear in the active pressure
    expected = math.pi * 10.1**3 * (1 - 2 / math.tan(math.radians(69.7)) ** 2) * (3000.0 - 68.0) * 1e-3
    assert float(bendpam.blocked_moment(hyd, 3000.0)) == pytest.approx(expected, rel=1e-12)
    ds = bendpam.sweep(hyd, [100.0, 3000.0], alpha0_deg=[69.7])
    assert float(ds["blocked_moment_nmm"][0, 1]) == pytest.approx(expected, rel=1e-9)
    with pytest.raises(InputError, match="burst limit 5000 kPa"):
        bendpam.moment(hyd, 6000.0, 0.0)


def test_max_pressure_round_trips_through_toml(tmp_path):
    a = BE.replace(max_pressure_kpa=5000.0)
    p = tmp_path / "a.toml"
    a.to_toml(p)
    assert "max_pressure_kpa = 5000.0" in p.read_text()
    assert bendpam.Actuator.from_toml(p) == a
    p.write_text(BE.to_toml().replace("max_pressure_kpa = 2000.0", "max_pressure_kpa = 1e308"))
    with pytest.raises(InputError, match=r"max_pressure_kpa = 1e\+308 kPa is outside the plausible range"):
        bendpam.Actuator.from_toml(p)
    p.write_text(BE.to_toml().replace("frame_thickness_mm = 0.5", "frame_thickness_mm = 1e308"))
    with pytest.raises(InputError, match="frame_thickness_mm = 1e\\+308 mm"):  # was an internal OverflowError
        bendpam.Actuator.from_toml(p)


def test_curvatures_nan_inf_and_absurd_are_refused_with_the_range():
    with pytest.raises(InputError, match="non-finite"):
        LAW.coefficients(math.nan)
    with pytest.raises(InputError, match="non-finite"):
        LAW.moment(150.0, math.inf)
    with pytest.raises(InputError, match=r"k' = 1e\+09 1/mm is beyond the braid lock-up .* allowed range \["):
        LAW.coefficients(1e9)
    with pytest.raises(InputError, match="lock-up"):
        LAW.basis([0.0, 1e9])
    with pytest.raises(InputError):
        bendpam.curvature_limits(None)  # was AttributeError


def test_wrong_kinds_are_input_errors_and_still_type_errors():
    for call in (lambda: bendpam.moment("be-pam", 100.0, 0.0), lambda: MomentLaw(None),
                 lambda: bendpam.limits(BE.params, 100.0), lambda: bendpam.kinematics({"alpha0_deg": 70}, 0.0)):
        with pytest.raises(InputError) as exc:
            call()
        assert isinstance(exc.value, TypeError) and isinstance(exc.value, bendpam.InputTypeError)


def test_tension_stresses_beyond_a_rubber_are_refused():
    lam = np.linspace(1.0, 2.0, 11)
    stress = MooneyRivlin(0.2, 0.1).uniaxial_nominal_stress(lam) * 1e3
    with pytest.raises(InputError, match=r"nominal_stress_kpa = .* at index 1 .* 100 MPa"):
        fit_tension(lam, stress * 1e6)  # the audit's x1e6: C10 = 1.1e8 kPa was accepted
    with pytest.raises(bendpam.FitError, match="fitted C10_kpa"):
        fit_tension(1.0 + (lam - 1.0) * 1e-3, stress * 10)  # tiny strains, large stresses: C10 beyond 100 MPa
    with pytest.raises(InputError, match="stretch = 50 at index 10"):
        fit_tension(np.r_[lam[:10], 50.0], stress)


def test_fixture_refuses_absurd_dimensions_in_one_line():
    with pytest.raises(InputError, match=r"fixture L0_mm = 1e\+308 mm is outside the plausible range \[1, 5000\]"):
        Fixture(35.0, 2.5, 4.0, 1e308)  # was an internal LinAlgError in processing
    with pytest.raises(InputError, match=r"fixture d_mm = 1e\+06 mm"):
        Fixture(1e6, 2.5, 4.0, 145.0)
    Fixture(20.0, 0.0, 0.0, 100.0)  # the test fixtures stay valid


# ------------------------------------------------------------------------------------------------
# results beyond a plausibility bound
# ------------------------------------------------------------------------------------------------
def test_a_free_angle_beyond_a_full_turn_warns():
    long = BE.replace(L0_mm=1000.0)
    with pytest.warns(PlausibilityWarning, match=r"free-bending angle 775 deg at 200 kPa is beyond a full turn"):
        fb = bendpam.free_curvature(long, [100.0, 200.0])
    # the number is still the model's: k' L0 (the curvature does not depend on the length)
    assert fb.angle_deg[1] == pytest.approx(math.degrees(float(bendpam.free_curvature(BE, 200.0).curvature_per_mm))
                                            * 1000.0, rel=1e-9)
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlausibilityWarning)
        bendpam.free_curvature(BE, [100.0, 200.0])  # 112 deg: no warning
        bendpam.prediction_table(BE, [100.0, 200.0])


def test_a_frame_strained_beyond_a_beam_warns():
    soft = BE.replace(frame_thickness_mm=20.0, frame_width_mm=0.05, frame_modulus_mpa=0.5)
    with pytest.warns(PlausibilityWarning, match=r"frame bending strain h \|k'\| / 2 = .* % at 400 kPa"):
        bendpam.limits(soft, [100.0, 400.0])


def test_a_moment_beyond_the_mckibben_bound_warns():
    from bendpam.physics.law import _flag_moment

    p = BE.params
    bound = math.pi * 10.1**3 * (1 + 2 / math.tan(p.alpha0) ** 2) * 0.1  # N*mm at 100 kPa
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlausibilityWarning)
        _flag_moment(p, 100.0, 9.9 * bound, "blocked moment")
    with pytest.warns(PlausibilityWarning, match="beyond 10 times the McKibben bound"):
        _flag_moment(p, 100.0, 10.1 * bound, "blocked moment")


def test_cli_shows_a_plausibility_warning_as_one_line(tmp_path, capsys):
    f = tmp_path / "long.toml"
    f.write_text(BE.replace(L0_mm=1000.0).to_toml())
    assert main(["predict", "--actuator", str(f), "--pressure-kpa", "100", "200"]) == 0
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if "full turn" in line]
    assert len(lines) == 1 and re.match(r"bendpam: warning: free-bending angle 775 deg at 200 kPa", lines[0]), err


def test_cli_refuses_a_pressure_above_the_burst_limit_and_says_where_to_raise_it(capsys):
    assert main(["predict", "--preset", "be-pam", "--pressure-kpa", "3000"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and err.startswith("bendpam: error: --pressure-kpa 3000 kPa")
    assert "--actuator" in err and "max_pressure_kpa" in err


def test_cli_refuses_an_absurd_l0(tmp_path, capsys):
    assert main(["process", str(tmp_path), "--out", str(tmp_path / "out"), "--l0-mm", "1e308"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "--l0-mm = 1e+308 mm is outside the plausible range [1, 5000] mm" in err
