"""`oceanmc sweep`: key paths and axes, validation before any photon, and real Dask clusters on
127.0.0.1 (a LocalCluster of two worker processes; a scheduler and two workers started as
separate processes, one of them killed mid-sweep; a rerun after Ctrl-C). Every point is checked
bit for bit against simulate() of its scene, which is what `oceanmc run` of it computes."""
import copy
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml

import oceanmc
from conftest import REPO
from oceanmc.run.derived import derive
from oceanmc.sweeps import FailedPoints, SweepError, load_sweep, set_key_path
from oceanmc.sweeps.dataset import variable_name
from oceanmc.sweeps.points import build_points

ENV = dict(os.environ, PYTHONPATH=str(REPO))
PYTHON_BIN = Path(sys.executable).parent

TINY = {
    "name": "tiny sweep scene",
    "photons": 1200,
    "batches": 4,
    "seed": 7,
    "illumination": {"sun_zenith_deg": 30, "diffuse_fraction": 0.2},
    "water": {"layers": [{"thickness_m": 2.0, "a": 0.1, "b": 0.4,
                          "phase": {"model": "henyey_greenstein", "g": 0.8}}]},
    "bottom": {"model": "lambertian", "reflectance": 0.3},
    "tallies": {"depths_m": [0, 1]},
}


def sweep_file(tmp_path, axes, base=TINY, **extra):
    path = tmp_path / "sweep.yaml"
    path.write_text(yaml.safe_dump({"base": base, "axes": axes, **extra}, sort_keys=False))
    return path


def oceanmc_cli(*args, cwd, **kwargs):
    return subprocess.Popen([sys.executable, "-m", "oceanmc", *map(str, args)], cwd=cwd,
                            env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            **kwargs)


def assert_points_match_single_runs(ds, spec_source, only_done=False):
    """Each done point's estimates and standard errors equal those of one simulate() of its
    scene, exactly."""
    checked = 0
    for point in build_points(load_sweep(spec_source)):
        if ds["status"].values[point.index] != "done":
            assert only_done, point.label
            continue
        single = oceanmc.simulate(point.config, threads=1)
        # every quantity, and the derived ones (Kd, R, Q, ...: the results file's group
        # `derived`) as derived_NAME
        pairs = [(name, q.mean, q.stderr) for name, q in single.quantities.items()] + \
            [(f"derived/{d.name}", d.value, d.stderr) for d in derive(single).values()]
        assert any(name == "derived/Kd" for name, _, _ in pairs)
        for name, mean, stderr in pairs:
            var = variable_name(name)
            assert np.array_equal(ds[var].values[point.index], mean, equal_nan=True), \
                (point.label, name)
            assert np.array_equal(ds[var + "_stderr"].values[point.index], stderr,
                                  equal_nan=True), (point.label, name)
        checked += 1
    return checked


# --- key paths and axes (no cluster) -------------------------------------------------------------

def test_key_paths_reach_nested_lists_and_create_missing_mappings():
    scene = copy.deepcopy(TINY)
    scene["water"]["layers"][0]["phase"] = {"model": "mixture", "components": [
        {"b": 0.1, "phase": {"model": "pure_water"}}, {"b": 0.3, "phase": {"model": "petzold"}}]}
    set_key_path(scene, "water.layers[0].phase.components[1].b", 0.5)
    set_key_path(scene, "water.layers[-1].a", 0.2)
    set_key_path(scene, "surface.n_water", 1.33)          # `surface` is not in the base scene
    assert scene["water"]["layers"][0]["phase"]["components"][1]["b"] == 0.5
    assert scene["water"]["layers"][0]["a"] == 0.2
    assert scene["surface"] == {"n_water": 1.33}
    with pytest.raises(SweepError, match=r"water\.layers has 1 entry .*allowed indices -1 \.\. 0"):
        set_key_path(scene, "water.layers[1].a", 0.1)
    with pytest.raises(SweepError, match="bottom is not a list"):
        set_key_path(scene, "bottom[0].reflectance", 0.1)
    with pytest.raises(SweepError, match="not a key path"):
        set_key_path(scene, "water..a", 0.1)


def test_unknown_key_in_an_axis_is_named_with_a_suggestion(tmp_path):
    """A misspelt key on the way to a list index said `water.layerz has 0 entries`: it is an
    unknown key, with the nearest valid one (the schema's keys at that level); a valid key the
    base scene leaves out cannot be indexed; one line, exit 2, before anything runs."""
    scene = copy.deepcopy(TINY)
    with pytest.raises(SweepError, match=r"^axes: water\.layerz\[0\]\.a: water\.layerz is an "
                                         r"unknown key; did you mean water\.layers\?$"):
        set_key_path(scene, "water.layerz[0].a", 0.1)
    with pytest.raises(SweepError, match=r"illumination\.skyy is an unknown key; did you mean "
                                         r"illumination\.sky\?"):
        set_key_path(scene, "illumination.skyy.x", 1)
    with pytest.raises(SweepError, match=r"estimator\.foo is an unknown key; allowed keys there: "
                                         r".*split_weight"):
        set_key_path(scene, "estimator.foo.bar", 1)
    with pytest.raises(SweepError, match=r"the base scene has no tallies\.local_directions_deg, "
                                         r"so \[0\] does not apply"):
        set_key_path(scene, "tallies.local_directions_deg[0]", [180, 0])
    scene = copy.deepcopy(TINY)
    set_key_path(scene, "surface.n_water", 1.34)     # a key the base scene leaves out: created
    assert scene == {**TINY, "surface": {"n_water": 1.34}}
    path = sweep_file(tmp_path, {"water.layerz[0].a": [0.1, 0.2]})
    done = subprocess.run([sys.executable, "-m", "oceanmc", "sweep", path, "-o", "lut.nc"],
                          cwd=tmp_path, env=ENV, capture_output=True, text=True, timeout=300)
    assert done.returncode == 2, done.stderr
    assert done.stderr == ("oceanmc: config error: axes: water.layerz[0].a: water.layerz is an "
                           "unknown key; did you mean water.layers?\n")
    assert not (tmp_path / "lut.nc").exists() and not (tmp_path / "lut.points").exists()


