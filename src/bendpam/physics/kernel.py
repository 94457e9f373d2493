r"""The evaluation kernels of the fast path: ``M = max(P - P_start, 0) A(k') - k' G(k')`` from spline tables.

:class:`SplineKernel` holds the cubic pieces of ``A(k')`` and ``G(k') = B(k')/k'`` of one
:class:`~bendpam.MomentTable` and evaluates the moment at many points in one of two ways that give
**bit-identical** results (the same arithmetic in the same order, no fused multiply-add, no
fast-math):

* ``"numpy"``: NumPy in blocks of :data:`CHUNK` points that stay in cache, in-place ufuncs, about
  30 NumPy calls a block;
* ``"numba"``: one compiled loop (`numba <https://numba.pydata.org>`_, the optional extra
  ``bendpam[fast]``), with the range checks fused into the loop.  It is compiled on its first use
  in a process that asks for it (numba is imported then, never at ``import bendpam``) and cached on
  disk (``cache=True``), so a later process only loads it.

The interval of a point is the knot interval that contains it (the largest knot ``<= k'``), found
from a first guess (``arccos`` of the Chebyshev map in NumPy, a polynomial ``arccos`` in the
compiled loop: the two differ by a few units in the last place) taken half an interval low and
moved up by one comparison with the next knot, so both ways land on the same interval.

Which kernel runs (:func:`kernel_choice`): the environment variable :data:`KERNEL_ENV`
(``BENDPAM_KERNEL``) set to ``numpy`` forces NumPy, ``numba`` forces the compiled loop (an error
if numba cannot be imported), ``auto`` or unset takes the compiled loop for calls of at least
:data:`NUMBA_MIN_POINTS` points when numba imports (importing numba takes about 0.3 s, which a
small call would not win back), and NumPy otherwise.

>>> import numpy as np, bendpam
>>> table = bendpam.MomentLaw.of(bendpam.physics.presets.be_pam()).tabulated()
>>> out = np.empty(2)
>>> table.kernel.evaluate(np.array([200.0]), np.array([0.0, 0.01]), out, 2000.0, -0.1, 0.1, "numpy")
(True, 200.0)
>>> out.round(3).tolist()                                                     # N*mm
[310.329, 63.183]
"""

from __future__ import annotations

import math
import os
from functools import lru_cache
from typing import Any

import numpy as np

from bendpam.errors import InputError

__all__ = ["CHUNK", "KERNEL_ENV", "NUMBA_MIN_POINTS", "SplineKernel", "kernel_choice", "numba_kernel"]

#: The environment variable that picks the kernel: ``auto`` (default), ``numpy`` or ``numba``.
KERNEL_ENV = "BENDPAM_KERNEL"
#: ``auto`` takes the compiled kernel for calls of at least this many points (when numba imports).
NUMBA_MIN_POINTS = 1 << 18
#: Points per block of the NumPy kernel: its temporaries (64 KiB real, 128 KiB complex) stay in the L2 cache, and the
#: call overhead (about 12 us a block) is under a tenth of a block's time; 6144-16384 measured within a few per cent.
CHUNK = 8192
_KERNELS = ("auto", "numpy", "numba")
# The compiled kernel's first guess of arccos(x), x in [0, 1]: sqrt(1 - x) times a polynomial,
# Abramowitz & Stegun 4.4.46 (|error| <= 2.2e-8 rad)
_ACOS8 = (1.5707963050, -0.2145988016, 0.0889789874, -0.0501743046,
          0.0308918810, -0.0170881256, 0.0066700901, -0.0012624911)
_ACOS8_ERR = 2.3e-8
#: The guess may be off by this fraction of an interval at most (half the margin of the shift below).
_GUESS_TOL = 0.25
_BLOCK = 512  # points per block of the compiled loop


