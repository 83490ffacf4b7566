"""The HDF5 results file: contract names, units, dimension scales, round trip, atomic writes."""
import h5py
import numpy as np
import pytest
import xarray as xr

import oceanmc
from oceanmc.run.hdf5 import save_result
from oceanmc.cli import main
from oceanmc.run.results import format_summary


@pytest.fixture(scope="module")
def result():
    from conftest import SMALL_SCENE
    return oceanmc.simulate(SMALL_SCENE)


@pytest.fixture(scope="module")
def saved(result, tmp_path_factory):
    return result.save(tmp_path_factory.mktemp("r") / "run.h5")


WATER = ["Ed", "Eu", "Eod", "Eou", "Eo", "Lu", "radiance"]
AIR = ["Ed", "Eu", "radiance", "Lw", "Lu", "Lw_nadir", "Rrs_nadir"]


def test_a_name_not_held_says_the_nearest_and_the_repr_is_one_line(result):
    with pytest.raises(KeyError, match="'Rrs_nadir'.*did you mean air/Rrs_nadir"):
        result["Rrs_nadir"]
    with pytest.raises(KeyError, match="'Edd'.*did you mean Ed"):
        result.stderr("Edd")
    with pytest.raises(KeyError, match="'nothing like it' in this result\"$"):   # (no hint)
        result["nothing like it"]
    # (the dataclass's repr printed every batch: 67,000 characters for a one-wavelength run)
    text = repr(result)
    assert "\n" not in text and len(text) < 300 and "quantities" in text, text


def test_contract_names_with_stderr_units_and_descriptions(saved):
    with h5py.File(saved) as f:
        for name in WATER + [f"air/{n}" for n in AIR]:
            for full in (name, name + "_stderr"):
                assert full in f, full
                assert f[full].attrs["units"] and f[full].attrs["description"], full
        for coord in ("depth", "theta", "phi", "theta_edges", "phi_edges"):
            assert coord in f
        assert f["radiance"].shape == (3, 20, 24)
        terms = [k for k in f["budget"] if not k.endswith("_stderr")]
        assert {"surface_reflection", "water_leaving", "absorbed_layer_1", "absorbed_bottom",
                "lost_below", "total"} <= set(terms)
        for key in ("config_yaml", "oceanmc_version", "numba_version", "seed", "photons",
                    "batches", "wall_time_s", "photons_per_s"):
            assert key in f.attrs, key


def test_budget_terms_add_up_to_total(saved):
    with h5py.File(saved) as f:
        parts = sum(f["budget"][k][()] for k in f["budget"]
                    if not k.endswith("_stderr") and k not in ("total", "batch"))
        assert parts == pytest.approx(f["budget/total"][()], abs=1e-12)


def test_xarray_sees_named_dimensions(saved):
    ds = xr.open_dataset(saved, engine="h5netcdf")
    assert ds["radiance"].dims == ("depth", "theta", "phi")
    assert list(ds["depth"].values) == [0.0, 1.0, 2.0]
    assert ds["Ed"].attrs["units"].startswith("W m-2")
    air = xr.open_dataset(saved, engine="h5netcdf", group="air")
    assert air["Lw"].dims == ("theta", "phi")
    assert air["theta"].values[-1] == pytest.approx(177.5)
    ds.close()
    air.close()


def test_direction_angles_are_coordinates_in_every_group(small_scene, tmp_path):
    small_scene["tallies"]["local_directions_deg"] = [[180, 0], [150, 30]]
    saved = oceanmc.simulate(small_scene).save(tmp_path / "local.h5")
    for group, variable in ((None, "local_radiance"), ("air", "Lw_local"),
                            ("batches/air", "Rrs_local")):
        with xr.open_dataset(saved, engine="h5netcdf", group=group) as ds:
            for angle, values in (("direction_theta", [180, 150]), ("direction_phi", [0, 30])):
                assert angle in ds.coords and angle not in ds.data_vars, (group, angle)
                assert ds[variable].coords[angle].values.tolist() == values
                assert ds[angle].dims == ("direction",)
    with xr.open_dataset(saved, engine="h5netcdf", group="air") as air:
        assert air["Lw_local"].sel(direction=1).direction_theta == 150.0


def test_direction_angles_are_coordinates_without_local_directions(saved):
    with xr.open_dataset(saved, engine="h5netcdf") as ds:
        assert {"direction_theta", "direction_phi"} <= set(ds.coords)
        assert not {"direction_theta", "direction_phi"} & set(ds.data_vars)


def test_show_lists_the_summary_in_the_order_run_does(small_scene, tmp_path, capsys):
    small_scene["water"]["layers"] *= 11   # absorbed_layer_10 sorts before _2 by name
    small_scene["photons"] = 2000
    result = oceanmc.simulate(small_scene)
    assert main(["show", str(result.save(tmp_path / "r.h5"))]) == 0
    summary = capsys.readouterr().out.split("\n  derived (")[0]   # show adds the derived ones
    shown = [line.split()[:2] for line in summary.splitlines()[2:]]
    ran = [line.split()[:2] for line in format_summary(result).splitlines()[2:]]
    assert shown == ran
    budget = [words[1] for words in ran if words[0] == "budget"]
    assert budget[:3] == ["surface_reflection", "water_leaving", "absorbed_layer_1"]
    assert budget[13:] == ["absorbed_bottom", "lost_below", "truncated", "total"]


def test_load_result_gives_back_the_same_result(result, saved):
    back = oceanmc.load_result(saved)
    assert set(back.quantities) == set(result.quantities)
    for name, q in result.quantities.items():
        assert back.quantities[name].dims == q.dims
        assert np.array_equal(back.quantities[name].batches, q.batches), name
        assert np.array_equal(back.stderr(name), result.stderr(name)), name
    for name, values in result.coords.items():
        assert np.array_equal(back.coords[name], values)
    assert back.config_yaml == result.config_yaml
    assert oceanmc.load_config(__import__("yaml").safe_load(back.config_yaml)).seed == 5


def test_stored_means_match_batches(saved):
    with h5py.File(saved) as f:
        batches = f["batches/air/Lw"][()]
        assert np.allclose(f["air/Lw"][()], batches.mean(axis=0))
        assert np.allclose(f["air/Lw_stderr"][()],
                           batches.std(axis=0, ddof=1) / np.sqrt(batches.shape[0]))


def test_failed_write_leaves_no_file(result, tmp_path, monkeypatch):
    target = tmp_path / "out.h5"

    def explode(*args, **kwargs):
        raise RuntimeError("disk full")
    monkeypatch.setattr("oceanmc.run.format._write", explode)
    with pytest.raises(RuntimeError):
        save_result(result, target)
    assert list(tmp_path.iterdir()) == []
