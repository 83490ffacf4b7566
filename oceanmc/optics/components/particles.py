"""Non-algal particles or minerals: a(lambda) = a443 exp(-slope (lambda - 443)) (Babin et al.
2003, J. Geophys. Res. 108, 3211), b(lambda) = b550 (550 / lambda)^exponent, a Fournier-Forand
phase function with the backscatter fraction bb_ratio; all scaled by concentration."""
from __future__ import annotations

import numpy as np

from . import Contribution, fournier_forand_by_ratio


def iops(component, wavelengths_nm: np.ndarray, where: str) -> Contribution:
    scale = component.concentration
    a = scale * component.a443 * np.exp(-component.slope * (wavelengths_nm - 443.0))
    b = scale * component.b550 * (550.0 / wavelengths_nm) ** component.exponent
    phases, weights = fournier_forand_by_ratio(np.full(len(wavelengths_nm), component.bb_ratio))
    return Contribution(a, b, phases, weights)
