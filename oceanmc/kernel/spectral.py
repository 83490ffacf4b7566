"""All wavelengths in one photon history: hero-wavelength sampling with spectral multiple
importance sampling (Wilkie et al. 2014, "Hero wavelength spectral sampling", Computer Graphics
Forum 33(4), 123-131), inside the implicit-capture walk of transport.py.

Each photon draws a hero wavelength h uniformly among the scene's n wavelengths (p.wavelength);
its path x is sampled exactly as the monochromatic walk at h samples it (free paths with c_h,
new directions from the phase mixture at h, roulette on its weight p.w). Every wavelength l
scores the path with the one-sample multiple-importance estimator and the balance heuristic
(Veach 1997, PhD thesis, section 9.2.4), the techniques being the n monochromatic walks, each
chosen with probability 1/n:

    F_l(x) = f_l(x) / ((1/n) sum_j p_j(x)) = W_l(x) R_l / mean_j R_j,

with f_l the path's contribution at l, p_j the density with which the walk at j samples x,
W_l = f_l / p_l the weight the monochromatic walk at l carries on x and R_j = p_j(x) / p_h(x).
Unbiased: E_h E_x[F_l] = sum_h (1/n) int p_h f_l / mean_j p_j = int f_l. Bound: R_l / mean_j R_j
<= n, so no wavelength ever weighs more than n times what its own walk would carry on x.

The walk keeps F_l = p.w G_l / mean_j K_j, with p.w a common factor (the source's weight, the
surface's, the hero's albedos, roulette) and, per wavelength, K_j (R_j) and G_j:
- a collision at scattering angle psi multiplies G_j by beta_j(psi) / beta_h(psi) (the albedo
  times the phase function times the free-path density, b_j p_j / (b_h p_h), the hero's albedo
  going to p.w) and K_j by (c_j p_j) / (c_h p_h): products, no exponential;
- a free path of length s in a scattering layer only adds s to D; the factor exp(-(c_j - c_h)
  D) of both is applied when the packet settles (settle): on every plane (layer boundaries,
  tally depths, surface, bottom), before any score, and when a K_j grows past a bound. So a
  collision costs a few products per wavelength, and a settle one exponential per wavelength.
- After a settle mean K = 1, so G_j is F_j / p.w, the share q_j a scorer multiplies a packet's
  weight by (tally.score).
- What a layer absorbs is what enters it less what leaves it: a settle adds F_j(last settle) -
  F_j(now) to the layer's absorption (the collisions' implicit capture since then, and the
  roulette's gains), and a packet that loses roulette adds what it carried at the last settle.
  Every path thus closes its own budget at every wavelength.
The surface (Fresnel with one n_water), the rough surface's facet walk and the bottom's sampled
direction are the same at every wavelength (they act on p.w); the bottom's reflectance may
differ (bottom_q). Roulette acts on the largest F_j (survives_roulette); it is unbiased whatever
it acts on, since every wavelength's weight is divided by the same survival probability. (On the
hero's weight alone, walks were half as long but a blue wavelength carried by a red hero lost
roulette early: 30 times the variance at 400 nm in a Case-1 water.)

The packet's spectral state lives at the head of the batch's tally row (grid.spectral; not a
tally, the results skip it), so every scorer reaches it without another argument: K (n), G (n),
F at the last settle (n), D, then scratch for one collision's beta_j (n).
"""
import math

from .compile import kernel
from .models import BUDGET_BOTTOM, BUDGET_LAYERS, BUDGET_LOST_BELOW, PHASE_TABULATED
from .phase import dispatch as phase
from .phase import tabulated
from .rng import uniform

# a K_j past this settles the packet (its exponentials bring the K back near 1), long before
# products of ratios could overflow
K_BOUND = 1e100


@kernel
def start(grid, gf, tally, p, from_sky, rng):
    """A new photon: its wavelengths' shares of the source (sun or sky: grid.source_q) and its
    hero wavelength."""
    n = grid.n_wl
    m = grid.spectral
    row = grid.source_q + (n if from_sky else 0)
    for j in range(n):
        tally[m + j] = 1.0
        tally[m + n + j] = gf[row + j]
        tally[m + 2 * n + j] = 0.0
    tally[m + 3 * n] = 0.0
    p.wavelength = min(n - 1, int(uniform(rng) * n))


@kernel
def carry(grid, tally, p):
    """The packet's weights as they are now are what it carries on in its layer (it has just
    entered the water, or been reflected by the surface or the bottom)."""
    n = grid.n_wl
    g = grid.spectral + n
    for j in range(n):
        tally[g + n + j] = p.w * tally[g + j]


@kernel
def advance(grid, tally, dist):
    """A free path of length dist in a scattering layer (its exponentials wait for settle)."""
    tally[grid.spectral + 3 * grid.n_wl] += dist


@kernel
def settle(medium, mf, grid, tally, p, layer):
    """Applies exp(-(c_j - c_h) D) to K_j and G_j, scales them to mean K = 1 (G_j is then the
    share q_j of p.w), and adds to the layer's absorption what each wavelength lost since the
    last settle."""
    n = grid.n_wl
    m = grid.spectral
    g = m + n
    last = m + 2 * n
    dist = tally[m + 3 * n]
    row = medium.layer_c + layer * n
    total = 0.0
    if dist > 0.0:
        c_h = mf[row + p.wavelength]
        for j in range(n):
            factor = math.exp(-(mf[row + j] - c_h) * dist)
            tally[m + j] *= factor
            tally[g + j] *= factor
            total += tally[m + j]
        tally[m + 3 * n] = 0.0
    else:
        for j in range(n):
            total += tally[m + j]
    norm = n / total
    absorbed = grid.budget + BUDGET_LAYERS + layer
    for j in range(n):
        tally[m + j] *= norm
        tally[g + j] *= norm
        now = p.w * tally[g + j]
        tally[absorbed + j * grid.wl_stride] += tally[last + j] - now
        tally[last + j] = now


