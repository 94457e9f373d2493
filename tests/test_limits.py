"""Structural limits (issue 15 item 1): frame force and stress, buckling on the bladder, lock-up, bladder stretch.

Hand computations (the buckling margin of one frame, written out), the McKibben force at k' = 0, the
force balance against the force-balance stress state, the sweep against the direct evaluation, the
CLI's warning, and bad input.
"""

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

import bendpam
from bendpam import Actuator, presets
from bendpam.cli import main
from bendpam.errors import InputError, NoEquilibrium
from bendpam.physics.limits import buckling_load, foundation_modulus, section_limits
from bendpam.physics.models import force_balance

MARGINS = ("frame_strength_margin", "buckling_margin", "lockup_margin", "bladder_stretch_margin")


# ------------------------------------------------------------------------------------------------
# buckling: the margin of the paper's BC-PAM frame by hand
# ------------------------------------------------------------------------------------------------
def test_buckling_margin_of_one_frame_by_hand():
    """The paper's BC-PAM (Table 1 frame, Table 3 energy constants), blocked at 200 kPa."""
    a = presets.bc_pam("energy")
    # frame: glass-fibre epoxy strip 0.5 x 5 mm, E_f = 6796 MPa, L0 = 145 mm
    EI = 6796.0 * 5.0 * 0.5**3 / 12.0  # = 353.9583 N*mm^2
    assert EI == pytest.approx(353.9583, abs=1e-4)
    # foundation: the bladder wall under the frame, E_bl = 6 (C10 + C01) = 6 (1485.3 - 1196.8) kPa = 1.731 MPa,
    # thickness t0_start = 8.6 - sqrt(8.6^2 - 2 * 8.5 * 2.5 + 2.5^2) = 2.45915 mm (eq 52), width 5 mm
    t0s = 8.6 - math.sqrt(8.6**2 - 2 * 8.5 * 2.5 + 2.5**2)
    assert t0s == pytest.approx(2.45915, abs=1e-5)
    beta = 1.731 * 5.0 / t0s  # = 3.51951 N/mm^2
    assert beta == pytest.approx(3.51951, abs=1e-5)
    # half-waves: m* = (145 / pi) (beta / EI)^(1/4) = 14.575, so m = 14 or 15
    m_star = 145.0 / math.pi * (beta / EI) ** 0.25
    assert m_star == pytest.approx(14.575, abs=1e-3)
    n14 = EI * (14 * math.pi / 145) ** 2 + beta * (145 / (14 * math.pi)) ** 2  # = 32.566 + 38.253 = 70.819 N
    n15 = EI * (15 * math.pi / 145) ** 2 + beta * (145 / (15 * math.pi)) ** 2  # = 37.385 + 33.322 = 70.707 N
    assert n14 == pytest.approx(70.819, abs=1e-3) and n15 == pytest.approx(70.707, abs=1e-3)
    n_cr = min(n14, n15)  # 2 sqrt(beta EI) = 70.59 N is the long-beam limit, just below
    assert 2 * math.sqrt(beta * EI) < n_cr
    # frame force at k' = 0: N = P_a pi R0_start^2 (1 - 2 cot^2 alpha0), P_a = 0.200 - 0.032 = 0.168 MPa
    cot2 = 1.0 / math.tan(math.radians(36.57)) ** 2  # = 1.81737
    N = 0.168 * math.pi * 8.6**2 * (1.0 - 2.0 * cot2)  # = 0.168 * 232.353 * (-2.63474) = -102.82 N
    assert N == pytest.approx(-102.82, abs=0.01)
    margin = n_cr / -N  # = 70.707 / 102.82 = 0.6877
    assert margin == pytest.approx(0.6877, abs=1e-4)

    lim = bendpam.limits(a, [200.0])
    assert lim.blocked["buckling_load_n"][0] == pytest.approx(n_cr, rel=1e-12)
    assert lim.blocked["buckling_half_waves"][0] == 15
    assert lim.blocked["foundation_modulus_n_per_mm2"][0] == pytest.approx(beta, rel=1e-12)
    assert lim.blocked["axial_force_n"][0] == pytest.approx(N, rel=1e-12)
    assert lim.buckling_margin[0] == pytest.approx(margin, rel=1e-12)
    assert float(foundation_modulus(a.params)) == pytest.approx(beta, rel=1e-12)
    assert lim.violations[0] == "frame buckling: margin 0.69 at 200 kPa (blocked)"


