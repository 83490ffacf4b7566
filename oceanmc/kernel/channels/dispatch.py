"""A collision's channel: chosen by its share of the scattering coefficient, then run."""
from ..compile import internal
from ..models import CHANNEL_ELASTIC
from ..rng import uniform
from . import elastic


@internal
def choose(medium, mf, layer, h, rng):
    """The channel of a collision in `layer` with hero wavelength h, drawn with probability
    b_channel / b (MEDIUM channel_b); a scene of one channel draws nothing."""
    n = medium.n_channels
    if n == 1:
        return 0
    n_wl = medium.n_wl
    row = medium.channel_b + layer * n * n_wl + h
    total = 0.0
    for k in range(n):
        total += mf[row + k * n_wl]
    left = uniform(rng) * total
    for k in range(n - 1):
        left -= mf[row + k * n_wl]
        if left < 0.0:
            return k
    return n - 1


@internal
def scatter(channel, medium, mf, mi, ctrl, grid, tally, ps, work, p, layer, rng):
    """Runs channel `channel` of the scene (its model: MEDIUM channel_model)."""
    model = mi[medium.channel_model + channel]
    if model == CHANNEL_ELASTIC:
        elastic.scatter(medium, mf, mi, ctrl, grid, tally, ps, work, p, layer, rng)
