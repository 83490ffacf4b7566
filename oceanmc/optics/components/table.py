"""Measured IOPs from a user's CSV: columns wavelength_nm, a, b (1/m) and bb_ratio, linearly
interpolated in wavelength; a Fournier-Forand phase function with the tabulated bb/b."""
from __future__ import annotations

import numpy as np

from ...config import ConfigError
from ..tables import columns, interpolate, read_csv
from . import Contribution, fournier_forand_by_ratio

NEEDED = ("wavelength_nm", "a", "b", "bb_ratio")


def iops(component, wavelengths_nm: np.ndarray, where: str) -> Contribution:
    table = read_csv(component.file)
    columns(table, NEEDED, f"{where}.file", component.file)
    nodes = table["wavelength_nm"]
    if np.any(np.diff(nodes) <= 0.0):
        raise ConfigError(f"{where}.file: {component.file}: wavelength_nm must be strictly "
                          "increasing")
    for name in ("a", "b"):
        if np.any(table[name] < 0.0):
            raise ConfigError(f"{where}.file: {component.file}: column {name} has negative "
                              "values; allowed: >= 0 (1/m)")
    bad = (table["bb_ratio"] < 0.0005) | (table["bb_ratio"] > 0.45)
    if bad.any():
        raise ConfigError(f"{where}.file: {component.file}: bb_ratio = "
                          f"{table['bb_ratio'][bad][0]:g}; allowed: 0.0005 .. 0.45")
    what = f"{component.file}"
    a, b, ratio = (interpolate(wavelengths_nm, nodes, table[name], f"{where}.file", what)
                   for name in ("a", "b", "bb_ratio"))
    phases, weights = fournier_forand_by_ratio(ratio)
    return Contribution(a, b, phases, weights)