def test_axes_product_zip_and_generators(tmp_path):
    spec = load_sweep(sweep_file(tmp_path, {
        "water.layers[0].a": {"geomspace": [0.01, 1.0, 3]},
        "zip": {"illumination.sun_zenith_deg": [0, 60],
                "illumination.diffuse_fraction": [0.1, 0.3]},
    }))
    assert spec.shape == (3, 2)
    points = build_points(spec)
    assert len(points) == 6 and len({p.key for p in points}) == 6
    last = points[-1].config
    assert last.water.layers[0].a == pytest.approx(1.0)
    assert (last.illumination.sun_zenith_deg, last.illumination.diffuse_fraction) == (60, 0.3)
    with pytest.raises(SweepError, match="equal lengths"):
        load_sweep(sweep_file(tmp_path, {"zip": {"bottom.reflectance": [0.1, 0.2],
                                                 "water.layers[0].a": [0.1]}}))


def test_a_notebook_s_numpy_axes_and_settings_are_the_lists_a_file_gives(tmp_path):
    """A sweep given as a mapping with np.linspace axes and numpy numbers under `set` was
    refused ('expected a non-empty list of values') or raised PyYAML's RepresenterError (a
    user's review): the same points, labels and scenes as the plain lists."""
    plain = {"base": TINY, "set": {"photons": 4000},
             "axes": {"bottom.reflectance": [0.1, 0.2, 0.3],
                      "zip": {"illumination.sun_zenith_deg": [0, 60],
                              "illumination.diffuse_fraction": [0.1, 0.3]}}}
    numpy = {"base": TINY, "set": {"photons": np.int64(4000)},
             "axes": {"bottom.reflectance": np.linspace(0.1, 0.3, 3),
                      "zip": {"illumination.sun_zenith_deg": np.array([0, 60]),
                              "illumination.diffuse_fraction": [np.float64(0.1),
                                                                np.float64(0.3)]}}}
    expected, got = (build_points(load_sweep(spec)) for spec in (plain, numpy))
    assert [p.key for p in got] == [p.key for p in expected]
    assert [p.label for p in got] == [p.label for p in expected]
    assert got[-1].config == expected[-1].config


def test_an_axis_may_have_a_short_name(tmp_path):
    """`NAME: {key: PATH, values: [...]}` beside `PATH: [...]`, also in a zip group: the axis
    (the dataset's dimension) and coordinate are named NAME; the sweep's stored text reads
    back as the same axes."""
    spec = load_sweep(sweep_file(tmp_path, {
        "absorption": {"key": "water.layers[0].a", "values": {"linspace": [0.1, 0.3, 3]}},
        "bottom.reflectance": [0.1, 0.4],
        "zip": {"sun": {"key": "illumination.sun_zenith_deg", "values": [0, 60]},
                "illumination.diffuse_fraction": [0.1, 0.3]},
    }))
    assert [axis.dim for axis in spec.axes] == ["absorption", "bottom.reflectance", "sun"]
    assert spec.axes[2].names == ("sun", "illumination.diffuse_fraction")
    assert spec.axes[0].keys == ("water.layers[0].a",)
    last = build_points(spec)[-1].config
    assert last.water.layers[0].a == pytest.approx(0.3)
    assert last.illumination.sun_zenith_deg == 60
    again = load_sweep({"base": TINY, **yaml.safe_load(spec.to_yaml())})
    assert again.axes == spec.axes


def test_an_axis_of_exponent_numbers_is_a_numeric_coordinate(tmp_path):
    """YAML 1.1 (PyYAML) reads 1e-2 and 5e-1 (no decimal point) as strings: an axis written
    with them became a text coordinate of the dataset (a zip group's mixed [1e-1, 0.2] one of
    YAML texts), and {geomspace: [1e-1, 4e-1, 3]} was refused as not numbers. They are the
    numbers, as in a scene."""
    from oceanmc.sweeps.dataset import assemble

    path = sweep_file(tmp_path, {
        "water.layers[0].a": ["1e-2", "2e-2"],
        "zip": {"bottom.reflectance": ["1e-1", 0.2],
                "g": {"key": "water.layers[0].phase.g", "values": ["5e-1", "8e-1"]}},
        "water.layers[0].b": {"geomspace": ["1e-1", "4e-1", 3]}})
    text = path.read_text()
    assert "- 1e-2\n" in text and "- 1e-1\n" in text and "- 4e-1\n" in text   # unquoted
    spec = load_sweep(path)
    dataset = assemble(spec, build_points(spec), {}, {})
    for name, values in (("water.layers[0].a", [0.01, 0.02]), ("bottom.reflectance", [0.1, 0.2]),
                         ("g", [0.5, 0.8]), ("water.layers[0].b", [0.1, 0.2, 0.4])):
        assert dataset[name].dtype == np.float64, name
        assert dataset[name].values == pytest.approx(values), name


@pytest.mark.parametrize("axes, message", [
    ({"depth": {"key": "water.layers[0].thickness_m", "values": [1, 2]}},
     "depth: the name is taken by the sweep dataset's own"),
    ({"air_x": {"key": "bottom.reflectance", "values": [0.1]}}, "the name is taken"),
    ({"chl": {"key": "bottom.reflectance"}}, "values is missing"),
    ({"chl": {"key": "bottom.reflectance", "values": [0.1], "unit": "1"}}, "unknown key 'unit'"),
    ({"bottom.reflectance": {"key": "bottom.reflectance", "values": [0.1]}},
     "a short axis name is letters, digits and _"),
    ({"a": {"key": "bottom.reflectance", "values": [0.1]},
      "zip": {"a": {"key": "water.layers[0].a", "values": [0.1]}, "water.layers[0].b": [0.1]}},
     r"a: the name is given twice \(bottom.reflectance and water.layers\[0\].a\)"),
    ({"chl": {"key": "bottom..reflectance", "values": [0.1]}}, "is not a key path"),
    # a misspelt key of the named form: that form, the key and the nearest one (it said
    # "expected a list of values or one of {linspace ...}")
    ({"chl": {"kee": "bottom.reflectance", "values": [0.1]}},
     "a named axis is {key: KEY.PATH, values: \\[...\\]}; unknown key 'kee'; did you mean key\\?"),
])
def test_a_bad_short_axis_name_is_refused_in_one_line(tmp_path, axes, message):
    with pytest.raises(SweepError, match=message):
        load_sweep(sweep_file(tmp_path, axes))


