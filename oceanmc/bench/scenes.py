"""The benchmark's scenes: error-against-time scenes with their headline quantities and
references, the sky-spot scenes, the feature rows, the start-up scenes."""
from __future__ import annotations

import copy
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..config import config_to_yaml, load_config
from ..kernel.surface.fresnel import fresnel


@dataclass
class Quantity:
    label: str
    name: str            # Result key
    index: tuple = ()    # index into the Result array



# --- references --------------------------------------------------------------------------------

def snell_window_reference(config) -> dict[str, float]:
    """Uniform sky, black clear water: Ed(0-) = Ed0 (1 - r) with r the cosine-weighted Fresnel
    reflectance, and the 0-5 deg downward cap radiance just below the surface =
    average over the cap of t(theta_air) n^2 L_sky, L_sky = Ed0 / pi (DESIGN.md section 4)."""
    n = config.surface.n_water
    ed0 = config.illumination.Ed0
    mu = np.linspace(0.0, 1.0, 20001)[1:]
    r = np.array([fresnel(1.0, n, m)[0] for m in mu])
    ed_0minus = ed0 * (1.0 - np.trapezoid(2.0 * r * mu, mu))
    mu_w = np.linspace(math.cos(math.radians(5.0)), 1.0, 2001)
    sin_a = np.sqrt(1.0 - mu_w ** 2) * n
    t = np.array([1.0 - fresnel(1.0, n, math.sqrt(1.0 - s * s))[0] for s in sin_a])
    cap = np.trapezoid(t * n * n * ed0 / math.pi, mu_w) / (1.0 - mu_w[0])
    return {"Ed(0-)": float(ed_0minus), "L cap down (0-)": float(cap)}


# --- scenes ------------------------------------------------------------------------------------

def without_exact_directions(config):
    return with_photons(config, config.photons, **{"tallies.local_directions_deg": []})


CROSSING_ONLY = ", crossing estimator only"
NO_ROULETTE = ", roulette at weight 1e-12"
UPWARD_FRACTION = 0.1
UPWARD = f", upward-biased scattering (fraction {UPWARD_FRACTION:g})"


