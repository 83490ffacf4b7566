"""A collision's channels: the elastic one turns the packet; each inelastic one (Raman
scattering, fluorescence) takes its share of every wavelength and emits a packet of its own."""
from ..compile import internal
from . import elastic, inelastic


@internal
def scatter(medium, floats, ints, ctrl, grid, tally, ps, work, p, layer, carrying, rng,
            with_spectral):
    """The elastic channel, every scene's (scene/medium.py packs it first as channel 0): the
    packet's new direction and weights; returns the density the direction was drawn with
    when the packet carries emissions (elastic.scatter)."""
    return elastic.scatter(medium, floats, ints, ctrl, grid, tally, ps, work, p, layer,
                           carrying, rng, with_spectral)


@internal
def emit(medium, surface, ctrl, grid, est, floats, ints, tally_row, work, stack, stack_ps,
         n_stacked, p, ps, layer, carrying, rng_emitted, with_rough_surface, with_facet_walk,
         with_local_estimates, with_exact_directions):
    """Every inelastic channel (1 .. n_channels - 1; their models: MEDIUM channel_model, all
    run by channels/inelastic.py) of a collision of packet p, before its implicit capture;
    work[:n_wl] holds the collision's weight per unit coefficient at every wavelength
    (spectral.collision_density). carrying: the packet carries the emissions on (carry), else
    each starts a packet of its own. Returns the new stack height."""
    if medium.n_channels == 1:
        return n_stacked
    inelastic.book_takes(medium, grid, floats, tally_row, work, ps, layer)
    for channel in range(1, medium.n_channels):
        n_stacked = inelastic.emit(channel, medium, surface, ctrl, grid, est, floats, ints,
                                   tally_row, work, stack, stack_ps, n_stacked, p, ps, layer,
                                   carrying, rng_emitted, with_rough_surface,
                                   with_facet_walk, with_local_estimates,
                                   with_exact_directions)
    return n_stacked


@internal
def carry(medium, grid, floats, tally_row, work, ps, p, layer, cos_psi, density):
    """The collision's emissions ride on in packet p (inelastic.carry)."""
    inelastic.carry(medium, grid, floats, tally_row, work, ps, p, layer, cos_psi, density)
