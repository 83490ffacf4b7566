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

An areal mixture (bottom.model: mixture) of components of one shape reflects the
fraction-weighted sum of their BRDFs, sum_k f_k R_k(l) g(i, o) with g the shared shape: the
bottom of that shape and reflectance spectrum sum_k f_k R_k(l) (the fractions add up to 1
within 1e-9; dividing by their sum keeps the mixture within 0 .. 1)."""
from __future__ import annotations

import numpy as np

from ..config import LambertianBottom, MinnaertBottom, ReflectanceSpectrum
from ..config.bottom import reflectance_keys
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
    """(n_wl,) the bottom's reflectance at each wavelength (a mixture's fraction-weighted), or
    None for a bottom whose reflectance cannot vary with wavelength."""
    keys = reflectance_keys(bottom)
    if not keys:
        return None
    values = [reflectance(value, wavelengths_nm, key) for key, value in keys]
    if bottom.model != "mixture":
        return values[0]
    fractions = np.array([c.fraction for c in bottom.components])
    return np.einsum("k,kj->j", fractions, np.array(values)) / fractions.sum()


def kernel_bottom(bottom, wavelengths_nm: np.ndarray):
    """(the bottom config the kernel runs, (n_wl,) bottom_q): one BRDF of reflectance R_max and
    each wavelength's share R_j / R_max of it (ones if R_max = 0, or for bottoms of one
    reflectance)."""
    n = len(wavelengths_nm)
    values = spectrum(bottom, wavelengths_nm)
    if values is None:
        return bottom, np.ones(n)
    top = float(values.max())
    shares = values / top if top > 0.0 else np.ones(n)
    if bottom.model == "mixture":
        first = bottom.components[0]
        shape = LambertianBottom(model="lambertian", reflectance=top, sampling=bottom.sampling) \
            if first.model == "lambertian" else \
            MinnaertBottom(model="minnaert", reflectance=top, k=first.k, sampling=bottom.sampling)
        return shape, shares
    return bottom.model_copy(update={"reflectance": top}), shares
