"""Measured IOPs from a user's CSV: columns wavelength_nm, a, b (1/m) and bb_ratio, linearly
interpolated in wavelength; a Fournier-Forand phase function with the tabulated bb/b."""
from __future__ import annotations

import numpy as np

from ...config.base import MAX_COEFFICIENT
from ...config.wavelengths import MAX_BB_RATIO, MAX_WAVELENGTH_NM, MIN_BB_RATIO, MIN_WAVELENGTH_NM
from ..tables import interpolate, read_table
from . import Contribution, fournier_forand_by_ratio

# the columns and their ranges: those of wavelengths_nm and of a layer's a, b and bb_ratio
COLUMNS = {"wavelength_nm": (MIN_WAVELENGTH_NM, MAX_WAVELENGTH_NM, "nm"),
           "a": (0.0, MAX_COEFFICIENT, "1/m"), "b": (0.0, MAX_COEFFICIENT, "1/m"),
           "bb_ratio": (MIN_BB_RATIO, MAX_BB_RATIO, "")}


def iops(component, wavelengths_nm: np.ndarray, where: str) -> Contribution:
    table = read_table(component.file, f"{where}.file", COLUMNS)
    a, b, ratio = (interpolate(wavelengths_nm, table["wavelength_nm"], table[name],
                               f"{where}.file", component.file) for name in ("a", "b", "bb_ratio"))
    phases, weights = fournier_forand_by_ratio(ratio)
    return Contribution(a, b, phases, weights)
