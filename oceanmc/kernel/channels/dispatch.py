"""A collision's channel: chosen by its share of the scattering coefficient, then run."""
from ..compile import internal
from ..models import CHANNEL_ELASTIC
from ..rng import uniform
from . import elastic


@internal
def choose(medium, floats, layer, h, rng):
    """The channel of a collision in `layer` with hero wavelength h, drawn with probability
    b_channel / b (MEDIUM channel_b); a scene of one channel draws nothing."""
    n = medium.n_channels
    if n == 1:
        return 0
    n_wl = medium.n_wl
    row = medium.channel_b + layer * n * n_wl + h
    total = 0.0
    for k in range(n):
        total += floats[row + k * n_wl]
    left = uniform(rng) * total
    for k in range(n - 1):
        left -= floats[row + k * n_wl]
        if left < 0.0:
            return k
    return n - 1


@internal
def scatter(channel, medium, floats, ints, ctrl, grid, tally, ps, work, p, layer, rng):
    """Runs channel `channel` of the scene (its model: MEDIUM channel_model). Channel 0 is
    every scene's elastic scattering (scene/medium.py packs it first), run without reading
    its model."""
    if channel == 0 or ints[medium.channel_model + channel] == CHANNEL_ELASTIC:
        elastic.scatter(medium, floats, ints, ctrl, grid, tally, ps, work, p, layer, rng)
