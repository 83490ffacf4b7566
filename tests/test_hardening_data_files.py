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


def test_the_summary_names_each_data_file_its_key_and_its_content_hash(tmp_path):
    """The summary (of `run` and of `show`, one function) names every data file the scene read
    with the key that gives it and the start of its sha256 when run, so that a result says what
    it was made from after the file has moved or changed; a byte-order mark (Excel's "CSV
    UTF-8") before the header is no part of the first column's name; an empty path is refused
    as one, not read as the config's folder."""
    import hashlib
    from oceanmc.run.summary import format_summary
    table = tmp_path / "aw.csv"
    table.write_bytes(b"\xef\xbb\xbfwavelength_nm,a\n300,0.05\n800,2.0\n")
    config = dict(SMALL_SCENE, photons=2000, batches=4, wavelengths_nm=[450.0, 550.0])
    config["water"] = {"layers": [{"thickness_m": 5.0, "components": [
        {"model": "pure_water", "absorption_file": "aw.csv"}]}]}
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(config))
    result = oceanmc.simulate(path)
    digest = hashlib.sha256(table.read_bytes()).hexdigest()
    table.unlink()   # moved away: the result still says what it read
    summary = " ".join(format_summary(result).split())
    assert (f"data files (sha256 when run): water.layers[0].components[0].absorption_file = "
            f"{table} ({digest[:12]})") in summary, summary
    config["water"]["layers"][0]["components"][0]["absorption_file"] = ""
    with pytest.raises(oceanmc.config.ConfigError, match=r"absorption_file = '': a file path "
                                                          r"cannot be empty"):
        oceanmc.load_config(config)
