"""Elastic scattering: the packet keeps its wavelengths and turns by an angle drawn from the
hero wavelength's phase function (a mixture of components: phase/dispatch.py), or, with
scattering biased toward straight up (kernel/upward.py), from the defensive mixture of the phase
function and the upward cone. A spectral walk then gives every wavelength the factors of its
one-sample MIS weight (spectral.scatter_weights)."""
from .. import spectral, upward
from ..compile import internal
from ..geometry import turn
from ..phase import dispatch as phase
from ..phase import tabulated
from ..rng import uniform


@internal
def scatter(medium, floats, ints, ctrl, grid, tally, ps, work, p, layer, carrying, rng,
            with_spectral):
    """The packet's new direction, and its weights for it (see channels/__init__.py).
    carrying: the packet carries a collision's emissions on (channels/inelastic.py carry),
    and the scratch holds the hero's posterior (spectral.posterior_at); returns the
    density with which the direction was drawn, averaged over it (1/sr; else 0)."""
    ux, uy, uz = p.ux, p.uy, p.uz
    h = p.wavelength
    spectral_walk = grid.n_wl > 1
    psi_s = -1
    node_s = -1
    toward_up = ctrl.upward != 0 and uniform(rng) < floats[medium.up_fraction + layer]
    if toward_up:
        nx, ny, nz = upward.cone_direction(medium, rng)
        cos_s = ux * nx + uy * ny + uz * nz
        angle = tabulated.clamped_angle(cos_s)
    else:
        u_pick = uniform(rng) if ints[medium.comp_count + layer] > 1 else 0.0
        if with_spectral is not None and spectral_walk:
            k_s = phase.pick(medium, floats, ints, layer, h, u_pick)
            cos_s, angle, psi_s, node_s = phase.sample_angle(medium, floats, ints, k_s,
                                                             uniform(rng))
        else:
            cos_s = phase.sample_cos(medium, floats, ints, layer, h, u_pick, uniform(rng))
            angle = 0.0
        nx, ny, nz = turn(ux, uy, uz, cos_s, uniform(rng))
    density = 0.0
    if with_spectral is not None and spectral_walk:
        keep = 1.0
        cone_density = 0.0
        if ctrl.upward:
            keep = floats[medium.up_keep + layer]
            if -nz > medium.up_cos:
                cone_density = floats[medium.up_density + layer]
        spectral.scatter_weights(medium, floats, ints, grid, tally, ps, work, p, layer, cos_s,
                                 angle, psi_s, node_s, keep, cone_density, ctrl.analog != 0)
        if carrying:
            n = grid.n_wl
            at = spectral.posterior_at(grid)
            density = spectral.direction_density(medium, floats, grid, work[at:at + n],
                                                 work[:n], layer, angle, keep, cone_density)
    elif ctrl.upward:
        p.w = upward.weight(medium, floats, ints, layer, p.w, ux * nx + uy * ny + uz * nz, nz)
    p.ux = nx
    p.uy = ny
    p.uz = nz
    return density