def test_hetenyi_formula_against_a_finite_difference_eigenvalue():
    """Pinned beam on a Winkler foundation: the closed form is the smallest eigenvalue; clamped ends only raise it."""
    from scipy.linalg import eigh

    EI, L, n = 353.96, 145.0, 600
    h = L / n
    N = n - 1  # interior nodes, w = 0 at both ends
    D2 = (np.diag(np.full(N, -2.0)) + np.diag(np.ones(N - 1), 1) + np.diag(np.ones(N - 1), -1)) / h**2
    D4 = np.zeros((N, N))
    for i in range(N):
        for j, c in zip(range(i - 2, i + 3), (1.0, -4.0, 6.0, -4.0, 1.0), strict=True):
            if 0 <= j < N:
                D4[i, j] += c
    for beta in (0.0, 0.05, 3.5):
        got = {}
        for bc, ghost in (("pinned", -1.0), ("clamped", 1.0)):  # w_-1 = -w_1 (w'' = 0) or w_1 (w' = 0)
            A = D4.copy()
            A[0, 0] += ghost
            A[-1, -1] += ghost
            got[bc] = eigh(EI * A / h**4 + beta * np.eye(N), -D2, eigvals_only=True, subset_by_index=[0, 0])[0]
        n_cr, m = buckling_load(EI, beta, L)
        assert got["pinned"] == pytest.approx(float(n_cr), rel=2e-3), beta
        assert got["clamped"] >= got["pinned"]
    assert float(buckling_load(EI, 0.0, L)[0]) == pytest.approx(math.pi**2 * EI / L**2, rel=1e-14)  # Euler
    # vectorised: m jumps where the two neighbouring integers exchange
    n_cr, m = buckling_load(EI, np.array([0.0, 0.01, 3.5, 50.0]), L)
    assert n_cr.shape == (4,) and m[0] == 1 and np.all(np.diff(m) >= 0)


def test_paper_bc_pam_buckles_between_its_test_pressures_and_200_kpa():
    """Tested 40-140 kPa without failure; the frame buckled in the blocked test near 200 kPa (802 N*mm)."""
    for model in ("energy", "force_balance"):
        lim = bendpam.limits(presets.bc_pam(model), [40.0, 140.0, 200.0], model)
        assert lim.buckling_margin[0] > 10 and lim.buckling_margin[1] > 1.0 > lim.buckling_margin[2]
        assert lim.blocked["buckling_margin"][2] == lim.buckling_margin[2]  # the blocked state governs
        assert not np.any(lim.free["buckling_margin"] < 1.0)  # free bending relieves the compression


# ------------------------------------------------------------------------------------------------
# the frame's axial force
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("alpha0_deg", [30.0, 36.57, 50.0, 54.0, 60.0, 69.7, 80.0])
def test_axial_force_at_zero_curvature_is_the_mckibben_force(alpha0_deg):
    a = presets.be_pam().replace(alpha0_deg=alpha0_deg)
    P = np.array([80.0, 150.0, 250.0])
    lim = bendpam.limits(a, P)
    pa = (P - a.P_start_kpa) * 1e-3  # MPa
    al = math.radians(alpha0_deg)
    R = a.R0_start_mm
    mckibben = pa * math.pi * R**2 * (3 * math.cos(al) ** 2 - 1) / math.sin(al) ** 2  # contraction force
    assert_allclose(lim.blocked["axial_force_n"], -mckibben, rtol=1e-12)
    # the frame holds the actuator's axial force at the lever arm R0_start: N R0_start = M(P, 0)
    assert_allclose(lim.blocked["axial_force_n"] * R, bendpam.blocked_moment(a, P), rtol=1e-12)


