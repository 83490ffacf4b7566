"""Scene configuration: schema, defaults and validation.

A scene is read from YAML (or a dict), checked against the schema and resolved into a
`SceneConfig` (pydantic models). Every problem is reported as one `ConfigError` that names the key
path, the offending value and what is allowed; nothing downstream sees an unchecked value.

The schema, by component: base (ConfigError, the strict base model, number types), phase, water,
illumination, surface, bottom, tallies, estimator, scene (SceneConfig and the checks across
components); loading (load_config, config_to_yaml). Every name is re-exported here.
"""
from .base import Asymmetry, ConfigError, Finite, Fraction, NonNegative, _Strict
from .bottom import (BlackBottom, Bottom, BottomComponent, GGXBottom, HapkeBottom,
                     LambertianBottom, LambertianSpecularBottom, MinnaertBottom, MixtureBottom,
                     NoBottom, ReflectanceSpectrum, Sampling, SpecularBottom, TableBottom,
                     bottom_has_mirror, bottom_weight_bounded)
from .components import (Case1Component, CdomComponent, ChlorophyllComponent, Component,
                         ConstantComponent, GaussianProfile, LinearProfile, ParticlesComponent,
                         Profile, PureWaterComponent, TableComponent, TableProfile)
from .estimator import Estimator
from .illumination import (FlatSpectrum, Illumination, SkyMap, Spectrl2Spectrum, Spectrum,
                           SunPosition, TableSpectrum)
from .loading import (_describe, _key_path, _resolve_files, config_to_yaml, data_file_hashes,
                      load_config)
from .phase import (BasicPhase, FournierForand, HenyeyGreenstein, Isotropic, Mixture,
                    MixtureComponent, Petzold, Phase, PureWater, Rayleigh, TablePhase, TwoTermHG)
from .scene import SceneConfig
from .surface import Surface
from .tallies import HYDROLIGHT_THETA_EDGES_DEG, Tallies
from .water import Layer, Water
from .wavelengths import WavelengthRange

__all__ = [
    "ConfigError", "Finite", "NonNegative", "Fraction", "Asymmetry",
    "Isotropic", "Rayleigh", "PureWater", "HenyeyGreenstein", "TwoTermHG", "FournierForand",
    "Petzold", "TablePhase", "BasicPhase", "MixtureComponent", "Mixture", "Phase",
    "Layer", "Water", "WavelengthRange",
    "GaussianProfile", "LinearProfile", "TableProfile", "Profile", "PureWaterComponent",
    "ChlorophyllComponent", "Case1Component", "CdomComponent", "ParticlesComponent",
    "TableComponent", "ConstantComponent", "Component",
    "SkyMap", "Illumination", "SunPosition", "FlatSpectrum", "Spectrl2Spectrum", "TableSpectrum",
    "Spectrum",
    "Surface",
    "NoBottom", "BlackBottom", "Sampling", "LambertianBottom", "MinnaertBottom",
    "SpecularBottom", "LambertianSpecularBottom", "GGXBottom", "HapkeBottom", "TableBottom",
    "ReflectanceSpectrum", "BottomComponent", "MixtureBottom", "Bottom", "bottom_has_mirror",
    "bottom_weight_bounded",
    "HYDROLIGHT_THETA_EDGES_DEG", "Tallies",
    "Estimator",
    "SceneConfig",
    "load_config", "config_to_yaml",
]
