"""Config loading and validation: every bad scene gets one clear ConfigError naming the key path,
the value and what is allowed."""
import math
import os
import subprocess
import sys

import pytest
import yaml

import oceanmc
from oceanmc.config import ConfigError, config_to_yaml, load_config

from conftest import REPO


def test_shipped_configs_load():
    for path in sorted((REPO / "configs").glob("*.yaml")):
        config = load_config(path)
        assert config.photons > 0, path


def test_defaults_are_filled_in(small_scene):
    del small_scene["tallies"]
    config = load_config(small_scene)
    assert config.tallies.phi_bands == 24
    assert config.tallies.theta_edges[1] == 5.0 and len(config.tallies.theta_edges) == 21
    assert config.estimator.mode == "implicit"
    assert config.surface.fresnel == "exact"


def test_round_trip_through_yaml(small_scene, tmp_path):
    config = load_config(small_scene)
    path = tmp_path / "again.yaml"
    path.write_text(config_to_yaml(config))
    assert load_config(path) == config


def test_infinite_thickness_round_trips(tmp_path):
    scene = {"water": {"layers": [{"thickness_m": math.inf, "a": 0.1, "b": 0.2}]},
             "bottom": {"model": "none"}}
    text = config_to_yaml(load_config(scene))
    assert ".inf" in text
    assert math.isinf(load_config(yaml.safe_load(text)).water.layers[0].thickness_m)


def test_overrides_replace_photons_and_seed(small_scene):
    config = load_config(small_scene, {"photons": 1234, "seed": 9})
    assert (config.photons, config.seed) == (1234, 9)


@pytest.mark.parametrize("key, bad, override", [
    ("photons", "many", 1234), ("seed", -1, 9),
    ("seed", "5", 3), ("photons", True, 3000)])   # refused by the model's check: location ()
def test_a_bad_value_in_the_file_is_refused_though_overridden(small_scene, key, bad, override):
    """`photons: many` ran when --photons replaced it, the mistake in the file unsaid; so did
    `seed: '5'` and `photons: yes`, whose errors (from the model's own check) have no key in
    their location."""
    small_scene[key] = bad
    with pytest.raises(ConfigError, match=rf"^config: {key} = {bad!r}: .* \(the file's value, "
                                          r"which is overridden, must be valid too\)$"):
        load_config(small_scene, {key: override})


def test_an_overridden_value_needs_only_to_be_valid_on_its_own(small_scene):
    small_scene["photons"] = 10   # fewer than 2 per batch: the override decides
    assert load_config(small_scene, {"photons": 1234}).photons == 1234


def test_mixture_b_is_the_sum_of_its_components():
    scene = {"water": {"layers": [{"thickness_m": 1, "a": 0.1, "phase": {
        "model": "mixture", "components": [
            {"b": 0.002, "phase": {"model": "pure_water"}},
            {"b": 0.3, "phase": {"model": "petzold"}}]}}]},
        "bottom": {"model": "black"}}
    assert load_config(scene).water.layers[0].b == pytest.approx(0.302)


def _error(scene) -> str:
    with pytest.raises(ConfigError) as info:
        load_config(scene)
    return str(info.value)