def test_axial_forces_integrate_the_force_balance_stress_state(preset_model):
    """``axial_forces`` is the section integral of :func:`force_balance.stress_state` (eq 43-48), any curvature."""
    a, _ = preset_model
    p = a.params
    phi, wbar = bendpam.physics.braid.gauss_nodes(32)
    for k in np.linspace(-0.8, 0.8, 5) * min(-bendpam.curvature_limits(a).k_min, bendpam.curvature_limits(a).k_max):
        for pa in (0.0, 0.05, 0.15):
            kin = bendpam.kinematics(a, k)
            f = force_balance.axial_forces(p, pa, kin.u, kin.radius)
            st = force_balance.stress_state(p, pa, k, phi)
            R, tb = st["R"], st["t_bar"]
            f_br = 2 * np.pi * R * (st["N_br1"] @ wbar)
            f_bl = 2 * np.pi * R * tb * ((st["sigma_bl1"] + pa) @ wbar)  # elastic part: without -P
            assert float(f["F_br"]) == pytest.approx(float(f_br), rel=1e-12, abs=1e-12)
            assert float(f["F_bl"]) == pytest.approx(float(f_bl), rel=1e-10, abs=1e-10)
            assert float(f["N_frame"]) == pytest.approx(float(pa * np.pi * R**2 - f_br - f_bl), rel=1e-10, abs=1e-10)


def test_be_frame_in_tension_bc_frame_in_compression():
    P = [100.0, 200.0, 300.0]
    for model in ("energy", "force_balance"):
        be = bendpam.limits(presets.be_pam(model), P, model)
        assert np.all(be.blocked["axial_force_n"] > 0) and np.all(be.free["axial_force_n"] > 0)
        assert np.all(be.buckling_margin == np.inf)  # a frame in tension does not buckle
        bc = bendpam.limits(presets.bc_pam(model), P, model)
        assert np.all(bc.blocked["axial_force_n"] < 0) and np.all(bc.frame_axial_force_n < 0)
        assert np.all(np.isfinite(bc.buckling_margin))
        assert np.all(np.diff(bc.buckling_margin) < 0)  # worse with pressure


# ------------------------------------------------------------------------------------------------
# strength, stretch and lock-up margins by hand
# ------------------------------------------------------------------------------------------------
def test_strength_and_stretch_margins_by_hand():
    a = presets.bc_pam().replace(frame_strength_mpa=50.0, bladder_stretch_limit=1.5)
    lim = bendpam.limits(a, [100.0, 200.0])
    area = 5.0 * 0.5  # mm^2
    # blocked at 200 kPa: sigma = |N| / (w h) = 102.8215 / 2.5 = 41.13 MPa, margin 50 / 41.13 = 1.216
    N = lim.blocked["axial_force_n"][1]
    assert lim.blocked["stress_mpa"][1] == pytest.approx(-N / area, rel=1e-14)
    assert lim.frame_strength_margin[1] == pytest.approx(50.0 * area / -N, rel=1e-12)
    # free at 100 kPa: axial plus bending stress E_f h |k'| / 2
    k = lim.free["curvature_per_mm"][0]
    Nf = lim.free["axial_force_n"][0]
    sig = abs(Nf) / area + 6796.0 * 0.5 * abs(k) / 2.0
    assert lim.free["stress_mpa"][0] == pytest.approx(sig, rel=1e-12)
    assert lim.frame_stress_mpa[0] == pytest.approx(max(sig, -lim.blocked["axial_force_n"][0] / area), rel=1e-12)
    assert lim.frame_strength_margin[0] == pytest.approx(50.0 / lim.frame_stress_mpa[0], rel=1e-12)
    # stretch, blocked: the prestrain's hoop stretch at the inner surface (R0_start - t0_start) / (R0 - t0)
    t0s = 8.6 - math.sqrt(8.6**2 - 2 * 8.5 * 2.5 + 2.5**2)
    lam0 = (8.6 - t0s) / (8.5 - 2.5)  # = 6.14085 / 6 = 1.02347
    assert lim.blocked["bladder_stretch"][1] == pytest.approx(lam0, rel=1e-12)
    # stretch, free at 100 kPa: hoop (R - t_bar) / 6, axial max(1, 1 + 2u), radial R0 / (R min(1, 1 + 2u))
    kin = bendpam.kinematics(a, k)
    R, u, tb = float(kin.radius), float(kin.u), float(kin.mean_thickness)
    lam = max((R - tb) / 6.0, 1.0 + 2.0 * u, 1.0, 8.5 / (R * min(1.0, 1.0 + 2.0 * u)))
    assert lim.free["bladder_stretch"][0] == pytest.approx(lam, rel=1e-9)
    assert lim.bladder_stretch_max[0] == pytest.approx(lam, rel=1e-9)
    assert lim.bladder_stretch_margin[0] == pytest.approx(0.5 / (lam - 1.0), rel=1e-9)  # in strain
    # the BE-PAM's prestrain (10.1 / 8.5 outside, 1.3515 inside) is past a 1.3 limit even when straight
    be = bendpam.limits(presets.be_pam().replace(bladder_stretch_limit=1.3), [50.0])
    lam_be = (10.1 - presets.be_pam().t0_start_mm) / 6.0
    assert be.bladder_stretch_max[0] == pytest.approx(lam_be, rel=1e-12) and lam_be == pytest.approx(1.3515, abs=1e-4)
    assert be.bladder_stretch_margin[0] == pytest.approx(0.3 / (lam_be - 1.0), rel=1e-12)
    assert be.violations == ("bladder stretch: margin 0.85 at 50 kPa (blocked and free)",)
    # no limits given: inf margins, never a NaN
    plain = bendpam.limits(presets.bc_pam(), [100.0, 200.0])
    assert np.all(plain.frame_strength_margin == np.inf) and np.all(plain.bladder_stretch_margin == np.inf)
    assert not np.any(np.isnan(plain.min_margin))


