"""How photon weights evolve: implicit or analog, roulette, splitting, upward-biased scattering."""
from __future__ import annotations

from typing import Annotated, Literal, Optional

from pydantic import Field

from .base import _Strict


class Estimator(_Strict):
    """How photon weights evolve. `implicit`: absorption and Fresnel splitting by weight, with
    Russian roulette below `roulette_weight` (survivors get weight / roulette_survival).
    `analog`: absorption, Fresnel and bottom reflection decided by random draws (for tests).
    split_weight: a packet heavier than this (a launched packet weighs 1) is split into
    floor(w / split_weight) + 1 packets of equal weight; off (null) by default.
    upward_fraction: the largest fraction of scattering events that draw the new direction
    uniformly in the cone of half-angle upward_cone_deg around straight up (in a layer of
    single-scattering albedo w0 the fraction is min(upward_fraction, 1 - w0)); for Lu,
    Lw_nadir and Rrs_nadir; off (null) by default."""
    mode: Literal["implicit", "analog"] = "implicit"
    roulette_weight: Annotated[float, Field(gt=0.0, lt=1.0, allow_inf_nan=False)] = 1e-3
    roulette_survival: Annotated[float, Field(gt=0.0, le=1.0, allow_inf_nan=False)] = 0.1
    max_events: Annotated[int, Field(ge=100, le=10**12)] = 1_000_000
    split_weight: Optional[Annotated[float, Field(gt=1.0, allow_inf_nan=False)]] = None
    # scattering biased toward straight up (kernel/upward.py): off (null) by default
    upward_fraction: Optional[Annotated[float, Field(gt=0.0, lt=1.0, allow_inf_nan=False)]] = None
    # at least 0.01 deg: the kernel draws cos psi = 1 - u (1 - cos A), whose 1 - cos A is
    # accurate to 1e-8 relative there and loses all accuracy near 1e-6 deg
    upward_cone_deg: Annotated[float, Field(ge=0.01, le=90.0, allow_inf_nan=False)] = 15.0
