"""Sweep files (issue 29, section 6): NaN, +-inf, 1e308, 1e-308, -1 and 0 as axis values, in
`set`, in linspace/geomspace generators and as batch_groups; empty and malformed axes, unknown
keys, zip lists of different lengths, bases that do not exist or are not scenes. Each sweep is
refused in one line (SweepError, a ConfigError; `oceanmc sweep` prints it and exits with 2,
writing nothing) or gives points whose every scene is valid; no point is run here."""
import math
import os
import signal
import subprocess
import sys

import pytest
import yaml

from oceanmc.cli import main
from oceanmc.config import ConfigError
from oceanmc.sweeps import SweepError, load_sweep
from oceanmc.sweeps.points import build_points, check_scenes

from test_sweep import ENV, TINY

VALUES = (math.nan, math.inf, -math.inf, 1e308, 1e-308, -1, 0)
KEYS = ("water.layers[0].a", "water.layers[0].thickness_m", "photons", "seed", "batches",
        "bottom.reflectance", "illumination.sun_zenith_deg", "illumination.Ed0",
        "surface.n_water", "tallies.phi_bands", "estimator.split_weight")


def points_or_one_line(spec, *words):
    """The sweep's points (their scenes packed, as before a run), or its one-line refusal
    holding every word."""
    try:
        points = build_points(load_sweep(spec))
        check_scenes(points)
        return points
    except SweepError as exc:
        message = str(exc)
        assert message and "\n" not in message and "Traceback" not in message, message
        for word in words:
            assert word in message, (word, message)
        return message


def shown(value) -> tuple[str, ...]:
    return tuple({repr(value), str(value), f"{value:g}", yaml.safe_dump(value).split("\n")[0]})


@pytest.mark.parametrize("key", KEYS)
def test_extreme_axis_and_set_values_give_valid_points_or_one_line_naming_the_point(key):
    for value in VALUES:
        for spec, start in (({"base": TINY, "axes": {key: [0.5, value]}},
                             f"point ({key} = "), ({"base": TINY, "set": {key: value}},
                                                   (f"set: {key}", "point (): "))):
            got = points_or_one_line(spec)
            if isinstance(got, str):   # the key, or for a refusal across keys its value
                assert got.startswith(start), got
                assert key in got or any(s in got for s in shown(value)), got
    both = points_or_one_line({"base": TINY, "axes": {key: list(VALUES)}})
    assert isinstance(both, str) and "more point" in both   # NaN and inf at least


@pytest.mark.parametrize("kind", ["linspace", "geomspace"])
def test_generators_with_extreme_values_are_refused_in_one_line_or_valid(kind):
    for value in VALUES:
        for args in ([value, 1, 3], [1e-3, value, 3], [0.1, 0.2, value]):
            got = points_or_one_line({"base": TINY, "axes": {"water.layers[0].a":
                                                             {kind: args}}},
                                     "water.layers[0].a")
            if not isinstance(got, str):
                assert all(math.isfinite(p.config.water.layers[0].a) for p in got)
    for value in VALUES:
        got = points_or_one_line({"base": TINY, "axes": {"water.layers[0].a": [0.1]},
                                  "batch_groups": value}, "batch_groups")
        assert isinstance(got, str), got


