"""Helpers of the inelastic-light tests (tests/test_inelastic.py, tests/test_cdom_fluorescence.py),
written here from their definitions, not taken from oceanmc."""
from __future__ import annotations

import numpy as np


def trapezoid_weights(wl: np.ndarray) -> np.ndarray:
    """The hat integrals of a grid (nm): half the gaps on either side."""
    w = np.zeros(len(wl))
    gaps = np.diff(wl)
    w[:-1] += 0.5 * gaps
    w[1:] += 0.5 * gaps
    return w


def hat_integral(wl: np.ndarray, sigma: np.ndarray, j: int, mask=None) -> float:
    """(1 / (sigma_j l_j)) int hat_j(l') sigma(l') l' [mask(l')] dl', sigma interpolated
    linearly between the grid's wavelengths, by 8-point Gauss-Legendre on each side of l_j
    (exact for the cubic integrand; written here, not taken from oceanmc): the photons a
    process takes around l_j per unit of its take at l_j, in units of l_j's photons."""
    x, weights = np.polynomial.legendre.leggauss(8)
    total = 0.0
    for a, b in ((j - 1, j), (j, j + 1)):
        if a < 0 or b >= len(wl):
            continue
        lo, hi = wl[a], wl[b]
        lam = 0.5 * (hi - lo) * x + 0.5 * (hi + lo)
        hat = (lam - lo) / (hi - lo) if b == j else (hi - lam) / (hi - lo)
        s = np.interp(lam, wl, sigma)
        m = np.ones_like(lam) if mask is None else mask(lam)
        total += 0.5 * (hi - lo) * float((weights * hat * s * lam * m).sum())
    return total / (sigma[j] * wl[j])


def z_of(value, stderr, reference):
    """z-scores, 0 where the standard error is 0 and the value equals the reference to 1e-9
    (a quantity without noise), inf where it is 0 and they differ."""
    value, stderr = np.asarray(value, float), np.asarray(stderr, float)
    diff = value - reference
    exact = np.abs(diff) <= 1e-9
    safe = np.where(stderr > 0.0, stderr, 1.0)
    return np.where(stderr > 0.0, diff / safe, np.where(exact, 0.0, np.inf))


def assert_budgets_close(result, sources: dict, z_max: float) -> dict:
    """Each part's budget total equals its source (elastic 1, an inelastic part 0) within
    z_max standard errors, or to 1e-9 where it has no noise; returns each part's max |z|."""
    worst = {}
    for part, source in sources.items():
        total = result[f"{part}/budget/total"]
        se = result.stderr(f"{part}/budget/total")
        z = z_of(total, se, source)
        worst[part] = float(np.abs(z).max())
        ok = (np.abs(total - source) <= z_max * se) | (np.abs(total - source) <= 1e-9)
        assert ok.all(), (part, z)
    return worst


def assert_estimates_agree(result, reference, quantities, z_max: float) -> dict:
    """Two independent estimates of each quantity agree within |z| < z_max (both standard
    errors) wherever the reference is lit (above 1e-3 of its largest value); returns each
    quantity's max |z|."""
    worst = {}
    for quantity in quantities:
        expected = reference[quantity]
        lit = np.abs(expected) > 1e-3 * np.abs(expected).max()
        z = z_of(result[quantity] - expected,
                 np.hypot(result.stderr(quantity), reference.stderr(quantity)), 0.0)[lit]
        worst[quantity] = float(np.abs(z).max())
        assert (np.abs(z) < z_max).all(), (quantity, z)
    return worst
