"""Local (next-event, point) estimates: of radiance in exact upward directions, and of the
nadir-viewing polar-cap average (Lu, Lw_nadir, Rrs_nadir; tables in scene/estimates.py; through
the rough sea, the air cap's tables hold the surface's transmission lobe: kernel/rough_cap.py).

At every collision a packet of weight w in a layer with scattering b and extinction c sends
w (b/c) p(cos Theta) per steradian into the requested direction Omega; that light reaches a level
above it with transmission exp(-delta tau / |mu|), and the crossing estimator's expectation for
it is w (b/c) p T / |mu| (the radiance at the level). At a bottom reflection the reflected radiance
is w f(wi, Omega) (per unit incident weight), carried up with the same T. Just above the surface
the in-water radiance in the refracted direction is multiplied by the Fresnel transmittance and
1/n^2 (the n^2 law: L_air = t L_water / n^2; Mobley 1994, Light and Water, 4.3).
References: Kalos & Whitlock, Monte Carlo Methods (2008), 6.3 (point detectors); Gordon (1985),
Appl. Opt. 24, 4172 (ocean radiance by point estimates).

Through the rough surface (surface.delta 0) an air row's in-water direction is not fixed: each
collision or bottom reflection draws one from the surface's facet walk run backwards from the air
direction (into_water_through_rough), an unbiased estimate with the same bounded scores.

Only upward directions are offered: their paths from a collision to the level cross no surface.
A mirror bottom has no density to evaluate, so scenes with one do not use these estimates.

A spectral walk (kernel/spectral.py) scores every wavelength j from the same collision or bottom
reflection, with its own weight (spectral.collision_weights: the path's weight at j with the
collision point added, w_j = F_j b_j / mean_k(K_k c_k), from spectral.collision_density), phase function p_j (spectral.phase_values)
and optical depths tau_j: the same next-event estimate, with the one-sample MIS weight of the
path that led to it. The weights, optical depths and phase values of one event live in the
batch's scratch row `work` (after a collision's volume scattering function; records.work_size),
a one-wavelength scene's too.
"""
import math

from . import spectral
from .brdf import dispatch as brdf
from .compile import internal, kernel
from .exp import exp
from .geometry import from_angles
from .packet import weights
from .phase import dispatch as phase
from .phase import quadratic
from .records import CAP_POINT_FLOATS
from .rng import uniform
from .surface import dispatch as surface_bsdf
from .tally import deposit, deposit_range


# below this transmission (at mu = 1, the least attenuated wavelength) to the nearest level
# above, a collision's cap scores play roulette (at_collision)
CAP_ROULETTE = 0.05


@internal
def scratch(grid, work):
    """Views (n_wl each) of one event's weight at each wavelength, optical depth there, and
    phase function toward the direction being scored (after the n_wl values of a collision's
    volume scattering function, spectral.scatter_weights)."""
    n = grid.n_wl
    return work[n:2 * n], work[2 * n:3 * n], work[3 * n:4 * n]


@internal
def cap_transmissions(grid, work):
    """Views (n_wl each) of the transmissions from the point being scored up to the deepest
    tally level above it (at the water cap's mu; 0 when no level is above) and up to 0+ (at
    the air cap's mu), in the scratch row after the emissions' rows (records.work_size). A
    collision's elastic light and each of its emissions are scored from the same point with
    the same optical depths, so the first of their cap scores computes these exponentials and
    the others read them (measured on the inelastic bench's scene, Raman and fluorescence: the
    cap scores took half the run's time; a scene without inelastic light computes them as it
    scores: through the scratch row, its one-wavelength nadir cap lost 8% of its photons/s).
    The third view holds the rest of what the first cap score found for the point (cap_point):
    1 once it has (collide sets it to 0 at every collision of a scene with inelastic light),
    the alpha node, the fraction to the next, the number of levels above and the roulette's
    scale (0: the point lost it)."""
    n = grid.n_wl
    at = (3 + grid.n_parts) * n
    point = at + 2 * n
    return work[at:at + n], work[at + n:point], work[point:point + CAP_POINT_FLOATS]


