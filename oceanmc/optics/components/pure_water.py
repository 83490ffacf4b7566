"""Pure (sea) water.

a_w: the IOCCG Protocols (2018)'s recommended spectrum, 180-1230 nm: Pope & Fry (1997), Appl.
Opt. 36, 8710, from 420 to 727.5 nm (at its 2.5 nm resolution); below, Morel et al. (2007),
Limnol. Oceanogr. 52, 217, Table 2a (345-415 nm) and Jonasz & Fournier (2007) (180-340 nm);
above, Kou et al. (1993), Appl. Opt. 32, 3531. Both tables in oceanmc/data with their
provenance; or the user's own (absorption_file, user_absorption). (Until 2026-11-29 Smith &
Baker (1981) below 380 nm, whose clearest natural waters absorb 2-7x more in the ultraviolet
and met Pope & Fry with a step of 2.6x, 0.030 1/m at 370 nm to 0.0114 at 380 nm: the Raman
light at 400-430 nm, excited at 345-375 nm, was too weak.)
b_w: pure sea water after Morel (1974), b_w = 0.00288 (lambda/500)^-4.32 1/m (the power law that
represents Morel's values; oceanmc/data/... README compares it with the printed table: within 1%
to 550 nm), and its phase function 0.06225 (1 + 0.835 cos^2) (Morel 1974), bb/b = 1/2."""
from __future__ import annotations

import numpy as np

from ...config import PureWater
from ...config.base import MAX_COEFFICIENT
from ...config.wavelengths import MAX_WAVELENGTH_NM, MIN_WAVELENGTH_NM
from ..tables import interpolate, packaged, read_table
from . import Contribution

MOREL_B500 = 0.00288
MOREL_EXPONENT = 4.32


# where the IOCCG (2018) spectrum takes Pope & Fry (1997) up (below it Morel et al. 2007, whose
# 380-415 nm values are 0.5-1x Pope & Fry's and meet them here)
POPE_FRY_FROM_NM = 420.0


def absorption(wavelengths_nm: np.ndarray, where: str) -> np.ndarray:
    pope = packaged("pure_water_absorption_pope_fry_1997.csv")
    beside = packaged("pure_water_absorption_ioccg_2018.csv")
    pope_nodes, beside_nodes = pope["wavelength_nm"], beside["wavelength_nm"]
    used = pope_nodes >= POPE_FRY_FROM_NM
    below = beside_nodes < POPE_FRY_FROM_NM
    above = beside_nodes > pope_nodes[-1]
    nodes = np.concatenate([beside_nodes[below], pope_nodes[used], beside_nodes[above]])
    values = np.concatenate([beside["a_w_per_m"][below], pope["a_w_per_m"][used],
                             beside["a_w_per_m"][above]])
    return interpolate(wavelengths_nm, nodes, values, where,
                       "pure-water absorption (IOCCG 2018, Pope & Fry 1997 at 420-727.5 nm)")


# the columns of a user's absorption_file and their ranges
USER_COLUMNS = {"wavelength_nm": (MIN_WAVELENGTH_NM, MAX_WAVELENGTH_NM, "nm"),
                "a": (0.0, MAX_COEFFICIENT, "1/m")}


def user_absorption(path: str, wavelengths_nm: np.ndarray, where: str) -> np.ndarray:
    """a_w from the user's CSV (absorption_file), linearly interpolated; every traced wavelength
    inside its range."""
    key = f"{where}.absorption_file"
    table = read_table(path, key, USER_COLUMNS, rows=2)
    return interpolate(wavelengths_nm, table["wavelength_nm"], table["a"], key, path)


def scattering(wavelengths_nm: np.ndarray) -> np.ndarray:
    return MOREL_B500 * (wavelengths_nm / 500.0) ** -MOREL_EXPONENT


def iops(component, wavelengths_nm: np.ndarray, where: str) -> Contribution:
    a = (absorption(wavelengths_nm, where) if component.absorption_file is None
         else user_absorption(component.absorption_file, wavelengths_nm, where))
    return Contribution(a, scattering(wavelengths_nm),
                        (PureWater(model="pure_water"),), np.ones((len(wavelengths_nm), 1)))
