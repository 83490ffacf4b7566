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

FAMILY_ALPHA = 1e-3   # false-alarm probability allowed for a whole validation case (all its
                      # statistical checks together: Bonferroni over them, see Ctx.finalize)
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


def z_tolerance(n_compared: int, n_batches: int, alpha: float = FAMILY_ALPHA) -> float:
    """|z| bound for one of n_compared quantities: Bonferroni over them at the family-wise
    two-sided false-alarm probability alpha, with Student's t (batches - 1 degrees of freedom,
    since the standard error is estimated from the batches), and never below MIN_Z_TOL."""
    df = max(n_batches - 1, 2)
    tail = alpha / (2.0 * max(n_compared, 1))
    return max(MIN_Z_TOL, float(_st.t.isf(tail, df)))


def summary_tolerance(n_summaries: int, alpha: float = FAMILY_ALPHA) -> float:
    """Bound for one of n_summaries one-sided normal z (group summaries: chi2_z, hotelling_z):
    Bonferroni at the family-wise false-alarm probability alpha, never below MIN_Z_TOL."""
    return max(MIN_Z_TOL, float(_st.norm.isf(alpha / max(n_summaries, 1))))


def normal_equivalent(z: np.ndarray, n_batches: int) -> np.ndarray:
    """The standard normal deviate with the same tail probability as a Student-t z of
    batches - 1 degrees of freedom (a z over a batch standard error of few batches is t
    distributed, with heavier tails than the normal)."""
    z = np.asarray(z, dtype=np.float64)
    df = max(n_batches - 1, 2)
    # the upper tail of |z|, mapped through the normal's (isf keeps precision far out)
    return np.sign(z) * _st.norm.isf(_st.t.sf(np.abs(z), df))


def chi2_z(z: np.ndarray, n_batches: int) -> float:
    """Joint test of a group of independent z-scores: each Student-t z (nu = batches - 1) is
    mapped to its normal equivalent, whose squares sum to a chi-square of N degrees of freedom;
    its upper tail probability is returned as a one-sided normal z. Large positive values mean
    the estimates scatter about the references more than their errors allow (a bias spread
    thinly over many bins). Exact for independent t members, where the standardised sum of z^2
    (a normal approximation) had a heavy right tail for small groups."""
    z = np.asarray(z, dtype=np.float64)
    z = z[np.isfinite(z)]
    if z.size == 0:
        return 0.0
    q = float(np.sum(normal_equivalent(z, n_batches) ** 2))
    return float(_st.norm.isf(max(float(_st.chi2.sf(q, z.size)), 1e-300)))


# Eigenvalues of a group's correlation matrix below RANK_RTOL of the largest are taken as zero:
# the test is made in the other directions only. A bias confined to the dropped directions, even
# at 6 of their own standard deviations, moves each member's z by at most 6 sqrt(RANK_RTOL
# lambda_max) <= 6 sqrt(RANK_RTOL p) (lambda_max <= p, the trace, for p members): 0.14 for the
# largest group (54), so nothing is given up at the members' error bars. What is gained: groups of
# members that are one shape up to fine structure (the fluorescence part of Rrs at six
# wavelengths: correlation eigenvalues of 1e-9, 1e-8, 1e-6 .. 1e-5, 3e-4 .. 3e-3, 0.01 and 1
# relative to the largest, on every seed) had T^2 dominated by directions holding 1e-9 .. 1e-6 of
# the variance, where 32 batch means of heavy-tailed scores are far from normal: its z on ten
# seeds (10^6 photons, 32 batches; members' |z| <= 1.7) was 3.21 on one and averaged 0.63 (0 +-
# 0.32 expected); with 1e-5, 0.47 and 0.29 (1e-7: 2.91 and 0.56; 1e-3: -1.96 and -0.54,
# conservative). 1e-9, before 2026-11-29, only merged exact multiples (rounding: 1e-16).
RANK_RTOL = 1e-5


def hotelling_z(diff: np.ndarray, loo: np.ndarray, ref_error=None) -> float | None:
    """Joint test of a group of correlated estimates (e.g. Ed at several depths from the same
    photons): Hotelling's T^2 = d' S^-1 d with S the jackknife covariance of the estimates (plus
    the references' own variances), converted through F(r, B - r) to a one-sided normal z, r the
    rank of the batch covariance. Estimates that are exact multiples of one another (the local
    estimates of an isotropic radiance in several directions score the same events) make S
    singular: the test is then taken in the r independent combinations only (the differences
    along the null directions carry no batch error and are the references' own business), and
    so are groups whose members are one shape up to directions holding less than RANK_RTOL of
    the variance (see there).
    None when there are too few batches for a stable covariance (r > B/2)."""
    diff = np.asarray(diff, dtype=np.float64).ravel()
    loo = np.asarray(loo, dtype=np.float64).reshape(loo.shape[0], -1)
    b, n = loo.shape
    if n < 2 or not np.all(np.isfinite(diff)) or not np.all(np.isfinite(loo)):
        return None
    centred = loo - loo.mean(axis=0)
    cov = (b - 1) / b * centred.T @ centred
    scale = np.sqrt(np.diag(cov))
    if not np.all(scale > 0):
        return None
    corr = cov / np.outer(scale, scale)
    lam, vec = np.linalg.eigh(corr)
    keep = lam > RANK_RTOL * lam.max()
    r = int(np.sum(keep))
    if r > b // 2:
        return None
    # the kept principal combinations c = V' D^-1 d, their covariance Lambda (+ references')
    basis = vec[:, keep] / scale[:, None]
    c = basis.T @ diff
    cov_c = np.diag(lam[keep])
    if ref_error is not None:
        re = np.broadcast_to(np.asarray(ref_error, dtype=np.float64), diff.shape)
        cov_c = cov_c + basis.T @ np.diag(re ** 2) @ basis
    try:
        t2 = float(c @ np.linalg.solve(cov_c, c))
    except np.linalg.LinAlgError:
        return None
    if not math.isfinite(t2) or t2 < 0:
        return None
    f = t2 * (b - r) / (r * (b - 1))
    p = float(_st.f.sf(f, r, b - r))
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
