"""Given IOPs: a, b (one number or one per wavelength) and a phase function (isotropic unless
phase or bb_ratio, which makes it Fournier-Forand, is given), scaled by concentration."""
from __future__ import annotations

import numpy as np

from ...config import Isotropic
from . import Contribution, fournier_forand_by_ratio, per_wavelength


def iops(component, wavelengths_nm: np.ndarray, where: str) -> Contribution:
    n_wl = len(wavelengths_nm)
    a = component.concentration * per_wavelength(component.a, n_wl)
    b = component.concentration * per_wavelength(component.b, n_wl)
    if component.bb_ratio is not None:
        phases, weights = fournier_forand_by_ratio(per_wavelength(component.bb_ratio, n_wl))
    else:
        phases, weights = (component.phase or Isotropic(model="isotropic"),), np.ones((n_wl, 1))
    return Contribution(a, b, phases, weights)
