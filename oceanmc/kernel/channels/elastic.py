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
def scatter(medium, mf, mi, ctrl, grid, tally, ps, work, p, layer, rng):
    """The packet's new direction, and its weights for it (see channels/__init__.py)."""
    ux, uy, uz = p.ux, p.uy, p.uz
    h = p.wavelength
    spectral_walk = grid.n_wl > 1
    psi_s = -1
    node_s = -1
    toward_up = ctrl.upward != 0 and uniform(rng) < mf[medium.up_fraction + layer]
    if toward_up:
        nx, ny, nz = upward.cone_direction(medium, rng)
        cos_s = ux * nx + uy * ny + uz * nz
        angle = tabulated.clamped_angle(cos_s)
    else:
        u_pick = uniform(rng) if mi[medium.comp_count + layer] > 1 else 0.0
        if spectral_walk:
            k_s = phase.pick(medium, mf, mi, layer, h, u_pick)
            cos_s, angle, psi_s, node_s = phase.sample_angle(medium, mf, mi, k_s, uniform(rng))
        else:
            cos_s = phase.sample_cos(medium, mf, mi, layer, h, u_pick, uniform(rng))
            angle = 0.0
        nx, ny, nz = turn(ux, uy, uz, cos_s, uniform(rng))
    if ctrl.upward:
        if spectral_walk:
            inside = -nz > medium.up_cos
            spectral.scatter_weights(medium, mf, mi, grid, tally, ps, work, p, layer, cos_s,
                                     angle, psi_s, node_s, mf[medium.up_keep + layer],
                                     mf[medium.up_density + layer] if inside else 0.0)
        else:
            p.w = upward.weight(medium, mf, mi, layer, p.w, ux * nx + uy * ny + uz * nz, nz)
    elif spectral_walk:
        spectral.scatter_weights(medium, mf, mi, grid, tally, ps, work, p, layer, cos_s, angle,
                                 psi_s, node_s, 1.0, 0.0)
    p.ux = nx
    p.uy = ny
    p.uz = nz
