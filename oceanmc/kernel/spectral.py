"""All wavelengths in one photon history: hero-wavelength sampling with spectral multiple
importance sampling (Wilkie et al. 2014, "Hero wavelength spectral sampling", Computer Graphics
Forum 33(4), 123-131), inside the implicit-capture walk of transport.py.

Each photon draws a hero wavelength h (p.wavelength) among the scene's n wavelengths with
probability pi_h (MEDIUM hero_cdf; scene/medium.py hero_probabilities); its path x is sampled
exactly as the monochromatic walk at h samples it (free paths with c_h, new directions from the
phase mixture at h). Every wavelength l scores the path with the one-sample multiple-importance
estimator and the balance heuristic (Veach 1997, PhD thesis, section 9.2.4), the techniques
being the n monochromatic walks, walk j chosen with probability pi_j:

    F_l(x) = f_l(x) / sum_j pi_j p_j(x) = W_l(x) R_l / sum_j pi_j R_j,

with f_l the path's contribution at l, p_j the density with which the walk at j samples x,
W_l = f_l / p_l the weight the monochromatic walk at l carries on x and R_j = p_j(x) / p_h(x).
Unbiased: E_h E_x[F_l] = sum_h pi_h int p_h f_l / sum_j pi_j p_j = int f_l, for any pi > 0.
Bound: R_l / sum_j pi_j R_j <= 1 / pi_l, so no wavelength ever weighs more than 1 / pi_l times
what its own walk would carry on x. pi_j is in proportion to (1 / (1 - w0_j))^a, w0 the top
layer's single-scattering albedo (estimator.hero_exponent a, 1 by default; 0: uniform): more
heroes where walks are long, whose paths the short walks of strongly absorbed wavelengths
sample poorly. Measured (2026-11-28, the spectral bench's 6 Case-1 scenes, 2 interleaved
rounds against uniform heroes): the water-leaving fraction's worst band gained 1.3-1.8x in
the three scenes where it was weakest (clear water, blue: its long walks), Rrs nadir's worst
band stayed 4.5x or more the single-wavelength runs' FOM; a = 1.5 was no better
(benchmarks/spectral.md compares with uniform heroes).

The walk keeps F_l = p.w G_l / mean_j K_j, with p.w a common factor (the source's weight, the
surface's, the albedos, roulette) and, per wavelength, G_j and K_j = n pi_j R_j (so that
mean_j K_j = sum_j pi_j R_j):
- a collision at scattering angle psi multiplies G_j by beta_j(psi) / beta_h(psi) (the albedo
  times the phase function times the free-path density, b_j p_j / (b_h p_h), the hero's albedo
  going to p.w) and K_j by (c_j p_j) / (c_h p_h): products, no exponential (scatter);
- a free path of length s in a scattering layer only adds s to D; the factor exp(-(c_j - c_h)
  D) of both is applied when the packet settles (settle): on every plane (layer boundaries,
  tally depths, surface, bottom), before any score, and when a K_j grows past a bound. So a
  collision costs a few products per wavelength, and a settle one exponential per wavelength.
  A settle also comes when a K_j shrinks below 1 / K_BOUND, or when D is so long that a
  deferred exponential would leave exp(+-DEFERRED_EXPONENT_BOUND) (turbid water).
- p.w follows the reference wavelength r (p.reference: the heaviest at the last roulette test):
  a collision gives p.w the factor beta_r / beta_h and G_j beta_j / beta_r, a free path gives
  p.w exp(-(c_r - c_h) s) at once (fly), and a settle scales G to G_r = 1. So roulette, tested
  when p.w falls below its threshold, is tested when the wavelength that carries the packet
  has lost weight, not whenever a strongly absorbed hero has (which cost a settle at almost
  every collision of a red hero carrying blue light: 13 settles per photon against 3, Chl 1).
- After a settle mean K = 1, so p.w G_j is F_j and G_j the share q_j a scorer
  multiplies a packet's weight by (tally.score).
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

The packet's spectral state is a float row of its own, `ps` (records.packet_state_size), which
travels with the PACKET record (the split stack holds rows of both): K (n), G (n), F at the last
settle (n), D. One collision's beta_j (n) is scratch in the batch's `work` row, which no packet
keeps.

Splitting (transport.split) divides p.w and F at the last settle by the number of copies, and
each copy carries the same K, G and D: the walk has no memory, so each is an unbiased copy at
every wavelength. The analog walk draws the hero's absorption at a collision, its reflection at
the surface and at the bottom (the other wavelengths keep their ratios to the hero's weight:
one-sample MIS over analog walks); attenuation in layers that scatter at no wavelength stays
exact. Scattering biased toward straight up (upward.py) is one more sampling technique per
wavelength: each wavelength's walk would draw directions from the same mixture of its own phase
function and the upward cone (scatter_weights).
"""
import math

