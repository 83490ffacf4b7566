"""The water column's inherent optical properties per layer and wavelength: what the medium
packer (scene/medium.py) turns into the kernel's record and what the results' `iops` group shows.

A layer is given either by a, b and phase (numbers or one per wavelength) or by its components
(constituents; components/). A component whose amount follows a depth profile (profiles.py) makes
the layer continuously varying; it is resolved into homogeneous sublayers, each with the IOPs of
the profile's exact mean amount over it, halved until replacing the continuous attenuation c(z)
by the sublayer's c moves the optical depth from the sublayer's top to any depth inside it by at
most OPTICAL_DEPTH_TOLERANCE, at every wavelength (the integral of the difference by the
trapezoidal rule on 9 depths per sublayer; sublayers are also cut at the profile's nodes). At
sublayer boundaries the optical depth is exact for constituents linear in their amount (cdom,
particles, constant) and within the tolerance for chlorophyll and case1, so the error never
accumulates beyond one sublayer's for them. tests/test_optics_profiles.py checks the bound
against a finer layering."""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from .. import config as cfg
from ..config import ConfigError
from ..config.components import PROFILE_KEYS
from . import inelastic, profiles
from .components import Contribution, fournier_forand_by_ratio, iops, per_wavelength
from .phases import backscatter_fraction

OPTICAL_DEPTH_TOLERANCE = 0.001
MAX_SUBLAYERS = 5000
CHECK_POINTS = 9


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
    a_phytoplankton: np.ndarray | None = None   # (n_wl,) the part of a that may fluoresce
    a_cdom: np.ndarray | None = None            # (n_wl,) CDOM's part of a, which may fluoresce

    @property
    def c(self) -> np.ndarray:
        return self.a + self.b


def mix(parts: list[Contribution]) -> Contribution:
    """The sum of several constituents: a and b add, the phase function is the b-weighted
    mixture (identical phase functions merged)."""
    a = np.sum([p.a for p in parts], axis=0)
    b = np.sum([p.b for p in parts], axis=0)
    phases: list = []
    columns: list[np.ndarray] = []
    fallback: list[np.ndarray] = []     # the first component's rows, where nothing scatters
    seen: dict[str, int] = {}           # repr of a phase config -> its column
    for k, part in enumerate(parts):
        for j, phase in enumerate(part.phases):
            share = np.divide(part.b * part.weights[:, j], b, out=np.zeros_like(b),
                              where=b > 0.0)
            first = part.weights[:, j] if k == 0 else np.zeros_like(b)
            at = seen.get(repr(phase))
            if at is None:
                seen[repr(phase)] = len(phases)
                phases.append(phase)
                columns.append(share)
                fallback.append(first)
            else:
                columns[at] = columns[at] + share
                fallback[at] = fallback[at] + first
    weights = np.stack(columns, axis=1)
    empty = b <= 0.0
    weights[empty] = np.stack(fallback, axis=1)[empty]
    return Contribution(a, b, tuple(phases), weights, _sum_of(parts, "a_phytoplankton"),
                        _sum_of(parts, "a_cdom"))


def _sum_of(parts: list[Contribution], name: str) -> np.ndarray | None:
    """The sum of the parts' absorption `name` (a_phytoplankton, a_cdom), None if none has it."""
    given = [getattr(p, name) for p in parts if getattr(p, name) is not None]
    return np.sum(given, axis=0) if given else None


def _layer(part: Contribution, top: float, thickness: float, index: int) -> LayerIOPs:
    fractions = np.array([backscatter_fraction(p) for p in part.phases])
    # (numpy's own sum, not BLAS's, whose result depends on its threads: inelastic transfer)
    return LayerIOPs(top, thickness, part.a, part.b,
                     part.b * np.einsum("...k,k->...", part.weights, fractions),
                     part.phases, part.weights, index, part.a_phytoplankton, part.a_cdom)


def _given(layer: cfg.Layer, n_wl: int) -> Contribution:
    """A layer given by a, b and phase (or bb_ratio)."""
    a, b = per_wavelength(layer.a, n_wl), per_wavelength(layer.b, n_wl)
    if layer.bb_ratio is not None:
        return Contribution(a, b, *fournier_forand_by_ratio(per_wavelength(layer.bb_ratio, n_wl)))
    if isinstance(layer.phase, cfg.Mixture):
        parts = layer.phase.components
        shares = np.array([c.b for c in parts], dtype=np.float64)
        total = shares.sum()
        shares = shares / total if total > 0.0 else np.full(len(parts), 1.0 / len(parts))
        return Contribution(a, b, tuple(c.phase for c in parts), np.tile(shares, (n_wl, 1)))
    return Contribution(a, b, (layer.phase,), np.ones((n_wl, 1)))


