"""Scene configuration: schema, defaults and validation.

A scene is read from YAML (or a dict), checked against the schema below and resolved into a
`SceneConfig` (pydantic models). Every problem is reported as one `ConfigError` that names the key
path, the offending value and what is allowed; nothing downstream sees an unchecked value.
"""
from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Any, Literal, Optional, Union

import yaml
from pydantic import (BaseModel, ConfigDict, Discriminator, Field, Tag, ValidationError,
                      field_validator, model_validator)


class ConfigError(ValueError):
    """A scene that cannot be run; the message names the key, the value and what is allowed."""


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", validate_default=True)


Finite = Annotated[float, Field(allow_inf_nan=False)]
NonNegative = Annotated[float, Field(ge=0.0, allow_inf_nan=False)]
Fraction = Annotated[float, Field(ge=0.0, le=1.0, allow_inf_nan=False)]
Asymmetry = Annotated[float, Field(gt=-1.0, lt=1.0, allow_inf_nan=False)]


# --- phase functions -------------------------------------------------------------------------

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
    file: str


BasicPhase = Annotated[
    Union[Isotropic, Rayleigh, PureWater, HenyeyGreenstein, TwoTermHG, FournierForand, Petzold,
          TablePhase],
    Field(discriminator="model"),
]


class MixtureComponent(_Strict):
    b: NonNegative
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


# --- water -----------------------------------------------------------------------------------

class Layer(_Strict):
    thickness_m: Annotated[float, Field(gt=0.0)]
    a: NonNegative
    b: NonNegative | None = None
    phase: Phase = Field(default_factory=lambda: Isotropic(model="isotropic"))

    @field_validator("thickness_m")
    @classmethod
    def _no_nan(cls, v: float) -> float:
        if math.isnan(v):
            raise ValueError("must be a positive number or .inf, got nan")
        return v

    @model_validator(mode="after")
    def _scattering(self) -> "Layer":
        if isinstance(self.phase, Mixture):
            total = sum(c.b for c in self.phase.components)
            if self.b is None:
                self.b = total
            elif not math.isclose(self.b, total, rel_tol=1e-9, abs_tol=1e-12):
                raise ValueError(f"b = {self.b} differs from the sum of the mixture's component b "
                                 f"({total}); give one or make them agree")
        elif self.b is None:
            raise ValueError("b (scattering coefficient, 1/m) is required")
        return self


class Water(_Strict):
    layers: list[Layer] = Field(min_length=1, max_length=100_000)

    @model_validator(mode="after")
    def _infinite_last_only(self) -> "Water":
        for i, layer in enumerate(self.layers):
            if math.isinf(layer.thickness_m):
                if i != len(self.layers) - 1:
                    raise ValueError(f"layers[{i}].thickness_m = .inf: only the last layer may be "
                                     "infinitely deep")
                if layer.a == 0.0 and layer.b > 0.0:
                    raise ValueError(f"layers[{i}]: an infinitely deep layer that scatters (b > 0) "
                                     "needs a > 0, or photons never leave it")
        return self

    @property
    def depth_m(self) -> float:
        return math.fsum(layer.thickness_m for layer in self.layers)


# --- illumination, surface, bottom -----------------------------------------------------------

class SkyMap(_Strict):
    """A sky radiance map from a file (sky_maps.py): an equirectangular (theta_view, phi_view)
    array in .npy, .npz or HDF5, or an OpenEXR image (.exr; the upper half of a 2:1 full-sphere
    image); its absolute scale is irrelevant (the sky's share of Ed0 is diffuse_fraction).
    dataset: the array in a .npz / HDF5 file; in an .exr, the channel to read (by default Y if
    present, else the Rec. 709 luminance of R, G, B). sampling: importance draws directions in
    proportion to L cos dOmega (every sky photon has the same weight); cosine draws them
    cosine-weighted over the hemisphere whatever L, each photon weighted by L(its cell) pi / E
    with E the integral of L cos dOmega: the same expectation, far more noise for a peaked map
    (for comparisons). layout (.exr only): what the image's rows cover: sphere (theta_view
    0..180 deg; the upper half is read), hemisphere (0..90 deg), or auto: sphere exactly when
    the image is twice as wide as it is high."""
    map: str
    dataset: str = "radiance"
    sampling: Literal["importance", "cosine"] = "importance"
    layout: Literal["auto", "hemisphere", "sphere"] = "auto"

    @model_validator(mode="after")
    def _layout_is_for_images(self) -> "SkyMap":
        if self.layout != "auto" and not self.map.lower().endswith(".exr"):
            raise ValueError(f"layout = {self.layout!r} with map = {self.map!r}: layout applies "
                             "to .exr images; a .npy, .npz or HDF5 map covers theta_view "
                             "0..90 deg (or its own theta_edges_deg); leave layout out")
        return self


