"""All wavelengths in one photon history (kernel/spectral.py): every wavelength of a spectral run
against an independent single-wavelength run of the same scene (z against both standard errors,
Bonferroni bound over the values compared, fixed seeds), energy closure per wavelength, the
sun/sky shares of a spectral illumination, the results' wavelength dimension and the scenes the
spectral walk refuses."""
import copy

import numpy as np
import pytest

import oceanmc
from oceanmc.config import ConfigError
from oceanmc.scene.medium import hero_probabilities

from stats_helpers import assert_z, dof_of

THREADS = 2
WAVELENGTHS = [440.0, 550.0, 670.0]
# one 4 m layer whose a, b and Fournier-Forand backscatter fraction all change with wavelength
# (so the free paths, albedos and phase functions of the wavelengths differ), over sand
SCENE = {
    "name": "three wavelengths over sand",
    "photons": 80_000, "batches": 16, "seed": 11,
    "wavelengths_nm": WAVELENGTHS,
    "illumination": {"sun_zenith_deg": 40, "diffuse_fraction": 0.3},
    "water": {"layers": [{"thickness_m": 4.0, "a": [0.03, 0.08, 0.5], "b": [0.6, 0.45, 0.3],
                          "bb_ratio": [0.03, 0.02, 0.01]}]},
    "bottom": {"model": "lambertian", "reflectance": 0.3},
    "tallies": {"depths_m": [0, 2, 4], "nadir_estimator": "crossing"},
}
COMPARED = ("Ed", "Eu", "Eo", "air/Eu", "budget/water_leaving", "budget/absorbed_bottom",
            "budget/absorbed_layer_1")


def single(config: dict, k: int, seed: int) -> dict:
    """The same scene at wavelength k alone, by the default (implicit, unbiased) walk."""
    out = copy.deepcopy(config)
    out.pop("estimator", None)
    out["wavelengths_nm"] = [config["wavelengths_nm"][k]]
    out["seed"] = seed
    out["photons"] = 40_000
    layer = out["water"]["layers"][0]
    for part in [layer] + layer.get("components", []):
        for key in ("a", "b", "bb_ratio"):
            if isinstance(part.get(key), list):
                part[key] = [part[key][k]]
    return out


def compare_with_singles(config: dict, compared=COMPARED, rel_max: float = 0.1) -> None:
    spectral = oceanmc.simulate(config, threads=THREADS)
    singles = [oceanmc.simulate(single(config, k, 100 + k), threads=THREADS)
               for k in range(len(config["wavelengths_nm"]))]
    n_compared = sum(spectral[name].size for name in compared)
    for name in compared:
        reference = np.stack([s[name] for s in singles])
        ref_se = np.stack([s.stderr(name) for s in singles])
        assert_z(spectral[name], reference, np.hypot(spectral.stderr(name), ref_se),
                 n_compared=n_compared, dof=dof_of(spectral), rel_max=rel_max, abs_max=2e-3,
                 what=name)
    # energy closure at every wavelength
    assert_z(spectral["budget/total"], 1.0, spectral.stderr("budget/total"),
             dof=dof_of(spectral), abs_max=3e-3, what="budget/total")


def test_one_history_matches_single_wavelength_runs():
    compare_with_singles(SCENE)


def test_hero_probabilities_follow_the_walks_lengths():
    """pi_j in proportion to (1 / (1 - w0_j))^exponent, 1 - w0 taken as at least 0.01; uniform
    at exponent 0."""
    albedo = np.array([0.0, 0.5, 0.9, 0.999])
    np.testing.assert_allclose(hero_probabilities(albedo, 1.0),
                               np.array([1.0, 2.0, 10.0, 100.0]) / 113.0, rtol=1e-12)
    np.testing.assert_allclose(hero_probabilities(albedo, 0.5),
                               np.sqrt([1.0, 2.0, 10.0, 100.0]) / sum(np.sqrt([1, 2, 10, 100])),
                               rtol=1e-12)
    np.testing.assert_allclose(hero_probabilities(albedo, 0.0), 0.25, rtol=1e-12)


@pytest.mark.parametrize("exponent", [0.0, 2.0])
def test_one_history_with_other_hero_probabilities_matches_single_wavelength_runs(exponent):
    """Any hero probabilities give the same light (the default exponent is 1): uniform, and the
    largest exponent allowed, whose heroes are 89% at 440 nm and 0.6% at 670 nm here (a K
    that did not start at n pi_j would weigh each path by the wrong mixture)."""
    config = copy.deepcopy(SCENE)
    config["estimator"] = {"hero_exponent": exponent}
    compare_with_singles(config, rel_max=0.2)


