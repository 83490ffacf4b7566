"""Bottoms whose reflectance varies with wavelength (issue 28, section 2): bottom.reflectance of
lambertian, minnaert and specular bottoms as one number, one per wavelength or a CSV spectrum,
and areal mixtures of one shape (config/bottom.py, optics/bottom.py). The kernel runs one BRDF
of the largest reflectance R_max and gives wavelength j the share R_j / R_max (GRID bottom_q;
kernel/spectral.py reflect and bottom_weights): the packing is checked here, and a spectral run
against single-wavelength runs of each wavelength's reflectance (z-scores, fixed seeds). The
albedo_scale of ggx, hapke and table and the parts of lambertian_specular:
test_spectral_bottom_shapes.py."""
import copy

import h5py
import numpy as np
import pytest
import yaml

import oceanmc
from oceanmc import scene
from oceanmc.config import ConfigError, config_to_yaml, data_file_hashes, load_config
from oceanmc.optics.bottom import kernel_bottom

from bottom_helpers import WAVELENGTHS, scene_dict
from stats_helpers import assert_z

SPECTRUM = [0.05, 0.3, 0.15]


def refused(config, *words):
    with pytest.raises(ConfigError) as info:
        load_config(config)
    message = str(info.value)
    assert message and "\n" not in message and "Traceback" not in message, message
    for word in words:
        assert word in message, (word, message)
    return message


def packed(config):
    """(kernel bottom config, bottom_q) and the scene's own GRID bottom_q and BRDF scalars."""
    config = load_config(config)
    bottom, shares = kernel_bottom(config.bottom, config.wavelengths)
    sc = scene.build(config)
    g = sc.grid[0]
    q = sc.floats[g["bottom_q"]:g["bottom_q"] + 2 * int(g["n_wl"])]
    np.testing.assert_array_equal(q, shares.ravel())
    # every bottom but lambertian_specular has one row of shares (its second row the same)
    np.testing.assert_array_equal(shares[1], shares[0])
    return bottom, shares[0], sc.floats[sc.bottom[0]["params"]:sc.bottom[0]["params"] + 2]


def spectrum_csv(path, rows):
    path.write_text("# wavelength_nm, reflectance: a test spectrum\nwavelength_nm,reflectance\n"
                    + "".join(f"{w},{r}\n" for w, r in rows))
    return str(path)


# --- what the user writes -----------------------------------------------------------------------

@pytest.mark.parametrize("bottom", [
    {"model": "lambertian", "reflectance": SPECTRUM},
    {"model": "minnaert", "reflectance": SPECTRUM, "k": 0.4},
    {"model": "specular", "reflectance": SPECTRUM},
    {"model": "mixture", "components": [
        {"fraction": 0.6, "model": "lambertian", "reflectance": SPECTRUM},
        {"fraction": 0.4, "model": "lambertian", "reflectance": 0.2}]},
    {"model": "mixture", "components": [
        {"fraction": 0.25, "model": "minnaert", "k": 0.7, "reflectance": 0.1},
        {"fraction": 0.75, "model": "minnaert", "k": 0.7, "reflectance": SPECTRUM}]},
])
def test_spectral_reflectances_and_mixtures_load(bottom):
    """They load, and the stored config (config_to_yaml) loads back to the same bottom."""
    config = load_config(scene_dict(bottom))
    assert load_config(yaml.safe_load(config_to_yaml(config))).bottom == config.bottom


def test_the_new_users_reflectance_list_is_accepted():
    """The issue's new user: `reflectance: [0.15, ...]` was refused ("Input should be a valid
    number")."""
    config = load_config(scene_dict({"model": "lambertian", "reflectance": [0.15, 0.2, 0.1]}))
    assert config.bottom.reflectance == [0.15, 0.2, 0.1]