@pytest.mark.parametrize("change, key, fragment", [
    (lambda s: s["water"]["layers"][0].update(a=-1), "water.layers[0].a = -1",
     "allowed: a number 0 .. 1e+06"),
    (lambda s: s["water"]["layers"][0].update(b=-0.5), "water.layers[0].b = -0.5",
     "allowed: a number 0 .. 1e+06"),
    (lambda s: s["water"]["layers"][0]["phase"].update(g=1.0),
     "water.layers[0].phase.g = 1.0", "allowed: a number -0.999999 .. 0.999999"),
    (lambda s: s["water"]["layers"][0]["phase"].update(g=-1.0),
     "water.layers[0].phase.g = -1.0", "allowed: a number -0.999999 .. 0.999999"),
    (lambda s: s["surface"].update(n_water=0.9), "surface.n_water = 0.9",
     "allowed: a number 1 .. 3"),
    (lambda s: s["bottom"].update(reflectance=1.5), "bottom.reflectance = 1.5",
     "allowed: a number 0 .. 1"),
    (lambda s: s["bottom"].update(reflectance=-0.1), "bottom.reflectance = -0.1",
     "allowed: a number 0 .. 1"),
    (lambda s: s["illumination"].update(sun_zenith_deg=90), "illumination.sun_zenith_deg = 90",
     "allowed: a number >= 0 and < 90"),
    (lambda s: s["illumination"].update(sun_zenith_deg=-1), "illumination.sun_zenith_deg = -1",
     "allowed: a number >= 0 and < 90"),
    (lambda s: s["illumination"].update(diffuse_fraction=1.2),
     "illumination.diffuse_fraction = 1.2", "allowed: a number 0 .. 1"),
    (lambda s: s["illumination"].update(sky="stormy"), "illumination.sky = 'stormy'",
     "'cardioidal'"),
    (lambda s: s.update(photons=0), "photons = 0", "allowed: an integer 1 .. 1e+13"),
    (lambda s: s.update(photons="many"), "photons = 'many'", "integer"),
    (lambda s: s["tallies"].update(depths_m=[0, 5]), "tallies.depths_m", "below the bottom"),
    (lambda s: s["tallies"].update(depths_m=[-1]), "tallies.depths_m[0] = -1",
     "allowed: a number >= 0"),
    (lambda s: s["tallies"].update(theta_edges_deg=[0, 100, 90, 180]), "tallies.theta_edges_deg",
     "increase"),
    (lambda s: s["water"]["layers"][0].update(colour="blue"), "water.layers[0].colour",
     "unknown key"),
    (lambda s: s.update(photon=5), "photon", "unknown key"),
    (lambda s: s["bottom"].update(model="mud"), "bottom.model = 'mud'", "allowed"),
    (lambda s: s["bottom"].update(model="minnaert"), "bottom.k", "missing"),
    (lambda s: s["water"]["layers"][0].update(a=math.nan), "water.layers[0].a = nan", "finite"),
    (lambda s: s["water"]["layers"][0].update(thickness_m=0), "water.layers[0].thickness_m = 0",
     "allowed: a number > 0"),
    (lambda s: s["water"]["layers"][0]["phase"].update(model="mie"),
     "water.layers[0].phase.model = 'mie'", "'petzold'"),
    (lambda s: s["water"]["layers"][0]["phase"].pop("model"), "water.layers[0].phase.model",
     "missing"),
    (lambda s: s.update(water={"layers": []}), "water.layers", "at least 1"),
])
def test_bad_values_name_key_value_and_allowed(small_scene, change, key, fragment):
    change(small_scene)
    message = _error(small_scene)
    assert key in message, message
    assert fragment in message, message
    assert "Traceback" not in message


