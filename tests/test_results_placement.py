"""Placing results files: no silent loss when two writers race on one path, no stale temporary
files after a SIGKILL, results kept elsewhere when the disk is full."""
import errno
import os
import subprocess
import sys
import threading

import numpy as np
import pytest

from oceanmc.run import placement
from oceanmc.run.placement import ResultsSavedElsewhere, place_atomically


def _writer(value):
    def write(tmp):
        np.save(open(tmp, "wb"), np.array([value]))
    return write


def test_two_racing_writers_one_wins_other_kept(tmp_path):
    target = tmp_path / "out.h5"
    barrier = threading.Barrier(2)
    outcomes = {}

    def run(value):
        def write(tmp):
            _writer(value)(tmp)
            barrier.wait()  # both temporary files are written before either is placed
        try:
            outcomes[value] = place_atomically(target, write, overwrite=False)
        except ResultsSavedElsewhere as exc:
            outcomes[value] = exc
    threads = [threading.Thread(target=run, args=(v,)) for v in (1.0, 2.0)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    lost = [v for v, o in outcomes.items() if isinstance(o, ResultsSavedElsewhere)]
    assert len(lost) == 1, outcomes
    exc = outcomes[lost[0]]
    assert str(exc.kept) in str(exc) and exc.kept != target
    assert np.load(open(exc.kept, "rb"))[0] == lost[0]
    assert np.load(open(target, "rb"))[0] != lost[0]
    assert not list(tmp_path.glob(".*.tmp"))


def test_a_run_whose_new_file_another_run_made_meanwhile_keeps_its_results(tmp_path,
                                                                           small_scene):
    """Two runs to one new file: the second's end met the first's file and lost its results
    with a FileExistsError traceback (Result.save's refusal comes before writing; a user's
    review). A run's file (run/resume.RunFile) is placed atomically instead: the results are
    kept beside it and the message says where; the other run's file is untouched."""
    import oceanmc
    from oceanmc.run.hdf5 import load_result
    from oceanmc.run.resume import RunFile
    target = tmp_path / "same.h5"
    first = oceanmc.simulate(dict(small_scene, seed=1), threads=1).save(target)
    before = target.read_bytes()
    result = oceanmc.simulate(dict(small_scene, seed=2), threads=1)
    with pytest.raises(ResultsSavedElsewhere, match="another process created this file") as info:
        RunFile(target, None, overwrite=False).save(result)
    assert first.read_bytes() == before
    kept = load_result(info.value.kept)
    np.testing.assert_array_equal(kept.quantities["Ed"].batches, result.quantities["Ed"].batches)


def test_overwrite_replaces(tmp_path):
    target = tmp_path / "out.h5"
    place_atomically(target, _writer(1.0), overwrite=False)
    with pytest.raises(ResultsSavedElsewhere):
        place_atomically(target, _writer(2.0), overwrite=False)
    place_atomically(target, _writer(3.0), overwrite=True)
    assert np.load(open(target, "rb"))[0] == 3.0


def test_stale_temps_of_dead_writers_removed_live_ones_kept(tmp_path):
    target = tmp_path / "out.h5"
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    stale = tmp_path / f".out.h5.oceanmc-{dead.pid}-0a1b2c3d.tmp"
    live = tmp_path / f".out.h5.oceanmc-{os.getppid()}-0a1b2c3d.tmp"
    other = tmp_path / f".other.h5.oceanmc-{dead.pid}-0a1b2c3d.tmp"
    users = tmp_path / ".out.h5.mine.tmp"
    for f in (stale, live, other, users):
        f.write_bytes(b"x")
    place_atomically(target, _writer(1.0))
    assert not stale.exists()
    assert live.exists() and other.exists() and users.exists()


def test_disk_full_keeps_results_in_temp_dir(tmp_path, monkeypatch):
    target = tmp_path / "full" / "out.h5"
    spare = tmp_path / "spare"
    spare.mkdir()
    monkeypatch.setattr(placement.tempfile, "gettempdir", lambda: str(spare))
    real = placement._write_temp

    def failing(tmp, write):
        if tmp.parent == target.parent:
            raise OSError(errno.ENOSPC, "No space left on device")
        real(tmp, write)
    monkeypatch.setattr(placement, "_write_temp", failing)
    with pytest.raises(ResultsSavedElsewhere) as info:
        place_atomically(target, _writer(5.0))
    assert info.value.kept.parent == spare
    assert np.load(open(info.value.kept, "rb"))[0] == 5.0
    assert "no space" in str(info.value)


def test_phase_table_scaled_by_1e300_same_as_unscaled(tmp_path):
    from oceanmc.scene.phase_tables import user_table
    angle = np.linspace(0.0, 180.0, 19)
    p = np.exp(-angle / 30.0)
    for name, scale in (("a.csv", 1.0), ("b.csv", 1e300), ("c.csv", 1e308 / p.max())):
        np.savetxt(tmp_path / name, np.column_stack([angle, p * scale]), delimiter=",")
    ref = user_table(tmp_path / "a.csv")
    for name in ("b.csv", "c.csv"):
        got = user_table(tmp_path / name)
        for r, g in zip(ref, got):
            assert np.all(np.isfinite(g))
            np.testing.assert_allclose(g, r, rtol=1e-12)
