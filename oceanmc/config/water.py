"""The water column: layers of absorption a, scattering b and a phase function; a and b (and the
backscatter fraction bb_ratio, which makes the phase function Fournier-Forand) may be lists, one
value per wavelength of `wavelengths_nm`."""
from __future__ import annotations

import math
from typing import Annotated

from pydantic import Field, field_validator, model_validator

from .base import MAX_COEFFICIENT, MAX_THICKNESS_M, Coefficient, _Strict
from .components import Component
from .inelastic import Inelastic
from .phase import Isotropic, Mixture, Phase
from .wavelengths import BackscatterRatio, check_count, spectral


def values(value: float | list[float]) -> list[float]:
    """A spectral key's values: a list as given, one number as a list of one."""
    return list(value) if isinstance(value, list) else [value]


class Layer(_Strict):
    thickness_m: Annotated[float, Field(gt=0.0)]
    a: spectral(Coefficient) | None = None
    b: spectral(Coefficient) | None = None
    phase: Phase | None = None         # isotropic unless bb_ratio is given
    bb_ratio: spectral(BackscatterRatio) | None = None
    components: Annotated[list[Component], Field(min_length=1, max_length=32)] | None = None

    @field_validator("thickness_m")
    @classmethod
    def _no_nan(cls, v: float) -> float:
        if math.isnan(v) or (math.isfinite(v) and v > MAX_THICKNESS_M):
            raise ValueError(f"must be a positive number up to {MAX_THICKNESS_M:g} m (deeper "
                             "than any ocean) or .inf")
        return v

    @model_validator(mode="after")
    def _scattering(self) -> "Layer":
        if self.components is not None:
            given = [k for k in ("a", "b", "phase", "bb_ratio") if getattr(self, k) is not None]
            if given:
                raise ValueError(f"{', '.join(given)} given with components: a layer is described "
                                 "by its components or by a, b and phase; for constant IOPs "
                                 "beside constituents add {model: constant, a: ..., b: ...}")
            return self
        if self.a is None:
            raise ValueError("a (absorption coefficient, 1/m) or components is required")
        if self.bb_ratio is not None and self.phase is not None:
            raise ValueError("bb_ratio and phase both given: bb_ratio makes the phase function "
                             "Fournier-Forand with that backscatter fraction; give one")
        if self.bb_ratio is None and self.phase is None:
            self.phase = Isotropic(model="isotropic")
        if isinstance(self.phase, Mixture):
            total = sum(c.b for c in self.phase.components)
            if self.b is None:
                if total > MAX_COEFFICIENT:
                    raise ValueError(f"phase.components: their b add up to {total:g} 1/m, the "
                                     f"layer's b; allowed: at most {MAX_COEFFICIENT:g} 1/m")
                self.b = total
            elif isinstance(self.b, list):
                raise ValueError("b is a list with phase.model = 'mixture', whose components "
                                 "carry their own b; give b as one number or leave it out")
            elif not math.isclose(self.b, total, rel_tol=1e-9, abs_tol=1e-12):
                raise ValueError(f"b = {self.b} differs from the sum of the mixture's component b "
                                 f"({total}); give one or make them agree")
        elif self.b is None:
            raise ValueError("b (scattering coefficient, 1/m) is required")
        return self


class Water(_Strict):
    layers: list[Layer] = Field(min_length=1, max_length=100_000)
    inelastic: Inelastic | None = None     # Raman scattering, fluorescence (config/inelastic.py)

    @model_validator(mode="after")
    def _infinite_last_only(self) -> "Water":
        for i, layer in enumerate(self.layers):
            if math.isinf(layer.thickness_m):
                if i != len(self.layers) - 1:
                    raise ValueError(f"layers[{i}].thickness_m = .inf: only the last layer may be "
                                     "infinitely deep")
                if layer.components is not None:
                    continue   # checked per wavelength when the IOPs are resolved (optics)
                a, b = values(layer.a), values(layer.b)
                if any(b[k % len(b)] > 0.0 and a[k % len(a)] == 0.0
                       for k in range(max(len(a), len(b)))):
                    raise ValueError(f"layers[{i}]: an infinitely deep layer that scatters (b > 0) "
                                     "needs a > 0, or photons never leave it")
        return self

    def check_wavelength_count(self, n_wavelengths: int, spectral: bool) -> None:
        """Every list (a layer's a, b, bb_ratio; a component's) has one value per wavelength;
        lists need `wavelengths_nm`."""
        for i, layer in enumerate(self.layers):
            if layer.components is not None and not spectral:
                raise ValueError(f"water.layers[{i}].components: constituents need "
                                 "wavelengths_nm (a list in nm, or {start, stop, step})")
        for key, value in self.spectral_values():
            check_count(key, value, n_wavelengths, spectral)

    def spectral_values(self) -> list[tuple[str, object]]:
        """(key path, value) of every key that may hold one value per wavelength: a layer's a,
        b and bb_ratio, and a component's lists."""
        values = []
        for i, layer in enumerate(self.layers):
            values += [(f"water.layers[{i}].{key}", getattr(layer, key))
                       for key in ("a", "b", "bb_ratio")]
            values += [(f"water.layers[{i}].components[{k}].{key}", value)
                       for k, component in enumerate(layer.components or ())
                       for key, value in component if isinstance(value, list)]
        return values

    @property
    def depth_m(self) -> float:
        return math.fsum(layer.thickness_m for layer in self.layers)