class _Constituents:
    """A layer's components, with the profiled amounts evaluated at a depth or over a range."""

    def __init__(self, layer: cfg.Layer, wl: np.ndarray, where: str):
        self.wl = wl
        self.components = layer.components
        self.where = [f"{where}.components[{k}]" for k in range(len(layer.components))]
        self.profiled = [(k, key, getattr(comp, key)) for k, comp in enumerate(self.components)
                         for key in PROFILE_KEYS[comp.model]
                         if not isinstance(getattr(comp, key), (int, float))]
        # the IOPs of a component without a depth profile, the same at every depth: once, not
        # at each of a profile's sublayers and check points (pure water and CDOM took half of
        # configs/deep_chlorophyll_maximum.yaml's 2,841 evaluations)
        varying = {k for k, _, _ in self.profiled}
        self.fixed = {k: iops(comp, wl, self.where[k]) for k, comp in enumerate(self.components)
                      if k not in varying}

    def parts(self, amounts: dict) -> list[Contribution]:
        out = []
        for k, comp in enumerate(self.components):
            if k in self.fixed:
                out.append(self.fixed[k])
                continue
            update = {key: v for (kk, key), v in amounts.items() if kk == k}
            out.append(iops(comp.model_copy(update=update) if update else comp, self.wl,
                            self.where[k]))
        return out

    def iops(self, amounts: dict) -> Contribution:
        return mix(self.parts(amounts))

    def amounts_at(self, z: float) -> dict:
        return {(k, key): float(profiles.value_at(p, np.array([z]), f"{self.where[k]}.{key}")[0])
                for k, key, p in self.profiled}

    def at(self, z: float) -> Contribution:
        return self.iops(self.amounts_at(z))

    def attenuation_at(self, z: float) -> np.ndarray:
        return np.sum([p.a + p.b for p in self.parts(self.amounts_at(z))], axis=0)

    def over(self, top: float, bottom: float) -> Contribution:
        return self.iops({(k, key): profiles.mean(p, top, bottom, f"{self.where[k]}.{key}")
                          for k, key, p in self.profiled})

    def breakpoints(self, top: float, bottom: float) -> np.ndarray:
        points = [profiles.breakpoints(p, f"{self.where[k]}.{key}")
                  for k, key, p in self.profiled]
        points = np.concatenate(points) if points else np.zeros(0)
        return np.unique(points[(points > top) & (points < bottom)])

    def constant_below(self) -> float:
        return max(profiles.constant_below(p, f"{self.where[k]}.{key}")
                   for k, key, p in self.profiled)

    def step(self) -> tuple[float, str]:
        """The profiles' shortest length scale (m) and the key of the profile that has it."""
        return min((profiles.length_scale(p, f"{self.where[k]}.{key}"), f"{self.where[k]}.{key}")
                   for k, key, p in self.profiled)


