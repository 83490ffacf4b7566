"""What the rough-sea tests share (tests/test_surface_cox_munk.py, tests/test_surface_table.py):
light carried from one cell of directions to another by the surface, and a cell's projected
solid angle, for reciprocity checks (Heitz et al. 2016, 5.3; Veach 1997, 5.2)."""
import math

import numba

from oceanmc.kernel.rng import uniform
from oceanmc.kernel.surface import dispatch


@numba.njit
def cell_transfer(surface, floats, from_air, a, b, n, rng):
    """Light arriving uniformly in projected solid angle from the cell a = (theta0, theta1, phi0,
    phi1) of directions pointing away from the surface on the incident side (polar angle from
    the outward normal): the number of n samples that leave into cell b, on the far side when
    b's angles are negative (transmitted), on the incident side otherwise. floats: the scene's
    float pool (the surface's table), or None (its facet walk)."""
    hits = 0
    sign = 1.0 if from_air else -1.0   # oceanmc's uz of travel into the surface
    for _ in range(n):
        c0, c1 = math.cos(a[0]) ** 2, math.cos(a[1]) ** 2
        mu = math.sqrt(c0 + (c1 - c0) * uniform(rng))   # cosine-weighted within the cell
        phi = a[2] + (a[3] - a[2]) * uniform(rng)
        s = math.sqrt(1.0 - mu * mu)
        ox, oy, oz, w, t = dispatch.sample(surface, -s * math.cos(phi), -s * math.sin(phi),
                                           sign * mu, uniform(rng), rng, floats)
        if t != (b[0] < 0.0):
            continue
        theta = math.acos(min(1.0, abs(oz)))
        phi_o = math.atan2(oy, ox) % (2.0 * math.pi)
        if abs(b[0]) <= theta < abs(b[1]) and abs(b[2]) <= phi_o < abs(b[3]):
            hits += 1
    return hits


def projected(cell):
    """The projected solid angle of a cell: integral of cos over it."""
    t0, t1, p0, p1 = (abs(x) for x in cell)
    return 0.5 * (math.sin(t1) ** 2 - math.sin(t0) ** 2) * (p1 - p0)
