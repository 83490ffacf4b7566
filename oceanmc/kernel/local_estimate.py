"""Local (next-event, point) estimates: of radiance in exact upward directions, and of the
nadir-viewing polar-cap average (Lu, Lw_nadir, Rrs_nadir; tables in scene/estimates.py).

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
"""
import math

from .brdf import dispatch as brdf
from .compile import internal
from .geometry import from_angles
from .phase import dispatch as phase
from .rng import uniform
from .surface import dispatch as surface_bsdf


@internal
def optical_depth(medium, mf, seg, layer, z):
    """tau from the surface to depth z in segment seg (of the given layer)."""
    return mf[medium.plane_tau + seg] + mf[medium.layer_c + layer * medium.n_wl] * (
        z - mf[medium.plane_z + seg])


@internal
def direction(est, ef, k):
    """The in-water direction (travel, up) of local-estimate row k."""
    at = est.dirs + 3 * k
    return ef[at], ef[at + 1], ef[at + 2]


@internal
def add_to_levels(est, ef, ei, grid, gf, tally, z, tau_here, k, base, mu):
    """Row k scores the in-water levels above z (if it is an in-water row) and/or 0+ (factor
    t/n^2; 0 if it is not scored there)."""
    n_dirs = est.n_dirs
    if ei[est.in_water + k]:
        for level in range(grid.n_depths):
            if gf[grid.level_z + level] <= z:
                tally[grid.local + level * n_dirs + k] += base * math.exp(
                    -(tau_here - gf[grid.level_tau + level]) / mu)
    factor = ef[est.air_factor + k]
    if factor > 0.0:
        tally[grid.local + grid.n_depths * n_dirs + k] += base * math.exp(-tau_here / mu) * factor


@internal
def cap_lookup(est, ef, table, cos_alpha):
    """(M0, M1) of the water cap and of the air cap's water side for a packet whose direction
    makes the angle acos(cos_alpha) with straight up; linear in alpha on two uniform pieces."""
    alpha = math.acos(min(1.0, max(-1.0, cos_alpha)))
    if alpha < est.fine_end:
        x = alpha / est.fine_step
    else:
        x = (est.fine_nodes - 1) + (alpha - est.fine_end) / est.coarse_step
    i = min(int(x), est.n_alpha - 2)
    f = x - i
    g = 1.0 - f
    at = table * est.n_alpha + i
    return (g * ef[est.cap_m0w + at] + f * ef[est.cap_m0w + at + 1],
            g * ef[est.cap_m1w + at] + f * ef[est.cap_m1w + at + 1],
            g * ef[est.cap_m0a + at] + f * ef[est.cap_m0a + at + 1],
            g * ef[est.cap_m1a + at] + f * ef[est.cap_m1a + at + 1])


@internal
def into_water_through_rough(surface, est, ef, k, rng):
    """(ix, iy, iz, t): for air row k (upward air direction o, stored as its flat-surface
    refracted in-water direction), an in-water direction of travel i whose light the rough
    surface sends into o, with t = 1, or t = 0 (nothing sent): one sample of the facet walk of
    a photon travelling -o from the air, reversed. By the walk's reciprocity (f(i->o) / n_o^2 =
    f(o->i) / n_i^2 for a dielectric BSDF; Veach 1997, PhD thesis, 5.2) the radiance L(o) at 0+
    is the expectation of t L_water(i) / n^2, which the row's air factor 1/n^2 completes."""
    dx, dy, dz = direction(est, ef, k)
    n = surface.n_water
    ax = n * dx
    ay = n * dy
    az = math.sqrt(max(0.0, 1.0 - ax * ax - ay * ay))
    ox, oy, oz, weight, transmitted = surface_bsdf.sample(surface, -ax, -ay, az, uniform(rng),
                                                          rng)
    return -ox, -oy, -oz, weight if transmitted else 0.0


