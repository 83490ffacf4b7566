"""All wavelengths in one photon history: hero-wavelength sampling with spectral multiple
importance sampling (Wilkie et al. 2014, "Hero wavelength spectral sampling", Computer Graphics
Forum 33(4), 123-131), inside the implicit-capture walk of transport.py.

Each photon draws a hero wavelength h uniformly among the scene's n wavelengths (p.wavelength);
its path x is sampled exactly as the monochromatic walk at h samples it (free paths with c_h,
new directions from the phase mixture at h). Every wavelength l scores the path with the
one-sample multiple-importance estimator and the balance heuristic (Veach 1997, PhD thesis,
section 9.2.4), the techniques being the n monochromatic walks, each chosen with probability 1/n:

    F_l(x) = f_l(x) / ((1/n) sum_j p_j(x)) = W_l(x) R_l / mean_j R_j,

with f_l the path's contribution at l, p_j the density with which the walk at j samples x,
W_l = f_l / p_l the weight the monochromatic walk at l carries on x (albedos, attenuation in
layers that do not scatter, bottom reflectance, roulette) and R_j = p_j(x) / p_h(x) the density
ratios, products over the events so far: free paths (c_j exp(-c_j s) / (c_h exp(-c_h s)) to a
collision, exp(-(c_j - c_h) d) across a segment) and turns (p_j(cos) / p_h(cos), each
wavelength's own phase mixture). The surface (Fresnel with one n_water) and the bottom's
sampled direction are the same at every wavelength, so they cancel from R; the bottom's
reflectance may differ (bottom_q). Unbiased: E_h E_x[F_l] = sum_h (1/n) int p_h f_l / mean_j p_j
= int f_l. Roulette and the surface's reflect-or-leave draw act on the whole path, with the same
factor at every wavelength.

Bound on the weights: R_l / mean_j R_j <= n, so F_l <= n W_l: no wavelength ever weighs more
than n_wl times what its own monochromatic walk would carry on the same path (W_l <= 1 there, up
to roulette's 1 / roulette_survival), however different the wavelengths' optics.

The packet's spectral state lives at the head of the batch's tally row (grid.spectral; not a
tally, the results skip it), so every scorer reaches it without another argument: m_j = R_j /
mean R (mean 1) and q_j = F_j / p.w, with p.w = max_j F_j, what roulette and the loop's p.w > 0
test see; a scorer adds p.w q_j to wavelength j's block (tally.score). After the m_j: scratch
for one collision's phase-component values.
"""
import math

from .compile import kernel
from .models import BUDGET_BOTTOM, BUDGET_LAYERS, BUDGET_LOST_BELOW
from .phase import dispatch as phase
from .rng import uniform


@kernel
def start(grid, gf, tally, p, from_sky, from_air, rng):
    """A new photon: its wavelengths' shares of the source (sun or sky: grid.source_q) and its
    hero wavelength. from_air: its weight is the source's, not yet scaled to the largest share
    (the implicit sun packets start below the surface with the already scaled entered beam)."""
    n = grid.n_wl
    m = grid.spectral
    source = 1 if from_sky else 0
    row = grid.source_q + source * n
    for j in range(n):
        tally[m + j] = 1.0
        tally[m + n + j] = gf[row + j]
    if from_air:
        p.w *= gf[grid.source_scale + source]
    p.wavelength = min(n - 1, int(uniform(rng) * n))


@kernel
def rescale(grid, tally, p):
    """p.w becomes the largest wavelength weight F_j = p.w q_j, and the q_j its shares."""
    q = grid.spectral + grid.n_wl
    top = 0.0
    for j in range(grid.n_wl):
        top = max(top, tally[q + j])
    if top > 0.0:
        for j in range(grid.n_wl):
            tally[q + j] /= top
    p.w *= top


@kernel
def renormalise(grid, tally, p, total):
    """After the density ratios changed: m_j back to mean 1 (total: their sum), q_j with them."""
    n = grid.n_wl
    m = grid.spectral
    norm = n / total
    for j in range(n):
        tally[m + j] *= norm
        tally[m + n + j] *= norm
    rescale(grid, tally, p)