from .compile import internal, kernel
from .exp import exp
from .models import BUDGET_BOTTOM, BUDGET_LAYERS, BUDGET_LOST_BELOW, PHASE_TABULATED
from .phase import dispatch as phase
from .phase import tabulated
from .rng import uniform
from .packet import belong_to, free_path_at, weights
from .records import CAP_POINT_FLOATS
from .tally import deposit, deposit_all, spectral_at

# a K_j past this, or positive below its inverse, settles the packet (its exponentials bring
# the K back near 1), long before products of ratios could overflow or underflow; a K_j still
# below the inverse after a settle is 0 (its walk's density is nothing beside the others': in
# a turbid layer a hero of the largest c shrinks every other K_j by c_j / c_h per collision
# while the deferred exp((c_h - c_j) D) grows, 0 x inf = NaN without these bounds)
K_BOUND = 1e100
K_FLOOR = 1.0 / K_BOUND
# a packet whose deferred path D would make some exp(-(c_j - c_h) D) leave exp(+-this) settles
# (MEDIUM layer_settle_path, scene/medium.py): the exponentials of a settle stay finite
DEFERRED_EXPONENT_BOUND = 300.0


@kernel
def start(medium, grid, floats, ps, p, from_sky, rng):
    """A new photon: its wavelengths' shares of the source (sun or sky: grid.source_q) and its
    hero wavelength h, drawn with probability pi_h (MEDIUM hero_cdf); K_j starts at n pi_j
    (MEDIUM hero_k), so that mean K is sum_j pi_j R_j along the path. The reference wavelength
    starts as the hero."""
    n = grid.n_wl
    k, g, last, _ = weights(grid, ps)
    row = grid.source_q + (n if from_sky else 0)
    share = floats[row:row + n]
    hero_k = floats[medium.hero_k:medium.hero_k + n]
    for j in range(n):
        k[j] = hero_k[j]
        g[j] = share[j]
        last[j] = 0.0
    ps[free_path_at(grid)] = 0.0
    belong_to(grid, ps, 0)
    u = uniform(rng)
    h = 0
    while h < n - 1 and u >= floats[medium.hero_cdf + h]:
        h += 1
    p.wavelength = h
    p.reference = h


@kernel
def carry(grid, ps, p):
    """The packet's weights as they are now are what it carries on in its layer (it has just
    entered the water, or been reflected by the surface or the bottom)."""
    _, g, last, _ = weights(grid, ps)
    w = p.w
    for j in range(grid.n_wl):
        last[j] = w * g[j]


@internal
def fly(medium, floats, grid, ps, p, layer, dist):
    """A free path of length dist in a scattering layer, to a collision or a plane: its
    exponentials wait for the next settle (D), except the reference wavelength's
    exp(-(c_r - c_h) dist), which p.w takes at once (so that p.w follows F_r; see scatter;
    settle gives G_j exp(-(c_j - c_r) D) to match)."""
    ps[free_path_at(grid)] += dist
    if p.reference != p.wavelength:
        row = medium.layer_c + layer * grid.n_wl
        p.w *= math.exp(-(floats[row + p.reference] - floats[row + p.wavelength]) * dist)


