"""The photon loop: weighted photon packets from the sun and sky, through the surface, the layered
water and off the bottom, until they leave, are absorbed or lose Russian roulette.

The walk is a sequence of events, each an ordinary compiled function with one call site in
trace_batch's event loop (move to the next event, then handle it, as MC/DC's loop does):
free_flight (to the next collision or plane), collide, cross_plane, and on the surface
leave_or_reflect, on the bottom reflect_at_bottom, after either after_reflection; a packet from
the air meets the surface in enter_from_air. Only trace_batch sees the whole scene; each event
takes the component records it needs, the scene's float and int pools (kernel/records.py) and
the packet (kernel/packet.py: a PACKET record p and its spectral state ps), which it updates in
place. A collision that scatters runs one of the scene's collision channels (kernel/channels/).
The event functions carry LLVM's alwaysinline attribute (kernel/compile.py): compiled once
each, they are merged into the loop by LLVM, not copied by Numba.

Estimator (estimator.analog false, the default): implicit capture (a collision keeps the packet
and multiplies its weight by the single-scattering albedo), expected values at the surface
(light from the air: the reflected part w R is scored and the packet enters with w (1 - R);
light from the water: the leaving part w (1 - R) is scored, and the packet goes on, reflected,
with probability R and weight w), weight times rho_dh at the bottom, exact exponential
attenuation in layers that do not scatter, and unbiased Russian roulette below
roulette_weight; optionally, scattering biased toward straight up (upward.py), splitting of
heavy packets, and depth importance windows (weight_window.py: on entering a segment of the
column a packet is split above the segment's window weight, and the roulette threshold at
collisions is scaled by it: the estimator record ctrl of an event is its segment's row).
Analog mode decides each of these with a random draw instead (in a spectral walk, for the hero
wavelength; kernel/spectral.py). Either way every quantity has the same expectation; only the
variance differs.

A spectral scene traces all its wavelengths in one history (kernel/spectral.py): a hero
wavelength per photon (p.wavelength) samples the path, and every wavelength's weight follows it;
the events below call spectral.* only where grid.n_wl > 1. Each optional part of the walk is
behind its with_ argument, which compiles it in or out (kernel/variants.py).

Every draw comes from the batch's own stream (kernel/rng.py), passed down as `rng`; it is
kept apart from the packet, so split copies do not copy it. One event's scratch is the batch's
`work` row, kept by no packet.
"""
import math

from . import local_estimate, packet, spectral, weight_window
from .brdf import dispatch as brdf
from .channels import dispatch as channels
from .compile import batch, internal
from .models import (BUDGET_BOTTOM, BUDGET_LAYERS, BUDGET_LOST_BELOW, BUDGET_SURFACE_REFLECTION,
                     BUDGET_TRUNCATED, BUDGET_WATER_LEAVING)
from .rng import uniform
from .sources import sky_direction
from .surface import dispatch as surface_bsdf
from .tally import score, score_crossing

# what a free flight ends in
FLIGHT_COLLISION = 0
FLIGHT_PLANE = 1
FLIGHT_GONE = 2     # absorbed in, or lost below, a layer that does not scatter
# what a plane is
PLANE_INSIDE = 0
PLANE_SURFACE = 1
PLANE_BOTTOM = 2


@internal
def exponential(rng):
    return -math.log(1.0 - uniform(rng))


@internal
def survives_roulette(ctrl, p, rng):
    """Below the threshold a packet survives with probability s and then carries w/s, so the
    expected weight is unchanged."""
    if ctrl.analog or p.w >= ctrl.roulette_weight:
        return True
    if uniform(rng) < ctrl.roulette_survival:
        p.w /= ctrl.roulette_survival
        return True
    return False