STRUCTURES = [
    ("an empty axis", {"axes": {"water.layers[0].a": []}}, "non-empty list"),
    ("an axis mapping", {"axes": {"water.layers[0].a": {}}}, "expected a list of values"),
    ("an axis of None", {"axes": {"water.layers[0].a": None}}, "non-empty list"),
    ("an axis of one number", {"axes": {"water.layers[0].a": 0.1}}, "non-empty list"),
    ("an unknown generator", {"axes": {"water.layers[0].a": {"arange": [0, 1, 2]}}},
     "expected a list of values"),
    ("axes a list", {"axes": [1, 2]}, "expected a mapping"),
    ("an empty zip", {"axes": {"zip": {}}}, "two or more key paths"),
    ("a zip of one key", {"axes": {"zip": {"water.layers[0].a": [0.1, 0.2]}}},
     "two or more key paths"),
    ("a zip of None", {"axes": {"zip": None}}, "two or more key paths"),
    ("zip lists of different lengths", {"axes": {"zip": {"water.layers[0].a": [0.1, 0.2],
                                                         "bottom.reflectance": [0.1]}}},
     "equal lengths; got water.layers[0].a: 2, bottom.reflectance: 1"),
    ("zip lists of different lengths, one empty",
     {"axes": {"zip": {"water.layers[0].a": [0.1], "bottom.reflectance": []}}},
     "non-empty list"),
    ("a key twice", {"axes": {"water.layers[0].a": [0.1], "zip": {
        "water.layers[0].a": [0.1], "bottom.reflectance": [0.1]}}}, "appears twice"),
    ("an unknown key on the way", {"axes": {"water.layerz[0].a": [0.1]}},
     "water.layerz is an unknown key; did you mean water.layers?"),
    ("an unknown last key", {"axes": {"water.layers[0].zz": [0.1]}},
     "water.layers[0].zz: unknown key"),
    ("an index out of range", {"axes": {"water.layers[5].a": [0.1]}}, "allowed indices -1 .. 0"),
    ("a huge index", {"axes": {"water.layers[99999999999999999999].a": [0.1]}},
     "allowed indices -1 .. 0"),
    ("a key path of a number", {"axes": {5: [0.1]}}, "5 is not a key path"),
    ("an empty key path", {"axes": {"": [0.1]}}, "'' is not a key path"),
    ("two dots", {"axes": {"water..a": [0.1]}}, "is not a key path"),
    ("a key below a number", {"axes": {"photons.x": [1]}}, "photons is not a mapping"),
    ("a key below a list", {"axes": {"water.layers.a": [1]}}, "water.layers is not a mapping"),
    ("NaN inside a mapping value", {"axes": {"water.layers[0].phase": [
        {"model": "henyey_greenstein", "g": math.nan}]}}, "water.layers[0].phase.g = nan"),
    ("values of every type", {"axes": {"water.layers[0].a": [0.1, "x", None, [1], {"a": 1},
                                                             True]}},
     "water.layers[0].a = 'x'"),
    ("tallies differing", {"axes": {"tallies.depths_m": [[0], [0, 1]]}},
     "tallies.depths_m differs"),
    ("set a list", {"set": [1]}, "set: expected a mapping"),
    ("set a bad key", {"set": {"water..a": 1}}, "is not a key path"),
    ("an unknown sweep key", {"axis": {}}, "sweep: axis: unknown key"),
    ("no base", {"base": None}, "base: required key is missing"),
    ("base a list", {"base": [1]}, "expected a scene file or a scene mapping"),
    ("base a number", {"base": 5}, "expected a scene file or a scene mapping"),
    ("base not a scene", {"base": {"water": 5}}, "water"),
]


@pytest.mark.parametrize("label, changes, words", STRUCTURES, ids=[s[0] for s in STRUCTURES])
def test_malformed_sweeps_are_refused_in_one_line(label, changes, words):
    spec = {"base": TINY, **changes}
    got = points_or_one_line(spec, words)
    assert isinstance(got, str), (label, got)


@pytest.mark.parametrize("base, words", [
    ("nope.yaml", "no such file"), (".", "not a regular file"),
    ("bad.yaml", "not valid YAML: line 2"), ("binary.yaml", "not UTF-8 text"),
    ("empty.yaml", "not a scene"), ("list.yaml", "not a scene"),
    ("fifo.yaml", "not a regular file"), ("/dev/zero", "not a regular file"),
    ("big.yaml", "larger than 1024 KB; a scene file is a few KB of YAML"),
    ("bomb.yaml", "its aliases expand to more than 100,000 values; a scene needs far fewer"),
])
def test_a_base_file_that_is_missing_or_no_scene_is_refused_in_one_line(tmp_path, base, words):
    """The base is read with the scene loader's guards (config/loading.py read_yaml_file):
    /dev/zero was a MemoryError traceback and a FIFO blocked."""
    (tmp_path / "bad.yaml").write_text("water: [\n")
    (tmp_path / "binary.yaml").write_bytes(b"\xff\xfe\x00")
    (tmp_path / "empty.yaml").write_text("")
    (tmp_path / "list.yaml").write_text("[1, 2]\n")
    os.mkfifo(tmp_path / "fifo.yaml")
    (tmp_path / "big.yaml").write_text("# " + "x" * (1 << 20) + "\n")
    (tmp_path / "bomb.yaml").write_text(
        "a: &a [" + ",".join(["1"] * 10) + "]\n"
        + "".join(f"{n}: &{n} [" + ",".join([f"*{p}"] * 10) + "]\n"
                  for p, n in zip("abcde", "bcdef")))
    sweep = tmp_path / "sweep.yaml"
    sweep.write_text(yaml.safe_dump({"base": base, "axes": {"water.layers[0].a": [0.1]}}))
    assert points_or_one_line(sweep, f"base = {base!r}", words)
    assert points_or_one_line(tmp_path / "no_sweep.yaml", "no such file")
    assert points_or_one_line(tmp_path / "fifo.yaml", "fifo.yaml: not a regular file")


