"""Tests of inelastic light (water.inelastic: Raman scattering by water, chlorophyll
fluorescence; DESIGN.md 7.4): the traced grid (config/inelastic.py transport_grid), the optics
(optics/inelastic: Walrafen's redistribution, the packed transfer T and its photon
conservation, the fluorescence coefficient, the Ed0 ratio), a short kernel run (every part's
budget closes, the parts add up to the whole batch by batch, the emissions' expected value),
its elastic part against the same scene without inelastic light, the HDF5 round trip of the
parts, and the refusal of bad values.

Statistics: seeds are fixed; a z-score is (estimate - reference) / standard error over the
32 batches, and each bound is stated where it is used (Z_MAX = 5: with 37 wavelengths, most of
them strongly correlated, a correct code exceeds it with probability below 1e-4). Exact
identities (sums of parts, the same random draws) are checked to rtol 1e-9.

Run time: about 16 s on 2 cores with the kernel cached (the two kernel runs of 30k photons take a
few seconds, the transfer matrices a few more).

Measured (seed 20240611): budget closure max |z| elastic 0.77, raman 1.12, fluorescence 0.50;
emission = take x T max |z| raman 0.92, fluorescence 0.82; Raman share of Rrs(550) 0.116."""
from __future__ import annotations

import copy
import math
from types import SimpleNamespace

import numpy as np
import pytest

import oceanmc
from oceanmc.config import ConfigError
from oceanmc.config.inelastic import (RAMAN_SHIFT_RANGE, ChlorophyllFluorescence, Inelastic,
                                      Raman, transport_grid)
from oceanmc.optics import column_iops
from oceanmc.optics.illumination import illumination_spectrum
from oceanmc.optics.inelastic import channels, factors, transfer
from oceanmc.optics.inelastic import chlorophyll_fluorescence as fluorescence
from oceanmc.optics.inelastic import raman
from oceanmc.run.simulation import prepare
from oceanmc.validation.cases.inelastic import LEE_2013_RTOL, clear_water
from oceanmc.validation.raman_reference import lee_2013_raman_share

from inelastic_helpers import (assert_budgets_close, assert_estimates_agree, hat_integral,
                               trapezoid_weights, z_of)

Z_MAX = 5.0
PHOTONS = 30_000
BATCHES = 32
SEED = 20240611
BOTH = {"raman": {}, "chlorophyll_fluorescence": {}}
PARTS = ("elastic", "raman", "chlorophyll_fluorescence")
REQUESTED = np.arange(400.0, 701.0, 10.0)
ADDED = [340.0, 350.0, 360.0, 370.0, 380.0, 390.0]


def scene(inelastic=BOTH, seed=SEED, extra_absorption=None, emitted_light=None) -> dict:
    """Chl 0.05 Case-1 water, deep, sun at 30 deg, flat sea, 400-700 nm every 10 nm
    (validation/cases/inelastic.py clear_water), 30k photons in 32 batches; emitted_light:
    estimator.emitted_light (default: carried)."""
    inelastic = copy.deepcopy(inelastic)
    config = clear_water("inelastic test", PHOTONS, inelastic, seed, extra_absorption)
    config["batches"] = BATCHES
    if emitted_light is not None:
        config["estimator"] = {"emitted_light": emitted_light}
    return config


# --- 1. the traced grid ---------------------------------------------------------------------------

def test_regular_grid_with_raman_adds_340_to_390():
    traced = transport_grid(REQUESTED, Inelastic(raman=Raman()))
    np.testing.assert_allclose(traced, np.arange(340.0, 701.0, 10.0), rtol=0, atol=1e-9)
    # the lowest excitation of 400 nm (Walrafen's largest shift) lies within the grid's start
    lowest = 1e7 / (1e7 / 400.0 + RAMAN_SHIFT_RANGE[1])
    assert traced[0] <= lowest < traced[1]
    config = oceanmc.load_config(scene({"raman": {}}))
    np.testing.assert_allclose(config.wavelengths, traced, rtol=0, atol=1e-9)
    assert config.added_wavelengths == ADDED
    # without inelastic light the grid is the requested one
    plain = oceanmc.load_config(scene(None))
    np.testing.assert_allclose(plain.wavelengths, REQUESTED)
    assert plain.added_wavelengths == []