class Illumination(_Strict):
    """sky: uniform; cardioidal or overcast (the CIE standard overcast sky, L ~ 1 + 2 cos Z;
    Moon & Spencer 1942); harrison_coombes (clear sky, Harrison & Coombes 1988, with the sun at
    sun_zenith_deg); or {map: FILE} (sky_maps.py)."""
    Ed0: Annotated[float, Field(gt=0.0, allow_inf_nan=False)] = 1.0
    sun_zenith_deg: Annotated[float, Field(ge=0.0, lt=90.0, allow_inf_nan=False)] = 30.0
    diffuse_fraction: Fraction = 0.0
    sky: Annotated[Union[Annotated[Literal["uniform", "cardioidal", "overcast",
                                           "harrison_coombes"], Tag("sky_name")],
                         Annotated[SkyMap, Tag("SkyMap")]],
                   Discriminator(lambda v: "SkyMap" if isinstance(v, (dict, SkyMap))
                                 else "sky_name")] = "uniform"


class Surface(_Strict):
    """flat: exact unpolarized Fresnel + Snell; none: no interface (index-matched, n = 1).
    fresnel: schlick swaps in Schlick's approximation, for comparisons only (never exact)."""
    model: Literal["flat", "none"] = "flat"
    n_water: Annotated[float, Field(ge=1.0, le=3.0, allow_inf_nan=False)] = 1.34
    fresnel: Literal["exact", "schlick"] = "exact"


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
    asymmetry: Annotated[float, Field(gt=-1.0, lt=1.0, allow_inf_nan=False)] = 0.0
    opposition_amplitude: Annotated[float, Field(ge=0.0, le=10.0, allow_inf_nan=False)] = 0.5
    opposition_width: Annotated[float, Field(gt=0.0, le=2.0, allow_inf_nan=False)] = 0.06
    allow_unphysical: bool = False


class TableBottom(_Strict):
    """A measured BRDF on an angular grid from a file (brdf_tables.read_brdf_table): isotropic
    (theta_i, theta_r, dphi) or anisotropic (theta_i, phi_i, theta_r, dphi); values in 1/sr, or
    reflectance factors (pi f) with quantity: reflectance_factor."""
    model: Literal["table"]
    file: str
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


# --- tallies and estimator -------------------------------------------------------------------

HYDROLIGHT_THETA_EDGES_DEG = (0.0, 5.0, 15.0, 25.0, 35.0, 45.0, 55.0, 65.0, 75.0, 85.0, 90.0,
                              95.0, 105.0, 115.0, 125.0, 135.0, 145.0, 155.0, 165.0, 175.0, 180.0)


class Tallies(_Strict):
    depths_m: list[NonNegative] = Field(default_factory=lambda: [0.0], max_length=10_000)
    theta_edges_deg: Literal["hydrolight"] | list[Finite] = "hydrolight"
    phi_bands: Annotated[int, Field(ge=1, le=360)] = 24
    radiance: bool = True
    local_directions_deg: list[tuple[Annotated[float, Field(gt=90.0, le=180.0,
                                                           allow_inf_nan=False)],
                                     Annotated[float, Field(ge=0.0, lt=360.0,
                                                           allow_inf_nan=False)]]] \
        = Field(default_factory=list, max_length=64)
    grazing_mu_cut: Annotated[float, Field(gt=0.0, le=0.1, allow_inf_nan=False)] = 0.01
    nadir_estimator: Literal["auto", "local", "crossing"] = "auto"

    @field_validator("depths_m")
    @classmethod
    def _sorted_unique(cls, v: list[float]) -> list[float]:
        return sorted(set(v))

    @field_validator("theta_edges_deg")
    @classmethod
    def _edges(cls, v):
        if v == "hydrolight":
            return v
        if len(v) < 2 or v[0] != 0.0 or v[-1] != 180.0:
            raise ValueError(f"must start at 0 and end at 180 (deg), got {v}")
        if any(b <= a for a, b in zip(v, v[1:])):
            raise ValueError(f"must increase strictly, got {v}")
        if 90.0 not in v:
            raise ValueError(f"must include 90 so that no band straddles the horizontal, got {v}")
        return v

    @property
    def theta_edges(self) -> tuple[float, ...]:
        if self.theta_edges_deg == "hydrolight":
            return HYDROLIGHT_THETA_EDGES_DEG
        return tuple(self.theta_edges_deg)


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
    max_events: Annotated[int, Field(ge=100)] = 1_000_000
    split_weight: Optional[Annotated[float, Field(gt=1.0, allow_inf_nan=False)]] = None
    # scattering biased toward straight up (kernel/upward.py): off (null) by default
    upward_fraction: Optional[Annotated[float, Field(gt=0.0, lt=1.0, allow_inf_nan=False)]] = None
    upward_cone_deg: Annotated[float, Field(gt=0.0, le=90.0, allow_inf_nan=False)] = 15.0


