"""A tabulated phase function: nodes psi (rad), density q = 2 pi p sin(psi) piecewise linear
between them, and its exact CDF (built in scene/phase_tables.py), stored in a flat pool: the
table's psi, q and cdf start at psi_at, q_at and cdf_at and have `length` nodes. Sampling inverts
the CDF exactly: within a node interval the CDF is quadratic in psi."""
import math

from ..compile import kernel

EDGE = 1e-12


@kernel
def sample_angle(pool, psi_at, q_at, cdf_at, length, u):
    """(node i, angle psi) sampled by inverting the CDF, psi[i] <= psi <= psi[i + 1]."""
    lo = 0
    hi = length - 1
    while hi - lo > 1:  # cdf[lo] <= u < cdf[hi]
        mid = (lo + hi) >> 1
        if pool[cdf_at + mid] <= u:
            lo = mid
        else:
            hi = mid
    need = u - pool[cdf_at + lo]
    q0 = pool[q_at + lo]
    psi0 = pool[psi_at + lo]
    psi1 = pool[psi_at + lo + 1]
    slope = (pool[q_at + lo + 1] - q0) / (psi1 - psi0)
    disc = q0 * q0 + 2.0 * slope * need
    root = q0 + math.sqrt(max(0.0, disc))
    x = 2.0 * need / root if root > 0.0 else 0.0
    return lo, min(psi1, psi0 + x)


@kernel
def sample(pool, psi_at, q_at, cdf_at, length, u):
    return math.cos(sample_angle(pool, psi_at, q_at, cdf_at, length, u)[1])


@kernel
def locate(pool, psi_at, length, angle):
    """(node i, fraction) with psi[i] <= angle < psi[i + 1] in the table's angle grid: where the
    angle falls, for every table on that grid (phase/dispatch.py searches a shared grid once)."""
    lo = 0
    hi = length - 1
    while hi - lo > 1:
        mid = (lo + hi) >> 1
        if pool[psi_at + mid] <= angle:
            lo = mid
        else:
            hi = mid
    psi0 = pool[psi_at + lo]
    return lo, (angle - psi0) / (pool[psi_at + lo + 1] - psi0)


@kernel
def interpolate(pool, q_at, node, frac):
    """q at the located angle: linear between the nodes (exact for this table)."""
    q0 = pool[q_at + node]
    return q0 + frac * (pool[q_at + node + 1] - q0)


@kernel
def density(pool, psi_at, q_at, length, angle):
    """q(angle) = 2 pi p sin(angle), the probability per unit scattering angle (exact: linear
    between nodes)."""
    node, frac = locate(pool, psi_at, length, angle)
    return interpolate(pool, q_at, node, frac)


@kernel
def clamped_angle(cos_psi):
    """The scattering angle, kept EDGE rad inside [0, pi]: at psi = 0 and pi both q and
    2 pi sin psi vanish; with q linear there the ratio tends to a finite limit."""
    return min(math.pi - EDGE, max(EDGE, math.acos(min(1.0, max(-1.0, cos_psi)))))


@kernel
def evaluate(pool, psi_at, q_at, length, cos_psi):
    """p(psi) = q / (2 pi sin psi)."""
    angle = clamped_angle(cos_psi)
    return density(pool, psi_at, q_at, length, angle) / (2.0 * math.pi * math.sin(angle))