def scenes(configs_dir: Path) -> list[dict]:
    """The benchmark scenes with their headline quantities and references: None (a long run
    of their own), a scene's name (that scene's long run) or a dict of analytic values."""
    def cfg(name):
        return load_config(configs_dir / name)
    snell = cfg("snell_window.yaml")
    bare = cfg("bare_walk.yaml")
    # their headline quantities come from the cap estimates: the exact-nadir local estimates of
    # the example configs (a Petzold phase-function evaluation per collision) are left out
    clear, shallow = (without_exact_directions(cfg(name))
                      for name in ("clear_ocean.yaml", "coastal_sand.yaml"))
    return [
        {"name": "bare walk", "config": bare, "reference": None,
         "quantities": [Quantity("reflectance (water-leaving)", "budget/water_leaving"),
                        Quantity("Ed(1 m)", "Ed", (1,))]},
        {"name": "clear ocean", "config": clear, "reference": None,
         "quantities": [Quantity("Rrs nadir (local)", "air/Rrs_nadir"),
                        Quantity("Rrs nadir (crossing)", "air/Rrs_nadir_crossing"),
                        Quantity("Lu(10 m) (local)", "Lu", (2,)),
                        Quantity("Lu(10 m) (crossing)", "Lu_crossing", (2,)),
                        Quantity("Ed(10 m)", "Ed", (2,))]},
        # plain photon counting on its own: the fair time for the crossing estimates
        {"name": f"clear ocean{CROSSING_ONLY}", "reference": "clear ocean",
         "config": with_photons(clear, clear.photons, **{"tallies.nadir_estimator": "crossing"}),
         "quantities": [Quantity("Rrs nadir (crossing)", "air/Rrs_nadir"),
                        Quantity("Lu(10 m) (crossing)", "Lu", (2,)),
                        Quantity("Ed(10 m)", "Ed", (2,))]},
        # Russian roulette's worth: the same scene with roulette at a weight packets never
        # reach in practice (they are followed until they leave or the weight underflows)
        {"name": f"clear ocean{NO_ROULETTE}", "reference": "clear ocean",
         "config": with_photons(clear, clear.photons, **{"estimator.roulette_weight": 1e-12}),
         "quantities": [Quantity("Rrs nadir (local)", "air/Rrs_nadir"),
                        Quantity("Lu(10 m) (local)", "Lu", (2,)),
                        Quantity("Ed(10 m)", "Ed", (2,))]},
        # scattering biased toward straight up: the same expectations, so the plain scene's
        # long run is its reference
        {"name": f"clear ocean{UPWARD}", "reference": "clear ocean",
         "config": with_photons(clear, clear.photons,
                                **{"estimator.upward_fraction": UPWARD_FRACTION}),
         "quantities": [Quantity("Rrs nadir (local)", "air/Rrs_nadir"),
                        Quantity("Rrs nadir (crossing)", "air/Rrs_nadir_crossing"),
                        Quantity("Lu(10 m) (local)", "Lu", (2,)),
                        Quantity("Lu(10 m) (crossing)", "Lu_crossing", (2,)),
                        Quantity("Ed(10 m)", "Ed", (2,))]},
        {"name": "shallow sand", "config": shallow, "reference": None,
         "quantities": [Quantity("Rrs nadir (local)", "air/Rrs_nadir"),
                        Quantity("Rrs nadir (crossing)", "air/Rrs_nadir_crossing"),
                        Quantity("Eu(0-)", "Eu", (0,))]},
        {"name": f"shallow sand{UPWARD}", "reference": "shallow sand",
         "config": with_photons(shallow, shallow.photons,
                                **{"estimator.upward_fraction": UPWARD_FRACTION}),
         "quantities": [Quantity("Rrs nadir (local)", "air/Rrs_nadir"),
                        Quantity("Rrs nadir (crossing)", "air/Rrs_nadir_crossing"),
                        Quantity("Eu(0-)", "Eu", (0,))]},
        # the rough sea against the flat one: exact-nadir Rrs by local estimates through the
        # surface (each its own long run: the two surfaces give different Rrs)
        {"name": f"clear ocean{FLAT_NADIR}", "reference": None,
         "config": with_photons(clear, clear.photons, **NADIR_LOCAL),
         "quantities": [Quantity("Rrs exact nadir (local)", "air/Rrs_local", (0,))]},
        {"name": f"clear ocean{ROUGH_NADIR}", "reference": None,
         "config": with_photons(clear, clear.photons, **NADIR_LOCAL, surface={
             "model": "cox_munk", "n_water": clear.surface.n_water, "wind_speed_m_s": 5.0}),
         "quantities": [Quantity("Rrs exact nadir (local)", "air/Rrs_local", (0,))]},
        {"name": "Snell's window", "config": snell, "reference": snell_window_reference(snell),
         "quantities": [Quantity("Ed(0-)", "Ed", (0,)),
                        Quantity("L cap down (0-)", "radiance", (0, 0, 0))]},
    ]


SPOT_ZENITH_DEG = 40.0       # the bright spot's centre, seen at phi_view = 180 deg
SPOT_RADIUS_DEG = 2.0
SPOT_CONTRAST = 1000.0       # spot radiance over the background's
IMPORTANCE, COSINE = "(importance sampling)", "(cosine sampling)"
SPLIT_WEIGHT = 2.0
COSINE_SPLIT = f"(cosine sampling, split_weight {SPLIT_WEIGHT:g})"
SKY_SPOT = "sky map with a small bright spot"


