"""Phase functions: the single models (BasicPhase) and Mixture, several of them by weight b."""
from __future__ import annotations

from typing import Annotated, Literal, Union

from pydantic import Field

from .base import Asymmetry, Coefficient, FilePath, Fraction, _Strict


class Isotropic(_Strict):
    model: Literal["isotropic"]


class Rayleigh(_Strict):
    """Rayleigh-like (3/16 pi)(1 + cos^2)."""
    model: Literal["rayleigh"]


class PureWater(_Strict):
    """Pure sea water 0.06225 (1 + 0.835 cos^2) (Morel 1974; Mobley 1994, Light and Water)."""
    model: Literal["pure_water"]


class HenyeyGreenstein(_Strict):
    model: Literal["henyey_greenstein"]
    g: Asymmetry = 0.9


class TwoTermHG(_Strict):
    """alpha HG(g1) + (1 - alpha) HG(g2)."""
    model: Literal["two_term_hg"]
    g1: Asymmetry = 0.95
    g2: Asymmetry = -0.5
    alpha: Fraction = 0.95


class FournierForand(_Strict):
    """Fournier-Forand with the backscatter fraction bb/b (Mobley et al. 2002, Appl. Opt. 41)."""
    model: Literal["fournier_forand"]
    bb_ratio: Annotated[float, Field(ge=0.0005, le=0.45, allow_inf_nan=False)] = 0.0183


class Petzold(_Strict):
    model: Literal["petzold"]


class TablePhase(_Strict):
    """A user table: a CSV or whitespace file of (scattering angle in deg, phase value) rows."""
    model: Literal["table"]
    file: FilePath


BasicPhase = Annotated[
    Union[Isotropic, Rayleigh, PureWater, HenyeyGreenstein, TwoTermHG, FournierForand, Petzold,
          TablePhase],
    Field(discriminator="model"),
]


class MixtureComponent(_Strict):
    b: Coefficient        # 1/m, as a layer's b (0 .. 1e6)
    phase: BasicPhase


class Mixture(_Strict):
    """Several scatterers in one layer (e.g. water + particles), weighted by their b (1/m)."""
    model: Literal["mixture"]
    components: list[MixtureComponent] = Field(min_length=1, max_length=16)


Phase = Annotated[
    Union[Isotropic, Rayleigh, PureWater, HenyeyGreenstein, TwoTermHG, FournierForand, Petzold,
          TablePhase, Mixture],
    Field(discriminator="model"),
]
