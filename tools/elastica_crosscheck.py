"""Cross-check of the spatial finger (bendpam.design.finger3d) against PyElastica, an independent Cosserat-rod engine.

PyElastica's rods are linear-elastic, so the finger is given to it as a **linear-elastic equivalent rod at the
operating point**: the free shape at the pressure as the rest shape (rest curvature = the free curvature), the
bending stiffnesses ``diag(EI_lat, -dM/dk', GJ)`` of bendpam's laws there
(:func:`bendpam.physics.spatial.spatial_stiffness`),
stiff in stretch and shear (inextensible and unshearable within 1e-3), and bendpam's finger without the braid's
lock torque (``sleeve_lock=False``: a kinked law PyElastica cannot take).  A tip force is ramped up and the rod
is run to rest with PyElastica's analytical linear damper (mass and damping are numerical only: statics).

Run ``python tools/elastica_crosscheck.py`` for the table at 20, 40 and 80 elements (PyElastica converges at
first order in the element length; bendpam's rod integrates exact arcs) and its Richardson extrapolation.
tests/test_finger3d_elastica.py runs one size.  Units: mm, N, g, ms (so that N = g mm / ms^2).
"""

from __future__ import annotations

import numpy as np

from bendpam.design.finger import Finger
from bendpam.design.finger3d import Finger3D, FingerLoads3D, solve_finger3d
from bendpam.design.rod3d import segment_maps
from bendpam.physics.presets import be_pam
from bendpam.physics.spatial import spatial_stiffness

__all__ = ["crosscheck"]


def _elastica_rod(ea, free, finger3d, stiffness, elements: int):
    """A PyElastica rod at the finger's free shape, with bendpam's stiffnesses at the operating point."""
    L = finger3d.finger.length
    h = L / elements
    kap = finger3d.finger.frame_side * free.curvature
    Om = np.stack([np.zeros_like(kap), kap, np.zeros_like(kap)], -1)
    Qh, _ = segment_maps(0.5 * (Om[1:] + Om[:-1]), 0.5 * h)
    mid = free.directors[:-1] @ Qh  # element directors: the arc's mid-tangent frame (columns d1, d2, d3)
    directors = np.ascontiguousarray(np.transpose(mid, (0, 2, 1)).transpose(1, 2, 0))  # [i, :, k]: director i
    r = 9.0  # mm: rotary inertia on the scale of the bending stiffness / stretch stiffness ratio
    rod = ea.CosseratRod.straight_rod(elements, np.zeros(3), np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]),
                                      L, r, 1.0 / (np.pi * r * r), youngs_modulus=1e3, shear_modulus=1e3,
                                      position=np.ascontiguousarray(free.xyz.T), directors=directors)
    EA = 2e3  # N: stretch and shear strain below 1e-3 under the test loads
    rod.shear_matrix[:] = np.diag([EA, EA, EA])[:, :, None]
    rod.bend_matrix[:] = np.diag(stiffness)[:, :, None]
    rod.compute_internal_forces_and_torques(np.float64(0.0))
    rod.rest_kappa[:] = rod.kappa  # the free shape is the rest shape
    rod.rest_sigma[:] = rod.sigma
    return rod


def crosscheck(elements: int = 40, pressure_kpa: float = 150.0, tip_force_n=(0.0, 0.0, 0.5),
               steps_per_element: int = 800, final_time_ms: float = 800.0) -> dict:
    """Tip of bendpam's spatial BE-PAM finger and of PyElastica's equivalent rod under ``tip_force_n``.

    Returns ``{"bendpam_tip_mm", "elastica_tip_mm", "difference_mm", "difference_of_length",
    "tip_displacement_mm", "rest_speed_mm_per_ms"}``.
    """
    import elastica as ea

    a = be_pam()
    f3 = Finger3D(Finger(a, nodes=elements + 1), sleeve_lock=False)
    F = np.asarray(tip_force_n, dtype=float)
    free = solve_finger3d(f3, pressure_kpa)
    ours = solve_finger3d(f3, pressure_kpa, FingerLoads3D(tip_force_n=tuple(F)))
    st = spatial_stiffness(a, pressure_kpa, float(free.curvature[0]))
    B = [float(st.lateral_stiffness_nmm2), float(st.inplane_stiffness_nmm2), float(st.torsional_stiffness_nmm2_per_rad)]

    class Sim(ea.BaseSystemCollection, ea.Constraints, ea.Forcing, ea.Damping):
        pass

    sim = Sim()
    rod = _elastica_rod(ea, free, f3, B, elements)
    sim.append(rod)
    sim.constrain(rod).using(ea.OneEndFixedBC, constrained_position_idx=(0,), constrained_director_idx=(0,))
    sim.add_forcing_to(rod).using(ea.EndpointForces, np.zeros(3), F, ramp_up_time=0.2 * final_time_ms)
    steps = steps_per_element * elements
    dt = np.float64(final_time_ms / steps)
    # about critical damping of the softest mode (numerical: the result is the state at rest)
    sim.dampen(rod).using(ea.AnalyticalLinearDamper, damping_constant=0.066, time_step=dt)
    sim.finalize()
    stepper = ea.PositionVerlet()
    t = np.float64(0.0)
    for _ in range(steps):
        t = stepper.step(sim, t, dt)
    tip_e = rod.position_collection[:, -1].copy()
    tip_b = np.asarray(ours.xyz[-1])
    d = float(np.linalg.norm(tip_b - tip_e))
    return {"bendpam_tip_mm": tip_b.tolist(), "elastica_tip_mm": tip_e.tolist(), "difference_mm": d,
            "difference_of_length": d / a.L0_mm,
            "tip_displacement_mm": float(np.linalg.norm(tip_b - free.xyz[-1])),
            "rest_speed_mm_per_ms": float(np.abs(rod.velocity_collection).max())}


if __name__ == "__main__":
    rows = {n: crosscheck(n) for n in (20, 40, 80)}
    for n, r in rows.items():
        print(f"{n:3d} elements: elastica tip {np.round(r['elastica_tip_mm'], 3)} mm, "
              f"bendpam {np.round(r['bendpam_tip_mm'], 3)} mm, difference {100 * r['difference_of_length']:.3f} % of L")
    e40, e80 = np.asarray(rows[40]["elastica_tip_mm"]), np.asarray(rows[80]["elastica_tip_mm"])
    rich = 2.0 * e80 - e40  # first-order convergence
    print(f"Richardson (40, 80): {np.round(rich, 3)} mm; bendpam (81 nodes) {np.round(rows[80]['bendpam_tip_mm'], 3)}"
          f" mm; difference {100 * np.linalg.norm(rich - rows[80]['bendpam_tip_mm']) / 145.0:.3f} % of L")
