"""Constituents of the water: one module per model (registry.CONSTITUENT names them), each with

    iops(component, wavelengths_nm, where) -> Contribution

where component is the schema entry (config/components.py) with any depth profile already
evaluated to a number, wavelengths_nm the grid (n_wl,) and where the key path for error messages.
The layer's IOPs are the sums of its components' a and b, its phase function their b-weighted
mixture (column.py)."""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from importlib import import_module

import numpy as np

from ... import registry
from ...config.wavelengths import MAX_BB_RATIO, MIN_BB_RATIO


@dataclass(frozen=True)
class Contribution:
    a: np.ndarray          # (n_wl,) 1/m
    b: np.ndarray          # (n_wl,) 1/m
    phases: tuple          # schema phase configs
    weights: np.ndarray    # (n_wl, n_phases): share of this component's b by phase; rows sum to 1
    # (n_wl,) 1/m: the part of a absorbed by phytoplankton, which fluoresces
    # (optics/inelastic/); None: none
    a_phytoplankton: np.ndarray | None = None
    # (n_wl,) 1/m: the part of a absorbed by CDOM, which fluoresces; None: none
    a_cdom: np.ndarray | None = None


def per_wavelength(value, n_wl: int) -> np.ndarray:
    """A spectral key (one number or one per wavelength) as (n_wl,) values."""
    out = np.asarray(value if isinstance(value, list) else [value], dtype=np.float64)
    return np.full(n_wl, out[0]) if len(out) == 1 else out


def iops(component, wavelengths_nm: np.ndarray, where: str) -> Contribution:
    module = import_module(f"{__name__}.{registry.CONSTITUENT[component.model]}")
    return module.iops(component, wavelengths_nm, where)


def fournier_forand_by_ratio(ratios: np.ndarray) -> tuple[tuple, np.ndarray]:
    """(phases, weights) of Fournier-Forand phase functions with the backscatter fraction of each
    wavelength: one phase per distinct ratio (rounded to 4 significant digits, so that a smooth
    spectrum or a depth profile does not tabulate a new phase function at every wavelength and
    sublayer; the bb reported is b times the rounded ratio, what the kernel samples)."""
    clipped = np.clip(ratios, MIN_BB_RATIO, MAX_BB_RATIO)
    scale = 10.0 ** (3 - np.floor(np.log10(clipped)))
    rounded = np.round(clipped * scale) / scale
    distinct, column = np.unique(rounded, return_inverse=True)
    weights = np.zeros((len(rounded), len(distinct)))
    weights[np.arange(len(rounded)), column] = 1.0
    return tuple(_fournier_forand(float(r)) for r in distinct), weights


@lru_cache(maxsize=4096)
def _fournier_forand(bb_ratio: float):
    from ...config import FournierForand
    return FournierForand(model="fournier_forand", bb_ratio=bb_ratio)
