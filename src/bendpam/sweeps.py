"""Design sweeps (the module behind :func:`bendpam.sweep`): any actuator parameters crossed with pressures, in-process or on a Dask cluster.

``bendpam.sweep(base, pressure_kpa=[...], alpha0_deg=[...], t0_mm=[...])`` evaluates every
combination of the swept parameters (an "actuator case") at every pressure and returns an
:class:`xarray.Dataset` with dimensions ``(param_1, ..., param_n, pressure_kpa)``:

* ``blocked_moment_nmm`` (case, pressure): M(P, 0), signed as in the paper's convention;
* ``free_curvature_per_mm`` and ``free_angle_deg`` (case, pressure): the free-bending equilibrium
  on the branch connected to the straight state, NaN where there is none;
* ``max_pressure_kpa`` (case): the highest pressure with a free-bending equilibrium (the fold or
  lock-up pressure; ``inf`` if unbounded) and ``branch_end`` (0 lock-up, 1 fold, 2 unbounded,
  3 neutral);
* ``lockup_margin`` (case, pressure): ``1 - |k'_free| / |k'_lock|``, the fraction of the admissible
  curvature range left before braid lock-up in the bending direction;
* ``frame_stress_mpa`` (case, pressure): the frame's bending stress ``E_f (h_f / 2) |k'_free|`` at
  free bending.

How it is computed
    The kernel evaluates a whole block of cases at once: the braid kinematics and both models
    accept per-case parameter arrays, so the lock-up limits (vectorised bisection), the
    free-bending branch of every case (the same sampling and fold refinement as
    :func:`bendpam.branch_info`, vectorised: golden-section search on the sampled maximum) and the
    roots at every pressure (vectorised Illinois iteration) are array operations over the block.
    There is no Python loop over cases or pressures.

Scaling out
    Cases are split into blocks of at most ``chunk_cases``.  With Dask installed
    (``pip install bendpam[distributed]``) the result is a ``dask.array``-backed dataset built
    with ``map_blocks``; it runs on the threaded scheduler in-process by default, on a
    distributed cluster when ``scheduler`` (an address) is given, or on a ``LocalCluster`` of
    ``workers`` processes.  Each block is computed by the same deterministic function, so every
    way of running gives bit-for-bit the same numbers (tested).  Without Dask the same blocks
    are computed in a loop.  Memory is bounded by the block size (``chunk_cases`` x pressures x the
    1200 branch samples x the quadrature order), never by the sweep size: with ``compute=False``
    the dataset stays lazy and ``to_netcdf`` writes it block by block.

When only ``R0_mm`` is swept, ``R0_start_mm`` keeps the base actuator's ratio ``R0_start / R0``;
``t0_start`` always follows from eq 52.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass

import numpy as np
import xarray as xr

from .actuator import NEUTRAL_ANGLE_DEG, Actuator
from .braid import DEFAULT_ORDER, LOCK_FRACTION, MIN_FAR_STRETCH, _ibar, gauss_nodes
from .models import get_model
from .predict import illinois
from .presets import normalise_model

__all__ = ["sweep", "SWEEP_PARAMETERS", "evaluate_cases", "CaseArrays"]

#: Parameters that can be swept (Actuator field names; units in the names).
SWEEP_PARAMETERS = (
    "alpha0_deg", "R0_mm", "t0_mm", "L0_mm", "frame_thickness_mm", "frame_width_mm", "frame_modulus_mpa",
    "C10_kpa", "C01_kpa", "P_start_kpa", "R0_start_mm",
)
BRANCH_END = {"lock-up": 0, "fold": 1, "unbounded": 2, "neutral": 3}
_BRANCH_SAMPLES = 300
_OUTPUTS = ("blocked_moment_nmm", "free_curvature_per_mm", "free_angle_deg", "lockup_margin", "frame_stress_mpa",
            "max_pressure_kpa", "branch_end")
_UNITS = {
    "blocked_moment_nmm": ("N*mm", "blocked moment M(P, 0)"),
    "free_curvature_per_mm": ("1/mm", "free-bending frame curvature k' (NaN: no equilibrium on the branch)"),
    "free_angle_deg": ("deg", "free-bending angle k' L0"),
    "lockup_margin": ("1", "1 - |k'_free| / |k'_lock|: curvature range left before braid lock-up"),
    "frame_stress_mpa": ("MPa", "frame bending stress E_f h_f |k'_free| / 2 at free bending"),
    "max_pressure_kpa": ("kPa", "highest pressure with a free-bending equilibrium (fold or lock-up)"),
    "branch_end": ("1", "end of the free-bending branch: 0 lock-up, 1 fold, 2 unbounded, 3 neutral"),
}


@dataclass
class CaseArrays:
    """Actuator parameters as arrays (one entry per case), duck-typed like :class:`Actuator`.

    The model functions only read these attributes, in internal units (mm, MPa, rad).
    """

    alpha0: np.ndarray
    R0_start: np.ndarray
    t0_start: np.ndarray
    bladder_area: np.ndarray
    frame_stiffness: np.ndarray
    frame_modulus: np.ndarray
    frame_thickness: np.ndarray
    C10: np.ndarray
    C01: np.ndarray
    P_start: np.ndarray
    L0: np.ndarray

    @classmethod
    def build(cls, base: Actuator, values: dict[str, np.ndarray]) -> CaseArrays:
        """Cases from the base actuator with ``values`` (Actuator field names -> arrays of one shape)."""
        n = np.broadcast_shapes(*(np.shape(v) for v in values.values())) if values else ()
        get = {f: np.broadcast_to(np.asarray(values.get(f, getattr(base, f)), dtype=float), n)
               for f in SWEEP_PARAMETERS if f != "R0_start_mm"}
        if "R0_start_mm" in values:
            R0s = np.broadcast_to(np.asarray(values["R0_start_mm"], dtype=float), n)
        else:
            R0s = get["R0_mm"] * (base.R0_start / base.R0_mm)
        _validate(get, R0s)
        R0, t0 = get["R0_mm"], get["t0_mm"]
        area = np.pi * (2.0 * R0 * t0 - t0 * t0)
        t0s = R0s - np.sqrt(R0s * R0s - 2.0 * R0 * t0 + t0 * t0)
        inertia = get["frame_width_mm"] * get["frame_thickness_mm"] ** 3 / 12.0
        return cls(
            alpha0=np.radians(get["alpha0_deg"]), R0_start=np.array(R0s, dtype=float), t0_start=t0s,
            bladder_area=area, frame_stiffness=get["frame_modulus_mpa"] * inertia,
            frame_modulus=np.array(get["frame_modulus_mpa"]), frame_thickness=np.array(get["frame_thickness_mm"]),
            C10=get["C10_kpa"] * 1e-3, C01=get["C01_kpa"] * 1e-3, P_start=get["P_start_kpa"] * 1e-3,
            L0=np.array(get["L0_mm"]),
        )

    def col(self) -> CaseArrays:
        """The same cases with a trailing axis, to broadcast against per-case samples."""
        return CaseArrays(**{k: np.asarray(v)[..., None] for k, v in self.__dict__.items()})

    @property
    def bend_sign(self) -> np.ndarray:
        deg = np.degrees(self.alpha0)
        return np.where(np.abs(deg - NEUTRAL_ANGLE_DEG) < 1e-9, 0, np.where(deg > NEUTRAL_ANGLE_DEG, 1, -1))


def _validate(get: dict, R0s) -> None:
    """Vectorised versions of the Actuator checks; the first bad case is named."""
    def bad(mask, msg):
        if np.any(mask):
            i = np.unravel_index(int(np.flatnonzero(np.ravel(mask))[0]), np.shape(mask))
            vals = ", ".join(f"{k}={np.asarray(v)[i] if np.ndim(v) else v:g}" for k, v in get.items())
            raise ValueError(f"sweep case {tuple(int(x) for x in i)}: {msg} ({vals})")

    for k, v in get.items():
        bad(~np.isfinite(v), f"{k} is not finite")
    bad((get["alpha0_deg"] <= 0) | (get["alpha0_deg"] >= 90), "alpha0_deg outside (0, 90) deg")
    for k in ("R0_mm", "L0_mm", "frame_thickness_mm", "frame_width_mm", "frame_modulus_mpa"):
        bad(get[k] <= 0, f"{k} must be > 0")
    bad((get["t0_mm"] <= 0) | (get["t0_mm"] >= get["R0_mm"]), "t0_mm must lie in (0, R0_mm)")
    bad(get["C10_kpa"] + get["C01_kpa"] <= 0, "C10_kpa + C01_kpa must be > 0")
    bad(get["P_start_kpa"] < 0, "P_start_kpa must be >= 0")
    bad(R0s < get["R0_mm"], "R0_start_mm must be >= R0_mm")


# ------------------------------------------------------------------------------------------------
# vectorised kernel
# ------------------------------------------------------------------------------------------------
def _xi(u, c, s, omc, wbar):
    ib, _ = _ibar(u, c, omc, wbar)
    return 1.0 / (s * ib)


def _bisect(f, a, b, iters=60):
    """Vectorised bisection for a sign change of ``f`` between ``a`` (f > 0) and ``b`` (f <= 0)."""
    for _ in range(iters):
        m = 0.5 * (a + b)
        pos = f(m) > 0
        a, b = np.where(pos, m, a), np.where(pos, b, m)
    return 0.5 * (a + b)


def _limits(cs: CaseArrays, order: int):
    """Vectorised :func:`bendpam.curvature_limits`: (k_min, k_max) per case."""
    phi, wbar = gauss_nodes(order)
    omc = 1.0 - np.cos(phi)
    a0 = cs.alpha0
    c, s = np.cos(a0), np.sin(a0)
    u_lock = (1.0 / c - 1.0) / 2.0
    R0, t0 = cs.R0_start, cs.t0_start

    def lumen(u, cc=c[..., None], ss=s[..., None], R=R0[..., None], t=t0[..., None]):
        x = _xi(u, cc, ss, omc, wbar)
        return R * x * x * (1.0 + u) - t

    out = []
    for end in (LOCK_FRACTION * u_lock, np.full(a0.shape, -0.5 * (1.0 - MIN_FAR_STRETCH))):
        grid = end[..., None] * np.linspace(0.0, 1.0, 201)
        vals = lumen(grid)
        neg = vals <= 0.0
        has = neg.any(axis=-1)
        j = np.where(has, np.argmax(neg, axis=-1), 1)
        a = np.take_along_axis(grid, (j - 1)[..., None], -1)[..., 0]
        b = np.take_along_axis(grid, j[..., None], -1)[..., 0]
        root = _bisect(lambda u: lumen(u[..., None])[..., 0], a, b) if has.any() else a
        u_end = np.where(has, root, end)
        out.append(u_end / (R0 * _xi(u_end[..., None], c[..., None], s[..., None], omc, wbar)[..., 0]))
    return out[1], out[0]


def _branch(cs: CaseArrays, mod, order: int, eq19: bool):
    """Vectorised :func:`bendpam.branch_info`: sampled branch tables and their ends, per case."""
    sgn = cs.bend_sign
    k_min, k_max = _limits(cs, order)
    k_lim = np.where(sgn > 0, k_max, k_min)
    frac = np.linspace(0.0, 1.0, _BRANCH_SAMPLES + 1)[1:] ** 1.5
    kg = k_lim[..., None] * frac
    col = cs.col()
    A, B = mod.coefficients(col, kg, order=order, eq19_factor=eq19)
    sA = sgn[..., None] * A
    with np.errstate(divide="ignore", invalid="ignore"):
        p = np.where(sA > 0.0, B / A, np.nan)
    n = kg.shape[-1]
    bad_a = ~(sA > 0.0)
    n_ok = np.where(bad_a.any(-1), np.argmax(bad_a, -1), n)
    pk = np.concatenate([np.zeros(kg.shape[:-1] + (1,)), p], axis=-1)
    kk = np.concatenate([np.zeros(kg.shape[:-1] + (1,)), kg], axis=-1)
    idx = np.arange(n + 1)
    valid = idx[None, :] <= n_ok[..., None]  # the first n_ok samples (+ the origin)
    pk_valid = np.where(valid, pk, np.nan)
    dec = (np.diff(pk_valid, axis=-1) <= 0.0) & valid[..., 1:]
    has_dec = dec.any(-1)
    j = np.where(has_dec, np.argmax(dec, -1), 0)
    # fold refinement: golden-section maximisation of p on [kk[j-1], kk[j+1]]
    jl = np.clip(j - 1, 0, n)
    jr = np.clip(j + 1, 0, n)
    lo = np.take_along_axis(kk, jl[..., None], -1)[..., 0]
    hi = np.take_along_axis(kk, jr[..., None], -1)[..., 0]
    a_, b_ = np.minimum(lo, hi), np.maximum(lo, hi)

    def p_of(x):
        Ax, Bx = mod.coefficients(cs, x, order=order, eq19_factor=eq19)
        with np.errstate(divide="ignore", invalid="ignore"):
            return Bx / Ax

    g = (math.sqrt(5.0) - 1.0) / 2.0
    x1, x2 = b_ - g * (b_ - a_), a_ + g * (b_ - a_)
    f1, f2 = p_of(x1), p_of(x2)
    for _ in range(60):
        left = f1 > f2  # the maximum lies in [a, x2]
        b_ = np.where(left, x2, b_)
        a_ = np.where(left, a_, x1)
        new = np.where(left, b_ - g * (b_ - a_), a_ + g * (b_ - a_))
        fnew = p_of(new)
        x1, f1, x2, f2 = (np.where(left, new, x2), np.where(left, fnew, f2),
                          np.where(left, x1, new), np.where(left, f1, fnew))
    xm = 0.5 * (a_ + b_)
    pj = np.take_along_axis(pk, j[..., None], -1)[..., 0]
    pm = p_of(xm)
    use_ref = np.isfinite(pm) & (pm > pj)
    k_fold = np.where(use_ref, xm, np.take_along_axis(kk, j[..., None], -1)[..., 0])
    p_fold = np.where(use_ref, pm, pj)
    # assemble per case: end kind, end curvature, end active pressure
    kind = np.where(has_dec, BRANCH_END["fold"], np.where(n_ok < n, BRANCH_END["unbounded"], BRANCH_END["lock-up"]))
    kind = np.where(sgn == 0, BRANCH_END["neutral"], kind)
    unstable = has_dec & (j == 0)
    p_end = np.where(kind == BRANCH_END["fold"], np.where(unstable, 0.0, p_fold),
                     np.where(kind == BRANCH_END["unbounded"], np.inf,
                              np.take_along_axis(pk, np.minimum(n_ok, n)[..., None], -1)[..., 0]))
    p_end = np.where(kind == BRANCH_END["neutral"], np.inf, p_end)
    # monotone table for bracketing: samples up to the branch end, then +inf
    last = np.where(kind == BRANCH_END["fold"], j, np.minimum(n_ok, n))
    in_tab = idx[None, :] <= last[..., None]
    kt = kk.copy()
    pt = np.where(in_tab, pk, np.inf)
    # the unbounded case brackets up to the first sample where A lost its sign
    nxt = np.clip(last + 1, 0, n)
    k_after = np.take_along_axis(kk, nxt[..., None], -1)[..., 0]
    k_end = np.where(kind == BRANCH_END["fold"], k_fold, np.where(kind == BRANCH_END["unbounded"], k_after, k_lim))
    return dict(sgn=sgn, k_lim=k_lim, kind=kind, p_end=p_end, k_end=k_end, last=last, kt=kt, pt=pt,
                k_fold=k_fold, p_fold=p_fold, use_ref=use_ref)


def _roots(cs: CaseArrays, mod, br: dict, pa: np.ndarray, order: int, eq19: bool, xtol: float = 1e-13):
    """Free curvature for active pressures ``pa`` (cases, pressures) on each case's branch."""
    sgn = br["sgn"][..., None]
    kt, pt = br["kt"], br["pt"]
    # bracket: first table index with p >= pa (the table is increasing up to its end, then inf)
    j = (pt[..., None, :] < pa[..., :, None]).sum(-1)
    j = np.clip(j, 1, kt.shape[-1] - 1)
    a = np.take_along_axis(kt, j - 1, -1)
    b = np.take_along_axis(kt, j, -1)
    # a fold end lies between table samples: use it as the bracket end where it applies
    fold_end = (br["kind"] == BRANCH_END["fold"])[..., None] & br["use_ref"][..., None] & (j > br["last"][..., None])
    b = np.where(fold_end, br["k_fold"][..., None], b)
    # the unbounded case: beyond the last finite sample, bracket up to where A changed sign
    unb = (br["kind"] == BRANCH_END["unbounded"])[..., None] & (j > br["last"][..., None])
    b = np.where(unb, br["k_end"][..., None], b)
    a = np.where(unb | fold_end, np.take_along_axis(kt, np.broadcast_to(br["last"][..., None], j.shape), -1), a)
    case = np.broadcast_to(np.arange(pa.shape[0])[:, None], pa.shape).ravel()
    pa_flat, sgn_flat = pa.ravel(), np.broadcast_to(sgn, pa.shape).ravel()

    def F(x, idx):
        sub = CaseArrays(**{f: np.asarray(v)[case[idx]] for f, v in cs.__dict__.items()})
        A, B = mod.coefficients(sub, x, order=order, eq19_factor=eq19)
        return sgn_flat[idx] * (pa_flat[idx] * A - B)

    tol = xtol * np.abs(br["k_end"])[:, None] + np.zeros(pa.shape) + 1e-300
    return illinois(F, a, b, tol)


