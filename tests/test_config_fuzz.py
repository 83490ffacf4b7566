"""Fuzzing the scene loader: any input either loads or fails with one ConfigError; nothing else
escapes, nothing hangs, no results file is written."""
import math
import os
import subprocess
import sys

import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from oceanmc.config import ConfigError, load_config

from conftest import REPO, SMALL_SCENE

KEYS = ["name", "photons", "seed", "batches", "illumination", "surface", "water", "bottom",
        "tallies", "estimator", "layers", "thickness_m", "a", "b", "phase", "model", "g",
        "reflectance", "k", "depths_m", "Ed0", "sun_zenith_deg", "diffuse_fraction", "sky",
        "n_water", "components", "file", "theta_edges_deg", "phi_bands", "mode", "bb_ratio",
        "petzold", "lambertian", "minnaert", "none", "flat", "ünïcödé", ""]

scalars = st.one_of(
    st.none(), st.booleans(), st.integers(min_value=-10**30, max_value=10**30),
    st.floats(allow_nan=True, allow_infinity=True), st.text(max_size=20),
    st.sampled_from(["petzold", "lambertian", "flat", "none", ".inf", "nan", "1e400"]),
)
values = st.recursive(
    scalars,
    lambda children: st.one_of(
        st.lists(children, max_size=6),
        st.dictionaries(st.sampled_from(KEYS) | st.text(max_size=8), children, max_size=6)),
    max_leaves=40)


def _load(data):
    try:
        load_config(data)
    except ConfigError as exc:
        message = str(exc)
        assert message and "\n" not in message.strip() and "Traceback" not in message


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(values)
def test_random_documents_load_or_fail_cleanly(data):
    if isinstance(data, dict):
        _load(data)
    else:
        _load({"water": data, "bottom": data})


def _mutate(tree, path, value):
    node = tree
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value


PATHS = [("photons",), ("seed",), ("batches",), ("illumination", "sun_zenith_deg"),
         ("illumination", "Ed0"), ("illumination", "diffuse_fraction"), ("surface", "n_water"),
         ("water", "layers", 0, "a"), ("water", "layers", 0, "b"),
         ("water", "layers", 0, "thickness_m"), ("water", "layers", 0, "phase", "g"),
         ("bottom", "reflectance"), ("tallies", "depths_m"), ("tallies", "phi_bands"),
         ("water", "layers"), ("bottom",), ("water", "layers", 0, "phase")]


@settings(max_examples=400, deadline=None)
@given(st.sampled_from(PATHS), values)
def test_one_bad_value_in_a_good_scene(path, value):
    import copy
    scene = copy.deepcopy(SMALL_SCENE)
    _mutate(scene, path, value)
    _load(scene)


@settings(max_examples=200, deadline=None)
@given(st.text(max_size=200) | st.binary(max_size=200).map(lambda b: b.decode("latin-1")))
def test_random_yaml_text(tmp_path_factory, text):
    path = tmp_path_factory.mktemp("fuzz") / "scene.yaml"
    path.write_text(text, encoding="utf-8")
    _load_path(path)


def _load_path(path):
    try:
        load_config(path)
    except ConfigError as exc:
        assert str(path) in str(exc)


def test_huge_and_deep_inputs(tmp_path):
    deep = "a: " + "[" * 5000 + "]" * 5000 + "\n"
    path = tmp_path / "deep.yaml"
    path.write_text(deep)
    _load_path(path)
    huge = dict(SMALL_SCENE, tallies={"depths_m": [0.5] * 200_000})
    try:
        load_config(huge)
        raise AssertionError("200000 tally depths were accepted")
    except ConfigError as exc:
        assert "at most 10000" in str(exc)
    many = dict(SMALL_SCENE, water={"layers": [{"thickness_m": 1e-3, "a": 0.1, "b": 0.1}] * 2000})
    assert len(load_config(many).water.layers) == 2000
    for bad in (math.nan, math.inf, -math.inf, 1e308 * 10):
        _load(dict(SMALL_SCENE, photons=bad))


def test_cli_on_fuzzed_files_never_tracebacks_or_writes(tmp_path):
    texts = ["", "[]", "water: 5\nbottom: 5", "photons: .nan\nwater: {layers: []}",
             "\x00\x01", "water: {layers: [{thickness_m: .inf, a: 0, b: 0}]}\nbottom: {model: x}",
             yaml.safe_dump(dict(SMALL_SCENE, photons=-1))]
    env = dict(os.environ, PYTHONPATH=str(REPO))
    for i, text in enumerate(texts):
        path = tmp_path / f"s{i}.yaml"
        path.write_text(text)
        done = subprocess.run([sys.executable, "-m", "oceanmc", "run", str(path), "-o",
                               str(tmp_path / f"s{i}.h5")], capture_output=True, text=True,
                              env=env, timeout=120)
        assert done.returncode == 2, (text, done.stderr)
        assert "Traceback" not in done.stderr and done.stderr.startswith("oceanmc:"), done.stderr
        assert not (tmp_path / f"s{i}.h5").exists()
