"""Fresnel reflectance and Snell refraction at a plane interface (shared by the surface models)."""
import math

from ..compile import kernel
from ..geometry import renormalised


@kernel
def fresnel(n1, n2, cos_i):
    """(R, cos_t) for light going from index n1 into n2 at incidence cosine cos_i >= 0.
    R = (Rs + Rp)/2 (Born & Wolf, Principles of Optics, 1.5.3); total internal reflection gives
    (1, 0). Normal incidence gives ((n1 - n2)/(n1 + n2))^2."""
    if n1 == n2:
        return 0.0, cos_i
    sin_t2 = (n1 / n2) ** 2 * max(0.0, 1.0 - cos_i * cos_i)
    if sin_t2 >= 1.0:
        return 1.0, 0.0
    cos_t = math.sqrt(1.0 - sin_t2)
    den_s = n1 * cos_i + n2 * cos_t
    den_p = n1 * cos_t + n2 * cos_i
    if den_s == 0.0 or den_p == 0.0:   # grazing incidence from the less dense side
        return 1.0, cos_t
    rs = (n1 * cos_i - n2 * cos_t) / den_s
    rp = (n1 * cos_t - n2 * cos_i) / den_p
    return 0.5 * (rs * rs + rp * rp), cos_t


@kernel
def schlick(n1, n2, cos_i):
    """Schlick's approximation R0 + (1 - R0)(1 - cos)^5 (Schlick 1994), with the cosine taken on
    the less dense side and total internal reflection kept: offered for comparisons only."""
    r_exact, cos_t = fresnel(n1, n2, cos_i)
    if r_exact >= 1.0:
        return 1.0, cos_t
    r0 = ((n1 - n2) / (n1 + n2)) ** 2
    c = cos_i if n1 <= n2 else cos_t
    return r0 + (1.0 - r0) * (1.0 - c) ** 5, cos_t


@kernel
def refract(ux, uy, uz, ratio, cos_t):
    """Direction after crossing a horizontal interface: tangential components scale by
    ratio = n1/n2 (Snell), the vertical one keeps its sign with magnitude cos_t."""
    nx = ux * ratio
    ny = uy * ratio
    nz = cos_t if uz > 0.0 else -cos_t
    return renormalised(nx, ny, nz)