def evaluate_cases(base: Actuator, model: str, values: dict[str, np.ndarray], pressure_kpa, *,
                   order: int = DEFAULT_ORDER, eq19_factor: bool = True) -> dict[str, np.ndarray]:
    """The sweep kernel: all outputs for the cases in ``values`` (1-D arrays) at ``pressure_kpa``.

    Returns arrays of shape (cases, pressures) and (cases,) keyed by the names in the module doc.
    """
    mod = get_model(normalise_model(model))
    cs = CaseArrays.build(base, values)
    P = np.asarray(pressure_kpa, dtype=float) * 1e-3
    pa = np.maximum(P[None, :] - cs.P_start[:, None], 0.0)
    A0, _ = mod.coefficients(cs, np.zeros(cs.alpha0.shape), order=order, eq19_factor=eq19_factor)
    blocked = pa * A0[:, None]
    br = _branch(cs, mod, order, eq19_factor)
    k = np.zeros(pa.shape)
    above = pa > br["p_end"][:, None]
    solve = (pa > 0.0) & ~above & (br["sgn"][:, None] != 0)
    if np.any(solve):
        rows = np.flatnonzero(solve.any(axis=1))
        sub = CaseArrays(**{f: np.asarray(v)[rows] for f, v in cs.__dict__.items()})
        br_sub = {key: (v[rows] if np.ndim(v) else v) for key, v in br.items()}
        pa_sub = np.where(solve[rows], pa[rows], np.nan)
        # solve with a harmless pressure where no root is wanted, then discard
        safe = np.where(solve[rows], pa[rows], np.take_along_axis(br_sub["pt"], np.ones((rows.size, 1), int), -1))
        x = _roots(sub, mod, br_sub, safe, order, eq19_factor)
        k[rows] = np.where(solve[rows], x, 0.0)
        del pa_sub
    k = np.where(above, np.nan, k)
    k_lim = np.abs(br["k_lim"])[:, None]
    with np.errstate(invalid="ignore"):
        margin = 1.0 - np.abs(k) / k_lim
    return {
        "blocked_moment_nmm": blocked,
        "free_curvature_per_mm": k,
        "free_angle_deg": np.degrees(k * cs.L0[:, None]),
        "lockup_margin": margin,
        "frame_stress_mpa": cs.frame_modulus[:, None] * cs.frame_thickness[:, None] * 0.5 * np.abs(k),
        "max_pressure_kpa": (cs.P_start + br["p_end"]) * 1e3,
        "branch_end": br["kind"].astype(float),
    }