@pytest.mark.parametrize("change, message", [
    (lambda s: s.update(estimator={"upward_fraction": "autoo"}),
     "config: estimator.upward_fraction = 'autoo': allowed: a number > 0 and < 1 or 'auto'"),
    (lambda s: s.update(estimator={"upward_fraction": -0.1}),
     "config: estimator.upward_fraction = -0.1: allowed: a number > 0 and < 1 or 'auto'"),
    (lambda s: s["tallies"].update(theta_edges_deg="hydrolite"),
     "config: tallies.theta_edges_deg = 'hydrolite': allowed: 'hydrolight' or a valid list"),
    (lambda s: s["bottom"].update(reflectance={"fil": "sand.csv"}),
     "config: bottom.reflectance.fil: unknown key; did you mean file?"),
    (lambda s: s["illumination"].update(sky={"mapp": "sky.csv"}),
     "config: illumination.sky.mapp: unknown key; did you mean map?"),
    # a key given without its unit (chl for chl_mg_m3) is matched by the key without it, and
    # counts as the missing key it stands for
    (lambda s: s["water"].update(layers=[{"thickness_m": float("inf"), "components": [
        {"model": "pure_water"}, {"model": "case1", "chl": 1.0}]}]),
     "config: water.layers[0].components[1].chl: unknown key; did you mean chl_mg_m3?"),
    # a value of the wrong form where the union picks its member by form: every form named
    (lambda s: s.update(wavelengths_nm=550),
     "config: wavelengths_nm = 550: allowed: a list or a mapping {start, stop, step}"),
    (lambda s: s["illumination"].update(sky="harrison-coombes"),
     "config: illumination.sky = 'harrison-coombes': allowed: 'uniform', 'cardioidal', "
     "'overcast', 'harrison_coombes' or a mapping {map} (did you mean 'harrison_coombes'?)"),
    # a non-number where a number or another form is allowed: not the number's range alone
    (lambda s: s["bottom"].update(reflectance="x"),
     "config: bottom.reflectance = 'x': expected a number or a list or a mapping {file}"),
    # a list of the list member's form but not of numbers: that member's own problem
    (lambda s: s["tallies"].update(theta_edges_deg=["a"]),
     "config: tallies.theta_edges_deg[0] = 'a': allowed: a finite number (and 1 more "
     "problem)"),
    # a key of another section: its path there
    # a boolean for a string: what the key takes, not "a number"
    (lambda s: s.update(name=False),
     "config: name = False: expected a string (YAML reads true, false, yes, no, on and off as "
     "booleans)"),
    (lambda s: s.update(sun_zenith=30),
     "config: sun_zenith: unknown key; did you mean illumination.sun_zenith_deg (not at this "
     "level)?"),
    # two keys without their units: one problem each, not two
    (lambda s: s["illumination"].update(sun_position={"time": "2024-06-21T12:00:00Z",
                                                      "latitude": 1, "longitude": 2}),
     "config: illumination.sun_position.latitude: unknown key; did you mean latitude_deg? "
     "(and 1 more problem)"),
    # a value of the wrong form at a key of one form: that form in words, not pydantic's
    # Python types ('a valid tuple', 'a valid dictionary or instance of Inelastic')
    (lambda s: s["tallies"].update(local_directions_deg=[180, 0]),
     "config: tallies.local_directions_deg[0] = 180: expected a list of 2 numbers (and 1 more "
     "problem)"),
    (lambda s: s["water"].update(inelastic=["raman"]),
     "config: water.inelastic = ['raman']: expected a mapping of its keys (raman, "
     "chlorophyll_fluorescence, cdom_fluorescence, max_step_nm)"),
    (lambda s: s["water"].update(inelastic={"chlorophyll_fluorescence": {
        "excitation_range_nm": 400}}),
     "config: water.inelastic.chlorophyll_fluorescence.excitation_range_nm = 400: expected a "
     "list of 2 numbers"),
    (lambda s: s.update(bottom="lambertian"),
     "config: bottom = 'lambertian': expected a mapping {model: ..., ...} with model one of "
     "none, black, lambertian, minnaert, specular, lambertian_specular, ggx, hapke, table, "
     "mixture"),
])
def test_a_value_no_member_of_a_union_takes_is_one_line_naming_what_each_allows(
        small_scene, change, message):
    """A key that takes one of several kinds (a number or 'auto'; a list or 'hydrolight'; a
    value or a table file) gets one pydantic error per kind: one line says what each allows,
    under the key as the user wrote it (no 'constrained-float'); a misspelt key of a mapping
    is named before the keys it leaves missing, and is the one problem where it is the key
    suggested."""
    change(small_scene)
    assert _error(small_scene) == message