def test_a_stored_config_loads_to_the_same_traced_grid():
    """The config keeps the requested wavelengths; the traced grid follows from them, so a
    config dumped or written as YAML (a results file's, a checkpoint's) and loaded again
    traces the same grid, not one extended again for the added wavelengths' own excitation
    (it once was: 290 nm, outside SPECTRL2)."""
    import yaml
    from oceanmc.config import config_to_yaml
    config = oceanmc.load_config(scene())
    assert config.wavelengths_nm.start == 400.0
    for again in (oceanmc.load_config(config.model_dump()),
                  oceanmc.load_config(yaml.safe_load(config_to_yaml(config))),
                  config.model_copy(update={"photons": 64})):
        np.testing.assert_array_equal(again.wavelengths, config.wavelengths)
        assert again.added_wavelengths == ADDED


def test_the_analog_walk_closes_every_part_exactly():
    """The analog walk (absorption drawn; emissions still expected values) closes each part's
    budget to rounding: elastic 1, inelastic 0."""
    config = scene({"raman": {"b488_per_m": 2.6e-3}, "chlorophyll_fluorescence": {}})
    config["photons"] = 8000
    config["estimator"] = {"mode": "analog", "upward_fraction": None}
    result = oceanmc.simulate(config, threads=2)
    for part, source in zip(PARTS, (1.0, 0.0, 0.0)):
        np.testing.assert_allclose(result[f"{part}/budget/total"], source, rtol=0, atol=1e-9)
    assert result["raman/budget/shifted_in"].max() > 0.0


def test_raman_shift_range_holds_walrafen_lines():
    # outside RAMAN_SHIFT_RANGE (where the grid stops extending) lies less than 1e-6 of
    # Walrafen's density (the photons a grid that stops there loses), and its value there is
    # below 1e-5 of the peak (measured: 2.0e-6 at 2800 1/cm, the 3250 line's 5.05 sigma)
    shifts = np.arange(1500.0, 6000.0, 0.5)
    g = raman.shift_density(shifts)
    outside = (shifts < RAMAN_SHIFT_RANGE[0]) | (shifts > RAMAN_SHIFT_RANGE[1])
    assert abs(np.trapezoid(g, shifts) - 1.0) < 1e-9
    assert np.trapezoid(np.where(outside, g, 0.0), shifts) < 1e-6
    assert g[outside].max() < 1e-5 * g.max()


@pytest.mark.parametrize("where", ["component", "layer"])
def test_per_wavelength_list_needing_extension_is_refused(where):
    config = scene({"raman": {}})
    values = [0.01] * len(REQUESTED)
    if where == "component":
        config["water"]["layers"][0]["components"].append(
            {"model": "constant", "a": values, "b": 0.0})
        key = "water.layers[0].components[2].a"
    else:
        config["water"]["layers"] = [{"thickness_m": 5.0, "a": values, "b": 0.1}]
        config["bottom"] = {"model": "black"}
        key = "water.layers[0].a"
    with pytest.raises(ConfigError) as info:
        oceanmc.load_config(config)
    message = str(info.value)
    assert "\n" not in message.strip(), message
    assert "water.inelastic.raman" in message, message
    assert "340, 350, 360, 370, 380, 390 nm" in message, message
    assert key in message, message
    # (the user's own count of wavelengths, not the traced grid's)
    assert f"hold values for its {len(values)} wavelengths only" in message, message


def test_every_per_wavelength_list_needing_extension_is_named():
    config = scene({"raman": {}})
    values = [0.01] * len(REQUESTED)
    config["water"]["layers"] = [{"thickness_m": 5.0, "a": values, "b": 0.1}]
    config["bottom"] = {"model": "lambertian", "reflectance": [0.2] * len(REQUESTED)}
    with pytest.raises(ConfigError, match=r"water\.layers\[0\]\.a, bottom\.reflectance hold "
                                          r"values for its 31 wavelengths only"):
        oceanmc.load_config(config)


def test_inelastic_without_wavelengths_is_refused():
    for inelastic, names in (({"raman": {}}, ["water.inelastic.raman"]),
                             (BOTH, ["water.inelastic.raman",
                                     "water.inelastic.chlorophyll_fluorescence"])):
        config = scene(inelastic)
        del config["wavelengths_nm"]
        with pytest.raises(ConfigError) as info:
            oceanmc.load_config(config)
        message = str(info.value)
        assert "\n" not in message.strip(), message
        assert "wavelengths_nm" in message, message
        for name in names:
            assert name in message, message