def test_one_history_matches_single_wavelength_runs_deep_turbid():
    config = copy.deepcopy(SCENE)
    config["water"]["layers"] = [{"thickness_m": float("inf"), "a": [0.9, 0.4, 0.7],
                                  "b": [3.0, 2.6, 2.2], "bb_ratio": 0.018}]
    config["bottom"] = {"model": "none"}
    config["tallies"]["depths_m"] = [0, 1, 3]
    compare_with_singles(config, tuple(n for n in COMPARED if n != "budget/absorbed_bottom"))


def test_spectral_illumination_sun_and_sky_shares(tmp_path):
    """Ed0 and the diffuse fraction per wavelength (a spectrum file): Ed(0+) is Ed0 at every
    wavelength, and Ed(0-), Eu(0-) match the single-wavelength runs with the same spectrum."""
    table = tmp_path / "sky.csv"
    table.write_text("wavelength_nm,Ed0,diffuse_fraction\n400,1.2,0.6\n700,0.8,0.05\n")
    config = copy.deepcopy(SCENE)
    config["illumination"] = {"sun_zenith_deg": 40,
                              "spectrum": {"model": "table", "file": str(table)}}
    spectral = oceanmc.simulate(config, threads=THREADS)
    ed0 = np.interp(WAVELENGTHS, [400, 700], [1.2, 0.8])
    np.testing.assert_allclose(spectral["air/Ed"], ed0, rtol=1e-9)
    singles = [oceanmc.simulate(single(config, k, 200 + k), threads=THREADS) for k in range(3)]
    for name in ("Ed", "Eu"):
        reference = np.stack([s[name] for s in singles])
        ref_se = np.stack([s.stderr(name) for s in singles])
        assert_z(spectral[name], reference, np.hypot(spectral.stderr(name), ref_se),
                 n_compared=18, dof=dof_of(spectral), rel_max=0.1, what=name)


def test_wavelength_dimension_and_monochromatic_layout(tmp_path):
    """A spectral file has a leading wavelength dimension (nm) that xarray names; a scene
    without wavelengths_nm keeps today's layout; one wavelength runs the monochromatic walk
    and keeps the monochromatic layout (the same numbers as the scene without wavelengths_nm)."""
    xr = pytest.importorskip("xarray")
    config = copy.deepcopy(SCENE)
    config["photons"] = 4000
    spectral = oceanmc.simulate(config, threads=THREADS)
    assert spectral.quantities["radiance"].dims == ("wavelength", "depth", "theta", "phi")
    spectral.save(tmp_path / "s.h5")
    ds = xr.open_dataset(tmp_path / "s.h5", engine="h5netcdf")
    assert ds["Ed"].dims == ("wavelength", "depth")
    np.testing.assert_array_equal(ds["wavelength"].values, WAVELENGTHS)
    air = xr.open_dataset(tmp_path / "s.h5", engine="h5netcdf", group="air")
    assert air["Rrs_nadir"].dims == ("wavelength",)
    assert air["Rrs_nadir_stderr"].dims == ("wavelength",)
    assert oceanmc.load_result(tmp_path / "s.h5").coords["wavelength"].tolist() == WAVELENGTHS

    mono = single(config, 1, 7)
    mono["photons"] = 4000
    one = oceanmc.simulate(mono, threads=THREADS)
    plain = copy.deepcopy(mono)
    del plain["wavelengths_nm"]
    for key in ("a", "b", "bb_ratio"):
        plain["water"]["layers"][0][key] = plain["water"]["layers"][0][key][0]
    bare = oceanmc.simulate(plain, threads=THREADS)
    assert "wavelength" not in bare.coords
    assert bare.quantities["Ed"].dims == ("depth",)
    assert one.quantities["Ed"].dims == ("depth",)   # one wavelength: monochromatic layout
    np.testing.assert_array_equal(one["radiance"], bare["radiance"])
    bare.save(tmp_path / "m.h5")
    assert "wavelength" not in xr.open_dataset(tmp_path / "m.h5", engine="h5netcdf").dims


def test_one_history_matches_single_wavelength_runs_early_roulette():
    """Roulette from a weight of 0.2 on and tally planes every metre: the packet's reference
    wavelength (the heaviest, which p.w follows) moves away from the hero after a few
    collisions, and each plane's settle must then undo exactly what p.w took on the way (a
    path to a plane once went without it: Eu 2% low at 412 nm over a bottom, |z| 24)."""
    config = copy.deepcopy(SCENE)
    config["estimator"] = {"roulette_weight": 0.2, "roulette_survival": 0.5}
    config["tallies"]["depths_m"] = [0, 1, 2, 3, 4]
    compare_with_singles(config)