def test_lockup_margin_is_a_safety_factor():
    be = presets.be_pam()
    lim = bendpam.limits(be, [50.0, 150.0, 250.0])
    k_max = bendpam.curvature_limits(be).k_max  # the BE-PAM's branch is unbounded: the lock-up limit
    assert lim.lockup_margin[0] == np.inf  # below P_start: straight
    assert_allclose(lim.lockup_margin[1:], k_max / lim.free["curvature_per_mm"][1:], rtol=1e-12)
    assert np.all(lim.lockup_margin[1:] > 1.0)
    # the BC-PAM's branch folds at 134.2 kPa: k'_fold / |k'| on it, P_a,end / P_a past it
    bc = presets.bc_pam()
    br = bendpam.free_branch(bc)
    lim = bendpam.limits(bc, [100.0, 160.0])
    assert lim.lockup_margin[0] == pytest.approx(br.k_end_per_mm / lim.free["curvature_per_mm"][0], rel=1e-9)
    assert lim.lockup_margin[1] == pytest.approx(br.p_end_active_kpa / (160.0 - 32.0), rel=1e-12)
    assert lim.branch_end == "fold" and lim.max_pressure_kpa == pytest.approx(br.max_pressure_kpa, rel=1e-12)
    assert "free-bending fold: margin 0.80 at 160 kPa (no free-bending equilibrium above 134.2 kPa)" in lim.violations


def test_min_margin_and_result_views():
    a = presets.bc_pam().replace(frame_strength_mpa=300.0, bladder_stretch_limit=2.0)
    P = [40.0, 100.0, 200.0]
    lim = bendpam.limits(a, P)
    assert_allclose(lim.min_margin, np.min([getattr(lim, m) for m in MARGINS], axis=0), rtol=0)
    assert list(lim.past_limit) == [False, False, True] and not lim.ok
    assert lim.notes[0] == "" and "frame buckling" in lim.notes[2]
    df = lim.to_dataframe()
    assert len(df) == 3 and "blocked_buckling_margin" in df and "free_bladder_stretch" in df
    d = lim.to_dict()
    assert d["pressure_kpa"] == P and d["frame_strength_mpa"] == 300.0 and d["violations"] == list(lim.violations)
    table = bendpam.prediction_table(a, P)
    assert_allclose(table.buckling_margin, lim.buckling_margin, rtol=0)
    assert list(table.limit_note) == list(lim.notes)


# ------------------------------------------------------------------------------------------------
# sweeps, predict, finger
# ------------------------------------------------------------------------------------------------
SWEEP_OUTPUTS = ("frame_axial_force_n", "frame_stress_mpa", "frame_strength_margin", "buckling_margin",
                 "lockup_margin", "bladder_stretch_max", "bladder_stretch_margin", "min_margin")


