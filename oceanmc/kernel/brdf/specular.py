"""A mirror of reflectance rho = params[0]: wo is wi mirrored about the normal, weight rho.
The BRDF is a delta function, so evaluate and pdf (densities) are 0 for every finite pair."""
from ..compile import kernel


@kernel
def sample(params, wix, wiy, wiz, u1, u2):
    return -wix, -wiy, wiz, params[0]


@kernel
def evaluate(params, wix, wiy, wiz, wox, woy, woz):
    return 0.0


@kernel
def pdf(params, wix, wiy, wiz, wox, woy, woz):
    return 0.0