@pytest.mark.parametrize("change, message", [
    (lambda s: s.update(batches=1), "batches = 1: allowed: an integer 2 .. 100000"),
    (lambda s: s["water"]["layers"][0].update(thickness_m=-1),
     "water.layers[0].thickness_m = -1: allowed: a number > 0"),
    (lambda s: s["illumination"].update(sun_zenith_deg=95),
     "illumination.sun_zenith_deg = 95: allowed: a number >= 0 and < 90"),
    (lambda s: s["bottom"].update(reflectance=1.5),
     "bottom.reflectance = 1.5: allowed: a number 0 .. 1"),
    (lambda s: s["bottom"].update(reflectance=[0.2, -0.1]),
     "bottom.reflectance[1] = -0.1: allowed: a number 0 .. 1"),
    (lambda s: s["water"]["layers"][0]["phase"].update(g=1.0),
     "water.layers[0].phase.g = 1.0: allowed: a number -0.999999 .. 0.999999"),
    (lambda s: s["surface"].update(model="cox_munk", wind_speed_m_s=40),
     "surface.wind_speed_m_s = 40: allowed: a number 0 .. 30"),
    (lambda s: s.update(wavelengths_nm=[400, 50]),
     "wavelengths_nm[1] = 50: allowed: a number 100 .. 10000"),
    (lambda s: s["tallies"].update(local_directions_deg=[[120, 360]]),
     "tallies.local_directions_deg[0][1] = 360: allowed: a number >= 0 and < 360"),
    (lambda s: s.update(photons=0), "photons = 0: allowed: an integer 1 .. 1e+13"),
])
def test_a_number_out_of_range_names_the_range_the_key_allows(tmp_path, small_scene, change,
                                                               message):
    """Out of its range, a number was refused in pydantic's words, one bound at a time
    ('batches = 1: Input should be greater than or equal to 2'); now as photons' and seed's
    were, with the key's whole range as a bare nan's message writes it, and by `oceanmc run`
    in that one line, exit status 2."""
    change(small_scene)
    assert _error(small_scene) == f"config: {message}"
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(small_scene))
    done = subprocess.run([sys.executable, "-m", "oceanmc", "run", str(path), "-o",
                           str(tmp_path / "r.h5")], cwd=tmp_path, capture_output=True,
                          text=True, timeout=600, env=dict(os.environ, PYTHONPATH=str(REPO)))
    assert (done.returncode, done.stderr) == (2, f"oceanmc: config error: {path}: {message}\n")



@pytest.mark.parametrize("change, message", [
    (lambda s: s.update(surface={"model": "coxmunk"}),
     "surface.model = 'coxmunk': allowed: 'flat', 'none' or 'cox_munk' (did you mean "
     "'cox_munk'?)"),
    (lambda s: s.update(surface={"model": "wavy"}),
     "surface.model = 'wavy': allowed: 'flat', 'none' or 'cox_munk'"),
    (lambda s: s.update(estimator={"mode": "analogue"}),
     "estimator.mode = 'analogue': allowed: 'implicit' or 'analog' (did you mean 'analog'?)"),
    # and lists of too few or too many, and a value that is no boolean (the same review)
    (lambda s: s["water"].update(layers=[]), "water.layers = []: allowed: at least 1 item "
     "(found 0)"),
    (lambda s: s["tallies"].update(local_directions_deg=[[180, 0]] * 65),
     "tallies.local_directions_deg = [[180, 0], [180, 0], [180, 0], [180, 0], [180, 0], "
     "[180, 0], [180, 0], [180, ...: allowed: at most 64 items (found 65)"),
    (lambda s: s["tallies"].update(radiance="maybe"),
     "tallies.radiance = 'maybe': allowed: true or false"),
    # a word or a list of a union's members (the code review of the change)
    (lambda s: s["illumination"].update(sky="unifrom"),
     "illumination.sky = 'unifrom': allowed: 'uniform', 'cardioidal', 'overcast', "
     "'harrison_coombes' or a mapping {map} (did you mean 'uniform'?)"),
    (lambda s: s.update(wavelengths_nm=[]), "wavelengths_nm = []: allowed: at least 1 item "
     "(found 0)"),
])
def test_a_word_not_allowed_is_answered_with_the_words_allowed(small_scene, change, message):
    """One of a few words misspelt was refused in pydantic's words ("surface.model =
    'coxmunk': Input should be 'flat', 'none' or 'cox_munk'", a user's review); now as every
    other message, with the nearest word where it is a misspelling."""
    change(small_scene)
    assert _error(small_scene) == f"config: {message}"