@pytest.mark.parametrize("bottom, words", [
    ({"model": "lambertian", "reflectance": [0.1, 0.2]},
     ("bottom.reflectance has 2 values", "one value per wavelength (3 in wavelengths_nm)")),
    ({"model": "minnaert", "k": 0.5, "reflectance": [0.1, 0.2, 0.3, 0.4]},
     ("bottom.reflectance has 4 values",)),
    ({"model": "lambertian", "reflectance": [0.1, 1.2, 0.3]},
     ("bottom.reflectance[1] = 1.2", "allowed: a number 0 .. 1")),
    ({"model": "lambertian", "reflectance": [0.1, -0.01, 0.3]},
     ("bottom.reflectance[1] = -0.01", "allowed: a number 0 .. 1")),
    ({"model": "lambertian", "reflectance": [0.1, float("nan"), 0.3]},
     ("bottom.reflectance[1] = nan",)),
    ({"model": "mixture", "components": [
        {"fraction": 0.6, "model": "lambertian", "reflectance": 0.1},
        {"fraction": 0.3, "model": "lambertian", "reflectance": 0.2}]},
     ("the fractions add up to 0.9", "adding up to 1 (within 1e-09)")),
    ({"model": "mixture", "components": [
        {"fraction": 0.6, "model": "lambertian", "reflectance": 0.1},
        {"fraction": 0.4 + 1e-8, "model": "lambertian", "reflectance": 0.2}]},
     ("the fractions add up to 1.00000001",)),
    ({"model": "mixture", "components": [
        {"fraction": 0.0, "model": "lambertian", "reflectance": 0.1},
        {"fraction": 1.0, "model": "lambertian", "reflectance": 0.2}]},
     ("bottom.components[0].fraction = 0", "allowed: a number > 0 and <= 1")),
    ({"model": "mixture", "components": [
        {"fraction": 0.5, "model": "minnaert", "k": 0.5, "reflectance": 0.1},
        {"fraction": 0.5, "model": "minnaert", "k": 0.6, "reflectance": 0.2}]},
     ("components[1] is minnaert with k = 0.6", "all minnaert of one k",
      "one BRDF shape for every wavelength")),
    ({"model": "mixture", "components": [
        {"fraction": 0.5, "model": "lambertian", "reflectance": 0.1},
        {"fraction": 0.5, "model": "minnaert", "k": 0.6, "reflectance": 0.2}]},
     ("components[1] is minnaert", "components of one shape")),
    ({"model": "mixture", "components": [
        {"fraction": 0.5, "model": "lambertian", "reflectance": 0.1},
        {"fraction": 0.5, "model": "ggx", "roughness": 0.3}]},
     ("bottom.components[1].model = 'ggx'", "allowed in a mixture",
      "one BRDF shape for every wavelength")),
    ({"model": "mixture", "components": [
        {"fraction": 1.0, "model": "hapke", "albedo": 0.3}]},
     ("bottom.components[0].model = 'hapke'", "allowed in a mixture")),
    ({"model": "mixture", "components": [
        {"fraction": 1.0, "model": "minnaert", "reflectance": 0.3}]},
     ("bottom.components[0]", "k is required")),
    ({"model": "mixture", "components": [
        {"fraction": 1.0, "model": "lambertian", "reflectance": [0.3, 0.2]}]},
     ("bottom.components[0].reflectance has 2 values",)),
    ({"model": "ggx", "roughness": 0.3, "diffuse_reflectance": [0.1, 0.2, 0.3]},
     ("bottom.diffuse_reflectance", "'ggx' takes one diffuse_reflectance, not a list",
      "give albedo_scale")),
    ({"model": "hapke", "albedo": {"file": "sand.csv"}},
     ("bottom.albedo", "'hapke' takes one albedo, not a spectrum file", "give albedo_scale")),
])
def test_refusals_are_one_line_naming_the_key(bottom, words):
    refused(scene_dict(bottom), *words)


