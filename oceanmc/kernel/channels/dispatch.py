"""A collision's channels: the elastic one turns the packet; each inelastic one (Raman
scattering, fluorescence) takes its share of every wavelength and emits a packet of its own."""
from ..compile import internal
from . import elastic, inelastic


@internal
def scatter(medium, floats, ints, ctrl, grid, tally, ps, work, p, layer, rng):
    """The elastic channel, every scene's (scene/medium.py packs it first as channel 0): the
    packet's new direction and weights."""
    elastic.scatter(medium, floats, ints, ctrl, grid, tally, ps, work, p, layer, rng)


@internal
def emit(medium, surface, ctrl, grid, est, floats, ints, tally_row, work, stack, stack_ps,
         n_stacked, p, ps, layer, rng_emitted):
    """Every inelastic channel (1 .. n_channels - 1; their models: MEDIUM channel_model, all
    run by channels/inelastic.py) of a collision of packet p, before its implicit capture;
    work[:n_wl] holds the collision's weight per unit coefficient at every wavelength
    (spectral.collision_density). Returns the new stack height."""
    if medium.n_channels == 1:
        return n_stacked
    for channel in range(1, medium.n_channels):
        n_stacked = inelastic.emit(channel, medium, surface, ctrl, grid, est, floats, ints,
                                   tally_row, work, stack, stack_ps, n_stacked, p, ps, layer,
                                   rng_emitted)
    return n_stacked