@internal
def split_into(grid, stack, stack_ps, n_stacked, p, ps, copies):
    """The packet becomes `copies` packets of weight w / copies that go on independently from
    the same state (the walk has no memory, so each is an unbiased copy; Kalos & Whitlock,
    Monte Carlo Methods, 2008, 4.2). All but one wait on the stack, as many as it has room for
    (fewer, heavier copies are as unbiased); every copy carries the packet's spectral state.
    Returns the new stack height."""
    copies = min(copies, stack.shape[0] - n_stacked + 1)
    if copies <= 1:
        return n_stacked
    packet.divide(grid, p, ps, copies)
    for _ in range(copies - 1):
        packet.copy(grid, stack[n_stacked], stack_ps[n_stacked], p, ps)
        n_stacked += 1
    return n_stacked


@internal
def split(ctrl, grid, stack, stack_ps, n_stacked, p, ps):
    """Splitting by weight: a packet heavier than split_weight becomes k = floor(w /
    split_weight) + 1 packets of weight w / k, each lighter than split_weight (split_into).
    Returns the new stack height."""
    return split_into(grid, stack, stack_ps, n_stacked, p, ps, int(p.w / ctrl.split_weight) + 1)


@internal
def facet_walk(surface, floats, p, rng, with_facet_walk):
    """The rough surface in split()'s form: one sample of it (its table or its facet walk;
    weight f cos / pdf applied to p.w), as R = 1 into the reflected direction or R = 0 into the
    transmitted one, so that the delta surface's expected-value scoring applies to it
    unchanged."""
    ox, oy, oz, weight, transmitted = surface_bsdf.sample(surface, p.ux, p.uy, p.uz,
                                                          uniform(rng), rng, floats,
                                                          with_facet_walk)
    p.w *= weight
    return (0.0 if transmitted else 1.0), ox, oy, oz, ox, oy, oz


@internal
def enter_from_air(surface, ctrl, grid, floats, ints, tally, ps, p, rng, with_rough_surface,
                   with_facet_walk):
    """A packet from the air meets the surface: scored at 0+ (incoming, and the reflected part),
    and what enters the water is scored at 0-; returns whether anything enters. Linear in w: in
    implicit mode the whole solar beam of a batch enters a delta surface in one call."""
    air = grid.air_level
    w = p.w
    score_crossing(grid, floats, ints, tally, ps, air, w, p.ux, p.uy, p.uz, p.beam)
    if with_rough_surface is None or surface.delta:
        r, rx, ry, rz, tx, ty, tz = surface_bsdf.split(surface, p.ux, p.uy, p.uz)
    else:
        r, rx, ry, rz, tx, ty, tz = facet_walk(surface, floats, p, rng, with_facet_walk)
        w = p.w
    if ctrl.analog:
        reflected = r > 0.0 and uniform(rng) < r
        w_reflected = w if reflected else 0.0
    else:
        reflected = False
        w_reflected = w * r
        p.w = w * (1.0 - r)
    if w_reflected > 0.0:
        score_crossing(grid, floats, ints, tally, ps, air, w_reflected, rx, ry, rz, p.beam)
        score(grid, tally, ps, grid.budget + BUDGET_SURFACE_REFLECTION, w_reflected)
    if reflected or p.w <= 0.0:
        return False
    p.ux = tx
    p.uy = ty
    p.uz = tz
    if grid.surface_level >= 0:
        score_crossing(grid, floats, ints, tally, ps, grid.surface_level, p.w, tx, ty, tz, p.beam)
    return True