class SplineKernel:
    """The cubic pieces of ``A`` and ``G = B/k'`` on Chebyshev-Lobatto knots, and the moment kernels.

    Parameters
    ----------
    knots_per_mm : array
        The ``2 n - 1`` knots (1/mm), increasing: ``n`` Chebyshev-Lobatto points on ``[k_min, 0]``
        and ``n`` on ``[0, k_max]`` (``k' = 0`` shared).
    coef : array, shape (intervals, 8)
        Per interval ``(a3, a2, a1, a0, g3, g2, g1, g0)``: ``A = ((a3 dx + a2) dx + a1) dx + a0``
        with ``dx = k' - knot``, and the same for ``G``.
    P_start_kpa : float
        The threshold pressure (kPa).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.cos(np.linspace(0.0, np.pi, 3))
    >>> kj = np.concatenate([-0.5 * (1 + t), 0.5 * (1 - t[1:])])          # 5 knots on [-1, 1]
    >>> coef = np.zeros((4, 8)); coef[:, 3] = 2.0; coef[:, 7] = 1.0         # A = 2, G = 1
    >>> kern = SplineKernel(kj, coef, 10.0)
    >>> kern.interval(np.array([-1.0, -0.5, 0.0, 0.7, 1.0])).tolist()
    [0, 1, 2, 3, 3]
    >>> out = np.empty(2)
    >>> kern.evaluate(np.array([30.0, 5.0]), np.array([0.5, -0.5]), out, 100.0, -1.0, 1.0, "numpy"), out.tolist()
    ((True, 30.0), [39.5, 0.5])
    """

    def __init__(self, knots_per_mm, coef, P_start_kpa: float):
        kj = np.ascontiguousarray(knots_per_mm, dtype=float)
        c = np.ascontiguousarray(coef, dtype=float)
        if kj.ndim != 1 or kj.size < 5 or kj.size % 2 == 0 or c.shape != (kj.size - 1, 8):
            raise InputError(f"SplineKernel needs 2 n - 1 >= 5 knots and (intervals, 8) coefficients, "
                             f"not {kj.shape} and {c.shape}")
        self.knots_per_mm = kj
        self.coef = c
        self.P_start_kpa = float(P_start_kpa)
        n1 = (kj.size - 1) // 2
        self._n1 = n1
        self._last = kj.size - 2
        self._scale = n1 / math.pi
        self._shift = n1 - 0.5  # the guess half an interval low: the true interval is the guess or the next
        lo, hi = float(kj[0]), float(kj[-1])
        self._inv_lo, self._inv_hi = 1.0 / lo, 1.0 / hi
        # NumPy's guess: r = 1 + k m with m = -2 / (the lock-up limit on k's side), i.e. 1 + min(k m_lo, k m_hi) (the
        # product with the other side's m is the positive one: no np.where).  The m shrunk by 4 eps keep r in [-1, 1]
        # through the rounding (no clip); r is then off by at most 11 eps, arccos(r) by sqrt(22 eps) rad.
        eps = float(np.finfo(float).eps)
        if self._scale * max(math.sqrt(22.0 * eps) + 1e-14, _ACOS8_ERR) >= _GUESS_TOL:
            raise InputError(f"SplineKernel takes at most 2 x 10^7 knots (a first guess must land within a quarter "
                             f"interval), not {kj.size}")
        self._m_lo, self._m_hi = np.array(-2.0 * (1.0 - 4.0 * eps) / lo), np.array(-2.0 * (1.0 - 4.0 * eps) / hi)
        self._sc, self._sh, self._one = np.array(self._scale), np.array(self._shift), np.array(1.0)
        self._next = np.append(kj[1:-1], np.inf)  # the knot after each interval's start (none after the last)
        self._zk = kj[:-1].astype(complex)  # each interval's start + 0i
        self._zcols = tuple(_complex(c[:, i], c[:, 4 + i]) for i in range(4))  # a_i + i g_i

    def interval(self, k) -> np.ndarray:
        """The knot interval of each real curvature ``k`` (1/mm): the largest knot ``<= k``, within [0, intervals)."""
        kk = np.minimum(np.asarray(k, dtype=float).reshape(-1), self.knots_per_mm[-1])
        np.maximum(kk, self.knots_per_mm[0], out=kk)  # outside the knots: the first or the last interval
        j = np.empty(kk.size, dtype=np.intp)
        t, r = np.empty(min(CHUNK, kk.size)), np.empty(min(CHUNK, kk.size))
        for s0 in range(0, kk.size, CHUNK):
            m = min(CHUNK, kk.size - s0)
            j[s0:s0 + m] = self._interval(kk[s0:s0 + m], t[:m], r[:m])
        return j.reshape(np.shape(k))

    def _interval(self, kk: np.ndarray, t: np.ndarray, r: np.ndarray) -> np.ndarray:
        """The intervals of curvatures within the knots (``t``, ``r``: work arrays of ``kk``'s size)."""
        np.multiply(kk, self._m_lo, out=t)
        np.multiply(kk, self._m_hi, out=r)
        np.minimum(r, t, out=r)
        r += self._one  # 1 - 2 k / (lock-up limit on k's side), in [-1, 1]
        np.arccos(r, out=r)
        r *= self._sc
        np.copysign(r, kk, out=r)  # k < 0: n1 - th (left piece), k >= 0: n1 + th
        r += self._sh
        j = r.astype(np.intp)  # in [0, intervals): r is in [-0.5, 2 n1 - 0.5] up to rounding
        j += kk >= self._next.take(j)
        return j

    def evaluate(self, P, k, out, limit_kpa: float, k_min: float, k_max: float,
                 kernel: str | None = None) -> tuple[bool, float]:
        """``out = max(P - P_start, 0) A(k) - k G(k)`` after checking ``0 <= P <= limit_kpa``, ``k_min <= k <= k_max``.

        ``P`` and ``k`` are 1-D float arrays, ``P`` of ``k``'s size or of size 1; ``out`` has ``k``'s
        size.  ``kernel``: ``"numpy"``, ``"numba"`` or None (:func:`kernel_choice`).  Returns
        ``(ok, largest pressure)``; when ``ok`` is False (a value not finite or out of range), nothing
        is computed and the caller reports the bad value.
        """
        if k.size == 0 or P.size == 0:
            return True, 0.0
        pmin, pmax = float(P.min()), float(P.max())  # NaN propagates: one reduction checks finiteness and range
        if not (0.0 <= pmin and pmax <= limit_kpa and k_min <= float(k.min()) and float(k.max()) <= k_max):
            return False, pmax
        if (kernel or kernel_choice(k.size)) == "numba":
            numba_kernel()(np.ascontiguousarray(P), np.ascontiguousarray(k), out, self.knots_per_mm, self._next,
                           self.coef, self._inv_lo, self._inv_hi, self._scale, self._shift, self._last,
                           self.P_start_kpa)
        else:
            self._moment_numpy(P, k, out)
        return True, pmax

    def _moment_numpy(self, P, k, out) -> None:
        """The NumPy kernel on checked input, in blocks of :data:`CHUNK` points.

        ``A`` and ``G`` run through Horner's steps together as one complex number ``A + iG`` (four
        gathers instead of eight): a product with ``dx + 0i`` is ``(a dx - g 0) + i (a 0 + g dx)``,
        and with one product exactly zero each part is ``a dx`` and ``g dx`` rounded once, as in the
        compiled loop's real arithmetic.  Constants are 0-d arrays and gathers ``ndarray.take`` (the
        cheapest calls: a block spends a tenth of its time in call overhead).
        """
        z3, z2, z1, z0 = self._zcols
        zk, Ps, zero = self._zk, np.array(self.P_start_kpa), np.array(0.0)
        pa_all = np.array(max(float(P[0]) - self.P_start_kpa, 0.0)) if P.size == 1 else None
        t, r = np.empty(min(CHUNK, k.size)), np.empty(min(CHUNK, k.size))
        for s0 in range(0, k.size, CHUNK):
            kk = k[s0:s0 + CHUNK]
            if kk.size < t.size:
                t, r = t[:kk.size], r[:kk.size]
            j = self._interval(kk, t, r)
            dx = zk.take(j)  # knot + 0i
            np.subtract(kk, dx.real, out=dx.real)  # k - knot + 0i
            V = z3.take(j)
            V *= dx
            V += z2.take(j)
            V *= dx
            V += z1.take(j)
            V *= dx
            V += z0.take(j)
            A, G = V.real, V.imag
            if pa_all is None:
                pa = np.subtract(P[s0:s0 + CHUNK], Ps, out=t)
                np.maximum(pa, zero, out=pa)
                A *= pa
            else:
                A *= pa_all
            G *= kk
            np.subtract(A, G, out=out[s0:s0 + CHUNK])


