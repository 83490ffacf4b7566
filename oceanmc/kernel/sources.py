"""Where photons come from: the sun's collimated beam and the sky's diffuse radiance, sampled in
proportion to their contribution to the downward plane irradiance just above the surface
(scene/sky_maps.py documents the sky shapes and the map conventions)."""
import math

import numpy as np

from .compile import kernel, setup
from .geometry import from_angles
from .models import SKY_CARDIOIDAL, SKY_HARRISON_COOMBES, SKY_MAP, SKY_MAP_COSINE
from .rng import uniform
from .search import interval


@kernel
def sky_cosine(sky_model, rng):
    """Cosine of the travel direction's angle from nadir for a sky photon: density proportional to
    L(theta) cos(theta). Uniform L: cos = sqrt(u). Cardioidal L ~ 1 + 2 cos: the cosine-weighted
    draw is accepted with probability (1 + 2 cos)/3 (rejection, exact)."""
    if sky_model == SKY_CARDIOIDAL:
        while True:
            mu = math.sqrt(uniform(rng))
            if 3.0 * uniform(rng) < 1.0 + 2.0 * mu:
                return mu
    return math.sqrt(uniform(rng))


@kernel
def harrison_coombes(floats, p, ux, uy, uz):
    """Harrison & Coombes (1988) radiance of the sky element a photon travelling (ux, uy, uz)
    comes from (floats[p:p + 4]: sun travel direction, cos of the sun zenith); sky_maps.py has the
    formula."""
    cos_psi = min(1.0, max(-1.0, ux * floats[p] + uy * floats[p + 1] + uz * floats[p + 2]))
    psi = math.acos(cos_psi)
    horizon = 1.0 - math.exp(-0.19 / uz) if uz > 0.0 else 1.0
    return ((1.63 + 53.7 * math.exp(-5.49 * psi) + 2.04 * cos_psi * cos_psi * floats[p + 3])
            * horizon * (1.0 - math.exp(-0.53 / floats[p + 3])))


@kernel
def sky_direction(sky, floats, rng):
    """(ux, uy, uz, weight factor) of a sky photon's travel direction. Tabulated skies: a row by
    the marginal CDF, a cell by the row's conditional CDF, sin^2(theta) and phi uniform within
    the cell (density exactly proportional to the cell's L cos); the map gives the view
    direction, the photon travels the opposite way (phi + 180 deg). Harrison-Coombes is weighted
    by L(direction) / L(cell), so its exact radiance is reproduced; maps and the analytic shapes
    have factor 1. A cosine-sampled map draws sin^2(theta) and phi_view uniformly (density
    cos / pi over the hemisphere), finds the cell by bisection on the same edges and takes the
    cell's L pi / E as the factor (the cell_l table holds it; sky_maps.cosine_weights)."""
    model = sky.model
    if model == SKY_MAP or model == SKY_HARRISON_COOMBES or model == SKY_MAP_COSINE:
        n_cols = sky.n_cols
        if model == SKY_MAP_COSINE:
            s = uniform(rng)
            phi_view = floats[sky.phi_edges] + 2.0 * math.pi * uniform(rng)
            # the cell holding (s, phi_view), edge[i] <= value < edge[i + 1]; the final edge is
            # not read (the last cell if rounding puts phi_view on it)
            row = interval(floats, sky.s_edges, -1, sky.n_rows, s)
            col = interval(floats, sky.phi_edges, -1, n_cols, phi_view)
        else:
            # the row and cell with cdf[i - 1] <= u < cdf[i], cdf[-1] = 0; the last entry, 1, is
            # not read
            row = interval(floats, sky.row_cdf, -1, sky.n_rows - 1, uniform(rng)) + 1
            col = interval(floats, sky.cell_cdf + row * n_cols, -1, n_cols - 1, uniform(rng)) + 1
            s0 = floats[sky.s_edges + row]
            s = s0 + uniform(rng) * (floats[sky.s_edges + row + 1] - s0)
            p0 = floats[sky.phi_edges + col]
            phi_view = p0 + uniform(rng) * (floats[sky.phi_edges + col + 1] - p0)
        sin_t = math.sqrt(min(1.0, max(0.0, s)))
        uz = math.sqrt(max(0.0, 1.0 - s))
        ux = -sin_t * math.cos(phi_view)
        uy = -sin_t * math.sin(phi_view)
        cell_l = floats[sky.cell_l + row * n_cols + col]
        if model == SKY_HARRISON_COOMBES:
            return ux, uy, uz, harrison_coombes(floats, sky.params, ux, uy, uz) / cell_l
        if model == SKY_MAP_COSINE:
            return ux, uy, uz, cell_l
        return ux, uy, uz, 1.0
    mu = sky_cosine(model, rng)
    ux, uy, uz = from_angles(mu, 2.0 * math.pi * uniform(rng))
    return ux, uy, uz, 1.0


@setup
def sky_many(sky_record, floats, n, rng):
    """Rows (ux, uy, uz, weight factor) of n sky photons drawn from the stream rng (tests and
    reports)."""
    sky = sky_record[0]
    out = np.empty((n, 4))
    for k in range(n):
        ux, uy, uz, m = sky_direction(sky, floats, rng)
        out[k, 0] = ux
        out[k, 1] = uy
        out[k, 2] = uz
        out[k, 3] = m
    return out