def test_every_point_is_validated_first_with_its_coordinates_one_line_exit_2(tmp_path):
    path = sweep_file(tmp_path, {"water.layers[0].a": [0.1, 0.2],
                                 "bottom.reflectance": [0.5, 1.5]})
    done = subprocess.run([sys.executable, "-m", "oceanmc", "sweep", path, "-o", "lut.nc"],
                          cwd=tmp_path, env=ENV, capture_output=True, text=True, timeout=300)
    assert done.returncode == 2, done.stderr
    lines = [line for line in done.stderr.splitlines() if "compil" not in line]
    assert len(lines) == 1, done.stderr
    assert lines[0].startswith("oceanmc: config error: point (water.layers[0].a = 0.1, "
                               "bottom.reflectance = 1.5): bottom.reflectance = 1.5")
    assert "(and 1 more point)" in lines[0]
    assert not (tmp_path / "lut.nc").exists() and not (tmp_path / "lut.points").exists()
    with pytest.raises(SweepError, match=r"tallies\.depths_m differs"):
        build_points(load_sweep(sweep_file(tmp_path, {"tallies.depths_m": [[0], [0, 1]]})))


@pytest.mark.parametrize("settings, axes, message", [
    ({"illumination.sun_zenit_deg": 30}, {"bottom.reflectance": [0.1, 0.2]},
     r"set: illumination\.sun_zenit_deg: unknown key; did you mean sun_zenith_deg\?"),
    ({"water.layers[0].q": 1}, {"bottom.reflectance": [0.1, 0.2]},
     r"set: water\.layers\[0\]\.q: unknown key \(check its spelling and level\)"),
    ({"illumination.sun_zenith_deg": 300}, {"bottom.reflectance": [0.1, 0.2]},
     r"set: illumination\.sun_zenith_deg = 300: allowed: a number >= 0 and < 90"),
    # at one point only: which one, and that the value is the set's
    ({"photons": 10}, {"batches": [4, 8]},
     r"point \(batches = 8\): set: photons = 10: need at least 2 per batch \(batches = 8\)"),
    # the axis's value, not the set's: the point, as before
    ({"bottom": {"model": "lambertian", "reflectance": 0.3}}, {"bottom.reflectance": [0.1, 1.5]},
     r"point \(bottom\.reflectance = 1\.5\): bottom\.reflectance = 1\.5: allowed: a number 0 "
     r"\.\. 1$")])
def test_a_bad_value_under_set_is_named_as_the_sweep_file_gives_it(tmp_path, settings, axes,
                                                                   message):
    """A `set:` key the scene refuses was blamed on the first point, `(and N more points)`,
    as if the axes' values were wrong; now the message starts `set:` (with the point only where
    the problem is at some points and not others)."""
    with pytest.raises(SweepError, match=f"^{message}") as info:
        build_points(load_sweep(sweep_file(tmp_path, axes, set=settings)))
    assert "\n" not in str(info.value) and "more point" not in str(info.value)


@pytest.mark.parametrize("settings, axes, message", [
    ({"bottom.model": "ggx", "bottom.roughness": 0.3}, {"water.layers[0].a": [0.1, 0.2]},
     "set: bottom.model = 'ggx': takes no bottom.reflectance, which the base scene gives "
     "(set: changes only the keys it names; give the whole bottom mapping there instead)"),
    ({"bottom.model": "black"}, {"water.layers[0].a": [0.1, 0.2]},
     "set: bottom.model = 'black': takes no bottom.reflectance, which the base scene gives "
     "(set: changes only the keys it names; give the whole bottom mapping there instead)"),
    ({"bottom.model": "minnaert"}, {"water.layers[0].a": [0.1, 0.2]},
     "set: bottom.model = 'minnaert': bottom.k: required key is missing"),
    # an axis that switches the model: its point, and the model's value
    ({}, {"bottom.model": ["lambertian", "black"]},
     "point (bottom.model = black): bottom.model = 'black': takes no bottom.reflectance, "
     "which the base scene gives (an axis changes only the keys it names; give the whole "
     "bottom mapping there instead)")])
def test_a_model_switched_over_the_base_scenes_keys_names_the_switch_and_the_key(
        tmp_path, settings, axes, message):
    """`set: {bottom.model: ggx}` over a base scene's lambertian bottom (reflectance: 0.3)
    was refused as `point (water.layers[0].a = 0.1): bottom.reflectance: unknown key; did you
    mean diffuse_reflectance? (and 1 more point)`, blaming the axes; `minnaert` as `point
    (...): bottom.k: required key is missing`. set: and the axes change only the keys they
    name (README: Sweeps), so the message names the model's key path, its value and the
    base scene's key it does not take (or the key it needs)."""
    with pytest.raises(SweepError) as info:
        build_points(load_sweep(sweep_file(tmp_path, axes, set=settings)))
    assert str(info.value) == message
    # what the message says to do: the whole mapping under set:
    whole = {"bottom": {"model": "ggx", "roughness": 0.3}}
    points = build_points(load_sweep(sweep_file(tmp_path, {"water.layers[0].a": [0.1, 0.2]},
                                                set=whole)))
    assert [p.config.bottom.model for p in points] == ["ggx", "ggx"]


