"""The air-water surface packer: the SURFACE record (kernel/records.py)."""
from __future__ import annotations

import math

import numpy as np

from .. import config as cfg
from .. import registry
from ..kernel.records import SURFACE, record


def pack(surface: cfg.Surface, n_water: float) -> np.ndarray:
    if surface.model != "cox_munk":
        return record(SURFACE, model=registry.surface_id(surface.model), n_water=float(n_water),
                      schlick=int(surface.fresnel == "schlick"), delta=1, alpha_u=0.0,
                      alpha_c=0.0, wind_cos=1.0, wind_sin=0.0)
    upwind, crosswind = surface.slope_variances()
    azimuth = math.radians(surface.wind_direction_deg or 0.0)
    # Beckmann's alpha^2 is twice a slope component's variance (p ~ exp(-z^2 / alpha^2))
    return record(SURFACE, model=registry.surface_id(surface.model), n_water=float(n_water),
                  schlick=0, delta=0, alpha_u=math.sqrt(2.0 * upwind),
                  alpha_c=math.sqrt(2.0 * crosswind), wind_cos=math.cos(azimuth),
                  wind_sin=math.sin(azimuth))
