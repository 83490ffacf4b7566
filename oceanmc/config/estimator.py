"""How photon weights evolve: implicit or analog, roulette, splitting, upward-biased scattering."""
from __future__ import annotations

from typing import Annotated, Literal, Optional, Union

from pydantic import Field, field_validator

from .base import _Strict


# auto's upward fraction in spectral scenes: the Rrs nadir of a 31-band windy Case-1 scene to 1%
# in 20-30 s where it took 1,000-10,000 s without it (benchmarks/real_scenes.md)
AUTO_UPWARD_FRACTION = 0.1
DEFAULT_EMISSION_WEIGHT = 0.003
# the least emission_weight: an emitted packet carries at least emission_weight per wavelength,
# and its spectral weights divide by what it carries (kernel/channels/inelastic.py), which
# overflows below about 1e-308: emission_weight 5e-324 gave NaN results with three inelastic
# processes (tests/test_fuzz_numeric_keys.py)
MIN_EMISSION_WEIGHT = 1e-100


class Estimator(_Strict):
    """How photon weights evolve. `implicit`: absorption and Fresnel splitting by weight, with
    Russian roulette below `roulette_weight` (survivors get weight / roulette_survival).
    `analog`: absorption, Fresnel and bottom reflection decided by random draws (for tests).
    split_weight: a packet heavier than this (a launched packet weighs 1) is split into
    floor(w / split_weight) + 1 packets of equal weight; off (null) by default.
    upward_fraction: the largest fraction of scattering events that draw the new direction
    uniformly in the cone of half-angle upward_cone_deg around straight up (in a layer of
    single-scattering albedo w0 the fraction is min(upward_fraction, 1 - w0)); for Lu,
    Lw_nadir and Rrs_nadir. auto (the default): AUTO_UPWARD_FRACTION in a spectral scene of
    the implicit walk and in a one-wavelength one whose depth windows are on, off (null)
    otherwise; resolved by config/scene.py, in one-wavelength scenes by the build
    (scene/weight_window.upward_fraction; the result's attribute upward_fraction says it).
    depth_splitting: depth importance weight windows (scene/weight_window.py): packets are
    split as they go deeper and play roulette as they come up, so that light is followed as
    well at the deepest tally depth as near the surface. auto (the default): on in an implicit
    walk of scattering water without inelastic light whose deepest tally depth lies at least
    scene.weight_window.AUTO_ATTENUATION_DEPTHS attenuation depths down; on: whenever the
    tallies go below the surface (not with inelastic light); off: never."""
    mode: Literal["implicit", "analog"] = "implicit"
    roulette_weight: Annotated[float, Field(gt=0.0, lt=1.0, allow_inf_nan=False)] = 1e-3
    roulette_survival: Annotated[float, Field(gt=0.0, le=1.0, allow_inf_nan=False)] = 0.1
    max_events: Annotated[int, Field(ge=100, le=10**12)] = 1_000_000
    split_weight: Optional[Annotated[float, Field(gt=1.0, allow_inf_nan=False)]] = None
    # scattering biased toward straight up (kernel/upward.py)
    upward_fraction: Union[Annotated[float, Field(gt=0.0, lt=1.0, allow_inf_nan=False)],
                           Literal["auto"], None] = "auto"
    # at least 0.01 deg: the kernel draws cos psi = 1 - u (1 - cos A), whose 1 - cos A is
    # accurate to 1e-8 relative there and loses all accuracy near 1e-6 deg
    upward_cone_deg: Annotated[float, Field(ge=0.01, le=90.0, allow_inf_nan=False)] = 15.0
    # the light an inelastic process (water.inelastic) emits at a collision: `carried` on by
    # the packet that emitted it (its weight times the emission's phase function over the
    # density of the packet's new direction), or each emission in a `packets` of its own (the
    # reference the carried light is checked against: validation case inelastic). The default
    # measured best for the inelastic parts of Rrs (benchmarks/inelastic.md)
    emitted_light: Literal["carried", "packets"] = "carried"
    depth_splitting: Literal["auto", "on", "off"] = "auto"
    # a spectral photon's hero wavelength is drawn with probability in proportion to
    # (1 / (1 - w0))^hero_exponent, w0 the top layer's single-scattering albedo there
    # (scene/medium.py hero_probabilities; 0: uniform). The default measured best for the
    # spectral bench's weakest bands (benchmarks/spectral.md)
    hero_exponent: Annotated[float, Field(ge=0.0, le=2.0, allow_inf_nan=False)] = 1.0
    # the least weight of an emitted packet (emitted_light packets, the analog walk); lighter
    # emissions are made with probability weight / emission_weight and carry emission_weight
    # (kernel/channels/inelastic.py); measured best for packets in clear water
    # (benchmarks/inelastic.md)
    emission_weight: Annotated[float, Field(ge=MIN_EMISSION_WEIGHT, le=1.0,
                                            allow_inf_nan=False)] = DEFAULT_EMISSION_WEIGHT

    @field_validator("depth_splitting", mode="before")
    @classmethod
    def _yaml_switch(cls, value):
        # YAML 1.1 reads a bare on / off as true / false
        if value is True:
            return "on"
        if value is False:
            return "off"
        return value