def _complex(re: np.ndarray, im: np.ndarray) -> np.ndarray:
    z = np.empty(re.shape, dtype=complex)
    z.real, z.imag = re, im
    return z


def _moment_loop(P, k, out, kj, nxt, C, inv_lo, inv_hi, scale, shift, last, Ps):  # pragma: no cover
    """The compiled kernel's source, on checked input (numba compiles it; the NumPy kernel's arithmetic).

    In blocks of :data:`_BLOCK` points: a first loop (branch-free, so the compiler vectorises it)
    guesses the intervals, a second one corrects each guess and evaluates the moment.
    """
    c0, c1, c2, c3, c4, c5, c6, c7 = _ACOS8
    ps = 1 if P.size == k.size else 0
    guess = np.empty(_BLOCK)
    for s in range(0, k.size, _BLOCK):
        m = min(_BLOCK, k.size - s)
        for i in range(m):
            kk = k[s + i]
            r = kk * (inv_lo if kk < 0.0 else inv_hi)
            r = min(max(r * -2.0 + 1.0, -1.0), 1.0)
            x = abs(r)
            a = math.sqrt(1.0 - x) * (c0 + x * (c1 + x * (c2 + x * (c3 + x * (c4 + x * (c5 + x * (c6 + x * c7)))))))
            guess[i] = math.copysign((a if r >= 0.0 else math.pi - a) * scale, kk) + shift
        for i in range(m):
            kk = k[s + i]
            j = min(max(int(guess[i]), 0), last)
            j += kk >= nxt[j]
            dx = kk - kj[j]
            A = ((C[j, 0] * dx + C[j, 1]) * dx + C[j, 2]) * dx + C[j, 3]
            G = ((C[j, 4] * dx + C[j, 5]) * dx + C[j, 6]) * dx + C[j, 7]
            pa = P[(s + i) * ps] - Ps
            pa = pa if pa > 0.0 else 0.0
            A = A * pa
            G = G * kk
            out[s + i] = A - G