@pytest.mark.parametrize("change, message", [
    (lambda s: s.update(photons=True), "config: photons = True: expected a number"),
    (lambda s: s["water"]["layers"][0].update(a=True),
     "config: water.layers[0]: a = True: expected a number or a list"),
    (lambda s: s["bottom"].update(reflectance=False),
     "config: bottom: reflectance = False: expected a number, a list or a mapping"),
    (lambda s: s["illumination"].update(sun_zenith_deg=True),
     "config: illumination: sun_zenith_deg = True: expected a number"),
    (lambda s: s["water"].update(inelastic=True),
     "config: water: inelastic = True: expected a mapping"),
])
def test_a_boolean_for_a_number_is_refused(small_scene, change, message):
    """pydantic reads True as 1 and YAML reads yes/no/on/off as booleans: `a: yes` ran with
    a = 1 and exit status 0. Refused in one line naming the key."""
    change(small_scene)
    assert _error(small_scene).startswith(message + " (YAML reads true, false, yes, no, on "
                                          "and off as booleans)")


@pytest.mark.parametrize("line, message", [
    ("  sun_zenith_deg: '30'", "illumination.sun_zenith_deg = '30'"),
    ('  sun_zenith_deg: "1.5e+1"', "illumination.sun_zenith_deg = '1.5e+1'"),
    ("  depths_m: [0, '1']", "tallies.depths_m[1] = '1'"),
    ("  depths_m: [1e-1, '1']", "tallies.depths_m[1] = '1'")])
def test_a_quoted_number_is_refused(tmp_path, small_scene, line, message):
    """`sun_zenith_deg: '30'` ran as 30 (pydantic reads the string as a number): a number in
    the scene is written as a number. (A quoted '1e1' is read as the number: it cannot be told
    from an unquoted 1e1, which YAML 1.1 reads as a string; '1.5e+1' it reads as a number.)"""
    del small_scene["illumination"]["sun_zenith_deg"], small_scene["tallies"]
    text = yaml.safe_dump(small_scene).replace("illumination:\n", "illumination:\n" + line + "\n")
    if "depths_m" in line:
        text = yaml.safe_dump(small_scene) + "tallies:\n" + line + "\n"
    path = tmp_path / "scene.yaml"
    path.write_text(text)
    with pytest.raises(ConfigError) as info:
        load_config(path)
    assert str(info.value) == (f"{path}: {message}: expected a number, got a string (write the "
                               "number without quotes)")


def test_a_quoted_number_is_refused_where_a_name_is_allowed_too(small_scene):
    small_scene["estimator"] = {"upward_fraction": "0.5"}   # a number, 'auto' or null
    assert _error(small_scene) == ("config: estimator.upward_fraction = '0.5': expected a "
                                   "number, got a string (write the number without quotes)")
    small_scene["estimator"] = {"upward_fraction": "auto"}
    assert load_config(small_scene).estimator.upward_fraction == "auto"


@pytest.mark.parametrize("where, written, message", [
    (("illumination", "sun_zenith_deg"), "inf",
     "illumination.sun_zenith_deg = inf: not a finite number; allowed: a number >= 0 and < 90"),
    (("illumination", "sun_zenith_deg"), "-inf",
     "illumination.sun_zenith_deg = -inf: not a finite number; allowed: a number >= 0 and < 90"),
    (("illumination", "sun_zenith_deg"), "NaN",
     "illumination.sun_zenith_deg = NaN: not a finite number; allowed: a number >= 0 and < 90"),
    (("bottom", "reflectance"), "nan",
     "bottom.reflectance = nan: not a finite number; allowed: a number 0 .. 1"),
    (("batches",), "inf", "batches = inf: not a finite number; allowed: an integer 2 .. 100000"),
    (("photons",), "nan", "photons = nan: not a finite number; allowed: an integer 1 .. 1e+13"),
    (("photons",), "-inf", "photons = -inf: not a finite number; allowed: an integer 1 .. 1e+13"),
    (("tallies", "depths_m", 1), "inf",
     "tallies.depths_m[1] = inf: not a finite number; allowed: a number >= 0"),
    # a key that takes .inf (an infinitely deep layer): the way to write it
    (("water", "layers", 0, "thickness_m"), "inf",
     "water.layers[0].thickness_m = inf: YAML reads a bare inf as text; write .inf for "
     "infinity")])
