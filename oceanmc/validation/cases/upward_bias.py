"""Validation case upward_bias: three of the DISORT slabs again with scattering biased toward
straight up (estimator.upward_fraction), against the same DISORT references."""
from __future__ import annotations

from ..context import Ctx
from .common import DISORT_SLABS, Case, _disort_slab


UPWARD_FRACTION = 0.1
UPWARD_SLABS = [DISORT_SLABS[0], DISORT_SLABS[2], DISORT_SLABS[3]]


def case_upward_bias(ctx: Ctx) -> None:
    photons = ctx.pick(6_000_000, 200_000)
    for slab in UPWARD_SLABS:
        _disort_slab(ctx, slab, photons, {"upward_fraction": UPWARD_FRACTION},
                     tag=", upward-biased scattering")
    ctx.note(f"The DISORT slabs {', '.join(f'tau {s[0]:g}, w0 {s[1]:g}, g {s[2]:g}' for s in UPWARD_SLABS)} "
             f"run with `estimator.upward_fraction: {UPWARD_FRACTION:g}` (cone 15 deg): a "
             "fraction min(0.1, 1 - w0) of scattering events draws its new direction uniformly "
             "in the cone around straight up and the packet carries the defensive-mixture "
             "weight p / ((1 - f) p + f g) (kernel/upward.py). The weights change, the "
             "expectations must not: the same checks as the disort case, against the same "
             "DISORT references (fluxes, every distinct quad, exact-direction local estimates).")


CASE = Case("upward_bias", "Scattering biased toward straight up, against DISORT",
            case_upward_bias, "DISORT slabs rerun with estimator.upward_fraction 0.1: fluxes, "
            "quad radiances, exact-direction local estimates")
