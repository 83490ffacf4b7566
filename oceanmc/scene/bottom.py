"""The bottom packer: the BOTTOM record (kernel/records.py) and the bottom pool, the BRDF's
parameters and tables laid out by brdf_tables.py (which also runs the physical checks), and each
wavelength's share of the packed BRDF's reflectance (optics/bottom.py)."""
from __future__ import annotations

import numpy as np

from ..kernel import models
from ..optics.bottom import kernel_bottom
from ..kernel.records import BOTTOM, record
from . import brdf_tables


def pack(bottom, wavelengths_nm: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(BOTTOM record, its float pool: the BRDF's parameters from offset 0, and (2, n_wl) each
    wavelength's share of the packed BRDF's reflectance, row 1 that of a lambertian_specular
    bottom's mirror lobe: GRID bottom_q)."""
    bottom, shares = kernel_bottom(bottom, wavelengths_nm)
    model, params = brdf_tables.bottom_arrays(bottom)
    rec = record(BOTTOM, model=model,
                 reflects=int(model not in (models.BOTTOM_NONE, models.BOTTOM_BLACK)),
                 mirror=int(model == models.BOTTOM_SPECULAR), params=0)
    return rec, params, shares