def test_a_bare_inf_or_nan_is_refused_as_not_finite_not_as_quoted(tmp_path, small_scene, where,
                                                                    written, message):
    """YAML 1.1 reads a bare inf, -inf or nan as a string: `sun_zenith_deg: inf` was refused
    with "write the number without quotes", though no quotes were written (and `photons: nan`
    as "unable to parse string as an integer"). The message says what is wrong and what is
    allowed."""
    node = small_scene
    for step in where[:-1]:
        node = node[step]
    node[where[-1]] = "SENTINEL"
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(small_scene).replace("SENTINEL", written))
    with pytest.raises(ConfigError) as info:
        load_config(path)
    assert str(info.value) == f"{path}: {message}"


@pytest.mark.parametrize("key, value, shown", [
    ("sun_zenith_deg", ".inf", "inf"), ("sun_zenith_deg", ".nan", "nan"),
    ("sun_zenith_deg", "-.inf", "-inf"), ("diffuse_fraction", ".NaN", "nan")])
def test_yaml_infinity_and_nan_are_refused_where_a_finite_number_is_needed(
        tmp_path, small_scene, key, value, shown):
    """.inf and .nan, which YAML reads as floats, are refused in one line naming the key."""
    small_scene["illumination"][key] = "SENTINEL"
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(small_scene).replace("SENTINEL", value))
    with pytest.raises(ConfigError) as info:
        load_config(path)
    assert str(info.value).startswith(f"{path}: illumination.{key} = {shown}: ")
    assert "finite number" in str(info.value) and "\n" not in str(info.value)


def test_a_photon_count_beyond_the_limit_is_shown_in_readable_digits(tmp_path, small_scene):
    """`photons: 100000000000000000000` (an integer to YAML) was refused as pydantic's `photons
    = 100000000000000000000: Input should be less than or equal to 10000000000000`: every digit
    of the value and of the limit. Shown as the float forms are (`photons = 1e+308: allowed: an
    integer 1 .. 1e+13`), and as `--photons` shows one (cli.py, config.scene.readable_count)."""
    small_scene["photons"] = "SENTINEL"
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(small_scene).replace("SENTINEL", "100000000000000000000"))
    with pytest.raises(ConfigError) as info:
        load_config(path)
    assert str(info.value) == f"{path}: photons = 1e+20: allowed: an integer 1 .. 1e+13"
    for value, shown in ((-10**20, "-1e+20"), (10**400, "1000000000... (401 digits)"),
                         (10**5000, "an integer of more than 4300 digits")):
        small_scene["photons"] = value
        assert _error(small_scene) == \
            f"config: photons = {shown}: allowed: an integer 1 .. 1e+13"
    small_scene["photons"] = 10**13   # the limit itself loads
    assert load_config(small_scene).photons == 10**13


@pytest.mark.parametrize("written, shown", [
    ("9223372036854775808", "9223372036854775808"), ("-1", "-1"),
    ("1.0e+19", "1e+19"), ("9" * 30, "9999999999... (30 digits)")])
def test_a_seed_beyond_int64_is_refused_naming_the_allowed_range(tmp_path, small_scene,
                                                                 written, shown):
    """`seed: 9223372036854775808` was refused in pydantic's words, "Input should be less than
    9223372036854775808", a float beyond it as "Unable to parse input string as an integer,
    exceeded maximum size"; -1 as "greater than or equal to 0". One range, as photons' are."""
    small_scene["seed"] = "SENTINEL"
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(small_scene).replace("SENTINEL", written))
    with pytest.raises(ConfigError) as info:
        load_config(path)
    assert str(info.value) == \
        f"{path}: seed = {shown}: allowed: an integer 0 .. 9223372036854775807"
    small_scene["seed"] = 2**63 - 1   # the limit itself loads
    assert load_config(small_scene).seed == 2**63 - 1


def test_a_seed_given_as_nan_names_the_exact_range(tmp_path, small_scene):
    """The range of a bare nan's message was rounded to 6 digits: `an integer 0 ..
    9.22337e+18`, which reads as if 9223372036854775807 were beyond it."""
    small_scene["seed"] = "nan"
    assert _error(small_scene) == ("config: seed = nan: not a finite number; allowed: an "
                                   "integer 0 .. 9223372036854775807")


