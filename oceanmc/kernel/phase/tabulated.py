"""A tabulated phase function: nodes psi (rad), density q = 2 pi p sin(psi) piecewise linear
between them, and its exact CDF (built in scene/phase_tables.py), stored in a flat pool: the
table's psi, q and cdf start at psi_at, q_at and cdf_at and have `length` nodes. Sampling inverts
the CDF exactly: within a node interval the CDF is quadratic in psi.

The interval that holds u is found through a guide table (Chen & Asau 1974, "On generating random
variates from an empirical distribution", AIIE Transactions 6(2), 163-166; Devroye 1986,
Non-Uniform Random Variate Generation, III.2.4): guide[k] is the interval that holds k / G (G =
length - 1 cells of equal probability), so u's interval lies between guide[floor(u G)] and
guide[floor(u G) + 1], a search over a few nodes instead of all of them (a bisection of a
3,501-node table took 12 unpredictable steps, a quarter of a spectral walk's time; measured with
perf). The interval found is the same as a bisection of the whole table finds: the one with
cdf[i] <= u < cdf[i + 1]."""
import math

from ..compile import kernel
from ..search import interval

EDGE = 1e-12


@kernel
def sample_angle(pool, guide, psi_at, q_at, cdf_at, guide_at, length, u):
    """(node i, angle psi) sampled by inverting the CDF, psi[i] <= psi <= psi[i + 1]; guide:
    the int pool holding the table's guide at guide_at (length entries,
    scene/phase_tables.py guide)."""
    cells = length - 1
    cell = min(int(u * cells), cells - 1)
    lo = guide[guide_at + cell]
    hi = min(guide[guide_at + cell + 1] + 1, length - 1)
    # u * cells may round across a cell boundary: widen the bracket until it holds u
    while lo > 0 and pool[cdf_at + lo] > u:
        lo -= 1
    while hi < length - 1 and pool[cdf_at + hi] <= u:
        hi += 1
    lo = interval(pool, cdf_at, lo, hi, u)  # cdf[lo] <= u < cdf[hi]
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
def sample(pool, guide, psi_at, q_at, cdf_at, guide_at, length, u):
    return math.cos(sample_angle(pool, guide, psi_at, q_at, cdf_at, guide_at, length, u)[1])


@kernel
def locate(pool, psi_at, length, angle):
    """(node i, fraction) with psi[i] <= angle < psi[i + 1] in the table's angle grid: where the
    angle falls, for every table on that grid (phase/dispatch.py searches a shared grid once)."""
    lo = interval(pool, psi_at, 0, length - 1, angle)
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