def excitation_bounds(requested, inelastic: dict) -> tuple[float, float]:
    """The excitation range (nm) the requested wavelengths need, written from the processes'
    definitions: Raman shifts within RAMAN_SHIFT_RANGE (1/cm), fluorescence excited within
    excitation_range_nm for emission within 6 sigma of its peak (and below the emission)."""
    low, high = math.inf, -math.inf
    if "raman" in inelastic:
        for lam in requested:
            low = min(low, 1e7 / (1e7 / lam + RAMAN_SHIFT_RANGE[1]))
            high = max(high, 1e7 / (1e7 / lam + RAMAN_SHIFT_RANGE[0]))
    if "chlorophyll_fluorescence" in inelastic:
        settings = ChlorophyllFluorescence(**inelastic["chlorophyll_fluorescence"])
        for lam in requested:
            if abs(lam - settings.peak_nm) <= 6.0 * settings.sigma_nm:
                low = min(low, settings.excitation_range_nm[0])
                high = max(high, min(lam, settings.excitation_range_nm[1]))
    return low, high


@pytest.mark.parametrize("requested, inelastic, step", [
    ([400.0, 450.0, 500.0, 600.0, 700.0], {"raman": {}}, 10.0),
    ([400.0, 450.0, 500.0, 600.0, 700.0], {"raman": {}}, 7.0),
    ([420.0, 500.0, 600.0, 685.0, 700.0], {"chlorophyll_fluorescence": {}}, 10.0),
    ([410.0, 480.0, 560.0, 640.0, 690.0], BOTH, 4.0),
])
def test_sparse_grid_gaps_filled_in_excitation_range(requested, inelastic, step):
    config = scene(dict(inelastic, max_step_nm=step))
    config["wavelengths_nm"] = requested
    loaded = oceanmc.load_config(config)
    traced = np.asarray(loaded.wavelengths)
    assert np.all(np.diff(traced) > 0.0)
    for lam in requested:                                   # every requested one is traced
        assert np.isclose(traced, lam).any()
    added = [w for w in traced if not np.isclose(requested, w).any()]
    np.testing.assert_allclose(loaded.added_wavelengths, added)
    assert len(added) > 0
    low, high = excitation_bounds(requested, inelastic)
    assert traced[0] <= low + 1e-9                          # extended below far enough
    for a, b in zip(traced[:-1], traced[1:]):
        if a < high and b > low:                            # a gap in the excitation range
            assert b - a <= step * (1.0 + 1e-9), (a, b, step, low, high)
    # wavelengths are added below the requested ones, or in a requested gap that reaches
    # into the excitation range, nowhere else
    for w in added:
        if w < requested[0]:
            continue
        k = int(np.searchsorted(requested, w))
        a, b = requested[k - 1], requested[k]
        assert a < high and b > low, (w, a, b, low, high)


# --- 2. the optics ------------------------------------------------------------------------------

def test_walrafen_redistribution_integrates_to_one():
    emission = np.arange(300.0, 1000.0, 0.01)
    excitation = np.array([340.0, 400.0, 488.0, 550.0, 600.0])
    f = raman.redistribution(Raman(), excitation, emission)            # (n_exc, n_emi) 1/nm
    assert f.shape == (len(excitation), len(emission))
    assert (f >= 0.0).all()
    np.testing.assert_allclose(np.trapezoid(f, emission, axis=1), 1.0, atol=1e-6)
    # the emission lies where the shift range puts it (488 nm excites ~ 584 nm, the 3400 line)
    peak = emission[np.argmax(f[2])]
    assert 570.0 < peak < 600.0


def test_fluorescence_redistribution_integrates_to_one():
    """The range is in the coefficient (0 outside it), not in the redistribution, so that the
    take between an edge wavelength and its neighbour outside the range is re-emitted."""
    settings = ChlorophyllFluorescence()
    emission = np.arange(550.0, 850.0, 0.01)
    excitation = np.array([360.0, 370.0, 440.0, 690.0, 700.0])
    f = fluorescence.redistribution(settings, excitation, emission)
    total = np.trapezoid(f, emission, axis=1)
    np.testing.assert_allclose(total, 1.0, atol=1e-6)
    sigma = fluorescence.coefficient(settings, SimpleNamespace(a_phytoplankton=np.ones(5)),
                                     excitation)
    np.testing.assert_array_equal(sigma == 0.0, [True, False, False, False, True])


@pytest.fixture(scope="module")
def raman_fine():
    """T of water Raman on a regular 1 nm grid 340-700 nm with a flat Ed0."""
    settings = Raman()
    wl = np.arange(340.0, 701.0, 1.0)
    sigma = raman.coefficient_at(settings, wl)
    return wl, sigma, transfer(raman, settings, wl, sigma, np.ones(len(wl)))


