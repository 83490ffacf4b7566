"""Depth importance weight windows (estimator.depth_splitting; scene/weight_window.py,
kernel/weight_window.py): unbiased against the plain walk, on deep water, in a spectral walk and
over a bottom; the budget still closes; off or idle, the walk is the plain one bit for bit; the
auto rule and the switch's errors.

Each comparison runs the scene with windows and without (independent seeds) and bounds every
tallied Ed, Eou, Eu and Lu at every depth by |z| under the Bonferroni-t bound of all compared
values (stats_helpers), with a cap on the relative error so that a test cannot pass by being
underpowered; and it checks that the windows did their work: the deepest level's relative
standard errors smaller than the plain run's."""
import copy

import numpy as np
import pytest
import yaml

import oceanmc
from oceanmc import optics
from oceanmc.config import ConfigError
from oceanmc.scene import weight_window

from stats_helpers import assert_same, dof_of

THREADS = 2
QUANTITIES = ("Ed", "Eou", "Eu", "Lu")
# a stratified column: clearer water over a turbid layer over clear deep water; the deepest
# tally at 52 m lies 4.3 attenuation depths down (scene/weight_window.py)
DEEP = {
    "name": "stratified deep column",
    "photons": 100_000, "batches": 20, "seed": 1,
    "illumination": {"sun_zenith_deg": 30.0, "diffuse_fraction": 0.2},
    "surface": {"model": "flat"},
    "water": {"layers": [
        {"thickness_m": 20.0, "a": 0.04, "b": 0.2,
         "phase": {"model": "henyey_greenstein", "g": 0.8}},
        {"thickness_m": 10.0, "a": 0.08, "b": 0.6,
         "phase": {"model": "henyey_greenstein", "g": 0.85}},
        {"thickness_m": float("inf"), "a": 0.04, "b": 0.2,
         "phase": {"model": "henyey_greenstein", "g": 0.8}}]},
    "bottom": {"model": "none"},
    "tallies": {"depths_m": [0.0, 8.0, 16.0, 24.0, 32.0, 40.0, 52.0], "radiance": False},
}


def deep(mode, seed, **changes):
    config = copy.deepcopy(DEEP)
    config["seed"] = seed
    config.update(changes)
    # the windows alone: without the upward bias that auto adds to them (test_auto_upward_bias)
    config["estimator"] = {"upward_fraction": None, **config.get("estimator", {}),
                           "depth_splitting": mode}
    return config


def compare(windowed, plain, rel_max, gain_at_depth=None):
    """Every quantity at every depth (and wavelength) agrees; where gain_at_depth is given, the
    windowed run's relative standard error at the deepest level is smaller by that factor for
    each quantity."""
    n_compared = sum(np.size(plain[q]) for q in QUANTITIES)
    for q in QUANTITIES:
        assert_same(windowed[q], windowed.stderr(q), plain[q], plain.stderr(q),
                    dof=dof_of(plain), n_compared=n_compared, rel_max=rel_max,
                    what=f"{q}: depth windows vs plain")
        if gain_at_depth is not None:
            rel_on = windowed.stderr(q)[..., -1] / np.abs(windowed[q][..., -1])
            rel_off = plain.stderr(q)[..., -1] / np.abs(plain[q][..., -1])
            assert np.all(rel_on * gain_at_depth < rel_off), (q, rel_on, rel_off)


def assert_budget_closes(result):
    """The implicit walk's budget adds up to 1 within its standard error (its roulette at
    collisions and at the surface books nothing), at every wavelength."""
    total, se = result["budget/total"], result.stderr("budget/total")
    assert np.all(np.abs(total - 1.0) < 4.0 * se + 1e-9), (total, se)


def test_windows_are_unbiased_in_deep_water():
    """The stratified column to 4.3 attenuation depths: the same expectations with windows;
    the windows split (more scattering events per photon) and the deepest level's errors fall;
    the implicit budget closes within its standard error, as without."""
    plain = oceanmc.simulate(deep("off", seed=1), threads=THREADS)
    windowed = oceanmc.simulate(deep("auto", seed=2), threads=THREADS)
    assert windowed.attrs["depth_splitting"].startswith("on (auto")
    assert plain.attrs["depth_splitting"] == "off"
    compare(windowed, plain, rel_max=0.25, gain_at_depth=1.5)
    per_photon = [r.attrs["scattering_events"] / r.attrs["photons"] for r in (plain, windowed)]
    assert per_photon[1] > 1.5 * per_photon[0]
    assert_budget_closes(windowed)


