"""Inelastic channels (Raman scattering, fluorescence: optics/inelastic/ packs them): at every
collision, each process takes from every wavelength j what it takes in expectation, x_j =
w_j sigma_j (w_j the collision's weight per unit coefficient, spectral.collision_density;
sigma_j the process's coefficient in the layer), and emits at each wavelength i
E_i = sum_j x_j T_ji (T the process's transfer: redistribution, photon-to-energy factor
lambda_j / lambda_i, and the source spectrum's ratio Ed0_j / Ed0_i, since a packet's weight at
a wavelength is a share of that wavelength's Ed0). The emitting packet goes on elastically: the
process's loss is in its attenuation (Raman) or absorption (fluorescence), and the budget moves
x_j from absorbed to shifted out.

The light an emission sends straight up (to the tally levels above and out of the water) is
scored at every collision by local estimates of the expected emission (local_estimate.
at_emission), as a collision's elastic light is: in clear water most Raman light leaves
without scattering again.

The rest rides on in the packet that emitted it (carry): the packet turns by its elastic phase
function, and the emission goes the same way with the weight E_i p_e(psi) / q(psi), p_e the
emission's phase function and q the density with which the walk drew the new direction. In a
spectral walk that is the hero's phase mixture averaged over the hero's posterior given the
path so far (the walk's K_j c_j at the collision, kernel/spectral.py): q(psi) = sum_j K_j c_j
q_j(psi) / sum_j K_j c_j, so that from there on the emitted light's weight at i takes the
same factors as the packet's elastic light at i (the one-sample MIS weight of the rest of the
path; its ratio to the weight at the collision is unbiased for light that starts there, given
the path). The packet's state keeps each part's share of its light (packet.shares), and
every scorer splits what it scores by them (tally.deposit). One walk thus carries every
emission of a history (the emitted packets it replaces cost 8x the elastic walk's time;
benchmarks/inelastic.md). The weight p_e / q is bounded (p_e <= 0.104 1/sr for Raman, q at least
the layer's least phase function value, the water's own molecular scattering in every layer).
(Drawing a fifth of the carried packets' directions uniformly over the sphere, a defensive
mixture, cut the variance of the carried Raman light's Eu(0-) by 2.6 but broke, by 0.1-0.5%,
the agreement of fluorescence's take with the quantum yield times the light phytoplankton
absorb (validation case inelastic, Hotelling T^2 6-7 against its bound 4.1): dropped, not
understood.)

Where the packet does not go on with its weight (the analog walk, which draws absorption, or
a layer that only scatters inelastically), the emission starts a packet of its own at the
collision point (hero wavelength drawn in proportion to the emission), in a direction drawn
from the process's phase function, tallied in the process's part; it waits on the split stack
and is traced after the packet that emitted it, within the same photon history. An emission
whose mean weight per wavelength is below the estimator's emission_weight is made with
probability mean / emission_weight and then carries that mean (Russian roulette on the
emission, unbiased; Kalos & Whitlock, Monte Carlo Methods, 2008, 4.2). The transfer is banded
(channel_band), so the emission costs the band's width per excitation wavelength, not n; a
separable one (channel_factors: fluorescence) costs n plus the emitted band's width. The
emitted packets' draws come from the batch's second stream (rng_emitted)."""
import math

from .. import local_estimate, packet, spectral
from ..compile import internal
from ..geometry import turn
from ..models import BUDGET_LAYERS, BUDGET_SHIFTED_IN, BUDGET_SHIFTED_OUT, BUDGET_TRUNCATED
from ..phase import quadratic
from ..rng import uniform
from ..tally import move_all, spectral_at