def test_an_integer_of_more_than_4300_digits_is_refused_in_one_line(tmp_path, small_scene):
    """Python (3.11+) will not turn an integer of more than 4300 digits into text or back:
    one in a scene file was a ValueError traceback from PyYAML's int(), one in a dict (seed) a
    ValueError from the message's repr()."""
    small_scene["photons"] = "SENTINEL"
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(small_scene).replace("SENTINEL", "9" * 5000))
    with pytest.raises(ConfigError) as info:
        load_config(path)
    assert str(info.value).startswith(f"{path}: not valid for a scene: line ")
    assert str(info.value).endswith(": an integer of 5000 digits; allowed: at most 4300 digits")
    small_scene["photons"] = 20000
    small_scene["seed"] = 10**5000
    assert _error(small_scene) == ("config: seed = an integer of more than 4300 digits: "
                                   "allowed: an integer 0 .. 9223372036854775807")


def test_a_number_with_an_exponent_is_a_number_and_a_name_that_looks_like_one_round_trips(
        tmp_path, small_scene):
    """YAML 1.1 (PyYAML, which reads the stored configs back) reads 1e-1 and 2.5e1 (no decimal
    point, or an unsigned exponent) as strings: they are let through as the numbers, from a
    file and from a dict of yaml.safe_load alike (a YAML 1.2 loader had made the dict's strings
    'quoted numbers' and the unquoted name 1e6 a float, which no longer loaded back)."""
    small_scene["name"] = "1e6"
    text = (yaml.safe_dump(small_scene).replace("a: 0.1", "a: 1e-1")
            .replace("sun_zenith_deg: 30", "sun_zenith_deg: 2.5e1"))
    assert "name: 1e6\n" in text   # safe_dump writes the name unquoted: YAML 1.1 reads text
    path = tmp_path / "scene.yaml"
    path.write_text(text)
    config = load_config(path)
    assert (config.water.layers[0].a, config.illumination.sun_zenith_deg) == (0.1, 25.0)
    assert config.name == "1e6" and load_config(yaml.safe_load(text)) == config
    stored = config_to_yaml(config)
    assert "name: 1e6\n" in stored and yaml.safe_load(stored)["name"] == "1e6"
    path.write_text(stored)
    assert load_config(path) == config and load_config(yaml.safe_load(stored)) == config


def test_a_gaussian_profile_given_integral_and_total_mg_m2_says_they_are_one_quantity(
        small_scene):
    """The README accepts total_mg_m2 for integral; both given was called an unknown key."""
    profile = {"profile": "gaussian", "background": 0.1, "peak_depth_m": 1.0, "width_m": 0.5,
               "integral": 2.0, "total_mg_m2": 3.0}
    small_scene["water"]["layers"][0]["components"] = [
        {"model": "pure_water"}, {"model": "chlorophyll", "chl_mg_m3": profile}]
    for key in ("a", "b", "phase"):
        del small_scene["water"]["layers"][0][key]
    small_scene["wavelengths_nm"] = [550.0]
    assert _error(small_scene) == (
        "config: water.layers[0].components[1].chl_mg_m3: integral = 2.0 and total_mg_m2 = "
        "3.0: the same quantity given twice (total_mg_m2 is another name for integral); give "
        "one of them")
    del profile["integral"]
    assert load_config(small_scene).water.layers[0].components[1].chl_mg_m3.integral == 3.0


def test_a_blank_inelastic_process_is_refused_and_the_stored_config_leaves_out_those_off(
        small_scene):
    """`raman:` with nothing after it is YAML's null, which turned Raman scattering off (exit
    status 0) where the user asked for it: refused in one line. The stored config leaves out
    the processes that are off instead of writing them as null, and loads back the same."""
    small_scene["wavelengths_nm"] = [500.0, 550.0]
    small_scene["water"]["inelastic"] = {"raman": None, "chlorophyll_fluorescence": {}}
    assert _error(small_scene) == (
        "config: water.inelastic: raman = null (nothing after 'raman:'): give {} for its "
        "published defaults, or leave the key out to turn it off")
    small_scene["water"]["inelastic"] = {"chlorophyll_fluorescence": {}}
    config = load_config(small_scene)
    text = config_to_yaml(config)
    assert "raman" not in text and "cdom_fluorescence" not in text
    assert load_config(yaml.safe_load(text)).water.inelastic == config.water.inelastic


