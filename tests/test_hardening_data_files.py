"""Merge and resume compare the content of every data file a scene names (sha256 stored in the
results), not only the stored config text that holds their paths (issue 13)."""
import subprocess
import sys

import pytest
import yaml

import oceanmc
from oceanmc.run.results import MergeError, merge_results

from conftest import REPO, SMALL_SCENE
from test_robustness import ENV


def write_table(path, backscatter):
    rows = [(0.0, 10.0), (10.0, 1.0), (90.0, 0.1), (180.0, backscatter)]
    path.write_text("".join(f"{angle} {value}\n" for angle, value in rows))


def scene_file(tmp_path, seed, photons=8000):
    config = dict(SMALL_SCENE, seed=seed, photons=photons, batches=4)
    config["water"] = {"layers": [{"thickness_m": 2.0, "a": 0.1, "b": 0.4,
                                   "phase": {"model": "table", "file": "phase.txt"}}]}
    path = tmp_path / f"scene{seed}.yaml"
    path.write_text(yaml.safe_dump(config))
    return path


def test_merge_refuses_an_edited_table(tmp_path):
    table = tmp_path / "phase.txt"
    write_table(table, 0.1)
    first = oceanmc.simulate(scene_file(tmp_path, 1))
    same = oceanmc.simulate(scene_file(tmp_path, 2))
    assert merge_results([first, same]).attrs["batches"] == 8
    write_table(table, 0.2)
    edited = oceanmc.simulate(scene_file(tmp_path, 3))
    with pytest.raises(MergeError, match=f"content of {table} differs for result 2"):
        merge_results([first, edited])
    with pytest.raises(MergeError, match=f"content of {table} differs for the resumed part"):
        merge_results([first, oceanmc.simulate(scene_file(tmp_path, 1))], resume=True)


def test_resume_refuses_an_edited_table_before_running(tmp_path):
    table = tmp_path / "phase.txt"
    write_table(table, 0.1)
    config = scene_file(tmp_path, 1)
    part = oceanmc.simulate(config)
    for q in part.quantities.values():   # as if stopped after two of its four batches
        q.batches = q.batches[:2]
    part.attrs.update(batches=2, photons=4000, partial=True)
    part.save(tmp_path / "r.h5")
    write_table(table, 0.2)
    done = subprocess.run([sys.executable, "-m", "oceanmc", "run", str(config), "-o",
                           str(tmp_path / "r.h5"), "--resume", "--quiet"],
                          capture_output=True, text=True, env=ENV, cwd=REPO, timeout=300)
    assert done.returncode == 2, done.stderr
    assert f"content of {table} differs" in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1
