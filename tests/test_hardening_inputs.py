"""Bad data in a scene's tables and keys (issue 29, sections 1 and 2): one line naming the key,
the value and what is allowed, exit status 2 and no results file; never a traceback, never NaN
results with exit 0, never a runaway allocation."""
import resource
import subprocess
import sys

import pytest
import yaml

import oceanmc
from oceanmc.cli import main
from oceanmc.config import ConfigError

from conftest import REPO
from test_robustness import ENV

WATER = [{"model": "pure_water"}]


def scene(components=(), illumination=None, thickness=10.0, **extra):
    config = {"photons": 2000, "batches": 2, "wavelengths_nm": [400, 500, 600],
              "water": {"layers": [{"thickness_m": thickness,
                                    "components": WATER + list(components)}]},
              "bottom": {"model": "black"}, **extra}
    if illumination:
        config["illumination"] = illumination
    return config


def refused_run(tmp_path, capsys, config, *words):
    """`oceanmc run` of the scene: exit 2, one line holding every word, no results file."""
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(config))
    out = tmp_path / "out.h5"
    capsys.readouterr()
    assert main(["run", str(path), "-o", str(out), "-q"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "Traceback" not in err, err
    for word in words:
        assert word in err, (word, err)
    assert not out.exists()
    return err


def refused(config, *words):
    with pytest.raises(ConfigError) as info:
        oceanmc.load_config(config)
    message = str(info.value)
    assert "\n" not in message
    for word in words:
        assert word in message, (word, message)


IOPS = "wavelength_nm,a,b,bb_ratio\n"
SPECTRUM = "wavelength_nm,Ed0,diffuse_fraction\n"
PROFILE = "depth_m,value\n"


@pytest.mark.parametrize("text, use, words", [
    (IOPS + "400,nan,1,0.01\n700,0.1,1,0.01\n", "component", ["components[1].file", "a = nan",
                                                              "allowed: 0 .. 1e+06 1/m"]),
    (IOPS + "400,0.1,inf,0.01\n700,0.1,1,0.01\n", "component", ["b = inf at wavelength_nm = 400"]),
    (IOPS + "400,0.1,1,nan\n700,0.1,1,0.01\n", "component", ["bb_ratio = nan",
                                                             "allowed: 0.0005 .. 0.45"]),
    (IOPS + "400,0.1,1,0.01\nnan,0.1,1,0.01\n", "component", ["wavelength_nm = nan at row 2"]),
    (IOPS + "400,1e308,1e308,0.01\n700,0.1,1,0.01\n", "component", ["a = 1e+308"]),
    (PROFILE + "0,nan\n10,1\n", "profile", ["chl_mg_m3.file", "value = nan at depth_m = 0",
                                            "allowed: 0 .. 100 mg/m3"]),
    (PROFILE + "0,1\ninf,1\n", "profile", ["depth_m = inf at row 2", "allowed: 0 .. 1e+06 m"]),
    (PROFILE + "0,1e308\n10,1\n", "profile", ["value = 1e+308"]),
    (SPECTRUM + "400,nan,0.1\n700,1,0.1\n", "spectrum", ["illumination.spectrum.file",
                                                         "Ed0 = nan at wavelength_nm = 400"]),
    (SPECTRUM + "400,1,nan\n700,1,0.1\n", "spectrum", ["diffuse_fraction = nan",
                                                       "allowed: 0 .. 1"]),
    (SPECTRUM + "400,1e308,0.1\n700,1e308,0.1\n", "spectrum", ["Ed0 = 1e+308",
                                                               "allowed: 0 .. 1e+100"]),
])
def test_non_finite_or_overflowing_table_values_are_refused(tmp_path, capsys, text, use, words):
    (tmp_path / "t.csv").write_text(text)
    if use == "component":
        config = scene([{"model": "table", "file": "t.csv"}])
    elif use == "profile":
        config = scene([{"model": "chlorophyll", "chl_mg_m3": {"profile": "table",
                                                               "file": "t.csv"}}])
    else:
        config = scene(illumination={"spectrum": {"model": "table", "file": "t.csv"}})
    refused_run(tmp_path, capsys, config, "t.csv", *words)


def test_spectrum_times_ed0_beyond_the_bound_is_refused(tmp_path, capsys):
    (tmp_path / "t.csv").write_text(SPECTRUM + "400,10,0.1\n700,10,0.1\n")
    refused_run(tmp_path, capsys, scene(illumination={
        "Ed0": 1e100, "spectrum": {"model": "table", "file": "t.csv"}}),
        "illumination.Ed0 = 1e+100 times the spectrum's Ed0 reaches 1e+101",
        "allowed: at most 1e+100")


def test_nan_table_is_exit_2_from_the_command(tmp_path):
    (tmp_path / "t.csv").write_text(IOPS + "400,nan,1,0.01\n700,0.1,1,0.01\n")
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(scene([{"model": "table", "file": "t.csv"}])))
    done = subprocess.run([sys.executable, "-m", "oceanmc", "run", str(path), "-o",
                           str(tmp_path / "out.h5"), "--photons", "2000"],
                          capture_output=True, text=True, env=ENV, cwd=REPO, timeout=300)
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and "a = nan" in done.stderr
    assert not (tmp_path / "out.h5").exists()


@pytest.mark.parametrize("text, use", [
    ("wavelength_nm,a,a,b,bb_ratio\n400,0.1,0.2,1,0.01\n700,0.1,0.2,1,0.01\n", "component"),
    ("wavelength_nm,Ed0,diffuse_fraction,Ed0\n400,1,0.1,2\n700,1,0.1,2\n", "spectrum"),
])
def test_duplicate_table_column_is_refused(tmp_path, capsys, text, use):
    (tmp_path / "t.csv").write_text(text)
    config = scene([{"model": "table", "file": "t.csv"}]) if use == "component" \
        else scene(illumination={"spectrum": {"model": "table", "file": "t.csv"}})
    column = "'a'" if use == "component" else "'Ed0'"
    refused_run(tmp_path, capsys, config, "t.csv", f"column {column} appears twice")


@pytest.mark.parametrize("component, words", [
    ({"model": "chlorophyll", "chl_mg_m3": 1e4}, ["chl_mg_m3 = 10000.0",
                                                  "allowed: 0 .. 100 mg/m3"]),
    ({"model": "chlorophyll", "chl_mg_m3": {"profile": "gaussian", "background": 0.1,
                                            "peak_depth_m": 5, "width_m": 0.01,
                                            "integral": 10}},
     ["chl_mg_m3: the gaussian's peak", "is 399.042", "allowed: 0 .. 100 mg/m3"]),
    ({"model": "chlorophyll", "chl_mg_m3": {"profile": "linear", "depths_m": [0, 5],
                                            "values": [1, 1e30]}},
     ["chl_mg_m3: values reach 1e+30"]),
    ({"model": "cdom", "a440": 1e30}, ["a440 = 1e+30", "allowed: 0 .. 1000 1/m"]),
    ({"model": "particles", "b550": 1e30}, ["b550 = 1e+30", "allowed: a number 0 .. 1000"]),
    ({"model": "particles", "b550": 1, "a443": 1e30}, ["a443 = 1e+30"]),
    ({"model": "particles", "b550": 1, "concentration": 1e30},
     ["concentration = 1e+30", "allowed: 0 .. 1000"]),
    ({"model": "constant", "a": 1e308}, ["components[1].a = 1e+308",
                                         "allowed: a number 0 .. 1e+06"]),
    ({"model": "chlorophyll", "chl_mg_m3": {"profile": "gaussian", "background": 0.1,
                                            "peak_depth_m": 1e30, "width_m": 1,
                                            "integral": 1}}, ["peak_depth_m = 1e+30"]),
])
def test_constituent_amounts_beyond_their_models_are_refused(component, words):
    refused(scene([component]), *words)


def test_wavelengths_and_profile_table_amounts_beyond_their_range_are_refused(tmp_path, capsys):
    refused(scene(wavelengths_nm=[1e-300, 500]), "wavelengths_nm[0] = 1e-300",
            "allowed: a number 100 .. 10000")
    (tmp_path / "t.csv").write_text(PROFILE + "0,0.1\n10,1e4\n")
    refused_run(tmp_path, capsys, scene([{"model": "chlorophyll", "chl_mg_m3": {
        "profile": "table", "file": "t.csv"}}]), "value = 10000 at depth_m = 10",
        "allowed: 0 .. 100 mg/m3")


@pytest.mark.parametrize("key, value, words", [
    ("surface_pressure_pa", 1e30, ["surface_pressure_pa = 1e+30", "110000"]),
    ("precipitable_water_cm", 1e30, ["precipitable_water_cm = 1e+30", "allowed: a number 0 .. 10"]),
    ("ozone_atm_cm", 50, ["ozone_atm_cm = 50", "allowed: a number 0 .. 1"]),
    ("aerosol_turbidity_500nm", 1e30, ["aerosol_turbidity_500nm = 1e+30"]),
    ("alpha", 1e30, ["alpha = 1e+30", "allowed: a number 0 .. 4"]),
    ("wavelength_variation_factor", 1e30, ["wavelength_variation_factor = 1e+30"]),
])
def test_spectrl2_inputs_out_of_range_are_refused(key, value, words):
    refused(scene(illumination={"spectrum": {"model": "spectrl2", key: value}}),
            "illumination.spectrum.", *words)


def test_sun_position_beyond_the_solar_position_algorithm_is_refused():
    refused(scene(illumination={"sun_position": {"time": "9999-06-21T12:00:00Z",
                                                 "latitude_deg": 0.0, "longitude_deg": 0.0}}),
            "illumination.sun_position.time", "year 9999; allowed: up to 6000")


@pytest.mark.parametrize("component, key, count", [
    ({"model": "constant", "a": [0.1]}, "a", 1),
    ({"model": "constant", "a": [0.1, 0.2]}, "a", 2),
    ({"model": "constant", "a": 0.1, "b": [0.1, 0.2, 0.3, 0.4]}, "b", 4),
    ({"model": "constant", "a": 0.1, "b": 0.1, "bb_ratio": [0.01, 0.02]}, "bb_ratio", 2),
])
def test_component_lists_need_one_value_per_wavelength(component, key, count):
    refused(scene([component]), f"water.layers[0].components[1].{key} has {count} values",
            "allowed: one number or one value per wavelength (3 in wavelengths_nm)")
    # a list with one value per wavelength is what is allowed
    component = dict(component, **{key: [0.01, 0.02, 0.03]})
    assert oceanmc.load_config(scene([component])).water.layers[0].components[1]


@pytest.mark.parametrize("profile, key", [
    ({"model": "chlorophyll", "chl_mg_m3": {"profile": "gaussian", "background": 0.1,
                                            "peak_depth_m": 5, "width_m": 1e-9,
                                            "integral": 1e-9}}, "chl_mg_m3"),
    ({"model": "cdom", "a440": {"profile": "linear", "depths_m": [0, 1e-9, 1e6],
                                "values": [0.1, 0.1, 0.2]}}, "a440"),
])
def test_profile_needing_too_many_sublayers_is_refused_before_allocation(tmp_path, capsys,
                                                                         profile, key):
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    err = refused_run(tmp_path, capsys, scene([profile], thickness=1e6),
                      f"water.layers[0].components[1].{key}: its length scale of 1e-09 m",
                      "allowed: at most 5000")
    assert "e+" in err.split("needs ")[1]   # the count, e.g. 5e+09 sublayers
    # nothing near the 37 GiB of intervals was allocated (ru_maxrss in KiB on Linux)
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before < 500_000


def test_one_row_profile_table_is_refused(tmp_path, capsys):
    (tmp_path / "t.csv").write_text(PROFILE + "0,1\n")
    refused_run(tmp_path, capsys, scene([{"model": "chlorophyll", "chl_mg_m3": {
        "profile": "table", "file": "t.csv"}}]), "chl_mg_m3.file", "t.csv has 1 row of depth_m",
        "allowed: at least 2")
