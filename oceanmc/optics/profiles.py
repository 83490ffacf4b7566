"""Depth profiles of a component's amount (config/components.py): gaussian, linear, table.
z is the depth below the surface (m)."""
from __future__ import annotations

import math

import numpy as np

from .. import config as cfg
from ..config.base import MAX_THICKNESS_M
from .tables import read_table

GAUSSIAN_REACH = 8.0    # widths beyond the peak where a gaussian is its background to 1e-14


def nodes(profile, where: str) -> tuple[np.ndarray, np.ndarray]:
    """(depths, values) of a piecewise-linear profile (linear or table)."""
    if isinstance(profile, cfg.LinearProfile):
        return np.array(profile.depths_m), np.array(profile.values)
    limit, unit = profile._limit    # the range of the key it profiles (config/components.py)
    table = read_table(profile.file, f"{where}.file", {"depth_m": (0.0, MAX_THICKNESS_M, "m"),
                                                       "value": (0.0, limit, unit)}, rows=2)
    return table["depth_m"], table["value"]


def value_at(profile, z: np.ndarray, where: str) -> np.ndarray:
    if isinstance(profile, cfg.GaussianProfile):
        s = profile.width_m
        return profile.background + profile.integral / (s * math.sqrt(2.0 * math.pi)) \
            * np.exp(-0.5 * ((z - profile.peak_depth_m) / s) ** 2)
    depth, value = nodes(profile, where)
    return np.interp(z, depth, value)    # held at the end values outside the nodes


def mean(profile, top: float, bottom: float, where: str) -> float:
    """The exact average over [top, bottom] (finite)."""
    if isinstance(profile, cfg.GaussianProfile):
        s = profile.width_m * math.sqrt(2.0)
        mass = 0.5 * profile.integral * (math.erf((bottom - profile.peak_depth_m) / s)
                                         - math.erf((top - profile.peak_depth_m) / s))
        return profile.background + mass / (bottom - top)
    depth, value = nodes(profile, where)
    inner = depth[(depth > top) & (depth < bottom)]
    z = np.concatenate([[top], inner, [bottom]])
    return float(np.trapezoid(np.interp(z, depth, value), z) / (bottom - top))


def breakpoints(profile, where: str) -> np.ndarray:
    """Depths where the profile bends (the nodes of a piecewise-linear one)."""
    if isinstance(profile, cfg.GaussianProfile):
        return np.array([profile.peak_depth_m])
    return nodes(profile, where)[0]


def constant_below(profile, where: str) -> float:
    """A depth below which the profile is constant."""
    if isinstance(profile, cfg.GaussianProfile):
        return profile.peak_depth_m + GAUSSIAN_REACH * profile.width_m
    return float(nodes(profile, where)[0][-1])


def length_scale(profile, where: str) -> float:
    """A depth step over which the profile is nearly linear (to start the subdivision)."""
    if isinstance(profile, cfg.GaussianProfile):
        return profile.width_m
    depth = nodes(profile, where)[0]
    return float(np.min(np.diff(depth)))
