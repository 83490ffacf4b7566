"""The kernel's random streams (kernel/rng.py): xoshiro256** against a plain-Python transcription
of the reference C code, one stream per (seed, batch), uniform statistics."""
import math

import numpy as np
import pytest

from oceanmc.kernel.rng import batch_state, uniform

MASK = (1 << 64) - 1


def reference_next(s):
    """xoshiro256** as in https://prng.di.unimi.it/xoshiro256starstar.c (Blackman & Vigna
    2021), on Python integers; s: a list of 4 words, advanced in place."""
    def rotl(x, k):
        return ((x << k) | (x >> (64 - k))) & MASK
    result = (rotl((s[1] * 5) & MASK, 7) * 9) & MASK
    t = (s[1] << 17) & MASK
    s[2] ^= s[0]
    s[3] ^= s[1]
    s[1] ^= s[2]
    s[0] ^= s[3]
    s[2] ^= t
    s[3] = rotl(s[3], 45)
    return result


@pytest.mark.parametrize("seed, batch", [(0, 0), (1, 0), (510, 3), (2**63 + 5, 1000)])
def test_matches_the_reference(seed, batch):
    state = batch_state(seed, batch)
    words = [int(w) for w in state]
    expected_state = list(np.random.SeedSequence(seed, spawn_key=(batch,)).generate_state(
        4, np.uint64))
    assert words == [int(w) for w in expected_state]
    for _ in range(1000):
        assert uniform(state) == (reference_next(words) >> 11) * 2.0 ** -53
    assert [int(w) for w in state] == words


def test_distinct_seeds_distinct_streams():
    """Seeds 510 and 898 gave batch streams that were identical bit for bit with the 32-bit
    seeds of before; now every (seed, batch) pair below has its own stream."""
    firsts = {}
    for seed in (510, 898, 0, 1, 2):
        for batch in range(64):
            state = batch_state(seed, batch)
            key = tuple(uniform(state) for _ in range(4))
            assert key not in firsts, (seed, batch, firsts.get(key))
            firsts[key] = (seed, batch)


def test_uniform_statistics():
    """Mean, variance and the 16-bin histogram of 10^6 draws against U[0, 1): z-scores of the
    mean and variance below 4, chi-square of the bins below its 1e-4 quantile (15 dof: 44.3),
    lag-1 correlation within 4 standard errors of 0."""
    state = batch_state(12345, 7)
    n = 1_000_000
    u = np.array([uniform(state) for _ in range(n)])
    assert u.min() >= 0.0 and u.max() < 1.0
    assert abs((u.mean() - 0.5) / math.sqrt(1.0 / 12.0 / n)) < 4.0
    # the variance of the sample variance of U[0, 1) is (1/80 - 1/144) / n
    assert abs((u.var() - 1.0 / 12.0) / math.sqrt((1.0 / 80.0 - 1.0 / 144.0) / n)) < 4.0
    counts = np.histogram(u, bins=16, range=(0.0, 1.0))[0]
    expected = n / 16
    assert np.sum((counts - expected) ** 2 / expected) < 44.3
    r = np.corrcoef(u[:-1], u[1:])[0, 1]
    assert abs(r) * math.sqrt(n) < 4.0
