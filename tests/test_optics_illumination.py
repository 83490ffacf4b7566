"""Spectral illumination: flat, SPECTRL2 (Bird & Riordan 1986, via pvlib), a CSV; the sun's
zenith angle from time and place."""
from __future__ import annotations

import datetime
import math

import numpy as np
import pytest
import yaml

import oceanmc
from oceanmc import optics
from oceanmc.config import ConfigError

WATER = {"layers": [{"thickness_m": math.inf, "components": [{"model": "pure_water"}]}]}


def scene(illumination, wavelengths=(400.0, 500.0, 600.0, 700.0)):
    return oceanmc.load_config({"wavelengths_nm": list(wavelengths), "water": WATER,
                                "bottom": {"model": "none"}, "illumination": illumination})


def test_sun_zenith_from_time_and_place():
    # June solstice 2024 (20 June 20:51 UTC), local solar noon at longitude 0 is ~12:02 UTC:
    # zenith = latitude - declination (23.44 deg), plus ~0.01 deg of refraction removed
    config = scene({"sun_position": {"time": "2024-06-21T12:02:00Z", "latitude_deg": 40.0,
                                     "longitude_deg": 0.0}})
    assert config.illumination.sun_zenith_deg == pytest.approx(40.0 - 23.44, abs=0.05)


def test_sun_below_the_horizon_is_one_line():
    with pytest.raises(ConfigError, match=r"illumination.*sun_position: the sun is .* below the "
                                          r"horizon") as err:
        scene({"sun_position": {"time": "2024-06-21T00:00:00Z", "latitude_deg": 40.0,
                                "longitude_deg": 0.0}})
    assert "\n" not in str(err.value)


def test_a_time_without_its_zone_is_refused():
    """13:00 read as UTC gave a Mediterranean noon sun 88.7 deg from the zenith: a clock time
    must say its zone."""
    with pytest.raises(ConfigError, match=r"illumination.sun_position.time.*has no time zone; "
                                          r"allowed: .*Z \(UTC\)") as err:
        scene({"sun_position": {"time": "2024-06-21T13:00:00", "latitude_deg": 40.0,
                                "longitude_deg": 15.0}})
    assert "\n" not in str(err.value)
    # as YAML reads it unquoted (a datetime), shown as written, not as Python's repr
    with pytest.raises(ConfigError, match=r"time = 2024-06-21T13:00:00: ") as err:
        scene({"sun_position": {"time": datetime.datetime(2024, 6, 21, 13),
                                "latitude_deg": 40.0, "longitude_deg": 15.0}})
    assert "datetime.datetime" not in str(err.value)
    with pytest.raises(ConfigError, match=r"time = \[2024-06-21T13:00:00\]: ") as err:
        scene({"sun_position": {"time": [datetime.datetime(2024, 6, 21, 13)],
                                "latitude_deg": 40.0, "longitude_deg": 15.0}})
    assert "datetime.datetime" not in str(err.value)


def test_spectrl2_clear_sky_is_blue_in_its_diffuse_share():
    config = scene({"spectrum": {"model": "spectrl2"}, "sun_zenith_deg": 30.0})
    ed0, diffuse, zenith = optics.illumination_spectrum(config)
    assert zenith == 30.0
    # a clear sky's diffuse share falls with wavelength (Rayleigh scattering ~ lambda^-4)
    assert np.all(np.diff(diffuse) < 0.0) and 0.15 < diffuse[0] < 0.5 and diffuse[-1] < 0.15
    # global horizontal irradiance at 500 nm with the sun at 30 deg: about 1.4-1.7 W m-2 nm-1
    # (ASTM G173 global tilt 1.54 at 550 nm for air mass 1.5)
    assert 1.2 < ed0[1] < 1.8
    scaled = scene({"spectrum": {"model": "spectrl2"}, "sun_zenith_deg": 30.0, "Ed0": 2.0})
    assert optics.illumination_spectrum(scaled)[0] == pytest.approx(2.0 * ed0)


