"""The photon loop: weighted photon packets from the sun and sky, through the surface, the layered
water and off the bottom, until they leave, are absorbed or lose Russian roulette.

Estimator (sc.analog False, the default): implicit capture (a collision keeps the packet and
multiplies its weight by the single-scattering albedo), expected values at the surface (light
from the air: the reflected part w R is scored and the packet enters with w (1 - R); light from
the water: the leaving part w (1 - R) is scored, and the packet goes on, reflected, with
probability R and weight w), weight times rho_dh at the bottom, exact exponential attenuation in layers that do not scatter, and unbiased Russian
roulette below sc.roulette_weight; optionally, scattering biased toward straight up (upward.py)
and splitting of heavy packets. Analog mode decides each of these with a random draw instead.
Either way every quantity has the same expectation; only the variance differs.

Every function that takes the scene (one large named tuple) is compiled with inline="always":
a real call copies the tuple (measured: 3x fewer photons/s without inlining). Functions of
scalars are left to LLVM, which inlines them where it pays: inlining those too in Numba's IR made
the first compilation 5x longer (240 s against 45 s) for 8% more photons/s.

`features` (bits FEATURE_* of models.py) is a compile-time constant: driver.py compiles the loop
once per combination of features a scene uses, and code behind a feature bit that is off is not
in that loop at all (measured on the bare-walk scene: ~10% more photons/s than with the unused
code present behind runtime tests). A scene whose features have not been compiled before pays
one compilation (cached on disk afterwards).

trace_batch is compiled without Numba's reference counting (_nrt=False): every read of an array
field of the scene tuple in inlined code otherwise costs an atomic incref/decref pair (1500 call
sites in the compiled loop; 1.8x to 2.4x fewer photons/s, and both threads contending for the
same counters). The arrays are borrowed from the caller, which holds them for the whole call,
and nothing in the loop allocates.
"""
import math

import numpy as np
from numba import njit

from . import local_estimate, upward
from .brdf import dispatch as brdf
from .geometry import turn
from .interface import reflectance, refract
from .models import (BOTTOM_SPECULAR, BUDGET_BOTTOM, BUDGET_LAYERS, BUDGET_LOST_BELOW,
                     BUDGET_SURFACE_REFLECTION, BUDGET_TRUNCATED, BUDGET_WATER_LEAVING,
                     FEATURE_BOTTOM, FEATURE_ESTIMATES, FEATURE_SKY, FEATURE_SPLITTING,
                     FEATURE_UPWARD, STACK_BEAM, STACK_SEGMENT, STACK_UX, STACK_UY, STACK_UZ,
                     STACK_WEIGHT, STACK_Z)
from .phase import dispatch as phase
from .sources import sky_direction
from .tally import score, score_air_up


@njit(error_model="numpy", cache=True)
def exponential():
    return -math.log(1.0 - np.random.random())


@njit(error_model="numpy", cache=True, inline="always")
def survives_roulette(sc, w):
    """(alive, new weight): below the threshold a packet survives with probability p and then
    carries w/p, so the expected weight is unchanged."""
    if sc.analog or w >= sc.roulette_weight:
        return True, w
    if np.random.random() < sc.roulette_survival:
        return True, w / sc.roulette_survival
    return False, 0.0


@njit(error_model="numpy", cache=True, inline="always")
def split(sc, stack, n_stacked, z, seg, w, ux, uy, uz, beam):
    """Splitting by weight: a packet heavier than sc.split_weight becomes k = floor(w /
    split_weight) + 1 packets of weight w / k, each lighter than split_weight, that go on
    independently from the same state (the walk has no memory, so each is an unbiased copy;
    Kalos & Whitlock, Monte Carlo Methods, 2008, 4.2). All but one wait on the stack, as many as
    it has room for (fewer, heavier copies are as unbiased). Returns (w, n_stacked)."""
    copies = min(int(w / sc.split_weight) + 1, stack.shape[0] - n_stacked + 1)
    if copies <= 1:
        return w, n_stacked
    w /= copies
    for _ in range(copies - 1):
        stack[n_stacked, STACK_Z] = z
        stack[n_stacked, STACK_SEGMENT] = seg
        stack[n_stacked, STACK_WEIGHT] = w
        stack[n_stacked, STACK_UX] = ux
        stack[n_stacked, STACK_UY] = uy
        stack[n_stacked, STACK_UZ] = uz
        stack[n_stacked, STACK_BEAM] = 1.0 if beam else 0.0
        n_stacked += 1
    return w, n_stacked