@kernel
def settle(medium, floats, grid, tally, ps, p, layer):
    """Applies the deferred exponentials (K_j times exp(-(c_j - c_h) D); G_j times
    exp(-(c_j - c_r) D), as p.w took the reference wavelength's share in fly), scales K to
    mean 1 and G to G_r = 1 (so p.w is F_r, and p.w G_j is F_j), and adds to the layer's
    absorption what each wavelength lost since the last settle."""
    n = grid.n_wl
    k, g, last, share = weights(grid, ps)
    dist = ps[free_path_at(grid)]
    row = medium.layer_c + layer * n
    c = floats[row:row + n]
    r = p.reference
    if dist > 0.0:
        c_h = c[p.wavelength]
        shift = math.exp((c[r] - c_h) * dist)
        for j in range(n):
            factor = exp(-(c[j] - c_h) * dist)
            k[j] *= factor
            g[j] *= factor * shift
        ps[free_path_at(grid)] = 0.0
    total = 0.0
    for j in range(n):
        total += k[j]
    norm = n / total
    to_reference = g[r] * norm
    if to_reference > 0.0:
        p.w *= to_reference
        g_norm = norm / to_reference
    else:
        g_norm = norm
    w = p.w
    # what each wavelength lost since the last settle, F_j(last) - F_j(now), kept in `last`
    # for the one booking of every wavelength (tally.deposit_all), then F_j(now) in its place
    for j in range(n):
        k_j = k[j] * norm
        k[j] = k_j if k_j >= K_FLOOR else 0.0
        g[j] *= g_norm
        last[j] -= w * g[j]
    deposit_all(grid, tally, share, spectral_at(grid, grid.budget + BUDGET_LAYERS + layer),
                1.0, last)
    for j in range(n):
        last[j] = w * g[j]


@internal
def volume_scattering(medium, floats, ints, layer, cos_s, angle, psi_s, node_s, beta):
    """2 pi sin(psi) beta_j(psi) of every wavelength of the layer into the view beta (n_wl),
    from the layer's terms (MEDIUM mix_*): tables are read in these units (q, phase_tables.py),
    and the common factor cancels in the ratios that scatter takes. A table on the angle grid
    that the hero's direction was sampled from (psi_s) is read at the sampled node node_s, the
    others after one search per grid; then rows of n_wl numbers."""
    n = beta.shape[0]
    for j in range(n):
        beta[j] = 0.0
    angle = min(math.pi - tabulated.EDGE, max(tabulated.EDGE, angle))
    for e in range(ints[medium.mix_ptr + layer], ints[medium.mix_ptr + layer + 1]):
        k = ints[medium.mix_comp + e]
        at = medium.mix_coef + ints[medium.mix_at + e]
        if ints[medium.comp_model + k] == PHASE_TABULATED:
            psi_at, _, _, length = phase.table_at(medium, ints, k)
            if psi_at == psi_s and floats[psi_at + node_s] <= angle <= floats[psi_at + node_s + 1]:
                node = node_s
                psi0 = floats[psi_at + node]
                frac = (angle - psi0) / (floats[psi_at + node + 1] - psi0)
            else:
                node, frac = tabulated.locate(floats, psi_at, length, angle)
            lo = at + node * n
            below = floats[lo:lo + n]
            above = floats[lo + n:lo + 2 * n]
            for j in range(n):
                beta[j] += below[j] + frac * (above[j] - below[j])
        else:
            value = phase.evaluate_component(medium, floats, ints, k, cos_s) * (
                2.0 * math.pi * math.sin(angle))
            coef = floats[at:at + n]
            for j in range(n):
                beta[j] += coef[j] * value


@internal
def phase_values(medium, floats, ints, layer, cos_psi, out):
    """p_j(psi) in 1/sr of every wavelength of the layer into the view out (n_wl): the volume
    scattering function over b_j, from the same terms as the collisions' ratios (a local
    estimate toward a fixed direction; tables read after one search per angle grid)."""
    angle = tabulated.clamped_angle(cos_psi)
    volume_scattering(medium, floats, ints, layer, cos_psi, angle, -1, -1, out)
    n = out.shape[0]
    row = layer * n
    c_over_b = floats[medium.layer_c_over_b + row:medium.layer_c_over_b + row + n]
    inv_c = floats[medium.layer_inv_c + row:medium.layer_inv_c + row + n]
    per_angle = 1.0 / (2.0 * math.pi * math.sin(angle))
    for j in range(n):
        out[j] *= per_angle * c_over_b[j] * inv_c[j]