@internal
def free_flight(medium, ctrl, grid, floats, ints, tally, ps, p, tau, rng, with_spectral,
                with_inelastic):
    """Moves the packet through its segment with tau optical depths left to its next
    collision: (FLIGHT_COLLISION, layer, 0) at a collision, (FLIGHT_PLANE, plane, tau left) on
    reaching the plane ahead, or (FLIGHT_GONE, -1, 0) when a layer that does not scatter
    absorbs it or it leaves down an infinitely deep one (attenuation there is exact: weight
    times exp(-c dist), or survival with that probability in the analog walk)."""
    seg = p.seg
    layer = ints[medium.segment_layer + seg]
    at = layer * medium.n_wl + p.wavelength
    c = floats[medium.layer_c + at]
    albedo = floats[medium.layer_albedo + at]
    uz = p.uz
    if uz > 0.0:
        target = seg + 1
        dist = (floats[medium.plane_z + target] - p.z) / uz
    elif uz < 0.0:
        target = seg
        dist = (floats[medium.plane_z + target] - p.z) / uz
    else:
        target = -1
        dist = math.inf
    budget = grid.budget
    # with inelastic processes every layer has collisions (Raman scattering is the water's own)
    if albedo > 0.0 or (with_inelastic is not None and medium.n_channels > 1):
        s = tau * floats[medium.layer_inv_c + at]
        if s < dist:
            p.z += s * uz
            if with_spectral is not None and grid.n_wl > 1:
                spectral.fly(medium, floats, grid, ps, p, layer, s)
            return FLIGHT_COLLISION, layer, 0.0
        tau -= dist * c
        if with_spectral is not None and grid.n_wl > 1 and dist < math.inf:
            spectral.fly(medium, floats, grid, ps, p, layer, dist)
    elif with_spectral is not None and grid.n_wl > 1:
        if spectral.attenuate(medium, floats, grid, tally, ps, p, layer, dist):
            return FLIGHT_GONE, -1, 0.0
    elif dist == math.inf:
        # no scattering and no plane ahead: down an infinitely deep clear layer, or level
        score(grid, tally, ps, budget + ((BUDGET_LAYERS + layer) if c > 0.0
                                         else BUDGET_LOST_BELOW), p.w)
        return FLIGHT_GONE, -1, 0.0
    elif c > 0.0:
        transmitted = math.exp(-c * dist)
        if ctrl.analog:
            if uniform(rng) >= transmitted:
                score(grid, tally, ps, budget + BUDGET_LAYERS + layer, p.w)
                return FLIGHT_GONE, -1, 0.0
        else:
            score(grid, tally, ps, budget + BUDGET_LAYERS + layer, p.w * (1.0 - transmitted))
            p.w *= transmitted
    if with_spectral is not None and grid.n_wl > 1:
        spectral.settle(medium, floats, grid, tally, ps, p, layer)
    if dist == math.inf:  # b so small that tau / c overflowed: the packet never collides
        score(grid, tally, ps, budget + BUDGET_LOST_BELOW, p.w)
        return FLIGHT_GONE, -1, 0.0
    p.z = floats[medium.plane_z + target]
    return FLIGHT_PLANE, target, tau


