"""Collision channels: what a collision does with the light that interacts. Channel 0, elastic
scattering (elastic.py), turns the packet; channels 1 .. (water.inelastic: Raman scattering,
fluorescence; inelastic.py) each take their share of every wavelength at every collision and
emit it at other wavelengths (dispatch.emit), light that rides on in the packet (dispatch.carry)
or, where the packet does not go on with its weight, in a packet of its own. One module per channel model,
one registry line (oceanmc/registry.py CHANNEL), one branch in dispatch, as phase functions and
BRDFs.

The elastic channel's scatter(medium, mf, mi, ctrl, grid, tally, ps, work, p, layer, carrying,
rng) is called with p.w already multiplied by the hero's single-scattering albedo (implicit
capture) or after the analog walk's survival draw, and leaves the packet's new direction and
weights in p and ps (and returns the density of that direction when the packet carries
emissions on).

Energy: the budget has a column for the weight a process takes from a wavelength
(BUDGET_SHIFTED_OUT) and one for what it gives to another (BUDGET_SHIFTED_IN), so that each
wavelength's budget closes in every part of the tally row (the elastic light's and each
process's): reflected + water-leaving + absorbed + bottom + lost + truncated + shifted out -
shifted in = the part's source (1 for the elastic part, 0 for an inelastic one)
(run/derivation.py budget_terms)."""
