"""Hardening (issue 13): malformed or extreme input gets one clear line and exit 2, never a
wrong answer, a lost run or someone else's files deleted."""
import os
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import REPO

ENV = dict(os.environ, PYTHONPATH=str(REPO))


def test_cache_dir_keeps_folders_oceanmc_did_not_create(tmp_path):
    users = tmp_path / "numba-mine"
    users.mkdir()
    (users / "data.bin").write_bytes(b"x")
    ours = tmp_path / "numba-0000000000000000"
    ours.mkdir()
    (ours / ".oceanmc-kernel-cache").touch()
    env = dict(ENV, OCEANMC_CACHE_DIR=str(tmp_path))
    subprocess.run([sys.executable, "-c", "import oceanmc.kernel.compile"], env=env, check=True,
                   timeout=120)
    assert (users / "data.bin").is_file()
    assert not ours.exists()
    current = [p for p in tmp_path.glob("numba-*") if p != users]
    assert len(current) == 1 and (current[0] / ".oceanmc-kernel-cache").is_file()


def test_an_unwritable_cache_folder_falls_back_to_a_writable_one(tmp_path):
    """OCEANMC_CACHE_DIR (or an installed package's __pycache__) that cannot be made or
    written: the compile cache goes to the next writable folder instead of Numba failing at
    import with a traceback (a folder under a regular file cannot be made, even by root)."""
    blocker = tmp_path / "a-file"
    blocker.write_text("not a folder")
    env = dict(ENV, OCEANMC_CACHE_DIR=str(blocker / "cache"))
    done = subprocess.run([sys.executable, "-c", "from oceanmc.kernel.compile import CACHE_DIR, "
                           "CACHE_WRITABLE; print(CACHE_DIR); print(CACHE_WRITABLE)"],
                          env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    folder, writable = done.stdout.split()
    assert writable == "True" and not folder.startswith(str(blocker))
    assert (Path(folder) / ".oceanmc-kernel-cache").is_file()


@pytest.mark.parametrize("value", ["nan", "-1", "inf", "soon"])
def test_checkpoint_interval_must_be_a_finite_number_at_least_0(tmp_path, value):
    """--checkpoint-every nan would never checkpoint (every comparison with NaN is false), inf
    neither, a negative one means nothing (0: at every check, which the interrupt tests use):
    refused in one line, exit 2."""
    done = subprocess.run([sys.executable, "-m", "oceanmc", "run", "scene.yaml",
                           "--checkpoint-every", value], cwd=tmp_path, env=ENV,
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 2
    assert f"--checkpoint-every: expected a finite number of seconds >= 0, got '{value}'" \
        in done.stderr and "Traceback" not in done.stderr


def test_show_and_plot_say_a_folder_is_not_a_results_file(tmp_path):
    for command in ("show", "plot"):
        done = subprocess.run([sys.executable, "-m", "oceanmc", command, str(tmp_path)],
                              env=ENV, capture_output=True, text=True, timeout=120)
        assert done.returncode == 2 and done.stderr.strip().endswith(
            f"{tmp_path}: not a regular file"), done.stderr


def test_saving_over_an_existing_file_without_overwrite_is_refused_before_writing(tmp_path):
    """Result.save(path, overwrite=False) on a file that exists: FileExistsError naming the
    option, the file untouched and no stray file beside it (it wrote <stem>.<pid>.h5 and blamed
    "another process")."""
    import oceanmc
    from conftest import SMALL_SCENE
    result = oceanmc.simulate(dict(SMALL_SCENE, photons=400), threads=1)
    path = result.save(tmp_path / "r.h5")
    before = path.read_bytes()
    with pytest.raises(FileExistsError, match=r"r\.h5 exists; save\(\.\.\., overwrite=True\) "
                       r"replaces it"):
        result.save(path, overwrite=False)
    assert path.read_bytes() == before and sorted(p.name for p in tmp_path.iterdir()) == ["r.h5"]


def test_show_and_plot_of_a_sweep_dataset_say_how_to_open_it(tmp_path):
    """A sweep's NetCDF dataset given to show or plot was 'no format_version attribute: not an
    oceanmc results file', with no word of what it is or how to read it."""
    import h5py
    from oceanmc.run.format import SWEEP_TITLE
    path = tmp_path / "lut.nc"
    with h5py.File(path, "w") as f:
        f.attrs["title"] = SWEEP_TITLE
    for command in ("show", "plot"):
        done = subprocess.run([sys.executable, "-m", "oceanmc", command, str(path)],
                              env=ENV, capture_output=True, text=True, timeout=120)
        assert done.returncode == 2, done.stderr
        assert "an oceanmc sweep dataset (NetCDF), not the results file of one run: open it " \
            "with xarray.open_dataset" in done.stderr and done.stderr.count("\n") == 1


def test_saving_to_a_folder_is_refused_in_one_line(tmp_path, monkeypatch):
    """Result.save(".") was pathlib's "has an empty name", save(folder) an IsADirectoryError
    about a temporary file beside the folder."""
    import oceanmc
    from conftest import SMALL_SCENE
    result = oceanmc.simulate(dict(SMALL_SCENE, photons=400), threads=1)
    monkeypatch.chdir(tmp_path)
    for folder in (".", tmp_path, "..", tmp_path / "sub" / ".."):
        with pytest.raises(IsADirectoryError, match=r"is a folder: save\(\) takes the results "
                           r"file's own path"):
            result.save(folder)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("threads", [0, -3, "x", 1.5])
def test_simulate_refuses_a_thread_count_that_is_not_a_positive_integer(threads):
    """simulate(threads=0) ran on 1 thread without a word, threads='x' gave int()'s error."""
    import oceanmc
    from conftest import SMALL_SCENE
    with pytest.raises(ValueError, match=rf"^threads = {threads!r}: allowed an integer >= 1"):
        oceanmc.simulate(dict(SMALL_SCENE, photons=400), threads=threads)


# --- configs: read safely, one line per problem -------------------------------------------

import yaml  # noqa: E402

from oceanmc.config import ConfigError, load_config  # noqa: E402


def oceanmc(*args, cwd):
    return subprocess.run([sys.executable, "-m", "oceanmc", *map(str, args)], cwd=cwd, env=ENV,
                          capture_output=True, text=True, timeout=600)


def refused(source, *words, overrides=None):
    with pytest.raises(ConfigError) as info:
        load_config(source, overrides)
    message = str(info.value)
    assert "\n" not in message
    for word in words:
        assert word in message, (word, message)
    return message


def test_config_files_that_are_not_regular_or_too_large_are_refused(tmp_path):
    refused("/dev/zero", "not a regular file")
    refused(tmp_path, "not a regular file")
    fifo = tmp_path / "pipe.yaml"
    os.mkfifo(fifo)
    refused(fifo, "not a regular file")  # would block forever if opened for a blocking read
    big = tmp_path / "big.yaml"
    big.write_text("name: x\n" + "#" * (2 << 20))
    refused(big, "larger than")
    loop = tmp_path / "loop.yaml"
    loop.symlink_to(loop)
    refused(loop, "cannot read it")
    refused(str(tmp_path / "a\0b.yaml"), "cannot read it")


@pytest.mark.parametrize("text, at", [("a: &x [*x]\n", "line 1, column 4"),
                                      ("name: x\nwater: &w\n  layers: [*w]\n", "line 2, column 8"),
                                      ("b: &y {c: [1, {d: *y}]}\n", "line 1, column 4")])
def test_a_recursive_yaml_alias_is_called_so(tmp_path, text, at):
    """`a: &x [*x]` was reported as aliases expanding to more than 100,000 values."""
    path = tmp_path / "loop.yaml"
    path.write_text(text)
    message = refused(path, f"{path}: not valid for a scene: {at}: an anchor's value holds an "
                      "alias to that anchor (a recursive alias")
    assert "100,000" not in message


def test_yaml_alias_bomb_duplicate_keys_and_syntax_errors(tmp_path, small_scene):
    bomb = tmp_path / "bomb.yaml"
    lines = ["a: &a [1, 1, 1, 1, 1, 1, 1, 1, 1, 1]"]
    for level in "bcdefghi":
        previous = chr(ord(level) - 1)
        lines.append(f"{level}: &{level} [{', '.join(['*' + previous] * 10)}]")
    bomb.write_text("\n".join(lines) + "\n")
    message = refused(bomb, str(bomb), "aliases expand")
    assert len(message) < 200
    twice = tmp_path / "twice.yaml"
    twice.write_text(yaml.safe_dump(small_scene) + "name: again\n")
    refused(twice, str(twice), "'name' given twice")
    broken = tmp_path / "broken.yaml"
    broken.write_text("name: a\nwater: {layers: [\n")
    message = refused(broken, str(broken), "line 3")
    assert "<unicode string>" not in message


def test_photons_in_e_notation_and_blame_on_the_flag(tmp_path, small_scene):
    small_scene["photons"] = "1e6"  # what YAML makes of `photons: 1e6`
    assert load_config(small_scene).photons == 1_000_000
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(small_scene))
    refused(path, "--photons", overrides={"photons": 3})
    done = oceanmc("run", path, "--photons", "1e400", cwd=tmp_path)
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert "--photons" in done.stderr


@pytest.mark.parametrize("name", ["a\0b", "a\udc80b", "red \x1b[31m", "x" * 201])
def test_names_that_cannot_be_stored_or_printed_are_refused(small_scene, name):
    small_scene["name"] = name
    refused(small_scene, "name")


def test_unknown_key_suggests_the_nearest(small_scene):
    small_scene["illumination"] = {"sun_zenit_deg": 30}
    refused(small_scene, "did you mean sun_zenith_deg?")
    small_scene["illumination"] = {}
    small_scene["water"]["layers"][0]["phase"]["gg"] = 0.9
    refused(small_scene, "did you mean")


def test_all_configs_are_checked_before_any_runs(tmp_path, small_scene):
    good = tmp_path / "good.yaml"
    good.write_text(yaml.safe_dump(small_scene))
    small_scene["bottom"] = {"model": "table", "file": "missing.h5"}
    bad = tmp_path / "bad.yaml"
    bad.write_text(yaml.safe_dump(small_scene))
    done = oceanmc("run", good, bad, "-o", tmp_path / "out/", cwd=tmp_path)
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
    assert "missing.h5" in done.stderr
    assert not (tmp_path / "out" / "good.h5").exists()


# --- extreme but finite numbers: refused with one line, or computed without cancelling -----

@pytest.mark.parametrize("change", [
    lambda s: s["water"]["layers"][0].update(a=1e308, b=1e308),
    lambda s: s["water"]["layers"][0].update(thickness_m=1e308),
    lambda s: s["illumination"].update(Ed0=1e308),
    lambda s: s.update(estimator={"max_events": 10**400}),
    lambda s: s.update(estimator={"upward_fraction": 0.1, "upward_cone_deg": 1e-6}),
])
def test_huge_or_tiny_values_are_refused(small_scene, change):
    change(small_scene)
    refused(small_scene, "config: ")


def test_small_upward_cone_density_does_not_cancel(small_scene):
    import math
    from oceanmc import scene
    small_scene["estimator"] = {"upward_fraction": 0.1, "upward_cone_deg": 0.01}
    config = load_config(small_scene)
    built = scene.build(config)
    cone = math.radians(0.01)
    # 2 pi (1 - cos A) by its series 2 pi (A^2/2 - A^4/24), exact to 1e-20 relative here
    solid_angle = 2.0 * math.pi * (cone ** 2 / 2.0 - cone ** 4 / 24.0)
    density = built.floats[int(built.medium["up_density"][0])]
    assert abs(density / (0.1 / solid_angle) - 1.0) < 1e-12


@pytest.mark.long(cpu_s=19)
def test_results_with_more_than_4100_layers_can_be_saved(tmp_path):
    # one budget/absorbed_layer_N per layer, each attached to the batch dimension scale: the
    # scale's reference list outgrew HDF5's 64 KB compact attribute limit at ~4,100 layers
    import numpy as np
    from oceanmc.run.hdf5 import COORD_UNITS, load_result
    from oceanmc.run.results import Quantity, Result
    names = [f"budget/absorbed_layer_{i + 1}" for i in range(4200)]
    quantities = {name: Quantity(name, (), np.full(2, 0.5), "1", "absorbed") for name in names}
    coords = {name: np.zeros(0) for name in COORD_UNITS if name != "batch"}
    attrs = {"photons": 4, "batches": 2, "config_yaml": "name: many\n", "threads": 1,
             "seed": 1, "first_batch": 0, "photons_per_batch": 2, "scattering_events": 0,
             "wall_time_s": 1.0, "startup_time_s": 0.0, "photons_per_s": 4.0}
    Result(coords, quantities, attrs).save(tmp_path / "many.h5")
    back = load_result(tmp_path / "many.h5")
    assert len(back.quantities) == 4200
    assert back.quantities[names[-1]].batches.tolist() == [0.5, 0.5]
