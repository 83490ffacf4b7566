"""Stopping within a fraction of a second and resuming bit for bit: a batch is traced in short
calls (transport.trace_batch continues it exactly), a stop keeps the whole batches as the
estimate and the begun ones as state to resume from."""
import signal
import subprocess
import sys
import time

import h5py
import numpy as np
import pytest
import yaml

import oceanmc
from oceanmc.run import simulation
from oceanmc.run.hdf5 import load_result
from oceanmc.run.results import MergeError, merge_results
from oceanmc.scene.grid import tally_arrays, tally_views, write_tally_arrays

from conftest import REPO
from test_robustness import ENV


def stop_after(polls):
    count = [0]

    def should_stop():
        count[0] += 1
        return count[0] > polls
    return should_stop


def stopped_run(scene, monkeypatch, poll_s, polls):
    """The scene run in the smallest calls, the main thread looking at should_stop every
    poll_s seconds, and stopped after `polls` looks: a partial Result."""
    monkeypatch.setattr(simulation, "CALL_SECONDS", 0.0)
    monkeypatch.setattr(simulation, "POLL_SECONDS", poll_s)
    return oceanmc.simulate(scene, threads=2, should_stop=stop_after(polls))


def test_stopped_runs_resumed_are_bit_identical(tmp_path, small_scene, monkeypatch):
    """A run stopped three times, each partial file saved, loaded and resumed, against one
    uninterrupted run: every batch value equal bit for bit (different call lengths, different
    stops, the same draws and additions)."""
    small_scene.update(photons=300_000, batches=6, estimator={"split_weight": 2.0})
    full = oceanmc.simulate(small_scene, threads=2)
    # the smallest calls, and the main thread looking at should_stop every 5 ms
    monkeypatch.setattr(simulation, "CALL_SECONDS", 0.0)
    monkeypatch.setattr(simulation, "POLL_SECONDS", 0.005)
    result, stops, begun = None, 0, 0
    while result is None or result.attrs["partial"]:
        first = 0 if result is None else result.attrs["first_batch"] + result.attrs["batches"]
        part = oceanmc.simulate(small_scene, threads=2, first_batch=first,
                                resume_state=None if result is None else result.resume_state,
                                should_stop=stop_after(2) if stops < 3 else None)
        stops += 1
        result = part if result is None else merge_results([result, part], resume=True)
        if result.attrs["partial"]:
            begun += len(result.resume_state["batch"])
        result.save(tmp_path / "r.h5")
        result = load_result(tmp_path / "r.h5")
    assert stops == 4 and begun >= 3
    assert result.resume_state is None and result.attrs["batches"] == 6
    for name, q in full.quantities.items():
        assert np.array_equal(result.quantities[name].batches, q.batches), name


def test_a_stop_before_any_batch_is_whole(small_scene, monkeypatch, tmp_path):
    """No whole batch: no estimate (NaN), 0 batches, the begun batches' state kept; resuming
    from it gives the uninterrupted run."""
    small_scene.update(photons=20000, batches=2)
    full = oceanmc.simulate(small_scene, threads=2)
    part = stopped_run(small_scene, monkeypatch, 0.001, 0)
    assert part.attrs["batches"] == 0 and part.attrs["partial"]
    assert np.isnan(part["Ed"]).all()
    part.save(tmp_path / "p.h5")
    part = load_result(tmp_path / "p.h5")
    assert sorted(part.resume_state["batch"]) == [0, 1]
    rest = oceanmc.simulate(small_scene, threads=2, resume_state=part.resume_state)
    done = merge_results([part, rest], resume=True)
    for name, q in full.quantities.items():
        assert np.array_equal(done.quantities[name].batches, q.batches), name


