"""The bottom's reflectance per wavelength, and the one BRDF the kernel samples for every
wavelength.

A bottom reflectance that varies with wavelength (bottom.reflectance of lambertian, minnaert and
specular bottoms: one number, one per wavelength, or a CSV spectrum; config/bottom.py) keeps the
BRDF's angular shape, which depends on k alone for Minnaert ((rho/pi)(cos t_i cos t_r)^k,
kernel/brdf/minnaert.py) and on nothing for Lambertian (rho/pi) and the mirror. So the bottom
is packed as the BRDF of the largest reflectance R_max over the run's wavelengths, and
wavelength j gets the share R_j / R_max <= 1 of it (GRID bottom_q): the spectral walk
multiplies wavelength j's weight by it at each reflection and in the local estimates from the
bottom (kernel/spectral.py reflect, bottom_weights), which is exactly the BRDF of reflectance R_j
at wavelength j, and no weight grows. A one-wavelength run packs R itself.

The albedo_scale of ggx, hapke and table bottoms (f times it) is packed the same way: the BRDF
at the largest scale s_max, and wavelength j's share s_j / s_max. rho_dh <= 1 of the packed BRDF
(scene/brdf_tables.py) is then rho_dh <= 1 at every wavelength, as rho_dh is linear in the
scale; the analog walk, which needs the packed weight <= 1, is refused for a GGX of s_max > 1
(config/bottom.py bottom_weight_bounded).

A lambertian_specular bottom changes its angular shape with wavelength (its two lobes'
shares): see _lambertian_specular.

An areal mixture (bottom.model: mixture) of components of one shape reflects the
fraction-weighted sum of their BRDFs, sum_k f_k R_k(l) g(i, o) with g the shared shape: the
bottom of that shape and reflectance spectrum sum_k f_k R_k(l) (the fractions add up to 1
within 1e-9; dividing by their sum keeps the mixture within 0 .. 1)."""
from __future__ import annotations

import math

import numpy as np

from ..config import LambertianBottom, MinnaertBottom, ReflectanceSpectrum
from ..config import ConfigError
from ..config.bottom import SCALED_MODELS, reflectance_keys
from ..config.wavelengths import MAX_WAVELENGTH_NM, MIN_WAVELENGTH_NM
from .components import per_wavelength
from .tables import interpolate, read_table

# a spectrum file's columns and their ranges: those of wavelengths_nm, and a reflectance
COLUMNS = {"wavelength_nm": (MIN_WAVELENGTH_NM, MAX_WAVELENGTH_NM, "nm"),
           "reflectance": (0.0, 1.0, "")}


def reflectance(value, wavelengths_nm: np.ndarray, where: str) -> np.ndarray:
    """(n_wl,) reflectances of one reflectance key: a number, a list (one per wavelength) or a
    spectrum file read and interpolated linearly to the wavelengths, which must lie within its
    range (as for the water's component tables)."""
    if isinstance(value, ReflectanceSpectrum):
        table = read_table(value.file, f"{where}.file", COLUMNS)
        return interpolate(wavelengths_nm, table["wavelength_nm"], table["reflectance"],
                           f"{where}.file", value.file)
    return per_wavelength(value, len(wavelengths_nm))


def spectrum(bottom, wavelengths_nm: np.ndarray) -> np.ndarray | None:
    """(n_wl,) the bottom's reflectance at each wavelength (a mixture's fraction-weighted, a
    lambertian_specular bottom's diffuse plus specular part: its rho_dh at every incidence), or
    None for a bottom without one (black, none; ggx, hapke and table, whose rho_dh depends on
    the incidence: their albedo_scale is in the stored config)."""
    keys = reflectance_keys(bottom)
    if not keys or bottom.model in SCALED_MODELS:
        return None
    values = [reflectance(value, wavelengths_nm, key) for key, value in keys]
    if bottom.model == "lambertian_specular":
        return values[0] + values[1]
    if bottom.model != "mixture":
        return values[0]
    fractions = np.array([c.fraction for c in bottom.components])
    return np.einsum("k,kj->j", fractions, np.array(values)) / fractions.sum()


