"""Bottoms whose reflectance varies with wavelength, beyond one reflectance of a fixed shape
(issue 28, section 2; test_spectral_bottom.py holds lambertian, minnaert, specular and
mixtures):

- albedo_scale of ggx, hapke and table bottoms (a number, one per wavelength or a CSV
  spectrum): the BRDF's f times it at each wavelength. The angular shape does not change, so
  the kernel packs the BRDF at the largest scale and gives wavelength j the share
  s_j / s_max (GRID bottom_q), as for a Lambertian reflectance.
- diffuse_reflectance and specular_reflectance of lambertian_specular bottoms, each a number,
  a list or a spectrum: the two lobes' shares change with wavelength. The kernel samples one
  lobe with the packed parts' probabilities; wavelength j then takes that lobe's share (GRID
  bottom_q's first row for the diffuse lobe, its second for the mirror).

Checked: loading, packing, refusals (one line each), and spectral runs against
single-wavelength runs of each wavelength's values (|z| < 4 with a Bonferroni bound, fixed
seeds), with the energy budget closing at every wavelength."""
import copy
import math

import numpy as np
import pytest
import yaml

import oceanmc
from oceanmc import scene
from oceanmc.config import ConfigError, config_to_yaml, data_file_hashes, load_config
from oceanmc.optics.bottom import kernel_bottom

from bottom_helpers import WAVELENGTHS, scene_dict
from stats_helpers import assert_z

GGX = {"model": "ggx", "roughness": 0.4, "fresnel": False}
HAPKE = {"model": "hapke", "albedo": 0.6}
SCALE = [0.4, 1.0, 0.7]


def refused(config, *words, build=False):
    with pytest.raises(ConfigError) as info:
        loaded = load_config(config)
        if build:
            scene.build(loaded)
    message = str(info.value)
    assert message and "\n" not in message and "Traceback" not in message, message
    for word in words:
        assert word in message, (word, message)
    return message


def spectrum_csv(path, rows):
    path.write_text("# wavelength_nm, reflectance: a test spectrum\nwavelength_nm,reflectance\n"
                    + "".join(f"{w},{r}\n" for w, r in rows))
    return str(path)


def table_csv(path, rho=0.3, lobe=0.3):
    """An isotropic reciprocal BRDF table: (rho/pi)(1 + lobe cos t_i cos t_r) on a 15 deg grid
    (rho_dh(0) = rho (1 + 2 lobe / 3) <= 0.36 for the defaults)."""
    rows = ["theta_i,theta_r,phi,f"]
    for ti in range(0, 91, 15):
        for tr in range(0, 91, 15):
            for phi in (0, 90, 180):
                f = rho / math.pi * (1.0 + lobe * math.cos(math.radians(ti))
                                     * math.cos(math.radians(tr)))
                rows.append(f"{ti},{tr},{phi},{f!r}")
    path.write_text("\n".join(rows) + "\n")
    return str(path)


def packed(config):
    """(kernel bottom config, (2, n_wl) bottom_q, the packed BRDF scalars 0..4), checking that
    the scene's GRID holds the shares."""
    config = load_config(config)
    bottom, shares = kernel_bottom(config.bottom, config.wavelengths)
    sc = scene.build(config)
    g = sc.grid[0]
    n = int(g["n_wl"])
    np.testing.assert_array_equal(sc.floats[g["bottom_q"]:g["bottom_q"] + 2 * n],
                                  shares.ravel())
    at = sc.bottom[0]["params"]
    return bottom, shares, sc.floats[at:at + 5]


# --- what the user writes -----------------------------------------------------------------------