def test_merge_refuses_shared_batches(small_scene):
    """Batch b of seed s is the same photons in every run: runs of one seed over disjoint batch
    ranges merge, overlapping ones do not, also through an earlier merge (batch_ranges)."""
    small_scene.update(photons=8000, batches=8)
    tail = oceanmc.simulate(small_scene, first_batch=4)
    other = oceanmc.simulate(dict(small_scene, seed=6))
    merged = merge_results([tail, other])
    assert merged.attrs["batch_ranges"] == "5:4:8,6:0:8"
    with pytest.raises(MergeError, match="batches 4..7 of seed 5 are in both result 1 and "
                                         "result 2"):
        merge_results([merged, oceanmc.simulate(small_scene, first_batch=2)])
    # batches 0..3 of seed 5: a run stopped after them (its first four batches)
    head = oceanmc.simulate(small_scene)
    for q in head.quantities.values():
        q.batches = q.batches[:4]
    head.attrs.update(batches=4, photons=4000, partial=True)
    assert merge_results([head, merged]).attrs["batches"] == 16


def test_next_budget_aims_at_the_call_length():
    assert simulation.next_budget(1000, simulation.CALL_SECONDS) == 1000
    assert simulation.next_budget(4000, 10.0) == 1000           # at most 4x per call
    assert simulation.next_budget(1000, 0.0) == 4000
    assert simulation.next_budget(300, 100.0) == simulation.MIN_BUDGET


HUGE = {"name": "huge", "photons": 10**12, "batches": 4, "seed": 3,
        "water": {"layers": [{"thickness_m": 20, "a": 0.05, "b": 0.3}]},
        "bottom": {"model": "lambertian", "reflectance": 0.2}}