@pytest.fixture
def cli(tmp_path, monkeypatch, capsys):
    """oceanmc.cli.main in this process (its signal handlers put back afterwards), in
    tmp_path: (exit status, stderr)."""
    handlers = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    monkeypatch.chdir(tmp_path)

    def run(*argv):
        capsys.readouterr()
        try:
            code = main([str(a) for a in argv])
        finally:
            for number, handler in handlers.items():
                signal.signal(number, handler)
        return code, capsys.readouterr().err
    return run


@pytest.mark.parametrize("axes, words", [
    ({"water.layers[0].a": [0.1, math.nan]}, "point (water.layers[0].a = .nan): "
                                             "water.layers[0].a = nan"),
    ({"water.layers[0].a": [1e308]}, "water.layers[0].a = 1e+308"),
    ({"water.layers[0].a": {"linspace": [0, math.inf, 3]}}, "finite numbers"),
    ({"water.layers[0].a": []}, "non-empty list"),
    ({"zip": {"water.layers[0].a": [0.1, 0.2], "bottom.reflectance": [0.1]}}, "equal lengths"),
    ({"water.layerz[0].a": [0.1]}, "unknown key"),
])
def test_bad_sweeps_on_the_command_line_exit_2_in_one_line_writing_nothing(tmp_path, cli, axes,
                                                                         words):
    (tmp_path / "sweep.yaml").write_text(yaml.safe_dump({"base": TINY, "axes": axes}))
    code, err = cli("sweep", "sweep.yaml", "-o", "lut.nc", "--workers", "1", "-q")
    assert code == 2, err
    assert err.startswith("oceanmc: config error: ") and err.count("\n") == 1, err
    assert words in err, err
    assert not (tmp_path / "lut.nc").exists() and not (tmp_path / "lut.points").exists()