def test_oceanmc_sweep_refuses_a_model_switched_by_set_in_one_line_exit_2(tmp_path):
    path = sweep_file(tmp_path, {"water.layers[0].a": [0.1, 0.2]},
                      set={"bottom.model": "black"})
    done = subprocess.run([sys.executable, "-m", "oceanmc", "sweep", path, "-o", "lut.nc"],
                          cwd=tmp_path, env=ENV, capture_output=True, text=True, timeout=300)
    assert done.returncode == 2, done.stderr
    assert done.stderr == ("oceanmc: config error: set: bottom.model = 'black': takes no "
                           "bottom.reflectance, which the base scene gives (set: changes only "
                           "the keys it names; give the whole bottom mapping there instead)\n")
    assert not (tmp_path / "lut.nc").exists() and not (tmp_path / "lut.points").exists()


def test_a_table_file_under_set_that_cannot_be_read_is_named_as_set(tmp_path):
    """A table file given under `set:` that is missing or malformed (found when each point's
    scene is built, after the schema) was blamed on the first point, `point (water.layers[0].a
    = 0.1): BRDF table ...: no such file (and 1 more point)`, as if an axis were wrong; now the
    message names `set:` and the file's key. A file an axis gives is still its point's."""
    (tmp_path / "bad.csv").write_text("garbage\n1,2\n")
    (tmp_path / "phase.csv").write_text("0,10\n10,1\n90,0.1\n180,0.1\n")
    axes = {"water.layers[0].a": [0.1, 0.2]}
    table_phase = copy.deepcopy(TINY)
    table_phase["water"]["layers"][0]["phase"] = {"model": "table", "file": "phase.csv"}
    for base, settings, start in (
            (TINY, {"bottom": {"model": "table", "file": "missing.csv"}},
             f"set: bottom.file: BRDF table {tmp_path / 'missing.csv'}: no such file"),
            (TINY, {"water.layers[0].phase": {"model": "table", "file": "bad.csv"}},
             f"set: water.layers[0].phase.file: phase table {tmp_path / 'bad.csv'}: "),
            (table_phase, {"water.layers[0].phase.file": "missing.csv"},
             f"set: water.layers[0].phase.file: phase table {tmp_path / 'missing.csv'}: ")):
        with pytest.raises(SweepError) as info:
            oceanmc.sweeps.prepare(sweep_file(tmp_path, axes, base=base, set=settings),
                                   tmp_path / "lut.points")
        assert str(info.value).startswith(start), str(info.value)
        assert "point" not in str(info.value) and "\n" not in str(info.value)
    settings = {"water.layers[0].phase": {"model": "table", "file": "phase.csv"}}
    with pytest.raises(SweepError, match=r"^point \(water\.layers\[0\]\.phase\.file = "
                       r"missing\.csv\): phase table .*missing\.csv: no such file$"):
        oceanmc.sweeps.prepare(sweep_file(tmp_path, {"water.layers[0].phase.file": [
            "phase.csv", "missing.csv"]}, set=settings), tmp_path / "lut.points")
    assert not (tmp_path / "lut.points").exists()


def test_repeated_axis_values_and_too_many_batch_groups_are_refused_before_any_run(tmp_path):
    """A value given twice on an axis (the dataset's coordinate would hold it twice, and
    selecting it return two points), and batch_groups beyond what a point's batches allow
    (each group runs as a scene of 2 batches or more): one line naming the key, before
    anything is compiled or run."""
    with pytest.raises(SweepError, match=r"^axes: bottom\.reflectance: point 3 repeats point 1 "
                       r"\(0\.1\); allowed: distinct values$"):
        load_sweep(sweep_file(tmp_path, {"bottom.reflectance": [0.1, 0.2, 0.1]}))
    with pytest.raises(SweepError, match=r"axes: bottom\.reflectance and bottom\.model: point 2"):
        load_sweep(sweep_file(tmp_path, {"zip": {"bottom.reflectance": [0.1, 0.1],
                                                 "bottom.model": ["lambertian"] * 2}}))
    # the same reflectance with another model is another point
    load_sweep(sweep_file(tmp_path, {"zip": {"bottom.reflectance": [0.1, 0.1],
                                             "bottom.model": ["lambertian", "minnaert"]}}))
    path = sweep_file(tmp_path, {"bottom.reflectance": [0.1]}, batch_groups=4)   # 4 batches
    with pytest.raises(SweepError, match=r"^batch_groups = 4: point \(bottom\.reflectance = "
                       r"0\.1\) has 4 batches, which can be spread over at most 2 groups .*"
                       r"allowed: 1 \.\. 2, or give the scene more batches$"):
        oceanmc.sweeps.prepare(path, tmp_path / "lut.points")
    assert not (tmp_path / "lut.points").exists()


@pytest.mark.parametrize("option", [{"workers": 0}, {"workers": -1}, {"threads": 0},
                                    {"batch_groups": 0}, {"batch_groups": 1.5}])
def test_sweep_options_of_the_python_api_are_checked_as_the_command_checks_them(tmp_path,
                                                                                 option):
    """oceanmc.sweep(workers=-1) started no worker and waited for ever, batch_groups=0 divided
    by zero: each is refused in one line before anything runs."""
    (name, value), = option.items()
    with pytest.raises(SweepError, match=rf"^{name} = {value!r}: expected an integer >= 1$"):
        oceanmc.sweep(sweep_file(tmp_path, {"bottom.reflectance": [0.1]}), **option)


def test_a_misspelt_top_level_key_names_the_nearest(tmp_path):
    with pytest.raises(SweepError, match=r"sweep: batch_group: unknown key; did you mean "
                                         r"batch_groups\? \(allowed: base, set, axes"):
        load_sweep(sweep_file(tmp_path, {"bottom.reflectance": [0.1]}, batch_group=2))


