"""The `oceanmc` command as a user runs it: exit codes, messages, files."""
import os
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest
import yaml

from conftest import REPO

ENV = dict(os.environ, PYTHONPATH=str(REPO))


def oceanmc(*args, cwd):
    return subprocess.run([sys.executable, "-m", "oceanmc", *map(str, args)], cwd=cwd, env=ENV,
                          capture_output=True, text=True, timeout=600)


@pytest.fixture
def scene_file(tmp_path, small_scene):
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(small_scene))
    return path


def test_run_writes_results_and_prints_summary(tmp_path, scene_file):
    done = oceanmc("run", scene_file, "--threads", "2", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    out = tmp_path / "results" / "scene.h5"
    assert out.is_file()
    for word in ("photons/s", "Ed(0+)", "Rrs nadir", "std err", "rel err", "budget total",
                 f"wrote {out.relative_to(tmp_path)}"):
        assert word in done.stdout, word
    with h5py.File(out) as f:
        assert f.attrs["photons"] == 20000
        assert "Rrs_nadir" in f["air"]



def test_show_into_a_closed_pipe_prints_no_traceback(tmp_path, scene_file):
    """`oceanmc show x.h5 | head -1`: the reader goes away; no BrokenPipeError traceback."""
    assert oceanmc("run", scene_file, "-o", tmp_path / "s.h5", cwd=tmp_path).returncode == 0
    show = subprocess.Popen([sys.executable, "-m", "oceanmc", "show", tmp_path / "s.h5"],
                            cwd=tmp_path, env=ENV, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE)
    show.stdout.close()   # nobody reads: the first write meets a broken pipe
    stderr = show.stderr.read().decode()
    show.wait(timeout=120)
    assert "Traceback" not in stderr and "BrokenPipeError" not in stderr, stderr

def test_several_configs_run_in_turn_into_a_folder(tmp_path, scene_file, small_scene):
    second = tmp_path / "second.yaml"
    small_scene["name"] = "second"
    second.write_text(yaml.safe_dump(small_scene))
    done = oceanmc("run", scene_file, second, "-o", "out", "-q", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["scene.h5", "second.h5"]


def test_photons_and_seed_options_override_the_config(tmp_path, scene_file):
    done = oceanmc("run", scene_file, "-o", "x.h5", "--photons", "8000", "--seed", "3", "-q",
                   cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    with h5py.File(tmp_path / "x.h5") as f:
        assert (f.attrs["photons"], f.attrs["seed"]) == (8000, 3)
        assert "seed: 3" in f.attrs["config_yaml"]


def test_bad_config_exits_2_with_one_clear_line_and_no_file(tmp_path, small_scene):
    small_scene["water"]["layers"][0]["a"] = -0.1
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(small_scene))
    done = oceanmc("run", path, cwd=tmp_path)
    assert done.returncode == 2
    assert "Traceback" not in done.stderr
    assert "water.layers[0].a = -0.1" in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "results").exists() or not any((tmp_path / "results").iterdir())


def test_a_bad_config_among_several_stops_before_any_run(tmp_path, scene_file):
    bad = tmp_path / "bad.yaml"
    bad.write_text("water: {layers: [{thickness_m: 1, a: 0.1, b: 0.1}]}\nbottom: {model: mud}\n")
    worse = tmp_path / "worse.yaml"
    worse.write_text(scene_file.read_text().replace("photons:", "photonz:"))
    done = oceanmc("run", scene_file, bad, worse, cwd=tmp_path)
    assert done.returncode == 2
    # each bad config named in a line of its own, not only the first
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 2 and "bottom.model = 'mud'" in lines[0], lines
    assert "worse.yaml: photonz: unknown key; did you mean photons?" in lines[1], lines
    assert not (tmp_path / "results" / "scene.h5").exists()


def test_missing_config_and_bad_options(tmp_path):
    done = oceanmc("run", tmp_path / "nope.yaml", cwd=tmp_path)
    assert done.returncode == 2 and "no such file" in done.stderr
    done = oceanmc("run", "x.yaml", "--photons", "-5", cwd=tmp_path)
    assert done.returncode == 2 and "positive integer" in done.stderr
    done = oceanmc("frobnicate", cwd=tmp_path)
    assert done.returncode == 2


@pytest.mark.parametrize("photons, shown", [("1e99", "'1e99'"), ("1e400", "'1e400'"),
                                            ("9" * 90, "9999999999... (90 digits)"),
                                            ("9" * 400, "9999999999... (400 digits)")])
def test_photons_above_the_limit_are_refused_in_readable_digits(tmp_path, photons, shown):
    """--photons 1e99 was echoed back as an 80-digit integer (and 1e400 called not positive),
    a 400-digit count as 'inf'."""
    done = oceanmc("run", "x.yaml", "--photons", photons, cwd=tmp_path)
    assert done.returncode == 2
    assert done.stderr.startswith(f"oceanmc run: error: argument --photons: {shown} is more than "
                                  "1e+13 photons; allowed: 1 .. 1e+13"), done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and len(done.stderr) < 160


@pytest.mark.parametrize("option, where", [
    (("--seed", "9223372036854775808"), "--seed (with {file})"), ((), "{file}")])
def test_a_seed_beyond_int64_is_refused_naming_the_allowed_range(tmp_path, small_scene,
                                                                 option, where):
    """--seed 9223372036854775808, and the same seed in the file, were refused in pydantic's
    words ("Input should be less than 9223372036854775808")."""
    small_scene["seed"] = 2**63 if not option else 5
    scene_file = tmp_path / "scene.yaml"
    scene_file.write_text(yaml.safe_dump(small_scene))
    done = oceanmc("run", scene_file, *option, "-o", tmp_path / "r.h5", cwd=tmp_path)
    assert done.returncode == 2
    assert done.stderr == (f"oceanmc: config error: {where.format(file=scene_file)}: seed = "
                           "9223372036854775808: allowed: an integer 0 .. 9223372036854775807\n")
    assert not (tmp_path / "r.h5").exists()


@pytest.mark.parametrize("option, value", [("--photons", "1.5e0"), ("--photons", "2.5e-1"),
                                           ("--threads", "2.5e0")])
def test_a_count_in_e_notation_that_is_not_whole_is_refused(tmp_path, option, value):
    """--photons 1.5e0 ran 1 photon (int(float()) truncated it), --threads 2.5e0 2 threads."""
    done = oceanmc("run", "x.yaml", option, value, cwd=tmp_path)
    assert done.returncode == 2
    assert done.stderr.startswith(f"oceanmc run: error: argument {option}: expected a positive "
                                  f"integer, got '{value}', which is {float(value):g} ("), \
        done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and "Traceback" not in done.stderr


def test_output_names_a_results_file_or_a_folder(tmp_path):
    """-o: a name ending in .h5 is the file, and so, for one config, is a name without a suffix
    (-o name: the file name.h5, as 884245e made it; f0c242a had made it the folder name/, where
    `-o name --resume` no longer found the partial name.h5); an existing folder or a name
    ending in '/' is the folder for <config name>.h5, as is a name without a suffix for several
    configs (x.h5/ was the file x.h5)."""
    from oceanmc.cli import UsageError, _outputs
    one, two = [tmp_path / "scene.yaml"], [tmp_path / "scene.yaml", tmp_path / "b.yaml"]
    assert _outputs(one, "r.h5") == [Path("r.h5")]
    assert _outputs(one, "x.h5/") == [Path("x.h5/scene.h5")]
    assert _outputs(one, "newdir/") == [Path("newdir/scene.h5")]
    assert _outputs(one, "newdir") == [Path("newdir.h5")]
    assert _outputs(one, str(tmp_path)) == [tmp_path / "scene.h5"]
    assert _outputs(two, "out") == [Path("out/scene.h5"), Path("out/b.h5")]
    (tmp_path / "plain").write_text("")   # a file without a suffix: one config writes plain.h5
    assert _outputs(one, str(tmp_path / "plain")) == [tmp_path / "plain.h5"]
    with pytest.raises(UsageError, match=r"plain: several configs need a folder for -o, not a "
                                         r"file name$"):
        _outputs(two, str(tmp_path / "plain"))


def test_output_without_a_suffix_is_the_results_file_with_h5_added(tmp_path, scene_file):
    """`-o out` writes out.h5 and a second `-o out` finds it (the file to --resume)."""
    done = oceanmc("run", scene_file, "-o", "out", "--photons", "2000", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert "wrote out.h5" in done.stdout and (tmp_path / "out.h5").is_file()
    assert not (tmp_path / "out").exists()
    again = oceanmc("run", scene_file, "-o", "out", "-q", cwd=tmp_path)
    assert again.returncode == 2
    assert again.stderr.startswith("oceanmc: error: out.h5 exists; pass --overwrite to replace it "
                                   "(or --resume to continue a partial run)"), again.stderr


@pytest.mark.parametrize("command, out, expected", [
    ("run", "/dev/null", "-o /dev/null: not a regular file (a device, a FIFO or a socket); -o "
     "takes a results file name ending in .h5 (or .hdf5, .nc) or without a suffix"),
    ("run", "res.yaml", "-o res.yaml: -o takes a results file name ending in .h5 (or .hdf5, "
     ".nc) or without a suffix (NAME.h5; one config) or a folder (an existing one, or a name "
     "ending in /)"),
    ("merge", "/dev/null", "-o /dev/null: not a regular file"),
    ("merge", "m.yaml", "-o m.yaml: -o takes a results file name ending in .h5 (or .hdf5, .nc)"),
    ("merge", "m.h5/", "-o m.h5/: a folder; -o takes a results file name ending in .h5"),
    ("merge", "", "-o '': an empty name; -o takes a results file name ending in .h5"),
    ("sweep", "", "-o '': an empty name; -o takes a NetCDF file name ending in .nc"),
    ("sweep", "lut.nc/", "-o lut.nc/: a folder; -o takes a NetCDF file name ending in .nc"),
    ("sweep", "/dev/null", "-o /dev/null: not a regular file")])
def test_output_that_is_not_a_results_file_is_refused_in_one_line(tmp_path, scene_file, command,
                                                                   out, expected):
    """`-o /dev/null` wrote /dev/null.h5, `-o res.yaml` res.yaml.h5, `merge -o m.h5/` the file
    m.h5: each is refused before anything is written."""
    inputs = [scene_file] if command != "merge" else [tmp_path / "a.h5", tmp_path / "b.h5"]
    done = oceanmc(command, *inputs, "-o", out, *(["-q"] if command != "merge" else []),
                   cwd=tmp_path)
    assert done.returncode == 2, done.stderr
    assert done.stderr.startswith(f"oceanmc: error: {expected}"), done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and "Traceback" not in done.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scene.yaml"]


def test_help_does_not_import_the_heavy_modules(tmp_path):
    """`oceanmc --help` (run as `python -m oceanmc --help`) imports neither the kernel (numba),
    the results file (h5py) nor the schema (pydantic): commands that need little start fast."""
    heavy = ("numba", "h5py", "pydantic")
    code = ("import runpy, sys\n"
            "sys.argv = ['oceanmc', '--help']\n"
            "try:\n"
            "    runpy.run_module('oceanmc', run_name='__main__', alter_sys=True)\n"
            "except SystemExit as exc:\n"
            "    assert exc.code == 0, exc.code\n"
            f"print('imported:', *sorted(m for m in {heavy!r} if m in sys.modules))\n")
    done = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=ENV,
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert "usage: oceanmc" in done.stdout
    assert done.stdout.strip().splitlines()[-1] == "imported:"


def test_existing_results_are_not_overwritten_without_the_flag(tmp_path, scene_file):
    target = tmp_path / "r.h5"
    target.write_bytes(b"precious")
    done = oceanmc("run", scene_file, "-o", target, "-q", cwd=tmp_path)
    assert done.returncode == 2 and "--overwrite" in done.stderr
    assert target.read_bytes() == b"precious"
    done = oceanmc("run", scene_file, "-o", target, "-q", "--overwrite", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert h5py.is_hdf5(target)


def test_unwritable_output_fails_before_running(tmp_path, scene_file):
    """A results folder that cannot be made (a file stands in its place) fails at once, even for
    root, before any photon is traced."""
    (tmp_path / "blocker").write_text("a file, not a folder")
    done = oceanmc("run", scene_file, "-o", tmp_path / "blocker" / "r.h5", cwd=tmp_path)
    assert done.returncode == 2 and "cannot write" in done.stderr
    # the file in the way is named (mkdir's own words were "File exists")
    assert f"{tmp_path / 'blocker'} is a file, not a folder" in done.stderr, done.stderr
    assert "photons/s" not in done.stdout


def test_a_broken_link_in_the_output_path_is_named(tmp_path, scene_file):
    (tmp_path / "gone").symlink_to(tmp_path / "nowhere")
    done = oceanmc("run", scene_file, "-o", tmp_path / "gone" / "r.h5", cwd=tmp_path)
    assert done.returncode == 2
    assert f"{tmp_path / 'gone'} is a broken symbolic link" in done.stderr, done.stderr


def test_a_scene_refused_by_its_packer_leaves_no_results_folder(tmp_path, scene_file,
                                                                 small_scene):
    # a wavelength outside the water's tables: refused when the scene is packed, after the
    # good config beside it was read; the folder for their results is not made
    bad = dict(small_scene, wavelengths_nm=[150.0])
    bad["water"] = {"layers": [{"thickness_m": 10.0, "components": [{"model": "pure_water"}]}]}
    (tmp_path / "bad.yaml").write_text(yaml.safe_dump(bad))
    done = oceanmc("run", scene_file, tmp_path / "bad.yaml", "-o", tmp_path / "out" / "",
                   cwd=tmp_path)
    assert done.returncode == 2 and "150 nm is outside" in done.stderr, done.stderr
    assert not (tmp_path / "out").exists()


def test_a_missing_table_file_is_named_with_its_key(tmp_path, small_scene):
    # (the table's own check names the file; the key says which of the scene's tables it is)
    small_scene["water"]["layers"][0]["phase"] = {"model": "table", "file": "nope.csv"}
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(small_scene))
    done = oceanmc("run", tmp_path / "s.yaml", "-o", "r.h5", cwd=tmp_path)
    assert done.returncode == 2
    assert f"water.layers[0].phase.file: phase table {tmp_path / 'nope.csv'}: no such file" \
        in done.stderr, done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and not (tmp_path / "r.h5").exists()


def test_show_prints_the_summary(tmp_path, scene_file):
    assert oceanmc("run", scene_file, "-o", "r.h5", "-q", cwd=tmp_path).returncode == 0
    done = oceanmc("show", "r.h5", "--config", cwd=tmp_path)
    assert done.returncode == 0
    assert "Ed(0-)" in done.stdout and "water:" in done.stdout
    done = oceanmc("show", scene_file, cwd=tmp_path)
    assert done.returncode == 2 and "not an oceanmc results file" in done.stderr


def test_start_up_time_is_the_first_runs_and_counts_loading_the_loop(tmp_path, scene_file):
    """`oceanmc run` makes the photon loop ready before it packs its scenes; the first scene's
    startup_time_s still holds the time that took (in a fresh process at least the cache's
    load, 0.05-0.1 s on the CI machine), the next scene's is 0."""
    second = tmp_path / "second.yaml"
    second.write_text(scene_file.read_text())
    done = oceanmc("run", scene_file, second, "-o", "out", "-q", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    with h5py.File(tmp_path / "out" / "scene.h5") as first, \
            h5py.File(tmp_path / "out" / "second.h5") as later:
        assert first.attrs["startup_time_s"] >= 0.01
        assert later.attrs["startup_time_s"] == 0.0


@pytest.mark.long(cpu_s=15)
def test_the_compiling_child_packs_the_scenes_it_is_given(tmp_path):
    """On a cold start the compiling child (run/compiling.py child_main) says on stdout when its
    part is compiled, then packs the scenes it was given, whose tables land in the disk caches
    for the parent; a scene it cannot pack (here a missing file) is left to the parent, and the
    child still ends well. (The compiled code is copied in, the tables are not.)"""
    import shutil
    from oceanmc.kernel.compile import CACHE_DIR
    from oceanmc.run.compiling import EVENTS_COMPILED
    cache = tmp_path / "cache"
    shutil.copytree(CACHE_DIR, cache / CACHE_DIR.name)
    code = ("import sys; from oceanmc.run.compiling import child_main; "
            "child_main(sys.argv[1], sys.argv[2:])")
    done = subprocess.run([sys.executable, "-c", code, "11111", str(tmp_path / "missing.yaml"),
                           str(REPO / "configs" / "windy_case1.yaml")],
                          env=dict(ENV, OCEANMC_CACHE_DIR=str(cache)), capture_output=True,
                          text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == [EVENTS_COMPILED]
    assert list((cache / "surface_tables").iterdir())
    assert list((cache / "cap-moments").glob("*.npy"))


def test_same_seed_gives_identical_files_apart_from_times(tmp_path, scene_file):
    for name, threads in (("a.h5", "1"), ("b.h5", "2")):
        done = oceanmc("run", scene_file, "-o", name, "-q", "--threads", threads, cwd=tmp_path)
        assert done.returncode == 0, done.stderr
    timing = {"wall_time_s", "startup_time_s", "photons_per_s", "threads"}
    with h5py.File(tmp_path / "a.h5") as a, h5py.File(tmp_path / "b.h5") as b:
        assert {k: a.attrs[k] for k in a.attrs if k not in timing} == \
               {k: b.attrs[k] for k in b.attrs if k not in timing}
        names = []
        a.visititems(lambda n, o: names.append(n) if isinstance(o, h5py.Dataset) else None)
        assert len(names) > 50
        for name in names:
            assert np.array_equal(a[name][()], b[name][()], equal_nan=True), name


def test_kernel_runs_without_jit(tmp_path, scene_file):
    """The kernel is plain Python under NUMBA_DISABLE_JIT=1 (for debugging and coverage)."""
    env = dict(ENV, NUMBA_DISABLE_JIT="1")
    done = subprocess.run([sys.executable, "-m", "oceanmc", "run", str(scene_file), "-o", "r.h5",
                           "--photons", "400", "-q"], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert "budget total" in done.stdout


def test_a_stop_while_the_loop_loads_from_the_cache_says_loading():
    """A stop asked while the photon loop is loaded from the disk cache (some tenths of a
    second; the stop is polled every 0.1 s) names the loading, not a compilation (the tests'
    session has put the whole loop in the cache: conftest.whole_photon_loop)."""
    code = ("from oceanmc.run.compiling import CompileInterrupted, ready\n"
            "try:\n    ready(should_stop=lambda: True)\n"
            "except CompileInterrupted as exc:\n    print(exc)\n")
    done = subprocess.run([sys.executable, "-c", code], env=ENV, capture_output=True,
                          text=True, timeout=300)
    assert done.stdout.strip() == "while loading the photon loop from the disk cache", done


def test_ctrl_c_while_compiling_stops_at_once_without_a_file(tmp_path, scene_file):
    """With an empty compile cache the run says that it is compiling (what and why); Ctrl-C
    then ends it within a second, with exit status 130, a clear message and no results file."""
    import signal
    import time
    env = dict(ENV, OCEANMC_CACHE_DIR=str(tmp_path / "empty-cache"))
    out = tmp_path / "out.h5"
    proc = subprocess.Popen([sys.executable, "-m", "oceanmc", "run", str(scene_file), "-o",
                             str(out)], cwd=tmp_path, env=env, stderr=subprocess.PIPE, text=True)
    notice = proc.stderr.readline()
    assert "compiling the photon loop" in notice and "once per oceanmc version" in notice
    proc.send_signal(signal.SIGINT)
    t0 = time.perf_counter()
    rest = proc.communicate(timeout=30)[1]
    assert time.perf_counter() - t0 < 1.0
    assert proc.returncode == 130
    assert "while compiling the photon loop" in rest and "no file was written" in rest
    assert not out.exists() and not list(tmp_path.glob(".out.h5.*"))


def test_resume_with_no_file_says_so_and_runs_from_the_start(tmp_path, scene_file):
    """--resume where no file was ever written (a resubmitted job whose first try ended before
    its first checkpoint) runs the scene from the start and says so, exit status 0."""
    done = oceanmc("run", scene_file, "-o", "fresh.h5", "--resume", "--photons", "2000", "-q",
                   cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert f"--resume: no file at fresh.h5 to continue; running {scene_file} from the start" \
        in done.stderr
    assert (tmp_path / "fresh.h5").is_file() and "budget total" in done.stdout


def test_show_iops_prints_each_layer_s_iops_and_the_bottom(tmp_path, scene_file):
    """`oceanmc show --iops`: the IOPs the run stored (group iops), layer by layer, with bb/b
    and w0 = b/c computed from them, and the bottom's reflectance; a file without them says so."""
    from oceanmc.run.result import Result
    from oceanmc.run.summary import format_iops

    iops = {"wavelength": np.array([400.0, 500.0]), "layer_top": np.array([0.0, 5.0]),
            "layer_thickness": np.array([5.0, np.inf]),
            "a": np.array([[0.1, 0.2], [0.3, 0.4]]), "b": np.array([[0.4, 0.5], [0.0, 0.6]]),
            "bb": np.array([[0.008, 0.01], [0.0, 0.03]]),
            "c": np.array([[0.5, 0.7], [0.3, 1.0]]), "bottom_reflectance": np.array([0.1, 0.2])}
    text = format_iops(Result({}, {}, {}, None, iops))
    lines = text.splitlines()
    assert "2 layers" in lines[0]
    assert lines[1].split(":")[1].strip() == "0 m to 5 m"
    assert lines[3].split() == ["400", "0.1", "0.4", "0.008", "0.5", "0.02", "0.8"]
    assert "5 m to infinite depth" in text
    assert lines[7].split() == ["400", "0.3", "0", "0", "0.3", "nan", "0"]   # no scattering
    assert lines[-1].split() == ["500", "0.2"] and "reflectance" in lines[-3]
    assert "a minnaert" in lines[-5] and max(map(len, lines)) <= 100   # what rho is, wrapped
    assert "holds none" in format_iops(Result({}, {}, {}, None, {}))
    # the command: a run's own file
    assert oceanmc("run", scene_file, "-o", "r.h5", "-q", cwd=tmp_path).returncode == 0
    done = oceanmc("show", "r.h5", "--iops", cwd=tmp_path)
    assert done.returncode == 0 and "IOPs the run used (1 layer" in done.stdout, done.stderr


def test_a_one_wavelength_summary_says_the_sun_that_sun_position_came_to(small_scene):
    """A spectral summary's illumination line says the sun's zenith angle; a one-wavelength
    one said nothing of it, though sun_position computed it."""
    from oceanmc import simulate
    from oceanmc.run.summary import format_summary
    small_scene["illumination"] = {"sun_position": {"time": "2024-06-21T14:00:00Z",
                                                    "latitude_deg": 31.7,
                                                    "longitude_deg": -64.2}}
    small_scene.update(photons=2000)
    text = format_summary(simulate(small_scene))
    assert "  sun at 31.68 deg from the zenith (sun_position)" in text.splitlines()
    small_scene["illumination"] = {"sun_zenith_deg": 30.0}
    assert "sun_position" not in format_summary(simulate(small_scene))


def test_an_error_line_escapes_a_line_break_in_a_name(tmp_path, scene_file):
    """Every refusal is one line: a name given with a line break (-o) is shown escaped."""
    done = oceanmc("run", scene_file, "-o", "a\nb.yaml", cwd=tmp_path)
    assert done.returncode == 2
    assert done.stderr.count("\n") == 1 and "-o a\\nb.yaml: -o takes" in done.stderr, \
        done.stderr


def test_the_summary_warns_of_a_spectral_nadir_cap_without_upward_bias(small_scene):
    """A spectral run's nadir-cap local estimate without upward-biased scattering reads low with
    error bars that hide it at modest photon counts (a user's review): its summary says so; the
    default (upward_fraction auto) says nothing of it."""
    from oceanmc import simulate
    from oceanmc.run.summary import format_summary
    small_scene.update(photons=2000, wavelengths_nm=[450.0, 550.0])
    default = format_summary(simulate(small_scene))
    small_scene["estimator"] = {"upward_fraction": None}
    unbiased = format_summary(simulate(small_scene))
    assert "heavy-tailed in a spectral run" in " ".join(unbiased.split())
    assert "heavy-tailed in a spectral run" not in " ".join(default.split())


def test_two_configs_that_would_write_one_file_are_named(tmp_path, small_scene):
    """Two configs of one name in different folders, run into one folder: the refusal names
    both and the file (it said only 'two configs share a file name')."""
    for folder in ("a", "b"):
        (tmp_path / folder).mkdir()
        (tmp_path / folder / "s.yaml").write_text(yaml.safe_dump(small_scene))
    done = oceanmc("run", "a/s.yaml", "b/s.yaml", "-o", "out/", cwd=tmp_path)
    assert done.returncode == 2
    assert "a/s.yaml and b/s.yaml would both write out/s.h5" in done.stderr, done.stderr


def test_merge_onto_a_disk_without_room_is_refused_before_writing(tmp_path, small_scene,
                                                                    monkeypatch, capsys):
    """merge wrote onto a full disk until h5py's write failed in C (1300 lines of tracebacks
    and a segfault: a user's review); like run, it now checks the room first: the inputs'
    sizes together, twice over, in one line, exit 2, nothing written."""
    import shutil

    import oceanmc
    from oceanmc.cli import main
    a = oceanmc.simulate(dict(small_scene, seed=1), threads=1).save(tmp_path / "a.h5")
    b = oceanmc.simulate(dict(small_scene, seed=2), threads=1).save(tmp_path / "b.h5")
    need = a.stat().st_size + b.stat().st_size
    usage = shutil.disk_usage(tmp_path)
    monkeypatch.setattr(shutil, "disk_usage",
                        lambda folder: usage._replace(free=need))   # less than twice over
    assert main(["merge", str(a), str(b), "-o", str(tmp_path / "ab.h5")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("oceanmc: error: not enough disk space in ") and err.count("\n") == 1
    assert not (tmp_path / "ab.h5").exists()


def test_resume_and_overwrite_together_are_refused(tmp_path, scene_file, capsys):
    """`--resume --overwrite` started the run over and dropped the partial file's batches
    without a word (a user's review): the two ask opposite things; one line, exit 2."""
    from oceanmc.cli import main
    assert main(["run", str(scene_file), "-o", str(tmp_path / "r.h5"), "--resume",
                 "--overwrite"]) == 2
    err = capsys.readouterr().err
    assert err == ("oceanmc: error: --resume and --overwrite together: --resume continues a "
                   "partial file, --overwrite replaces it with a new run; give one of them\n")


def test_a_background_run_s_early_sigint_interrupts_it(tmp_path, scene_file, monkeypatch,
                                                        capsys):
    """A job a script starts in the background inherits SIGINT as ignored; before the run's own
    handler took over (reading the scenes, building their tables), `kill -INT` was dropped and
    the run finished with exit 0 (a user's review). Now it interrupts there too: exit 130, no
    file."""
    import signal

    import oceanmc.config as config_module
    from oceanmc import cli
    original = config_module.load_config

    def load_then_signal(*args, **kwargs):
        os.kill(os.getpid(), signal.SIGINT)    # what `kill -INT` does while the scene is read
        return original(*args, **kwargs)

    monkeypatch.setattr(config_module, "load_config", load_then_signal)
    before = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        code = cli.main(["run", str(scene_file), "-o", str(tmp_path / "r.h5"), "-q"])
    finally:
        signal.signal(signal.SIGINT, before)
    assert code == 130 and not (tmp_path / "r.h5").exists()
    assert "interrupted; no partial results file was written" in capsys.readouterr().err
