"""Water described by its constituents: a layer's `components:` (each adds absorption, scattering
and a phase function per wavelength; oceanmc/optics/components/ has one module per model) and the
depth profiles a component's amount may follow (oceanmc/optics/profiles.py)."""
from __future__ import annotations

import math
from typing import Annotated, Literal, Union

from pydantic import (AfterValidator, AliasChoices, Discriminator, Field, PrivateAttr, Tag,
                      model_validator)

from .base import MAX_THICKNESS_M, Coefficient, FilePath, NonNegative, _Strict
from .phase import BasicPhase
from .wavelengths import BackscatterRatio, spectral

Depth = Annotated[float, Field(ge=0.0, le=MAX_THICKNESS_M, allow_inf_nan=False)]
Positive = Annotated[float, Field(gt=0.0, le=MAX_THICKNESS_M, allow_inf_nan=False)]
# The ranges of the constituents' amounts: chlorophyll, the range the Case-1 models are published
# for (Bricaud et al. 1998: 0.02-25 mg/m3; at 1e4 Morel et al. 2002's bb/b is negative); the
# others generous natural bounds (the darkest or most turbid waters reach ~1e2-1e3 1/m).
MAX_CHL_MG_M3 = 100.0
MAX_CONSTITUENT = 1000.0      # a440, a443, b550 (1/m) and concentration (a factor)
Constituent = Annotated[float, Field(ge=0.0, le=MAX_CONSTITUENT, allow_inf_nan=False)]


class GaussianProfile(_Strict):
    """background + integral / (width sqrt(2 pi)) exp(-(z - peak_depth)^2 / (2 width^2)), z the
    depth below the surface (m); integral is the whole peak's column amount (e.g. mg/m2 for
    chlorophyll; the share of a peak near the surface that lies above z = 0 is not in the
    water), also accepted as total_mg_m2."""
    profile: Literal["gaussian"]
    background: NonNegative
    peak_depth_m: Depth
    width_m: Positive
    integral: NonNegative = Field(validation_alias=AliasChoices("integral", "total_mg_m2"))


class LinearProfile(_Strict):
    """Piecewise linear through (depths_m, values), held at the end values above the first depth
    and below the last."""
    profile: Literal["linear"]
    depths_m: Annotated[list[Depth], Field(min_length=2)]
    values: Annotated[list[NonNegative], Field(min_length=2)]

    @model_validator(mode="after")
    def _matching(self) -> "LinearProfile":
        if len(self.values) != len(self.depths_m):
            raise ValueError(f"values has {len(self.values)} entries and depths_m "
                             f"{len(self.depths_m)}; give one value per depth")
        if any(b <= a for a, b in zip(self.depths_m, self.depths_m[1:])):
            raise ValueError(f"depths_m = {self.depths_m}: must be strictly increasing")
        return self


class TableProfile(_Strict):
    """A CSV (or whitespace) file of depth_m, value rows; piecewise linear between them and held
    at the end values outside."""
    profile: Literal["table"]
    file: FilePath
    # (largest value, unit) of the key it profiles, set by amount(); checked when it is read
    _limit: tuple[float, str] = PrivateAttr(default=(math.inf, ""))


Profile = Annotated[Union[GaussianProfile, LinearProfile, TableProfile],
                    Field(discriminator="profile")]


def _amount_kind(value) -> str:
    return "profile" if isinstance(value, (dict, GaussianProfile, LinearProfile, TableProfile)) \
        else "amount_value"


def amount(limit: float, unit: str):
    """A component's amount: one number, or a profile over depth, within 0 .. limit (a table
    profile's values are checked when it is read, optics/profiles.py)."""
    allowed = f"allowed: 0 .. {limit:g}{' ' + unit if unit else ''}"

    def within(value):
        if isinstance(value, TableProfile):
            value._limit = (limit, unit)
        elif isinstance(value, GaussianProfile):
            peak = value.background + value.integral / (value.width_m * math.sqrt(2.0 * math.pi))
            if peak > limit:
                raise ValueError(f"the gaussian's peak, background + integral / (width_m "
                                 f"sqrt(2 pi)), is {peak:g}; {allowed}")
        elif isinstance(value, LinearProfile):
            if max(value.values) > limit:
                raise ValueError(f"values reach {max(value.values):g}; {allowed}")
        elif value > limit:
            raise ValueError(allowed)
        return value
    return Annotated[Union[Annotated[NonNegative, Tag("amount_value")],
                           Annotated[Profile, Tag("profile")]],
                     Discriminator(_amount_kind), AfterValidator(within)]