def test_lists_and_spectra_need_wavelengths(tmp_path):
    refused(scene_dict({"model": "lambertian", "reflectance": [0.2]}, wavelengths=None),
            "bottom.reflectance is a list", "wavelengths_nm is not given")
    path = spectrum_csv(tmp_path / "sand.csv", [(400, 0.1), (700, 0.3)])
    refused(scene_dict({"model": "lambertian", "reflectance": {"file": path}}, wavelengths=None),
            "bottom.reflectance.file", "needs wavelengths_nm")


# --- the packing --------------------------------------------------------------------------------

def test_packed_shares_are_the_reflectance_over_its_maximum():
    bottom, shares, params = packed(scene_dict({"model": "lambertian", "reflectance": SPECTRUM}))
    assert bottom.model == "lambertian" and bottom.reflectance == 0.3 and params[0] == 0.3
    np.testing.assert_allclose(shares, np.array(SPECTRUM) / 0.3, rtol=1e-15)
    assert shares.max() == 1.0
    bottom, shares, params = packed(scene_dict({"model": "minnaert", "k": 0.4,
                                                "reflectance": SPECTRUM}))
    assert (bottom.model, bottom.reflectance, bottom.k) == ("minnaert", 0.3, 0.4)
    assert list(params) == [0.3, 0.4]
    np.testing.assert_allclose(shares, np.array(SPECTRUM) / 0.3, rtol=1e-15)


def test_one_reflectance_packs_as_before():
    """A number (or a list of one value in a one-wavelength run) packs the BRDF of that
    reflectance with share 1, so existing scenes run the same kernel arrays."""
    number = scene.build(load_config(scene_dict({"model": "lambertian", "reflectance": 0.2},
                                                wavelengths=[550.0])))
    one = scene.build(load_config(scene_dict({"model": "lambertian", "reflectance": [0.2]},
                                             wavelengths=[550.0])))
    np.testing.assert_array_equal(number.floats, one.floats)
    g = number.grid[0]
    assert number.floats[g["bottom_q"]] == 1.0 and number.floats[number.bottom[0]["params"]] == 0.2
    assert number.floats[g["bottom_q"] + 1] == 1.0   # the mirror lobe's row
    _, shares, _ = packed(scene_dict({"model": "lambertian", "reflectance": 0.2}))
    np.testing.assert_array_equal(shares, np.ones(3))
    _, shares, params = packed(scene_dict({"model": "lambertian", "reflectance": [0, 0, 0]}))
    assert params[0] == 0.0 and np.all(shares == 1.0)   # no 0 / 0


def test_a_spectrum_file_is_interpolated_within_its_range(tmp_path):
    path = spectrum_csv(tmp_path / "sand.csv", [(400, 0.1), (500, 0.2), (700, 0.4)])
    bottom, shares, _ = packed(scene_dict({"model": "lambertian", "reflectance": {"file": path}},
                                          wavelengths=[450.0, 600.0, 700.0]))
    expected = np.array([0.15, 0.3, 0.4])
    assert bottom.reflectance == pytest.approx(0.4, rel=1e-15)
    np.testing.assert_allclose(shares, expected / 0.4, rtol=1e-14)
    # a one-wavelength run reads it too
    bottom, shares, params = packed(scene_dict(
        {"model": "lambertian", "reflectance": {"file": path}}, wavelengths=[450.0]))
    assert params[0] == pytest.approx(0.15, rel=1e-14) and shares[0] == 1.0
    # outside the table's range: refused, as for the water's component tables
    config = load_config(scene_dict({"model": "lambertian", "reflectance": {"file": path}},
                                    wavelengths=[390.0, 500.0]))
    with pytest.raises(ConfigError) as info:
        scene.build(config)
    message = str(info.value)
    assert "\n" not in message and "bottom.reflectance.file" in message and "sand.csv" in message
    assert "wavelength 390 nm is outside" in message and "400-700 nm" in message
    bad = spectrum_csv(tmp_path / "bad.csv", [(400, 0.1), (700, 1.3)])
    with pytest.raises(ConfigError, match=r"bottom.reflectance.file: .*bad.csv: reflectance = "
                                          r"1.3 at wavelength_nm = 700; allowed: 0 .. 1"):
        scene.build(load_config(scene_dict({"model": "lambertian",
                                            "reflectance": {"file": bad}})))