@internal
def cap_scratch(grid, work):
    """Views (n_wl each) of a cap score's values at each wavelength and of the transmissions
    it carries from level to level, after cap_transmissions' (records.work_size)."""
    n = grid.n_wl
    at = (5 + grid.n_parts) * n + CAP_POINT_FLOATS
    return work[at:at + n], work[at + n:at + 2 * n]


@internal
def optical_depth(medium, floats, seg, layer, z, j):
    """tau at wavelength index j from the surface to depth z in segment seg (of the given
    layer)."""
    return floats[medium.plane_tau + j * medium.n_planes + seg] + floats[
        medium.layer_c + layer * medium.n_wl + j] * (z - floats[medium.plane_z + seg])


@internal
def direction(est, floats, k):
    """The in-water direction (travel, up) of local-estimate row k."""
    at = est.dirs + 3 * k
    return floats[at], floats[at + 1], floats[at + 2]


@kernel
def layer_phase(medium, floats, ints, grid, layer, cos_psi, out):
    """The layer's phase function p_j(cos_psi) in 1/sr at every wavelength into out (called,
    not inlined: its two call sites, exact directions through the flat and the rough surface,
    would otherwise each carry a copy of the spectral terms' reading into the collision)."""
    if grid.n_wl == 1:
        out[0] = phase.evaluate(medium, floats, ints, layer, cos_psi)
    else:
        spectral.phase_values(medium, floats, ints, layer, cos_psi, out)


@internal
def add_to_levels(est, floats, ints, grid, tally, share, z, tau_here, k, base, mu, j):
    """Row k scores the in-water levels above z (if it is an in-water row) and/or 0+ (factor
    t/n^2; 0 if it is not scored there), at wavelength index j (split by the parts' shares
    `share`: tally.deposit)."""
    n = grid.n_wl
    row = est.n_dirs * n     # one level's scores: direction-major, wavelength fastest
    local = grid.local + k * n
    if ints[est.in_water + k]:
        for level in range(grid.n_depths):
            if floats[grid.level_z + level] <= z:
                deposit(grid, tally, share, local + level * row, j, base * math.exp(
                    -(tau_here - floats[grid.level_tau + level * n + j]) / mu))
    factor = floats[est.air_factor + k]
    if factor > 0.0:
        deposit(grid, tally, share, local + grid.n_depths * row, j,
                base * math.exp(-tau_here / mu) * factor)


@internal
def from_air_through_rough(surface, floats, ax, ay, az, rng, with_facet_walk):
    """(ix, iy, iz, t): for the upward air direction o = (ax, ay, -az) (az > 0), an in-water
    direction of travel i whose light the rough surface sends into o, with t = 1, or t = 0
    (nothing sent): one sample of the rough surface (its table, or its facet walk) for a photon
    travelling -o from the air, reversed. By the reciprocity of the walk and of its table
    (f(i->o) / n_o^2 = f(o->i) / n_i^2 for a dielectric BSDF; Veach 1997, PhD thesis, 5.2;
    tests/test_surface_table.py) the radiance L(o) at 0+ is the expectation of
    t L_water(i) / n^2."""
    ox, oy, oz, weight, transmitted = surface_bsdf.sample(surface, -ax, -ay, az, uniform(rng),
                                                          rng, floats, with_facet_walk)
    return -ox, -oy, -oz, weight if transmitted else 0.0


@internal
def into_water_through_rough(surface, est, floats, k, rng, with_facet_walk):
    """from_air_through_rough for air row k (its upward air direction stored as its
    flat-surface refracted in-water direction); the row's air factor 1/n^2 completes it."""
    dx, dy, dz = direction(est, floats, k)
    n = surface.n_water
    ax = n * dx
    ay = n * dy
    return from_air_through_rough(surface, floats, ax, ay,
                                  math.sqrt(max(0.0, 1.0 - ax * ax - ay * ay)), rng,
                                  with_facet_walk)


@internal
def collision_depths(medium, floats, grid, work, p, layer):
    """The optical depth of packet p's collision point at every wavelength, into the scratch's
    view (scratch) that the collision's local estimates and its emissions' read (once per
    collision: computed for each emission, it took 4% of the inelastic bench's run)."""
    tau = scratch(grid, work)[1]
    for j in range(grid.n_wl):
        tau[j] = optical_depth(medium, floats, p.seg, layer, p.z, j)


