"""The water column: layers of absorption a, scattering b and a phase function."""
from __future__ import annotations

import math
from typing import Annotated

from pydantic import Field, field_validator, model_validator

from .base import NonNegative, _Strict
from .phase import Isotropic, Mixture, Phase


class Layer(_Strict):
    thickness_m: Annotated[float, Field(gt=0.0)]
    a: NonNegative
    b: NonNegative | None = None
    phase: Phase = Field(default_factory=lambda: Isotropic(model="isotropic"))

    @field_validator("thickness_m")
    @classmethod
    def _no_nan(cls, v: float) -> float:
        if math.isnan(v):
            raise ValueError("must be a positive number or .inf, got nan")
        return v

    @model_validator(mode="after")
    def _scattering(self) -> "Layer":
        if isinstance(self.phase, Mixture):
            total = sum(c.b for c in self.phase.components)
            if self.b is None:
                self.b = total
            elif not math.isclose(self.b, total, rel_tol=1e-9, abs_tol=1e-12):
                raise ValueError(f"b = {self.b} differs from the sum of the mixture's component b "
                                 f"({total}); give one or make them agree")
        elif self.b is None:
            raise ValueError("b (scattering coefficient, 1/m) is required")
        return self


class Water(_Strict):
    layers: list[Layer] = Field(min_length=1, max_length=100_000)

    @model_validator(mode="after")
    def _infinite_last_only(self) -> "Water":
        for i, layer in enumerate(self.layers):
            if math.isinf(layer.thickness_m):
                if i != len(self.layers) - 1:
                    raise ValueError(f"layers[{i}].thickness_m = .inf: only the last layer may be "
                                     "infinitely deep")
                if layer.a == 0.0 and layer.b > 0.0:
                    raise ValueError(f"layers[{i}]: an infinitely deep layer that scatters (b > 0) "
                                     "needs a > 0, or photons never leave it")
        return self

    @property
    def depth_m(self) -> float:
        return math.fsum(layer.thickness_m for layer in self.layers)