def test_raman_transfer_conserves_photons(raman_fine):
    wl, sigma, t = raman_fine
    w = trapezoid_weights(wl)
    assert t.shape == (len(wl), len(wl)) and (t >= 0.0).all()
    # excitation wavelengths whose emission (up to the largest shift) lies inside the grid
    for lam in (341.0, 360.0, 400.0, 450.0, 500.0, 540.0):
        assert 1e7 / (1e7 / lam - RAMAN_SHIFT_RANGE[1]) < wl[-1]
        j = int(np.argmin(np.abs(wl - lam)))
        emitted = float((t[j] * (wl / wl[j]) * w).sum())     # photons, in units of l_j's
        taken = hat_integral(wl, sigma, j)
        # against the hat integral of l'/l_j (about w_j = 1 nm) ...
        assert abs(emitted / w[j] - 1.0) < 1e-3, (lam, emitted, w[j])
        # ... and, tighter, against the same integral with b_R interpolated as the kernel does
        assert abs(emitted / taken - 1.0) < 1e-6, (lam, emitted, taken)
    # Raman light goes to longer wavelengths only, within the shift range of the excitation
    # that l_j's hat covers (l_j +- 1 nm) but for the lines' far tails (T keeps entries down to
    # 1e-9 of a row's largest; RAMAN_SHIFT_RANGE cuts at about 1e-6)
    for j in (0, 60, 160):
        lowest = 1e7 / (1e7 / max(wl[j] - 1.0, wl[0]) - RAMAN_SHIFT_RANGE[0]) - 1.0
        highest = 1e7 / (1e7 / (wl[j] + 1.0) - RAMAN_SHIFT_RANGE[1]) + 1.0
        assert (t[j][wl <= wl[j] + 1.0] == 0.0).all()
        outside = (wl < lowest) | (wl > highest)
        assert t[j][outside].sum() < 1e-5 * t[j].sum(), wl[j]


def test_transfer_ed0_ratio():
    settings = Raman()
    wl = np.arange(340.0, 601.0, 2.0)
    sigma = raman.coefficient_at(settings, wl)
    ed0 = 1.0 + 0.6 * np.sin(wl / 37.0) + (wl - 340.0) / 200.0     # non-flat, > 0
    assert ed0.min() > 0.1
    flat = transfer(raman, settings, wl, sigma, np.ones(len(wl)))
    shaped = transfer(raman, settings, wl, sigma, ed0)
    ratio = ed0[:, None] / ed0[None, :]                               # Ed0_j / Ed0_i
    strong = flat > 1e-6 * flat.max(axis=1, keepdims=True)
    assert strong.sum() > 1000
    np.testing.assert_allclose(shaped[strong], (flat * ratio)[strong], rtol=1e-12)
    # the photons emitted, in Ed0-weighted units (sum_i T_ji Ed0_i/Ed0_j (l_i/l_j) w_i), do
    # not depend on Ed0 (to the dropped tails, below 1e-9 of each row's largest entry)
    w = trapezoid_weights(wl)
    for j in (5, 40, 60, 80):
        emitted = float((shaped[j] / ratio[j] * (wl / wl[j]) * w).sum())
        emitted_flat = float((flat[j] * (wl / wl[j]) * w).sum())
        assert emitted > 0.0 and abs(emitted / emitted_flat - 1.0) < 1e-6
    # an excitation whose lines fall beyond the grid (580 nm: Raman at about 705 nm) has an
    # empty row, not the lines' far tails
    assert not shaped[wl == 580.0].any() and not flat[wl == 580.0].any()
    assert flat[wl == 500.0].any()


@pytest.fixture(scope="module")
def raman_and_fluorescence_config():
    """The clear-water scene with Chl 1 (plenty of phytoplankton absorption), both processes."""
    config = scene()
    config["water"]["layers"][0]["components"][1]["chl_mg_m3"] = 1.0
    return oceanmc.load_config(config)