@pytest.mark.parametrize("name", ["be-pam", "bc-pam"])
def test_sweep_outputs_equal_direct_limits(name):
    base = presets.get(name).replace(frame_strength_mpa=60.0, bladder_stretch_limit=1.25)
    a0 = base.alpha0_deg + np.array([-3.0, 0.0, 2.0])
    t0 = np.array([2.0, 2.5])
    P = np.array([50.0, 120.0, 200.0, 280.0])
    ds = bendpam.sweep(base, P, alpha0_deg=a0, t0_mm=t0)
    for out in SWEEP_OUTPUTS:
        assert ds[out].dims == ("alpha0_deg", "t0_mm", "pressure_kpa"), out
        assert ds[out].attrs["units"] in ("1", "N", "MPa")
    for i, a in enumerate(a0):
        for j, t in enumerate(t0):
            lim = bendpam.limits(base.replace(alpha0_deg=a, t0_mm=t), P)
            for out in SWEEP_OUTPUTS:
                assert_allclose(ds[out].values[i, j], getattr(lim, out), rtol=1e-7, err_msg=out)


def test_sweep_kernel_on_a_shared_table_block():
    """Many cases per braid angle take the law's shared-table path; the limits still match one by one."""
    from bendpam.sweeps import evaluate_cases

    base = presets.bc_pam()
    t0 = np.linspace(2.0, 3.0, 8)
    h = np.array([0.4, 0.6])
    T, H = np.meshgrid(t0, h, indexing="ij")
    P = np.array([60.0, 110.0, 150.0])
    res = evaluate_cases(base, "energy", {"t0_mm": T.ravel(), "frame_thickness_mm": H.ravel()}, P)
    for c in (0, 7, 15):
        lim = bendpam.limits(base.replace(t0_mm=float(T.ravel()[c]), frame_thickness_mm=float(H.ravel()[c])), P)
        for out in SWEEP_OUTPUTS:
            assert_allclose(res[out][c], getattr(lim, out), rtol=1e-6, err_msg=out)


def test_case_kernel_without_u_interpolates_and_polishes_eq5():
    """Given only k', the kernel solves eq 5 for u = k'R: the same limits."""
    from bendpam.physics.limits import case_limits
    from bendpam.sweeps import build_cases

    cs = build_cases(presets.be_pam(), {"alpha0_deg": np.array([64.0, 69.7, 75.0]), "t0_mm": np.array([2.0, 2.5, 3.0])})
    law = bendpam.MomentLaw(cs)
    P = np.array([60.0, 120.0, 200.0, 320.0])
    k, u = law.free_state_array(P)
    with_u = case_limits(law, P, k, free_u=u)
    without = case_limits(law, P, k)
    for key in ("axial_force_n", "stress_mpa", "buckling_margin", "bladder_stretch"):
        assert_allclose(without["free"][key], with_u["free"][key], rtol=1e-12, err_msg=key)
    kin = bendpam.kinematics(presets.be_pam().replace(alpha0_deg=69.7, t0_mm=2.5), k[1, 2])
    assert u[1, 2] == pytest.approx(float(kin.u), rel=1e-12)


def test_predict_cli_warns_past_a_limit(capsys):
    code = main(["predict", "--preset", "bc-pam", "--pressure-kpa", "100", "200"])
    out, err = capsys.readouterr()
    assert code == 0, err
    assert "buckling" in out and "0.69" in out and "1.70" in out  # the margins table
    assert "bendpam: warning: past a limit: frame buckling: margin 0.69 at 200 kPa (blocked)" in err
    assert "100 kPa" not in err
    code = main(["predict", "--preset", "bc-pam", "--pressure-kpa", "40", "100"])
    out, err = capsys.readouterr()
    assert code == 0 and "warning" not in err
    code = main(["predict", "--preset", "bc-pam", "--pressure-kpa", "200", "--json"])
    out, err = capsys.readouterr()
    import json

    r = json.loads(out)["results"][0]
    assert r["buckling_margin"] == pytest.approx(0.6877, abs=1e-4) and "frame buckling" in r["limit_note"]
    assert "frame buckling" in err


