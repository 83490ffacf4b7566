"""Local (next-event, point) estimates: of radiance in exact upward directions, and of the
nadir-viewing polar-cap average (Lu, Lw_nadir, Rrs_nadir; tables in cap_tables.py).

At every collision a packet of weight w in a layer with scattering b and extinction c sends
w (b/c) p(cos Theta) per steradian into the requested direction Omega; that light reaches a level
above it with transmission exp(-delta tau / |mu|), and the crossing estimator's expectation for
it is w (b/c) p T / |mu| (the radiance at the level). At a bottom reflection the reflected radiance
is w f(wi, Omega) (per unit incident weight), carried up with the same T. Just above the surface
the in-water radiance in the refracted direction is multiplied by the Fresnel transmittance and
1/n^2 (the n^2 law: L_air = t L_water / n^2; Mobley 1994, Light and Water, 4.3).
References: Kalos & Whitlock, Monte Carlo Methods (2008), 6.3 (point detectors); Gordon (1985),
Appl. Opt. 24, 4172 (ocean radiance by point estimates).

Only upward directions are offered: their paths from a collision to the level cross no surface.
A mirror bottom has no density to evaluate, so scenes with one do not use these estimates.
"""
import math

import numpy as np
from numba import njit

from .brdf import dispatch as brdf
from .geometry import from_angles
from .interface import fresnel
from .phase import dispatch as phase


@njit(error_model="numpy", cache=True, inline="always")
def add_to_levels(sc, local, z, tau_here, k, base, mu):
    """Row k scores the in-water levels above z (sc.le_water[k]) and/or 0+ (factor t/n^2)."""
    if sc.le_water[k]:
        for level in range(sc.level_z.shape[0]):
            if sc.level_z[level] <= z:
                local[level, k] += base * math.exp(-(tau_here - sc.level_tau[level]) / mu)
    if sc.le_air_factor[k] > 0.0:
        air = sc.level_z.shape[0]
        local[air, k] += base * math.exp(-tau_here / mu) * sc.le_air_factor[k]


@njit(error_model="numpy", cache=True, inline="always")
def score_collision(sc, local, seg, layer, z, w_scattered, ux, uy, uz):
    tau_here = sc.plane_tau[seg] + sc.layer_c[layer] * (z - sc.plane_z[seg])
    for k in range(sc.le_dirs.shape[0]):
        dx = sc.le_dirs[k, 0]
        dy = sc.le_dirs[k, 1]
        dz = sc.le_dirs[k, 2]
        mu = -dz
        p = phase.evaluate(sc, layer, ux * dx + uy * dy + uz * dz)
        add_to_levels(sc, local, z, tau_here, k, w_scattered * p / mu, mu)


@njit(error_model="numpy", cache=True, inline="always")
def score_bottom(sc, local, w, ux, uy, uz):
    """A packet of weight w travelling (ux, uy, uz) meets the bottom (in the BRDF's local frame
    (x, -y, -z), as brdf.dispatch.reflect)."""
    bottom_plane = sc.plane_z.shape[0] - 1
    z = sc.plane_z[bottom_plane]
    tau_here = sc.plane_tau[bottom_plane]
    for k in range(sc.le_dirs.shape[0]):
        dx = sc.le_dirs[k, 0]
        dy = sc.le_dirs[k, 1]
        dz = sc.le_dirs[k, 2]
        f = brdf.evaluate_local(sc.bottom_model, sc.bottom_params, -ux, uy, uz, dx, -dy, -dz)
        add_to_levels(sc, local, z, tau_here, k, w * f, -dz)


