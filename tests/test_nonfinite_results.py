"""A run whose tallies hold NaN or inf (issue 29: a kernel fault printed a NaN summary with exit
status 0 and wrote it) is refused: simulate() raises NonFiniteResult naming the quantity and
the wavelength, `oceanmc run` says it in one line with exit status 3 and leaves no results file
(not even one its checkpoints wrote before the fault showed). The fault is injected here into
the tallies, not left to a kernel bug."""
import math

import numpy as np
import pytest
import yaml

import oceanmc
from oceanmc.cli import main
from oceanmc.kernel.models import FLUX_EOD
from oceanmc.run import derivation, simulation
from oceanmc.run.simulation import NonFiniteResult

SPECTRAL = {"photons": 400, "batches": 4, "seed": 2, "wavelengths_nm": [400, 500, 600],
            "water": {"layers": [{"thickness_m": 2.0, "a": [0.1, 0.2, 0.3], "b": 0.3}]},
            "bottom": {"model": "lambertian", "reflectance": 0.2},
            "tallies": {"depths_m": [0, 1]}}


def poison(monkeypatch, value=math.nan, wavelength=None, when=lambda batches: True):
    """from_tallies with `value` in one batch of the flux tallies (Eod at the first depth, so
    Eod and Eo = Eod + Eou) of
    the given wavelength (index; None: every one), when `when(whole batches)` holds."""
    real = derivation.from_tallies
    seen = {"k": -1}

    def from_tallies(raw, *args, **kwargs):
        seen["k"] += 1
        raw = dict(raw, flux=raw["flux"].copy())
        if raw["flux"].shape[0] and when(raw["flux"].shape[0]) and \
                wavelength in (None, seen["k"] % len(SPECTRAL["wavelengths_nm"])):
            raw["flux"][0, 0, FLUX_EOD] = value
        return real(raw, *args, **kwargs)
    monkeypatch.setattr(derivation, "from_tallies", from_tallies)


def test_a_nan_in_one_wavelengths_tallies_is_refused_naming_quantity_and_wavelength(
        monkeypatch):
    poison(monkeypatch, wavelength=1)
    with pytest.raises(NonFiniteResult) as info:
        oceanmc.simulate(SPECTRAL, threads=1)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith("the run produced non-finite values (NaN) in Eod at 500 nm, and "
                              "in 1 other quantity: a fault of oceanmc"), message  # and Eo
    assert "please report it" in message


def test_an_inf_in_a_monochromatic_run_is_refused(monkeypatch, small_scene):
    poison(monkeypatch, value=math.inf)
    small_scene.update(photons=400, batches=4)
    with pytest.raises(NonFiniteResult, match=r"non-finite values \(inf\) in Eod, and in 1 "
                                              r"other quantity: a fault of oceanmc"):
        oceanmc.simulate(small_scene, threads=1)


def test_finite_runs_pass_the_check():
    result = oceanmc.simulate(SPECTRAL, threads=1)
    assert all(np.isfinite(q.batches).all() for q in result.quantities.values())


@pytest.fixture
def scene_file(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(SPECTRAL))
    return tmp_path / "s.yaml"


def test_oceanmc_run_exits_3_in_one_line_with_no_file(scene_file, monkeypatch, capsys):
    poison(monkeypatch, wavelength=2)
    code = main(["run", "s.yaml", "-o", "out.h5", "-q"])
    out, err = capsys.readouterr()
    assert code == 3, err
    assert err.startswith("oceanmc: error: s.yaml: the run produced non-finite values (NaN) in "
                          "Eod at 600 nm") and err.count("\n") == 1, err
    assert out == "" and not (scene_file.parent / "out.h5").exists()
    assert [p.name for p in scene_file.parent.iterdir()] == ["s.yaml"]   # no temporary left


def test_a_checkpoint_written_before_the_fault_showed_is_removed(scene_file, monkeypatch,
                                                                  capsys):
    """The fault only in the last batches: the checkpoints before it wrote a (finite, partial)
    file, which is removed when the end is refused."""
    from oceanmc.run import resume
    saves = []
    real_save = resume.save_result     # (how a run's file is written: run/resume.RunFile)
    monkeypatch.setattr(resume, "save_result", lambda result, path, overwrite=True: (
        saves.append(result.attrs["batches"]), real_save(result, path, overwrite))[1])
    monkeypatch.setattr(simulation, "POLL_SECONDS", 0.01)
    batches = 8
    (scene_file).write_text(yaml.safe_dump(dict(SPECTRAL, photons=80_000, batches=batches)))
    poison(monkeypatch, when=lambda whole: whole == batches)
    code = main(["run", "s.yaml", "-o", "out.h5", "-q", "--checkpoint-every", "0",
                 "--threads", "1"])
    err = capsys.readouterr().err
    assert code == 3 and "non-finite values (NaN) in Eod at 400, 500, 600 nm" in err, err
    assert saves and max(saves) < batches, saves   # checkpoints were written, then refused
    assert not (scene_file.parent / "out.h5").exists()
