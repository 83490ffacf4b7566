"""Fuzzing the data files a scene names (phase tables, sky maps, BRDF tables), the results files
given to show, merge and --resume, and the command-line flags: every input is accepted or
refused in one line (ConfigError, or exit status 2), never a traceback. In-process calls of
oceanmc.cli.main with captured output keep it within seconds."""
import io
import shutil

import h5py
import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

import oceanmc
from oceanmc import scene
from oceanmc.cli import _outputs, main
from oceanmc.config import ConfigError, load_config

from conftest import SMALL_SCENE

FAST = settings(max_examples=60, deadline=None,
                suppress_health_check=[HealthCheck.too_slow,
                                       HealthCheck.function_scoped_fixture])


def _npy(array) -> bytes:
    out = io.BytesIO()
    np.save(out, array)
    return out.getvalue()


def _npz(**arrays) -> bytes:
    out = io.BytesIO()
    np.savez(out, **arrays)
    return out.getvalue()


ANGLES = np.arange(0.0, 90.1, 10.0)
PHI = np.arange(0.0, 180.1, 30.0)
# (file suffix, a valid file's bytes, where the scene names it)
DATA_FILES = {
    "phase table": (".csv", b"0,10\n10,1\n90,0.1\n180,0.1\n",
                    lambda s, path: s["water"]["layers"][0].update(
                        phase={"model": "table", "file": path})),
    "sky map npy": (".npy", _npy(np.ones((9, 36))),
                    lambda s, path: s["illumination"].update(sky={"map": path})),
    "sky map npz": (".npz", _npz(radiance=np.ones((9, 36))),
                    lambda s, path: s["illumination"].update(sky={"map": path})),
    "brdf table": (".npz", _npz(theta_i_deg=ANGLES, theta_r_deg=ANGLES, phi_deg=PHI,
                                brdf=np.full((10, 10, 7), 0.3 / np.pi)),
                   lambda s, path: s.update(bottom={"model": "table", "file": path})),
}


def _mutations(valid: bytes):
    """Random bytes; the valid file truncated; the valid file with bytes overwritten."""
    truncated = st.integers(0, len(valid)).map(lambda n: valid[:n])
    overwritten = st.lists(st.tuples(st.integers(0, len(valid) - 1), st.integers(0, 255)),
                           min_size=1, max_size=8).map(
        lambda edits: bytes(_overwrite(bytearray(valid), edits)))
    return st.binary(max_size=400) | truncated | overwritten


def _overwrite(data: bytearray, edits) -> bytearray:
    for where, value in edits:
        data[where] = value
    return data


def _accepted_or_one_line(config: dict) -> None:
    try:
        scene.build(load_config(config))
    except ConfigError as exc:   # TableError is one
        message = str(exc)
        assert message and "\n" not in message.strip(), message


@pytest.mark.parametrize("kind", sorted(DATA_FILES))
def test_fuzzed_data_files_load_or_fail_in_one_line(kind, tmp_path_factory):
    suffix, valid, place = DATA_FILES[kind]
    folder = tmp_path_factory.mktemp("data")

    @FAST
    @given(_mutations(valid))
    def check(content):
        path = folder / f"table{suffix}"
        path.write_bytes(content)
        config = yaml.safe_load(yaml.safe_dump(SMALL_SCENE))
        place(config, str(path))
        _accepted_or_one_line(config)
    check()


@pytest.fixture(scope="module")
def results_file(tmp_path_factory):
    scene_dict = dict(SMALL_SCENE, photons=2000, batches=4)
    return oceanmc.simulate(scene_dict).save(tmp_path_factory.mktemp("r") / "run.h5")


def _exit_and_error(argv, capsys):
    code = main([str(a) for a in argv])
    err = capsys.readouterr().err.strip()
    assert code in (0, 2), (argv, code, err)
    assert code == 0 or (err and "\n" not in err and "Traceback" not in err), (argv, err)
    return code


ATTR_VALUES = (st.none() | st.integers(-2**63, 2**63 - 1) | st.floats() | st.text(max_size=30)
               | st.binary(max_size=30) | st.booleans()
               | st.lists(st.integers(-5, 5), max_size=4).map(np.array))
