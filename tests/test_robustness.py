"""Interrupted, resumed and merged runs; reproducibility from the stored scene."""
import os
import signal
import subprocess
import sys
import time

import h5py
import numpy as np
import pytest
import yaml

import oceanmc
from oceanmc.run.results import MergeError, merge_results

from conftest import REPO

ENV = dict(os.environ, PYTHONPATH=str(REPO))

# Enough photons that a run lasts several seconds on 2 cores, in many batches.
LONG = {"name": "long", "photons": 2_000_000, "batches": 64, "seed": 2,
        "illumination": {"sun_zenith_deg": 20},
        "water": {"layers": [{"thickness_m": 20, "a": 0.02, "b": 0.5,
                              "phase": {"model": "henyey_greenstein", "g": 0.9}}]},
        "bottom": {"model": "lambertian", "reflectance": 0.5},
        "tallies": {"depths_m": [0, 10]}}


def start(args, cwd):
    return subprocess.Popen([sys.executable, "-m", "oceanmc", *map(str, args)], cwd=cwd, env=ENV,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def run(args, cwd):
    return subprocess.run([sys.executable, "-m", "oceanmc", *map(str, args)], cwd=cwd, env=ENV,
                          capture_output=True, text=True, timeout=600)


def wait_for(path, proc, timeout=120.0):
    t0 = time.time()
    while not path.exists():
        assert proc.poll() is None, proc.communicate()
        assert time.time() - t0 < timeout, "no checkpoint appeared"
        time.sleep(0.05)


@pytest.fixture
def long_scene(tmp_path):
    path = tmp_path / "long.yaml"
    path.write_text(yaml.safe_dump(LONG))
    return path


@pytest.mark.long(cpu_s=31)
def test_sigint_writes_a_partial_file_and_resume_completes_it_bit_for_bit(tmp_path):
    # a third of LONG's photons in as many batches: the SIGINT still comes after the first
    # batch of 64 (the file appears), and the resumed and the whole run, which this test
    # traces in full, cost about 5 s each instead of 15 s
    long_scene = tmp_path / "long.yaml"
    long_scene.write_text(yaml.safe_dump(dict(LONG, photons=640_000)))
    out = tmp_path / "r.h5"
    proc = start(["run", long_scene, "-o", out, "-q", "--checkpoint-every", "0", "--threads", "2"],
                 tmp_path)
    wait_for(out, proc)
    proc.send_signal(signal.SIGINT)
    stdout, stderr = proc.communicate(timeout=300)
    assert proc.returncode == 130, stderr
    assert "PARTIAL" in stdout and "--resume" in stdout
    with h5py.File(out) as f:
        assert bool(f.attrs["partial"])
        done = int(f.attrs["batches"])
        assert 0 <= done < 64
        assert f.attrs["photons"] == done * f.attrs["photons_per_batch"]
        assert f["batches/Ed"].shape[0] == done

    resumed = run(["run", long_scene, "-o", out, "-q", "--resume"], tmp_path)
    assert resumed.returncode == 0, resumed.stderr
    full = run(["run", long_scene, "-o", tmp_path / "full.h5", "-q"], tmp_path)
    assert full.returncode == 0, full.stderr
    a, b = oceanmc.load_result(out), oceanmc.load_result(tmp_path / "full.h5")
    assert not a.attrs["partial"] and a.attrs["batches"] == 64
    for name, q in b.quantities.items():
        assert np.array_equal(a.quantities[name].batches, q.batches), name

    again = run(["run", long_scene, "-o", out, "-q", "--resume"], tmp_path)
    assert again.returncode == 2 and "already complete" in again.stderr


def test_sigterm_also_stops_cleanly(tmp_path, long_scene):
    out = tmp_path / "r.h5"
    proc = start(["run", long_scene, "-o", out, "-q", "--checkpoint-every", "0"], tmp_path)
    wait_for(out, proc)
    proc.send_signal(signal.SIGTERM)
    proc.communicate(timeout=300)
    assert proc.returncode == 130
    assert oceanmc.load_result(out).attrs["partial"]


def test_second_sigint_quits_at_once_without_a_corrupt_file(tmp_path, long_scene):
    out = tmp_path / "r.h5"
    proc = start(["run", long_scene, "-o", out, "-q", "--checkpoint-every", "0"], tmp_path)
    wait_for(out, proc)
    proc.send_signal(signal.SIGINT)
    time.sleep(0.01)
    sent = time.time()
    proc.send_signal(signal.SIGINT)
    proc.communicate(timeout=300)
    assert time.time() - sent < 1.0
    assert proc.returncode in (130, -signal.SIGINT)
    result = oceanmc.load_result(out)  # whatever is there is a whole file
    assert result.attrs["partial"]


def test_resume_refuses_a_different_scene(tmp_path, long_scene):
    out = tmp_path / "r.h5"
    proc = start(["run", long_scene, "-o", out, "-q", "--checkpoint-every", "0"], tmp_path)
    wait_for(out, proc)
    proc.send_signal(signal.SIGINT)
    proc.communicate(timeout=300)
    other = dict(LONG, seed=99)
    other_path = tmp_path / "other.yaml"
    other_path.write_text(yaml.safe_dump(other))
    done = run(["run", other_path, "-o", out, "--resume"], tmp_path)
    # (a seed of its own is a scene key `oceanmc run --seed` can give again: the message says
    # how; any other key makes a different scene)
    assert done.returncode == 2 and "was run with seed = 2" in done.stderr \
        and "give --seed 2 to continue it" in done.stderr, done.stderr
    other = dict(LONG, batches=LONG["batches"] + 1)
    other_path.write_text(yaml.safe_dump(other))
    done = run(["run", other_path, "-o", out, "--resume"], tmp_path)
    assert done.returncode == 2 and "different scene" in done.stderr, done.stderr


def _small(seed, small_scene):
    return oceanmc.simulate(dict(small_scene, seed=seed))


def test_merge_of_independent_runs(tmp_path, small_scene):
    a, b = _small(1, small_scene), _small(2, small_scene)
    merged = merge_results([a, b])
    assert merged.attrs["batches"] == 16 and merged.attrs["photons"] == 40000
    assert merged.attrs["seeds"] == "1,2"
    both = np.concatenate([a.quantities["Ed"].batches, b.quantities["Ed"].batches])
    assert np.allclose(merged["Ed"], both.mean(axis=0))
    assert np.allclose(merged.stderr("Ed"), both.std(axis=0, ddof=1) / 4.0)
    # the standard error shrinks like 1/sqrt(photons): about sqrt(2) (loose: 16 batches)
    ratio = a.stderr("Eu") / merged.stderr("Eu")
    assert np.all((ratio > 0.9) & (ratio < 2.3))

    a.save(tmp_path / "a.h5")
    b.save(tmp_path / "b.h5")
    done = run(["merge", "a.h5", "b.h5", "-o", "c.h5"], tmp_path)
    assert done.returncode == 0, done.stderr
    assert oceanmc.load_result(tmp_path / "c.h5").attrs["batches"] == 16
    done = run(["merge", "a.h5", "a.h5", "-o", "d.h5"], tmp_path)
    assert done.returncode == 2 and "batches 0..7 of seed 1 are in both result 1 and result 2" \
        in done.stderr
    assert not (tmp_path / "d.h5").exists()


def test_merge_leaves_out_rho_of_two_definitions(small_scene):
    """air/rho of a file written before its denominator became the sky's own radiance
    (its description says the old way) is not joined with a newer run's: the merge leaves it
    out, and keeps everything else."""
    a, b = _small(1, small_scene), _small(2, small_scene)
    assert "air/rho" in merge_results([a, b]).quantities
    old = a.quantities["air/rho"]
    a.quantities["air/rho"] = type(old)(old.name, old.dims, old.batches, old.units,
                                        "an earlier definition")
    merged = merge_results([a, b])
    assert "air/rho" not in merged.quantities and "air/L_reflected" in merged.quantities


def test_merge_refuses_different_scenes(small_scene):
    a = _small(1, small_scene)
    small_scene["bottom"]["reflectance"] = 0.5
    with pytest.raises(MergeError, match="different scene"):
        merge_results([a, _small(2, small_scene)])


def test_stored_config_reproduces_the_file_bit_for_bit(tmp_path, small_scene):
    first = tmp_path / "first.h5"
    oceanmc.simulate(small_scene).save(first)
    stored = oceanmc.load_result(first).config_yaml
    (tmp_path / "stored.yaml").write_text(stored)
    done = run(["run", "stored.yaml", "-o", "second.h5", "-q"], tmp_path)
    assert done.returncode == 0, done.stderr
    a, b = oceanmc.load_result(first), oceanmc.load_result(tmp_path / "second.h5")
    for name, q in a.quantities.items():
        assert np.array_equal(q.batches, b.quantities[name].batches), name
    with h5py.File(first) as f:
        assert f.attrs["numba_version"] and f.attrs["oceanmc_version"]