def test_windows_are_unbiased_in_a_spectral_walk():
    """Three wavelengths in one history (the window is the least attenuated one's, the packet
    weighed by its heaviest wavelength): every wavelength agrees with the plain spectral walk,
    and its budget closes at every wavelength."""
    spectral = {"wavelengths_nm": [440.0, 490.0, 550.0], "photons": 100_000}
    layers = copy.deepcopy(DEEP["water"]["layers"])
    for layer, scale in zip(layers, (1.0, 1.5, 1.0)):
        layer["a"] = [scale * 0.05, scale * 0.04, scale * 0.07]
    spectral["water"] = {"layers": layers}
    plain = oceanmc.simulate(deep("off", seed=3, **spectral), threads=THREADS)
    windowed = oceanmc.simulate(deep("on", seed=4, **spectral), threads=THREADS)
    compare(windowed, plain, rel_max=0.3, gain_at_depth=1.2)
    assert_budget_closes(windowed)


def test_windows_are_unbiased_over_a_bottom():
    """A 40 m column over a Lambertian bottom (reflected light goes up through the windows):
    the same expectations, budget terms included (at 3.4 attenuation depths the windows gain
    little: this test is about the bottom's light going up through them)."""
    bottom = {"bottom": {"model": "lambertian", "reflectance": 0.3},
              "tallies": {"depths_m": [0.0, 10.0, 20.0, 30.0, 40.0], "radiance": False}}
    layers = copy.deepcopy(DEEP["water"]["layers"])
    layers[-1]["thickness_m"] = 10.0
    bottom["water"] = {"layers": layers}
    plain = oceanmc.simulate(deep("off", seed=5, **bottom), threads=THREADS)
    windowed = oceanmc.simulate(deep("on", seed=6, **bottom), threads=THREADS)
    compare(windowed, plain, rel_max=0.25)
    assert_budget_closes(windowed)
    for name in ("budget/absorbed_bottom", "budget/water_leaving"):
        assert_same(windowed[name], windowed.stderr(name), plain[name], plain.stderr(name),
                    dof=dof_of(plain), n_compared=2, rel_max=0.1, what=name)


def test_analog_walk_with_windows_closes_its_budget_exactly():
    """Splitting conserves weight and the analog walk plays no roulette: the budget adds up
    to 1 to rounding with windows on."""
    result = oceanmc.simulate(deep("on", seed=7, photons=4000, batches=4,
                                   estimator={"mode": "analog", "upward_fraction": None}),
                              threads=THREADS)
    assert result.attrs["depth_splitting"].startswith("on")
    assert result["budget/total"] == pytest.approx(1.0, abs=1e-9)


def test_off_and_idle_windows_change_nothing():
    """A scene that tallies only near the surface: auto leaves the windows off, and the run is
    the plain one bit for bit; so is a scene whose windows are on but flat (tallies only at
    0 m: nothing to split for)."""
    shallow = deep("auto", seed=8, photons=4000, batches=4,
                   tallies={"depths_m": [0.0, 5.0], "radiance": False})
    auto = oceanmc.simulate(shallow, threads=1)
    off = oceanmc.simulate(dict(shallow, estimator={"depth_splitting": "off"}), threads=1)
    assert auto.attrs["depth_splitting"].startswith("off (auto")
    surface_only = dict(shallow, tallies={"depths_m": [0.0], "radiance": False})
    idle = oceanmc.simulate(dict(surface_only, estimator={"depth_splitting": "on"}), threads=1)
    plain = oceanmc.simulate(dict(surface_only, estimator={"depth_splitting": "off"}),
                             threads=1)
    for a, b in ((auto, off), (idle, plain)):
        for name, q in b.quantities.items():
            assert np.array_equal(a.quantities[name].batches, q.batches), name


def test_auto_rule():
    """auto: on for a deep implicit scene; off for the analog walk, in water that does not
    scatter (the implicit walk is exact there) and with inelastic light (where `on` is
    refused)."""
    def decided(**changes):
        config = deep("auto", seed=1, photons=64, batches=2, **changes)
        return oceanmc.simulate(config, threads=1).attrs["depth_splitting"]
    assert decided().startswith("on (auto: the deepest tally depth 52 m at 4.")
    assert decided(estimator={"mode": "analog", "upward_fraction": None,
                              "depth_splitting": "auto"}) == "off (auto: the analog walk)"
    clear = deep("auto", seed=1)
    for layer in clear["water"]["layers"]:
        layer.update(b=0.0, phase={"model": "isotropic"})
    assert decided(water=clear["water"]) == "off (auto: no layer scatters)"
    raman = deep("auto", seed=1, wavelengths_nm=[490.0, 530.0])
    raman["water"]["inelastic"] = {"raman": {}}
    config = oceanmc.load_config(raman)
    assert weight_window.choose(config, optics.column_iops(config)).why == \
        "off (auto: inelastic light)"
    raman["estimator"]["depth_splitting"] = "on"
    with pytest.raises(ConfigError, match="depth_splitting = 'on' with water.inelastic"):
        oceanmc.load_config(raman)