@internal
def at_collision(est, grid, medium, surface, floats, ints, tally, ps, work, p, layer,
                 w_scattered, rng, with_rough_surface, with_facet_walk, with_exact_directions):
    """What one collision of packet p (scattered weight w_scattered in a one-wavelength scene;
    in a spectral walk its weight per unit coefficient at each wavelength in work[:n_wl],
    spectral.collision_density; the point's optical depths in the scratch, collision_depths)
    sends into the exact directions (at every level above it and 0+), and the polar-cap
    average of the nadir-viewing radiance, at every wavelength."""
    n = grid.n_wl
    weight, tau, phase_j = scratch(grid, work)
    share = weights(grid, ps)[3]
    if n == 1:
        weight[0] = w_scattered
    else:
        spectral.collision_weights(medium, floats, grid, layer, work[:n], weight)
    z = p.z
    ux, uy, uz = p.ux, p.uy, p.uz
    if with_exact_directions is not None and est.directions_on:
        rough = surface.delta == 0
        for k in range(est.n_dirs):
            factor = floats[est.air_factor + k]
            if with_rough_surface is not None and rough and factor > 0.0:
                ix, iy, iz, t = into_water_through_rough(surface, est, floats, k, rng,
                                                         with_facet_walk)
                if t > 0.0 and iz < 0.0:
                    layer_phase(medium, floats, ints, grid, layer, ux * ix + uy * iy + uz * iz,
                                phase_j)
                    at = grid.local + (grid.n_depths * est.n_dirs + k) * n
                    for j in range(n):
                        deposit(grid, tally, share, at, j, weight[j] * phase_j[j] * t * math.exp(
                            tau[j] / iz) / -iz * factor)
                continue
            dx, dy, dz = direction(est, floats, k)
            mu = -dz
            layer_phase(medium, floats, ints, grid, layer, ux * dx + uy * dy + uz * dz, phase_j)
            for j in range(n):
                add_to_levels(est, floats, ints, grid, tally, share, z, tau[j], k,
                              weight[j] * phase_j[j] / mu, mu, j)
    if est.cap_on:
        cap_scores(est, grid, floats, ints, tally, share, work, weight, tau, z, uz,
                   ints[est.table_of_layer + layer], 0, n, rng)