def _shares(values: np.ndarray, packed: float) -> np.ndarray:
    return values / packed if packed > 0.0 else np.ones(len(values))


def _lambertian_specular(bottom, wavelengths_nm: np.ndarray):
    """Diffuse d_j and mirror s_j parts: the kernel samples the mirror with probability
    S / (D + S) from the packed parts and weighs either lobe D + S; wavelength j takes the
    sampled lobe's share, d_j / D or s_j / S (GRID bottom_q's two rows; kernel/spectral.py
    reflect), so its expected reflection is d_j + s_j in the direction of each lobe. The parts
    are packed at the largest of each (D, S: shares <= 1), scaled down to D + S = 1 where their
    sum would exceed 1 while no wavelength's d_j + s_j does (so the analog walk's survival
    probability D + S stays a probability; some shares exceed 1 then; with allow_unphysical,
    down to the largest d_j + s_j). One wavelength, or parts that do not vary with it, pack
    the parts themselves with shares 1."""
    where = "bottom"
    d = reflectance(bottom.diffuse_reflectance, wavelengths_nm, f"{where}.diffuse_reflectance")
    s = reflectance(bottom.specular_reflectance, wavelengths_nm,
                    f"{where}.specular_reflectance")
    rho = d + s
    if not bottom.allow_unphysical and rho.max() > 1.0:
        j = int(np.argmax(rho))
        # (a monochromatic scene's grid is [nan]: no wavelength to name)
        at = "" if np.isnan(wavelengths_nm[j]) else f" at {wavelengths_nm[j]:g} nm"
        raise ConfigError(
            f"bottom.model = 'lambertian_specular': not energy conserving{at}: "
            f"diffuse_reflectance + specular_reflectance = "
            f"{d[j]:g} + {s[j]:g} = {rho[j]:g} > 1 (rho_dh at every incidence angle); set "
            "bottom.allow_unphysical: true to run it anyway")
    top_d, top_s = float(d.max()), float(s.max())
    target = max(1.0, float(rho.max()))
    if top_d + top_s > target:
        top_d *= target / (top_d + top_s)
        top_s = target - top_d
        while top_d + top_s > target:   # the sum's rounding
            top_s = math.nextafter(top_s, 0.0)
    shape = bottom.model_copy(update={"diffuse_reflectance": top_d,
                                      "specular_reflectance": top_s})
    return shape, np.stack([_shares(d, top_d), _shares(s, top_s)])


def kernel_bottom(bottom, wavelengths_nm: np.ndarray):
    """(the bottom config the kernel runs, (2, n_wl) bottom_q): one BRDF of reflectance R_max
    (albedo scale s_max for ggx, hapke and table) and each wavelength's share R_j / R_max of
    it (ones if R_max = 0, or for bottoms of one reflectance); row 1 is the share when the
    mirror lobe of a lambertian_specular bottom was sampled (row 0 for every other bottom)."""
    n = len(wavelengths_nm)
    if bottom.model == "lambertian_specular":
        return _lambertian_specular(bottom, wavelengths_nm)
    keys = reflectance_keys(bottom)
    if not keys:
        return bottom, np.ones((2, n))
    if bottom.model == "mixture":
        values = spectrum(bottom, wavelengths_nm)
    else:
        values = reflectance(keys[0][1], wavelengths_nm, keys[0][0])
    top = float(values.max())
    shares = np.tile(_shares(values, top), (2, 1))
    if bottom.model == "mixture":
        first = bottom.components[0]
        shape = LambertianBottom(model="lambertian", reflectance=top, sampling=bottom.sampling) \
            if first.model == "lambertian" else \
            MinnaertBottom(model="minnaert", reflectance=top, k=first.k, sampling=bottom.sampling)
        return shape, shares
    key = "albedo_scale" if bottom.model in SCALED_MODELS else "reflectance"
    return bottom.model_copy(update={key: top}), shares
