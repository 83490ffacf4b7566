"""Scattering biased toward straight up, for the nadir-viewing radiance (Lu, Lw_nadir, Rrs_nadir).

In forward-peaked water nearly all the variance of the local nadir estimates comes from the few
packets that travel within ~15 deg of straight up: each of their collisions sends the phase
function's forward peak into the viewing cap. Measured on the clear-ocean scene (2M photons):
collisions of packets within 15 deg of up give 47% of Rrs_nadir and 99.6% of its variance.
Such packets are born by rare backscatters. Here a fraction f of a layer's scattering events
draws the new direction uniformly in the cone of half-angle A around straight up, the others
from the phase function, and the packet carries the ratio of the phase function to the density
it was drawn from (the defensive mixture; Hesterberg 1995, Technometrics 37, 185; Veach 1997,
thesis, 9.2, one-sample balance heuristic):
    w' = w p(cos psi) / ((1 - f) p(cos psi) + f g),  g = 1 / (2 pi (1 - cos A)) in the cone,
which is w / (1 - f) outside the cone and at most w / (1 - f) anywhere. The expected weight
times any function of the new direction is that of plain phase-function sampling, so every
tally keeps its expectation. The caller has already multiplied w by the albedo w0, and
f <= 1 - w0 (scene/medium.py), so no scattering event makes a packet heavier: without that cap the
1 / (1 - f) per event outside the cone compounds over the long histories of turbid water
(measured, w0 = 0.976, f = 0.1: Ed at 20 m lost 99% of its figure of merit).
"""
import math

from .compile import kernel
from .geometry import cos_sin_turn, turn
from .phase import dispatch as phase
from .rng import uniform


@kernel
def scatter(medium, mf, mi, layer, w, ux, uy, uz, rng):
    """(w, ux, uy, uz) after a scattering event in `layer` of a packet of weight w (already
    times the albedo) travelling (ux, uy, uz); up is -z; rng: the batch's random stream."""
    up_cos = medium.up_cos
    if uniform(rng) < mf[medium.up_fraction + layer]:
        mu = 1.0 - uniform(rng) * (1.0 - up_cos)
        sin_t = math.sqrt(max(0.0, 1.0 - mu * mu))
        cp, sp = cos_sin_turn(uniform(rng))
        nx, ny, nz = sin_t * cp, sin_t * sp, -mu
    else:
        u_pick = uniform(rng) if mi[medium.comp_count + layer] > 1 else 0.0
        cos_s = phase.sample_cos(medium, mf, mi, layer, 0, u_pick, uniform(rng))
        nx, ny, nz = turn(ux, uy, uz, cos_s, uniform(rng))
    keep = mf[medium.up_keep + layer]
    if -nz > up_cos:
        p = phase.evaluate(medium, mf, mi, layer, ux * nx + uy * ny + uz * nz)
        return w * p / (keep * p + mf[medium.up_density + layer]), nx, ny, nz
    return w / keep, nx, ny, nz
