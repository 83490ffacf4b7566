"""Coloured dissolved organic matter: a_g(lambda) = a440 exp(-slope (lambda - 440)) (Bricaud,
Morel & Prieur 1981, Limnol. Oceanogr. 26, 43); dissolved, so it does not scatter. All of it may
fluoresce (optics/inelastic/cdom_fluorescence.py)."""
from __future__ import annotations

import numpy as np

from ...config import Isotropic
from . import Contribution


def iops(component, wavelengths_nm: np.ndarray, where: str) -> Contribution:
    a = component.a440 * np.exp(-component.slope * (wavelengths_nm - 440.0))
    return Contribution(a, np.zeros_like(a), (Isotropic(model="isotropic"),),
                        np.ones((len(wavelengths_nm), 1)), a_cdom=a)