@internal
def cap_scores(est, grid, floats, ints, tally, share, work, weight, tau, z, uz, table, first,
               last, rng):
    """The polar-cap averages (to the levels above depth z and to 0+) of what a point of
    scattering sends up, for a packet travelling with direction cosine uz, from the cap tables
    `table` (a layer's phase function, or an inelastic emission's) at the wavelengths
    first .. last - 1 (weights `weight`; optical depths `tau` at every wavelength; the
    transmissions of the event's first cap score, cap_transmissions)."""
    n = grid.n_wl
    if grid.n_parts > 1:
        # a collision's elastic light and each of its emissions are scored from one point:
        # the first of their cap scores finds its node, levels and roulette (over every
        # wavelength) and its transmissions, and the others read them (each its own took
        # 4% of the inelastic bench's collision time, by cycle counters)
        to_level, to_air, point = cap_transmissions(grid, work)
        if point[0] == 0.0:
            i, f, above, scale = cap_point(est, grid, floats, tau, z, uz, 0, n, rng)
            point[0] = 1.0
            point[1] = i
            point[2] = f
            point[3] = above
            point[4] = scale
            if scale > 0.0:
                spectral_transmissions(est, floats, grid, tau, above, 0, n, to_level, to_air)
        i, f, above, scale = int(point[1]), point[2], int(point[3]), point[4]
    else:
        i, f, above, scale = cap_point(est, grid, floats, tau, z, uz, first, last, rng)
    if scale == 0.0:
        return
    # (see scene/estimates.py for the expansion and its accuracy; the tables' M0, M1 linear in
    # alpha between nodes i and i + 1; no division per wavelength: each is a product with a
    # reciprocal taken once, which changed the scores by rounding only)
    g = 1.0 - f
    node = (table * est.n_alpha + i) * n + first
    per_mu = 1.0 / est.mu_w
    water_factor = scale * per_mu / est.omega_w
    air_factor = scale / est.omega_a
    h_per_mu2 = est.h / (est.mu_a * est.mu_a)
    if n == 1:
        # one wavelength: scalars (through the scratch row's views, the bare walk's nadir cap
        # lost 13% of its photons/s)
        level_t, air_t = transmissions(est, floats, grid, tau[0], above, 0)
        m0 = g * floats[est.cap_m0w + node] + f * floats[est.cap_m0w + node + 1]
        m1 = g * floats[est.cap_m1w + node] + f * floats[est.cap_m1w + node + 1]
        for level in range(above - 1, -1, -1):
            deposit(grid, tally, share, grid.cap + level, 0, water_cap_score(
                weight[0] * water_factor, level_t, m0, m1, tau[0] - floats[grid.level_tau + level],
                per_mu))
            level_t *= floats[est.level_decay + level]
        m0 = g * floats[est.cap_m0a + node] + f * floats[est.cap_m0a + node + 1]
        m1 = g * floats[est.cap_m1a + node] + f * floats[est.cap_m1a + node + 1]
        deposit(grid, tally, share, grid.cap + grid.n_depths, 0, air_cap_score(
            weight[0] * air_factor, air_t, m0, m1, tau[0], est.h, h_per_mu2, est.dh))
        return
    # with inelastic light, the point's transmissions were computed with it (above); a scene
    # without it computes them for the wavelengths it scores
    to_level, to_air, _ = cap_transmissions(grid, work)
    if grid.n_parts == 1:
        spectral_transmissions(est, floats, grid, tau, above, first, last, to_level, to_air)
    # the scores one level at a time over the wavelengths first .. last - 1, through views
    # that start at 0, which LLVM vectorises (per wavelength, they took a third of the
    # inelastic bench's run)
    count = last - first
    value_all, carried_all = cap_scratch(grid, work)
    value = value_all[:count]
    w = weight[first:last]
    tau_j = tau[first:last]
    if above > 0:
        # the levels are sorted by depth: each level up multiplies the transmission by the
        # transmission between the two levels (level_decay), so the cap costs two exps (water
        # and air) whatever the number of levels
        m0_lo = floats[est.cap_m0w + node:est.cap_m0w + node + count]
        m0_hi = floats[est.cap_m0w + node + n:est.cap_m0w + node + n + count]
        m1_lo = floats[est.cap_m1w + node:est.cap_m1w + node + count]
        m1_hi = floats[est.cap_m1w + node + n:est.cap_m1w + node + n + count]
        carried = carried_all[:count]
        level_t = to_level[first:last]
        for j in range(count):
            carried[j] = level_t[j]
        for level in range(above - 1, -1, -1):
            # this level's optical depth and decay at each wavelength
            at = level * n + first
            level_tau = floats[grid.level_tau + at:grid.level_tau + at + count]
            decay = floats[est.level_decay + at:est.level_decay + at + count]
            for j in range(count):
                value[j] = water_cap_score(w[j] * water_factor, carried[j],
                                           g * m0_lo[j] + f * m0_hi[j],
                                           g * m1_lo[j] + f * m1_hi[j],
                                           tau_j[j] - level_tau[j], per_mu)
                carried[j] *= decay[j]
            deposit_range(grid, tally, share, grid.cap + level * n, first, 1.0, value)
    m0_lo = floats[est.cap_m0a + node:est.cap_m0a + node + count]
    m0_hi = floats[est.cap_m0a + node + n:est.cap_m0a + node + n + count]
    m1_lo = floats[est.cap_m1a + node:est.cap_m1a + node + count]
    m1_hi = floats[est.cap_m1a + node + n:est.cap_m1a + node + n + count]
    air_t = to_air[first:last]
    for j in range(count):
        value[j] = air_cap_score(w[j] * air_factor, air_t[j], g * m0_lo[j] + f * m0_hi[j],
                                 g * m1_lo[j] + f * m1_hi[j], tau_j[j], est.h, h_per_mu2,
                                 est.dh)
    deposit_range(grid, tally, share, grid.cap + grid.n_depths * n, first, 1.0, value)


