"""f = rho/pi; cosine-weighted sampling theta_o = acos(sqrt(u1)), phi uniform; weight = rho."""
import math

from ..compile import kernel
from ..geometry import from_angles


@kernel
def sample(params, wix, wiy, wiz, u1, u2):
    wox, woy, woz = from_angles(math.sqrt(u1), 2.0 * math.pi * u2)
    return wox, woy, woz, params[0]


@kernel
def evaluate(params, wix, wiy, wiz, wox, woy, woz):
    if wiz <= 0.0 or woz <= 0.0:
        return 0.0
    return params[0] / math.pi


@kernel
def pdf(params, wix, wiy, wiz, wox, woy, woz):
    return max(0.0, woz) / math.pi
