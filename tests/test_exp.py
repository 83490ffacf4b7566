"""The kernel's exp (kernel/exp.py) against libm's exp (math.exp, glibc: correctly rounded in
nearly every case): within 1 unit in the last place wherever the result is a normal float,
within one subnormal step below 2^-1022, the same special values."""
import math

import numpy as np
import pytest
from numba import njit

from oceanmc.kernel.exp import exp

SMALLEST_NORMAL = np.finfo(np.float64).tiny
SUBNORMAL_STEP = 5e-324


@njit(cache=False)
def _kernel_exp(x, out):
    for i in range(x.size):
        out[i] = exp(x[i])


def kernel_exp(x):
    out = np.empty_like(x)
    _kernel_exp(x, out)
    return out


def libm_exp(x):
    return np.array([math.exp(v) if v < 709.79 else math.inf for v in x])


def test_within_one_ulp_of_libm_over_the_whole_range():
    rng = np.random.default_rng(20261127)
    x = np.concatenate([
        rng.uniform(-745.0, 709.7, 400_000),            # every binade of the result
        rng.uniform(-0.5, 0.5, 200_000),                 # the reduced range itself
        np.logspace(-300, 2.8, 20_000), -np.logspace(-300, 2.8, 20_000),   # tiny |x|
        np.arange(-1074, 1024) * math.log(2.0),          # at and beside the powers of 2
        np.arange(-1074, 1024) * math.log(2.0) + 0.5 * math.log(2.0)])   # k's rounding ties
    ours, libm = kernel_exp(x), libm_exp(x)
    normal = libm >= SMALLEST_NORMAL
    ulps = np.abs(ours[normal] - libm[normal]) / np.spacing(libm[normal])
    assert ulps.max() <= 1.0, x[normal][np.argmax(ulps)]
    assert ulps.mean() < 0.2    # measured 0.09: most results are libm's exactly
    subnormal = ~normal
    assert subnormal.sum() > 100
    assert np.abs(ours[subnormal] - libm[subnormal]).max() <= SUBNORMAL_STEP


@pytest.mark.parametrize("x, expected", [
    (0.0, 1.0), (-0.0, 1.0), (math.inf, math.inf), (-math.inf, 0.0),
    (709.78, math.exp(709.78)), (709.79, math.inf), (1e300, math.inf),
    (-745.13, 5e-324), (-745.14, 0.0), (-1e300, 0.0)])
def test_special_values(x, expected):
    assert kernel_exp(np.array([x]))[0] == expected


def test_nan_gives_nan():
    assert math.isnan(kernel_exp(np.array([math.nan]))[0])
