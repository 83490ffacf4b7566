"""The bottom packer: the BOTTOM record (kernel/records.py) and the bottom pool, the BRDF's
parameters and tables laid out by brdf_tables.py (which also runs the physical checks)."""
from __future__ import annotations

import numpy as np

from ..kernel import models
from ..kernel.records import BOTTOM, record
from . import brdf_tables


def pack(bottom) -> tuple[np.ndarray, np.ndarray]:
    """(BOTTOM record, its float pool: the BRDF's parameters from offset 0)."""
    model, params = brdf_tables.bottom_arrays(bottom)
    rec = record(BOTTOM, model=model,
                 reflects=int(model not in (models.BOTTOM_NONE, models.BOTTOM_BLACK)),
                 mirror=int(model == models.BOTTOM_SPECULAR), params=0)
    return rec, params
