"""The bottom: none (infinitely deep water), black, or a BRDF model; and what a model allows."""
from __future__ import annotations

from typing import Annotated, Literal, Union

from pydantic import Field

from .base import Asymmetry, FilePath, Fraction, _Strict


class NoBottom(_Strict):
    model: Literal["none"]


class BlackBottom(_Strict):
    model: Literal["black"]


# Every BRDF below is checked when the scene is built (brdf_tables.py): f >= 0, reciprocity
# f(i, o) = f(o, i) and energy conservation rho_dh(theta_i) <= 1; a violation is a ConfigError
# naming the model and the worst incidence angle unless allow_unphysical is true.
# sampling: auto = the model's own sampler; tabulated = the general tabulated sampler (exact in
# expectation; for comparisons and for models without an analytic sampler).
Sampling = Literal["auto", "tabulated"]


class LambertianBottom(_Strict):
    model: Literal["lambertian"]
    reflectance: Fraction
    sampling: Sampling = "auto"
    allow_unphysical: bool = False


class MinnaertBottom(_Strict):
    """(rho/pi)(cos t_i cos t_r)^k; rho_dh = 2 rho cos^k(t_i)/(k + 2) <= 1 for k >= 0."""
    model: Literal["minnaert"]
    reflectance: Fraction
    k: Annotated[float, Field(ge=0.0, le=100.0, allow_inf_nan=False)]
    sampling: Sampling = "auto"
    allow_unphysical: bool = False


class SpecularBottom(_Strict):
    model: Literal["specular"]
    reflectance: Fraction


class LambertianSpecularBottom(_Strict):
    """diffuse_reflectance/pi + specular_reflectance x mirror; rho_dh is their sum."""
    model: Literal["lambertian_specular"]
    diffuse_reflectance: Fraction
    specular_reflectance: Fraction
    allow_unphysical: bool = False


class GGXBottom(_Strict):
    """Glossy microfacets: GGX (Trowbridge-Reitz) with roughness alpha, height-correlated Smith
    shadowing, Fresnel reflection at facets of relative index n_ratio (fresnel: false makes them
    perfect mirrors, F = 1), plus an optional Lambertian term (kernel/brdf/ggx.py)."""
    model: Literal["ggx"]
    roughness: Annotated[float, Field(ge=0.01, le=1.0, allow_inf_nan=False)]
    n_ratio: Annotated[float, Field(gt=1.0, le=10.0, allow_inf_nan=False)] = 1.15
    fresnel: bool = True
    diffuse_reflectance: Fraction = 0.0
    sampling: Sampling = "auto"
    allow_unphysical: bool = False


class HapkeBottom(_Strict):
    """Hapke's model with the shadow-hiding opposition (hot-spot) term, for sediments
    (kernel/brdf/hapke.py): grain single-scattering albedo, Henyey-Greenstein asymmetry of the
    grains (negative: backward), opposition surge amplitude B0 and width h."""
    model: Literal["hapke"]
    albedo: Annotated[float, Field(gt=0.0, le=1.0, allow_inf_nan=False)]
    asymmetry: Asymmetry = 0.0
    opposition_amplitude: Annotated[float, Field(ge=0.0, le=10.0, allow_inf_nan=False)] = 0.5
    opposition_width: Annotated[float, Field(gt=0.0, le=2.0, allow_inf_nan=False)] = 0.06
    allow_unphysical: bool = False


class TableBottom(_Strict):
    """A measured BRDF on an angular grid from a file (brdf_tables.read_brdf_table): isotropic
    (theta_i, theta_r, dphi) or anisotropic (theta_i, phi_i, theta_r, dphi); values in 1/sr, or
    reflectance factors (pi f) with quantity: reflectance_factor."""
    model: Literal["table"]
    file: FilePath
    quantity: Literal["brdf", "reflectance_factor"] = "brdf"
    reciprocity_tolerance: Annotated[float, Field(gt=0.0, le=1.0, allow_inf_nan=False)] = 0.05
    allow_unphysical: bool = False


Bottom = Annotated[
    Union[NoBottom, BlackBottom, LambertianBottom, MinnaertBottom, SpecularBottom,
          LambertianSpecularBottom, GGXBottom, HapkeBottom, TableBottom],
    Field(discriminator="model"),
]


def bottom_has_mirror(bottom) -> bool:
    """Whether the bottom reflects part of the light as a mirror: a delta function, which a
    local (next-event) estimate cannot evaluate."""
    if bottom.model == "specular":
        return True
    return bottom.model == "lambertian_specular" and bottom.specular_reflectance > 0.0


def bottom_weight_bounded(bottom) -> bool:
    """Whether the bottom's sampling weight f cos / pdf never exceeds 1 (analog bottom
    reflection survives with probability = weight, so it needs this)."""
    if bottom.model in ("hapke", "table") or getattr(bottom, "sampling", "auto") == "tabulated":
        return False
    return not (bottom.model == "ggx" and bottom.diffuse_reflectance > 0.0)