@internal
def cap_point(est, grid, floats, tau, z, uz, first, last, rng):
    """(i, f, above, scale) of a point at depth z (optical depths tau) that scatters a packet
    travelling with direction cosine uz: the node of the cap tables' alpha grid (uniform on
    two pieces) below the angle between the packet's direction and straight up and the
    fraction f to the next, the number of tally levels at or above the point (sorted by
    depth), and the cap roulette's factor for the wavelengths first .. last - 1 (0: lost)."""
    n = grid.n_wl
    alpha = math.acos(min(1.0, max(-1.0, -uz)))
    if alpha < est.fine_end:
        x = alpha / est.fine_step
    else:
        x = (est.fine_nodes - 1) + (alpha - est.fine_end) / est.coarse_step
    i = min(int(x), est.n_alpha - 2)
    f = x - i
    above = 0   # the tally levels at or above the point (sorted by depth)
    while above < grid.n_depths and floats[grid.level_z + above] <= z:
        above += 1
    # roulette on the cap's scores: when even the least attenuated wavelength keeps less
    # than CAP_ROULETTE of its light on the way to the nearest level above (or to the
    # surface), the point scores with probability t / CAP_ROULETTE and its scores are
    # divided by it (unbiased; Kalos & Whitlock 2008, 4.2): deep collisions in turbid water,
    # which send almost nothing up, cost a comparison instead of n_wl table reads
    least = math.inf
    if above > 0:
        at = grid.level_tau + (above - 1) * n + first
        nearest = floats[at:at + last - first]
        for j in range(last - first):
            least = min(least, tau[first + j] - nearest[j])
    else:
        for j in range(first, last):
            least = min(least, tau[j])
    scale = 1.0
    kept = math.exp(-least)
    if kept < CAP_ROULETTE:
        if uniform(rng) * CAP_ROULETTE >= kept:
            return i, f, above, 0.0
        scale = CAP_ROULETTE / kept
    return i, f, above, scale


@internal
def water_cap_score(weight, transmitted, m0, m1, dtau, per_mu):
    """The water cap's average radiance at a level dtau above a point of scattering that sends
    weight (over the cap's mu and solid angle) up, transmitted to the level at the cap's mu
    (scene/estimates.py: M0 + M1 (dtau / mu - 1) / mu)."""
    return weight * transmitted * (m0 + m1 * (dtau * per_mu - 1.0) * per_mu)


@internal
def air_cap_score(weight, transmitted, m0, m1, tau, h, h_per_mu2, dh):
    """The air cap's average radiance at 0+ from a point of scattering at optical depth tau that
    sends weight (over the air cap's solid angle) up, transmitted at the air cap's mu
    (scene/estimates.py: M0 h + M1 (h tau / mu^2 + dh))."""
    return weight * transmitted * (m0 * h + m1 * (tau * h_per_mu2 + dh))


@internal
def transmissions(est, floats, grid, tau_here, above, j):
    """The transmissions from optical depth tau_here, at wavelength index j: at the water cap's
    mu up to the deepest of the `above` tally levels above the point (0 when none is above),
    and at the air cap's mu up to 0+."""
    to_air = math.exp(-tau_here / est.mu_a)
    if above == 0:
        return 0.0, to_air
    return math.exp(-(tau_here - floats[grid.level_tau + (above - 1) * grid.n_wl + j])
                    / est.mu_w), to_air


@internal
def spectral_transmissions(est, floats, grid, tau, above, first, last, to_level, to_air):
    """transmissions() at the wavelengths first .. last - 1 (optical depths tau), into the views
    to_level and to_air: loops over wavelengths with exp.py's exp, which LLVM vectorises (one
    wavelength keeps the scalar transmissions() and libm's exp, whose latency is shorter)."""
    count = last - first
    tau_j = tau[first:last]
    air_t = to_air[first:last]
    for j in range(count):
        air_t[j] = exp(-tau_j[j] / est.mu_a)
    level_t = to_level[first:last]
    if above == 0:
        level_t[:] = 0.0
        return
    at = grid.level_tau + (above - 1) * grid.n_wl + first
    nearest = floats[at:at + count]
    for j in range(count):
        level_t[j] = exp(-(tau_j[j] - nearest[j]) / est.mu_w)