def test_fluorescence_coefficient_is_yield_times_aph_in_range(raman_and_fluorescence_config):
    config = raman_and_fluorescence_config
    wl = np.asarray(config.wavelengths)
    assert wl[0] < 370.0 and wl[-1] > 690.0            # the grid reaches outside the range
    layers = column_iops(config)
    layer = layers[0]
    assert layer.a_phytoplankton is not None and (layer.a_phytoplankton > 0.0).all()
    settings = ChlorophyllFluorescence()
    inside = (wl >= 370.0) & (wl <= 690.0)
    expected = np.where(inside, 0.02 * layer.a_phytoplankton, 0.0)
    coefficient = fluorescence.coefficient(settings, layer, wl)
    np.testing.assert_allclose(coefficient, expected, rtol=1e-12, atol=0.0)
    assert (coefficient[~inside] == 0.0).all() and (coefficient[inside] > 0.0).all()
    # the channels the kernel gets: Raman's b_R in every layer, fluorescence's yield x a_ph;
    # fluorescence adds no loss, Raman's b_R is in the absorption
    ed0 = illumination_spectrum(config)[0]
    raman_channel, fluo_channel = channels(config, layers, ed0)
    assert (raman_channel.name, fluo_channel.name) == ("raman", "chlorophyll_fluorescence")
    np.testing.assert_allclose(raman_channel.sigma[0], raman.coefficient_at(Raman(), wl),
                               rtol=1e-12)
    np.testing.assert_allclose(fluo_channel.sigma[0], expected, rtol=1e-12, atol=0.0)
    assert raman_channel.phase_beta == 0.55 and fluo_channel.phase_beta == 0.0
    plain = dict(scene(None), wavelengths_nm=[float(v) for v in wl])
    plain["water"]["layers"][0]["components"][1]["chl_mg_m3"] = 1.0
    without = oceanmc.load_config(plain)
    np.testing.assert_allclose(layer.a - column_iops(without)[0].a,
                               raman.coefficient_at(Raman(), wl), rtol=1e-9)


def test_fluorescence_transfer_conserves_photons():
    settings = ChlorophyllFluorescence()
    wl = np.arange(360.0, 761.0, 2.0)                    # holds 685 +- 6 sigma
    aph = 0.03 * (1.0 + 0.5 * np.sin(wl / 45.0)) * np.exp(-(wl - 440.0) ** 2 / 2e4) + 0.002
    sigma = fluorescence.coefficient(settings, SimpleNamespace(a_phytoplankton=aph), wl)
    t = transfer(fluorescence, settings, wl, sigma, np.ones(len(wl)))
    w = trapezoid_weights(wl)
    # no emission from wavelengths outside the excitation range
    assert (t[sigma == 0.0] == 0.0).all()
    assert (sigma[(wl < 370.0) | (wl > 690.0)] == 0.0).all()
    # emitted photons = taken photons (the yield is in sigma): the hat integral of the
    # interpolated coefficient, at the range's edges too (whose hats reach outside it)
    for lam in (370.0, 372.0, 440.0, 500.0, 600.0, 686.0, 690.0):
        j = int(np.argmin(np.abs(wl - lam)))
        emitted = float((t[j] * (wl / wl[j]) * w).sum())
        if 370.0 < lam < 690.0:
            assert abs(emitted / w[j] - 1.0) < 1e-3, (lam, emitted, w[j])
        # (the transfer's 0.02 nm trapezoids: 2e-5 where the coefficient ramps from 0)
        assert abs(emitted / hat_integral(wl, sigma, j) - 1.0) < (
            1e-6 if 370.0 < lam < 690.0 else 1e-4), lam
    # the emission is the 685 nm Gaussian, whatever the excitation
    lit = wl[t[int(np.argmin(np.abs(wl - 440.0)))] > 0.0]
    assert lit.min() >= 685.0 - 6 * 10.6 and lit.max() <= 685.0 + 6 * 10.6


def test_only_the_fluorescence_transfer_is_separable():
    """factors(): the kernel emits a separable transfer as b_i sum_j x_j a_j; only one whose
    rows are all multiples of one row may take that way (chlorophyll fluorescence's, whose
    emission does not depend on the excitation), not Raman's, whose lines move with it."""
    wl = np.arange(340.0, 761.0, 10.0)
    aph = 0.03 * np.exp(-(wl - 440.0) ** 2 / 2e4) + 0.002
    ed0 = 1.0 + 0.3 * np.cos(wl / 37.0)                  # a source spectrum that is not flat
    settings = ChlorophyllFluorescence()
    sigma = fluorescence.coefficient(settings, SimpleNamespace(a_phytoplankton=aph), wl)
    t = transfer(fluorescence, settings, wl, sigma, ed0)
    a, b = factors(t)
    np.testing.assert_allclose(np.outer(a, b), t, rtol=0.0, atol=1e-14 * t.max())
    assert np.count_nonzero(b) == np.count_nonzero(t.max(axis=0))
    t_raman = transfer(raman, Raman(), wl, raman.coefficient_at(Raman(), wl), ed0)
    assert factors(t_raman) is None
    assert factors(np.zeros((3, 3))) is None


# --- 3. a short kernel run ------------------------------------------------------------------------

@pytest.fixture(scope="module")
def whole():
    """The clear-water scene with Raman scattering and chlorophyll fluorescence."""
    return oceanmc.simulate(scene(BOTH))