def test_finger_margins_along_the_finger():
    from bendpam.design import Finger, FingerLoads, solve_finger

    bc = presets.bc_pam()
    free = solve_finger(Finger(bc), 100.0)
    fl = free.limits()
    ref = bendpam.limits(bc, [100.0])
    # an unloaded finger is the free state at every section
    assert fl.buckling_margin == pytest.approx(ref.free["buckling_margin"][0])  # inf: the frame is in tension
    assert fl.frame_axial_force_n == pytest.approx(ref.free["axial_force_n"][0], rel=1e-9)
    assert fl.bladder_stretch_max == pytest.approx(ref.free["bladder_stretch"][0], rel=1e-9)
    assert fl.min_margin == pytest.approx(fl.lockup_margin) and fl.min_margin > 1 and fl.violations == ()
    # a tip force: the frame line carries its component along the tangent
    loaded = solve_finger(Finger(bc), 100.0, FingerLoads(tip_force_n=(-1.0, 0.0)))
    lim = loaded.limits()
    t = lim.sections["external_axial_force_n"]
    assert t[-1] == pytest.approx(-1.0 * math.cos(loaded.angle[-1]), rel=1e-12)
    assert np.all(t < 0)  # pushing the tip back compresses every section
    sec = section_limits(bc, 100.0, loaded.curvature)
    assert_allclose(lim.sections["axial_force_n"], sec["axial_force_n"] + t, rtol=1e-12)
    with pytest.raises(NoEquilibrium):
        solve_finger(Finger(bc), 200.0).limits()  # above the fold: no free shape


def test_finger_cli_prints_the_margins(capsys):
    code = main(["finger", "--preset", "bc-pam", "--pressure-kpa", "100", "130"])
    out, err = capsys.readouterr()
    assert code == 0, err
    assert "limits along the finger" in out and "buckling" in out and "warning" not in err


# ------------------------------------------------------------------------------------------------
# bad input
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("kw,words", [
    (dict(frame_strength_mpa=0.0), ["frame_strength_mpa", "(0, inf) MPa"]),
    (dict(frame_strength_mpa=-20.0), ["frame_strength_mpa", "-20"]),
    (dict(frame_strength_mpa="400"), ["frame_strength_mpa", "not a number"]),
    (dict(bladder_stretch_limit=1.0), ["bladder_stretch_limit", "(1, inf)"]),
    (dict(bladder_stretch_limit=0.5), ["bladder_stretch_limit", "0.5"]),
    (dict(bladder_stretch_limit=math.inf), ["bladder_stretch_limit", "not finite"]),
])
def test_bad_limits_on_the_actuator(kw, words):
    with pytest.raises(InputError) as exc:
        presets.bc_pam().replace(**kw)
    msg = str(exc.value)
    assert "\n" not in msg
    for w in words:
        assert w in msg


def test_limits_round_trip_through_toml(tmp_path):
    a = presets.bc_pam().replace(frame_strength_mpa=420.0, bladder_stretch_limit=3.0)
    p = tmp_path / "a.toml"
    a.to_toml(p)
    assert "frame_strength_mpa = 420.0" in p.read_text()
    b = Actuator.from_toml(p)
    assert b == a and b.frame_strength_mpa == 420.0 and b.bladder_stretch_limit == 3.0
    assert "frame_strength_mpa" not in presets.bc_pam().to_toml()  # unset limits are left out
    p.write_text(p.read_text().replace("420.0", "-1.0"))
    with pytest.raises(InputError, match="frame_strength_mpa"):
        Actuator.from_toml(p)


def test_bad_calls():
    bc = presets.bc_pam()
    with pytest.raises(TypeError, match="Actuator"):
        bendpam.limits(bc.params, [100.0])
    with pytest.raises(InputError, match="below zero"):
        bendpam.limits(bc, [100.0, -5.0])
    with pytest.raises(InputError, match="1-D"):
        bendpam.limits(bc, [[100.0, 150.0]])
    with pytest.raises(InputError, match="fem"):
        bendpam.limits(bc, [100.0], "fem")
    with pytest.raises(InputError, match="lock-up"):
        section_limits(bc, 100.0, [0.0, 0.5])
    with pytest.raises(InputError, match="pressure_kpa"):
        section_limits(bc, -1.0, [0.0])
