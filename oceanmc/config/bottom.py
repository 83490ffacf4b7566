"""The bottom: none (infinitely deep water), black, a BRDF model, or an areal mixture of
bottom types; and what a model allows."""
from __future__ import annotations

import math
from typing import Annotated, Literal, Union

from pydantic import BeforeValidator, Field, field_validator, model_validator

from .base import Asymmetry, FilePath, Fraction, _Strict
from .wavelengths import check_count, spectral


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


class ReflectanceSpectrum(_Strict):
    """A reflectance spectrum from a CSV file: columns wavelength_nm and reflectance (0 .. 1),
    linearly interpolated to the run's wavelengths, which must lie within the table's
    (optics/bottom.py)."""
    file: FilePath


# A bottom reflectance that may vary with wavelength: one number, one per wavelength, or
# {file: CSV}. The spectral walk (kernel/spectral.py) samples one BRDF for every wavelength and
# gives wavelength j the share R_j / R_packed of the packed BRDF's reflectance (GRID bottom_q;
# optics/bottom.py packs it): exact where the angular shape does not depend on R (lambertian,
# minnaert, specular, and the albedo_scale of ggx, hapke and table), and per lobe for
# lambertian_specular (the diffuse lobe's shares, and the mirror lobe's used when the mirror
# was sampled).
Reflectance = spectral(Fraction, table=ReflectanceSpectrum)
SPECTRAL_MODELS = ("lambertian", "minnaert", "specular")
# the largest albedo_scale: a GGX with Fresnel facets reflects ~0.005, so scales of ~100 are
# physical; rho_dh <= 1 is checked per wavelength when the scene is built
MAX_ALBEDO_SCALE = 1000.0
# ggx, hapke, table: their f times albedo_scale at each wavelength (a CSV spectrum's values lie
# within 0 .. 1, as every reflectance spectrum's)
AlbedoScale = spectral(Annotated[float, Field(gt=0.0, le=MAX_ALBEDO_SCALE, allow_inf_nan=False)],
                       table=ReflectanceSpectrum)
SCALED_MODELS = ("ggx", "hapke", "table")


def _one_value(model: str, key: str):
    """A parameter of a BRDF whose angular shape changes with it: a list or a spectrum is
    refused in one line saying what is offered instead (albedo_scale)."""
    def check(value):
        if isinstance(value, (list, dict)):
            given = "a list" if isinstance(value, list) else "a spectrum file"
            raise ValueError(
                f"bottom.model {model!r} takes one {key}, not {given}: {model}'s angular shape "
                f"changes with {key}, and the spectral walk samples one shape for every "
                "wavelength; for a reflectance that varies with wavelength give albedo_scale "
                "(a number, one per wavelength or {file: CSV}: the BRDF times it)")
        return value
    return BeforeValidator(check)


class LambertianBottom(_Strict):
    model: Literal["lambertian"]
    reflectance: Reflectance
    sampling: Sampling = "auto"
    allow_unphysical: bool = False


MinnaertK = Annotated[float, Field(ge=0.0, le=100.0, allow_inf_nan=False)]


class MinnaertBottom(_Strict):
    """(rho/pi)(cos t_i cos t_r)^k; rho_dh = 2 rho cos^k(t_i)/(k + 2) <= 1 for k >= 0."""
    model: Literal["minnaert"]
    reflectance: Reflectance
    k: MinnaertK
    sampling: Sampling = "auto"
    allow_unphysical: bool = False


class SpecularBottom(_Strict):
    model: Literal["specular"]
    reflectance: Reflectance


class LambertianSpecularBottom(_Strict):
    """diffuse_reflectance/pi + specular_reflectance x mirror; rho_dh is their sum (at each
    wavelength: each part a number, one per wavelength or a spectrum)."""
    model: Literal["lambertian_specular"]
    diffuse_reflectance: Reflectance
    specular_reflectance: Reflectance
    allow_unphysical: bool = False


