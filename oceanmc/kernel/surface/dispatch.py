"""The air-water surface as a BSDF component, by model id (ids and names: kernel/registry.py).

The flat and the index-matched surfaces are delta BSDFs (a mirror and a refracted direction),
so, as in Mitsuba 3 and pbrt-v4, evaluate() and pdf() are 0 for every finite pair of directions
and the light is carried by sample(), which returns the direction and the weight f cos / pdf:
choosing reflection with probability R, each branch's weight is 1. The photon loop's implicit
estimator uses split() for them instead (surface.delta), the expected-value form of the same
BSDF: both branches with their shares R and 1 - R. The rough surface is sampled only, with
weight 1: from its table (cox_munk_table.py, surface.tabulated) where the caller passes the
scene's float pool, else by its facet walk (cox_munk.py). Local estimates through a delta surface ask for
transmittance(); through the rough one they sample the walk backwards (local_estimate.py)."""
import numpy as np

from ..compile import kernel, setup
from ..models import SURFACE_COX_MUNK, SURFACE_FLAT
from ..rng import uniform
from . import cox_munk, cox_munk_table, flat, index_matched


@kernel
def split(surface, ux, uy, uz):
    """(R, rx, ry, rz, tx, ty, tz): the share R reflected into (rx, ry, rz) and 1 - R
    transmitted into (tx, ty, tz), for a photon travelling (ux, uy, uz) that meets a delta
    surface from the air (uz > 0) or from the water (uz < 0)."""
    if surface.model == SURFACE_FLAT:
        return flat.split(surface, ux, uy, uz)
    return index_matched.split(surface, ux, uy, uz)


@kernel
def sample(surface, ux, uy, uz, u, rng, floats=None, with_facet_walk=True):
    """(ox, oy, oz, weight, transmitted): the direction the photon leaves in and the weight
    f cos / pdf, 1 for every model. u is the first uniform draw (a delta surface reflects when
    u < R), rng the stream for any further ones (the rough surface's). floats: the scene's
    float pool, which holds a tabulated rough surface's table; without it (None: Numba
    compiles that call without the table's branch) the rough surface walks.
    with_facet_walk None: a photon loop without the facet walk (kernel/variants.py), whose
    scenes' rough surfaces are all tabulated (weight 0 for any other)."""
    if surface.model == SURFACE_COX_MUNK:
        if floats is not None:
            if surface.tabulated:
                ox, oy, oz, transmitted = cox_munk_table.sample(surface, floats, ux, uy, uz,
                                                                u, rng)
                return ox, oy, oz, 1.0, transmitted
        if with_facet_walk is None:
            return ux, uy, uz, 0.0, False
        ox, oy, oz, transmitted = cox_munk.walk(surface, ux, uy, uz, u, rng)
        return ox, oy, oz, 1.0, transmitted
    r, rx, ry, rz, tx, ty, tz = split(surface, ux, uy, uz)
    if u < r:
        return rx, ry, rz, 1.0, False
    return tx, ty, tz, 1.0, True


@kernel
def evaluate(surface, ux, uy, uz, ox, oy, oz):
    """f for a finite pair of directions: 0 for a delta BSDF (Mitsuba's convention); the rough
    surface is not evaluated (its multiple-interaction BSDF has no closed form; it is sampled)."""
    return 0.0


@kernel
def pdf(surface, ux, uy, uz, ox, oy, oz):
    """sample()'s density per steradian at a finite pair of directions: 0 for a delta BSDF."""
    return 0.0


@kernel
def transmittance(surface, mu):
    """The share of light travelling up at direction cosine mu in the water that leaves a delta
    surface."""
    if surface.model == SURFACE_FLAT:
        return flat.transmittance(surface, mu)
    return index_matched.transmittance(surface, mu)


@setup
def reflected_from(surface, ox, oy, oz, n, rng):
    """Where the light a viewer sees in the upward air direction o comes from after the
    surface reflects it: n samples of the surface for a photon travelling -o from the air
    (reciprocity: reflection is symmetric), each the direction of travel (downward) of the sky
    light reflected into o, or a row of nan where that sample was transmitted instead."""
    out = np.full((n, 3), np.nan)
    for i in range(n):
        dx, dy, dz, weight, transmitted = sample(surface, -ox, -oy, -oz, uniform(rng), rng)
        if not transmitted:
            out[i, 0], out[i, 1], out[i, 2] = -dx, -dy, -dz   # weight 1 (sample())
    return out