def test_spectrum_table_and_its_errors(tmp_path):
    path = tmp_path / "sky.csv"
    path.write_text("wavelength_nm,Ed0,diffuse_fraction\n400,1.0,0.4\n700,1.6,0.1\n")
    ed0, diffuse, _ = optics.illumination_spectrum(scene({"spectrum": {"model": "table",
                                                                        "file": str(path)}}))
    assert ed0 == pytest.approx([1.0, 1.2, 1.4, 1.6]) and diffuse == pytest.approx(
        [0.4, 0.3, 0.2, 0.1])
    with pytest.raises(ConfigError, match=r"illumination.spectrum.file: wavelength 750 nm is "
                                          r"outside the .*sky.csv table's range 400-700 nm"):
        optics.illumination_spectrum(scene({"spectrum": {"model": "table", "file": str(path)}},
                                           (500.0, 750.0)))
    bad = tmp_path / "bad.csv"
    bad.write_text("wavelength_nm,Ed0\n400,1.0\n700,1.6\n")
    with pytest.raises(ConfigError, match=r"lacks the column\(s\) diffuse_fraction"):
        optics.illumination_spectrum(scene({"spectrum": {"model": "table", "file": str(bad)}}))


def test_diffuse_fraction_with_a_modelled_spectrum_is_refused():
    with pytest.raises(ConfigError, match=r"diffuse_fraction = 0.3 with spectrum.model = "
                                          r"'spectrl2'"):
        scene({"spectrum": {"model": "spectrl2"}, "diffuse_fraction": 0.3})


def test_flat_spectrum_is_todays_illumination():
    ed0, diffuse, zenith = optics.illumination_spectrum(
        scene({"Ed0": 2.0, "diffuse_fraction": 0.25, "sun_zenith_deg": 40.0}))
    assert ed0.tolist() == [2.0] * 4 and diffuse.tolist() == [0.25] * 4 and zenith == 40.0


def test_column_iops_and_the_illumination_take_a_scene_as_simulate_does(tmp_path):
    """README: column_iops and illumination_spectrum take a dict, a YAML path or a SceneConfig
    (a dict raised AttributeError before), and LayerIOPs has top_m and thickness_m."""
    from oceanmc.config import load_config
    from oceanmc.optics import column_iops, illumination_spectrum
    scene = {"wavelengths_nm": [450.0, 550.0], "illumination": {"sun_zenith_deg": 30},
             "water": {"layers": [{"thickness_m": 5.0, "components": [
                 {"model": "pure_water"}, {"model": "case1", "chl_mg_m3": 0.3}]}]},
             "bottom": {"model": "lambertian", "reflectance": 0.1}}
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(scene))
    layers = [column_iops(given) for given in (scene, path, load_config(scene))]
    for other in layers[1:]:
        assert np.array_equal(other[0].a, layers[0][0].a)
    assert layers[0][0].top_m == 0.0 and layers[0][0].thickness_m == 5.0
    assert np.array_equal(illumination_spectrum(scene)[0], illumination_spectrum(path)[0])


def test_irradiance_units_follow_the_spectrum_model():
    """A SPECTRL2 scene's irradiances and radiances are W m-2 nm-1 (sr-1) times Ed0, and say so
    in their units (they said 'W m-2 (per unit Ed0)', a flat spectrum's, in files, figures and
    the summary: a user's review); a flat spectrum's are per unit Ed0; Rrs is sr-1 in both."""
    from oceanmc.run.summary import format_summary
    base = {"photons": 2000, "wavelengths_nm": [550.0], "water": WATER,
            "bottom": {"model": "none"}, "illumination": {"sun_zenith_deg": 30.0}}
    flat = oceanmc.simulate(base)
    spectrl2 = oceanmc.simulate(dict(base, illumination={"sun_zenith_deg": 30.0,
                                                         "spectrum": {"model": "spectrl2"}}))
    assert flat.quantities["air/Ed"].units == "W m-2 (per unit Ed0)"
    assert spectrl2.quantities["air/Ed"].units == "W m-2 nm-1 (SPECTRL2 times Ed0)"
    assert spectrl2.quantities["Lu"].units == "W m-2 nm-1 sr-1 (SPECTRL2 times Ed0)"
    assert spectrl2.quantities["air/Rrs_nadir"].units == "sr-1"
    assert "W/m2/nm" in format_summary(spectrl2) and "W/m2/nm" not in format_summary(flat)