@pytest.fixture(scope="module")
def packets():
    """The same scene with each emission in a packet of its own (the reference estimator)."""
    return oceanmc.simulate(scene(BOTH, emitted_light="packets"))


@pytest.fixture(scope="module")
def elastic_only(whole):
    """The same scene without inelastic light, its Raman loss as a constant absorber, on the
    first run's traced grid, same seed."""
    grid = np.asarray(whole.coords["wavelength"])
    return oceanmc.simulate(scene(None, extra_absorption=(grid, raman.coefficient_at(Raman(),
                                                                                      grid))))


def test_run_grid_and_named_quantities(whole):
    grid = np.asarray(whole.coords["wavelength"])
    np.testing.assert_allclose(grid, np.arange(340.0, 701.0, 10.0), atol=1e-9)
    np.testing.assert_allclose(np.asarray(whole.attrs["wavelengths_added_nm"]), ADDED)
    for name in ("raman/air/Rrs_nadir", "chlorophyll_fluorescence/Lu",
                 "elastic/budget/shifted_out", "raman/budget/shifted_in",
                 "chlorophyll_fluorescence/budget/shifted_in", "budget/shifted_out",
                 "budget/shifted_in", "elastic/Ed", "raman/Eu", "chlorophyll_fluorescence/Ed",
                 "raman/air/Rrs_nadir_crossing", "elastic/budget/total"):
        assert name in whole, name
        assert whole.quantities[name].batches.shape[0] == BATCHES
    assert "air/rho" in whole                       # ratios are not split into parts
    for part in PARTS:
        assert f"{part}/air/rho" not in whole


def test_inelastic_light_where_expected(whole):
    grid = np.asarray(whole.coords["wavelength"])
    for part in ("raman", "chlorophyll_fluorescence"):
        rrs, se = whole[f"{part}/air/Rrs_nadir"], whole.stderr(f"{part}/air/Rrs_nadir")
        assert (rrs >= 0.0).all()
        # no Raman light where all its excitation lies below the grid (370 nm and below);
        # no fluorescence beyond 6 sigma of 685 nm
        if part == "raman":
            dark = 1e7 / (1e7 / grid + RAMAN_SHIFT_RANGE[0]) < grid[0]
            lit = grid >= 400.0
        else:
            dark = np.abs(grid - 685.0) > 6 * 10.6
            lit = np.abs(grid - 685.0) <= 15.0
        assert dark.any() and (rrs[dark] == 0.0).all(), part
        assert (rrs[lit] > Z_MAX * se[lit]).all(), (part, (rrs / np.where(se > 0, se, 1))[lit])
    # the Raman share of Rrs(550) in clear ocean water as Lee et al. (2013)'s empirical Eq. 11
    # has it from the run's own Rrs(443) / Rrs(550) (the validation case's bound)
    k = int(np.argmin(np.abs(grid - 550.0)))
    rrs = whole["air/Rrs_nadir"]
    share = whole["raman/air/Rrs_nadir"][k] / rrs[k]
    expected = lee_2013_raman_share(np.interp(443.0, grid, rrs), rrs[k])
    assert abs(share / expected - 1.0) < LEE_2013_RTOL, (share, expected)


def test_every_part_budget_closes(whole):
    worst = assert_budgets_close(whole, {"elastic": 1.0, "raman": 0.0,
                                         "chlorophyll_fluorescence": 0.0}, Z_MAX)
    print("budget closure max |z|:", worst)
    # the elastic part gives nothing to itself; the inelastic parts receive what was emitted
    assert (whole["elastic/budget/shifted_in"] == 0.0).all()
    assert whole["raman/budget/shifted_in"].sum() > 0.0
    assert whole["chlorophyll_fluorescence/budget/shifted_in"].sum() > 0.0


def test_parts_add_up_to_whole_batch_by_batch(whole):
    for name in ("Ed", "Eu", "Eo", "Lu", "air/Rrs_nadir", "air/Lw_nadir", "budget/water_leaving",
                 "budget/absorbed_layer_1", "budget/shifted_out", "budget/shifted_in",
                 "budget/total"):
        total = whole.quantities[name].batches
        parts = sum(whole.quantities[f"{part}/{name}"].batches for part in PARTS)
        np.testing.assert_allclose(parts, total, rtol=1e-9, atol=1e-15, err_msg=name)
        # and each inelastic part contributes (the check is not vacuous)
        if name in ("Ed", "Eu", "air/Rrs_nadir"):
            for part in ("raman", "chlorophyll_fluorescence"):
                assert whole.quantities[f"{part}/{name}"].batches.max() > 0.0, (part, name)