class GGXBottom(_Strict):
    """Glossy microfacets: GGX (Trowbridge-Reitz) with roughness alpha, height-correlated Smith
    shadowing, Fresnel reflection at facets of relative index n_ratio (fresnel: false makes them
    perfect mirrors, F = 1), plus an optional Lambertian term (kernel/brdf/ggx.py)."""
    model: Literal["ggx"]
    roughness: Annotated[float, Field(ge=0.01, le=1.0, allow_inf_nan=False)]
    n_ratio: Annotated[float, Field(gt=1.0, le=10.0, allow_inf_nan=False)] = 1.15
    fresnel: bool = True
    diffuse_reflectance: Annotated[Fraction, _one_value("ggx", "diffuse_reflectance")] = 0.0
    albedo_scale: AlbedoScale = 1.0
    sampling: Sampling = "auto"
    allow_unphysical: bool = False


class HapkeBottom(_Strict):
    """Hapke's model with the shadow-hiding opposition (hot-spot) term, for sediments
    (kernel/brdf/hapke.py): grain single-scattering albedo, Henyey-Greenstein asymmetry of the
    grains (negative: backward), opposition surge amplitude B0 and width h."""
    model: Literal["hapke"]
    albedo: Annotated[float, Field(gt=0.0, le=1.0, allow_inf_nan=False),
                      _one_value("hapke", "albedo")]
    asymmetry: Asymmetry = 0.0
    opposition_amplitude: Annotated[float, Field(ge=0.0, le=10.0, allow_inf_nan=False)] = 0.5
    opposition_width: Annotated[float, Field(gt=0.0, le=2.0, allow_inf_nan=False)] = 0.06
    albedo_scale: AlbedoScale = 1.0
    allow_unphysical: bool = False


class TableBottom(_Strict):
    """A measured BRDF on an angular grid from a file (brdf_tables.read_brdf_table): isotropic
    (theta_i, theta_r, dphi) or anisotropic (theta_i, phi_i, theta_r, dphi); values in 1/sr, or
    reflectance factors (pi f) with quantity: reflectance_factor."""
    model: Literal["table"]
    file: FilePath
    quantity: Literal["brdf", "reflectance_factor"] = "brdf"
    reciprocity_tolerance: Annotated[float, Field(gt=0.0, le=1.0, allow_inf_nan=False)] = 0.05
    albedo_scale: AlbedoScale = 1.0
    allow_unphysical: bool = False


# the fractions of a mixture add up to 1 within this
FRACTION_SUM_TOLERANCE = 1e-9


class BottomComponent(_Strict):
    """One bottom type of a mixture: the fraction of the bottom it covers, its model
    (lambertian, or minnaert with its k) and its reflectance (a number, a list or a spectrum)."""
    model: str
    fraction: Annotated[float, Field(gt=0.0, le=1.0, allow_inf_nan=False)]
    reflectance: Reflectance
    k: MinnaertK | None = None

    @field_validator("model")
    @classmethod
    def _one_shape(cls, model: str) -> str:
        if model not in ("lambertian", "minnaert"):
            raise ValueError(
                "allowed in a mixture: lambertian components, or minnaert components sharing "
                "one k (the spectral walk samples one BRDF shape for every wavelength, so a "
                "mixture must be one shape with a reflectance that varies with wavelength)")
        return model

    @model_validator(mode="after")
    def _k_for_minnaert(self) -> "BottomComponent":
        if self.model == "minnaert" and self.k is None:
            raise ValueError("k is required for a minnaert component")
        if self.model == "lambertian" and self.k is not None:
            raise ValueError(f"k = {self.k} given for a lambertian component; allowed: k only "
                             "with model: minnaert")
        return self


