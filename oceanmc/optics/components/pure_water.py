"""Pure (sea) water.

a_w: Pope & Fry (1997), Appl. Opt. 36, 8710 (380-727.5 nm); outside it Smith & Baker (1981),
Appl. Opt. 20, 177, Table 1 (200-800 nm). Both tables in oceanmc/data with their provenance.
b_w: pure sea water after Morel (1974), b_w = 0.00288 (lambda/500)^-4.32 1/m (the power law that
represents Morel's values; oceanmc/data/... README compares it with the printed table: within 1%
to 550 nm), and its phase function 0.06225 (1 + 0.835 cos^2) (Morel 1974), bb/b = 1/2."""
from __future__ import annotations

import numpy as np

from ...config import PureWater
from ..tables import interpolate, packaged
from . import Contribution

MOREL_B500 = 0.00288
MOREL_EXPONENT = 4.32


def absorption(wavelengths_nm: np.ndarray, where: str) -> np.ndarray:
    pope = packaged("pure_water_absorption_pope_fry_1997.csv")
    smith = packaged("pure_water_absorption_smith_baker_1981.csv")
    nodes = pope["wavelength_nm"]
    inside = (wavelengths_nm >= nodes[0]) & (wavelengths_nm <= nodes[-1])
    out = interpolate(wavelengths_nm, smith["wavelength_nm"], smith["a_w_per_m"], where,
                      "pure-water absorption (Smith & Baker 1981)") if not inside.all() \
        else np.empty_like(wavelengths_nm)
    out[inside] = np.interp(wavelengths_nm[inside], nodes, pope["a_w_per_m"])
    return out


def scattering(wavelengths_nm: np.ndarray) -> np.ndarray:
    return MOREL_B500 * (wavelengths_nm / 500.0) ** -MOREL_EXPONENT


def iops(component, wavelengths_nm: np.ndarray, where: str) -> Contribution:
    return Contribution(absorption(wavelengths_nm, where), scattering(wavelengths_nm),
                        (PureWater(model="pure_water"),), np.ones((len(wavelengths_nm), 1)))