def test_a_sweep_whose_base_file_does_not_exist_exits_2_in_one_line(tmp_path):
    """The real command in its own process: one line, exit status 2, no dataset."""
    (tmp_path / "sweep.yaml").write_text(yaml.safe_dump(
        {"base": "missing.yaml", "axes": {"water.layers[0].a": [0.1]}}))
    done = subprocess.run([sys.executable, "-m", "oceanmc", "sweep", "sweep.yaml", "-o",
                           "lut.nc", "--workers", "1"], cwd=tmp_path, env=ENV,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 2, done.stderr
    # the sweep file's folder is the current one: its base's path is as written
    assert done.stderr == "oceanmc: config error: base = 'missing.yaml': no such file\n", \
        done.stderr
    assert not (tmp_path / "lut.nc").exists() and not (tmp_path / "lut.points").exists()


def test_a_key_given_twice_in_a_sweep_file_or_its_base_is_refused(tmp_path):
    """`axes:` twice in a sweep file: the second silently replaced the first (a scene file is
    refused for it); the same in the base scene file. sweeps/axes.py read both with
    yaml.safe_load; it now reads them with the scene loader's guards."""
    sweep = tmp_path / "sweep.yaml"
    sweep.write_text(yaml.safe_dump({"base": TINY}) + "axes:\n  water.layers[0].a: [0.1]\n"
                     "axes:\n  water.layers[0].a: [0.2, 0.3]\n")
    with pytest.raises(ConfigError, match="given twice"):
        load_sweep(sweep)
    (tmp_path / "base.yaml").write_text(yaml.safe_dump(TINY) + "photons: 2000\n")
    sweep.write_text(yaml.safe_dump({"base": "base.yaml", "axes": {"water.layers[0].a": [0.1]}}))
    with pytest.raises(ConfigError, match="given twice"):
        load_sweep(sweep)


def test_a_sweep_or_base_that_is_a_fifo_or_a_device_exits_2_in_one_line(tmp_path, cli):
    """`base: /dev/zero` was a MemoryError traceback, a FIFO as base blocked, and a FIFO as the
    sweep file was called 'no such file'."""
    os.mkfifo(tmp_path / "fifo.yaml")
    for base in ("/dev/zero", "fifo.yaml"):
        (tmp_path / "sweep.yaml").write_text(yaml.safe_dump(
            {"base": base, "axes": {"water.layers[0].a": [0.1]}}))
        code, err = cli("sweep", "sweep.yaml", "-o", "lut.nc", "--workers", "1", "-q")
        assert code == 2 and err.count("\n") == 1, err
        assert err.startswith(f"oceanmc: config error: base = '{base}'") \
            and err.endswith(": not a regular file\n"), err
    code, err = cli("sweep", "fifo.yaml", "-o", "lut.nc", "--workers", "1", "-q")
    assert (code, err) == (2, "oceanmc: error: fifo.yaml: not a regular file\n")
    assert not (tmp_path / "lut.nc").exists() and not (tmp_path / "lut.points").exists()


def test_more_than_100000_points_are_refused_before_any_is_built(monkeypatch):
    """{linspace: [0, 1, 10000000]} was validated for more than 10 minutes before anything ran
    (and numpy made its grid first): at most 100,000 points per generator and in all, refused
    in one line before a point is built."""
    import time
    from oceanmc.sweeps import axes

    def no_grid(*args):
        raise AssertionError("the grid was made")
    monkeypatch.setattr(axes.np, "linspace", no_grid)
    start = time.perf_counter()
    assert points_or_one_line(
        {"base": TINY, "axes": {"water.layers[0].a": {"linspace": [0, 1, 10**7]}}},
        "axes: water.layers[0].a.linspace = [0, 1, 10000000]: 10,000,000 points; allowed: at "
        "most 100,000 points in a sweep")
    monkeypatch.undo()
    grid = {"linspace": [0.1, 1, 400]}
    assert points_or_one_line(
        {"base": TINY, "axes": {"water.layers[0].a": grid, "bottom.reflectance": grid}},
        "axes: 400 (water.layers[0].a) x 400 (bottom.reflectance) = 160,000 points; allowed: at "
        "most 100,000 points in a sweep (split it into several sweeps)")
    assert points_or_one_line(
        {"base": TINY, "axes": {"water.layers[0].a": list(range(1, 100_002))}},
        "axes: 100,001 (water.layers[0].a) points; allowed: at most 100,000")
    assert time.perf_counter() - start < 5.0
    assert len(load_sweep({"base": TINY, "axes": {"water.layers[0].a": {"linspace": [
        0.1, 1, 250]}, "bottom.reflectance": {"linspace": [0, 1, 400]}}}).axes) == 2


@pytest.mark.parametrize("changes, message", [
    ({"axes": {"chl": {"key": "water.layers[0].a", "values": [0.1, -1]}}},
     "point (chl = -1): water.layers[0].a = -1: allowed: a number 0 .. 1e+06"),
    ({"axes": {"zip": {"chl": {"key": "water.layers[0].a", "values": [0.1, -2]},
                       "bottom.reflectance": [0.1, 0.2]}}},
     "point (chl = -2, bottom.reflectance = 0.2): water.layers[0].a = -2: "),
    ({"axes": {"chl": {"key": "water.layers[0].a", "values": {"linspace": [0, 1, "x"]}}}},
     "axes: chl.values.linspace = [0, 1, 'x']: expected [start, stop, num]"),
    ({"axes": {"chl": {"key": "water.layers[0].a", "values": 5}}},
     "axes: chl.values = 5: expected a non-empty list of values"),
    ({"axes": {"chl": {"key": "water..a", "values": [1]}}},
     "axes: chl.key: 'water..a' is not a key path"),
    ({"axes": {"chl": {"key": "water.layerz[0].a", "values": [0.1]}}},
     "axes: chl.key = water.layerz[0].a: water.layerz is an unknown key; did you mean "
     "water.layers?"),
    ({"axes": {"chl": {"key": "water.layers[3].a", "values": [0.1]}}},
     "axes: chl.key = water.layers[3].a: water.layers has 1 entry in the base scene"),
    ({"set": {"water.layers[3].a": 0.1}}, "set: water.layers[3].a: water.layers has 1 entry"),
    ({"set": {"water..a": 0.1}}, "set: 'water..a' is not a key path"),
])
def test_messages_name_an_axis_as_the_sweep_file_wrote_it(changes, message):
    """A named axis (`chl: {key: PATH, values: ...}`) was reported by its key path, the point's
    coordinates too ('point (water.layers[0].a = -1)'), its generator as 'chl (PATH).linspace',
    and a bad `set` path as 'axes: ...': each message now starts with what the user wrote."""
    got = points_or_one_line({"base": TINY, **changes})
    assert isinstance(got, str) and got.startswith(message), got