# ------------------------------------------------------------------------------------------------
# the sweep
# ------------------------------------------------------------------------------------------------
def _grid_values(params: dict) -> dict[str, np.ndarray]:
    out = {}
    for name, vals in params.items():
        if name not in SWEEP_PARAMETERS:
            raise ValueError(f"cannot sweep {name!r}; choose from {', '.join(SWEEP_PARAMETERS)}")
        arr = np.atleast_1d(np.asarray(vals, dtype=float))
        if arr.ndim != 1 or arr.size == 0:
            raise ValueError(f"sweep values of {name} must be a non-empty 1-D list")
        if not np.all(np.isfinite(arr)):
            raise ValueError(f"sweep values of {name} must be finite")
        out[name] = arr
    return out


def _block(base, model, names, grids, P, order, eq19, idx_block):
    """Kernel for one block of flat case indices (any shape B) -> array B + (pressures, outputs)."""
    idx_block = np.asarray(idx_block)
    shape = tuple(g.size for g in grids)
    flat = idx_block.ravel()
    if names:
        sub = np.unravel_index(flat, shape)
        values = {n: g[i] for n, g, i in zip(names, grids, sub)}
    else:
        values = {"alpha0_deg": np.full(flat.size, base.alpha0_deg)}
    res = evaluate_cases(base, model, values, P, order=order, eq19_factor=eq19)
    out = np.empty((flat.size, P.size, len(_OUTPUTS)))
    for i, name in enumerate(_OUTPUTS):
        v = res[name]
        out[:, :, i] = v if v.ndim == 2 else v[:, None]
    return out.reshape(idx_block.shape + (P.size, len(_OUTPUTS)))


