"""The flat air-water surface: exact unpolarized Fresnel reflectance (or Schlick's, for
comparisons) and Snell refraction, from the air and from the water, total internal reflection
included. A delta BSDF: all light leaves in two directions, the mirror and the refracted one."""
from ..compile import kernel
from .fresnel import fresnel, refract, schlick


@kernel
def reflectance(surface, n1, n2, cos_i):
    """(R, cos_t) from index n1 into n2 with the surface's choice of formula."""
    if surface.schlick:
        return schlick(n1, n2, cos_i)
    return fresnel(n1, n2, cos_i)


@kernel
def split(surface, ux, uy, uz):
    """(R, reflected direction, transmitted direction) for a photon travelling (ux, uy, uz)
    that meets the surface: from the air when uz > 0, from the water when uz < 0. Under total
    internal reflection R = 1 and the transmitted direction is meaningless."""
    n = surface.n_water
    if uz > 0.0:
        r, cos_t = reflectance(surface, 1.0, n, uz)
        tx, ty, tz = refract(ux, uy, uz, 1.0 / n, cos_t)
    else:
        r, cos_t = reflectance(surface, n, 1.0, -uz)
        tx, ty, tz = refract(ux, uy, uz, n, cos_t)
    return r, ux, uy, -uz, tx, ty, tz


@kernel
def transmittance(surface, mu):
    """The share of upwelling light at direction cosine mu (in water, from the vertical) that
    leaves the water: 1 - R."""
    return 1.0 - reflectance(surface, surface.n_water, 1.0, mu)[0]
