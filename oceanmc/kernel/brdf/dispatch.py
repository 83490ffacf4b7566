"""Bottom reflection by model id, and the frame change between the kernel's global frame
(z down) and the BRDF's local frame (normal along +z, pointing up into the water).

A model whose parameter array asks for it (params[BRDF_SAMPLER] = 1: Hapke, measured tables, or
any model with `sampling: tabulated`) is sampled by the general tabulated sampler (general.py)
and weighted f cos / pdf with its own evaluate(); the others use their own exact samplers. The
length check on params keeps short parameter arrays (tests) on the models' own samplers."""
from ..compile import kernel
from ..models import (BOTTOM_GGX, BOTTOM_HAPKE, BOTTOM_LAMBERTIAN, BOTTOM_LAMBERTIAN_SPECULAR,
                      BOTTOM_MINNAERT, BOTTOM_SPECULAR, BOTTOM_TABLE, BRDF_SAMPLER)
from . import general, ggx, hapke, lambertian, lambertian_specular, minnaert, specular, table


@kernel
def tabulated_sampler(params):
    return params.shape[0] > BRDF_SAMPLER and params[BRDF_SAMPLER] > 0.0


@kernel
def evaluate_local(model, params, wix, wiy, wiz, wox, woy, woz, with_detailed_bottom=True):
    """f(wi, wo) in 1/sr; for models with a mirror component only the finite part (local
    estimates miss the mirror: config/scene.py refuses them for such bottoms).
    with_detailed_bottom None: the closed-form four only (kernel/variants.py; the photon loop
    passes its own, True elsewhere)."""
    if model == BOTTOM_LAMBERTIAN:
        return lambertian.evaluate(params, wix, wiy, wiz, wox, woy, woz)
    if model == BOTTOM_MINNAERT:
        return minnaert.evaluate(params, wix, wiy, wiz, wox, woy, woz)
    if model == BOTTOM_SPECULAR:
        return specular.evaluate(params, wix, wiy, wiz, wox, woy, woz)
    if model == BOTTOM_LAMBERTIAN_SPECULAR:
        return lambertian_specular.evaluate(params, wix, wiy, wiz, wox, woy, woz)
    if with_detailed_bottom is None:
        return 0.0
    if model == BOTTOM_GGX:
        return ggx.evaluate(params, wix, wiy, wiz, wox, woy, woz)
    if model == BOTTOM_HAPKE:
        return hapke.evaluate(params, wix, wiy, wiz, wox, woy, woz)
    if model == BOTTOM_TABLE:
        return table.evaluate(params, wix, wiy, wiz, wox, woy, woz)
    return 0.0


@kernel
def sample_local(model, params, wix, wiy, wiz, u1, u2, with_detailed_bottom=True):
    """(wox, woy, woz, weight) with weight = f cos(theta_o) / pdf (with_detailed_bottom as
    evaluate_local's)."""
    if with_detailed_bottom is not None and tabulated_sampler(params):
        wox, woy, woz, dens = general.sample(params, wix, wiy, wiz, u1, u2)
        if dens <= 0.0:
            return wox, woy, woz, 0.0
        return wox, woy, woz, evaluate_local(model, params, wix, wiy, wiz, wox, woy, woz) / dens
    if model == BOTTOM_LAMBERTIAN:
        return lambertian.sample(params, wix, wiy, wiz, u1, u2)
    if model == BOTTOM_MINNAERT:
        return minnaert.sample(params, wix, wiy, wiz, u1, u2)
    if model == BOTTOM_SPECULAR:
        return specular.sample(params, wix, wiy, wiz, u1, u2)
    if model == BOTTOM_LAMBERTIAN_SPECULAR:
        return lambertian_specular.sample(params, wix, wiy, wiz, u1, u2)
    if with_detailed_bottom is not None and model == BOTTOM_GGX:
        return ggx.sample(params, wix, wiy, wiz, u1, u2)
    return 0.0, 0.0, 1.0, 0.0  # black (Hapke and tables always use the tabulated sampler)


@kernel
def pdf_local(model, params, wix, wiy, wiz, wox, woy, woz):
    """Density (1/sr) of the sampler in use; for a mirror component only its finite part."""
    if tabulated_sampler(params):
        return general.pdf(params, wix, wiy, wiz, wox, woy, woz)
    if model == BOTTOM_LAMBERTIAN:
        return lambertian.pdf(params, wix, wiy, wiz, wox, woy, woz)
    if model == BOTTOM_MINNAERT:
        return minnaert.pdf(params, wix, wiy, wiz, wox, woy, woz)
    if model == BOTTOM_SPECULAR:
        return specular.pdf(params, wix, wiy, wiz, wox, woy, woz)
    if model == BOTTOM_LAMBERTIAN_SPECULAR:
        return lambertian_specular.pdf(params, wix, wiy, wiz, wox, woy, woz)
    if model == BOTTOM_GGX:
        return ggx.pdf(params, wix, wiy, wiz, wox, woy, woz)
    return 0.0


@kernel
def sampled_mirror(model, params, u1):
    """Whether reflect(model, params, ..., u1, u2) takes the mirror lobe of a Lambertian +
    mirror bottom (whose lobes' shares may differ per wavelength: kernel/spectral.py reflect);
    False for every other model."""
    if model == BOTTOM_LAMBERTIAN_SPECULAR:
        return lambertian_specular.mirror_sampled(params, u1)
    return False


@kernel
def reflect(model, params, ux, uy, uz, u1, u2, with_detailed_bottom=True):
    """A photon travelling (ux, uy, uz), uz > 0, meets the bottom: returns the reflected travel
    direction (upward) and the weight factor. Local frame = (x, -y, -z) of the global one (a
    rotation by pi about x, so handedness is kept); wi is minus the local travel direction.
    (with_detailed_bottom as evaluate_local's.)"""
    wox, woy, woz, weight = sample_local(model, params, -ux, uy, uz, u1, u2,
                                         with_detailed_bottom)
    return wox, -woy, -woz, weight