def test_spectrum_files_are_resolved_next_to_the_config_and_hashed(tmp_path):
    spectrum_csv(tmp_path / "seagrass.csv", [(400, 0.05), (700, 0.1)])
    (tmp_path / "scene.yaml").write_text(
        "wavelengths_nm: [440, 550]\nwater: {layers: [{thickness_m: 2, a: 0.05, b: 0.1}]}\n"
        "bottom:\n  model: mixture\n  components:\n"
        "    - {fraction: 0.6, model: lambertian, reflectance: [0.1, 0.2]}\n"
        "    - {fraction: 0.4, model: lambertian, reflectance: {file: seagrass.csv}}\n")
    config = load_config(tmp_path / "scene.yaml")
    path = config.bottom.components[1].reflectance.file
    assert path == str((tmp_path / "seagrass.csv").resolve())
    assert path in data_file_hashes(config)


def test_a_mixture_packs_as_the_bottom_of_its_weighted_spectrum(tmp_path):
    path = spectrum_csv(tmp_path / "seagrass.csv", [(400, 0.02), (550, 0.12), (700, 0.06)])
    mixture = {"model": "mixture", "components": [
        {"fraction": 0.6, "model": "lambertian", "reflectance": SPECTRUM},
        {"fraction": 0.4, "model": "lambertian", "reflectance": {"file": path}}]}
    seagrass = np.interp(WAVELENGTHS, [400, 550, 700], [0.02, 0.12, 0.06])
    weighted = 0.6 * np.array(SPECTRUM) + 0.4 * seagrass
    bottom, shares, params = packed(scene_dict(mixture))
    assert bottom.model == "lambertian"
    assert params[0] == pytest.approx(weighted.max(), rel=1e-14)
    np.testing.assert_allclose(shares, weighted / weighted.max(), rtol=1e-14)
    minnaert = {"model": "mixture", "components": [
        {"fraction": 0.3, "model": "minnaert", "k": 0.6, "reflectance": 0.2},
        {"fraction": 0.7, "model": "minnaert", "k": 0.6, "reflectance": SPECTRUM}]}
    bottom, shares, params = packed(scene_dict(minnaert))
    weighted = 0.3 * 0.2 + 0.7 * np.array(SPECTRUM)
    assert (bottom.model, bottom.k) == ("minnaert", 0.6)
    assert list(params) == pytest.approx([weighted.max(), 0.6], rel=1e-14)
    np.testing.assert_allclose(shares, weighted / weighted.max(), rtol=1e-14)


def test_a_mixture_runs_as_the_lambertian_bottom_of_its_weighted_spectrum():
    """Same seed: the mixture and the Lambertian bottom of its weighted spectrum give the same
    results (to rounding in the weighted spectrum's last bit)."""
    parts = ([0.1, 0.4, 0.2], [0.3, 0.1, 0.05])
    mixture = {"model": "mixture", "components": [
        {"fraction": 0.75, "model": "lambertian", "reflectance": parts[0]},
        {"fraction": 0.25, "model": "lambertian", "reflectance": parts[1]}]}
    weighted = [0.75 * a + 0.25 * b for a, b in zip(*parts)]
    runs = [oceanmc.simulate(load_config(scene_dict(b, photons=4000, batches=4)), threads=1)
            for b in (mixture, {"model": "lambertian", "reflectance": weighted})]
    for name in ("air/Rrs_nadir", "Eu", "Ed", "budget/absorbed_bottom"):
        np.testing.assert_allclose(runs[0][name], runs[1][name], rtol=1e-12, err_msg=name)
    assert np.all(runs[0]["budget/absorbed_bottom"] > 0.0)


