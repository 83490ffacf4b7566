"""Case-1 phytoplankton and the particles that covary with chlorophyll (Chl, mg/m3).

Absorption: a_ph(lambda) = A_phi(lambda) Chl^E_phi(lambda) (Bricaud et al. 1998, J. Geophys. Res.
103, 31033; the 2-nm table of A_phi, E_phi, 400-700 nm, in oceanmc/data).
Scattering: b_p(lambda) = 0.416 Chl^0.766 (550 / lambda) (Morel & Maritorena 2001, J. Geophys.
Res. 106, 7163, after Loisel & Morel 1998).
Backscatter fraction: bb_p/b_p = 0.002 + 0.01 (0.5 - 0.25 log10 Chl) (lambda / 550)^nu, with
nu = 0.5 (log10 Chl - 0.3) for Chl < 2 mg/m3 and nu = 0 above (Morel et al. 2002, Appl. Opt. 41,
6289), carried by a Fournier-Forand phase function with that bb/b (Mobley et al. 2002).
Only what is proportional to Chl's pigments is here: CDOM is a component of its own."""
from __future__ import annotations

import math

import numpy as np

from ..tables import interpolate, packaged
from . import Contribution, fournier_forand_by_ratio

BRICAUD = "chlorophyll_absorption_bricaud_1998.csv"


def absorption(chl: float, wavelengths_nm: np.ndarray, where: str) -> np.ndarray:
    table = packaged(BRICAUD)
    what = "phytoplankton absorption (Bricaud et al. 1998)"
    a_coef = interpolate(wavelengths_nm, table["wavelength_nm"], table["A_phi"], where, what)
    e_coef = np.interp(wavelengths_nm, table["wavelength_nm"], table["E_phi"])
    return a_coef * chl ** e_coef


def scattering(chl: float, wavelengths_nm: np.ndarray) -> np.ndarray:
    return 0.416 * chl ** 0.766 * (550.0 / wavelengths_nm)


def backscatter_ratio(chl: float, wavelengths_nm: np.ndarray) -> np.ndarray:
    log_chl = math.log10(chl)
    nu = 0.5 * (log_chl - 0.3) if chl < 2.0 else 0.0
    return 0.002 + 0.01 * (0.5 - 0.25 * log_chl) * (wavelengths_nm / 550.0) ** nu


def iops(component, wavelengths_nm: np.ndarray, where: str) -> Contribution:
    chl = float(component.chl_mg_m3)
    a = absorption(chl, wavelengths_nm, where)
    if chl <= 0.0:
        phases, weights = fournier_forand_by_ratio(np.full(len(wavelengths_nm), 0.0183))
        return Contribution(a, np.zeros_like(a), phases, weights)
    phases, weights = fournier_forand_by_ratio(backscatter_ratio(chl, wavelengths_nm))
    return Contribution(a, scattering(chl, wavelengths_nm), phases, weights)