def _resolve(parts: _Constituents, top: float, bottom: float, where: str
             ) -> list[tuple[float, float, Contribution]]:
    """(top, bottom, IOPs) of the sublayers of [top, bottom] (finite): intervals no longer than
    the profiles' length scale, cut at their nodes, halved until the optical-depth bound holds."""
    cuts = np.concatenate([[top], parts.breakpoints(top, bottom), [bottom]])
    step, key = parts.step()
    # counted before anything is allocated (a 1e-9 m gaussian over 10 m: 1e10 intervals)
    # (Python floats: a step near 1e-308 gives inf, where numpy's would print an overflow
    # warning beside the one-line refusal)
    spans = [max(1.0, float(z1 - z0) / step) for z0, z1 in zip(cuts[:-1], cuts[1:])]
    count = sum(spans)
    if count > MAX_SUBLAYERS:
        count = f"{count:.3g}" if math.isfinite(count) else "more than 1e+308"
        raise ConfigError(f"{key}: its length scale of {step:g} m (a gaussian's width_m, or the "
                          f"closest two depths) over {bottom - top:g} m of {where} needs "
                          f"{count} sublayers; allowed: at most {MAX_SUBLAYERS}")
    pending = []
    for z0, z1, n in zip(cuts[:-1], cuts[1:], spans):
        edges = np.linspace(z0, z1, math.ceil(n) + 1)
        pending += list(zip(edges[:-1], edges[1:]))
    out = []
    pending.reverse()
    while pending:
        z0, z1 = pending.pop()
        sub = parts.over(z0, z1)
        inside = np.linspace(z0, z1, CHECK_POINTS)
        excess = np.array([parts.attenuation_at(z) - sub.a - sub.b for z in inside])
        # optical depth from z0 with the continuous c minus with the sublayer's, at each point
        drift = np.cumsum(0.5 * (excess[1:] + excess[:-1]) * np.diff(inside)[:, None], axis=0)
        if np.max(np.abs(drift)) > OPTICAL_DEPTH_TOLERANCE:
            middle = 0.5 * (z0 + z1)
            pending += [(middle, z1), (z0, middle)]
            if len(out) + len(pending) > MAX_SUBLAYERS:
                raise ConfigError(f"{where}: the depth profile varies too steeply to resolve "
                                  f"into {MAX_SUBLAYERS} sublayers within an optical-depth "
                                  f"error of {OPTICAL_DEPTH_TOLERANCE}; smooth it")
            continue
        out.append((z0, z1, sub))
    return out


def _constituent_layers(layer: cfg.Layer, top: float, wl: np.ndarray, index: int
                        ) -> list[LayerIOPs]:
    where = f"water.layers[{index}]"
    parts = _Constituents(layer, wl, where)
    if not parts.profiled:
        return [_layer(parts.iops({}), top, layer.thickness_m, index)]
    bottom = top + layer.thickness_m
    end = min(bottom, max(top, parts.constant_below()))
    out = [_layer(sub, z0, z1 - z0, index) for z0, z1, sub in _resolve(parts, top, end, where)]
    if end < bottom:   # below every profile's last change: one homogeneous rest
        out.append(_layer(parts.at(end), end, bottom - end, index))
    return out


def column_iops(config: cfg.SceneConfig | dict | str | Path) -> list[LayerIOPs]:
    """The layers top to bottom, each homogeneous; the last may be infinitely deep. Raman
    scattering's loss (optics/inelastic/raman.py) is in every layer's absorption. config: a
    SceneConfig, or what load_config reads (a dict, a YAML path), as simulate() takes it."""
    if not isinstance(config, cfg.SceneConfig):
        config = cfg.load_config(config)
    wl = config.wavelengths
    out: list[LayerIOPs] = []
    top = 0.0
    for index, layer in enumerate(config.water.layers):
        if layer.components is None:
            out.append(_layer(_given(layer, len(wl)), top, layer.thickness_m, index))
        else:
            out += _constituent_layers(layer, top, wl, index)
        top += layer.thickness_m
    extra = inelastic.extra_attenuation(config)
    if extra is not None:
        out = [replace(layer, a=layer.a + extra) for layer in out]
    last = out[-1]
    if math.isinf(last.thickness_m):
        stuck = (last.b > 0.0) & (last.a <= 0.0)
        if stuck.any():
            raise ConfigError(f"water.layers[{last.config_layer}]: an infinitely deep layer that "
                              f"scatters needs a > 0; at {wl[stuck][0]:g} nm it has a = 0 (none "
                              f"of its components absorbs there: add pure_water, or end the "
                              f"column at a bottom)")
    return out


def iops_table(layers: list[LayerIOPs], wl: np.ndarray,
               bottom_reflectance: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """The results file's `iops` group: a, b, bb, c (layer, wavelength), 1/m; layer_top,
    layer_thickness (m), wavelength (nm); and bottom_reflectance (wavelength) where the bottom
    has one."""
    bottom = {} if bottom_reflectance is None else {
        "bottom_reflectance": np.asarray(bottom_reflectance, dtype=np.float64)}
    return {"layer_top": np.array([layer.top_m for layer in layers]),
            "layer_thickness": np.array([layer.thickness_m for layer in layers]),
            "wavelength": np.asarray(wl, dtype=np.float64),
            **{name: np.stack([getattr(layer, name) for layer in layers])
               for name in ("a", "b", "bb", "c")}, **bottom}