def test_booleans_stay_allowed_where_they_mean_something(small_scene):
    small_scene["tallies"]["radiance"] = False
    small_scene["estimator"] = {"depth_splitting": True}   # YAML's `on`
    config = load_config(small_scene)
    assert config.tallies.radiance is False and config.estimator.depth_splitting == "on"


def test_bottom_none_needs_an_infinitely_deep_layer(small_scene):
    small_scene["bottom"] = {"model": "none"}
    assert "infinitely deep" in _error(small_scene)


def test_infinite_layer_needs_bottom_none(small_scene):
    small_scene["water"]["layers"][0]["thickness_m"] = math.inf
    assert "bottom.model = 'lambertian'" in _error(small_scene)


def test_only_the_last_layer_may_be_infinite(small_scene):
    small_scene["water"]["layers"] = [{"thickness_m": math.inf, "a": 0.1, "b": 0.1},
                                      {"thickness_m": 1, "a": 0.1, "b": 0.1}]
    assert "only the last layer" in _error(small_scene)


def test_conservative_infinite_scatterer_is_refused():
    scene = {"water": {"layers": [{"thickness_m": math.inf, "a": 0.0, "b": 0.1}]},
             "bottom": {"model": "none"}}
    assert "needs a > 0" in _error(scene)


def test_mixture_b_mismatch_is_refused():
    scene = {"water": {"layers": [{"thickness_m": 1, "a": 0.1, "b": 1.0, "phase": {
        "model": "mixture", "components": [{"b": 0.3, "phase": {"model": "petzold"}}]}}]},
        "bottom": {"model": "black"}}
    assert "sum of the mixture" in _error(scene)


@pytest.mark.parametrize("text, fragment", [
    ("", "empty"),
    ("- 1\n- 2\n", "top level must be a mapping"),
    ("water: [unclosed\n", "not valid YAML"),
    ("name: x\n", "water: required key is missing"),
])
def test_bad_files(tmp_path, text, fragment):
    path = tmp_path / "scene.yaml"
    path.write_text(text)
    with pytest.raises(ConfigError) as info:
        load_config(path)
    assert fragment in str(info.value)
    assert str(path) in str(info.value)


def test_missing_file(tmp_path):
    with pytest.raises(ConfigError, match="no such file"):
        load_config(tmp_path / "nope.yaml")


def test_table_phase_path_is_relative_to_the_config(tmp_path):
    (tmp_path / "vsf.csv").write_text("0,10\n90,1\n180,2\n")
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump({
        "water": {"layers": [{"thickness_m": 1, "a": 0.1, "b": 0.1,
                              "phase": {"model": "table", "file": "vsf.csv"}}]},
        "bottom": {"model": "black"}}))
    config = load_config(path)
    assert config.water.layers[0].phase.file == str(tmp_path / "vsf.csv")


@pytest.mark.parametrize("content, fragment", [
    (None, "no such file"),
    ("", "at least 2 rows"),
    ("0,1\n90,x\n", "not a number"),
    ("0,1,2\n90,1,2\n", "expected 2 columns"),
    ("0,1\n90,-1\n180,1\n", "negative"),
    ("0,1\n90,1\n45,1\n", "increase strictly"),
    ("0,1\n90,nan\n", "NaN"),
    ("0,1\n200,1\n", "0..180"),
])
def test_bad_phase_tables_name_the_file(tmp_path, small_scene, content, fragment):
    table = tmp_path / "vsf.csv"
    if content is not None:
        table.write_text(content)
    small_scene["water"]["layers"][0]["phase"] = {"model": "table", "file": str(table)}
    with pytest.raises(ConfigError) as info:
        oceanmc.simulate(small_scene)
    assert fragment in str(info.value)
    assert str(table) in str(info.value)


def test_a_key_with_a_line_break_is_named_on_one_line():
    """A key the fuzz test found ('\\n' under illumination): the message names it quoted, on
    one line."""
    with pytest.raises(ConfigError) as info:
        load_config({"illumination": {"\n": None}})
    message = str(info.value)
    assert "\n" not in message and "illumination.'\\n'" in message, message