def test_emission_equals_take_times_transfer_in_expectation(whole):
    """What each process gave (its part's shifted_in, with roulette on the emissions) against
    what it took (the whole shifted_out, shared between the processes by their coefficients:
    both take at the same collisions, x_j = density_j sigma_j) times T: per batch the
    difference is noise of mean 0; |z| < Z_MAX per wavelength."""
    config = oceanmc.load_config(scene(BOTH))
    layers = column_iops(config)
    chans = channels(config, layers, illumination_spectrum(config)[0])
    sigma_total = sum(c.sigma[0] for c in chans)
    out = whole.quantities["budget/shifted_out"].batches
    worst = {}
    for chan in chans:
        share = np.divide(chan.sigma[0], sigma_total, out=np.zeros_like(sigma_total),
                          where=sigma_total > 0.0)
        expected = (out * share) @ chan.transfer
        given = whole.quantities[f"{chan.name}/budget/shifted_in"].batches
        diff = given - expected
        z = z_of(diff.mean(axis=0), diff.std(axis=0, ddof=1) / math.sqrt(BATCHES), 0.0)
        worst[chan.name] = float(np.abs(z).max())
        assert (np.abs(z) < Z_MAX).all(), (chan.name, z)
        lit = expected.mean(axis=0) > 1e-3 * expected.mean(axis=0).max()
        rel = np.abs(diff.mean(axis=0)[lit] / expected.mean(axis=0)[lit])
        assert rel.max() < 0.05, (chan.name, rel)
    print("emission vs take x T, max |z|:", worst)


# --- 4. the elastic part = the run without inelastic light ------------------------------------

def test_elastic_part_equals_run_without_inelastic_light(packets, elastic_only):
    """With emitted packets the elastic walk makes the draws of the run without inelastic
    light (the emissions draw from a stream of their own): equal batch by batch."""
    np.testing.assert_allclose(np.asarray(elastic_only.coords["wavelength"]),
                               np.asarray(packets.coords["wavelength"]))
    assert "budget/shifted_out" not in elastic_only
    for name in ("Ed", "Eu", "Lu", "air/Rrs_nadir", "Eo", "budget/water_leaving"):
        np.testing.assert_allclose(packets.quantities[f"elastic/{name}"].batches,
                                   elastic_only.quantities[name].batches, rtol=1e-9,
                                   atol=1e-300, err_msg=name)
    taken = (packets.quantities["elastic/budget/absorbed_layer_1"].batches
             + packets.quantities["elastic/budget/shifted_out"].batches)
    np.testing.assert_allclose(taken, elastic_only.quantities["budget/absorbed_layer_1"].batches,
                               rtol=1e-9, atol=1e-15)
    # the inelastic light is extra: the whole exceeds the elastic run at 550 nm
    k = int(np.argmin(np.abs(np.asarray(packets.coords["wavelength"]) - 550.0)))
    assert packets["air/Rrs_nadir"][k] > elastic_only["air/Rrs_nadir"][k]


def test_carried_elastic_part_matches_run_without_inelastic_light(whole, elastic_only):
    """Where the emitting packet carries the light on (the default), roulette weighs all the
    light a packet carries, so the draws part from the run without inelastic light: the
    elastic part agrees within |z| < Z_MAX at every wavelength and depth."""
    worst = 0.0
    for name in ("Ed", "Eu", "Lu", "air/Rrs_nadir", "Eo", "budget/water_leaving"):
        z = z_of(whole[f"elastic/{name}"] - elastic_only[name],
                 np.hypot(whole.stderr(f"elastic/{name}"), elastic_only.stderr(name)), 0.0)
        worst = max(worst, float(np.abs(z).max()))
        assert (np.abs(z) < Z_MAX).all(), (name, z)
    print("carried elastic part vs run without inelastic light, max |z|:", worst)


def test_carried_light_agrees_with_emitted_packets(whole, packets):
    """Two estimators of each inelastic part, independent draws: the light carried on by the
    emitting packet, and a packet of its own per emission; |z| < Z_MAX wherever the part is
    lit (above 1e-3 of its largest value)."""
    worst = assert_estimates_agree(
        whole, packets, [f"{part}/{name}" for part in ("raman", "chlorophyll_fluorescence")
                         for name in ("air/Rrs_nadir", "Ed", "Eu", "Eou", "budget/shifted_in")],
        Z_MAX)
    print("carried vs emitted packets, max |z|:", worst)


# --- 5. the HDF5 round trip ---------------------------------------------------------------------