@internal
def collide(medium, surface, ctrl, grid, est, floats, ints, tally, ps, work, stack, stack_ps,
            n_stacked, p, layer, events, rng, rng_emitted, with_spectral, with_inelastic,
            with_rough_surface, with_facet_walk, with_local_estimates, with_exact_directions):
    """A collision in `layer`: local estimates, the inelastic channels' emissions (kernel/
    channels/: they take their share of every wavelength and emit it, light the packet carries
    on or that waits on the stack in packets of its own), absorption (implicit: weight times
    the albedo), elastic scattering, roulette. tally: the batch's tally row, every part of it.
    Returns (alive, optical depth to the next collision, stack height)."""
    albedo = floats[medium.layer_albedo + layer * medium.n_wl + p.wavelength]
    # (each use of these two is behind its with_ argument: Numba prunes a branch on an argument
    # of NoneType, not on a variable computed from one; kernel/variants.py)
    estimates = (est.directions_on or est.cap_on) and albedo > 0.0
    # the packet carries its collisions' emissions on where it goes on with its weight
    # (channels/inelastic.py), with the hero's posterior at the collision
    carrying = (medium.n_channels > 1 and ctrl.carry_emissions != 0 and not ctrl.analog
                and albedo > 0.0)
    if with_spectral is not None and grid.n_wl > 1 and (
            (with_local_estimates is not None and estimates)
            or (with_inelastic is not None and medium.n_channels > 1)):
        # the collision's weight per unit coefficient at every wavelength, which the local
        # estimates (times b) and the inelastic channels (times theirs) read
        at = spectral.posterior_at(grid)
        spectral.collision_density(medium, floats, grid, ps, p, layer, work[:grid.n_wl],
                                   work[at:at + grid.n_wl if with_inelastic is not None
                                        and carrying else at])
    if with_inelastic is not None and grid.n_parts > 1:
        # a new point: its cap scores are not set up yet (local_estimate.cap_transmissions)
        local_estimate.cap_transmissions(grid, work)[2][0] = 0.0
    if with_local_estimates is not None and (est.directions_on or est.cap_on):
        # (read by the local estimates and the emissions')
        local_estimate.collision_depths(medium, floats, grid, work, p, layer)
    if with_local_estimates is not None and estimates:
        local_estimate.at_collision(est, grid, medium, surface, floats, ints, tally, ps, work,
                                    p, layer, p.w * albedo, rng, with_rough_surface,
                                    with_facet_walk, with_exact_directions)
    if with_inelastic is not None:
        n_stacked = channels.emit(medium, surface, ctrl, grid, est, floats, ints, tally, work,
                                  stack, stack_ps, n_stacked, p, ps, layer, carrying,
                                  rng_emitted, with_rough_surface, with_facet_walk,
                                  with_local_estimates, with_exact_directions)
    w = p.w
    budget = grid.budget
    if ctrl.analog:
        if uniform(rng) >= albedo:
            if with_spectral is not None and grid.n_wl > 1:
                spectral.lose(grid, tally, ps, layer)
            else:
                score(grid, tally, ps, budget + BUDGET_LAYERS + layer, w)
            return False, 0.0, n_stacked
    else:
        if with_inelastic is not None and with_spectral is not None and albedo <= 0.0:
            # a layer that only scatters inelastically (channels.emit; without inelastic
            # channels a layer of albedo 0 has no collisions: free_flight)
            spectral.lose(grid, tally, ps, layer)
            return False, 0.0, n_stacked
        scattered = w * albedo
        if grid.n_wl == 1:  # a spectral walk books absorption when it settles (spectral.py)
            score(grid, tally, ps, budget + BUDGET_LAYERS + layer, w - scattered)
        p.w = scattered
    ux, uy, uz = p.ux, p.uy, p.uz
    density = channels.scatter(medium, floats, ints, ctrl, grid, tally, ps, work, p, layer,
                               carrying, rng, with_spectral)
    if with_inelastic is not None and carrying:
        channels.carry(medium, grid, floats, tally, work, ps, p, layer,
                       ux * p.ux + uy * p.uy + uz * p.uz, density)
    p.beam = 0
    tau = exponential(rng)
    if with_spectral is not None and grid.n_wl > 1:
        if not spectral.survives_roulette(medium, floats, ctrl, grid, tally, ps, p, layer, rng):
            return False, tau, n_stacked
    elif not survives_roulette(ctrl, p, rng):
        return False, tau, n_stacked
    if events >= ctrl.max_events:
        if with_spectral is not None and grid.n_wl > 1:
            spectral.settle(medium, floats, grid, tally, ps, p, layer)
        score(grid, tally, ps, budget + BUDGET_TRUNCATED, p.w)
        return False, tau, n_stacked
    return True, tau, n_stacked


@internal
def leave_or_reflect(surface, ctrl, grid, floats, ints, tally, ps, p, rng, with_spectral,
                     with_rough_surface, with_facet_walk):
    """A packet meets the surface from below: what leaves is scored at 0+ (all light and
    water-leaving light) and in the budget; what is reflected goes on (implicit: by roulette
    with probability R, carrying w, so a weak internally reflected packet costs no more than in
    an analog walk; a rough surface: one sample of its facet walk). Returns whether the packet
    goes on."""
    if with_rough_surface is None or surface.delta:
        r, rx, ry, rz, tx, ty, tz = surface_bsdf.split(surface, p.ux, p.uy, p.uz)
    else:
        r, rx, ry, rz, tx, ty, tz = facet_walk(surface, floats, p, rng, with_facet_walk)
    w = p.w
    if ctrl.analog:
        goes_on = r > 0.0 and uniform(rng) < r
        leaving = 0.0 if goes_on else w
    else:
        leaving = w * (1.0 - r)
        goes_on = r > 0.0 and (r >= 1.0 or uniform(rng) < r)
    if leaving > 0.0:
        air = grid.air_level
        score_crossing(grid, floats, ints, tally, ps, air, leaving, tx, ty, tz, p.beam)
        score_crossing(grid, floats, ints, tally, ps, air + 1, leaving, tx, ty, tz, p.beam)
        score(grid, tally, ps, grid.budget + BUDGET_WATER_LEAVING, leaving)
    if not goes_on:
        return False
    p.ux = rx
    p.uy = ry
    p.uz = rz
    p.seg = 0
    if with_spectral is not None and grid.n_wl > 1:
        spectral.carry(grid, ps, p)
    return True


