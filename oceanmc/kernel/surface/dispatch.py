"""The air-water surface as a BSDF component, by model id (ids and names: kernel/registry.py).

Both surface models are delta BSDFs (a mirror and a refracted direction), so, as in Mitsuba 3
and pbrt-v4, evaluate() and pdf() are 0 for every finite pair of directions and the light is
carried by sample(), which returns the direction and the weight f cos / pdf: choosing reflection
with probability R, each branch's weight is 1. The photon loop's implicit estimator uses split()
instead, the expected-value form of the same BSDF: both branches with their shares R and 1 - R.
Local estimates through the surface ask for transmittance()."""
from ..compile import kernel
from ..models import SURFACE_FLAT
from . import flat, index_matched


@kernel
def split(surface, ux, uy, uz):
    """(R, rx, ry, rz, tx, ty, tz): the share R reflected into (rx, ry, rz) and 1 - R
    transmitted into (tx, ty, tz), for a photon travelling (ux, uy, uz) that meets the surface
    from the air (uz > 0) or from the water (uz < 0)."""
    if surface.model == SURFACE_FLAT:
        return flat.split(surface, ux, uy, uz)
    return index_matched.split(surface, ux, uy, uz)


@kernel
def sample(surface, ux, uy, uz, u):
    """(ox, oy, oz, weight, transmitted): reflection when u < R, else transmission; the weight
    f cos / pdf is 1 for either branch."""
    r, rx, ry, rz, tx, ty, tz = split(surface, ux, uy, uz)
    if u < r:
        return rx, ry, rz, 1.0, False
    return tx, ty, tz, 1.0, True


@kernel
def evaluate(surface, ux, uy, uz, ox, oy, oz):
    """f for a finite pair of directions: 0 for a delta BSDF (Mitsuba's convention)."""
    return 0.0


@kernel
def pdf(surface, ux, uy, uz, ox, oy, oz):
    """sample()'s density per steradian at a finite pair of directions: 0 for a delta BSDF."""
    return 0.0


@kernel
def transmittance(surface, mu):
    """The share of light travelling up at direction cosine mu in the water that leaves it."""
    if surface.model == SURFACE_FLAT:
        return flat.transmittance(surface, mu)
    return index_matched.transmittance(surface, mu)
