"""A tabulated phase function: nodes psi (rad), density q = 2 pi p sin(psi) piecewise linear
between them, and its exact CDF (built in phase_tables.py). Sampling inverts the CDF exactly:
within a node interval the CDF is quadratic in psi."""
import math

from numba import njit

EDGE = 1e-12


@njit(error_model="numpy", cache=True)
def sample(psi, q, cdf, start, length, u):
    lo = start
    hi = start + length - 1
    while hi - lo > 1:  # cdf[lo] <= u < cdf[hi]
        mid = (lo + hi) >> 1
        if cdf[mid] <= u:
            lo = mid
        else:
            hi = mid
    need = u - cdf[lo]
    q0 = q[lo]
    slope = (q[lo + 1] - q0) / (psi[lo + 1] - psi[lo])
    disc = q0 * q0 + 2.0 * slope * need
    root = q0 + math.sqrt(max(0.0, disc))
    x = 2.0 * need / root if root > 0.0 else 0.0
    angle = min(psi[lo + 1], psi[lo] + x)
    return math.cos(angle)


@njit(error_model="numpy", cache=True)
def density(psi, q, start, length, angle):
    """q(angle) = 2 pi p sin(angle), the probability per unit scattering angle (exact: linear
    between nodes)."""
    lo = start
    hi = start + length - 1
    while hi - lo > 1:
        mid = (lo + hi) >> 1
        if psi[mid] <= angle:
            lo = mid
        else:
            hi = mid
    frac = (angle - psi[lo]) / (psi[lo + 1] - psi[lo])
    return q[lo] + frac * (q[lo + 1] - q[lo])


@njit(error_model="numpy", cache=True)
def evaluate(psi, q, start, length, cos_psi):
    """p(psi) = q / (2 pi sin psi). At psi = 0 and pi both vanish; with q linear there the ratio
    tends to a finite limit, taken by staying EDGE rad inside the range."""
    angle = min(math.pi - EDGE, max(EDGE, math.acos(min(1.0, max(-1.0, cos_psi)))))
    return density(psi, q, start, length, angle) / (2.0 * math.pi * math.sin(angle))