@pytest.mark.parametrize("bottom", [
    dict(GGX, albedo_scale=SCALE),
    dict(GGX, albedo_scale=2.0, fresnel=True),
    dict(HAPKE, albedo_scale=SCALE),
    {"model": "lambertian_specular", "diffuse_reflectance": [0.05, 0.3, 0.15],
     "specular_reflectance": [0.4, 0.1, 0.25]},
    {"model": "lambertian_specular", "diffuse_reflectance": 0.2,
     "specular_reflectance": [0.0, 0.1, 0.05]},
])
def test_lists_load_and_round_trip(bottom):
    config = load_config(scene_dict(bottom))
    assert load_config(yaml.safe_load(config_to_yaml(config))).bottom == config.bottom


def test_spectrum_files_load_resolve_and_hash(tmp_path):
    sand = spectrum_csv(tmp_path / "sand.csv", [(400, 0.2), (700, 0.5)])
    table_csv(tmp_path / "brdf.csv")
    (tmp_path / "scene.yaml").write_text(
        "wavelengths_nm: [440, 550]\nwater: {layers: [{thickness_m: 2, a: 0.05, b: 0.1}]}\n"
        "bottom: {model: table, file: brdf.csv, albedo_scale: {file: sand.csv}}\n")
    config = load_config(tmp_path / "scene.yaml")
    assert config.bottom.albedo_scale.file == str((tmp_path / "sand.csv").resolve())
    assert config.bottom.albedo_scale.file in data_file_hashes(config)
    (tmp_path / "ls.yaml").write_text(
        "wavelengths_nm: [440, 550]\nwater: {layers: [{thickness_m: 2, a: 0.05, b: 0.1}]}\n"
        "bottom: {model: lambertian_specular, diffuse_reflectance: {file: sand.csv},\n"
        "         specular_reflectance: [0.1, 0.2]}\n")
    config = load_config(tmp_path / "ls.yaml")
    assert config.bottom.diffuse_reflectance.file == sand
    assert sand in data_file_hashes(config)


# --- the packing --------------------------------------------------------------------------------

def test_albedo_scale_packs_the_largest_and_gives_shares(tmp_path):
    for base in (GGX, HAPKE, {"model": "table", "file": table_csv(tmp_path / "brdf.csv")}):
        bottom, shares, params = packed(scene_dict(dict(base, albedo_scale=SCALE)))
        assert bottom.albedo_scale == 1.0 and params[4] == 1.0, base["model"]
        np.testing.assert_allclose(shares[0], SCALE, rtol=1e-15)
        np.testing.assert_array_equal(shares[1], shares[0])
    # a CSV spectrum interpolated to the run's wavelengths
    path = spectrum_csv(tmp_path / "sand.csv", [(400, 0.1), (500, 0.2), (700, 0.4)])
    bottom, shares, params = packed(scene_dict(dict(HAPKE, albedo_scale={"file": path}),
                                               wavelengths=[450.0, 600.0, 700.0]))
    assert params[4] == pytest.approx(0.4, rel=1e-15)
    np.testing.assert_allclose(shares[0], np.array([0.15, 0.3, 0.4]) / 0.4, rtol=1e-14)
    # the default (and one number) packs as before: scale 1 (or the number), shares 1
    _, shares, params = packed(scene_dict(GGX))
    assert params[4] == 1.0 and np.all(shares == 1.0)
    _, shares, params = packed(scene_dict(dict(GGX, albedo_scale=0.5), wavelengths=[550.0]))
    assert params[4] == 0.5 and np.all(shares == 1.0)


def test_albedo_scale_scales_f_and_rho_dh():
    """f times the scale: the kernel's BRDF values and the tabulated rho_dh."""
    from oceanmc.scene import brdf_tables
    from oceanmc.kernel.brdf import tables as ktables
    for base in (GGX, HAPKE):
        cfg = load_config(scene_dict(base, wavelengths=[550.0])).bottom
        half = cfg.model_copy(update={"albedo_scale": 0.5})
        model, one = brdf_tables.bottom_arrays(cfg)
        _, scaled = brdf_tables.bottom_arrays(half)
        wi = np.array([[0.3, 0.0, math.sqrt(1 - 0.09)], [0.0, 0.5, math.sqrt(0.75)]])
        wo = np.array([[-0.2, 0.1, math.sqrt(0.95)], [0.4, -0.3, math.sqrt(0.75)]])
        np.testing.assert_allclose(ktables.both_ways(model, scaled, wi, wo),
                                   0.5 * ktables.both_ways(model, one, wi, wo), rtol=1e-15)
        np.testing.assert_allclose(brdf_tables.tabulated_rho_dh(half)[1],
                                   0.5 * brdf_tables.tabulated_rho_dh(cfg)[1], rtol=1e-12)


