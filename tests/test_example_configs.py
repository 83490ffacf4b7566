"""Every shipped example runs: each scene of configs/*.yaml (at a small photon count; their own
counts are sized to run in seconds), and each sweep of configs/sweeps/*.yaml on a tiny grid of
its points (a cluster of threads in this process, as tests/test_sweep.py does). Sweep files
live in configs/sweeps/, out of reach of the `configs/*.yaml` globs that take every file there
for a scene (`oceanmc run configs/*.yaml`, benchmarks/regression.py record)."""
import copy
from pathlib import Path

import numpy as np
import pytest
import yaml

import oceanmc
from conftest import REPO
from oceanmc.run.results import format_summary
from oceanmc.run.simulation import prepare
from oceanmc.scene import predicted_variant
from oceanmc.sweeps import load_sweep
from oceanmc.sweeps.dataset import variable_name
from oceanmc.sweeps.points import build_points

SCENES = sorted((REPO / "configs").glob("*.yaml"))
SWEEPS = sorted((REPO / "configs" / "sweeps").glob("*.yaml"))
PHOTONS_PER_BATCH = 100


def small(path: Path):
    """The scene of `path` at PHOTONS_PER_BATCH photons a batch (its files resolved)."""
    config = oceanmc.load_config(path)
    return oceanmc.load_config({**config.model_dump(),
                                "photons": PHOTONS_PER_BATCH * config.batches})


def test_the_examples_are_there():
    names = {path.stem for path in SCENES}
    assert {"case1_spectral", "windy_case1", "shallow_sand_spectral",
            "deep_chlorophyll_maximum"} <= names
    assert "shallow_lut" in {path.stem for path in SWEEPS}


@pytest.mark.parametrize("path", SCENES, ids=lambda p: p.stem)
def test_every_shipped_scene_runs(path):
    """Each scene runs, its budget closes, and `oceanmc run`'s prediction of its variant of the
    photon loop from the config (compiled before the scene is packed) is the packed scene's
    own: a wrong one would compile a second variant (kernel/variants.py)."""
    config = small(path)
    run = prepare(config)
    assert predicted_variant(config) == run.scene.variant
    result = oceanmc.simulate(run, threads=2)
    total = np.atleast_1d(result["budget/total"])
    assert np.all(np.abs(total - 1.0) < 0.05), total
    for name in ("air/Ed", "air/Eu", "Ed", "Eu"):
        assert np.all(np.isfinite(result[name])), name
    if "air/Rrs_nadir" in result:
        assert np.all(np.isfinite(result["air/Rrs_nadir"]))
        assert np.all(result["air/Rrs_nadir"] >= 0.0)


@pytest.mark.parametrize("path", SCENES, ids=lambda p: p.stem)
def test_every_shipped_scene_is_commented_and_named(path):
    text = path.read_text()
    assert text.startswith("#"), "a comment saying what the scene is comes first"
    assert oceanmc.load_config(path).name != "oceanmc scene"


def test_the_spectral_examples_show_what_their_comments_promise():
    case1 = oceanmc.load_config(REPO / "configs" / "case1_spectral.yaml")
    assert len(case1.wavelengths) == 31 and case1.wavelengths[0] == 400.0 \
        and case1.wavelengths[-1] == 700.0
    models = {c.model: c for c in case1.water.layers[0].components}
    assert set(models) == {"pure_water", "chlorophyll", "cdom"}
    chl, a440 = models["chlorophyll"].chl_mg_m3, models["cdom"].a440
    # the CDOM the comment gives, a_CDOM(440) ~ 0.0316 Chl^0.63 (a fit without a traced
    # source; the comment also gives the published relation, 0.0104 Chl^0.635), within 10%
    assert a440 == pytest.approx(0.0316 * chl ** 0.63, rel=0.1)
    light = case1.illumination
    assert light.spectrum.model == "spectrl2" and light.sun_position is not None
    assert light.sun_position.time.tzinfo is not None
    windy = oceanmc.load_config(REPO / "configs" / "windy_case1.yaml")
    assert windy.surface.model == "cox_munk" and windy.surface.wind_speed_m_s > 0
    assert [180.0, 0.0] in [list(d) for d in windy.tallies.local_directions_deg]
    shallow = oceanmc.load_config(REPO / "configs" / "shallow_sand_spectral.yaml")
    assert shallow.bottom.model == "lambertian" and shallow.water.layers[0].thickness_m <= 10
    dcm = oceanmc.load_config(REPO / "configs" / "deep_chlorophyll_maximum.yaml")
    profile = [c for c in dcm.water.layers[0].components if c.model == "chlorophyll"][0]
    assert profile.chl_mg_m3.profile == "gaussian"


