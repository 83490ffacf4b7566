"""The wavelength grid: `wavelengths_nm`, a list of wavelengths (nm) or {start, stop, step}."""
from __future__ import annotations

import math
from typing import Annotated, Union

import numpy as np
from pydantic import Discriminator, Field, Tag, model_validator

from .base import _Strict

# far ultraviolet to thermal infrared: the power laws of the constituents ((550/l)^4 and the like)
# stay finite and mean something there
MIN_WAVELENGTH_NM, MAX_WAVELENGTH_NM = 100.0, 10_000.0
Wavelength = Annotated[float, Field(ge=MIN_WAVELENGTH_NM, le=MAX_WAVELENGTH_NM,
                                    allow_inf_nan=False)]
MAX_WAVELENGTHS = 10_000


class WavelengthRange(_Strict):
    """start, start + step, ... up to stop (included when it falls on the grid), in nm."""
    start: Wavelength
    stop: Wavelength
    step: Annotated[float, Field(gt=0.0, allow_inf_nan=False)]

    @model_validator(mode="after")
    def _ordered(self) -> "WavelengthRange":
        if self.stop < self.start:
            raise ValueError(f"stop = {self.stop} is below start = {self.start}; allowed: "
                             "stop >= start")
        if (self.stop - self.start) / self.step + 1 > MAX_WAVELENGTHS:
            raise ValueError(f"{{start: {self.start}, stop: {self.stop}, step: {self.step}}} "
                             f"gives more than {MAX_WAVELENGTHS} wavelengths")
        return self

    def grid(self) -> np.ndarray:
        # the stop is included when it lies on the grid up to rounding (400..700 by 10: 31 entries)
        count = math.floor((self.stop - self.start) / self.step * (1.0 + 1e-12) + 1e-9) + 1
        return self.start + self.step * np.arange(count, dtype=np.float64)


WavelengthList = Annotated[list[Wavelength], Field(min_length=1, max_length=MAX_WAVELENGTHS)]
Wavelengths = Annotated[
    Union[Annotated[WavelengthList, Tag("wavelength_list")],
          Annotated[WavelengthRange, Tag("wavelength_range")]],
    Discriminator(lambda v: "wavelength_range" if isinstance(v, (dict, WavelengthRange))
                  else "wavelength_list")]


def check_increasing(value: Wavelengths | None) -> Wavelengths | None:
    """A list must be strictly increasing (one line naming the first offending pair)."""
    if isinstance(value, list):
        for i in range(1, len(value)):
            if not value[i] > value[i - 1]:
                raise ValueError(f"must be strictly increasing; entry {i} ({value[i]} nm) follows "
                                 f"{value[i - 1]} nm")
    return value


def grid(value: Wavelengths | None) -> np.ndarray:
    """The wavelengths (nm) of the scene; a monochromatic scene (None) has one, NaN."""
    if value is None:
        return np.array([np.nan])
    if isinstance(value, WavelengthRange):
        return value.grid()
    return np.asarray(value, dtype=np.float64)


# per-wavelength keys (water.layers[i].a, b, bb_ratio; components; bottom.reflectance): one
# number or one per wavelength
# the Fournier-Forand phase functions are tabulated for these backscatter fractions
MIN_BB_RATIO, MAX_BB_RATIO = 0.0005, 0.45
BackscatterRatio = Annotated[float, Field(ge=MIN_BB_RATIO, le=MAX_BB_RATIO, allow_inf_nan=False)]


def spectral(number, table=None):
    """One number, or a list of them (one per wavelength), or (where `table` is given, a model
    naming a file) a spectrum read from a table; the discriminator makes a bad value report the
    error of the form it was given in, not of all of them."""
    def form(value) -> str:
        if table is not None and isinstance(value, (dict, table)):
            return "spectral_table"
        return "spectral_list" if isinstance(value, list) else "spectral_value"
    members = [Annotated[number, Tag("spectral_value")],
               Annotated[Annotated[list[number], Field(min_length=1)], Tag("spectral_list")]]
    if table is not None:
        members.append(Annotated[table, Tag("spectral_table")])
    return Annotated[Union[tuple(members)], Discriminator(form)]


def check_count(key: str, value, n_wavelengths: int, spectral: bool) -> None:
    """A spectral key given as a list has one value per wavelength, and lists need
    `wavelengths_nm`; one line naming the key otherwise."""
    if not isinstance(value, list):
        return
    if not spectral:
        raise ValueError(f"{key} is a list ({len(value)} values) but wavelengths_nm is not "
                         "given; give wavelengths_nm or one number")
    if len(value) != n_wavelengths:
        raise ValueError(f"{key} has {len(value)} values; allowed: one number or one value per "
                         f"wavelength ({n_wavelengths} in wavelengths_nm)")