def test_lambertian_specular_packs_each_part_and_its_shares():
    d, s = [0.05, 0.3, 0.15], [0.4, 0.1, 0.25]
    bottom, shares, params = packed(scene_dict({"model": "lambertian_specular",
                                                "diffuse_reflectance": d,
                                                "specular_reflectance": s}))
    assert (bottom.diffuse_reflectance, bottom.specular_reflectance) == (0.3, 0.4)
    assert list(params[:2]) == [0.3, 0.4]
    np.testing.assert_allclose(shares[0], np.array(d) / 0.3, rtol=1e-15)
    np.testing.assert_allclose(shares[1], np.array(s) / 0.4, rtol=1e-15)
    # D + S = 1.3 > 1 while every wavelength's d + s = 0.8: packed down to sum 1, so the
    # analog walk's survival probability stays a probability (shares above 1 then)
    d, s = [0.1, 0.6, 0.3], [0.7, 0.2, 0.5]
    _, shares, params = packed(scene_dict({"model": "lambertian_specular",
                                           "diffuse_reflectance": d,
                                           "specular_reflectance": s}))
    assert params[0] + params[1] <= 1.0 and params[0] + params[1] == pytest.approx(1.0, rel=1e-15)
    assert params[0] == pytest.approx(0.6 / 1.3, rel=1e-15) and shares.max() > 1.0
    np.testing.assert_allclose(params[0] * shares[0], d, rtol=1e-14)
    np.testing.assert_allclose(params[1] * shares[1], s, rtol=1e-14)
    # numbers pack as before: the parts themselves, shares 1
    _, shares, params = packed(scene_dict({"model": "lambertian_specular",
                                           "diffuse_reflectance": 0.2,
                                           "specular_reflectance": 0.3}))
    assert list(params[:2]) == [0.2, 0.3] and np.all(shares == 1.0)
    # a part that is 0 everywhere: shares 1 (no 0 / 0)
    _, shares, params = packed(scene_dict({"model": "lambertian_specular",
                                           "diffuse_reflectance": [0.1, 0.2, 0.3],
                                           "specular_reflectance": 0.0}))
    assert params[1] == 0.0 and np.all(shares[1] == 1.0)


def test_results_record_rho_dh_of_lambertian_specular():
    r = oceanmc.simulate(load_config(scene_dict({"model": "lambertian_specular",
                                                 "diffuse_reflectance": [0.05, 0.3, 0.15],
                                                 "specular_reflectance": [0.4, 0.1, 0.25]})),
                         threads=1)
    np.testing.assert_allclose(r.iops["bottom_reflectance"], [0.45, 0.4, 0.4], rtol=1e-15)
    ggx = oceanmc.simulate(load_config(scene_dict(dict(GGX, albedo_scale=SCALE))), threads=1)
    assert "bottom_reflectance" not in ggx.iops   # rho_dh depends on the incidence


# --- refusals -----------------------------------------------------------------------------------

