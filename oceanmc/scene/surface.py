"""The air-water surface packer: the SURFACE record (kernel/records.py)."""
from __future__ import annotations

import numpy as np

from .. import config as cfg
from .. import registry
from ..kernel.records import SURFACE, record


def pack(surface: cfg.Surface, n_water: float) -> np.ndarray:
    return record(SURFACE, model=registry.surface_id(surface.model), n_water=float(n_water),
                  schlick=int(surface.fresnel == "schlick"))