@kernel
def volume_scattering(medium, mf, mi, grid, tally, layer, cos_s, beta):
    """beta_j(psi) of every wavelength of the layer into tally[beta:beta + n_wl], from the
    layer's terms (MEDIUM mix_*): one search per angle grid, then rows of n_wl numbers."""
    n = grid.n_wl
    for j in range(n):
        tally[beta + j] = 0.0
    angle = tabulated.clamped_angle(cos_s)
    per_density = 1.0 / (2.0 * math.pi * math.sin(angle))
    for e in range(mi[medium.mix_ptr + layer], mi[medium.mix_ptr + layer + 1]):
        k = mi[medium.mix_comp + e]
        at = medium.mix_coef + mi[medium.mix_at + e]
        if mi[medium.comp_model + k] == PHASE_TABULATED:
            psi_at, _, _, length = phase.table_at(medium, mi, k)
            node, frac = tabulated.locate(mf, psi_at, length, angle)
            lo = at + node * n
            for j in range(n):
                q0 = mf[lo + j]
                tally[beta + j] += (q0 + frac * (mf[lo + n + j] - q0)) * per_density
        else:
            value = phase.evaluate_component(medium, mf, mi, k, cos_s)
            for j in range(n):
                tally[beta + j] += mf[at + j] * value


@kernel
def scatter(medium, mf, mi, grid, tally, p, layer, cos_s):
    """A collision that turned the packet by cos_s (p.w already times the hero's albedo): G_j
    times beta_j / beta_h and K_j times (c_j p_j) / (c_h p_h) = (beta_j c_j / b_j) / (beta_h
    c_h / b_h)."""
    n = grid.n_wl
    m = grid.spectral
    g = m + n
    beta = m + 3 * n + 1
    volume_scattering(medium, mf, mi, grid, tally, layer, cos_s, beta)
    row = medium.layer_c_over_b + layer * n
    h = p.wavelength
    per_beta = 1.0 / tally[beta + h]
    per_k = per_beta / mf[row + h]
    top = 0.0
    for j in range(n):
        tally[g + j] *= tally[beta + j] * per_beta
        tally[m + j] *= tally[beta + j] * mf[row + j] * per_k
        top = max(top, tally[m + j])
    if top > K_BOUND:
        settle(medium, mf, grid, tally, p, layer)


@kernel
def lose(grid, tally, layer):
    """The packet lost roulette in `layer`: what it carried at its last settle stays there."""
    n = grid.n_wl
    last = grid.spectral + 2 * n
    absorbed = grid.budget + BUDGET_LAYERS + layer
    for j in range(n):
        tally[absorbed + j * grid.wl_stride] += tally[last + j]


@kernel
def attenuate(medium, mf, grid, tally, p, layer, dist):
    """A layer that scatters at no wavelength: wavelength j keeps exp(-c_j dist) (the plane's
    settle books the rest as absorbed); dist = inf (down an infinitely deep layer): all of it
    is absorbed there, or lost below where c_j = 0. Returns whether the packet is gone."""
    n = grid.n_wl
    g = grid.spectral + n
    row = medium.layer_c + layer * n
    if dist < math.inf:
        for j in range(n):
            tally[g + j] *= math.exp(-mf[row + j] * dist)
        return False
    settle(medium, mf, grid, tally, p, layer)
    absorbed = grid.budget + BUDGET_LAYERS + layer
    for j in range(n):
        where = absorbed if mf[row + j] > 0.0 else grid.budget + BUDGET_LOST_BELOW
        tally[where + j * grid.wl_stride] += p.w * tally[g + j]
    return True


@kernel
def reflect(grid, gf, tally, p, rho):
    """The bottom reflects rho (the sampled BRDF's weight, on p.w) times wavelength j's share
    bottom_q_j of the reflectance (on G_j); the rest is absorbed by the bottom."""
    n = grid.n_wl
    g = grid.spectral + n
    absorbed = grid.budget + BUDGET_BOTTOM
    for j in range(n):
        kept = rho * gf[grid.bottom_q + j]
        tally[absorbed + j * grid.wl_stride] += p.w * tally[g + j] * (1.0 - kept)
        tally[g + j] *= gf[grid.bottom_q + j]
    p.w *= rho
    carry(grid, tally, p)


@kernel
def survives_roulette(medium, mf, ctrl, grid, tally, p, layer, rng):
    """Roulette after a collision, on the largest wavelength weight max_j F_j (as transport's
    survives_roulette on p.w): a packet with p.w at or above the threshold goes on untested;
    below it, the packet settles and p.w becomes max_j F_j (G_j / max G, so F is unchanged),
    which then plays roulette. So the exponentials of a settle are paid only near the end of a
    walk, and a hero wavelength that is absorbed fast does not end a path that other
    wavelengths still carry. The loser's weights stay in the layer (lose)."""
    if p.w >= ctrl.roulette_weight:
        return True
    settle(medium, mf, grid, tally, p, layer)
    n = grid.n_wl
    g = grid.spectral + n
    top = 0.0
    for j in range(n):
        top = max(top, tally[g + j])
    if top > 0.0:
        for j in range(n):
            tally[g + j] /= top
        p.w *= top
    if p.w >= ctrl.roulette_weight:
        return True
    if uniform(rng) < ctrl.roulette_survival:
        p.w /= ctrl.roulette_survival
        return True
    lose(grid, tally, layer)
    return False
