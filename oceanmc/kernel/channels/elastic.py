"""Elastic scattering: the packet keeps its wavelengths and turns by an angle drawn from the
hero wavelength's phase function (a mixture of components: phase/dispatch.py), or, with
scattering biased toward straight up (kernel/upward.py), from the defensive mixture of the phase
function and the upward cone. A spectral walk then gives every wavelength the factors of its
one-sample MIS weight (spectral.scatter_weights)."""
import math

from .. import spectral, upward
from ..compile import internal
from ..geometry import from_angles, turn
from ..phase import dispatch as phase
from ..phase import tabulated
from ..rng import uniform

# where the packet carries emissions on (channels/inelastic.py), the share of its new
# directions drawn uniformly over the sphere: the emitted light, nearly isotropic, then weighs
# at most 4 pi p_e / EMISSION_SHARE (<= 1.3 / EMISSION_SHARE for Raman's phase function) where
# the elastic phase function, peaked forward, rarely sends the packet. Measured (clear water,
# the inelastic bench's scene, 2 runs of 100k photons each, time to 1%): 0.2 against 0.5,
# Raman Rrs(550) 1.0-1.1 s against 1.2 s, fluorescence Rrs(680) 0.5-0.6 s against 0.7-0.9 s,
# Raman Eu(0-, 550) 3.2-4.4 s against 1.9-3.4 s; without it (0) Eu had 2.6 times the variance
EMISSION_SHARE = 0.2


@internal
def scatter(medium, floats, ints, ctrl, grid, tally, ps, work, p, layer, carrying, rng):
    """The packet's new direction, and its weights for it (see channels/__init__.py).
    carrying: the packet carries a collision's emissions on (channels/inelastic.py carry),
    and work[n_wl:2 n_wl] holds the hero's posterior (spectral.hero_posterior); the direction
    is then drawn, with probability EMISSION_SHARE, uniformly over the sphere (a third
    technique of the defensive mixture beside the phase function and the upward cone), and
    the density with which it was drawn, averaged over the posterior, is returned (1/sr;
    else 0)."""
    ux, uy, uz = p.ux, p.uy, p.uz
    h = p.wavelength
    spectral_walk = grid.n_wl > 1
    psi_s = -1
    node_s = -1
    up = floats[medium.up_fraction + layer] if ctrl.upward != 0 else 0.0
    isotropic_share = min(EMISSION_SHARE, 0.5 * (1.0 - up)) if carrying else 0.0
    u_technique = uniform(rng) if (ctrl.upward != 0 or carrying) else 1.0
    if u_technique < up:
        nx, ny, nz = upward.cone_direction(medium, rng)
        cos_s = ux * nx + uy * ny + uz * nz
        angle = tabulated.clamped_angle(cos_s)
    elif u_technique < up + isotropic_share:
        nx, ny, nz = from_angles(2.0 * uniform(rng) - 1.0, 2.0 * math.pi * uniform(rng))
        cos_s = ux * nx + uy * ny + uz * nz
        angle = tabulated.clamped_angle(cos_s)
    else:
        u_pick = uniform(rng) if ints[medium.comp_count + layer] > 1 else 0.0
        if spectral_walk:
            k_s = phase.pick(medium, floats, ints, layer, h, u_pick)
            cos_s, angle, psi_s, node_s = phase.sample_angle(medium, floats, ints, k_s,
                                                             uniform(rng))
        else:
            cos_s = phase.sample_cos(medium, floats, ints, layer, h, u_pick, uniform(rng))
            angle = 0.0
        nx, ny, nz = turn(ux, uy, uz, cos_s, uniform(rng))
    density = 0.0
    if spectral_walk:
        keep = 1.0 - isotropic_share
        # the density of the techniques that do not depend on the wavelength (1/sr)
        flat_density = isotropic_share / (4.0 * math.pi)
        if ctrl.upward:
            keep = floats[medium.up_keep + layer] - isotropic_share
            if -nz > medium.up_cos:
                flat_density += floats[medium.up_density + layer]
        spectral.scatter_weights(medium, floats, ints, grid, tally, ps, work, p, layer, cos_s,
                                 angle, psi_s, node_s, keep, flat_density, ctrl.analog != 0)
        if carrying:
            n = grid.n_wl
            density = spectral.direction_density(medium, floats, grid, work[n:2 * n],
                                                 work[:n], layer, angle, keep, flat_density)
    elif ctrl.upward:
        p.w = upward.weight(medium, floats, ints, layer, p.w, ux * nx + uy * ny + uz * nz, nz)
    p.ux = nx
    p.uy = ny
    p.uz = nz
    return density