ATTRS = ["format_version", "config_yaml", "batches", "photons", "seed", "first_batch",
         "photons_per_batch", "partial", "seeds", "batch_ranges", "merged_from",
         "data_files_sha256", "wall_time_s", "startup_time_s", "threads", "name"]


def _with_attribute(path, name, value):
    with h5py.File(path, "r+") as f:
        if value is None:
            f.attrs.pop(name, None)
        else:
            f.attrs[name] = value


@settings(max_examples=60, deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(st.sampled_from(ATTRS), ATTR_VALUES, st.sampled_from(["show", "merge", "resume"]))
@example("name", b"\x80", "show").via("found by a longer run")
@example("partial", True, "resume").via("found by a longer run")
def test_results_files_with_mutated_attributes(results_file, tmp_path, capsys, name, value,
                                               command):
    path = tmp_path / "mutated.h5"
    shutil.copy(results_file, path)
    try:
        _with_attribute(path, name, value)
    except (TypeError, ValueError):   # a value h5py cannot store as an attribute
        return
    _run_on(command, path, results_file, tmp_path, capsys)


def _run_on(command, path, good, tmp_path, capsys):
    if command == "show":
        _exit_and_error(["show", path], capsys)
    elif command == "merge":
        _exit_and_error(["merge", path, good, "-o", tmp_path / "merged.h5", "--overwrite"],
                        capsys)
    else:
        config = tmp_path / "scene.yaml"
        config.write_text(yaml.safe_dump(dict(SMALL_SCENE, photons=2000, batches=4)))
        _exit_and_error(["run", config, "-o", path, "--resume", "-q"], capsys)


@settings(max_examples=40, deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(st.data(), st.sampled_from(["show", "merge", "resume"]))
def test_truncated_and_random_results_files(results_file, tmp_path, capsys, data, command):
    valid = results_file.read_bytes()
    content = data.draw(st.binary(max_size=2000)
                        | st.integers(0, len(valid) - 1).map(lambda n: valid[:n]))
    path = tmp_path / "broken.h5"
    path.write_bytes(content)
    _run_on(command, path, results_file, tmp_path, capsys)


# flag values: numbers in every spelling, and text; -o without '/' (files stay in tmp_path)
NUMBERS = st.integers(-10**30, 10**30).map(str) | st.floats().map(repr) | st.sampled_from(
    ["1e400", "-0", "0x10", "1_000", " 5", "nan", "inf", "", "1e6", "2.5", "१२"])
FLAG_TEXT = NUMBERS | st.text(max_size=12)
OUT_NAMES = st.text(st.characters(blacklist_characters="/", blacklist_categories=("Cs",)),
                    max_size=20) | st.sampled_from(["a\0b", ".", "..", "x.h5", "x.nc", "-"])


class WouldRun(Exception):
    """Raised in place of tracing: every check before the first photon has passed."""


@settings(max_examples=150, deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(st.lists(st.tuples(st.sampled_from(["--photons", "--seed", "--threads",
                                           "--checkpoint-every"]), FLAG_TEXT), max_size=4),
       OUT_NAMES)
@example([], "a\0b").via("found by a longer run")
def test_random_flags_run_or_fail_in_one_line(tmp_path, monkeypatch, capsys, flags, out):
    """Every flag and -o value either passes every check made before the first photon (the
    run would start) or is refused with exit 2 in one line."""
    from oceanmc.run import simulation

    def would_run(*args, **kwargs):
        raise WouldRun
    monkeypatch.setattr(simulation, "simulate", would_run)
    monkeypatch.chdir(tmp_path)
    config = tmp_path / "scene.yaml"
    config.write_text(yaml.safe_dump(SMALL_SCENE))
    argv = ["run", str(config), "-o", out, "--overwrite"] + [x for pair in flags for x in pair]
    try:
        code = main(argv)
    except SystemExit as exc:   # argparse's refusal
        code = exc.code
    except WouldRun:   # then the results file can be written where the run will write it
        for path in _outputs([config], out):
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(b"")
        return
    err = capsys.readouterr().err.strip()
    assert code == 2 and "\n" not in err and "Traceback" not in err, (argv, err)
