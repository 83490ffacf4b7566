"""The air-water surface."""
from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field

from .base import _Strict


class Surface(_Strict):
    """flat: exact unpolarized Fresnel + Snell; none: no interface (index-matched, n = 1).
    fresnel: schlick swaps in Schlick's approximation, for comparisons only (never exact)."""
    model: Literal["flat", "none"] = "flat"
    n_water: Annotated[float, Field(ge=1.0, le=3.0, allow_inf_nan=False)] = 1.34
    fresnel: Literal["exact", "schlick"] = "exact"