class PureWaterComponent(_Strict):
    """a_w: Pope & Fry (1997), 420-727.5 nm; outside it (180-1230 nm) the IOCCG Protocols
    (2018)'s recommended spectrum (Morel et al. 2007, Jonasz & Fournier 2007, Kou et al. 1993);
    or the user's own from absorption_file (a CSV with columns wavelength_nm and a, in 1/m,
    covering every traced wavelength), to match another model's water (the Raman light in the
    blue follows pure water's absorption at 350-420 nm, where published values differ up to
    fourfold). b_w: pure sea water, Morel (1974), 0.00288 (lambda/500)^-4.32; phase 0.06225 (1
    + 0.835 cos^2)."""
    model: Literal["pure_water"]
    absorption_file: FilePath | None = None


class ChlorophyllComponent(_Strict):
    """Case-1 phytoplankton and the particles that covary with them: a_ph = A_phi Chl^E_phi
    (Bricaud et al. 1998, 400-700 nm; beyond it Vasilkov et al. 2005's ultraviolet shape and
    HydroLight's red tail: optics/components/chlorophyll.py); b_p and bb_p of Morel &
    Maritorena (2001) with the spectral exponent of Morel et al. (2002); Fournier-Forand phase
    by bb_p/b_p."""
    model: Literal["chlorophyll"]
    chl_mg_m3: amount(MAX_CHL_MG_M3, "mg/m3")


class Case1Component(_Strict):
    """Case-1 water's every non-water IOP from chlorophyll alone, HydroLight's "new Case 1" model
    (optics/components/case1.py): particles (phytoplankton and covarying detritus) a_p = A_p
    Chl^E_p (Bricaud et al. 1998; outside 400-700 nm HydroLight's coefficients of medium UV
    absorption), CDOM
    0.2 a_p(440) exp(-0.014 (lambda - 440)), b_p = 0.416 Chl^0.766 (lambda/550)^nu and two
    particle populations with the bb/b of Morel et al. (2002).
    Pure water is its own component."""
    model: Literal["case1"]
    chl_mg_m3: amount(MAX_CHL_MG_M3, "mg/m3")


class CdomComponent(_Strict):
    """Coloured dissolved organic matter: a_g = a440 exp(-slope (lambda - 440)); no scattering."""
    model: Literal["cdom"]
    a440: amount(MAX_CONSTITUENT, "1/m")
    slope: Annotated[float, Field(ge=0.0, le=0.1, allow_inf_nan=False)] = 0.014


class ParticlesComponent(_Strict):
    """Non-algal particles / minerals: a = a443 exp(-slope (lambda - 443)), b = b550 (550 /
    lambda)^exponent, Fournier-Forand phase with backscatter fraction bb_ratio. concentration
    (default 1) scales a and b together and may follow a depth profile."""
    model: Literal["particles"]
    b550: Constituent
    exponent: Annotated[float, Field(ge=-1.0, le=4.0, allow_inf_nan=False)] = 1.0
    bb_ratio: BackscatterRatio = 0.0183
    a443: Constituent = 0.0
    slope: Annotated[float, Field(ge=0.0, le=0.1, allow_inf_nan=False)] = 0.011
    concentration: amount(MAX_CONSTITUENT, "") = 1.0


class TableComponent(_Strict):
    """Measured IOPs from a CSV: columns wavelength_nm, a, b, bb_ratio (a and b in 1/m),
    linearly interpolated; Fournier-Forand phase by bb_ratio."""
    model: Literal["table"]
    file: FilePath


class ConstantComponent(_Strict):
    """a, b (1/m; one number or one per wavelength) and the phase function (or bb_ratio, which
    makes it Fournier-Forand), as a layer without components has them. concentration (default
    1) scales a and b and may follow a depth profile."""
    model: Literal["constant"]
    a: spectral(Coefficient)
    b: spectral(Coefficient) = 0.0
    phase: BasicPhase | None = None
    bb_ratio: spectral(BackscatterRatio) | None = None
    concentration: amount(MAX_CONSTITUENT, "") = 1.0

    @model_validator(mode="after")
    def _one_phase(self) -> "ConstantComponent":
        if self.bb_ratio is not None and self.phase is not None:
            raise ValueError("bb_ratio and phase both given: bb_ratio makes the phase function "
                             "Fournier-Forand with that backscatter fraction; give one")
        return self


Component = Annotated[
    Union[PureWaterComponent, ChlorophyllComponent, Case1Component, CdomComponent,
          ParticlesComponent, TableComponent, ConstantComponent],
    Field(discriminator="model"),
]

# the keys of each model whose value may be a depth profile
PROFILE_KEYS = {"pure_water": (), "chlorophyll": ("chl_mg_m3",), "case1": ("chl_mg_m3",),
                "cdom": ("a440",),
                "particles": ("concentration",), "table": (), "constant": ("concentration",)}