@internal
def reflect_at_bottom(medium, surface, bottom, ctrl, grid, est, floats, ints, bp, tally, ps,
                      work, p, rng, with_spectral, with_rough_surface, with_facet_walk,
                      with_reflecting_bottom, with_detailed_bottom, with_local_estimates,
                      with_exact_directions):
    """A packet meets the bottom: local estimates of what it reflects, a reflected direction
    sampled from the BRDF with weight rho_dh (f cos / pdf), absorption of the rest. Returns
    whether the packet goes on."""
    budget = grid.budget
    if with_reflecting_bottom is None or not bottom.reflects:
        # black (an infinitely deep bottom is never met)
        score(grid, tally, ps, budget + BUDGET_BOTTOM, p.w)
        return False
    if with_local_estimates is not None and (est.directions_on or est.cap_on):
        local_estimate.at_bottom(est, grid, medium, bottom, surface, floats, ints, bp, tally,
                                 ps, work, p, rng, with_rough_surface, with_facet_walk,
                                 with_detailed_bottom, with_exact_directions)
    u1 = uniform(rng)
    u2 = uniform(rng)
    ux, uy, uz, rho = brdf.reflect(bottom.model, bp, p.ux, p.uy, p.uz, u1, u2,
                                   with_detailed_bottom)
    p.ux = ux
    p.uy = uy
    p.uz = uz
    p.beam = 1 if (p.beam != 0 and bottom.mirror != 0) else 0
    if ctrl.analog:
        if uniform(rng) >= rho:
            score(grid, tally, ps, budget + BUDGET_BOTTOM, p.w)   # (settled on the plane)
            return False
        if with_spectral is not None and grid.n_wl > 1:
            spectral.reflect(grid, floats, tally, ps, p, 1.0,
                             brdf.sampled_mirror(bottom.model, bp, u1))
    elif with_spectral is not None and grid.n_wl > 1:
        spectral.reflect(grid, floats, tally, ps, p, rho,
                         brdf.sampled_mirror(bottom.model, bp, u1))
    else:
        score(grid, tally, ps, budget + BUDGET_BOTTOM, p.w * (1.0 - rho))
        p.w *= rho
    p.seg = medium.n_planes - 2
    return True


@internal
def cross_plane(medium, grid, floats, ints, tally, ps, p, target):
    """The packet is on plane `target`: scored if the plane is a tally level; returns what the
    plane is (PLANE_SURFACE, PLANE_BOTTOM, or PLANE_INSIDE, where the packet has gone on into
    the next segment) and the plane's tally level (-1: none)."""
    level = ints[medium.plane_tally + target]
    if level >= 0:
        score_crossing(grid, floats, ints, tally, ps, level, p.w, p.ux, p.uy, p.uz, p.beam)
    if target == 0:
        return PLANE_SURFACE, level
    if target == medium.n_planes - 1:
        return PLANE_BOTTOM, level
    p.seg = target if p.uz > 0.0 else target - 1
    return PLANE_INSIDE, level


