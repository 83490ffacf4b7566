"""What is tallied: depths, the radiance bands, local directions, the nadir estimator."""
from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, field_validator

from .base import MIN_ANGLE_DEG, Finite, NonNegative, _Strict

HYDROLIGHT_THETA_EDGES_DEG = (0.0, 5.0, 15.0, 25.0, 35.0, 45.0, 55.0, 65.0, 75.0, 85.0, 90.0,
                              95.0, 105.0, 115.0, 125.0, 135.0, 145.0, 155.0, 165.0, 175.0, 180.0)


class Tallies(_Strict):
    depths_m: list[NonNegative] = Field(default_factory=lambda: [0.0], max_length=10_000)
    theta_edges_deg: Literal["hydrolight"] | list[Finite] = "hydrolight"
    phi_bands: Annotated[int, Field(ge=1, le=360)] = 24
    radiance: bool = True
    local_directions_deg: list[tuple[Annotated[float, Field(gt=90.0, le=180.0,
                                                           allow_inf_nan=False)],
                                     Annotated[float, Field(ge=0.0, lt=360.0,
                                                           allow_inf_nan=False)]]] \
        = Field(default_factory=list, max_length=64)
    grazing_mu_cut: Annotated[float, Field(gt=0.0, le=0.1, allow_inf_nan=False)] = 0.01
    nadir_estimator: Literal["auto", "local", "crossing"] = "auto"

    @field_validator("depths_m")
    @classmethod
    def _sorted_unique(cls, v: list[float]) -> list[float]:
        return sorted(set(v))

    @field_validator("theta_edges_deg")
    @classmethod
    def _edges(cls, v):
        if v == "hydrolight":
            return v
        if len(v) < 2 or v[0] != 0.0 or v[-1] != 180.0:
            raise ValueError(f"must start at 0 and end at 180 (deg), got {v}")
        if any(b <= a for a, b in zip(v, v[1:])):
            raise ValueError(f"must increase strictly, got {v}")
        if any(b - a < MIN_ANGLE_DEG * (1.0 - 1e-9) for a, b in zip(v, v[1:])):  # 180 - 179.99
            raise ValueError(f"bands must be at least {MIN_ANGLE_DEG} deg wide (float64 does not "
                             f"resolve narrower ones near the poles), got {v}")
        if 90.0 not in v:
            raise ValueError(f"must include 90 so that no band straddles the horizontal, got {v}")
        return v

    @property
    def theta_edges(self) -> tuple[float, ...]:
        if self.theta_edges_deg == "hydrolight":
            return HYDROLIGHT_THETA_EDGES_DEG
        return tuple(self.theta_edges_deg)