@kernel
def collision_density(medium, floats, grid, ps, p, layer, weight, posterior):
    """What a collision of the packet carries per unit coefficient at each wavelength, without
    settling: times a wavelength's scattering coefficient b_j it is what the collision
    scatters (collision_weights), times an inelastic process's coefficient what that process
    takes (channels/inelastic.py). With e_j = exp(-(c_j - c_h) D) the deferred factors, a
    settle would make F_j = p.w s G_j e_j / mean_k(K_k e_k) (s = exp((c_r - c_h) D), what p.w
    took of the reference's), and adding the collision point to the path gives each K_k the
    factor c_k (its collision density), so weight_j = p.w s G_j e_j / mean_k(K_k e_k c_k) (the
    mean of K e cancels; one wavelength: w / c, the implicit-capture weight per unit b).
    Unless `posterior` is empty: also the probability that each wavelength is the hero, given
    the path so far and the collision point, K_j e_j c_j / sum_k K_k e_k c_k, into it (n_wl;
    direction_density averages over it). A packet that carries emissions on needs it, and
    takes it here without settling: its one settle comes when it has turned
    (channels/inelastic.py carry)."""
    n = grid.n_wl
    k, g, _, _ = weights(grid, ps)
    row = medium.layer_c + layer * n
    c = floats[row:row + n]
    dist = ps[free_path_at(grid)]
    c_h = c[p.wavelength]
    if dist > 0.0:
        for j in range(n):
            weight[j] = exp(-(c[j] - c_h) * dist)
    else:   # settled, nothing deferred
        for j in range(n):
            weight[j] = 1.0
    total = 0.0
    if posterior.shape[0] > 0:
        for j in range(n):
            density = k[j] * weight[j] * c[j]
            posterior[j] = density
            total += density
        per_total = 1.0 / total
        for j in range(n):
            posterior[j] *= per_total
    else:
        for j in range(n):
            total += k[j] * weight[j] * c[j]
    scale = p.w * math.exp((c[p.reference] - c_h) * dist) * n / total
    for j in range(n):
        weight[j] *= scale * g[j]


@internal
def posterior_at(grid):
    """Where the hero's posterior at a collision (collision_density; n_wl) lies in the
    scratch row, last (records.work_size); a scene without inelastic light has none."""
    return (7 + grid.n_parts) * grid.n_wl + CAP_POINT_FLOATS


@kernel
def direction_density(medium, floats, grid, posterior, beta, layer, angle, keep, cone_density):
    """The density (1/sr) with which the walk drew its new direction, turned by `angle` from
    the incident one, averaged over the hero's posterior: sum_j posterior_j (keep p_j + d),
    p_j = beta_j / (2 pi sin(psi) b_j) from the volume scattering function the collision just
    read (beta, volume_scattering's units, at the same clamped angle), d the upward cone's
    density (0 outside it)."""
    n = grid.n_wl
    row = layer * n
    c_over_b = floats[medium.layer_c_over_b + row:medium.layer_c_over_b + row + n]
    inv_c = floats[medium.layer_inv_c + row:medium.layer_inv_c + row + n]
    total = 0.0
    for j in range(n):
        total += posterior[j] * beta[j] * c_over_b[j] * inv_c[j]
    clamped = min(math.pi - tabulated.EDGE, max(tabulated.EDGE, angle))
    return keep * total / (2.0 * math.pi * math.sin(clamped)) + cone_density


@kernel
def collision_weights(medium, floats, grid, layer, density, weight):
    """What a collision sends at each wavelength, as a local estimate needs it: its weight per
    unit coefficient (collision_density) times b_j (the albedo times c)."""
    n = grid.n_wl
    row = layer * n
    albedo = floats[medium.layer_albedo + row:medium.layer_albedo + row + n]
    c = floats[medium.layer_c + row:medium.layer_c + row + n]
    for j in range(n):
        weight[j] = density[j] * albedo[j] * c[j]


@kernel
def bottom_weights(grid, floats, ps, p, weight):
    """What a bottom reflection sends at each wavelength, as a local estimate needs it (the
    packet settled on reaching the bottom plane): weight_j = p.w G_j bottom_q_j, times the
    BRDF the estimate evaluates (its finite part: a lambertian_specular bottom's diffuse lobe,
    whose shares are bottom_q's first row)."""
    n = grid.n_wl
    _, g, _, _ = weights(grid, ps)
    share = floats[grid.bottom_q:grid.bottom_q + n]
    w = p.w
    for j in range(n):
        weight[j] = w * g[j] * share[j]


