"""Statistics for the validation checks: jackknife estimates over batches, z-scores and tolerances.

Every Monte Carlo quantity comes with its per-batch values. `JK` carries an estimate together with
its leave-one-batch-out values, so that any smooth function of batch means (ratios such as
Lw / Eu, band averages, differences between runs) gets a jackknife standard error; for a linear
function this is exactly the usual standard error of the batch mean. Independent runs with the
same number of batches may be combined batch by batch (their batch pairs are independent and
identically distributed), which is how reciprocity pairs and multi-run averages get their errors.
"""
from __future__ import annotations

import math

import numpy as np
from scipy import stats as _st

FAMILY_ALPHA = 1e-3   # false-alarm probability allowed for a group of compared quantities
MIN_Z_TOL = 4.0       # never accept less than |z| < 4 (DESIGN.md section 5)


class JK:
    """An estimate (value) with its leave-one-batch-out replicates loo (batch axis first)."""

    __array_priority__ = 1000

    def __init__(self, value, loo):
        self.value = np.asarray(value, dtype=np.float64)
        self.loo = np.asarray(loo, dtype=np.float64)

    @classmethod
    def from_batches(cls, batches) -> "JK":
        x = np.asarray(batches, dtype=np.float64)
        n = x.shape[0]
        mean = x.mean(axis=0)
        return cls(mean, (n * mean[None, ...] - x) / (n - 1))

    @classmethod
    def of(cls, result, name: str) -> "JK":
        return cls.from_batches(result.quantities[name].batches)

    @classmethod
    def const(cls, value, n_batches: int) -> "JK":
        v = np.asarray(value, dtype=np.float64)
        return cls(v, np.broadcast_to(v, (n_batches,) + v.shape))

    @property
    def n(self) -> int:
        return self.loo.shape[0]

    @property
    def stderr(self) -> np.ndarray:
        n = self.n
        centred = self.loo - self.loo.mean(axis=0)
        return np.sqrt((n - 1) / n * np.sum(centred * centred, axis=0))

    @property
    def shape(self):
        return self.value.shape

    def _other(self, other):
        if isinstance(other, JK):
            if other.n != self.n:
                raise ValueError(f"cannot combine estimates over {self.n} and {other.n} batches")
            return other.value, other.loo
        o = np.asarray(other, dtype=np.float64)
        return o, o

    def _op(self, other, fn):
        ov, ol = self._other(other)
        nd = max(self.value.ndim, np.ndim(ov))

        def lift(loo, value_ndim):   # (batch, *shape) -> (batch, 1.., *shape), numpy-style
            return loo.reshape((loo.shape[0],) + (1,) * (nd - value_ndim) + loo.shape[1:])
        a = lift(self.loo, self.value.ndim)
        b = lift(ol, np.ndim(ov)) if isinstance(other, JK) else ol
        return JK(fn(self.value, ov), fn(a, b))

    def __add__(self, other):
        return self._op(other, np.add)

    __radd__ = __add__

    def __sub__(self, other):
        return self._op(other, np.subtract)

    def __rsub__(self, other):
        return self._op(other, lambda a, b: np.subtract(b, a))

    def __mul__(self, other):
        return self._op(other, np.multiply)

    __rmul__ = __mul__

    def __truediv__(self, other):
        return self._op(other, np.divide)

    def __rtruediv__(self, other):
        return self._op(other, lambda a, b: np.divide(b, a))

    def __neg__(self):
        return JK(-self.value, -self.loo)

    def __getitem__(self, key):
        if not isinstance(key, tuple):
            key = (key,)
        return JK(self.value[key], self.loo[(slice(None),) + key])

    def sum(self, axis=None):
        return self._reduce(np.sum, axis)

    def mean(self, axis=None):
        return self._reduce(np.mean, axis)

    def _reduce(self, fn, axis):
        if axis is None:
            return JK(fn(self.value), fn(self.loo.reshape(self.n, -1), axis=1))
        axes = (axis,) if isinstance(axis, int) else tuple(axis)
        axes_v = tuple(a % self.value.ndim for a in axes)
        return JK(fn(self.value, axis=axes_v), fn(self.loo, axis=tuple(a + 1 for a in axes_v)))

    def apply(self, fn):
        """Any function of the estimate, applied to the value and to every replicate."""
        return JK(fn(self.value), np.stack([fn(x) for x in self.loo]))


def z_tolerance(n_compared: int, n_batches: int) -> float:
    """|z| bound for one of n_compared quantities: Bonferroni over the group at FAMILY_ALPHA with
    Student's t (batches - 1 degrees of freedom, since the standard error is estimated from the
    batches), and never below MIN_Z_TOL."""
    df = max(n_batches - 1, 2)
    tail = FAMILY_ALPHA / (2.0 * max(n_compared, 1))
    return max(MIN_Z_TOL, float(_st.t.isf(tail, df)))


def chi2_z(z: np.ndarray, n_batches: int) -> float:
    """The sum of squared z-scores of a group, standardised: for t-distributed z with nu = batches
    - 1 degrees of freedom E[t^2] = nu/(nu-2) and Var[t^2] = 2 nu^2 (nu-1)/((nu-2)^2 (nu-4)).
    Large positive values mean the estimates scatter about the references more than their errors
    allow (a bias spread thinly over many bins)."""
    z = np.asarray(z, dtype=np.float64)
    z = z[np.isfinite(z)]
    if z.size == 0:
        return 0.0
    nu = max(n_batches - 1, 5)
    mean = nu / (nu - 2.0)
    var = 2.0 * nu * nu * (nu - 1.0) / ((nu - 2.0) ** 2 * (nu - 4.0))
    return float((np.sum(z * z) - z.size * mean) / math.sqrt(z.size * var))


def hotelling_z(diff: np.ndarray, loo: np.ndarray, ref_error=None) -> float | None:
    """Joint test of a group of correlated estimates (e.g. Ed at several depths from the same
    photons): Hotelling's T^2 = d' S^-1 d with S the jackknife covariance of the estimates (plus
    the references' own variances), converted through F(N, B - N) to a one-sided normal z.
    None when there are too few batches for a stable covariance (N > B/2)."""
    diff = np.asarray(diff, dtype=np.float64).ravel()
    loo = np.asarray(loo, dtype=np.float64).reshape(loo.shape[0], -1)
    b, n = loo.shape
    if n < 2 or n > b // 2 or not np.all(np.isfinite(diff)):
        return None
    centred = loo - loo.mean(axis=0)
    cov = (b - 1) / b * centred.T @ centred
    if ref_error is not None:
        cov = cov + np.diag(np.asarray(ref_error, dtype=np.float64).ravel() ** 2)
    try:
        t2 = float(diff @ np.linalg.solve(cov, diff))
    except np.linalg.LinAlgError:
        return None
    if not math.isfinite(t2) or t2 < 0:
        return None
    f = t2 * (b - n) / (n * (b - 1))
    p = float(_st.f.sf(f, n, b - n))
    return float(_st.norm.isf(max(p, 1e-300)))


def z_score(value, stderr, reference, ref_error=0.0):
    """(value - reference) / sqrt(stderr^2 + ref_error^2); 0 when both the difference and the
    error vanish, +-inf when only the error does."""
    value = np.asarray(value, dtype=np.float64)
    err = np.sqrt(np.asarray(stderr, dtype=np.float64) ** 2
                  + np.asarray(ref_error, dtype=np.float64) ** 2)
    diff = value - np.asarray(reference, dtype=np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        z = np.where(err > 0, diff / np.where(err > 0, err, 1.0),
                     np.where(diff == 0, 0.0, np.sign(diff) * np.inf))
    return z