@kernel
def flight(medium, mf, grid, tally, p, layer, dist, collided):
    """The free path's density ratio over dist in a scattering layer: exp(-(c_j - c_h) dist),
    times c_j / c_h when the flight ends in a collision there (c_h > 0: the layer scatters at
    every wavelength, scene/medium.py)."""
    n = grid.n_wl
    m = grid.spectral
    row = medium.layer_c + layer
    c_h = mf[row + p.wavelength * medium.n_layers]
    total = 0.0
    for j in range(n):
        c_j = mf[row + j * medium.n_layers]
        ratio = math.exp(-(c_j - c_h) * dist)
        if collided:
            ratio *= c_j / c_h
        tally[m + j] *= ratio
        tally[m + n + j] *= ratio
        total += tally[m + j]
    renormalise(grid, tally, p, total)


@kernel
def attenuate(medium, mf, grid, tally, p, layer, dist):
    """A layer that scatters at no wavelength: wavelength j keeps exp(-c_j dist) and the rest is
    absorbed there; dist = inf (down an infinitely deep layer): all of it is absorbed there, or
    lost below where c_j = 0."""
    n = grid.n_wl
    q = grid.spectral + n
    row = medium.layer_c + layer
    absorbed = grid.budget + BUDGET_LAYERS + layer
    for j in range(n):
        c_j = mf[row + j * medium.n_layers]
        weight = p.w * tally[q + j]
        if dist == math.inf:
            where = absorbed if c_j > 0.0 else grid.budget + BUDGET_LOST_BELOW
            tally[where + j * grid.wl_stride] += weight
            tally[q + j] = 0.0
        else:
            kept = math.exp(-c_j * dist)
            tally[absorbed + j * grid.wl_stride] += weight * (1.0 - kept)
            tally[q + j] *= kept
    rescale(grid, tally, p)


@kernel
def absorb(medium, mf, grid, tally, p, layer):
    """Implicit capture at a collision, at every wavelength: j keeps albedo_j of its weight."""
    n = grid.n_wl
    q = grid.spectral + n
    row = medium.layer_albedo + layer
    absorbed = grid.budget + BUDGET_LAYERS + layer
    for j in range(n):
        albedo = mf[row + j * medium.n_layers]
        tally[absorbed + j * grid.wl_stride] += p.w * tally[q + j] * (1.0 - albedo)
        tally[q + j] *= albedo
    rescale(grid, tally, p)


@kernel
def turn(medium, mf, mi, grid, tally, p, layer, cos_s):
    """The new direction's density ratio p_j(cos_s) / p_h(cos_s), each wavelength's phase
    mixture from one evaluation of the layer's components."""
    n = grid.n_wl
    m = grid.spectral
    values = m + 2 * n
    phase.evaluate_components(medium, mf, mi, layer, cos_s, tally, values)
    p_h = phase.mixture_at(medium, mf, mi, layer, p.wavelength, tally, values)
    total = 0.0
    for j in range(n):
        ratio = phase.mixture_at(medium, mf, mi, layer, j, tally, values) / p_h
        tally[m + j] *= ratio
        tally[m + n + j] *= ratio
        total += tally[m + j]
    renormalise(grid, tally, p, total)


@kernel
def reflect(grid, gf, tally, p, rho):
    """The bottom reflects rho (the sampled BRDF's weight) times wavelength j's share bottom_q_j
    of the reflectance; the rest is absorbed by the bottom."""
    n = grid.n_wl
    q = grid.spectral + n
    absorbed = grid.budget + BUDGET_BOTTOM
    for j in range(n):
        kept = rho * gf[grid.bottom_q + j]
        tally[absorbed + j * grid.wl_stride] += p.w * tally[q + j] * (1.0 - kept)
        tally[q + j] *= kept
    rescale(grid, tally, p)