@pytest.mark.parametrize("signal_number", [signal.SIGINT, signal.SIGTERM])
def test_a_huge_run_stops_within_seconds(tmp_path, signal_number):
    """10^12 photons in 4 batches (days of work per batch): a progress bar and an estimate of the
    time left within seconds, the notice that it runs longer than an hour, and after the signal
    an exit within 3 s (Ctrl-C latency; measured 0.3-0.6 s) with a valid partial file that
    --resume can continue."""
    config = tmp_path / "huge.yaml"
    config.write_text(yaml.safe_dump(HUGE))
    out = tmp_path / "huge.h5"
    proc = subprocess.Popen([sys.executable, "-m", "oceanmc", "run", config, "-o", out,
                             "--checkpoint-every", "4"], cwd=tmp_path, env=ENV,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    t0 = time.time()
    while not out.exists():
        assert proc.poll() is None, proc.communicate()
        assert time.time() - t0 < 120, "no checkpoint appeared"
        time.sleep(0.05)
    sent = time.time()
    proc.send_signal(signal_number)
    stdout, stderr = proc.communicate(timeout=60)
    latency = time.time() - sent
    assert proc.returncode == 130, stderr
    print(f"exit {latency:.2f} s after {signal.Signals(signal_number).name}")
    assert latency < 3.0, latency
    assert "to go at" in stderr and "Ctrl-C stops it" in stderr     # the long-run notice
    assert "photon/s" in stderr or "photons/s" in stderr              # the progress bar
    assert "no batch is whole yet" in stdout and "--resume" in stdout
    result = load_result(out)
    assert result.attrs["partial"] and result.attrs["batches"] == 0
    assert sorted(result.resume_state["batch"]) == [0, 1]
    assert (result.resume_state["next_photon"] > 0).all()


def test_tally_arrays_round_trip_exactly():
    """A spectral scene's tally rows as named arrays (wavelength last) and back, bit for bit:
    views -> rows -> views, and rows -> views -> rows on every score; the arrays are disjoint
    (random values survive the round trip) and tally_views is their slice at one wavelength."""
    config = oceanmc.load_config({
        "name": "tally arrays", "wavelengths_nm": [450.0, 550.0, 650.0],
        "water": {"layers": [{"thickness_m": 5.0, "a": 0.1, "b": 0.4},
                             {"thickness_m": 3.0, "a": 0.2, "b": 0.2}]},
        "bottom": {"model": "lambertian", "reflectance": 0.3},
        "tallies": {"depths_m": [0, 2, 5], "radiance": True, "phi_bands": 12,
                    "local_directions_deg": [[180, 0], [140, 45]]}})
    sc = oceanmc.scene.build(config)
    rows = np.random.default_rng(1).random((3, sc.tally_size))
    arrays = {name: values.copy() for name, values in tally_arrays(sc.grid, rows).items()}
    n_levels, n_wl = len(config.tallies.depths_m) + 2, 3
    assert arrays["flux"].shape == (3, n_levels, 4, n_wl)
    n_theta = len(config.tallies.theta_edges) - 1
    assert arrays["radiance"].shape == (3, n_levels, n_theta, 12, n_wl)
    n_dirs = int(sc.grid[0]["n_dirs"])   # kernel rows: in water, and refracted to the air
    assert n_dirs >= 2 and arrays["local"].shape == (3, n_levels - 1, n_dirs, n_wl)
    assert arrays["cap"].shape == (3, n_levels - 1, n_wl)
    assert arrays["budget"].shape[-1] == n_wl
    rebuilt = np.full_like(rows, np.nan)
    write_tally_arrays(sc.grid, arrays, rebuilt)
    for name, values in tally_arrays(sc.grid, rebuilt).items():
        assert np.array_equal(values, arrays[name]), name
    scores = ~np.isnan(rebuilt)   # every cell a score array wrote holds the row's value
    assert scores.sum() == sum(values.size for values in arrays.values())
    assert np.array_equal(rebuilt[scores], rows[scores])
    for j in range(n_wl):
        for name, values in tally_views(sc.grid, rows, j).items():
            assert np.array_equal(values, arrays[name][..., j]), name
    with pytest.raises(ValueError, match="tally cap is"):
        write_tally_arrays(sc.grid, dict(arrays, cap=arrays["cap"][..., :2]), rebuilt)


def stopped_saved_and_resumed(scene, monkeypatch, tmp_path):
    """The scene stopped mid-batch, its partial file saved and loaded, and the run resumed from
    it: every batch bit for bit the uninterrupted run's. Returns (the file, its Result)."""
    full = oceanmc.simulate(scene, threads=2)
    part = stopped_run(scene, monkeypatch, 0.001, 0)
    assert part.attrs["partial"] and part.resume_state is not None
    out = tmp_path / "p.h5"
    part.save(out)
    part = load_result(out)
    rest = oceanmc.simulate(scene, threads=1, resume_state=part.resume_state)
    done = merge_results([part, rest], resume=True)
    for name, q in full.quantities.items():
        assert np.array_equal(done.quantities[name].batches, q.batches), name
    assert done.attrs["threads"] == 1   # the continuing run's (it kept the first's, 2)
    return out, part


def test_spectral_run_stopped_mid_batch_resumes_bit_for_bit(tmp_path, small_scene, monkeypatch):
    """A spectral run stopped mid-batch resumes bit for bit from its file (the unfinished
    batches' tallies stored as named arrays, resume/tally/<name>); a scene whose tallies have
    another shape is refused."""
    small_scene.update(photons=20000, batches=2, wavelengths_nm=[450.0, 550.0, 650.0])
    out, part = stopped_saved_and_resumed(small_scene, monkeypatch, tmp_path)
    with h5py.File(out, "r") as f:
        assert sorted(f["resume/tally"]) == ["budget", "cap", "flux", "local", "radiance"]
        assert f["resume/tally/flux"].shape[-1] == 3   # wavelength last
    with pytest.raises(ValueError, match="tallies do not fit this scene: tally flux is"):
        oceanmc.simulate(dict(small_scene, tallies={"depths_m": [0, 1]}),
                         resume_state=part.resume_state)


def test_inelastic_run_stopped_mid_batch_resumes_bit_for_bit(tmp_path, small_scene, monkeypatch):
    """A run with inelastic light stopped mid-batch: its file (each part's unfinished tallies in
    a group of their own, resume/tally/part1/...) loads, shows and resumes bit for bit. (It was
    refused as 'not an oceanmc results file' until the reader went into those groups.)"""
    small_scene.update(photons=20000, batches=2, wavelengths_nm=[450.0, 500.0, 550.0],
                       water=dict(small_scene["water"], inelastic={"raman": {}}))
    out, part = stopped_saved_and_resumed(small_scene, monkeypatch, tmp_path)
    with h5py.File(out, "r") as f:
        assert "flux" in f["resume/tally/part1"]
    assert "tally/part1/flux" in part.resume_state
    shown = subprocess.run([sys.executable, "-m", "oceanmc", "show", str(out)],
                           capture_output=True, text=True, env=ENV)
    assert shown.returncode == 0 and "PARTIAL: 0 of 2" in shown.stdout, shown.stderr


@pytest.mark.parametrize("with_layout", [False, True])
def test_raw_tally_rows_of_an_earlier_oceanmc_are_refused(tmp_path, small_scene, monkeypatch,
                                                          with_layout):
    """A partial file whose resume group holds raw tally rows (an earlier oceanmc's, with or
    without their tally_layout) cannot be continued: --resume refuses it in one line, exit
    status 2, and leaves it as it was; its whole batches stay readable."""
    small_scene.update(photons=60000, batches=6)
    part = stopped_run(small_scene, monkeypatch, 0.005, 2)
    assert part.attrs["partial"] and part.resume_state is not None
    out = tmp_path / "p.h5"
    part.save(out)
    with h5py.File(out, "a") as f:   # what an earlier oceanmc wrote
        begun = len(f["resume/batch"])
        del f["resume/tally"]
        f["resume/tally"] = np.zeros((begun, 500))
        if with_layout:
            f["resume/tally_layout"] = np.array(2)
    before = out.read_bytes()
    assert load_result(out).attrs["batches"] == part.attrs["batches"]
    config = tmp_path / "s.yaml"
    config.write_text(yaml.safe_dump(small_scene))
    run = subprocess.run([sys.executable, "-m", "oceanmc", "run", config, "-o", out, "--resume"],
                         cwd=tmp_path, env=ENV, capture_output=True, text=True, timeout=600)
    assert run.returncode == 2, run.stderr
    message = run.stderr.strip()
    assert "Traceback" not in message and len(message.splitlines()) == 1, message
    assert "raw tally rows" in message and "cannot be continued" in message, message
    assert f"{part.attrs['batches']} whole batches stay readable" in message, message
    assert out.read_bytes() == before


def test_partial_summary_says_how_many_batches_and_that_few_give_unreliable_errors(
        tmp_path, small_scene, capsys):
    """`oceanmc show` (and the summary `oceanmc run` prints after a stop) of a partial file
    says, in one line, how many of the scene's batches are whole, and that standard errors from
    fewer than 8 batches are unreliable; so does a complete run of fewer than 8 batches."""
    from oceanmc.cli import main
    from oceanmc.run.results import RELIABLE_BATCHES, format_summary

    small_scene.update(photons=4000, batches=8)
    full = oceanmc.simulate(small_scene, threads=1)
    assert RELIABLE_BATCHES == 8
    assert "PARTIAL" not in format_summary(full) and "unreliable" not in format_summary(full)

    def cut(whole, partial=True):
        part = load_result(full.save(tmp_path / "full.h5"))
        for q in part.quantities.values():
            q.batches = q.batches[:whole]
        part.attrs.update(batches=whole, partial=partial,
                          photons=whole * int(part.attrs["photons_per_batch"]))
        return part.save(tmp_path / f"cut{whole}{partial}.h5")

    def shown(path):
        assert main(["show", str(path)]) == 0
        lines = capsys.readouterr().out.splitlines()
        said = [line for line in lines if "PARTIAL" in line or "note: " in line
                and "batches" in line]
        assert len(said) == 1 and lines.index(said[0]) == 2, lines
        return said[0]

    assert shown(cut(2)) == ("  PARTIAL: 2 of 8 batches whole (a stopped run; the estimates use "
                             "them only); standard errors from fewer than 8 batches are "
                             "unreliable")
    assert shown(cut(0)).endswith("0 of 8 batches whole (a stopped run; the estimates use them "
                                  "only); no batch is whole yet: the file holds no estimate, "
                                  "only the state to resume from")
    assert shown(cut(4, partial=False)) == ("  note: 4 batches; standard errors from fewer than 8 "
                                            "batches are unreliable")
    main(["show", str(full.save(tmp_path / "whole.h5"))])
    out = capsys.readouterr().out
    assert "PARTIAL" not in out and "unreliable" not in out


@pytest.mark.parametrize("junk, said", [
    ({}, "lack batch, rng, beam, next_photon, events"),
    ({"batch": [0], "rng": np.zeros((1, 4), dtype=np.uint64), "beam": np.zeros((1, 4))},
     "lack next_photon, events"),
    ({"batch": [0, 1], "rng": np.zeros((1, 4), dtype=np.uint64), "beam": np.zeros((2, 4)),
      "next_photon": [5, 5], "events": [0, 0]}, "rng do not hold one row for each of their 2"),
    ({"batch": [0], "rng": np.zeros((1, 99), dtype=np.uint64), "beam": np.zeros((1, 4)),
      "next_photon": [5], "events": [0]}, "rng do not hold one row"),
])
def test_a_resume_state_that_is_not_a_partial_results_is_refused(small_scene, junk, said):
    """simulate(resume_state=...) of something else than a partial Result's resume_state: one
    line saying what it lacks (was a KeyError 'batch'), before any photon is traced."""
    with pytest.raises(MergeError, match=said):
        oceanmc.simulate(small_scene, resume_state=junk)


@pytest.mark.parametrize("damage, said", [
    (lambda s: s["next_photon"].__setitem__(0, -3), "next photon outside -1 .. 10000"),
    (lambda s: s["next_photon"].__setitem__(0, 99999), "next photon outside -1 .. 10000"),
    (lambda s: s["rng"].__setitem__(0, 0), "a random stream of all zeros"),
    (lambda s: s["beam"].__setitem__(0, 5.0), "an entered sun beam without a finite weight "
                                              "and a unit direction"),
    (lambda s: s["events"].__setitem__(0, -1), "negative scattering events"),
])
def test_a_damaged_stored_state_is_refused_not_resumed(small_scene, monkeypatch, damage, said):
    """A partial file's unfinished batches edited by hand (a user's review: next_photon -3 or
    99999 and a zero random stream resumed with exit status 0 and wrong tallies, beam = 5
    crashed the process): refused in one line before any photon is traced."""
    small_scene.update(photons=20000, batches=2)
    part = stopped_run(small_scene, monkeypatch, 0.001, 0)
    state = {key: np.array(values) for key, values in part.resume_state.items()}
    damage(state)
    with pytest.raises(MergeError, match=f"the stored unfinished batches are damaged \\({said}"):
        oceanmc.simulate(small_scene, threads=1, resume_state=state)
    assert oceanmc.simulate(small_scene, threads=1, resume_state=part.resume_state)


def test_resume_with_other_command_line_counts_says_which_options_to_give(tmp_path, small_scene,
                                                                           monkeypatch):
    """A partial file run with --photons N, resumed without it, is refused with the option to
    give again (it said 'made from a different scene ... (photons differs)'); a different
    scene is still refused as one."""
    from oceanmc.run.resume import CannotResume, partial_run
    small_scene.update(photons=300_000, batches=6)
    part = stopped_run(small_scene, monkeypatch, 0.005, 1)
    assert part.attrs["partial"]
    out = tmp_path / "p.h5"
    part.save(out)
    config = tmp_path / "scene.yaml"
    config.write_text(yaml.safe_dump(dict(small_scene, photons=1000, seed=9)))
    with pytest.raises(CannotResume, match=r"was run with photons = 300000, seed = 5 \(the "
                                           r"scene's, or given by --photons / --seed\), .* "
                                           r"gives 1000, 9: give --photons 300000 --seed 5 to "
                                           r"continue it"):
        partial_run(out, simulation.prepare(oceanmc.load_config(config)), config)
    config.write_text(yaml.safe_dump(dict(small_scene, batches=7)))
    with pytest.raises(CannotResume, match="made from a different scene"):
        partial_run(out, simulation.prepare(oceanmc.load_config(config)), config)