@njit(error_model="numpy", cache=True, inline="always")
def enter_water(sc, features, w, ux, uy, uz, beam, flux, radiance, budget):
    """A packet from the air meets the surface: scores it at 0+ (incoming, and the reflected
    part), and returns (enters, w, ux, uy, uz) for what goes into the water, scored at 0-.
    Linear in w: in implicit mode the whole solar beam of a batch enters in one call."""
    score(sc, features, flux, radiance, sc.air_level, w, ux, uy, uz, beam)
    n = sc.n_water
    if sc.surface_flat:
        r, cos_t = reflectance(sc, 1.0, n, uz)
        if sc.analog:
            if np.random.random() < r:
                score_air_up(sc, features, flux, radiance, w, ux, uy, -uz, False, beam)
                budget[BUDGET_SURFACE_REFLECTION] += w
                return False, 0.0, ux, uy, uz
        else:
            if r > 0.0:
                score_air_up(sc, features, flux, radiance, w * r, ux, uy, -uz, False, beam)
                budget[BUDGET_SURFACE_REFLECTION] += w * r
            w *= 1.0 - r
        ux, uy, uz = refract(ux, uy, uz, 1.0 / n, cos_t)
    if sc.surface_tally >= 0:
        score(sc, features, flux, radiance, sc.surface_tally, w, ux, uy, uz, beam)
    return True, w, ux, uy, uz


@njit(error_model="numpy", cache=True, inline="always")
def trace_in_water(sc, features, z, seg, w, ux, uy, uz, beam, flux, radiance, local, cap,
                   budget, stack, n_stacked):
    """Follows one packet from depth z on plane or in segment seg (just below the surface, or a
    split copy at the bottom) until it leaves, is absorbed or loses roulette; returns its
    scattering count and the new number of packets on the stack. beam: it belongs to the
    collimated solar beam (until it scatters or meets a diffuse bottom)."""
    n = sc.n_water
    plane_z = sc.plane_z
    bottom_plane = plane_z.shape[0] - 1
    tau = exponential()
    events = 0
    while True:
        if w <= 0.0:
            return events, n_stacked
        layer = sc.segment_layer[seg]
        c = sc.layer_c[layer]
        albedo = sc.layer_albedo[layer]
        if uz > 0.0:
            target = seg + 1
            dist = (plane_z[target] - z) / uz
        elif uz < 0.0:
            target = seg
            dist = (plane_z[target] - z) / uz
        else:
            target = -1
            dist = math.inf
        if albedo > 0.0:
            s = tau * sc.layer_inv_c[layer]
            if s < dist:
                z += s * uz
                events += 1
                if features & FEATURE_ESTIMATES:
                    if sc.local_estimates:
                        local_estimate.score_collision(sc, local, seg, layer, z, w * albedo,
                                                       ux, uy, uz)
                    if sc.cap_estimates:
                        local_estimate.cap_collision(sc, cap, seg, layer, z, w * albedo, uz)
                if sc.analog:
                    if np.random.random() >= albedo:
                        budget[BUDGET_LAYERS + layer] += w
                        return events, n_stacked
                else:
                    scattered = w * albedo
                    budget[BUDGET_LAYERS + layer] += w - scattered
                    w = scattered
                if features & FEATURE_UPWARD:
                    w, ux, uy, uz = upward.scatter(sc, layer, w, ux, uy, uz)
                else:
                    u_pick = np.random.random() if sc.layer_comp_count[layer] > 1 else 0.0
                    cos_s = phase.sample_cos(sc, layer, u_pick, np.random.random())
                    ux, uy, uz = turn(ux, uy, uz, cos_s, np.random.random())
                beam = False
                tau = exponential()
                alive, w = survives_roulette(sc, w)
                if not alive:
                    return events, n_stacked
                if events >= sc.max_events:
                    budget[BUDGET_TRUNCATED] += w
                    return events, n_stacked
                continue
            tau -= dist * c
        elif dist == math.inf:
            # no scattering and no plane ahead: down an infinitely deep clear layer, or level
            budget[(BUDGET_LAYERS + layer) if c > 0.0 else BUDGET_LOST_BELOW] += w
            return events, n_stacked
        elif c > 0.0:
            transmitted = math.exp(-c * dist)
            if sc.analog:
                if np.random.random() >= transmitted:
                    budget[BUDGET_LAYERS + layer] += w
                    return events, n_stacked
            else:
                budget[BUDGET_LAYERS + layer] += w * (1.0 - transmitted)
                w *= transmitted
        if dist == math.inf:  # b so small that tau / c overflowed: the packet never collides
            budget[BUDGET_LOST_BELOW] += w
            return events, n_stacked

        z = plane_z[target]
        level = sc.plane_tally[target]
        if level >= 0:
            score(sc, features, flux, radiance, level, w, ux, uy, uz, beam)

        if target == 0:
            # at the surface from below
            if not sc.surface_flat:
                score_air_up(sc, features, flux, radiance, w, ux, uy, uz, True, beam)
                budget[BUDGET_WATER_LEAVING] += w
                return events, n_stacked
            r, cos_t = reflectance(sc, n, 1.0, -uz)
            if sc.analog:
                if np.random.random() >= r:
                    ox, oy, oz = refract(ux, uy, uz, n, cos_t)
                    score_air_up(sc, features, flux, radiance, w, ox, oy, oz, True, beam)
                    budget[BUDGET_WATER_LEAVING] += w
                    return events, n_stacked
            else:
                leaving = w * (1.0 - r)
                if leaving > 0.0:
                    ox, oy, oz = refract(ux, uy, uz, n, cos_t)
                    score_air_up(sc, features, flux, radiance, leaving, ox, oy, oz, True,
                                 beam)
                    budget[BUDGET_WATER_LEAVING] += leaving
                # the reflected part (expected weight w r) goes on by roulette: with
                # probability r, carrying w, so its expectation is kept while a weak
                # internally reflected packet costs no more than in an analog walk
                if r < 1.0 and np.random.random() >= r:
                    return events, n_stacked
            uz = -uz
            seg = 0
            if level >= 0 and w > 0.0:
                score(sc, features, flux, radiance, level, w, ux, uy, uz, beam)
        elif target == bottom_plane:
            if not features & FEATURE_BOTTOM:  # black (an infinitely deep bottom is never met)
                budget[BUDGET_BOTTOM] += w
                return events, n_stacked
            if features & FEATURE_ESTIMATES:
                if sc.local_estimates:
                    local_estimate.score_bottom(sc, local, w, ux, uy, uz)
                if sc.cap_estimates:
                    local_estimate.cap_bottom(sc, cap, w, ux, uy, uz)
            ux, uy, uz, rho = brdf.reflect(sc.bottom_model, sc.bottom_params, ux, uy, uz,
                                           np.random.random(), np.random.random())
            beam = beam and sc.bottom_model == BOTTOM_SPECULAR
            if sc.analog:
                if np.random.random() >= rho:
                    budget[BUDGET_BOTTOM] += w
                    return events, n_stacked
            else:
                budget[BUDGET_BOTTOM] += w * (1.0 - rho)
                w *= rho
            seg = bottom_plane - 1
            if level >= 0 and w > 0.0:
                score(sc, features, flux, radiance, level, w, ux, uy, uz, beam)
            if features & FEATURE_SPLITTING and w > sc.split_weight:
                w, n_stacked = split(sc, stack, n_stacked, z, seg, w, ux, uy, uz, beam)
        else:
            seg = target if uz > 0.0 else target - 1
            continue
        alive, w = survives_roulette(sc, w)
        if not alive:
            return events, n_stacked