def sweep(base_actuator: Actuator, pressure_kpa, model: str = "energy", *, chunk_cases: int = 256,
          scheduler: str | None = None, workers: int | None = None, compute: bool = True, progress: bool | None = None,
          order: int = DEFAULT_ORDER, eq19_factor: bool = True, **params) -> xr.Dataset:
    """Sweep actuator parameters crossed with pressures.  See the module docstring.

    Parameters
    ----------
    base_actuator : the actuator whose other parameters are kept.
    pressure_kpa : 1-D pressures (kPa).
    model : ``"energy"`` or ``"force_balance"``.
    chunk_cases : cases per block (memory bound).
    scheduler : address of a Dask distributed scheduler (e.g. ``"tcp://127.0.0.1:8786"``).
    workers : start a ``LocalCluster`` with this many worker processes (loopback only).
    compute : return computed (NumPy-backed) data; ``False`` keeps a lazy Dask-backed dataset.
    progress : show a progress bar (default: for sweeps of at least 20 blocks).
    **params : Actuator field names with 1-D values, e.g. ``alpha0_deg=np.linspace(60, 80, 41)``.
    """
    if not isinstance(base_actuator, Actuator):
        raise TypeError(f"base_actuator must be a bendpam.Actuator, got {type(base_actuator).__name__}")
    model = normalise_model(model)
    P = np.atleast_1d(np.asarray(pressure_kpa, dtype=float))
    if P.ndim != 1 or P.size == 0 or not np.all(np.isfinite(P)) or np.any(P < 0):
        raise ValueError("pressure_kpa must be a non-empty 1-D list of pressures >= 0 kPa")
    grids_d = _grid_values(params)
    names = list(grids_d)
    grids = [grids_d[n] for n in names]
    shape = tuple(g.size for g in grids)
    n_cases = int(np.prod(shape)) if shape else 1
    chunk_cases = int(chunk_cases)
    if chunk_cases < 1:
        raise ValueError(f"chunk_cases = {chunk_cases} must be >= 1")
    # validate before any work (the same checks as Actuator): every combination of the
    # parameters that constrain each other, each other parameter on its own
    _prevalidate(base_actuator, names, grids)
    chunks = _natural_chunks(shape, chunk_cases)
    n_blocks = int(np.prod([len(c) for c in chunks])) if shape else 1
    show = progress if progress is not None else (n_blocks >= 20 and sys.stderr.isatty())
    fn = _block_fn(base_actuator, model, names, grids, P, order, eq19_factor)
    try:
        import dask.array as da
    except ImportError:
        da = None
    if da is None:
        if scheduler or workers or not compute:
            raise ValueError("distributed or lazy sweeps need Dask: pip install 'bendpam[distributed]'")
        data = _loop_blocks(fn, shape, chunks, show)
    else:
        idx = da.arange(n_cases, chunks=n_cases).reshape(shape or (1,)).rechunk(chunks or ((1,),))
        nd = idx.ndim
        arr = idx.map_blocks(fn, dtype=float, new_axis=[nd, nd + 1],
                             chunks=idx.chunks + ((P.size,), (len(_OUTPUTS),)), meta=np.empty((0,) * (nd + 2)))
        data = _compute(arr, scheduler, workers, show) if compute else arr
    return _dataset(data, names, grids, shape, P, base_actuator, model, order)