@internal
def toward(model, bp, floats, beta_at, ux, uy, uz, ox, oy, oz, with_detailed_bottom):
    """What a point source sends per unit weight toward the travel direction (ox, oy, oz)
    (world frame, upward): a bottom of BRDF `model` (model >= 0; the packet travelling (ux, uy,
    uz), in the BRDF's local frame (x, -y, -z) as brdf.dispatch.reflect) its f in 1/sr; an
    inelastic emission (model < 0) its phase function (1 + beta cos^2), beta at
    floats[beta_at], about the packet's direction, over |oz| (a volume source: the radiance of
    the light it sends grows as the path crosses a plane more obliquely, as a collision's)."""
    if model >= 0:
        return brdf.evaluate_local(model, bp, -ux, uy, uz, ox, -oy, -oz, with_detailed_bottom)
    return quadratic.evaluate(floats[beta_at:], ux * ox + uy * oy + uz * oz) / -oz


@internal
def at_bottom(est, grid, medium, bottom, surface, floats, ints, bp, tally, ps, work, p, rng,
              with_rough_surface, with_facet_walk, with_detailed_bottom, with_exact_directions):
    """Packet p meets the bottom: the reflected radiance w f(wi, W) T in the exact directions
    and the polar-cap averages (from_point), at every wavelength (one BRDF shape, each
    wavelength's reflectance share in its weight)."""
    n = grid.n_wl
    weight, tau, _ = scratch(grid, work)
    bottom_plane = medium.n_planes - 1
    if n == 1:
        weight[0] = p.w
    else:
        spectral.bottom_weights(grid, floats, ps, p, weight)
    for j in range(n):
        tau[j] = floats[medium.plane_tau + j * medium.n_planes + bottom_plane]
    from_point(est, grid, surface, floats, ints, bp, tally, weights(grid, ps)[3], weight, tau,
               floats[medium.plane_z + bottom_plane], p.ux, p.uy, p.uz, bottom.model, rng,
               with_rough_surface, with_facet_walk, with_detailed_bottom, with_exact_directions)


@internal
def at_emission(est, grid, medium, surface, floats, ints, tally, work, weight, p, layer, beta_at,
                table, first, last, rng, with_rough_surface, with_facet_walk,
                with_exact_directions):
    """An inelastic emission at packet p's collision (its weights at each wavelength in
    `weight`, zero outside first .. last - 1, channels/inelastic.py; its phase function's
    beta at floats[beta_at], its cap tables `table`): the radiance it sends in the exact
    directions (directions_from_point) and the polar-cap averages (cap_scores, as a
    collision's), scored in the emission's part of the tally row, where `tally` starts."""
    tau = scratch(grid, work)[1]   # the collision's (collision_depths)
    one_part = work[:0]   # (tally.deposit: all of it in the part where `tally` starts)
    if with_exact_directions is not None and est.directions_on:
        # (an emission's: no BRDF, with_detailed_bottom None)
        directions_from_point(est, grid, surface, floats, ints, floats, tally, one_part, weight,
                              tau, p.z, p.ux, p.uy, p.uz, -1, beta_at, first, last, rng,
                              with_rough_surface, with_facet_walk, None)
    if est.cap_on:
        cap_scores(est, grid, floats, ints, tally, one_part, work, weight, tau, p.z, p.uz,
                   table, first, last, rng)