@internal
def scatter_weights(medium, floats, ints, grid, tally, ps, work, p, layer, cos_s, angle, psi_s,
                    node_s, keep, cone_density, analog):
    """A collision (p.w already times the hero's albedo) that turned the hero by psi (cos_s,
    angle; psi_s, node_s: the table node it was sampled at, or -1): per wavelength the factors
    of F_j = p.w G_j / mean K: beta_j / beta_h (the albedo times the phase function times the
    free-path density, relative to the hero's) and K_j times (c_j p_j) / (c_h p_h) =
    (beta_j c_j / b_j) / (beta_h c_h / b_h). The factor beta_j / beta_h is split as
    beta_r / beta_h on p.w and beta_j / beta_r on G_j, r the packet's reference wavelength (the
    heaviest at the last roulette test), so p.w follows the weight that decides roulette rather
    than the hero's: a red hero's p.w would fall below the threshold at every collision while
    blue wavelengths still carry the packet, each time paying a settle (measured: 13 settles
    per photon, Chl 1 deep).

    Scattering biased toward straight up (upward.py; keep = 1 - f < 1): every wavelength's walk
    would draw its direction from (1 - f) p_j + f g (g the cone's density, inside the cone), so
    its density is q_j = keep p_j + d, d = f g inside the cone (cone_density) and 0 outside.
    The path's value keeps b_j p_j: p.w takes beta_r / (keep beta_h + s b_h d) (the hero's p/q
    times beta_r / beta_h) and K_j the factor c_j q_j / (c_h q_h) = (keep beta_j c_j / b_j +
    s c_j d) / (keep beta_h c_h / b_h + s c_h d), s = 2 pi sin(psi) the units of beta.

    The analog walk (analog; never biased: config) survived the collision with the hero's
    albedo instead of taking it on p.w, so each wavelength's walk would have survived with its
    own: K_j takes the factor (c_j p_j w0_j) / (c_h p_h w0_h) = beta_j / beta_h. (With the
    implicit walk's K the estimate stays unbiased, but a wavelength of high albedo carried by a
    hero of low albedo gains w0_j / w0_h at every collision: a heavy tail, measured 10-20% low
    at 5 standard errors on Rrs, validation spectral_history.)"""
    h = p.wavelength
    n = grid.n_wl
    k, g, _, _ = weights(grid, ps)
    beta = work[:n]
    volume_scattering(medium, floats, ints, layer, cos_s, angle, psi_s, node_s, beta)
    row = medium.layer_c_over_b + layer * n
    c_over_b = floats[row:row + n]
    r = p.reference if beta[p.reference] > 0.0 else h
    # a count, not a max, of the K past the bound: an integer sum vectorises, a float max
    # does not (measured: the loop took twice as long with the max)
    over = 0
    if analog:
        per_ref = 1.0 / beta[r]
        per_k = 1.0 / beta[h]
        p.w *= beta[r] / beta[h]
        for j in range(n):
            g[j] *= beta[j] * per_ref
            k_j = k[j] * (beta[j] * per_k)
            k[j] = k_j
            over += (k_j > K_BOUND) | ((k_j < K_FLOOR) & (k_j > 0.0))
    elif keep == 1.0:
        per_ref = 1.0 / beta[r]
        per_k = 1.0 / (beta[h] * c_over_b[h])
        p.w *= beta[r] / beta[h]
        for j in range(n):
            g[j] *= beta[j] * per_ref
            k_j = k[j] * (beta[j] * c_over_b[j] * per_k)
            k[j] = k_j
            over += (k_j > K_BOUND) | ((k_j < K_FLOOR) & (k_j > 0.0))
    else:
        if beta[r] <= 0.0:   # a direction from the cone that the hero's phase function lacks
            for j in range(n):
                if beta[j] > beta[r]:
                    r = j
            if beta[r] <= 0.0:   # no wavelength scatters into it: the path ends here
                p.w = 0.0
                return
        row = medium.layer_c + layer * n
        c = floats[row:row + n]
        s_d = 2.0 * math.pi * math.sin(angle) * cone_density
        per_k = 1.0 / (keep * beta[h] * c_over_b[h] + s_d * c[h])
        per_ref = 1.0 / beta[r]
        p.w *= beta[r] * c_over_b[h] * per_k
        for j in range(n):
            g[j] *= beta[j] * per_ref
            k_j = k[j] * ((keep * beta[j] * c_over_b[j] + s_d * c[j]) * per_k)
            k[j] = k_j
            over += (k_j > K_BOUND) | ((k_j < K_FLOOR) & (k_j > 0.0))
    if over > 0 or ps[free_path_at(grid)] > floats[medium.layer_settle_path + layer]:
        settle(medium, floats, grid, tally, ps, p, layer)