@njit(error_model="numpy", cache=True, _nrt=False)
def trace_batch(sc, features, n_photons, seed, flux, radiance, local, cap, budget, stack):
    """One batch: its own random stream (seeded from (seed, batch) by the caller), n_photons
    packets whose weights add up to n_photons. The sky's share is stratified: round(f n) packets
    come from the sky and carry f n / n_sky each, the rest from the sun; returns the number of
    scattering events. A photon's split copies (stack) are traced before the next photon."""
    np.random.seed(seed)
    f = sc.diffuse_fraction
    if f <= 0.0:
        n_sky = 0
    elif f >= 1.0:
        n_sky = n_photons
    else:
        n_sky = min(n_photons - 1, max(1, int(round(f * n_photons))))
    w_sky = f * n_photons / n_sky if n_sky > 0 else 0.0
    w_sun = (1.0 - f) * n_photons / (n_photons - n_sky) if n_sky < n_photons else 0.0
    sun = (sc.sun_sin, 0.0, sc.sun_mu)
    n_sun = n_photons - n_sky
    w_sun_in, sx, sy, sz = 0.0, 0.0, 0.0, 1.0
    if not sc.analog and n_sun > 0:
        # every implicit-mode sun packet enters the same way: score the beam's entry once
        _, w_sun_in, sx, sy, sz = enter_water(sc, features, w_sun * n_sun, sun[0], sun[1],
                                              sun[2], True, flux, radiance, budget)
        w_sun_in /= n_sun
    events = 0
    for i in range(n_photons):
        if features & FEATURE_SKY and i < n_sky:
            ux, uy, uz, w = sky_direction(sc)
            enters, w, ux, uy, uz = enter_water(sc, features, w * w_sky, ux, uy, uz, False,
                                                flux, radiance, budget)
            beam = False
        elif sc.analog:
            enters, w, ux, uy, uz = enter_water(sc, features, w_sun, sun[0], sun[1], sun[2],
                                                True, flux, radiance, budget)
            beam = True
        else:
            enters, w, ux, uy, uz, beam = True, w_sun_in, sx, sy, sz, True
        if not enters:
            continue
        z, seg, n_stacked = 0.0, 0, 0
        if features & FEATURE_SPLITTING and w > sc.split_weight:
            w, n_stacked = split(sc, stack, n_stacked, z, seg, w, ux, uy, uz, beam)
        while True:
            traced, n_stacked = trace_in_water(sc, features, z, seg, w, ux, uy, uz, beam, flux,
                                               radiance, local, cap, budget, stack, n_stacked)
            events += traced
            if n_stacked == 0:
                break
            n_stacked -= 1
            z = stack[n_stacked, STACK_Z]
            seg = int(stack[n_stacked, STACK_SEGMENT])
            w = stack[n_stacked, STACK_WEIGHT]
            ux = stack[n_stacked, STACK_UX]
            uy = stack[n_stacked, STACK_UY]
            uz = stack[n_stacked, STACK_UZ]
            beam = stack[n_stacked, STACK_BEAM] > 0.5
    return events