def test_a_sweep_without_axes_is_one_point_and_exits_0(tmp_path):
    """The README's sweep with no axes (one scene spread over batch groups): the dataset is
    written and the command exits 0 (it crashed on the 0-d status array after writing it)."""
    path = tmp_path / "one.yaml"
    path.write_text(yaml.safe_dump({"base": TINY, "batch_groups": 2}, sort_keys=False))
    done = subprocess.run([sys.executable, "-m", "oceanmc", "sweep", path, "-o", "one.nc",
                           "--workers", "1", "--threads", "1"], cwd=tmp_path, env=ENV,
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert "1 of 1 points done, 0 failed" in done.stdout and "Traceback" not in done.stderr
    with xr.open_dataset(tmp_path / "one.nc", engine="h5netcdf") as ds:
        assert ds["status"].values[()] == "done"


# --- a LocalCluster of two worker processes ---------------------------------------------------

@pytest.mark.long(cpu_s=23)
def test_local_cluster_two_processes_points_bit_identical_batch_groups_and_rerun(tmp_path):
    path = sweep_file(tmp_path, {"water.layers[0].a": [0.05, 0.2],
                                 "zip": {"bottom.reflectance": [0.1, 0.4],
                                         "bottom.model": ["lambertian", "lambertian"]}},
                      batch_groups=2)
    out = tmp_path / "lut.nc"
    ds = oceanmc.sweep(path, out, workers=2, threads=1)
    assert ds.attrs["points_done"] == 4 and ds.attrs["partial"] == 0
    assert ds["air_Rrs_nadir"].dims == ("water.layers[0].a", "bottom.reflectance")
    assert ds["radiance"].dims[2:] == ("depth", "theta", "phi")
    assert list(ds["bottom.model"].values) == ["lambertian", "lambertian"]
    stored = xr.open_dataset(out, engine="h5netcdf")
    assert yaml.safe_load(stored.attrs["base_scene_yaml"]) == TINY
    assert "water.layers[0].a" in yaml.safe_load(stored.attrs["sweep_yaml"])["axes"]
    xr.testing.assert_identical(stored.load(), ds)
    # batches spread over two tasks per point, merged: the same numbers as one run
    assert assert_points_match_single_runs(ds, path) == 4
    # the K functions along the interval between the tally depths, which it names
    assert ds["derived_Kd"].dims[-1] == "depth_interval"
    assert list(ds["depth_upper"].values) == [0.0] and list(ds["depth_lower"].values) == [1.0]
    # more photons per point beside the reflectance axis: the finished points are skipped
    spec = yaml.safe_load(path.read_text())
    spec["axes"]["water.layers[0].a"].append(0.4)
    path.write_text(yaml.safe_dump(spec, sort_keys=False))
    said = []
    again = oceanmc.sweep(path, out, workers=2, threads=1, log=said.append)
    assert "4 finished earlier, 2 to run" in said[0]
    assert again.attrs["points_done"] == 6
    xr.testing.assert_equal(again.isel({"water.layers[0].a": slice(0, 2)})
                                .drop_vars(["wall_time_s"]), ds.drop_vars(["wall_time_s"]))


def test_a_failing_point_is_recorded_and_the_others_run(tmp_path, monkeypatch, thread_client):
    import oceanmc.run.simulation as simulation
    real = simulation.simulate

    def simulate(config, **kwargs):
        if config.water.layers[0].a == 0.2:
            raise FloatingPointError("the kernel gave up on this point")
        return real(config, **kwargs)

    monkeypatch.setattr(simulation, "simulate", simulate)  # the workers are threads here
    path = sweep_file(tmp_path, {"water.layers[0].a": [0.1, 0.2, 0.3]})
    # (a notebook is told: it returned without a sign before, a user's review)
    with pytest.warns(FailedPoints, match="1 of 3 points failed"):
        ds = oceanmc.sweep(path, tmp_path / "lut.nc", client=thread_client, threads=1)
    assert list(ds["status"].values) == ["done", "failed", "done"]
    assert ds["error"].values[1] == "FloatingPointError: the kernel gave up on this point"
    assert np.isnan(ds["air_Rrs_nadir"].values[1])
    assert np.all(np.isfinite(ds["air_Rrs_nadir"].values[[0, 2]]))
    assert ds.attrs["points_failed"] == 1
    assert ds[ds["status"].dims[0]].attrs["units"] == "m-1"   # CF units of the axis (a review)


def test_an_axis_s_units_come_from_its_key_s_name():
    from oceanmc.sweeps.dataset import axis_units
    assert [axis_units(k) for k in (
        "water.layers[0].thickness_m", "illumination.sun_zenith_deg", "surface.wind_speed_m_s",
        "water.layers[0].components[1].chl_mg_m3", "water.layers[2].b", "bottom.reflectance",
        "photons", "illumination.spectrum.ozone_atm_cm", "water.inelastic.raman.b488_per_m",
        "illumination.spectrum.surface_pressure_pa")] == [
        "m", "degree", "m s-1", "mg m-3", "m-1", None, None, "atm-cm", "m-1", "Pa"]


# --- a scheduler and two workers as separate processes; one killed mid-sweep ----------------

@pytest.fixture
def dask_processes(tmp_path):
    scheduler_file = tmp_path / "scheduler.json"
    dask = str(PYTHON_BIN / "dask")
    started = [subprocess.Popen([dask, "scheduler", "--host", "127.0.0.1", "--port", "0",
                                 "--no-dashboard", "--scheduler-file", scheduler_file],
                                env=ENV, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    deadline = time.monotonic() + 60
    while not scheduler_file.is_file():
        assert time.monotonic() < deadline, "the Dask scheduler did not start"
        time.sleep(0.1)
    address = yaml.safe_load(scheduler_file.read_text())["address"]
    for _ in range(2):
        started.append(subprocess.Popen(
            [dask, "worker", address, "--host", "127.0.0.1", "--nthreads", "1", "--no-nanny",
             "--no-dashboard"], env=ENV, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
    from distributed import Client
    with Client(address, timeout="60s") as client:
        client.wait_for_workers(2, timeout=60)
    yield address, started[1:]
    for process in reversed(started):
        process.kill()
        process.wait()


@pytest.mark.long(cpu_s=16)
def test_separate_scheduler_and_workers_survive_a_killed_worker(tmp_path, dask_processes):
    address, workers = dask_processes
    scene = copy.deepcopy(TINY)
    scene["photons"] = 8000      # long enough that the killed worker has points in hand
    path = sweep_file(tmp_path, {"water.layers[0].a": [0.05, 0.1, 0.2, 0.3],
                                 "bottom.reflectance": [0.1, 0.5]}, base=scene)
    points = tmp_path / "lut.points"
    run = oceanmc_cli("sweep", path, "-o", "lut.nc", "--scheduler", address, "--threads", "1",
                      "-q", cwd=tmp_path)
    deadline = time.monotonic() + 120
    while not (points.is_dir() and any(points.glob("*.h5"))):
        assert run.poll() is None, run.communicate()
        assert time.monotonic() < deadline, "no point finished"
        time.sleep(0.05)
    workers[0].kill()       # SIGKILL: its points in hand are lost and must be run elsewhere
    out, err = run.communicate(timeout=240)
    assert run.returncode == 0, err
    assert "8 of 8 points done, 0 failed" in out
    ds = xr.open_dataset(tmp_path / "lut.nc", engine="h5netcdf").load()
    assert (ds["status"].values == "done").all()
    assert assert_points_match_single_runs(ds, path) == 8


# --- Ctrl-C, then a rerun -------------------------------------------------------------------

@pytest.mark.long(cpu_s=22)
def test_ctrl_c_leaves_a_valid_partial_dataset_and_a_rerun_finishes_it(tmp_path):
    scene = copy.deepcopy(TINY)
    scene["photons"] = 20000
    path = sweep_file(tmp_path, {"water.layers[0].a": [0.05, 0.1, 0.2, 0.3, 0.4, 0.5]},
                      base=scene)
    points = tmp_path / "lut.points"
    run = oceanmc_cli("sweep", path, "-o", "lut.nc", "--workers", "1", "-q", cwd=tmp_path)
    deadline = time.monotonic() + 120
    while not (points.is_dir() and any(points.glob("*.h5"))):
        assert run.poll() is None, run.communicate()
        assert time.monotonic() < deadline, "no point finished"
        time.sleep(0.05)
    run.send_signal(signal.SIGINT)
    out, err = run.communicate(timeout=120)
    assert run.returncode == 130, err
    assert "sweep interrupted: wrote lut.nc" in err
    partial = xr.open_dataset(tmp_path / "lut.nc", engine="h5netcdf").load()
    done = int((partial["status"].values == "done").sum())
    assert partial.attrs["partial"] == 1 and 1 <= done < 6
    assert partial.attrs["points_pending"] == 6 - done
    assert np.isnan(partial["Ed"].values[partial["status"].values == "pending"]).all()
    assert assert_points_match_single_runs(partial, path, only_done=True) == done
    rerun = oceanmc_cli("sweep", path, "-o", "lut.nc", "--workers", "1", "-q", cwd=tmp_path)
    out, err = rerun.communicate(timeout=240)
    assert rerun.returncode == 0, err
    # the point in hand when Ctrl-C came may have been written since, by its worker
    earlier = int(re.search(r"(\d+) finished earlier, (\d+) to run", err).group(1))
    assert done <= earlier < 6 and f"{earlier} finished earlier, {6 - earlier} to run" in err
    final = xr.open_dataset(tmp_path / "lut.nc", engine="h5netcdf").load()
    assert final.attrs["partial"] == 0 and (final["status"].values == "done").all()
    assert assert_points_match_single_runs(final, path) == 6


# --- a dataset of another sweep is never replaced without --overwrite ---------------------------

def test_another_sweeps_dataset_is_refused_without_overwrite_and_a_rerun_is_not(
        tmp_path, thread_client):
    """lut.nc of sweep A: sweep B (other axis values, or another base scene) to the same lut.nc
    is refused in one line, exit 2, before anything runs, the dataset and the points folder
    untouched; A again, or A with a value added to an axis, replaces it (the resume feature);
    --overwrite replaces another sweep's dataset."""
    out = tmp_path / "lut.nc"
    a = sweep_file(tmp_path, {"water.layers[0].a": [0.05, 0.1],
                              "bottom.reflectance": [0.1, 0.2]})
    a = a.rename(tmp_path / "a.yaml")
    first = oceanmc.sweep(a, out, client=thread_client, threads=1)
    assert first.attrs["points_done"] == 4
    before = out.read_bytes()
    folder = sorted(p.name for p in (tmp_path / "lut.points").iterdir())

    def refused(spec, *words):
        done = subprocess.run([sys.executable, "-m", "oceanmc", "sweep", spec, "-o",
                               "lut.nc", "-q"], cwd=tmp_path, env=ENV, capture_output=True,
                              text=True, timeout=300)
        assert done.returncode == 2, done.stderr
        assert done.stderr.count("\n") == 1 and "Traceback" not in done.stderr, done.stderr
        assert done.stderr.startswith("oceanmc: error: lut.nc holds the dataset of another "
                                      "sweep ("), done.stderr
        assert "--overwrite" in done.stderr
        for word in words:
            assert word in done.stderr, done.stderr
        assert out.read_bytes() == before
        assert sorted(p.name for p in (tmp_path / "lut.points").iterdir()) == folder
        return done.stderr

    # other values on the same axes (a.yaml's 0.05 gone), then another base scene
    b = sweep_file(tmp_path, {"water.layers[0].a": [0.1, 0.3],
                              "bottom.reflectance": [0.1, 0.2]}).rename(tmp_path / "b.yaml")
    refused(b, "its point (water.layers[0].a = 0.05, bottom.reflectance = 0.1) is not one "
               "of this sweep's, and 1 more of its 4 points")
    other_base = copy.deepcopy(TINY)
    other_base["seed"] = 8
    c = sweep_file(tmp_path, {"water.layers[0].a": [0.05, 0.1],
                              "bottom.reflectance": [0.1, 0.2]}, base=other_base)
    refused(c.rename(tmp_path / "c.yaml"), "its base scene differs: seed differs")
    with pytest.raises(oceanmc.sweeps.OutputExists, match="another sweep"):
        oceanmc.sweep(b, out, client=thread_client, threads=1)     # the Python call refuses too
    assert out.read_bytes() == before

    # the same sweep with its axes in another order and a value added: not another sweep
    spec = yaml.safe_load(a.read_text())
    spec["axes"] = {"bottom.reflectance": [0.1, 0.2],
                    "water.layers[0].a": [0.05, 0.1, 0.2]}
    a.write_text(yaml.safe_dump(spec, sort_keys=False))
    said = []
    grown = oceanmc.sweep(a, out, client=thread_client, threads=1, log=said.append)
    assert "4 finished earlier, 2 to run" in said[0] and grown.attrs["points_done"] == 6

    replaced = oceanmc.sweep(b, out, client=thread_client, threads=1, overwrite=True)
    assert list(replaced["water.layers[0].a"].values) == [0.1, 0.3]
    stored = xr.open_dataset(out, engine="h5netcdf").load()
    assert list(stored["water.layers[0].a"].values) == [0.1, 0.3]
    # a file that is no sweep dataset: refused as well
    (tmp_path / "notes.nc").write_text("not a dataset")
    done = subprocess.run([sys.executable, "-m", "oceanmc", "sweep", "b.yaml", "-o", "notes.nc"],
                          cwd=tmp_path, env=ENV, capture_output=True, text=True, timeout=300)
    assert done.returncode == 2 and done.stderr.count("\n") == 1, done.stderr
    assert "notes.nc exists and is not an oceanmc sweep dataset" in done.stderr


def test_a_dataset_of_a_sweep_in_e_notation_is_its_own_on_a_rerun(tmp_path):
    """A sweep file with 4e-1 and 1e-1 (strings to YAML 1.1) in its base and on an axis: its
    dataset's base_scene_yaml and sweep_yaml, as stored from them and read back with
    yaml.safe_load, are this sweep's, not another's (a YAML 1.2 loader made the file's values
    numbers, and such a dataset 'another sweep' on a rerun or a resume)."""
    import h5py

    from oceanmc.run.format import SWEEP_TITLE
    from oceanmc.sweeps.dataset import check_replaceable

    base = copy.deepcopy(TINY)
    base["water"]["layers"][0]["b"] = "4e-1"
    path = sweep_file(tmp_path, {"water.layers[0].a": ["1e-1", "2e-1"]}, base=base)
    assert "b: 4e-1\n" in path.read_text() and "- 1e-1\n" in path.read_text()
    written = yaml.safe_load(path.read_text())
    out = tmp_path / "lut.nc"
    with h5py.File(out, "w") as f:
        f.attrs["title"] = SWEEP_TITLE
        f.attrs["base_scene_yaml"] = yaml.safe_dump(written["base"], sort_keys=False)
        f.attrs["sweep_yaml"] = yaml.safe_dump({"set": {}, "axes": written["axes"]})
    check_replaceable(out, tmp_path / "lut.points", load_sweep(path))   # no OutputExists


# --- SIGTERM, and SIGINT inherited as ignored (a background job of a script) ---------------------

def _ignore_sigint():
    signal.signal(signal.SIGINT, signal.SIG_IGN)


@pytest.mark.parametrize("signal_number, preexec", [(signal.SIGTERM, None),
                                                    (signal.SIGINT, _ignore_sigint)],
                         ids=["sigterm", "sigint_inherited_as_ignored"])
def test_sigterm_or_ignored_sigint_stops_a_sweep_with_a_valid_partial_dataset(
        tmp_path, signal_number, preexec):
    """What a batch scheduler sends (SIGTERM), and kill -INT to a sweep a script started in the
    background (SIGINT ignored from its start), stop it as Ctrl-C does: the points not finished
    are cancelled, lut.nc is written with those done (partial, the rest pending), the cluster is
    closed (no leaked semaphores), exit 130, within seconds."""
    scene = copy.deepcopy(TINY)
    scene["photons"] = 200000      # a point in hand when the signal comes
    path = sweep_file(tmp_path, {"water.layers[0].a": [0.05, 0.1, 0.2, 0.3, 0.4, 0.5]},
                      base=scene)
    points = tmp_path / "lut.points"
    run = oceanmc_cli("sweep", path, "-o", "lut.nc", "--workers", "1", "-q", cwd=tmp_path,
                      preexec_fn=preexec)
    deadline = time.monotonic() + 120
    while not (points.is_dir() and any(points.glob("*.h5"))):
        assert run.poll() is None, run.communicate()
        assert time.monotonic() < deadline, "no point finished"
        time.sleep(0.05)
    sent = time.monotonic()
    run.send_signal(signal_number)
    out, err = run.communicate(timeout=120)
    latency = time.monotonic() - sent
    print(f"exit {latency:.1f} s after {signal.Signals(signal_number).name}")
    assert run.returncode == 130, err
    assert latency < 30.0, latency
    assert "Traceback" not in err and "leaked" not in err, err
    assert f"stopped by {signal.Signals(signal_number).name}" in err
    assert "sweep interrupted: wrote lut.nc" in err
    partial = xr.open_dataset(tmp_path / "lut.nc", engine="h5netcdf").load()
    done = int((partial["status"].values == "done").sum())
    assert partial.attrs["partial"] == 1 and 1 <= done < 6
    assert partial.attrs["points_pending"] == 6 - done
    assert assert_points_match_single_runs(partial, path, only_done=True) == done
    assert sorted(p.name for p in tmp_path.iterdir()) == ["lut.nc", "lut.points", "sweep.yaml"]


def test_a_wavelength_added_for_the_excitation_outside_a_table_is_said_to_be_one(tmp_path):
    """A point's scene whose table stops above a wavelength the run adds for the Raman
    excitation is refused with the reason (OutsideTable.explained), as a single run's is: the
    user never asked for that wavelength."""
    (tmp_path / "aw.csv").write_text("wavelength_nm,a\n420,0.005\n700,0.63\n")
    base = copy.deepcopy(TINY)
    base["wavelengths_nm"] = [450.0, 550.0]
    base["water"] = {"layers": [{"thickness_m": 2.0, "components": [
        {"model": "pure_water", "absorption_file": "aw.csv"}]}],
        "inelastic": {"raman": {}}}
    with pytest.raises(SweepError) as info:
        oceanmc.sweeps.prepare(sweep_file(tmp_path, {"seed": [1, 2]}, base=base),
                               tmp_path / "lut.points")
    message = str(info.value)
    assert "water.layers[0].components[0].absorption_file: wavelength " in message, message
    assert "(traced for the excitation of water.inelastic, which adds " in message, message
    assert not (tmp_path / "lut.points").exists()


PACK_SCRIPT = """
import hashlib, sys, yaml
from oceanmc import scene
from oceanmc.config import load_config
packed = scene.build(load_config(yaml.safe_load(sys.stdin.read())))
print(hashlib.sha256(packed.floats.tobytes() + packed.ints.tobytes()).hexdigest())
"""


def test_a_packed_scene_does_not_depend_on_blas_threads():
    """A sweep's Dask workers run BLAS on one thread, `oceanmc run` on every core; a scene must
    pack to the same numbers either way, or a point is not its single run bit for bit. An
    inelastic scene with CDOM fluorescence (the transfers; the layers' backscattering): BLAS
    products on one and two OpenBLAS threads differed in the last bit of its transfers, until
    the packing summed them with numpy's own loops."""
    config = yaml.safe_load((REPO / "configs" / "raman_fluorescence.yaml").read_text())
    config["water"]["inelastic"]["cdom_fluorescence"] = {}
    digests = set()
    for threads in ("1", "2", "4"):
        env = dict(ENV, OPENBLAS_NUM_THREADS=threads, OMP_NUM_THREADS=threads,
                   MKL_NUM_THREADS=threads)
        done = subprocess.run([sys.executable, "-c", PACK_SCRIPT], input=yaml.safe_dump(config),
                              capture_output=True, text=True, env=env, cwd=REPO / "configs")
        assert done.returncode == 0, done.stderr
        digests.add(done.stdout.strip())
    assert len(digests) == 1


def test_points_that_trace_other_wavelengths_share_the_union_grid(tmp_path, thread_client):
    """An axis that switches Raman scattering on changes the wavelengths a point traces for the
    excitation (it crashed the dataset's assembly after every point had run): the dataset's
    grid is every wavelength some point traces, NaN where a point did not, and
    wavelength_traced says per point which were asked for (1), added for the excitation (2)
    or not traced (0); each point's values are its single run's."""
    base = copy.deepcopy(TINY)
    base["wavelengths_nm"] = [450.0, 500.0]
    base["water"] = {"layers": [{"thickness_m": 2.0, "components": [
        {"model": "pure_water"}, {"model": "case1", "chl_mg_m3": 0.5}]}]}
    axis = {"water.inelastic": [None, {"raman": {}}]}
    ds = oceanmc.sweep(sweep_file(tmp_path, axis, base=base), tmp_path / "lut.nc",
                       client=thread_client, threads=1)
    assert list(ds["status"].values) == ["done", "done"]
    grid = ds["wavelength"].values
    assert grid[0] < 400.0 and grid[-1] == 500.0 and list(grid).count(450.0) == 1
    flags = ds["wavelength_traced"].values
    asked = np.isin(grid, [450.0, 500.0])
    assert (flags[0] == np.where(asked, 1, 0)).all()
    assert (flags[1] == np.where(asked, 1, 2)).all()
    rrs = ds["air_Rrs_nadir"].values
    assert np.isnan(rrs[0, ~asked]).all() and np.isfinite(rrs[1]).all()
    for k, inelastic in enumerate(axis["water.inelastic"]):
        scene = copy.deepcopy(base)
        if inelastic is not None:
            scene["water"]["inelastic"] = inelastic
        single = oceanmc.simulate(scene, threads=1)
        traced = flags[k] > 0
        assert np.array_equal(rrs[k, traced], single["air/Rrs_nadir"]), k


def test_one_wavelength_points_beside_spectral_ones_take_their_place(tmp_path, thread_client):
    """An axis over wavelengths_nm mixing one wavelength and two: the one-wavelength point's
    values sit at its wavelength on the grid, NaN at the other (they were copied to every
    wavelength, or the assembly crashed); a sweep of one-wavelength points keeps no wavelength
    dimension; a point without wavelengths_nm beside spectral ones is refused before any run."""
    axis = {"wavelengths_nm": [[450.0], [450.0, 550.0]]}
    ds = oceanmc.sweep(sweep_file(tmp_path, axis), tmp_path / "lut.nc", client=thread_client,
                       threads=1)
    rrs = ds["air_Rrs_nadir"].values
    assert list(ds["wavelength"].values) == [450.0, 550.0]
    assert np.isfinite(rrs[0, 0]) and np.isnan(rrs[0, 1]) and np.isfinite(rrs[1]).all()
    assert ds["wavelength_traced"].values.tolist() == [[1, 0], [1, 1]]
    one = oceanmc.sweep(sweep_file(tmp_path, {"seed": [1, 2]},
                                   base=dict(TINY, wavelengths_nm=[550.0])),
                        tmp_path / "one.nc", client=thread_client, threads=1)
    assert one["air_Rrs_nadir"].dims == ("seed",) and "wavelength_traced" not in one
    with pytest.raises(SweepError, match="has no wavelengths_nm, point .* has: every point"):
        build_points(load_sweep(sweep_file(tmp_path, {"wavelengths_nm": [None, [450.0,
                                                                             550.0]]})))
