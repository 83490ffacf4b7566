"""The air-water surface packer: the SURFACE record (kernel/records.py)."""
from __future__ import annotations

import numpy as np

from .. import config as cfg
from ..kernel import models
from ..kernel.records import SURFACE, record

SURFACE_MODELS = {"none": models.SURFACE_NONE, "flat": models.SURFACE_FLAT}


def pack(surface: cfg.Surface, n_water: float) -> np.ndarray:
    return record(SURFACE, model=SURFACE_MODELS[surface.model], n_water=float(n_water),
                  schlick=int(surface.fresnel == "schlick"))