@pytest.mark.parametrize("bottom, words", [
    (dict(GGX, albedo_scale=[0.5, 1.0]),
     ("bottom.albedo_scale has 2 values", "one value per wavelength (3 in wavelengths_nm)")),
    (dict(HAPKE, albedo_scale=[0.5, 0.0, 1.0]),
     ("bottom.albedo_scale[1] = 0", "allowed: a number > 0 and <= 1000")),
    (dict(HAPKE, albedo_scale=-1.0),
     ("bottom.albedo_scale = -1", "allowed: a number > 0 and <= 1000")),
    (dict(GGX, albedo_scale=[0.5, float("nan"), 1.0]), ("bottom.albedo_scale[1] = nan",)),
    (dict(GGX, albedo_scale=2000.0),
     ("bottom.albedo_scale = 2000", "allowed: a number > 0 and <= 1000")),
    ({"model": "lambertian_specular", "diffuse_reflectance": [0.1, 0.2],
      "specular_reflectance": 0.1}, ("bottom.diffuse_reflectance has 2 values",)),
    ({"model": "lambertian_specular", "diffuse_reflectance": 0.1,
      "specular_reflectance": [0.1, 1.2, 0.1]},
     ("bottom.specular_reflectance[1] = 1.2", "allowed: a number 0 .. 1")),
    ({"model": "lambertian", "reflectance": 0.2, "albedo_scale": 0.5},
     ("bottom.albedo_scale: unknown key",)),
    (dict(GGX, diffuse_reflectance=[0.1, 0.2, 0.3]),
     ("bottom.diffuse_reflectance", "give albedo_scale")),
])
def test_refusals_are_one_line_naming_the_key(bottom, words):
    refused(scene_dict(bottom), *words)


def test_lists_and_spectra_need_wavelengths(tmp_path):
    refused(scene_dict(dict(GGX, albedo_scale=[0.5]), wavelengths=None),
            "bottom.albedo_scale is a list", "wavelengths_nm is not given")
    path = spectrum_csv(tmp_path / "sand.csv", [(400, 0.1), (700, 0.3)])
    refused(scene_dict({"model": "lambertian_specular", "diffuse_reflectance": 0.1,
                        "specular_reflectance": {"file": path}}, wavelengths=None),
            "bottom.specular_reflectance.file", "needs wavelengths_nm")


def test_spectrum_outside_its_range_or_values_is_refused(tmp_path):
    path = spectrum_csv(tmp_path / "sand.csv", [(400, 0.1), (700, 0.4)])
    refused(scene_dict(dict(GGX, albedo_scale={"file": path}), wavelengths=[390.0, 500.0]),
            "bottom.albedo_scale.file", "sand.csv", "wavelength 390 nm is outside",
            "400-700 nm", build=True)
    refused(scene_dict({"model": "lambertian_specular", "specular_reflectance": 0.1,
                        "diffuse_reflectance": {"file": path}}, wavelengths=[500.0, 720.0]),
            "bottom.diffuse_reflectance.file", "wavelength 720 nm is outside", build=True)
    bad = spectrum_csv(tmp_path / "bad.csv", [(400, 0.1), (700, 1.3)])
    refused(scene_dict(dict(HAPKE, albedo_scale={"file": bad})),
            "bottom.albedo_scale.file", "bad.csv", "reflectance = 1.3", "allowed: 0 .. 1",
            build=True)


def test_rho_dh_above_1_at_any_wavelength_is_refused(tmp_path):
    """The physical check (rho_dh <= 1) holds at every wavelength: the packed BRDF is the one
    of the largest scale, or, for lambertian_specular, each wavelength's sum is checked."""
    message = refused(scene_dict(dict(HAPKE, albedo=1.0, albedo_scale=[0.5, 1.5, 1.0])),
                      "bottom.model = 'hapke' at albedo_scale = 1.5", "not energy conserving",
                      "allow_unphysical", build=True)
    assert "rho_dh = 1.5" in message, message
    refused(scene_dict({"model": "table", "file": table_csv(tmp_path / "brdf.csv"),
                        "albedo_scale": [1.0, 3.0, 2.0]}),
            "bottom.model = 'table'", "at albedo_scale = 3", "not energy conserving", build=True)
    refused(scene_dict({"model": "lambertian_specular", "diffuse_reflectance": [0.5, 0.6, 0.2],
                        "specular_reflectance": [0.4, 0.5, 0.2]}),
            "'lambertian_specular': not energy conserving at 550 nm",
            "0.6 + 0.5 = 1.1 > 1", "allow_unphysical", build=True)
    # allowed with allow_unphysical
    scene.build(load_config(scene_dict(dict(HAPKE, albedo=1.0, albedo_scale=[0.5, 1.5, 1.0],
                                            allow_unphysical=True))))
    # a dark GGX (Fresnel facets reflect ~1%) may take a scale above 1
    scene.build(load_config(scene_dict(dict(GGX, fresnel=True, albedo_scale=[5.0, 10.0, 2.0]))))