@kernel
def lose(grid, tally, ps, layer):
    """The packet lost roulette, or the analog walk's absorption draw, in `layer`: what it
    carried at its last settle stays there (every collision since then was in that layer)."""
    _, _, last, share = weights(grid, ps)
    deposit_all(grid, tally, share, spectral_at(grid, grid.budget + BUDGET_LAYERS + layer), 1.0,
                last)


@kernel
def attenuate(medium, floats, grid, tally, ps, p, layer, dist):
    """A layer that scatters at no wavelength: wavelength j keeps exp(-c_j dist) (the plane's
    settle books the rest as absorbed); dist = inf (down an infinitely deep layer): all of it
    is absorbed there, or lost below where c_j = 0. Returns whether the packet is gone."""
    n = grid.n_wl
    _, g, _, share = weights(grid, ps)
    row = medium.layer_c + layer * n
    c = floats[row:row + n]
    if dist < math.inf:
        for j in range(n):
            g[j] *= exp(-c[j] * dist)
        return False
    settle(medium, floats, grid, tally, ps, p, layer)
    absorbed = spectral_at(grid, grid.budget + BUDGET_LAYERS + layer)
    lost = spectral_at(grid, grid.budget + BUDGET_LOST_BELOW)
    w = p.w
    for j in range(n):
        deposit(grid, tally, share, absorbed if c[j] > 0.0 else lost, j, w * g[j])
    return True


@kernel
def reflect(grid, floats, tally, ps, p, rho, mirror):
    """The bottom reflects rho (the sampled BRDF's weight, on p.w; 1 after the analog walk's
    reflection draw) times wavelength j's share bottom_q_j of the reflectance (on G_j); the
    rest is absorbed by the bottom. mirror: the BRDF sampled the mirror lobe of a Lambertian +
    mirror bottom, whose shares are bottom_q's second row (that lobe's reflectance at j over
    the packed one's; the first row is the diffuse lobe's, and every other bottom's)."""
    n = grid.n_wl
    _, g, _, parts = weights(grid, ps)
    row = grid.bottom_q + (n if mirror else 0)
    share = floats[row:row + n]
    absorbed = spectral_at(grid, grid.budget + BUDGET_BOTTOM)
    w = p.w
    for j in range(n):
        deposit(grid, tally, parts, absorbed, j, w * g[j] * (1.0 - rho * share[j]))
        g[j] *= share[j]
    p.w *= rho
    carry(grid, ps, p)


@kernel
def survives_roulette(medium, floats, ctrl, grid, tally, ps, p, layer, rng):
    """Roulette after a collision, on the largest wavelength weight max_j F_j (as transport's
    survives_roulette on p.w): a packet with p.w at or above the threshold goes on untested;
    below it, the packet settles and p.w becomes max_j F_j (G_j / max G, so F is unchanged),
    which then plays roulette; the heaviest wavelength becomes the reference that p.w follows
    (scatter). So the exponentials of a settle are paid only when the packet's heaviest
    wavelength has lost weight, and a hero wavelength that is absorbed fast does not end a path
    that other wavelengths still carry. The loser's weights stay in the layer (lose). The
    analog walk plays no roulette."""
    if ctrl.analog or p.w >= ctrl.roulette_weight:
        return True
    settle(medium, floats, grid, tally, ps, p, layer)
    n = grid.n_wl
    _, g, _, _ = weights(grid, ps)
    top = 0.0
    for j in range(n):
        if g[j] > top:
            top = g[j]
            p.reference = j
    if top > 0.0:
        per_top = 1.0 / top
        for j in range(n):
            g[j] *= per_top
        p.w *= top
    if p.w >= ctrl.roulette_weight:
        return True
    if uniform(rng) < ctrl.roulette_survival:
        p.w /= ctrl.roulette_survival
        return True
    lose(grid, tally, ps, layer)
    return False