def sky_spot_map(path: Path) -> Path:
    """Writes a 1 x 1 deg sky map (.npy): radiance 1, and SPOT_CONTRAST inside the cells whose
    centres lie within SPOT_RADIUS_DEG of the spot's centre (20 cells, ~0.004 sr, half of the
    sky's irradiance)."""
    theta = np.radians(np.arange(90) + 0.5)[:, None]
    phi = np.radians(np.arange(360) + 0.5)[None, :]
    centre = math.radians(SPOT_ZENITH_DEG)
    cos_from_centre = (np.cos(theta) * math.cos(centre)
                       + np.sin(theta) * math.sin(centre) * np.cos(phi - math.pi))
    inside = cos_from_centre >= math.cos(math.radians(SPOT_RADIUS_DEG))
    np.save(path, np.where(inside, SPOT_CONTRAST, 1.0))
    return path


def sky_spot_scenes(map_path: Path) -> list[dict]:
    """The spot map over clear, weakly scattering deep water, all light from the sky, sampled
    by importance, cosine-weighted, and cosine-weighted with splitting of the heavy packets
    (the spot's, weight ~500): the same expectations, so one reference serves all three."""
    def config(sampling, split_weight=None):
        return load_config({
            "name": f"{SKY_SPOT}, {sampling} sampling", "seed": 1,
            "estimator": {"split_weight": split_weight},
            "illumination": {"Ed0": 1.0, "diffuse_fraction": 1.0,
                             "sky": {"map": str(map_path), "sampling": sampling}},
            "water": {"layers": [{"thickness_m": math.inf, "a": 0.1, "b": 0.2,
                                  "phase": {"model": "henyey_greenstein", "g": 0.9}}]},
            "bottom": {"model": "none"}, "tallies": {"depths_m": [0.0, 5.0]}})
    importance = config("importance")
    # the spot's light travels at phi = 0 (phi_view + 180 deg), refracted by Snell's law
    n = importance.surface.n_water
    refracted = math.degrees(math.asin(math.sin(math.radians(SPOT_ZENITH_DEG)) / n))
    band = int(np.searchsorted(importance.tallies.theta_edges, refracted, side="right")) - 1
    quantities = [Quantity("Ed(0-)", "Ed", (0,)), Quantity("Ed(5 m)", "Ed", (1,)),
                  Quantity("Eou(0-)", "Eou", (0,)), Quantity("Lu(0-) (local)", "Lu", (0,)),
                  Quantity(f"L of the spot's quad (0-, {refracted:.1f} deg)", "radiance",
                           (0, band, 0))]
    return [{"name": f"{SKY_SPOT} {IMPORTANCE}", "config": importance, "reference": None,
             "quantities": quantities},
            {"name": f"{SKY_SPOT} {COSINE}", "config": config("cosine"), "reference": None,
             "quantities": quantities},
            {"name": f"{SKY_SPOT} {COSINE_SPLIT}", "config": config("cosine", SPLIT_WEIGHT),
             "reference": None, "quantities": quantities}]


FLAT_NADIR, ROUGH_NADIR = " (flat surface, exact nadir)", " (rough sea 5 m/s, exact nadir)"
NADIR_LOCAL = {"tallies.nadir_estimator": "crossing",
               "tallies.local_directions_deg": [[180.0, 0.0]]}


def with_photons(config, photons: int, **changes):
    data = copy.deepcopy(config.model_dump())
    data["photons"] = int(photons)
    for path, value in changes.items():
        node = data
        keys = path.split(".")
        for key in keys[:-1]:
            node = node[key]
        node[keys[-1]] = value
    return load_config(data)