def test_analog_walk_needs_a_packed_weight_of_at_most_1():
    """GGX without a Lambertian term weighs <= 1 at scale <= 1; the largest scale above 1 (a
    number or a list; a spectrum file's values lie within 0 .. 1) is refused with the analog
    walk."""
    analog = {"mode": "analog", "upward_fraction": None}
    load_config(scene_dict(dict(GGX, albedo_scale=SCALE), estimator=analog))
    refused(scene_dict(dict(GGX, fresnel=True, albedo_scale=[0.5, 1.2, 1.0]), estimator=analog),
            "estimator.mode = 'analog'", "'ggx'", "can exceed 1")
    load_config(scene_dict({"model": "lambertian_specular", "diffuse_reflectance": [0.1, 0.6],
                            "specular_reflectance": [0.7, 0.2]}, wavelengths=[440.0, 550.0],
                           estimator=analog))


# --- the physics: a spectral run against one run per wavelength ----------------------------------

STAT_SCENE = {"batches": 20, "illumination": {"sun_zenith_deg": 30, "diffuse_fraction": 0.2},
              "water": {"layers": [{"thickness_m": 2.0, "a": 0.05, "b": 0.1,
                                    "phase": {"model": "henyey_greenstein", "g": 0.8}}]},
              "tallies": {"depths_m": [0, 2]}}
# Rrs nadir (the local estimate; with a mirror, which it cannot see, the crossing estimate of
# a 10 deg cap: too noisy at these photon counts to bound its error, so z alone), Eu at 0- and
# just above the bottom (2 m)
QUANTITIES = {"air/Rrs_nadir": (slice(0, 1), 0.05), "Eu": (slice(0, 2), 0.05)}


def lambertian_specular(d, s):
    return {"model": "lambertian_specular", "diffuse_reflectance": d, "specular_reflectance": s}