class SceneConfig(_Strict):
    name: str = "oceanmc scene"
    photons: Annotated[int, Field(gt=0, le=10**13)] = 1_000_000
    seed: Annotated[int, Field(ge=0, lt=2**63)] = 1
    batches: Annotated[int, Field(ge=2, le=100_000)] = 32
    illumination: Illumination = Field(default_factory=Illumination)
    surface: Surface = Field(default_factory=Surface)
    water: Water
    bottom: Bottom
    tallies: Tallies = Field(default_factory=Tallies)
    estimator: Estimator = Field(default_factory=Estimator)

    @model_validator(mode="after")
    def _consistent(self) -> "SceneConfig":
        deep = math.isinf(self.water.layers[-1].thickness_m)
        if deep and self.bottom.model != "none":
            raise ValueError(f"bottom.model = {self.bottom.model!r} below an infinitely deep last "
                             "layer: use bottom.model = 'none'")
        if not deep and self.bottom.model == "none":
            raise ValueError("bottom.model = 'none' needs an infinitely deep last layer "
                             "(thickness_m: .inf); a finite water column needs a bottom "
                             "(black, lambertian, minnaert, specular, lambertian_specular, "
                             "ggx, hapke, table)")
        depth = self.water.depth_m
        for d in self.tallies.depths_m:
            if d > depth * (1.0 + 1e-12):
                raise ValueError(f"tallies.depths_m contains {d} m, below the bottom at "
                                 f"{depth} m; allowed: 0 <= depth <= {depth}")
        if self.photons < 2 * self.batches:
            raise ValueError(f"photons = {self.photons}: need at least 2 per batch "
                             f"(batches = {self.batches})")
        if self.tallies.nadir_estimator == "local" and bottom_has_mirror(self.bottom):
            raise ValueError(f"tallies.nadir_estimator = 'local' with bottom.model = "
                             f"{self.bottom.model!r}: a mirror has no density for a local "
                             "estimate; use 'crossing' or 'auto'")
        if self.tallies.local_directions_deg and bottom_has_mirror(self.bottom):
            raise ValueError(f"tallies.local_directions_deg with bottom.model = "
                             f"{self.bottom.model!r}: a mirror has no density for a local "
                             "estimate; use the quad radiances")
        if self.estimator.mode == "analog" and self.estimator.upward_fraction is not None:
            raise ValueError(f"estimator.upward_fraction = {self.estimator.upward_fraction} "
                             "with estimator.mode = 'analog': the biased scattering changes "
                             "weights, which the analog walk keeps at 1; use "
                             "estimator.mode = 'implicit' or upward_fraction: null")
        if self.estimator.mode == "analog" and not bottom_weight_bounded(self.bottom):
            raise ValueError(f"estimator.mode = 'analog' with bottom.model = "
                             f"{self.bottom.model!r} sampled by weight f cos/pdf, which can "
                             "exceed 1: analog bottom reflection (survival with probability = "
                             "weight) cannot carry it; use estimator.mode = 'implicit'")
        return self

    @property
    def nadir_local(self) -> bool:
        """Whether Lu, Lw_nadir and Rrs_nadir come from the local (cap) estimator."""
        mode = self.tallies.nadir_estimator
        return mode == "local" or (mode == "auto" and not bottom_has_mirror(self.bottom))

    @property
    def n_water(self) -> float:
        return self.surface.n_water if self.surface.model == "flat" else 1.0


# --- loading ---------------------------------------------------------------------------------

def _key_path(loc: tuple) -> str:
    path = ""
    for part in loc:
        if isinstance(part, int):
            path += f"[{part}]"
        elif part in {"isotropic", "rayleigh", "pure_water", "henyey_greenstein", "two_term_hg",
                      "fournier_forand", "petzold", "table", "mixture", "none", "black",
                      "lambertian", "minnaert", "specular", "lambertian_specular", "ggx",
                      "hapke", "SkyMap", "sky_name"} or str(part).startswith(("list[", "literal[")):
            continue  # pydantic's union-branch tags are not keys the user wrote
        else:
            path += ("." if path else "") + str(part)
    return path or "(top level)"