def test_the_windy_example_reports_rrs_in_its_exact_directions():
    result = oceanmc.simulate(small(REPO / "configs" / "windy_case1.yaml"), threads=2)
    assert result["air/Rrs_local"].shape == (16, 2)
    text = format_summary(result)
    assert "Rrs 180,0" in text and "Rrs 140,135" in text
    assert "crossing estimate" in text and "spectrum spectrl2" in text


def tiny(sweep_path: Path, photons_per_batch: int = 20) -> dict:
    """The sweep of `sweep_path` on the fewest points: the first two values of a zip group's
    keys, the first value of every other axis; its base an absolute path; photons few."""
    spec = yaml.safe_load(sweep_path.read_text())
    spec["base"] = str((sweep_path.parent / spec["base"]).resolve())
    base = oceanmc.load_config(spec["base"])
    spec.setdefault("set", {})["photons"] = photons_per_batch * base.batches

    def first(values, n):
        if isinstance(values, dict) and "key" in values:
            return dict(values, values=first(values["values"], n))
        return values[:n] if isinstance(values, list) else values   # {linspace: ...} kept
    axes = {}
    for name, values in spec["axes"].items():
        if name == "zip":
            groups = values if isinstance(values, list) else [values]
            axes["zip"] = [{k: first(v, 2) for k, v in group.items()} for group in groups]
        else:
            axes[name] = first(values, 1)
    spec["axes"] = axes
    return spec


@pytest.mark.parametrize("path", SWEEPS, ids=lambda p: p.stem)
def test_every_shipped_sweep_loads_with_all_its_points_valid(path):
    spec = load_sweep(path)
    points = build_points(spec)       # every point's scene built and checked, none run
    assert len(points) == int(np.prod(spec.shape)) > 1


def test_the_sweep_example_runs_with_named_dimensions_and_no_empty_direction(tmp_path,
                                                                            thread_client):
    path = REPO / "configs" / "sweeps" / "shallow_lut.yaml"
    spec = tiny(path)
    said = []
    ds = oceanmc.sweep(spec, tmp_path / "lut.nc", client=thread_client, threads=1)
    # a rerun finds both points done: a SPECTRL2 scene's stored text (with its note on
    # the diffuse share) is the text the sweep expects of the point
    oceanmc.sweep(spec, tmp_path / "lut.nc", client=thread_client, threads=1, log=said.append)
    assert ds.attrs["points_done"] == 2 and ds.attrs["points_failed"] == 0
    assert "2 finished earlier, 0 to run" in " ".join(said), said
    # the short names are the dimensions; a440 is a coordinate along chl (a zip group)
    assert ds["air_Rrs_nadir"].dims[:3] == ("chl", "bottom_depth", "bottom.reflectance")
    assert ds["a440"].dims == ("chl",)
    assert ds["chl"].attrs["key_path"] == "water.layers[0].components[1].chl_mg_m3"
    assert ds["bottom_depth"].attrs["key_path"] == "water.layers[0].thickness_m"
    # the scene has no local_directions_deg: no `direction` dimension or coordinates
    assert "direction" not in ds.dims
    assert not {"direction", "direction_theta", "direction_phi"} & set(ds.variables)
    # each point is the run of its scene
    for point in build_points(load_sweep(spec)):
        single = oceanmc.simulate(point.config, threads=1)
        for name in ("air/Rrs_nadir", "air/Ed", "budget/total"):
            assert np.array_equal(ds[variable_name(name)].values[point.index],
                                  single[name]), (point.label, name)
    # read back from the file, the same names
    import xarray as xr
    with xr.open_dataset(tmp_path / "lut.nc", engine="h5netcdf") as back:
        assert float(back["air_Rrs_nadir"].sel(chl=0.3, bottom_depth=2, wavelength=555).item()) \
            == float(ds["air_Rrs_nadir"].sel(chl=0.3, bottom_depth=2, wavelength=555).item())


def test_a_sweep_with_local_directions_keeps_its_direction_dimension(tmp_path, thread_client):
    spec = tiny(REPO / "configs" / "sweeps" / "shallow_lut.yaml")
    spec["set"]["tallies.local_directions_deg"] = [[180, 0]]
    spec["axes"] = {"chl": spec["axes"]["zip"][0]["chl"]}
    ds = oceanmc.sweep(copy.deepcopy(spec), None, client=thread_client, threads=1)
    assert ds["air_Rrs_local"].dims == ("chl", "wavelength", "direction")
    assert ds["direction_theta"].values.tolist() == [180.0]