class MixtureBottom(_Strict):
    """An areal mixture of bottom types (benthic mapping's description of a pixel): each
    component covers its fraction of the bottom. The reflected light is the fraction-weighted
    sum of the components', so a mixture of Lambertian bottoms is exactly the Lambertian bottom
    of the fraction-weighted reflectance spectrum, and one of Minnaert bottoms of one k the
    Minnaert bottom of that k and the weighted reflectance: optics/bottom.py packs it as that
    bottom, and no kernel module of its own runs it. Components of different shapes (Minnaert
    of different k, GGX, Hapke, a table, a specular part) would need the kernel to sample a
    mixture of shapes; they are refused."""
    model: Literal["mixture"]
    components: Annotated[list[BottomComponent], Field(min_length=1, max_length=32)]
    sampling: Sampling = "auto"

    @model_validator(mode="after")
    def _one_bottom(self) -> "MixtureBottom":
        total = math.fsum(c.fraction for c in self.components)
        if abs(total - 1.0) > FRACTION_SUM_TOLERANCE:
            raise ValueError(f"components: the fractions add up to {total:.12g}; allowed: "
                             f"fractions in (0, 1] adding up to 1 (within "
                             f"{FRACTION_SUM_TOLERANCE:g})")
        first = self.components[0]
        for i, c in enumerate(self.components[1:], start=1):
            if c.model != first.model or c.k != first.k:
                given = f"{c.model}" + (f" with k = {c.k}" if c.k is not None else "")
                raise ValueError(
                    f"components[{i}] is {given}, components[0] {first.model}"
                    + (f" with k = {first.k}" if first.k is not None else "")
                    + "; allowed: components of one shape (all lambertian, or all minnaert of "
                    "one k): the spectral walk samples one BRDF shape for every wavelength")
        return self


Bottom = Annotated[
    Union[NoBottom, BlackBottom, LambertianBottom, MinnaertBottom, SpecularBottom,
          LambertianSpecularBottom, GGXBottom, HapkeBottom, TableBottom, MixtureBottom],
    Field(discriminator="model"),
]


def reflectance_keys(bottom) -> list[tuple[str, object]]:
    """(key path, value) of each reflectance of the bottom that may vary with wavelength."""
    if bottom.model == "mixture":
        return [(f"bottom.components[{i}].reflectance", c.reflectance)
                for i, c in enumerate(bottom.components)]
    if bottom.model in SPECTRAL_MODELS:
        return [("bottom.reflectance", bottom.reflectance)]
    if bottom.model == "lambertian_specular":
        return [("bottom.diffuse_reflectance", bottom.diffuse_reflectance),
                ("bottom.specular_reflectance", bottom.specular_reflectance)]
    if bottom.model in SCALED_MODELS:
        return [("bottom.albedo_scale", bottom.albedo_scale)]
    return []


def _largest(value) -> float:
    """The largest value a spectral key can take: a number, a list's largest, 1 for a spectrum
    file (its values lie within 0 .. 1)."""
    if isinstance(value, list):
        return max(value)
    return 1.0 if isinstance(value, ReflectanceSpectrum) else value


def check_bottom_wavelengths(bottom, n_wavelengths: int, spectral: bool) -> None:
    """A reflectance list has one value per wavelength; a list or a spectrum file needs
    wavelengths_nm (a spectrum needs the wavelengths to read it at)."""
    for key, value in reflectance_keys(bottom):
        check_count(key, value, n_wavelengths, spectral)
        if isinstance(value, ReflectanceSpectrum) and not spectral:
            raise ValueError(f"{key}.file = {value.file!r}: a reflectance spectrum needs "
                             "wavelengths_nm (one wavelength for a monochromatic run); give "
                             "wavelengths_nm or one number")


def bottom_has_mirror(bottom) -> bool:
    """Whether the bottom reflects part of the light as a mirror: a delta function, which a
    local (next-event) estimate cannot evaluate."""
    if bottom.model == "specular":
        return True
    return bottom.model == "lambertian_specular" and _largest(bottom.specular_reflectance) > 0.0


def bottom_weight_bounded(bottom) -> bool:
    """Whether the bottom's sampling weight f cos / pdf never exceeds 1 (analog bottom
    reflection survives with probability = weight, so it needs this)."""
    if bottom.model in ("hapke", "table") or getattr(bottom, "sampling", "auto") == "tabulated":
        return False
    # GGX without a Lambertian term weighs F G2 / G1 <= 1 at albedo_scale 1: times the packed
    # scale, the largest over the wavelengths (optics/bottom.py)
    return not (bottom.model == "ggx" and (bottom.diffuse_reflectance > 0.0
                                          or _largest(bottom.albedo_scale) > 1.0))
