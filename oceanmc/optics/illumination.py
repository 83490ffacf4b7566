"""The illumination per wavelength: Ed(0+), its diffuse (sky) share and the sun's zenith angle."""
from __future__ import annotations

import numpy as np

from .. import config as cfg


def illumination_spectrum(config: cfg.SceneConfig) -> tuple[np.ndarray, np.ndarray, float]:
    """(Ed0 (n_wl,), diffuse_fraction (n_wl,), sun_zenith_deg)."""
    n_wl = len(config.wavelengths)
    light = config.illumination
    return (np.full(n_wl, float(light.Ed0)), np.full(n_wl, float(light.diffuse_fraction)),
            float(light.sun_zenith_deg))