def _describe(error: dict) -> str:
    path = _key_path(tuple(error.get("loc", ())))
    kind = error.get("type", "")
    ctx = error.get("ctx") or {}
    msg = error.get("msg", "invalid")
    if msg.startswith("Value error, "):
        msg = msg[len("Value error, "):]
    if kind == "extra_forbidden":
        return f"{path}: unknown key (check its spelling and level)"
    if kind == "missing":
        return f"{path}: required key is missing"
    if kind == "union_tag_invalid":
        return (f"{path}.model = {ctx.get('tag')!r}: unknown model; allowed: "
                f"{ctx.get('expected_tags')}")
    if kind == "union_tag_not_found":
        return f"{path}.model: required key is missing"
    if path == "(top level)" and kind == "value_error":
        return msg
    if "input" in error and not isinstance(error["input"], dict):
        shown = repr(error["input"])
        if len(shown) > 80:
            shown = shown[:77] + "..."
        return f"{path} = {shown}: {msg}"
    return f"{path}: {msg}"


def load_config(source: str | Path | dict[str, Any], overrides: dict[str, Any] | None = None
                ) -> SceneConfig:
    """Reads a scene from a YAML file path or a dict, applies top-level overrides (photons, seed),
    and returns the validated SceneConfig. Raises ConfigError with one clear message."""
    origin = "config"
    if isinstance(source, (str, Path)):
        path = Path(source)
        origin = str(path)
        try:
            text = path.read_text(encoding="utf-8")
        except FileNotFoundError:
            raise ConfigError(f"{origin}: no such file") from None
        except (OSError, UnicodeDecodeError) as exc:
            raise ConfigError(f"{origin}: cannot read it ({exc})") from None
        try:
            data = yaml.safe_load(text)
        except yaml.YAMLError as exc:
            raise ConfigError(f"{origin}: not valid YAML ({str(exc).splitlines()[0]} "
                              f"{getattr(exc, 'problem_mark', '') or ''})".strip()) from None
        except RecursionError:
            raise ConfigError(f"{origin}: nested too deeply to be a scene") from None
        base_dir = path.parent
    elif isinstance(source, dict):
        data = source
        base_dir = Path.cwd()
    else:
        raise ConfigError(f"{origin}: expected a YAML file path or a mapping, got "
                          f"{type(source).__name__}")
    if data is None:
        raise ConfigError(f"{origin}: the file is empty; a scene needs at least water and bottom")
    if not isinstance(data, dict):
        raise ConfigError(f"{origin}: the top level must be a mapping of keys (name, photons, "
                          f"water, bottom, ...), got {type(data).__name__}")
    data = dict(data)
    for key, value in (overrides or {}).items():
        if value is not None:
            data[key] = value
    try:
        config = SceneConfig.model_validate(data)
    except ValidationError as exc:
        errors = exc.errors()
        first = _describe(errors[0])
        more = f" (and {len(errors) - 1} more problem{'s' if len(errors) > 2 else ''})" \
            if len(errors) > 1 else ""
        raise ConfigError(f"{origin}: {first}{more}") from None
    except RecursionError:
        raise ConfigError(f"{origin}: nested too deeply to be a scene") from None
    _resolve_files(config, base_dir, origin)
    return config


def _resolve_files(config: SceneConfig, base_dir: Path, origin: str) -> None:
    """Table files are relative to the config file's folder; they are checked when the scene is
    built (scene.py), which reports the file and the problem."""
    for layer in config.water.layers:
        phases = [c.phase for c in layer.phase.components] \
            if isinstance(layer.phase, Mixture) else [layer.phase]
        for phase in phases:
            if isinstance(phase, TablePhase):
                phase.file = str((base_dir / phase.file).resolve())
    if isinstance(config.bottom, TableBottom):
        config.bottom.file = str((base_dir / config.bottom.file).resolve())
    if isinstance(config.illumination.sky, SkyMap):
        config.illumination.sky.map = str((base_dir / config.illumination.sky.map).resolve())


def config_to_yaml(config: SceneConfig) -> str:
    """The full resolved scene (defaults filled in) as YAML text; load_config reads it back."""
    return yaml.safe_dump(config.model_dump(), sort_keys=False, allow_unicode=True)
