"""The water column's inherent optical properties per layer and wavelength: what the medium
packer (scene/medium.py) turns into the kernel's record and what the results' `iops` group shows."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import config as cfg
from ..config.water import values
from .phases import backscatter_fraction


def wavelengths(config: cfg.SceneConfig) -> np.ndarray:
    """(n_wl,) nm; a monochromatic scene (no wavelengths_nm) has one entry, NaN."""
    return config.wavelengths


@dataclass(frozen=True)
class LayerIOPs:
    """One homogeneous layer of the column. A depth profile is resolved into several of these
    (sublayers), each naming the configured layer it belongs to (config_layer)."""
    top_m: float
    thickness_m: float          # may be inf for the last layer
    a: np.ndarray               # (n_wl,) absorption, 1/m
    b: np.ndarray               # (n_wl,) scattering, 1/m
    bb: np.ndarray              # (n_wl,) backscattering, 1/m
    phases: tuple               # schema phase configs (config/phase.py), none of them a mixture
    weights: np.ndarray         # (n_wl, n_phases): share of b scattered by each phase; rows sum
    #                             to 1 (a wavelength that does not scatter: any valid row)
    config_layer: int           # index in config.water.layers

    @property
    def c(self) -> np.ndarray:
        return self.a + self.b


def _per_wavelength(value, n_wl: int) -> np.ndarray:
    out = np.asarray(values(value), dtype=np.float64)
    return np.full(n_wl, out[0]) if len(out) == 1 else out


def _phases(layer: cfg.Layer, n_wl: int) -> tuple[tuple, np.ndarray]:
    """(phases, weights) of a layer given by a, b and phase (or bb_ratio)."""
    if layer.bb_ratio is not None:
        ratios = _per_wavelength(layer.bb_ratio, n_wl)
        distinct = sorted(set(ratios.tolist()))
        phases = tuple(cfg.FournierForand(model="fournier_forand", bb_ratio=r) for r in distinct)
        weights = np.zeros((n_wl, len(distinct)))
        weights[np.arange(n_wl), [distinct.index(r) for r in ratios]] = 1.0
        return phases, weights
    if isinstance(layer.phase, cfg.Mixture):
        parts = layer.phase.components
        shares = np.array([c.b for c in parts], dtype=np.float64)
        total = shares.sum()
        shares = shares / total if total > 0.0 else np.full(len(parts), 1.0 / len(parts))
        return tuple(c.phase for c in parts), np.tile(shares, (n_wl, 1))
    return (layer.phase,), np.ones((n_wl, 1))


def column_iops(config: cfg.SceneConfig) -> list[LayerIOPs]:
    """The layers top to bottom, each homogeneous; the last may be infinitely deep."""
    n_wl = len(config.wavelengths)
    out = []
    top = 0.0
    for index, layer in enumerate(config.water.layers):
        a = _per_wavelength(layer.a, n_wl)
        b = _per_wavelength(layer.b, n_wl)
        phases, weights = _phases(layer, n_wl)
        bb = b * (weights @ np.array([backscatter_fraction(p) for p in phases]))
        out.append(LayerIOPs(top, layer.thickness_m, a, b, bb, phases, weights, index))
        top += layer.thickness_m
    return out