@internal
def at_collision(est, ef, ei, grid, gf, medium, mf, mi, surface, tally, seg, layer, z,
                 w_scattered, ux, uy, uz, rng):
    """What one collision of a packet travelling (ux, uy, uz) sends into the exact directions
    (at every level above it and 0+), and the polar-cap average of the nadir-viewing radiance
    (see scene/estimates.py for the expansion and its accuracy). The levels are sorted by
    depth: the transmission to the deepest one above is one exp, and each level up multiplies
    it by the transmission between the two levels (level_decay), so the cap costs two exps
    (water and air) whatever the number of levels."""
    tau_here = optical_depth(medium, mf, seg, layer, z)
    if est.directions_on:
        rough = surface.delta == 0
        for k in range(est.n_dirs):
            if rough and ef[est.air_factor + k] > 0.0:
                ix, iy, iz, t = into_water_through_rough(surface, est, ef, k, rng)
                if t > 0.0 and iz < 0.0:
                    p = phase.evaluate(medium, mf, mi, layer, ux * ix + uy * iy + uz * iz)
                    tally[grid.local + grid.n_depths * est.n_dirs + k] += (
                        w_scattered * p * t * math.exp(tau_here / iz) / -iz
                        * ef[est.air_factor + k])
                continue
            dx, dy, dz = direction(est, ef, k)
            mu = -dz
            p = phase.evaluate(medium, mf, mi, layer, ux * dx + uy * dy + uz * dz)
            add_to_levels(est, ef, ei, grid, gf, tally, z, tau_here, k, w_scattered * p / mu, mu)
    if est.cap_on:
        m0w, m1w, m0a, m1a = cap_lookup(est, ef, ei[est.table_of_layer + layer], -uz)
        mu = est.mu_w
        above = 0
        while above < grid.n_depths and gf[grid.level_z + above] <= z:
            above += 1
        if above > 0:
            transmitted = math.exp(-(tau_here - gf[grid.level_tau + above - 1]) / mu)
            scale = w_scattered / (mu * est.omega_w)
            for level in range(above - 1, -1, -1):
                dtau = tau_here - gf[grid.level_tau + level]
                tally[grid.cap + level] += scale * transmitted * (m0w + m1w * (dtau / mu - 1.0)
                                                                  / mu)
                transmitted *= ef[est.level_decay + level]
        mu = est.mu_a
        e = math.exp(-tau_here / mu)
        tally[grid.cap + grid.n_depths] += w_scattered * e * (
            m0a * est.h + m1a * (est.h * tau_here / (mu * mu) + est.dh)) / est.omega_a


@internal
def at_bottom(est, ef, ei, grid, gf, medium, mf, bottom, bp, surface, tally, w, ux, uy, uz,
              rng):
    """A packet of weight w travelling (ux, uy, uz) meets the bottom (in the BRDF's local frame
    (x, -y, -z), as brdf.dispatch.reflect): the reflected radiance w f(wi, W) T in the exact
    directions, and the polar-cap average from one direction W drawn uniformly in the cap (an
    unbiased estimate of the cap average; f is bounded for every non-mirror BRDF), once in
    water and once for the air cap, through the surface's transmittance."""
    bottom_plane = medium.n_planes - 1
    z = mf[medium.plane_z + bottom_plane]
    tau_b = mf[medium.plane_tau + bottom_plane]
    model = bottom.model
    if est.directions_on:
        rough = surface.delta == 0
        for k in range(est.n_dirs):
            if rough and ef[est.air_factor + k] > 0.0:
                ix, iy, iz, t = into_water_through_rough(surface, est, ef, k, rng)
                if t > 0.0 and iz < 0.0:
                    f = brdf.evaluate_local(model, bp, -ux, uy, uz, ix, -iy, -iz)
                    tally[grid.local + grid.n_depths * est.n_dirs + k] += (
                        w * f * t * math.exp(tau_b / iz) * ef[est.air_factor + k])
                continue
            dx, dy, dz = direction(est, ef, k)
            f = brdf.evaluate_local(model, bp, -ux, uy, uz, dx, -dy, -dz)
            add_to_levels(est, ef, ei, grid, gf, tally, z, tau_b, k, w * f, -dz)
    if est.cap_on:
        mu = 1.0 - uniform(rng) * (1.0 - est.cos_water)
        ox, oy, oz = from_angles(mu, 2.0 * math.pi * uniform(rng))
        f = brdf.evaluate_local(model, bp, -ux, uy, uz, ox, -oy, oz)
        for level in range(grid.n_depths):
            if gf[grid.level_z + level] <= z:
                tally[grid.cap + level] += w * f * math.exp(
                    -(tau_b - gf[grid.level_tau + level]) / mu)
        n = surface.n_water
        mu_a = 1.0 - uniform(rng) * (1.0 - est.cos_air)
        sin_w = math.sqrt(max(0.0, 1.0 - mu_a * mu_a)) / n
        mu_w = math.sqrt(1.0 - sin_w * sin_w)
        t = surface_bsdf.transmittance(surface, mu_w)
        phi = 2.0 * math.pi * uniform(rng)
        f = brdf.evaluate_local(model, bp, -ux, uy, uz, sin_w * math.cos(phi),
                                -sin_w * math.sin(phi), mu_w)
        tally[grid.cap + grid.n_depths] += w * f * math.exp(-tau_b / mu_w) * t / (n * n)
