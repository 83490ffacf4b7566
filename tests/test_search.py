"""The kernel's one search (kernel/search.py) against numpy.searchsorted, under the compiled
function: random sorted stretches of a flat pool with ties, at offsets into the pool, values
below, on and above every entry, sub-ranges lo .. hi and the imaginary ends lo = -1 and
hi = length (the pool's entries beyond the stretch are NaN and out of order, so a read of an end
would show), rising and falling; and the callers that reduce to it."""
import numpy as np
import pytest

from oceanmc.kernel.search import interval
from oceanmc.kernel.tally import theta_band


def stretch(rng, n, falling):
    """n sorted entries with many ties (drawn from a few values, some of them repeated)."""
    levels = np.sort(rng.uniform(-5.0, 5.0, size=max(1, n // 3)))
    values = np.sort(rng.choice(levels, size=n))
    return values[::-1].copy() if falling else values


def probes(rng, values):
    """Every entry, its neighbours one ulp away, points between and beyond, and the infinities."""
    return np.concatenate([values, np.nextafter(values, -np.inf), np.nextafter(values, np.inf),
                           rng.uniform(values.min() - 1.0, values.max() + 1.0, size=16),
                           [-np.inf, np.inf, values.min() - 100.0, values.max() + 100.0]])


def expected(values, lo, hi, x, falling):
    """lo + how many of values[lo + 1 .. hi - 1] are <= x (falling: >= x)."""
    inner = values[lo + 1:hi]
    if falling:
        return lo + int(np.searchsorted(-inner, -x, side="right"))
    return lo + int(np.searchsorted(inner, x, side="right"))


@pytest.mark.parametrize("falling", [False, True])
def test_interval_matches_searchsorted(falling):
    rng = np.random.default_rng(11 + falling)
    checked = 0
    for _ in range(200):
        n = int(rng.integers(1, 40))
        values = stretch(rng, n, falling)
        pad = int(rng.integers(1, 4))
        junk = np.array([np.nan, 1e300, -1e300, 0.0])
        pool = np.concatenate([junk[:pad], values, junk[:pad][::-1]])
        start = pad
        ranges = [(-1, n), (0, n - 1), (0, n), (-1, n - 1)]
        for _ in range(4):
            lo = int(rng.integers(-1, n))
            ranges.append((lo, int(rng.integers(lo + 1, n + 1))))
        for lo, hi in ranges:
            if hi <= lo:
                continue
            for x in probes(rng, values):
                got = interval(pool, start, lo, hi, x, falling)
                assert got == expected(values, lo, hi, x, falling), (values, lo, hi, x)
                assert lo <= got <= max(lo, hi - 1)
                checked += 1
    assert checked > 50_000


def test_interval_contract_examples():
    v = np.array([0.0, 1.0, 1.0, 1.0, 2.0, 3.0])
    assert interval(v, 0, 0, 5, 1.0) == 3        # a tie: the interval after the last equal entry
    assert interval(v, 0, 0, 5, 0.999) == 0
    assert interval(v, 0, 0, 5, -7.0) == 0       # below values[lo + 1]: lo
    assert interval(v, 0, 0, 5, 3.0) == 4        # at or above values[hi - 1]: hi - 1
    assert interval(v, 0, -1, 5, -7.0) == -1     # lo = -1: an end that counts as -inf
    assert interval(v, 1, -1, 5, 1.5) == 2       # the stretch v[1:6] at offset 1, both ends
    assert interval(v, 1, -1, 5, 3.5) == 4       # imaginary (v[0] and v[6] are not read)
    assert interval(v, 0, 2, 3, 2.5) == 2        # hi = lo + 1 reads nothing
    assert interval(v, 0, 0, 5, np.nan) == 0     # NaN x: lo
    f = v[::-1].copy()                           # 3, 2, 1, 1, 1, 0
    assert interval(f, 0, 0, 5, 1.0, True) == 4  # a falling tie: after the last equal entry
    assert interval(f, 0, 0, 5, 1.5, True) == 1
    assert interval(f, 0, 0, 5, 9.0, True) == 0
    assert interval(f, 0, 0, 5, -9.0, True) == 4
    assert interval(f, 0, 0, 5, np.nan, True) == 0


def test_theta_band_is_a_falling_search():
    """tally.theta_band: mu_edges[i] >= uz > mu_edges[i + 1], the end bands taking whatever
    falls beyond the first and last edges."""
    rng = np.random.default_rng(3)
    mu = np.cos(np.radians(np.array([0.0, 10.0, 20.0, 40.0, 60.0, 80.0, 88.0, 90.0, 92.0, 100.0,
                                     120.0, 150.0, 170.0, 180.0])))
    for uz in np.concatenate([mu, np.nextafter(mu, 2.0), np.nextafter(mu, -2.0),
                              rng.uniform(-1.0, 1.0, 2000), [-1.5, 1.5, -0.0]]):
        band = int(np.searchsorted(-mu[1:-1], -uz, side="right"))
        assert theta_band(uz, mu) == band, uz
