"""The validation cases, one module each; CASES is the registry in the order they run and are
reported. A case module defines its case function (a function of a Ctx: it runs its scenes, records
checks against analytic or independent references, draws its figures and writes its notes for the
report) and CASE, its Case record; common.py holds what several cases share."""
from __future__ import annotations

from . import (beer_lambert, brdf_bottom, brdf_models, chandrasekhar, constituent_iops, disort,
               fraunhofer, fresnel, inelastic, nadir_cap, optical_manhole, profile_layering,
               realistic_phase, reciprocity, rough_surface, spectral_history, upward_bias,
               white_furnace)
from .common import Case

CASES: list[Case] = [module.CASE for module in (
    brdf_bottom, brdf_models, optical_manhole, fresnel, beer_lambert, chandrasekhar, disort,
    upward_bias, white_furnace, reciprocity, realistic_phase, constituent_iops, profile_layering,
    rough_surface, spectral_history, nadir_cap, inelastic, fraunhofer)]