def _numba_module() -> Any:
    """numba, or None when it is not installed or does not import (a NumPy it does not support)."""
    try:
        import numba
    except Exception:  # any failure to import (a NumPy it does not support) means: no compiled kernel
        return None
    return numba


@lru_cache(maxsize=1)
def numba_kernel():
    """The compiled kernel (numba imported and the loop compiled or loaded from its cache on the first call).

    Raises :class:`~bendpam.errors.InputError` when numba is not available.

    >>> callable(numba_kernel()) if _numba_module() else True
    True
    """
    numba = _numba_module()
    if numba is None:
        raise InputError(f"the compiled kernel needs numba (pip install 'bendpam[fast]'); set {KERNEL_ENV}=numpy "
                         "or auto to use NumPy")
    return numba.njit(cache=True, nogil=True, fastmath=False, error_model="numpy", boundscheck=False)(_moment_loop)


@lru_cache(maxsize=1)
def _have_numba() -> bool:
    return _numba_module() is not None


def kernel_choice(points: int) -> str:
    """The kernel a call of ``points`` points runs: ``"numpy"`` or ``"numba"`` (see :data:`KERNEL_ENV`).

    >>> import os
    >>> kernel_choice(10) if os.environ.get(KERNEL_ENV, "auto") == "auto" else "numpy"
    'numpy'
    """
    want = os.environ.get(KERNEL_ENV, "auto").strip().lower() or "auto"
    if want not in _KERNELS:
        raise InputError(f"environment variable {KERNEL_ENV} = {want!r} must be one of {', '.join(_KERNELS)}")
    if want == "numpy":
        return "numpy"
    if want == "numba":
        numba_kernel()  # raises when numba is missing
        return "numba"
    return "numba" if points >= NUMBA_MIN_POINTS and _have_numba() else "numpy"
