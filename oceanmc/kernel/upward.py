"""Scattering biased toward straight up, for the nadir-viewing radiance (Lu, Lw_nadir, Rrs_nadir).

In forward-peaked water nearly all the variance of the local nadir estimates comes from the few
packets that travel within ~15 deg of straight up: each of their collisions sends the phase
function's forward peak into the viewing cap. Measured on the clear-ocean scene (2M photons):
collisions of packets within 15 deg of up give 47% of Rrs_nadir and 99.6% of its variance.
Such packets are born by rare backscatters. Here a fraction f of a layer's scattering events
draws the new direction uniformly in the cone of half-angle A around straight up, the others
from the phase function (kernel/channels/elastic.py draws it), and the packet carries the
ratio of the phase function to the density it was drawn from (the defensive mixture;
Hesterberg 1995, Technometrics 37, 185; Veach 1997, thesis, 9.2, one-sample balance heuristic):
    w' = w p(cos psi) / ((1 - f) p(cos psi) + f g),  g = 1 / (2 pi (1 - cos A)) in the cone,
which is w / (1 - f) outside the cone and at most w / (1 - f) anywhere. The expected weight
times any function of the new direction is that of plain phase-function sampling, so every
tally keeps its expectation. The caller has already multiplied w by the albedo w0, and
f <= 1 - w0 (scene/medium.py; the largest w0 of the layer's wavelengths in a spectral scene),
so no scattering event makes a packet heavier: without that cap the 1 / (1 - f) per event
outside the cone compounds over the long histories of turbid water (measured, w0 = 0.976,
f = 0.1: Ed at 20 m lost 99% of its figure of merit).
"""
import math

from .compile import internal, kernel
from .geometry import cos_sin_turn
from .phase import dispatch as phase
from .rng import uniform


@internal
def cone_direction(medium, rng):
    """A direction drawn uniformly in the cone of half-angle acos(up_cos) around straight up
    (-z)."""
    mu = 1.0 - uniform(rng) * (1.0 - medium.up_cos)
    sin_t = math.sqrt(max(0.0, 1.0 - mu * mu))
    cp, sp = cos_sin_turn(uniform(rng))
    return sin_t * cp, sin_t * sp, -mu


@kernel
def weight(medium, floats, ints, layer, w, cos_new, nz):
    """The weight after a scattering event in `layer`, by cos_new = the cosine of the turn, into
    a direction whose z-component is nz, of a packet of weight w (already times the albedo),
    the direction having been drawn from the defensive mixture (one wavelength; a spectral walk:
    spectral.scatter_weights)."""
    keep = floats[medium.up_keep + layer]
    if -nz > medium.up_cos:
        p = phase.evaluate(medium, floats, ints, layer, cos_new)
        return w * p / (keep * p + floats[medium.up_density + layer])
    return w / keep