@pytest.mark.parametrize("surface", ["flat", "cox_munk"])
def test_local_estimates_in_one_history_match_single_wavelength_runs(surface):
    """The next-event estimates of the spectral walk (kernel/local_estimate.py: each
    wavelength's weight, phase function and optical depths from one collision or bottom
    reflection): the nadir polar-cap average (flat sea) and exact directions, in water and at
    0+ (through the rough sea: one facet-walk sample shared by all wavelengths), against the
    single-wavelength runs' own local estimates, with the energy closure at every
    wavelength."""
    config = copy.deepcopy(SCENE)
    config["tallies"] = {"depths_m": [0, 2], "local_directions_deg": [[180, 0], [140, 45]],
                         "nadir_estimator": "local" if surface == "flat" else "crossing"}
    # an exact direction's estimate through a sharply peaked phase function (Fournier-Forand)
    # has heavy tails (hence the cap's average, scene/cap_tables.py): here a mixture of a
    # Henyey-Greenstein and an isotropic scatterer whose shares change with wavelength
    config["water"]["layers"] = [{"thickness_m": 4.0, "components": [
        {"model": "constant", "a": [0.03, 0.08, 0.5], "b": [0.5, 0.3, 0.1],
         "phase": {"model": "henyey_greenstein", "g": 0.8}},
        {"model": "constant", "a": 0.0, "b": [0.1, 0.15, 0.2], "phase": {"model": "isotropic"}},
    ]}]
    compared = ("local_radiance", "air/Rrs_local", "air/L_reflected_local", "Ed",
                "budget/total")
    if surface == "flat":
        compared += ("Lu", "air/Rrs_nadir")
    else:
        config["surface"] = {"model": "cox_munk", "wind_speed_m_s": 5.0}
    compare_with_singles(config, compared)


def test_reflected_sky_in_exact_directions_follows_the_spectral_illumination(tmp_path):
    """The surface-reflected sky and sun in exact view directions at each wavelength scale
    with that wavelength's Ed0 and diffuse fraction (a spectrum file): rho_local, their ratio
    to the sky radiance, is the same at every wavelength, and L_sky = E_sky / pi (a uniform
    sky)."""
    table = tmp_path / "sky.csv"
    table.write_text("wavelength_nm,Ed0,diffuse_fraction\n400,1.2,0.6\n700,0.8,0.05\n")
    config = copy.deepcopy(SCENE)
    config["photons"] = 2000
    config["illumination"] = {"sun_zenith_deg": 40,
                              "spectrum": {"model": "table", "file": str(table)}}
    config["tallies"] = {"depths_m": [0], "local_directions_deg": [[140, 90]]}
    result = oceanmc.simulate(config, threads=THREADS)
    ed0 = np.interp(WAVELENGTHS, [400, 700], [1.2, 0.8])
    diffuse = np.interp(WAVELENGTHS, [400, 700], [0.6, 0.05])
    rho = result["air/rho_local"][:, 0]
    np.testing.assert_allclose(rho, rho[0], rtol=1e-12)
    reflected = result["air/L_reflected_local"][:, 0]
    np.testing.assert_allclose(reflected / rho, ed0 * diffuse / np.pi, rtol=1e-12)


@pytest.mark.parametrize("estimator", [{"mode": "analog"}, {"split_weight": 1.05},
                                       {"upward_fraction": 0.1}])
def test_every_estimator_of_the_spectral_walk_matches_single_wavelength_runs(estimator):
    """The analog walk (the hero's absorption, reflection and surface drawn), splitting (the
    split stack carries each copy's spectral state) and the upward bias (each wavelength's
    density of the biased mixture in its MIS weight) against the default walk at each
    wavelength alone; the biased walk also on the local nadir estimates it is made for."""
    config = copy.deepcopy(SCENE)
    config["estimator"] = estimator
    compared = COMPARED
    if "upward_fraction" in estimator:
        config["tallies"] = {"depths_m": [0, 2, 4], "nadir_estimator": "local"}
        compared = COMPARED + ("Lu", "air/Rrs_nadir")
    compare_with_singles(config, compared, rel_max=0.15)
    if "split_weight" in estimator:   # packets were split: the draws differ from the plain walk
        plain = oceanmc.simulate(SCENE, threads=THREADS)
        split = oceanmc.simulate(config, threads=THREADS)
        assert not np.array_equal(plain["Eu"], split["Eu"])


@pytest.mark.parametrize("change, key", [
    ({"water": {"layers": [{"thickness_m": 4.0, "a": 0.1, "b": [0.3, 0.0, 0.2]}]}},
     "water.layers[0].b"),
])
def test_spectral_walk_refuses_what_it_does_not_carry(change, key):
    config = copy.deepcopy(SCENE)
    config.update(change)
    with pytest.raises(ConfigError, match=key.replace("[", r"\[").replace("]", r"\]")) as info:
        oceanmc.simulate(config, threads=THREADS)
    assert "\n" not in str(info.value)