def test_results_record_the_reflectance_the_run_used(tmp_path):
    """The results' iops group holds the bottom's reflectance per wavelength (a spectrum file
    interpolated, a mixture weighted), in memory and in the file; bottoms without one have
    none."""
    path = spectrum_csv(tmp_path / "sand.csv", [(400, 0.1), (700, 0.4)])
    mixture = {"model": "mixture", "components": [
        {"fraction": 0.5, "model": "lambertian", "reflectance": SPECTRUM},
        {"fraction": 0.5, "model": "lambertian", "reflectance": {"file": path}}]}
    result = oceanmc.simulate(load_config(scene_dict(mixture)), threads=1)
    sand = 0.1 + 0.3 * (np.array(WAVELENGTHS) - 400) / 300
    expected = 0.5 * np.array(SPECTRUM) + 0.5 * sand
    np.testing.assert_allclose(result.iops["bottom_reflectance"], expected, rtol=1e-14)
    result.save(tmp_path / "out.h5")
    loaded = oceanmc.load_result(tmp_path / "out.h5")
    np.testing.assert_array_equal(loaded.iops["bottom_reflectance"],
                                  result.iops["bottom_reflectance"])
    with h5py.File(tmp_path / "out.h5") as f:
        assert f["iops/bottom_reflectance"].dims[0][0].name == "/iops/wavelength"
    black = oceanmc.simulate(load_config(scene_dict({"model": "black"})), threads=1)
    assert "bottom_reflectance" not in black.iops


# --- the physics: a spectral run against one run per wavelength ----------------------------------

STAT_SCENE = {"photons": 60_000, "batches": 16, "seed": 21,
              "illumination": {"sun_zenith_deg": 30, "diffuse_fraction": 0.2},
              "water": {"layers": [{"thickness_m": 2.0, "a": 0.05, "b": 0.1,
                                    "phase": {"model": "henyey_greenstein", "g": 0.8}}]},
              "tallies": {"depths_m": [0, 2]}}


def test_spectral_lambertian_bottom_matches_single_wavelength_runs():
    """Shallow clear water (2 m, a 0.05, b 0.1 1/m: the bottom's light is most of the upwelling
    light) over a Lambertian bottom of reflectance [0.05, 0.3, 0.15] at three wavelengths, in
    one spectral run, against three single-wavelength runs with that wavelength's reflectance
    as a number (other seeds): Rrs nadir and Eu(0-) at each wavelength, |z| < 4 against both
    standard errors, and within 5%."""
    spectral = oceanmc.simulate(load_config(dict(
        copy.deepcopy(STAT_SCENE), wavelengths_nm=WAVELENGTHS,
        bottom={"model": "lambertian", "reflectance": SPECTRUM})), threads=2)
    singles = [oceanmc.simulate(load_config(dict(
        copy.deepcopy(STAT_SCENE), photons=30_000, seed=100 + k,
        bottom={"model": "lambertian", "reflectance": r})), threads=2)
        for k, r in enumerate(SPECTRUM)]
    for name in ("air/Rrs_nadir", "Eu"):
        # the spectral run's wavelength axis leads; Eu's depth 0 is 0-
        estimate = spectral[name].reshape(3, -1)[:, 0]
        se = spectral.stderr(name).reshape(3, -1)[:, 0]
        reference = np.array([np.ravel(s[name])[0] for s in singles])
        ref_se = np.array([np.ravel(s.stderr(name))[0] for s in singles])
        assert_z(estimate, reference, np.hypot(se, ref_se), n_compared=1, rel_max=0.05,
                 what=name)
    # and the reflectance shows: Rrs follows the bottom's spectrum
    rrs = spectral["air/Rrs_nadir"]
    assert rrs[1] > rrs[2] > rrs[0]