def compare(spectral_bottom, single_bottoms, what, estimator=None, photons=20_000):
    """One spectral run of spectral_bottom against single-wavelength runs of single_bottoms[j]
    (other seeds, half the photons): Rrs nadir and Eu at 0- and 2 m at each wavelength, |z| < 4
    against both standard errors (and within 5%, but for Rrs nadir seen through a mirror); the
    spectral run's energy budget closes at every wavelength (|z| < 4 and within 1e-3). Returns
    the z values."""
    extra = {} if estimator is None else {"estimator": estimator}
    spectral = oceanmc.simulate(load_config(dict(
        copy.deepcopy(STAT_SCENE), photons=photons, seed=21, wavelengths_nm=WAVELENGTHS,
        bottom=spectral_bottom, **extra)), threads=2)
    singles = [oceanmc.simulate(load_config(dict(
        copy.deepcopy(STAT_SCENE), photons=photons // 2, seed=100 + k, bottom=b, **extra)),
        threads=2) for k, b in enumerate(single_bottoms)]
    mirror = spectral_bottom["model"] == "lambertian_specular"
    zs = {}
    for name, (depths, rel_max) in QUANTITIES.items():
        estimate = spectral[name].reshape(3, -1)[:, depths]
        se = spectral.stderr(name).reshape(3, -1)[:, depths]
        reference = np.array([np.ravel(s[name])[depths] for s in singles])
        ref_se = np.array([np.ravel(s.stderr(name))[depths] for s in singles])
        zs[name] = assert_z(estimate, reference, np.hypot(se, ref_se), n_compared=1,
                            rel_max=None if mirror and name == "air/Rrs_nadir" else rel_max,
                            what=f"{what} {name}")
    total, se = spectral["budget/total"], spectral.stderr("budget/total")
    zs["budget"] = assert_z(total, np.ones(3), se, n_compared=1, abs_max=1e-3,
                            what=f"{what} budget")
    print(what, {k: np.round(v, 2).tolist() for k, v in zs.items()})
    return zs


CASES = {
    "ggx albedo_scale": (dict(GGX, albedo_scale=SCALE),
                         [dict(GGX, albedo_scale=s) for s in SCALE], None),
    "ggx + lambertian albedo_scale": (
        dict(GGX, fresnel=True, diffuse_reflectance=0.2, albedo_scale=[2.0, 0.5, 1.0]),
        [dict(GGX, fresnel=True, diffuse_reflectance=0.2, albedo_scale=s)
         for s in (2.0, 0.5, 1.0)], None),
    "hapke albedo_scale": (dict(HAPKE, albedo_scale=SCALE),
                           [dict(HAPKE, albedo_scale=s) for s in SCALE], None),
    "lambertian_specular lists": (
        lambertian_specular([0.05, 0.3, 0.15], [0.4, 0.1, 0.25]),
        [lambertian_specular(d, s) for d, s in zip([0.05, 0.3, 0.15], [0.4, 0.1, 0.25])],
        None),
    # packed parts D + S = 1.3 scaled to 1 (shares above 1), with the analog walk
    "lambertian_specular lists, analog": (
        lambertian_specular([0.1, 0.6, 0.3], [0.7, 0.2, 0.5]),
        [lambertian_specular(d, s) for d, s in zip([0.1, 0.6, 0.3], [0.7, 0.2, 0.5])],
        {"mode": "analog", "upward_fraction": None}),
}


@pytest.mark.parametrize("what", list(CASES))
def test_spectral_run_matches_single_wavelength_runs(what):
    spectral_bottom, singles, estimator = CASES[what]
    compare(spectral_bottom, singles, what, estimator)


def test_table_with_a_spectrum_file_matches_single_wavelength_runs(tmp_path):
    """A measured BRDF shape (a table) scaled to a reflectance spectrum from a CSV file."""
    table = table_csv(tmp_path / "brdf.csv", rho=0.8, lobe=0.2)
    sand = spectrum_csv(tmp_path / "sand.csv", [(400, 0.2), (500, 0.6), (700, 0.3)])
    values = np.interp(WAVELENGTHS, [400, 500, 700], [0.2, 0.6, 0.3])
    compare({"model": "table", "file": table, "albedo_scale": {"file": sand}},
            [{"model": "table", "file": table, "albedo_scale": float(v)} for v in values],
            "table albedo_scale file")


def test_the_mirror_lobe_takes_its_own_shares():
    """The comparison has the power to see the mirror row: with the diffuse lobe's shares for
    both lobes, wavelength j would reflect (D + S) d_j / D = [0.117, 0.7, 0.35] instead of
    d_j + s_j = [0.45, 0.4, 0.4]; Eu just above the bottom over Ed there follows the latter."""
    r = oceanmc.simulate(load_config(dict(
        copy.deepcopy(STAT_SCENE), photons=10_000, seed=3, wavelengths_nm=WAVELENGTHS,
        bottom=lambertian_specular([0.05, 0.3, 0.15], [0.4, 0.1, 0.25]))), threads=2)
    ratio = r["Eu"].reshape(3, -1)[:, 1] / r["Ed"].reshape(3, -1)[:, 1]
    np.testing.assert_allclose(ratio, [0.45, 0.4, 0.4], rtol=0.03)