FEATURES: list[tuple[str, dict]] = [
    ("no tallies at all", {"tallies.depths_m": [], "tallies.radiance": False,
                           "tallies.nadir_estimator": "crossing"}),
    ("irradiances at 0, 1 m (radiance off)", {"tallies.radiance": False,
                                              "tallies.nadir_estimator": "crossing"}),
    ("+ radiance quads (the bare-walk config)", {}),
    ("+ local nadir-cap estimate", {"tallies.nadir_estimator": "local"}),
    ("+ local estimate, exact nadir", {"tallies.nadir_estimator": "local",
                                       "tallies.local_directions_deg": [[180.0, 0.0]]}),
    ("+ sky (20% uniform)", {"illumination.diffuse_fraction": 0.2}),
    ("+ Lambertian bottom (0.3)", {"bottom": {"model": "lambertian", "reflectance": 0.3}}),
    (f"+ upward-biased scattering (fraction {UPWARD_FRACTION:g}; shorter histories)",
     {"estimator.upward_fraction": UPWARD_FRACTION}),
    ("no surface (index-matched)", {"surface.model": "none"}),
    ("rough surface (cox_munk, 5 m/s)", {"surface": {"model": "cox_munk", "n_water": 1.34,
                                                     "wind_speed_m_s": 5.0}}),
    ("analog estimator", {"estimator.mode": "analog"}),
    ("Petzold phase function (tabulated)", {"water": {"layers": [
        {"thickness_m": 1, "a": 0.1, "b": 0.9, "phase": {"model": "petzold"}}]}}),
]

# The same rows as measured with the kernel before the component records (c077515's
# benchmarks/bench.md, full run of 2026-11-21): photons/s on 1 thread, and the bare walk's
# photons/s on 1 thread in that run. The report sets today's ratios to the bare walk beside
# those ratios.
FEATURES_BEFORE = {"bare walk": 5_083_073, "no tallies at all": 4_752_437,
                   "irradiances at 0, 1 m (radiance off)": 4_734_150,
                   "+ radiance quads (the bare-walk config)": 4_188_623,
                   "+ local nadir-cap estimate": 2_981_187,
                   "+ local estimate, exact nadir": 2_500_212, "+ sky (20% uniform)": 3_808_671,
                   "+ Lambertian bottom (0.3)": 1_199_230,
                   f"+ upward-biased scattering (fraction {UPWARD_FRACTION:g}; shorter "
                   "histories)": 4_106_959,
                   "no surface (index-matched)": 5_616_350, "analog estimator": 4_631_898}


# start-up: the bare-walk scene with every feature the issue names in one loop
ALL_FEATURES = {"illumination.diffuse_fraction": 0.2,
                "bottom": {"model": "lambertian", "reflectance": 0.3},
                "tallies.radiance": True, "tallies.local_directions_deg": [[180.0, 0.0]]}
FIRST_STARTUP_CONFIG = "default.yaml"   # the scene of the cached command-line run
# the --quick smoke test starts only this scene with an empty cache (the fewest features), and
# only these scenes with a cache
QUICK_COLD_START = "bare_walk.yaml"
QUICK_CONFIGS = ("bare_walk.yaml", "clear_ocean.yaml")


def startup_scenes(configs_dir: Path, folder: Path, quick: bool) -> list[tuple[str, Path]]:
    """The start-up scenes as (label, config file): every shipped config (issue 26 asks a cold
    start of each within 15 s: each compiles the variant of the photon loop with its own parts,
    kernel/variants.py; quick: QUICK_CONFIGS), default.yaml first, and the bare walk with sky, a
    Lambertian bottom, radiance quads and an exact-nadir local estimate (written to folder, for
    `oceanmc run`)."""
    bare = load_config(configs_dir / "bare_walk.yaml")
    features = with_photons(bare, bare.photons, **ALL_FEATURES)
    path = folder / "bare_walk_all_features.yaml"
    path.write_text(config_to_yaml(features))
    names = [config.name for config in sorted(configs_dir.glob("*.yaml"))
             if config.name != FIRST_STARTUP_CONFIG and (not quick or config.name in QUICK_CONFIGS)]
    return ([(name, configs_dir / name) for name in [FIRST_STARTUP_CONFIG, *names]]
            + [("bare_walk.yaml + sky, Lambertian bottom, radiance, local estimate", path)])
