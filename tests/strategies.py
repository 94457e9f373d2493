"""Hypothesis strategies shared by the property tests."""

from hypothesis import strategies as st

from bendpam import Actuator


def actuators(*, a0=((20.0, 52.0), (58.0, 85.0)), R0=(3.0, 15.0), tf=(0.1, 0.5), Rs=(1.0, 1.25),
              c10=(-400.0, 1500.0), c01=(0.0, 800.0), ps=(0.0, 80.0), E=(6796.0, 6796.0)):
    """Valid actuators over the given ranges (L0 = 145 mm, a 0.5 x 5 mm frame).

    ``a0`` is a pair of braid-angle ranges (deg) on either side of the neutral angle, ``tf`` the wall
    thickness as a fraction of R0, ``Rs`` the prestrain ratio R0_start / R0.  C01 is shifted so that
    C10 + C01 >= 20 kPa (a positive initial shear modulus).
    """
    return st.builds(
        lambda a, r, t, s, c1, c2, p, e: Actuator(
            alpha0_deg=a, R0_mm=r, t0_mm=t * r, L0_mm=145.0, frame_thickness_mm=0.5, frame_width_mm=5.0,
            frame_modulus_mpa=e, C10_kpa=c1, C01_kpa=c2 + max(-c1, 0.0) + 20.0, P_start_kpa=p, R0_start_mm=r * s),
        st.one_of(*(st.floats(lo, hi) for lo, hi in a0)), st.floats(*R0), st.floats(*tf), st.floats(*Rs),
        st.floats(*c10), st.floats(*c01), st.floats(*ps), st.floats(*E),
    )
