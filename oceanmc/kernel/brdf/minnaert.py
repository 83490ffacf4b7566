"""Minnaert: f = (rho/pi)(cos t_i cos t_o)^k, params = (rho, k). Sampled with
pdf = (k + 2) cos^(k+1)(t_o) / (2 pi): theta_o = acos(u1^(1/(k+2))), phi uniform, so the weight
f cos/pdf is rho_dh(t_i) = 2 rho cos^k(t_i) / (k + 2) (Minnaert 1941; see shared/seeds)."""
import math

from ..compile import kernel
from ..geometry import from_angles


@kernel
def reflectance(params, cos_i):
    """Directional-hemispherical reflectance rho_dh(t_i)."""
    return 2.0 * params[0] * max(0.0, cos_i) ** params[1] / (params[1] + 2.0)


@kernel
def sample(params, wix, wiy, wiz, u1, u2):
    cos_o = u1 ** (1.0 / (params[1] + 2.0))
    wox, woy, woz = from_angles(cos_o, 2.0 * math.pi * u2)
    return wox, woy, woz, reflectance(params, wiz)


@kernel
def evaluate(params, wix, wiy, wiz, wox, woy, woz):
    if wiz <= 0.0 or woz <= 0.0:
        return 0.0
    return params[0] / math.pi * (wiz * woz) ** params[1]


@kernel
def pdf(params, wix, wiy, wiz, wox, woy, woz):
    if woz <= 0.0:
        return 0.0
    return (params[1] + 2.0) * woz ** (params[1] + 1.0) / (2.0 * math.pi)
