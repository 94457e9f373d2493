r"""The moment law inside a MuJoCo simulation: pressure in, hinge torques out, every step.

A bending PAM exported by :func:`bendpam.export.mujoco` is a chain of ``N`` rigid links joined by
hinges; hinge ``j`` stands for the length ``h = L0 / N`` of the actuator around it, so its angle
``theta_j`` (rad, counterclockwise about the chain's in-plane normal) is the section's frame
curvature times ``h``::

    k'_j = c theta_j / h                         (1/mm; c = +-1, the frame side of the mounting)
    tau_j = c M(P, k'_j)                         (N*mm, the torque on the distal link)

``M`` is the actuator's :class:`bendpam.MomentLaw` through its spline table
(:meth:`bendpam.MomentLaw.tabulated`, :meth:`bendpam.physics.law.MomentTable.moment`), evaluated
for every hinge of every actuator in one call per distinct law (no Python loop over segments).
The torque stiffens as the law does: ``d tau / d theta = (dM/dk') / h < 0`` on the stable branch,
so the free shape (``M = 0``) is the chain's rest shape at that pressure.  With a fitted hysteresis
loop (:class:`bendpam.physics.hysteresis.LoopModel`, linear amplitude), each hinge carries its own
friction state ``z`` driven by its equivalent bending angle ``k'_j L0`` and the torque becomes
``c (M(P, k'_j) - A(P) z_j)``: the Prandtl-Ishlinskii stops or Dahl's law advanced exactly over
each step's increment.

Two engines give the same numbers: ``"numpy"`` (a dozen NumPy operations for all hinges at once)
and ``"numba"`` (the same arithmetic in one compiled loop, when Numba is installed: the ``mujoco``
extra brings it; compiled on the first step, about 2 s).  ``engine="auto"`` (default) takes Numba
where it is installed.

The pressure of each actuator is the control input (kPa, :meth:`PamController.set_pressure_kpa`):
no pneumatic dynamics.  The chains, their segment lengths and frame sides are read from the
model's ``<custom>`` numerics that the export writes (``bendpam:NAME:segment_length_mm``,
``bendpam:NAME:frame_side``) and its joints ``NAME_hinge1 .. NAME_hingeN``; MuJoCo's own
units are SI (m, kg, s, N*m), bendpam's N*mm are converted at the boundary.

``mujoco`` (the ``mujoco`` extra) is imported only when a controller is built.

Units: kPa, mm, N*mm, 1/mm at the interface; radians for hinge angles (MuJoCo's ``qpos``).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Any

import numpy as np

from bendpam.errors import InputError
from bendpam.physics.actuator import Actuator
from bendpam.physics.law import MomentLaw
from bendpam.validate import float_array

__all__ = ["ENGINES", "HingeTable", "PamChain", "PamController", "chains_of", "import_mujoco"]

_PREFIX = "bendpam:"


def import_mujoco():
    """The ``mujoco`` module, or one line saying how to install it.

    >>> import_mujoco().__name__
    'mujoco'
    """
    try:
        import mujoco
    except ImportError:
        raise InputError("MuJoCo is not installed: pip install \"bendpam[mujoco]\" (MuJoCo's bindings)") from None
    return mujoco


@dataclass(frozen=True)
class PamChain:
    """One bending PAM of a MuJoCo model: its hinges and how their angles map to curvature.

    Attributes
    ----------
    name : the chain's name (its joints are ``NAME_hinge1 .. NAME_hingeN``).
    dofs : (N,) the hinges' degree-of-freedom addresses (``qvel``/``qfrc_applied`` indices).
    qpos : (N,) the hinges' ``qpos`` addresses.
    segment_length_mm : h = L0 / N, mm.
    frame_side : c, +1 or -1.

    Examples
    --------
    >>> chain = PamChain("pam0", np.arange(4), np.arange(4), 36.25, 1)
    >>> chain.segments, chain.segment_length_mm * chain.segments     # mm
    (4, 145.0)
    """

    name: str
    dofs: np.ndarray
    qpos: np.ndarray
    segment_length_mm: float
    frame_side: int

    @property
    def segments(self) -> int:
        return int(self.dofs.size)


def chains_of(model) -> list[PamChain]:
    """The bending-PAM chains of a MuJoCo ``MjModel`` written by :func:`bendpam.export.mujoco`, in model order.

    >>> chains_of(None)
    Traceback (most recent call last):
    ...
    bendpam.errors.InputError: the model is not a mujoco.MjModel (got NoneType)
    """
    if not hasattr(model, "numeric") or not hasattr(model, "nnumeric"):
        raise InputError(f"the model is not a mujoco.MjModel (got {type(model).__name__})")
    names = [model.numeric(i).name for i in range(model.nnumeric)]
    chains = []
    for nm in names:
        if not (nm.startswith(_PREFIX) and nm.endswith(":segment_length_mm")):
            continue
        chain = nm[len(_PREFIX):-len(":segment_length_mm")]
        h = float(model.numeric(nm).data[0])
        side = _PREFIX + chain + ":frame_side"
        if side not in names:
            raise InputError(f"the model has {nm} but no {side}: not a bendpam export")
        c = round(float(model.numeric(side).data[0]))
        dofs, qpos = [], []
        j = 1
        while True:
            jid = _joint_id(model, f"{chain}_hinge{j}")
            if jid < 0:
                break
            dofs.append(int(model.jnt_dofadr[jid]))
            qpos.append(int(model.jnt_qposadr[jid]))
            j += 1
        if not dofs or not (h > 0 and c in (1, -1)):
            raise InputError(f"the bending PAM {chain!r} of the model has no hinges {chain}_hinge1.. or a bad "
                             f"segment length ({h:g} mm) or frame side ({c})")
        chains.append(PamChain(chain, np.array(dofs), np.array(qpos), h, c))
    if not chains:
        raise InputError("the model has no bending PAM (no bendpam:NAME:segment_length_mm numeric): "
                         "export it with bendpam.export.mujoco")
    return chains


def _joint_id(model, name: str) -> int:
    mujoco = import_mujoco()
    return int(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name))


class HingeTable:
    """The moment law of one actuator as a uniform cubic-Hermite table in k', for the per-step evaluation.

    Built from the law's fast path (:meth:`bendpam.MomentLaw.tabulated`: ``A``, ``B`` and their
    derivatives from :meth:`~bendpam.physics.law.MomentTable.derivatives` on a uniform grid over the
    lock-up range), so that one step costs a dozen NumPy operations for all hinges: the interval is
    ``floor((k' - k_min) / dk)`` (no arccos, no search) and one gather fetches its coefficients.
    The grid is doubled until ``M`` agrees with :meth:`~bendpam.physics.law.MomentTable.moment` to
    ``tol`` relative to ``|P_a A| + |B|`` (``P_a`` = 500 kPa) at every interval's midpoint.
    Curvatures beyond lock-up take the end values (the hinges' joint limits hold the lock-up).

    Examples
    --------
    >>> import bendpam
    >>> law = bendpam.MomentLaw.of(bendpam.physics.presets.be_pam())
    >>> ht = HingeTable(law.tabulated())
    >>> ht.max_rel_error < 1e-6
    True
    >>> round(float(ht.moment_nmm(np.array([132.0]), np.array([0.01]))[0]), 3)   # 200 kPa: 132 kPa active; N*mm
    63.183
    """

    def __init__(self, table, *, tol: float = 1e-6, points: int = 1025, max_points: int = 1 << 17):
        self.table = table
        lim = table.limits
        self.k_min, self.k_max = float(lim.k_min), float(lim.k_max)
        self.P_start_kpa = float(table.P_start_kpa)
        n = int(points)
        while True:
            self._build(n)
            if self.max_rel_error <= tol or n >= max_points:
                break
            n = 2 * n - 1
        self.points = n

    def _build(self, n: int) -> None:
        k = np.linspace(self.k_min, self.k_max, n)
        dk = k[1] - k[0]
        A, B, dA, dB = self.table.derivatives(k)
        y = np.stack([A, B], -1)  # (n, 2)
        d = np.stack([dA, dB], -1) * dk
        y0, y1, d0, d1 = y[:-1], y[1:], d[:-1], d[1:]
        # p(t) = ((c0 t + c1) t + c2) t + c3 on t in [0, 1]
        c0 = 2.0 * (y0 - y1) + d0 + d1
        c1 = 3.0 * (y1 - y0) - 2.0 * d0 - d1
        coef = np.stack([c0, c1, d0, y0], 1)  # (n - 1, 4, 2)
        self._cA = np.ascontiguousarray(coef[:, :, 0])
        self._cB = np.ascontiguousarray(coef[:, :, 1])
        self._inv_dk = 1.0 / dk
        self._last = float(n - 1) - 1e-9
        km = 0.5 * (k[1:] + k[:-1])
        Ae, Be, _, _ = self.table.derivatives(km)
        scale = 500.0 * np.abs(Ae) + np.abs(Be) + 1e-300
        ones = np.ones_like(km)
        err_a = np.abs(self.moment_nmm(ones, km) - self.moment_nmm(0.0 * ones, km) - Ae)
        err_b = np.abs(-self.moment_nmm(0.0 * ones, km) - Be)
        self.max_rel_error = float(np.max((500.0 * err_a + err_b) / scale))

    def moment_nmm(self, active_pressure_kpa: np.ndarray, curvature_per_mm: np.ndarray) -> np.ndarray:
        """``M = P_a A(k') - B(k')`` (N*mm) for 1-D float arrays of active pressure (kPa) and curvature (1/mm).

        The interval's two cubics are combined with the pressure first (``P_a c_A - c_B``), then one
        Horner evaluation gives ``M``.
        """
        u = (curvature_per_mm - self.k_min) * self._inv_dk
        np.clip(u, 0.0, self._last, out=u)
        j = u.astype(np.intp)
        u -= j
        w = active_pressure_kpa[:, None] * self._cA[j] - self._cB[j]
        return ((w[:, 0] * u + w[:, 1]) * u + w[:, 2]) * u + w[:, 3]


class PamController:
    """Applies each hinge's moment-law torque to a MuJoCo simulation, pressure as the control input.

    Parameters
    ----------
    model : mujoco.MjModel
        A model written by :func:`bendpam.export.mujoco` (or any model with the same ``<custom>``
        numerics and hinge names).
    actuators : Actuator or dict of name to Actuator
        The actuator of every chain (one for all), or one per chain name.
    law_model : {"energy", "force_balance"} or None
        The model of the moment law (None: each actuator's own).
    loop : LoopModel or dict of name to LoopModel, optional
        A fitted hysteresis loop (linear amplitude), for all chains or per chain name.
    engine : {"auto", "numpy", "numba"}
        How the torques are evaluated (the same numbers): ``"auto"`` takes Numba where installed.

    Attributes
    ----------
    chains : list of :class:`PamChain`.  pressure_kpa : (chains,) the current pressures, kPa.

    Examples
    --------
    >>> import bendpam, mujoco
    >>> from bendpam.export import mujoco_model
    >>> xml = mujoco_model(bendpam.physics.presets.be_pam(), "finger", segments=8).xml
    >>> m = mujoco.MjModel.from_xml_string(xml); d = mujoco.MjData(m)
    >>> ctl = PamController(m, bendpam.physics.presets.be_pam())
    >>> ctl.set_pressure_kpa(150.0); ctl.step(m, d, 100)             # 5 ms of a step to 150 kPa
    >>> [c.name for c in ctl.chains], ctl.curvature_per_mm(d).shape
    (['pam0'], (8,))
    """

    def __init__(self, model, actuators, *, law_model: str | None = None, loop=None, engine: str = "auto"):
        self.chains = chains_of(model)
        acts = self._per_chain("actuators", actuators, Actuator, required=True)
        loops = self._per_chain("loop", loop, None, required=False)
        self.actuators = acts
        n = [c.segments for c in self.chains]
        self._chain_of_hinge = np.repeat(np.arange(len(self.chains)), n)
        self.dofs = np.concatenate([c.dofs for c in self.chains])
        self.qpos = np.concatenate([c.qpos for c in self.chains])
        # contiguous addresses (every export): a slice, cheaper than fancy indexing at every step
        self._dof_ix: Any = _as_slice(self.dofs)
        self._qpos_ix: Any = _as_slice(self.qpos)
        self._c = np.repeat([float(c.frame_side) for c in self.chains], n)
        self._c_over_h = self._c * np.repeat([1.0 / c.segment_length_mm for c in self.chains], n)
        self._tau_scale = self._c * 1e-3  # N*mm -> N*m, in the hinge's sense
        # one group per distinct law (all hinges of the chains that share it)
        groups: dict[int, tuple[Any, list[int]]] = {}
        for i, a in enumerate(acts):
            law = MomentLaw.of(a, law_model)
            groups.setdefault(id(law), (law, []))[1].append(i)
        self._groups = []
        for law, idx in groups.values():
            sel = np.flatnonzero(np.isin(self._chain_of_hinge, idx))
            self._groups.append((HingeTable(law.tabulated()), None if sel.size == self.dofs.size else sel))
        self._p_start = np.array([a.P_start_kpa for a in acts])
        self._max_p = np.array([a.max_pressure_kpa for a in acts])
        self.pressure_kpa = np.zeros(len(self.chains))
        self._pa = np.zeros(self.dofs.size)  # active pressure of every hinge, kPa
        self._loop = _LoopState(acts, loops, self._chain_of_hinge, law_model) if any(loops) else None
        self.engine = _engine(engine)
        self._fast = _FastPath(self) if self.engine == "numba" else None

    def _per_chain(self, what: str, value, kind, required: bool) -> list:
        names = [c.name for c in self.chains]
        if isinstance(value, dict):
            missing = [nm for nm in names if nm not in value]
            if missing and required:
                raise InputError(f"{what}: no entry for the chain(s) {missing} of the model (chains: {names})")
            out = [value.get(nm) for nm in names]
        else:
            out = [value] * len(names)
        for v in out:
            if kind is not None and not isinstance(v, kind):
                raise InputError(f"{what}: expected a bendpam {kind.__name__}, got {type(v).__name__}")
        return out

    def set_pressure_kpa(self, pressure_kpa) -> None:
        """Set the pressure of every chain (a scalar for all, or one per chain), kPa; checked like every pressure.

        >>> import bendpam, mujoco
        >>> from bendpam.export import mujoco_model
        >>> act = bendpam.physics.presets.be_pam().replace(L0_mm=130.0)
        >>> m = mujoco.MjModel.from_xml_string(mujoco_model(act, "gripper", segments=4).xml)
        >>> ctl = PamController(m, act)
        >>> ctl.set_pressure_kpa([100.0, 150.0, 200.0]); ctl.pressure_kpa.tolist()
        [100.0, 150.0, 200.0]
        """
        p = float_array("pressure_kpa", pressure_kpa, "kPa")
        if p.ndim > 1 or p.size not in (1, len(self.chains)):
            raise InputError(f"pressure_kpa: give one pressure or one per chain ({len(self.chains)}), got {p.size}")
        p = np.broadcast_to(p, (len(self.chains),))
        bad = ~np.isfinite(p) | (p < 0) | (p > self._max_p)
        if np.any(bad):
            i = int(np.flatnonzero(bad)[0])
            raise InputError(f"pressure_kpa = {p[i]!r} of chain {i} is outside the allowed range "
                             f"[0, {self._max_p[i]:g}] kPa (the actuator's burst limit)")
        self.pressure_kpa = np.array(p, dtype=float)
        self._pa = np.maximum(self.pressure_kpa - self._p_start, 0.0)[self._chain_of_hinge]

    def curvature_per_mm(self, data) -> np.ndarray:
        """The frame curvature k' (1/mm) of every hinge of every chain, in chain order."""
        return self._c_over_h * data.qpos[self._qpos_ix]

    def moments_nmm(self, data, *, advance: bool = False) -> np.ndarray:
        """The section moments ``M`` (N*mm, the actuator's sign) of every hinge at the state of ``data``.

        ``advance`` moves the hysteresis state to this state (done once per step by :meth:`apply`).
        """
        if self._fast is not None:
            M = self._fast.moments(data.qpos, self._pa)
            if self._loop is not None:
                M = M - self._loop.friction_nmm(self._pa, self.curvature_per_mm(data), advance)
            return M
        k = self.curvature_per_mm(data)
        if len(self._groups) == 1:
            M = self._groups[0][0].moment_nmm(self._pa, k)
        else:
            M = np.empty_like(k)
            for table, sel in self._groups:
                M[sel] = table.moment_nmm(self._pa[sel], k[sel])
        if self._loop is not None:
            M -= self._loop.friction_nmm(self._pa, k, advance)
        return M

    def apply(self, data) -> None:
        """Write the hinge torques ``c M`` into ``data.qfrc_applied`` (N*m), before a ``mj_step``."""
        if self._fast is not None and self._loop is None:
            self._fast.apply(data.qpos, self._pa, data.qfrc_applied)
            return
        data.qfrc_applied[self._dof_ix] = self._tau_scale * self.moments_nmm(data, advance=True)

    def step(self, model, data, nstep: int = 1) -> None:
        """``nstep`` MuJoCo steps, the torques applied before each (``mj_step``)."""
        mujoco = import_mujoco()
        for _ in range(int(nstep)):
            self.apply(data)
            mujoco.mj_step(model, data)


#: the ways :class:`PamController` evaluates the torques (the same numbers)
ENGINES = ("auto", "numpy", "numba")


def _engine(name: str) -> str:
    """``"numba"`` where asked for (or ``"auto"`` and Numba is installed), else ``"numpy"``."""
    if name not in ENGINES:
        raise InputError(f"engine = {name!r} is not known; choose one of {', '.join(ENGINES)}")
    if name == "numpy":
        return name
    if _kernels() is None:
        if name == "numba":
            raise InputError("engine 'numba' needs Numba: pip install \"bendpam[mujoco]\"")
        return "numpy"
    return "numba"


@functools.cache
def _kernels():
    """The compiled per-step kernels (Numba, compiled on first use), or None without Numba."""
    try:
        import numba
    except ImportError:
        return None

    @numba.njit(cache=False, nogil=True, inline="always")
    def hinge(i, qpos, qadr, c_over_h, k0, inv_dk, last, off, cA, cB, pa):  # pragma: no cover - compiled
        u = (c_over_h[i] * qpos[qadr[i]] - k0[i]) * inv_dk[i]
        u = min(max(u, 0.0), last[i])
        j = int(u)
        t = u - j
        j += off[i]
        p = pa[i]
        w0 = p * cA[j, 0] - cB[j, 0]
        w1 = p * cA[j, 1] - cB[j, 1]
        w2 = p * cA[j, 2] - cB[j, 2]
        w3 = p * cA[j, 3] - cB[j, 3]
        return ((w0 * t + w1) * t + w2) * t + w3

    @numba.njit(cache=False, nogil=True)
    def moments(qpos, qadr, c_over_h, k0, inv_dk, last, off, cA, cB, pa, out):  # pragma: no cover - compiled
        for i in range(qadr.size):
            out[i] = hinge(i, qpos, qadr, c_over_h, k0, inv_dk, last, off, cA, cB, pa)

    @numba.njit(cache=False, nogil=True)
    def apply(qpos, qadr, dadr, c_over_h, k0, inv_dk, last, off, cA, cB, pa, scale, qfrc):  # pragma: no cover
        for i in range(qadr.size):
            qfrc[dadr[i]] = scale[i] * hinge(i, qpos, qadr, c_over_h, k0, inv_dk, last, off, cA, cB, pa)

    return moments, apply


class _FastPath:
    """Every hinge of a controller in one compiled loop: the :class:`HingeTable` arithmetic, tables concatenated."""

    def __init__(self, ctl: PamController):
        kern = _kernels()
        assert kern is not None
        self._moments, self._apply = kern
        nh = ctl.dofs.size
        self.qadr = np.ascontiguousarray(ctl.qpos, dtype=np.int64)
        self.dadr = np.ascontiguousarray(ctl.dofs, dtype=np.int64)
        self.c_over_h = np.ascontiguousarray(ctl._c_over_h)
        self.scale = np.ascontiguousarray(ctl._tau_scale)
        self.k0, self.inv_dk, self.last = np.empty(nh), np.empty(nh), np.empty(nh)
        self.off = np.empty(nh, dtype=np.int64)
        cA, cB, start = [], [], 0
        for table, sel in ctl._groups:
            ix = slice(None) if sel is None else sel
            self.k0[ix], self.inv_dk[ix], self.last[ix] = table.k_min, table._inv_dk, table._last
            self.off[ix] = start
            cA.append(table._cA)
            cB.append(table._cB)
            start += table._cA.shape[0]
        self.cA, self.cB = np.ascontiguousarray(np.concatenate(cA)), np.ascontiguousarray(np.concatenate(cB))
        self.out = np.empty(nh)

    def moments(self, qpos, pa) -> np.ndarray:
        self._moments(qpos, self.qadr, self.c_over_h, self.k0, self.inv_dk, self.last, self.off, self.cA, self.cB,
                      pa, self.out)
        return self.out.copy()

    def apply(self, qpos, pa, qfrc) -> None:
        self._apply(qpos, self.qadr, self.dadr, self.c_over_h, self.k0, self.inv_dk, self.last, self.off, self.cA,
                    self.cB, pa, self.scale, qfrc)


def _as_slice(ix: np.ndarray):
    """``ix`` as a slice when it is a contiguous increasing run, else itself."""
    if ix.size and np.array_equal(ix, np.arange(ix[0], ix[0] + ix.size)):
        return slice(int(ix[0]), int(ix[0]) + ix.size)
    return ix


class _LoopState:
    """The friction state ``z`` of every hinge (rate-independent: advanced by each step's angle increment)."""

    def __init__(self, acts, loops, chain_of_hinge, law_model):
        for lp in loops:
            if lp is not None and lp.amplitude != "linear":
                raise InputError("the hysteresis loop's amplitude must be 'linear' in a simulation "
                                 f"(got {lp.amplitude!r}: the interfacial amplitude needs the stress state per step)")
        nh = chain_of_hinge.size
        self.cof = chain_of_hinge
        on = np.array([lp is not None for lp in loops])[chain_of_hinge]
        self.on = on
        self.a0 = np.array([lp.a0_nmm if lp else 0.0 for lp in loops])[chain_of_hinge]
        self.a1 = np.array([lp.a1_nmm_per_kpa if lp else 0.0 for lp in loops])[chain_of_hinge]
        self.L0 = np.array([a.L0_mm for a in acts])[chain_of_hinge]
        laws = [lp.z_law if lp else None for lp in loops]
        self.dahl = np.array([getattr(z, "name", "") == "dahl" for z in laws])[chain_of_hinge]
        angle = np.array([z.angle_rad if z else 1.0 for z in laws])[chain_of_hinge]
        self.theta_c = angle
        # Prandtl-Ishlinskii stops: thresholds per hinge (n = 32 stops, bendpam's default)
        nops = max([z.n for z in laws if z is not None and z.name == "pi"], default=1)
        frac = (np.arange(1, nops + 1) - 0.5) / nops
        self.r = 0.5 * angle[:, None] * frac[None, :]
        self.s = np.zeros((nh, nops))
        self.z = np.zeros(nh)
        self.theta: np.ndarray | None = None

    def friction_nmm(self, pa, k, advance: bool) -> np.ndarray:
        th = k * self.L0
        if self.theta is None:
            self.theta = th.copy()
        d = th - self.theta
        s = np.clip(self.s + d[:, None], -self.r, self.r)
        z_pi = s.sum(axis=1) / self.r.sum(axis=1)
        sg = np.sign(d)
        z_dahl = np.where(sg == 0, self.z, sg + (self.z - sg) * np.exp(-np.abs(d) / self.theta_c))
        z = np.where(self.dahl, z_dahl, z_pi)
        if advance:
            self.s, self.z, self.theta = s, z, th
        amp = self.a0 + self.a1 * pa
        return np.where(self.on, amp * z, 0.0)

