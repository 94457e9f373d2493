r"""An N-finger gripper closing on a sphere: contact, normal force and pull-out (gripping) force.

The set-up follows the paper's Figure 8 test: identical fingers on a base circle, pointing down,
close on a sphere; the arm then pulls the gripper vertically off the (fixed) sphere and the peak
pull is the gripping force.

Model and assumptions
---------------------
* **Geometry.**  ``fingers`` fingers (default 3) sit on a base circle of radius ``base_radius_mm``
  (their frame lines), equally spaced, pointing straight down (or tilted outward by
  ``splay_deg``), and curl toward the axis.  The
  sphere (diameter ``D``) is centred on the gripper axis, so every finger works in its own radial
  plane with the same statics; the planar finger model of :mod:`bendpam.design.finger` applies
  (coordinates: ``x`` radial outward from the axis, ``y`` up, base at ``(R_b, 0)``).
* **Contact surface.**  A BE-PAM finger bends toward its frame, so the frame faces the sphere; a
  BC-PAM finger bends away from it, so the bladder side (about ``2 R0_start_mm`` from the frame)
  faces the sphere.  ``contact_offset_mm`` (default: half the frame thickness for a BE-PAM, ``2
  R0_start_mm`` for a BC-PAM) is that distance.  The rod's frame line then touches the sphere of radius
  ``D/2 + offset`` (body contact, tangent), or the fingertip point, at the end of a rigid
  fingertip of length ``fingertip_mm`` shifted by the offset toward the sphere, touches the sphere
  itself (tip contact).
* **Placement.**  As in the test, the arm brings the open (unpressurised, straight) gripper down
  onto the sphere, which rests on a table, and stops at the first contact: the palm (the base
  plane) on the top of the sphere, the lowest point of the straight fingers on the table, or the
  open fingers' contact surface on the sphere, whichever comes first (``center_depth_mm``
  overrides this).  A sphere wider than the opening between the open fingers is met by the
  fingertips on its upper half, at the angle ``beta0`` from the downward vertical; if that lies
  beyond the friction cone (``beta0 >= 90 deg + atan(mu)``) nothing can hold it: the sphere is
  **too large**, contact ``"none"``, zero force.
* **Grasp statics.**  Quasi-static inflation from the contact onset (the free finger, a circular
  arc, first touching the sphere) to the working pressure, with frictionless contact while the
  fingers close (friction only matters in the pull).  The contact set is tracked by an
  active-set continuation in pressure: a tip contact (the fingertip point on the sphere), a body
  contact (the contact surface tangent to the sphere, on the rod or on the flat pad), or both;
  a contact is added where the finger would penetrate the sphere, dropped where it would pull, and
  a body contact that runs off the end of the pad becomes a tip contact.  Each contact carries a
  normal force ``N >= 0`` along the sphere normal; every section stays on the stable branch of its
  moment law.  If the free finger does not reach the sphere at this pressure the sphere is **too
  small**: contact ``"none"``, zero force.  If the frictionless fingertip slides up over the
  sphere (a limit point with the contact above the equator), the result is ``"none"`` with zero
  force and a note.  If the finger has no stable equilibrium in contact (the BC-PAM above its
  fold: near the fingertip the contact moment is too small for the stable branch, that part
  snaps through), the result says so (``equilibrium=False``, NaN forces), never a wrong shape.
  The structural stability of contact equilibria is not checked (the finger statics are).
* **Pull-out (the grip force).**  The sphere is fixed; from the grasp the arm lifts the gripper
  base step by step (displacement control, adaptive steps).  At every step the fingers' statics
  are solved again with their moment law at the (unchanged) pressure under the contact loads: at
  each contact a normal force ``N >= 0`` along the sphere's outward normal ``n`` and a tangential
  (friction) force ``T`` along ``t = (-n_y, n_x)``.  Coulomb's law with ``mu``: a contact
  **sticks** (its material point moves with the sphere's surface, no tangential slip in the step;
  a body contact may roll) while ``|T| <= mu N``, and **slips** otherwise, with ``T = mu N``
  against the slip; a contact whose ``N`` would become negative **opens**, a part of the finger
  that would penetrate the sphere closes a contact, a flat pad rolling onto the sphere takes over
  the fingertip's contact, and a body contact that runs off the pad's end becomes the tip
  contact.  The lifting load is ``F = -fingers * sum F_y`` over the contacts of one finger
  (``F_y = N n_y + T t_y``, the sphere's force on the finger; per contact
  ``N cos beta - T sin beta`` with ``beta`` the angle of ``n`` from the downward vertical).  The
  pull stops when every contact has opened (the sphere escapes), when the load has fallen below
  half its peak (under a pulling force the sphere escapes at the peak), or when the fingers have
  no equilibrium (they snap off); the **grip force** is the peak of ``F`` (0 if it never pulls).
  Sticking contacts below the equator first load the fingers (the load rises with the lift); the
  peak is usually at the onset of slip, after which the tip slides toward the equator and the
  load falls.  The earlier estimate with the grasp's normal forces frozen,
  ``fingers * sum N (cos beta + mu sin beta)``, is kept as ``frozen_grip_force_n`` for comparison
  only.  Neglected: friction while closing, gravity on the fingers and the sphere's weight (a
  fixed sphere), rate effects and hysteresis, out-of-plane finger deformation and twisting,
  finger-finger and palm contacts, and more than one body contact per finger (the pull stops
  with a note if one would be needed).

Units: mm, N, kPa (every function takes and returns pressures in kPa, ``pressure_kpa``), degrees in
names ending ``_deg``.  Bad input raises :class:`bendpam.InputError`.
"""
from __future__ import annotations