@njit(error_model="numpy", cache=True, inline="always")
def cap_lookup(sc, table, cos_alpha):
    """(M0, M1) of the water cap and of the air cap's water side for a packet whose direction
    makes the angle acos(cos_alpha) with straight up; linear in alpha on two uniform pieces."""
    alpha = math.acos(min(1.0, max(-1.0, cos_alpha)))
    if alpha < sc.cap_fine_end:
        x = alpha / sc.cap_fine_step
    else:
        x = (sc.cap_fine_nodes - 1) + (alpha - sc.cap_fine_end) / sc.cap_coarse_step
    i = min(int(x), sc.cap_m0w.shape[1] - 2)
    f = x - i
    g = 1.0 - f
    return (g * sc.cap_m0w[table, i] + f * sc.cap_m0w[table, i + 1],
            g * sc.cap_m1w[table, i] + f * sc.cap_m1w[table, i + 1],
            g * sc.cap_m0a[table, i] + f * sc.cap_m0a[table, i + 1],
            g * sc.cap_m1a[table, i] + f * sc.cap_m1a[table, i + 1])


@njit(error_model="numpy", cache=True, inline="always")
def cap_collision(sc, cap, seg, layer, z, w_scattered, uz):
    """Polar-cap average of the nadir-viewing radiance sent by one collision to every level
    above it and to 0+ (see cap_tables.py for the expansion and its accuracy). The levels are
    sorted by depth: the transmission to the deepest one above is one exp, and each level up
    multiplies it by the transmission between the two levels (cap_level_decay), so a collision
    costs two exps (water and air) whatever the number of levels."""
    m0w, m1w, m0a, m1a = cap_lookup(sc, sc.cap_table_of_layer[layer], -uz)
    tau_here = sc.plane_tau[seg] + sc.layer_c[layer] * (z - sc.plane_z[seg])
    mu = sc.cap_mu_w
    above = 0
    while above < sc.level_z.shape[0] and sc.level_z[above] <= z:
        above += 1
    if above > 0:
        transmitted = math.exp(-(tau_here - sc.level_tau[above - 1]) / mu)
        scale = w_scattered / (mu * sc.cap_omega_w)
        for level in range(above - 1, -1, -1):
            dtau = tau_here - sc.level_tau[level]
            cap[level] += scale * transmitted * (m0w + m1w * (dtau / mu - 1.0) / mu)
            transmitted *= sc.cap_level_decay[level]
    mu = sc.cap_mu_a
    e = math.exp(-tau_here / mu)
    cap[sc.level_z.shape[0]] += w_scattered * e * (
        m0a * sc.cap_h + m1a * (sc.cap_h * tau_here / (mu * mu) + sc.cap_dh)) / sc.cap_omega_a


@njit(error_model="numpy", cache=True, inline="always")
def cap_bottom(sc, cap, w, ux, uy, uz):
    """Polar-cap average of the radiance the bottom reflects from one packet: w f(wi, W) T for
    one direction W drawn uniformly in the cap (an unbiased estimate of the cap average; f is
    bounded for every non-mirror BRDF), once in water and once for the air cap."""
    bottom_plane = sc.plane_z.shape[0] - 1
    z = sc.plane_z[bottom_plane]
    tau_b = sc.plane_tau[bottom_plane]
    mu = 1.0 - np.random.random() * (1.0 - sc.cap_cos_water)
    ox, oy, oz = from_angles(mu, 2.0 * math.pi * np.random.random())
    f = brdf.evaluate_local(sc.bottom_model, sc.bottom_params, -ux, uy, uz, ox, -oy, oz)
    for level in range(sc.level_z.shape[0]):
        if sc.level_z[level] <= z:
            cap[level] += w * f * math.exp(-(tau_b - sc.level_tau[level]) / mu)
    mu_a = 1.0 - np.random.random() * (1.0 - sc.cap_cos_air)
    sin_w = math.sqrt(max(0.0, 1.0 - mu_a * mu_a)) / sc.n_water
    mu_w = math.sqrt(1.0 - sin_w * sin_w)
    t = 1.0 - fresnel(sc.n_water, 1.0, mu_w)[0] if sc.surface_flat else 1.0
    phi = 2.0 * math.pi * np.random.random()
    f = brdf.evaluate_local(sc.bottom_model, sc.bottom_params, -ux, uy, uz,
                            sin_w * math.cos(phi), -sin_w * math.sin(phi), mu_w)
    cap[sc.level_z.shape[0]] += w * f * math.exp(-tau_b / mu_w) * t / (sc.n_water * sc.n_water)
