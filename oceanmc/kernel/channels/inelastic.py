"""Inelastic channels (Raman scattering, fluorescence: optics/inelastic/ packs them): at every
collision, each process takes from every wavelength j what it takes in expectation, x_j =
w_j sigma_j (w_j the collision's weight per unit coefficient, spectral.collision_density;
sigma_j the process's coefficient in the layer), and emits at each wavelength i
E_i = sum_j x_j T_ji (T the process's transfer: redistribution, photon-to-energy factor
lambda_j / lambda_i, and the source spectrum's ratio Ed0_j / Ed0_i, since a packet's weight at
a wavelength is a share of that wavelength's Ed0). The emission starts a packet of its own at
the collision point (a new source of light, as the sun's photons are: hero wavelength drawn
anew, in proportion to the emission), in a direction drawn from the process's phase function about the incident
direction, tallied in the process's part of the tally row (p.part); it waits on the split stack
and is traced after the packet that emitted it, within the same photon history. The emitting
packet goes on elastically: the process's loss is in its attenuation (Raman) or absorption
(fluorescence), and the budget moves x_j from absorbed to shifted out.

The light an emission sends straight up (to the tally levels above and out of the water) is
scored at every collision by local estimates of the expected emission (local_estimate.
at_emission), as a collision's elastic light is: in clear water most Raman light leaves
without scattering again. The emitted packet carries the rest. An emission whose mean weight
per wavelength is below the estimator's emission_weight is made with probability mean /
emission_weight and then carries that mean (Russian roulette on the emission, unbiased; Kalos &
Whitlock, Monte Carlo Methods, 2008, 4.2), so that the emitted packets of a history stay few
(a packet emitted by an emitted packet weighs about sigma / c of it, so their number falls
geometrically). The transfer is banded (channel_band), so the emission costs the band's width
per excitation wavelength, not n. Its draws come from the batch's second stream (rng_emitted), so that the elastic
light's draws, and with them the elastic part of every output, are those of the same scene
without the inelastic processes (whose loss is kept as absorption)."""
import math

from .. import local_estimate, packet
from ..compile import internal
from ..geometry import turn
from ..models import BUDGET_LAYERS, BUDGET_SHIFTED_IN, BUDGET_SHIFTED_OUT, BUDGET_TRUNCATED
from ..phase import quadratic
from ..rng import uniform
from ..tally import spectral_at


@internal
def emit(channel, medium, surface, ctrl, grid, est, floats, ints, tally_row, work, stack,
         stack_ps, n_stacked, p, ps, layer, rng_emitted):
    """Channel `channel` (1 ..) of a collision of packet p in `layer`, whose weights per unit
    coefficient are work[:n] (spectral.collision_density): books what it takes from each
    wavelength in p's part of the tally row, and, when it emits, books what it gives in its
    own part, scores the local estimates of the emission (local_estimate.at_emission) and
    pushes the emitted packet on the stack. Returns the new stack height."""
    n = grid.n_wl
    density = work[:n]
    taken = work[n:2 * n]
    k = channel - 1
    sigma_at = medium.channel_sigma + (k * medium.n_layers + layer) * n
    reach_at = medium.channel_reach + k * n
    part_size = grid.part_size
    own = p.part * part_size
    absorbed = own + spectral_at(grid, grid.budget + BUDGET_LAYERS + layer)
    out = own + spectral_at(grid, grid.budget + BUDGET_SHIFTED_OUT)
    total = 0.0
    for j in range(n):
        x = density[j] * floats[sigma_at + j]
        taken[j] = x
        tally_row[absorbed + j] -= x
        tally_row[out + j] += x
        total += x * floats[reach_at + j]
    if total <= 0.0:
        return n_stacked
    # roulette on the emitted packet, by its mean weight per wavelength (as p.w is one
    # wavelength's weight): made with probability mean / emission_weight below it
    target = ctrl.emission_weight * n
    spawn = True
    scale = 1.0
    if total < target:
        spawn = uniform(rng_emitted) * target < total
        scale = target / total
    estimate = est.directions_on or est.cap_on
    if not (spawn or estimate):
        return n_stacked
    # the emission at each wavelength: T is banded (Raman moves light by 60-120 nm,
    # fluorescence into 685 +- 64 nm), so each excitation row adds to its band only
    emission = work[2 * n:3 * n]
    transfer_at = medium.channel_transfer + k * n * n
    band_at = medium.channel_band + 2 * k * n
    for i in range(n):
        emission[i] = 0.0
    for j in range(n):
        x = taken[j]
        if x > 0.0:
            row = transfer_at + j * n
            for i in range(ints[band_at + 2 * j], ints[band_at + 2 * j + 1]):
                emission[i] += x * floats[row + i]
    part = channel
    child_part = part * part_size
    if estimate:
        # the expected emission's light straight to the levels above and out, at every
        # collision (the emitted packet's collisions score its light after it scatters)
        local_estimate.at_emission(est, grid, medium, surface, floats, ints,
                                   tally_row[child_part:child_part + part_size], work, p, layer,
                                   medium.channel_beta + channel, est.emission_tables + k,
                                   ints[medium.channel_emits + 2 * k],
                                   ints[medium.channel_emits + 2 * k + 1], rng_emitted)
    if not spawn:
        return n_stacked
    shifted_in = child_part + spectral_at(grid, grid.budget + BUDGET_SHIFTED_IN)
    heaviest = 0
    for i in range(n):
        emission[i] *= scale
        tally_row[shifted_in + i] += emission[i]
        if emission[i] > emission[heaviest]:
            heaviest = i
    if n_stacked >= stack.shape[0]:
        # no room left on the stack (SPLIT_STACK_ROWS packets waiting; never seen): the
        # emission is booked as truncated in its part
        truncated = child_part + spectral_at(grid, grid.budget + BUDGET_TRUNCATED)
        for i in range(n):
            tally_row[truncated + i] += emission[i]
        return n_stacked
    child = stack[n_stacked]
    child_ps = stack_ps[n_stacked]
    k_view, g, last = packet.weights(grid, child_ps)
    # its hero wavelength drawn in proportion to what it carries (pi_i = E_i / sum E), not
    # uniformly: the one-sample MIS weight becomes f_l / sum_j pi_j p_j, which the spectral
    # state holds with K_j = n pi_j at the start (mean K = 1; spectral.py), so a red emission
    # is not walked by an ultraviolet hero whose long free paths it does not survive
    emitted = total * scale
    per_emitted = 1.0 / emitted
    pick = uniform(rng_emitted) * emitted
    hero = heaviest
    for i in range(n):
        k_view[i] = n * emission[i] * per_emitted
        last[i] = emission[i]
        g[i] = emission[i] * per_emitted
        pick -= emission[i]
        if pick < 0.0 and emission[i] > 0.0:
            hero = i
            pick = math.inf
    child_ps[packet.free_path_at(grid)] = 0.0
    cos_t = quadratic.sample(floats[medium.channel_beta + channel:], uniform(rng_emitted))
    child.ux, child.uy, child.uz = turn(p.ux, p.uy, p.uz, cos_t, uniform(rng_emitted))
    child.z = p.z
    child.seg = p.seg
    child.w = total * scale
    child.beam = 0
    child.part = part
    child.wavelength = hero
    child.reference = heaviest
    return n_stacked + 1
