"""Collision channels: what a collision does once it scatters. A collision in a layer picks one
channel by its share of the layer's scattering coefficient at the hero wavelength (MEDIUM
channel_b; dispatch.choose), and the channel's module turns the packet (and, for an inelastic
process, moves its weight to other wavelengths). One module per channel, one registry line
(oceanmc/registry.py CHANNEL), one branch in dispatch.scatter, as phase functions and BRDFs.

Every channel's scatter(medium, mf, mi, ctrl, grid, tally, ps, work, p, layer, rng) is called
with p.w already multiplied by the hero's single-scattering albedo (implicit capture) or after
the analog walk's survival draw, and leaves the packet's new direction and weights in p and ps.

Energy: the budget has a column for the weight a process takes from a wavelength
(BUDGET_SHIFTED_OUT) and one for what it gives to another (BUDGET_SHIFTED_IN), so that each
wavelength's budget closes: reflected + water-leaving + absorbed + bottom + lost + truncated +
shifted out - shifted in = 1 (run/results.py budget_terms)."""
