"""Limits found before any photon: tallies too large for memory; partial files merged and then
resumed."""
import resource

import pytest
import yaml

import oceanmc
from oceanmc.cli import main
from oceanmc.config import ConfigError


def test_an_enormous_tally_is_refused_before_allocation(tmp_path, small_scene, capsys):
    # a small config (about 20 KB) asking for terabytes: 2,000 depths x 1 deg x 1 deg quads
    small_scene["batches"] = 1000
    small_scene["tallies"] = {"depths_m": [round(0.001 * i, 3) for i in range(2000)],
                              "theta_edges_deg": list(range(181)), "phi_bands": 360}
    path = tmp_path / "huge.yaml"
    path.write_text(yaml.safe_dump(small_scene))
    assert path.stat().st_size < 30_000
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    assert main(["run", str(path), "-o", str(tmp_path / "huge.h5")]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "GiB" in err and "more than the limit of" in err, err
    assert "tallies.depths_m" in err and not (tmp_path / "huge.h5").exists()
    # nothing near the tallies' size was allocated (ru_maxrss in KiB on Linux)
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before < 500_000
    with pytest.raises(ConfigError, match="GiB"):
        oceanmc.simulate(small_scene)


def test_merged_partial_files_are_refused_by_resume(tmp_path, small_scene, monkeypatch, capsys):
    from oceanmc.run import simulation
    from oceanmc.run.hdf5 import load_result
    from oceanmc.run.results import MergeError, merge_results
    small_scene.update(photons=120_000, batches=6)
    monkeypatch.setattr(simulation, "CALL_SECONDS", 0.0)
    monkeypatch.setattr(simulation, "POLL_SECONDS", 0.005)
    simulation.ready()   # compiled or loaded first: should_stop is polled while compiling
    files = []
    for seed in (1, 2):
        polls = [0]

        def stop():
            polls[0] += 1
            return polls[0] > 3
        part = oceanmc.simulate(dict(small_scene, seed=seed), threads=1, should_stop=stop)
        assert part.attrs["partial"]
        files.append(str(part.save(tmp_path / f"part{seed}.h5")))
    merged = tmp_path / "merged.h5"
    assert main(["merge", *files, "-o", str(merged)]) == 0
    assert load_result(merged).attrs["partial"]
    config = tmp_path / "scene.yaml"
    config.write_text(yaml.safe_dump(dict(small_scene, seed=1)))
    capsys.readouterr()
    assert main(["run", str(config), "-o", str(merged), "--resume", "-q"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "merges 2 runs (seeds 1,2)" in err and "resume each" in err, err
    with pytest.raises(MergeError, match="cannot be continued"):
        merge_results([load_result(merged), load_result(files[0])], resume=True)
    # each part resumes on its own and the two merge into a whole run
    for seed, path in zip((1, 2), files):
        config.write_text(yaml.safe_dump(dict(small_scene, seed=seed)))
        assert main(["run", str(config), "-o", path, "--resume", "-q"]) == 0
    assert main(["merge", *files, "-o", str(merged), "--overwrite"]) == 0
    whole = load_result(merged)
    assert not whole.attrs["partial"] and whole.attrs["batches"] == 12