@internal
def emit(channel, medium, surface, ctrl, grid, est, floats, ints, tally_row, work, stack,
         stack_ps, n_stacked, p, ps, layer, carrying, rng_emitted, with_rough_surface,
         with_facet_walk, with_local_estimates, with_exact_directions):
    """Channel `channel` (1 ..) of a collision of packet p in `layer`, whose weights per unit
    coefficient are work[:n] (spectral.collision_density; book_takes has booked what it takes
    from each wavelength): scores the local estimates of the emission
    (local_estimate.at_emission), and leaves the emission in the channel's row of the scratch
    for carry() (carrying: the packet goes on with its weight) or pushes a packet of its own
    on the stack. Returns the new stack height."""
    n = grid.n_wl
    density = work[:n]
    taken = work[n:2 * n]
    k = channel - 1
    sigma_at = medium.channel_sigma + (k * medium.n_layers + layer) * n
    reach_at = medium.channel_reach + k * n
    part_size = grid.part_size
    total = 0.0
    for j in range(n):
        x = density[j] * floats[sigma_at + j]
        taken[j] = x
        total += x * floats[reach_at + j]
    kept = work[(3 + channel) * n:(4 + channel) * n]   # what carry() adds to the packet
    for i in range(n):
        kept[i] = 0.0
    if total <= 0.0:
        return n_stacked
    # roulette on the emitted packet, by its mean weight per wavelength (as p.w is one
    # wavelength's weight): made with probability mean / emission_weight below it. (The same
    # roulette on the emission's local estimates, tried with carried light: no faster, and the
    # fluorescence part of Rrs(680) took 27 s to 1% instead of 0.9 s; dropped.)
    target = ctrl.emission_weight * n
    spawn = not carrying
    scale = 1.0
    if spawn and total < target:
        spawn = uniform(rng_emitted) * target < total
        scale = target / total
    estimate = est.directions_on or est.cap_on
    if not (spawn or estimate or carrying):
        return n_stacked
    # a carried emission is made in the channel's row, where carry() reads it, and a packet's
    # own in the fourth row (the third holds the point's optical depths)
    emission = kept if carrying else work[3 * n:4 * n]
    if not carrying:
        for i in range(n):
            emission[i] = 0.0
    first_emitted = ints[medium.channel_emits + 2 * k]
    after_emitted = ints[medium.channel_emits + 2 * k + 1]
    if ints[medium.channel_separable + k]:
        # a separable transfer, T_ji = a_j b_i (fluorescence's: optics/inelastic factors):
        # E_i = b_i sum_j x_j a_j, one sum and a product per emitted wavelength, where the
        # banded sum below costs the band's width per excitation wavelength (8 for
        # chlorophyll fluorescence on a 10 nm grid)
        factors_at = medium.channel_factors + 2 * k * n
        a = floats[factors_at:factors_at + n]
        excited = 0.0
        for j in range(n):
            excited += taken[j] * a[j]
        b = floats[factors_at + n + first_emitted:factors_at + n + after_emitted]
        out = emission[first_emitted:after_emitted]
        for i in range(after_emitted - first_emitted):
            out[i] = excited * b[i]
    else:
        # T is banded (Raman moves light by 60-120 nm), so each excitation row adds to its
        # band only, through views that start at 0 (an offset index costs a wraparound test
        # per element: measured 1.6x slower, banded loops alone)
        transfer_at = medium.channel_transfer + k * n * n
        band_at = medium.channel_band + 2 * k * n
        for j in range(n):
            x = taken[j]
            if x > 0.0:
                lo = ints[band_at + 2 * j]
                width = ints[band_at + 2 * j + 1] - lo
                row = floats[transfer_at + j * n + lo:transfer_at + j * n + lo + width]
                out = emission[lo:lo + width]
                for i in range(width):
                    out[i] += x * row[i]
    part = channel
    child_part = part * part_size
    if with_local_estimates is not None and estimate:
        # the expected emission's light straight to the levels above and out (the packet
        # that carries the emission, or the emitted packet, scores its light after it
        # scatters)
        local_estimate.at_emission(est, grid, medium, surface, floats, ints,
                                   tally_row[child_part:child_part + part_size], work,
                                   emission, p, layer, medium.channel_beta + channel,
                                   est.emission_tables + k, first_emitted, after_emitted,
                                   rng_emitted, with_rough_surface, with_facet_walk,
                                   with_exact_directions)
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
    k_view, g, last, _ = packet.weights(grid, child_ps)
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
    packet.belong_to(grid, child_ps, part)
    cos_t = quadratic.sample(floats[medium.channel_beta + channel:], uniform(rng_emitted))
    child.ux, child.uy, child.uz = turn(p.ux, p.uy, p.uz, cos_t, uniform(rng_emitted))
    child.z = p.z
    child.seg = p.seg
    child.w = emitted
    child.beam = 0
    child.part = part
    child.wavelength = hero
    child.reference = heaviest
    return n_stacked + 1