import numpy as np

from bendpam.design.contact import grasp_path
from bendpam.design.gripper import Grasp, Gripper
from bendpam.design.parts import checked_pressure_kpa, checked_pressures_kpa, pressures_checked
from bendpam.design.pullout import pull_grasps
from bendpam.errors import InputError
from bendpam.infra.accessors import figure
from bendpam.validate import number

__all__ = [
    "grasp_dataset",
    "grasp_sweep",
    "plot_grasp",
    "solve_grasp",
    "solve_grasps",
]


def solve_grasp(gripper: Gripper, diameter_mm, pressure_kpa) -> Grasp:
    """Grasp of a sphere of ``diameter_mm`` at ``pressure_kpa`` (kPa): contact, normal and gripping force.

    See the module docstring for the model.  A sphere that does not fit, or that the fingers do
    not reach at this pressure, gives contact ``"none"`` and zero force (not an error); where the
    fingers have no stable equilibrium in contact, ``equilibrium`` is False and the forces NaN.

    Examples
    --------
    >>> import bendpam
    >>> gripper = Gripper(bendpam.physics.presets.be_pam().replace(L0_mm=130.0))
    >>> solve_grasp(gripper, 180.0, 120.0).contact       # the fingers do not reach it yet
    'none'
    >>> g = solve_grasp(gripper, 180.0, 160.0)
    >>> g.contact, g.normal_force_n > 0, g.grip_force_n > 0
    ('tip', True, True)
    """
    _check_gripper(gripper)
    D = number("diameter_mm", diameter_mm, 0.0, 1e5, lo_open=True, unit="mm")
    P = checked_pressure_kpa(pressure_kpa, actuator=gripper.actuator)
    with pressures_checked():
        return pull_grasps(gripper, [grasp_path(gripper, D, [P])])[0][0]


def _check_gripper(gripper) -> None:
    if not isinstance(gripper, Gripper):
        raise TypeError(f"gripper must be a bendpam.design.Gripper, got {type(gripper).__name__}")


def _diameters_mm(value) -> np.ndarray:
    """Sphere diameters (mm) as a 1-D float array, each positive and finite, else an InputError."""
    arr = np.atleast_1d(np.asarray(value, dtype=object)).ravel()
    if arr.size == 0:
        raise InputError("diameters_mm is empty; give at least one sphere diameter (mm)")
    return np.array([number("diameters_mm", d, 0.0, 1e5, lo_open=True, unit="mm") for d in arr])


def solve_grasps(gripper: Gripper, diameters_mm, pressures_kpa) -> list[list[Grasp]]:
    """Grasps over diameters (mm) and pressures (kPa): ``grasps[i][j]`` for diameter i and pressure j.

    Each sphere is grasped inflating quasi-statically through the pressures (in ascending order),
    and all the pull-outs are solved together (batched Newton), so a sweep costs little more than
    its grasps.  :func:`grasp_dataset` makes them a dataset (:func:`grasp_sweep` does both).

    Examples
    --------
    >>> import bendpam
    >>> gripper = Gripper(bendpam.physics.presets.be_pam().replace(L0_mm=130.0))
    >>> grasps = solve_grasps(gripper, [180.0], [120.0, 160.0])
    >>> [[g.contact for g in row] for row in grasps]
    [['none', 'tip']]
    """
    _check_gripper(gripper)
    Ds = _diameters_mm(diameters_mm)
    Ps = checked_pressures_kpa(pressures_kpa, actuator=gripper.actuator)
    with pressures_checked():
        return pull_grasps(gripper, [grasp_path(gripper, float(D), [float(p) for p in Ps]) for D in Ds])