@internal
def directions_from_point(est, grid, surface, floats, ints, bp, tally, share, weight, tau, z,
                          ux, uy, uz, model, beta_at, first, last, rng, with_rough_surface,
                          with_facet_walk, with_detailed_bottom):
    """The radiance a point source at depth z (optical depths tau, weights `weight` at the
    wavelengths first .. last - 1, none elsewhere; toward() says what it sends, a bottom's
    BRDF or an emission's phase function) sends in the exact directions."""
    n = grid.n_wl
    rough = surface.delta == 0
    for k in range(est.n_dirs):
        factor = floats[est.air_factor + k]
        if with_rough_surface is not None and rough and factor > 0.0:
            ix, iy, iz, t = into_water_through_rough(surface, est, floats, k, rng,
                                                     with_facet_walk)
            if t > 0.0 and iz < 0.0:
                f = toward(model, bp, floats, beta_at, ux, uy, uz, ix, iy, iz,
                           with_detailed_bottom)
                at = grid.local + (grid.n_depths * est.n_dirs + k) * n
                for j in range(first, last):
                    deposit(grid, tally, share, at, j,
                            weight[j] * f * t * math.exp(tau[j] / iz) * factor)
            continue
        dx, dy, dz = direction(est, floats, k)
        f = toward(model, bp, floats, beta_at, ux, uy, uz, dx, dy, dz, with_detailed_bottom)
        for j in range(first, last):
            add_to_levels(est, floats, ints, grid, tally, share, z, tau[j], k, weight[j] * f,
                          -dz, j)


@internal
def from_point(est, grid, surface, floats, ints, bp, tally, share, weight, tau, z, ux, uy, uz,
               model, rng, with_rough_surface, with_facet_walk, with_detailed_bottom,
               with_exact_directions):
    """The radiance the bottom (BRDF `model`) at depth z sends in the exact directions
    (directions_from_point), and the polar-cap average from one direction W drawn uniformly in
    the cap (an unbiased estimate of the cap average; f is bounded for every non-mirror BRDF),
    once in water and once for the air cap, through the surface's transmittance."""
    n = grid.n_wl
    first, last = 0, n
    if with_exact_directions is not None and est.directions_on:
        directions_from_point(est, grid, surface, floats, ints, bp, tally, share, weight, tau,
                              z, ux, uy, uz, model, 0, first, last, rng, with_rough_surface,
                              with_facet_walk, with_detailed_bottom)
    if est.cap_on:
        mu = 1.0 - uniform(rng) * (1.0 - est.cos_water)
        ox, oy, oz = from_angles(mu, 2.0 * math.pi * uniform(rng))
        f = toward(model, bp, floats, 0, ux, uy, uz, ox, oy, -oz, with_detailed_bottom)
        for j in range(first, last):
            for level in range(grid.n_depths):
                if floats[grid.level_z + level] <= z:
                    deposit(grid, tally, share, grid.cap + level * n, j, weight[j] * f * math.exp(
                        -(tau[j] - floats[grid.level_tau + level * n + j]) / mu))
        n_water = surface.n_water
        mu_a = 1.0 - uniform(rng) * (1.0 - est.cos_air)
        if with_rough_surface is not None and surface.delta == 0:
            # the air cap's direction drawn uniformly, its light traced back through the
            # rough sea to one in-water direction (unbiased for the cap average)
            ax, ay, _ = from_angles(mu_a, 2.0 * math.pi * uniform(rng))
            ix, iy, iz, t = from_air_through_rough(surface, floats, ax, ay, mu_a, rng,
                                                   with_facet_walk)
            if t > 0.0 and iz < 0.0:
                f = toward(model, bp, floats, 0, ux, uy, uz, ix, iy, iz,
                           with_detailed_bottom) * t / (n_water * n_water)
                for j in range(first, last):
                    deposit(grid, tally, share, grid.cap + grid.n_depths * n, j,
                            weight[j] * f * math.exp(tau[j] / iz))
            return
        sin_w = math.sqrt(max(0.0, 1.0 - mu_a * mu_a)) / n_water
        mu_w = math.sqrt(1.0 - sin_w * sin_w)
        t = surface_bsdf.transmittance(surface, mu_w)
        phi = 2.0 * math.pi * uniform(rng)
        f = toward(model, bp, floats, 0, ux, uy, uz, sin_w * math.cos(phi),
                   sin_w * math.sin(phi), -mu_w, with_detailed_bottom)
        for j in range(first, last):
            deposit(grid, tally, share, grid.cap + grid.n_depths * n, j,
                    weight[j] * f * math.exp(-tau[j] / mu_w) * t / (n_water * n_water))