def test_hdf5_round_trip_keeps_parts(whole, tmp_path):
    path = whole.save(tmp_path / "inelastic.h5")
    loaded = oceanmc.load_result(path)
    for name in ("raman/air/Rrs_nadir", "chlorophyll_fluorescence/Lu",
                 "elastic/budget/shifted_out", "raman/budget/shifted_in", "budget/shifted_in",
                 "elastic/Ed", "air/Rrs_nadir"):
        assert name in loaded, name
        np.testing.assert_array_equal(loaded.quantities[name].batches,
                                      whole.quantities[name].batches, err_msg=name)
        np.testing.assert_array_equal(loaded.stderr(name), whole.stderr(name))
    np.testing.assert_allclose(np.asarray(loaded.attrs["wavelengths_added_nm"]), ADDED)
    np.testing.assert_array_equal(np.asarray(loaded.coords["wavelength"]),
                                  np.asarray(whole.coords["wavelength"]))
    assert set(whole.quantities) == set(loaded.quantities)


# --- 6. bad values ------------------------------------------------------------------------------

@pytest.mark.parametrize("inelastic, needles", [
    ({"raman": {"b488_per_m": -1}}, ["water.inelastic.raman.b488_per_m", "-1"]),
    ({"raman": {"exponent": float("nan")}}, ["water.inelastic.raman.exponent"]),
    ({"raman": {"b488": 2.6e-4}}, ["water.inelastic.raman.b488"]),
    ({"chlorophyll_fluorescence": {"excitation_range_nm": [690, 370]}},
     ["water.inelastic.chlorophyll_fluorescence", "excitation_range_nm", "690", "370"]),
    ({"chlorophyll_fluorescence": {"quantum_yield": 1.5}},
     ["water.inelastic.chlorophyll_fluorescence.quantum_yield"]),
    ({"raman": {}, "max_step_nm": 0}, ["water.inelastic.max_step_nm"]),
    # no process named: the scene would have run elastic, saying nothing
    ({}, ["water.inelastic: no process named", "raman", "leave water.inelastic out"]),
    ({"max_step_nm": 5}, ["water.inelastic: no process named"]),
])
def test_bad_values_are_refused_with_one_clear_line(inelastic, needles):
    with pytest.raises(ConfigError) as info:
        oceanmc.load_config(scene(inelastic))
    message = str(info.value)
    assert "\n" not in message.strip(), message
    for needle in needles:
        assert needle in message, (needle, message)


def test_a_traced_wavelength_outside_the_spectrum_is_said_to_be_added():
    # 300 nm is within SPECTRL2's table; Raman light there is excited at 260-290 nm, which the
    # run adds: the message says so, not only "260 nm is outside"
    config = scene({"raman": {}})
    config["wavelengths_nm"] = [300.0]
    config["illumination"] = {"spectrum": {"model": "spectrl2"}}
    with pytest.raises(ConfigError) as info:
        prepare(oceanmc.load_config(config))
    message = str(info.value)
    assert "wavelength 260 nm is outside the SPECTRL2" in message, message
    assert "(traced for the excitation of water.inelastic, which adds 260-290 nm;" in message


# --- the Fraunhofer lines (validation case fraunhofer, Ge, Gordon & Voss 1993) -------------------


def test_raman_light_fills_in_the_656_nm_line_with_depth_not_the_486_nm_one(tmp_path):
    """A solar line halving the 1-nm band at 486 and 656 nm (and 518, 589), Chl 0.05, 20k
    photons: at 0- the lines are whole in Ed (filling < 0.01); at 50 m the 656 nm line is gone
    from Ed (filling > 0.9: the light there is Raman light) and the 486 nm line is not
    (< 0.05). Measured (seed 7): at most 0.0022, 0.997, 0.012 (standard errors below 5e-3)."""
    from oceanmc.validation.cases import fraunhofer
    config = fraunhofer.water(fraunhofer.CLEAR, 20_000, fraunhofer.solar_table(tmp_path))
    config.update(seed=7, batches=BATCHES)
    f, rel = fraunhofer.filling(oceanmc.simulate(config, threads=2), "Ed")
    lines = list(fraunhofer.LINES_NM)
    surface, deep = fraunhofer.DEPTHS_M.index(0.0), fraunhofer.DEPTHS_M.index(50.0)
    assert np.all(np.abs(f.value[:, surface]) < 0.01)
    assert rel[lines.index(656.0), deep] < fraunhofer.WELL_MEASURED
    assert f.value[lines.index(656.0), deep] > 0.9
    assert f.value[lines.index(486.0), deep] < 0.05