def grasp_dataset(gripper: Gripper, grasps: list[list[Grasp]]):
    """The grasps of :func:`solve_grasps` (a diameter by pressure grid) as an :class:`xarray.Dataset`.

    Dimensions ``diameter_mm`` and ``pressure_kpa``; variables ``grip_force_n`` (N, the pull-out
    force: the peak of the quasi-static pull), ``peak_lift_mm`` (lift at the peak), ``pull_end``
    (why the pull stopped), ``frozen_grip_force_n`` (N, the frozen-normal estimate, for comparison
    only), ``contact_force_n`` (N, per finger, at the grasp), ``contact`` (str),
    ``contact_angle_deg``, ``equilibrium`` and ``note``; the gripper's geometry in the attributes.

    Examples
    --------
    >>> import bendpam
    >>> gripper = Gripper(bendpam.physics.presets.be_pam().replace(L0_mm=130.0))
    >>> ds = grasp_dataset(gripper, solve_grasps(gripper, [180.0], [120.0]))
    >>> ds.sizes["diameter_mm"], str(ds["contact"].values[0, 0])
    (1, 'none')
    """
    import xarray as xr

    _check_gripper(gripper)
    Ds = np.array([float(row[0].diameter_mm) for row in grasps])
    Ps = np.array([float(g.pressure_kpa) for g in grasps[0]]) if grasps else np.zeros(0)
    shape = (Ds.size, Ps.size)
    grip = np.full(shape, np.nan)
    frozen = np.full(shape, np.nan)
    lift = np.full(shape, np.nan)
    end = np.full(shape, "", dtype=object)
    normal = np.full(shape, np.nan)
    beta = np.full(shape, np.nan)
    contact = np.empty(shape, dtype=object)
    eq = np.zeros(shape, dtype=bool)
    note = np.empty(shape, dtype=object)
    for i, path in enumerate(grasps):
        for j, g in enumerate(path):
            grip[i, j], normal[i, j], beta[i, j] = g.grip_force_n, g.normal_force_n, g.contact_angle_deg
            frozen[i, j], lift[i, j] = g.frozen_grip_force_n, g.peak_lift_mm
            end[i, j] = g.pull_out.end if g.pull_out is not None else ""
            contact[i, j], eq[i, j], note[i, j] = g.contact, g.equilibrium, g.note
    dims = ("diameter_mm", "pressure_kpa")
    ds = xr.Dataset(
        {
            "grip_force_n": (dims, grip, {"units": "N", "long_name": "pull-out (gripping) force of the gripper"}),
            "frozen_grip_force_n": (dims, frozen, {
                "units": "N", "long_name": "frozen-normal estimate fingers * sum N (cos beta + mu sin beta), "
                                           "for comparison only"}),
            "peak_lift_mm": (dims, lift, {"units": "mm", "long_name": "lift of the base at the peak pull"}),
            "pull_end": (dims, end.astype(str)),
            "contact_force_n": (dims, normal, {"units": "N", "long_name": "normal contact force per finger"}),
            "contact_angle_deg": (dims, beta, {"units": "deg",
                                               "long_name": "sphere normal at the contact from the downward vertical"}),
            "contact": (dims, contact.astype(str)),
            "equilibrium": (dims, eq),
            "note": (dims, note.astype(str)),
        },
        coords={"diameter_mm": Ds, "pressure_kpa": Ps},
    )
    ds.attrs.update(actuator=gripper.actuator.name or gripper.actuator.kind, model=gripper.model,
                    fingers=gripper.fingers, base_radius_mm=gripper.base_radius_mm, mu=gripper.mu,
                    fingertip_mm=gripper.fingertip_mm, contact_offset_mm=gripper.contact_offset_mm,
                    splay_deg=gripper.splay_deg, L0_mm=gripper.actuator.L0_mm)
    return ds


def grasp_sweep(gripper: Gripper, diameters_mm, pressures_kpa):
    """Grasps over diameters (mm) and pressures (kPa): an :class:`xarray.Dataset` (see :func:`grasp_dataset`).

    :func:`solve_grasps`, then :func:`grasp_dataset`.  ``.to_dataframe()`` gives the flat table.
    All pull-outs are solved together (batched Newton), so a sweep costs little more than its grasps.

    Examples
    --------
    >>> import bendpam
    >>> gripper = Gripper(bendpam.physics.presets.be_pam().replace(L0_mm=130.0))
    >>> ds = grasp_sweep(gripper, [180.0], [120.0, 160.0])
    >>> list(ds.dims), ds["contact"].values.tolist()
    (['diameter_mm', 'pressure_kpa'], [['none', 'tip']])
    """
    return grasp_dataset(gripper, solve_grasps(gripper, diameters_mm, pressures_kpa))


def plot_grasp(ds, ax=None, title: str | None = None):
    """Grip (pull-out) force against sphere diameter, one line per pressure (cf. the paper's Figure 8(c, d)).

    ``ds`` is a :func:`grasp_sweep` result.  Where the gripper has no contact or no equilibrium the
    line has a gap (no point, no line through it), never a 0 N point; each pressure has its own
    marker and colour.  The figure is sized for a journal column (:func:`bendpam.present.figures.figure_size`).
    Returns the figure.

    Examples
    --------
    >>> import bendpam
    >>> import matplotlib.pyplot as plt
    >>> gripper = Gripper(bendpam.physics.presets.be_pam().replace(L0_mm=130.0))
    >>> fig = plot_grasp(grasp_sweep(gripper, [160.0, 200.0], [160.0]))
    >>> len(fig.axes)                                     # fig.savefig("grip.png") to keep it
    1
    >>> plt.close(fig)
    """
    return figure("grasp")(ds, ax=ax, title=title)