@internal
def after_reflection(medium, ctrl, grid, floats, ints, tally, ps, stack, stack_ps, n_stacked, p,
                     level, rng, with_spectral):
    """A packet reflected at the surface or the bottom crosses its plane's tally level again,
    may be split, and plays roulette; returns (alive, stack height)."""
    if level >= 0 and p.w > 0.0:
        score_crossing(grid, floats, ints, tally, ps, level, p.w, p.ux, p.uy, p.uz, p.beam)
    if ctrl.splitting and p.w > ctrl.split_weight:
        n_stacked = split(ctrl, grid, stack, stack_ps, n_stacked, p, ps)
    if with_spectral is not None and grid.n_wl > 1:
        return spectral.survives_roulette(medium, floats, ctrl, grid, tally, ps, p,
                                          ints[medium.segment_layer + p.seg], rng), n_stacked
    return survives_roulette(ctrl, p, rng), n_stacked


@batch
def trace_batch(medium_row, surface_row, bottom_row, sky_row, grid_row, est_row, ctrl_row,
                floats, ints, with_spectral, with_inelastic, with_rough_surface, with_facet_walk,
                with_reflecting_bottom, with_detailed_bottom, with_local_estimates,
                with_exact_directions, n_photons, start, work_budget,
                rng, rng_emitted, beam_in, tally_row, packet_row, stack, states, work):
    """Photons start, start + 1, ... of one batch of n_photons packets whose weights add up to
    n_photons, until the batch ends or, at a photon boundary, work_budget is spent (one unit
    per photon and per scattering event): returns (next photon index, scattering events).

    A batch may thus be traced in any number of calls, each continuing where the last stopped,
    with the same draws and the same additions in the same order as one call: its state between
    calls is its random streams rng and rng_emitted (kernel/rng.py, advanced in place; the
    second draws what inelastic emissions do: channels/inelastic.py), the next photon index
    (-1 at the start), its tally row, and beam_in, the entered solar beam (weight per sun
    packet and direction below the surface) that packet -1 computes once per batch in implicit
    mode; the split stack is empty between photons. The packet is packet_row[0] with the spectral
    state states[0]; the stack's rows k are stack[k] and states[k + 1]; work is one event's
    scratch (records.work_size). The sky's share is stratified: round(f n)
    packets come from the sky and carry f n / n_sky each, the rest from the sun. A photon's
    split copies and the packets its inelastic processes emit (channels/inelastic.py) wait on
    the stack and are traced before the next photon. The tally row holds one part per
    collision channel, each grid.part_size long: the elastic light's, then each process's (a
    packet's light may be of several parts, packet.shares; every scorer splits what it scores
    by them, tally.deposit). The records come as one-row
    arrays, the scene's tables as one float pool and one int pool (kernel/records.py); the GIL
    is released, so batches run in parallel threads. The with_ arguments say which optional
    parts of the loop are compiled in (kernel/variants.py)."""
    medium, surface, bottom, sky = medium_row[0], surface_row[0], bottom_row[0], sky_row[0]
    grid, est, ctrl, p = grid_row[0], est_row[0], ctrl_row[0], packet_row[0]
    bp = floats[bottom.params:]   # the BRDF's parameters, at offsets of their own
    ps = states[0]
    stack_ps = states[1:]
    f = sky.diffuse_fraction
    if f <= 0.0:
        n_sky = 0
    elif f >= 1.0:
        n_sky = n_photons
    else:
        n_sky = min(n_photons - 1, max(1, int(round(f * n_photons))))
    w_sky = f * n_photons / n_sky if n_sky > 0 else 0.0
    n_sun = n_photons - n_sky
    w_sun = (1.0 - f) * n_photons / n_sun if n_sun > 0 else 0.0
    analog = ctrl.analog
    # in implicit mode every sun packet enters a delta surface the same way, so the whole beam
    # of the batch enters once, as packet -1, before the others, and each sun packet starts
    # below the surface; through a rough surface each sun packet enters on its own
    beam_once = not analog and n_sun > 0 and surface.delta != 0
    w_sun_in, sx, sy, sz = beam_in[0], beam_in[1], beam_in[2], beam_in[3]
    events = 0
    n_stacked = 0   # the split stack is empty between photons
    for i in range(start, n_photons):
        if i > start and events + (i - start) >= work_budget:
            return i, events
        from_sky = 0 <= i < n_sky
        if i < 0:
            if not beam_once:
                continue
            ux, uy, uz, w = sky.sun_sin, 0.0, sky.sun_mu, w_sun * n_sun
        elif from_sky:
            ux, uy, uz, weight = sky_direction(sky, floats, rng)
            w = weight * w_sky
        elif not beam_once:
            ux, uy, uz, w = sky.sun_sin, 0.0, sky.sun_mu, w_sun
        else:
            ux, uy, uz, w = sx, sy, sz, w_sun_in
        packet.launch(p, w, ux, uy, uz, not from_sky)
        tally = tally_row
        from_air = i < 0 or from_sky or not beam_once
        if with_spectral is not None and grid.n_wl > 1:
            spectral.start(medium, grid, floats, ps, p, from_sky, rng)
        if from_air and not enter_from_air(surface, ctrl, grid, floats, ints, tally, ps, p, rng,
                                           with_rough_surface, with_facet_walk):
            continue
        if i < 0:
            w_sun_in, sx, sy, sz = p.w / n_sun, p.ux, p.uy, p.uz
            beam_in[0], beam_in[1], beam_in[2], beam_in[3] = w_sun_in, sx, sy, sz
            continue
        if with_spectral is not None and grid.n_wl > 1:
            spectral.carry(grid, ps, p)
        if ctrl.splitting and p.w > ctrl.split_weight:
            n_stacked = split(ctrl, grid, stack, stack_ps, n_stacked, p, ps)
        draws = rng
        while True:
            # the walk of packet p as a sequence of events, until it leaves, is absorbed or
            # loses roulette; then the next of its split copies or emitted packets, if any
            tau = exponential(draws)
            alive = True
            walk_events = 0   # this packet's collisions, against the max_events safety limit
            while alive and p.w > 0.0:
                outcome, where, tau = free_flight(medium, ctrl, grid, floats, ints, tally, ps, p,
                                                  tau, draws, with_spectral, with_inelastic)
                if outcome == FLIGHT_COLLISION:
                    walk_events += 1
                    alive, tau, n_stacked = collide(medium, surface, ctrl_row[p.seg], grid,
                                                    est, floats, ints, tally, ps, work, stack,
                                                    stack_ps, n_stacked, p, where, walk_events,
                                                    draws, rng_emitted, with_spectral,
                                                    with_inelastic, with_rough_surface,
                                                    with_facet_walk, with_local_estimates,
                                                    with_exact_directions)
                elif outcome == FLIGHT_PLANE:
                    plane, level = cross_plane(medium, grid, floats, ints, tally, ps, p, where)
                    if plane == PLANE_SURFACE:
                        alive = leave_or_reflect(surface, ctrl, grid, floats, ints, tally, ps, p,
                                                 draws, with_spectral, with_rough_surface,
                                                 with_facet_walk)
                    elif plane == PLANE_BOTTOM:
                        alive = reflect_at_bottom(medium, surface, bottom, ctrl, grid, est,
                                                  floats, ints, bp, tally, ps, work, p, draws,
                                                  with_spectral, with_rough_surface,
                                                  with_facet_walk, with_reflecting_bottom,
                                                  with_detailed_bottom, with_local_estimates,
                                                  with_exact_directions)
                    elif ctrl.depth_windows:
                        n_stacked = split_into(grid, stack, stack_ps, n_stacked, p, ps,
                                               weight_window.copies(ctrl_row[p.seg], grid, p,
                                                                    ps))
                    if alive and plane != PLANE_INSIDE:
                        alive, n_stacked = after_reflection(medium, ctrl_row[p.seg], grid,
                                                            floats, ints, tally, ps, stack,
                                                            stack_ps, n_stacked, p, level,
                                                            draws, with_spectral)
                else:
                    alive = False
            events += walk_events
            if n_stacked == 0:
                break
            n_stacked -= 1
            packet.copy(grid, p, ps, stack[n_stacked], stack_ps[n_stacked])
            # an emitted packet draws from the second stream
            draws = rng if p.part == 0 else rng_emitted
    return n_photons, events