def test_auto_upward_bias_goes_with_the_windows_in_one_wavelength_scenes():
    """estimator.upward_fraction auto in a one-wavelength implicit walk: 0.1 where the depth
    windows are on, off where they are not (scene/weight_window.upward_fraction), as the
    result's attribute says; the stored config keeps auto (so that rerunning it, or a sweep's
    point, is the same scene); a spectral walk has 0.1 either way, an explicit value is kept."""
    def ran(mode, **estimator):
        config = deep(mode, seed=1, photons=64, batches=2)
        config["estimator"] = dict(depth_splitting=mode, **estimator)
        result = oceanmc.simulate(config, threads=1)
        stored = yaml.safe_load(result.config_yaml)["estimator"]["upward_fraction"]
        return result.attrs["depth_splitting"].split(" ")[0], result.attrs["upward_fraction"], \
            stored
    assert ran("auto") == ("on", 0.1, "auto")
    assert ran("off") == ("off", 0.0, "auto")
    assert ran("auto", upward_fraction=None) == ("on", 0.0, None)
    assert ran("off", upward_fraction=0.2) == ("off", 0.2, 0.2)
    spectral = oceanmc.load_config(dict(deep("off", seed=1, wavelengths_nm=[490.0, 530.0]),
                                        estimator={"depth_splitting": "off"}))
    assert spectral.estimator.upward_fraction == 0.1


@pytest.mark.parametrize("value, expected", [("off", "off"), (False, "off"), ("on", "on"),
                                             (True, "on"), ("auto", "auto")])
def test_switch_values(value, expected):
    """The switch, as YAML's bare on / off (booleans) too."""
    config = oceanmc.load_config(deep(value, seed=1))
    assert config.estimator.depth_splitting == expected


@pytest.mark.parametrize("value", ["yes please", 2, None])
def test_bad_switch_is_one_clear_error(value):
    with pytest.raises(ConfigError) as caught:
        oceanmc.load_config(deep(value, seed=1))
    message = str(caught.value)
    assert "estimator.depth_splitting" in message and "'auto'" in message \
        and "'off'" in message and "\n" not in message, message


def test_windows_in_turbid_weakly_absorbing_water_do_not_flood_the_walk():
    """Where backscattering dominates absorption the light falls far slower than Gordon's
    (a + b_b) / 0.75 (b = 1000 1/m, a = 0.1 1/m over 1 m: K 31 1/m by Gordon, the measured
    ln(Ed(0)/Ed(1 m)) 7.8): the window takes diffusion theory's sqrt(3 a (a + b_b)) there
    (scene/weight_window.py), so that the copies stay few. Before, every packet was split
    into e^15 copies and 200 photons ran for more than 20 minutes; now the walk takes 1.5
    times the plain walk's events per photon (measured: 6,435 against 4,162)."""
    def run(mode):
        scene = {"photons": 400, "batches": 4, "seed": 5,
                 "illumination": {"sun_zenith_deg": 30.0, "diffuse_fraction": 0.2},
                 "surface": {"model": "flat"},
                 "water": {"layers": [{"thickness_m": 1.0, "a": 0.1, "b": 1000.0,
                                       "phase": {"model": "henyey_greenstein", "g": 0.9}}]},
                 "bottom": {"model": "lambertian", "reflectance": 0.3},
                 "tallies": {"depths_m": [0.0, 1.0], "radiance": False},
                 "estimator": {"depth_splitting": mode}}
        return oceanmc.simulate(scene, threads=1).attrs
    windows, plain = run("on"), run("off")
    assert windows["depth_splitting"].startswith("on")
    assert windows["scattering_events"] < 3 * plain["scattering_events"], \
        (windows["scattering_events"], plain["scattering_events"])


def test_the_same_seed_gives_the_same_bits_under_windows(monkeypatch):
    """Two runs of one windowed scene in one process, with the batches cut into kernel calls at
    other photons (and built anew): bit-identical (the phase-table pool once depended on
    allocation addresses: tests/test_phase_table_pool.py)."""
    from oceanmc.run import simulation
    config = deep("on", seed=4, photons=4_000, batches=8)
    first = oceanmc.simulate(config, threads=2)
    monkeypatch.setattr(simulation, "FIRST_BUDGET", 300)
    monkeypatch.setattr(simulation, "CALL_SECONDS", 0.002)
    again = oceanmc.simulate(config, threads=1)
    for name, q in first.quantities.items():
        assert np.array_equal(q.batches, again.quantities[name].batches), name
