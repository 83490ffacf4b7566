"""Bottom reflection by model id, and the frame change between the kernel's global frame
(z down) and the BRDF's local frame (normal along +z, pointing up into the water)."""
from numba import njit

from ..models import BOTTOM_LAMBERTIAN, BOTTOM_MINNAERT, BOTTOM_SPECULAR
from . import lambertian, minnaert, specular


@njit(error_model="numpy", cache=True, inline="always")
def sample_local(model, params, wix, wiy, wiz, u1, u2):
    if model == BOTTOM_LAMBERTIAN:
        return lambertian.sample(params, wix, wiy, wiz, u1, u2)
    if model == BOTTOM_MINNAERT:
        return minnaert.sample(params, wix, wiy, wiz, u1, u2)
    if model == BOTTOM_SPECULAR:
        return specular.sample(params, wix, wiy, wiz, u1, u2)
    return 0.0, 0.0, 1.0, 0.0  # black


@njit(error_model="numpy", cache=True, inline="always")
def evaluate_local(model, params, wix, wiy, wiz, wox, woy, woz):
    if model == BOTTOM_LAMBERTIAN:
        return lambertian.evaluate(params, wix, wiy, wiz, wox, woy, woz)
    if model == BOTTOM_MINNAERT:
        return minnaert.evaluate(params, wix, wiy, wiz, wox, woy, woz)
    if model == BOTTOM_SPECULAR:
        return specular.evaluate(params, wix, wiy, wiz, wox, woy, woz)
    return 0.0


@njit(error_model="numpy", cache=True, inline="always")
def pdf_local(model, params, wix, wiy, wiz, wox, woy, woz):
    if model == BOTTOM_LAMBERTIAN:
        return lambertian.pdf(params, wix, wiy, wiz, wox, woy, woz)
    if model == BOTTOM_MINNAERT:
        return minnaert.pdf(params, wix, wiy, wiz, wox, woy, woz)
    if model == BOTTOM_SPECULAR:
        return specular.pdf(params, wix, wiy, wiz, wox, woy, woz)
    return 0.0


@njit(error_model="numpy", cache=True, inline="always")
def reflect(model, params, ux, uy, uz, u1, u2):
    """A photon travelling (ux, uy, uz), uz > 0, meets the bottom: returns the reflected travel
    direction (upward) and the weight factor. Local frame = (x, -y, -z) of the global one (a
    rotation by pi about x, so handedness is kept); wi is minus the local travel direction."""
    wox, woy, woz, weight = sample_local(model, params, -ux, uy, uz, u1, u2)
    return wox, -woy, -woz, weight
