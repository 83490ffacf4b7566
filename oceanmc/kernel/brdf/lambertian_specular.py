"""Lambertian + mirror: f = rho_d/pi + rho_s delta(mirror direction), params = (rho_d, rho_s).
rho_dh = rho_d + rho_s at every incidence (the schema keeps it <= 1).

Sampling picks the mirror with probability p_s = rho_s/(rho_d + rho_s) (u1 decides and is then
reused, rescaled, for the diffuse direction), else a cosine-weighted direction; either way the
weight is rho_d + rho_s, exactly f cos / pdf for the branch taken.

evaluate and pdf return only the finite (diffuse) part: a delta function has no value at a
finite pair of directions. Local (next-event) estimates therefore miss the mirror part, which is
why config/scene.py refuses local estimates with a bottom that has a mirror component."""
import math

from ..compile import kernel
from ..geometry import from_angles
from . import lambertian


@kernel
def mirror_sampled(params, u1):
    """Whether sample(params, ..., u1, u2) takes the mirror lobe (the spectral walk then gives
    each wavelength its mirror part's share: kernel/spectral.py reflect)."""
    total = params[0] + params[1]
    return total > 0.0 and u1 < params[1] / total


@kernel
def sample(params, wix, wiy, wiz, u1, u2):
    rho_d = params[0]
    rho_s = params[1]
    total = rho_d + rho_s
    if total <= 0.0:
        return 0.0, 0.0, 1.0, 0.0
    p_s = rho_s / total
    if u1 < p_s:
        return -wix, -wiy, wiz, total
    u = (u1 - p_s) / (1.0 - p_s)
    wox, woy, woz = from_angles(math.sqrt(min(1.0, u)), 2.0 * math.pi * u2)
    return wox, woy, woz, total


@kernel
def evaluate(params, wix, wiy, wiz, wox, woy, woz):
    """The diffuse part only (the mirror is a delta function; see the module note): the
    Lambertian f of reflectance params[0]."""
    return lambertian.evaluate(params, wix, wiy, wiz, wox, woy, woz)


@kernel
def pdf(params, wix, wiy, wiz, wox, woy, woz):
    """Density of the diffuse branch (probability 1 - p_s times cos/pi); the mirror branch is
    a point mass of probability p_s, not a density."""
    total = params[0] + params[1]
    if woz <= 0.0 or total <= 0.0:
        return 0.0
    return (params[0] / total) * woz / math.pi