def _natural_chunks(shape: tuple[int, ...], chunk_cases: int) -> tuple[tuple[int, ...], ...]:
    """Block the case grid so that each block holds at most ``chunk_cases`` cases.

    Trailing dimensions are kept whole while they fit; the first dimension that does not fit is
    split, and the ones before it go one index at a time.
    """
    out = []
    prod = 1
    split = False
    for size in reversed(shape):
        if split:
            out.append((1,) * size)
            continue
        if prod * size <= chunk_cases:
            out.append((size,))
            prod *= size
        else:
            step = max(chunk_cases // prod, 1)
            out.append(tuple(min(step, size - i) for i in range(0, size, step)))
            split = True
    return tuple(reversed(out))


_COUPLED = ({"t0_mm", "R0_mm", "R0_start_mm"}, {"C10_kpa", "C01_kpa"})


def _prevalidate(base, names, grids) -> None:
    done = set()
    for group in _COUPLED:
        sel = [i for i, n in enumerate(names) if n in group]
        if sel:
            mesh = np.meshgrid(*(grids[i] for i in sel), indexing="ij", sparse=True)
            CaseArrays.build(base, {names[i]: m for i, m in zip(sel, mesh)})
            done.update(sel)
    for i, n in enumerate(names):
        if i not in done:
            CaseArrays.build(base, {n: grids[i]})


class _block_fn:
    """Picklable block kernel (for distributed workers)."""

    def __init__(self, base, model, names, grids, P, order, eq19):
        self.args = (base, model, names, grids, P, order, eq19)

    def __call__(self, idx_block):
        return _block(*self.args, idx_block)


def _loop_blocks(fn, shape, chunks, show):
    """The same blocks as the Dask path, computed in a loop (no Dask installed)."""
    flat = np.arange(int(np.prod(shape)) if shape else 1).reshape(shape or (1,))
    bounds = [np.cumsum((0,) + c) for c in (chunks or ((1,),))]
    blocks = list(np.ndindex(*[len(c) for c in (chunks or ((1,),))]))
    if show:
        from rich.progress import track

        blocks = track(blocks, description="sweep", transient=True)
    out = None
    for b in blocks:
        sl = tuple(slice(bd[i], bd[i + 1]) for bd, i in zip(bounds, b))
        res = fn(flat[sl])
        if out is None:
            out = np.empty(flat.shape + res.shape[-2:])
        out[sl] = res
    return out


def _compute(arr, scheduler, workers, show):
    import dask

    if scheduler or workers:
        from distributed import Client, LocalCluster, progress as dprogress

        if scheduler:
            client = Client(scheduler)
            cluster = None
        else:
            cluster = LocalCluster(n_workers=int(workers), threads_per_worker=1, processes=True,
                                   host="127.0.0.1", dashboard_address=None)
            client = Client(cluster)
        try:
            fut = client.compute(arr)
            if show:
                dprogress(fut)
            return fut.result()
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
    if show:
        from dask.diagnostics import ProgressBar

        with ProgressBar(out=sys.stderr):
            return dask.compute(arr, scheduler="threads")[0]
    return dask.compute(arr, scheduler="threads")[0]


def _dataset(data, names, grids, shape, P, base, model, order) -> xr.Dataset:
    dims = names + ["pressure_kpa"]
    vars_ = {}
    for i, name in enumerate(_OUTPUTS):
        if name in ("max_pressure_kpa", "branch_end"):
            v = data[..., 0, i]
            d = names
        else:
            v = data[..., i]
            d = dims
        if not shape:  # no swept parameter: drop the dummy case axis
            v = v[0]
        if name == "branch_end":
            v = v.astype(np.int8)
        unit, long_name = _UNITS[name]
        vars_[name] = xr.DataArray(v, dims=d, attrs={"units": unit, "long_name": long_name})
    coords = {n: (n, g, {"units": n.rsplit("_", 1)[-1]}) for n, g in zip(names, grids)}
    coords["pressure_kpa"] = ("pressure_kpa", P, {"units": "kPa"})
    ds = xr.Dataset(vars_, coords=coords)
    ds.attrs.update(model=model, base_actuator=base.to_toml(), quadrature_order=int(order),
                    branch_end_meanings="0 lock-up, 1 fold, 2 unbounded, 3 neutral",
                    sign_convention="k' > 0 toward the frame; BC-PAM values are negative")
    return ds
