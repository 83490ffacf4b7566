"""Local (next-event, point) estimates of radiance in exact upward directions.

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

from numba import njit

from .brdf import dispatch as brdf
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
    c = sc.layer_a[layer] + sc.layer_b[layer]
    tau_here = sc.plane_tau[seg] + c * (z - sc.plane_z[seg])
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