@internal
def book_takes(medium, grid, floats, tally_row, work, ps, layer):
    """What every channel takes at a collision in `layer` (the collision's weights per unit
    coefficient in work[:n], spectral.collision_density, times each channel's coefficient),
    moved at once from the layer's absorption to shifted out, split by the packet's parts
    (tally.move_all; one move per channel before kernel d428def)."""
    n = grid.n_wl
    density = work[:n]
    taken = work[n:2 * n]
    for j in range(n):
        taken[j] = 0.0
    for k in range(medium.n_channels - 1):
        sigma_at = medium.channel_sigma + (k * medium.n_layers + layer) * n
        sigma = floats[sigma_at:sigma_at + n]
        for j in range(n):
            taken[j] += density[j] * sigma[j]
    move_all(grid, tally_row, packet.weights(grid, ps)[3],
             spectral_at(grid, grid.budget + BUDGET_LAYERS + layer),
             spectral_at(grid, grid.budget + BUDGET_SHIFTED_OUT), taken)


CARRY_FLOOR = 1e-300


@internal
def carry(medium, grid, floats, tally_row, work, ps, p, layer, cos_psi, density):
    """The emissions of a collision (each channel's row of the scratch, emit) ride on in packet
    p, which has just turned by psi (cos_psi) from its incident direction, a direction drawn
    with density `density` in 1/sr (spectral.direction_density): channel k's light at i gains
    E_i p_k(psi) / density (p_k its phase function), booked as shifted into its part. The
    packet settles first, its one settle at the collision: the free path since its last settle
    and the collision's implicit capture are booked with the shares it had; then each
    wavelength's shares take the new light in. (Until kernel 9b845d7 the packet settled at the
    start of the collision as well; the one settle, one move for all channels' takes
    (book_takes), the transfer's empty rows and contiguous level rows (local_estimate) took
    13-16% off the inelastic bench's photon loop together, interleaved runs.)"""
    spectral.settle(medium, floats, grid, tally_row, ps, p, layer)
    # the emission is in the units of p.w (times the packet's G); one below CARRY_FLOOR (after
    # a bottom of reflectance 1e-308, say) would overflow 1 / p.w into inf x 0 = NaN, and its
    # light is nothing beside the others': left out, as absorbed light (the emitting part's
    # take stays booked as shifted out)
    if p.w < CARRY_FLOOR or density <= 0.0:
        return
    n = grid.n_wl
    _, g, last, share = packet.weights(grid, ps)
    added = work[:n]
    for i in range(n):
        added[i] = 0.0
    for channel in range(1, medium.n_channels):
        kept = work[(3 + channel) * n:(4 + channel) * n]
        factor = quadratic.evaluate(floats[medium.channel_beta + channel:], cos_psi) / density
        shifted_in = channel * grid.part_size + spectral_at(grid,
                                                            grid.budget + BUDGET_SHIFTED_IN)
        shifted = tally_row[shifted_in:shifted_in + n]
        for i in range(n):
            kept[i] *= factor
            added[i] += kept[i]
            shifted[i] += kept[i]
    # each wavelength's light with the emissions, the part of it that the shares it had keep
    # (1 where nothing was added) and its reciprocal, then the shares part by part over
    # contiguous wavelengths, which LLVM vectorises (wavelength by wavelength with the parts
    # inside, they took about 8% of the inelastic bench's run by perf). The scratch rows of the
    # hero's posterior and of the emission are free: the scattering has read the one, the
    # channels' rows hold the other
    keep = work[n:2 * n]
    per_after = work[3 * n:4 * n]
    per_w = 1.0 / p.w
    for i in range(n):
        if added[i] > 0.0:
            after = last[i] + added[i]
            per_after[i] = 1.0 / after
            keep[i] = last[i] * per_after[i]   # (one division, not two: 1.7% of the run)
            g[i] += added[i] * per_w
            last[i] = after
        else:
            keep[i] = 1.0
            per_after[i] = 0.0
    for part in range(grid.n_parts):
        part_share = share[part * n:(part + 1) * n]
        for i in range(n):
            part_share[i] *= keep[i]
    for channel in range(1, medium.n_channels):
        kept = work[(3 + channel) * n:(4 + channel) * n]
        part_share = share[channel * n:(channel + 1) * n]
        for i in range(n):
            part_share[i] += kept[i] * per_after[i]
