"""Tests of CDOM fluorescence (water.inelastic.cdom_fluorescence; Hawes 1992 as HydroLight uses
it: optics/inelastic/cdom_fluorescence.py): the quantum efficiency eta_Y against values of the
formula evaluated by hand, the quantum yield Phi against a quadrature written here, the
redistribution's normalisation, the photon conservation of the packed transfer, the CDOM
absorption of the constituents, the traced grid, a short kernel run (its cdom_fluorescence/
part, every part's budget, the elastic part against the run without it, the emission against
Phi x the CDOM-absorbed photons by two estimators, the summary) and the refusal of bad values.

Statistics: seeds are fixed; a z-score is (estimate - reference) / standard error over the
32 batches; Z_MAX = 5 as in tests/test_inelastic.py (70 wavelengths, strongly correlated).

Run time: about 10 s on 2 cores with the kernel cached (two kernel runs of 20,000 photons at 70
wavelengths, two transfer matrices).

Measured (seed 20251126, 20,000 photons): budget closure max |z| elastic 1.71,
cdom_fluorescence 3.03; take against Phi a_CDOM / a x absorbed max |z| 0.67; emitted photons
against Phi x CDOM-absorbed photons z 1.76, relative difference 1.06% (its standard error
0.6%; at 300,000 photons, seed 3: -0.28 +- 0.16%)."""
from __future__ import annotations

import copy
import math
from types import SimpleNamespace

import numpy as np
import pytest

import oceanmc
from oceanmc.config import ConfigError
from oceanmc.config.inelastic import PROCESSES, CdomFluorescence, Inelastic, transport_grid
from oceanmc.optics import column_iops
from oceanmc.optics.components import case1
from oceanmc.optics.illumination import illumination_spectrum
from oceanmc.optics.inelastic import cdom_fluorescence as cdom
from oceanmc.optics.inelastic import channels, transfer
from oceanmc.run.derivation import PART_DESCRIPTIONS
from oceanmc.run.results import PART_LABELS, format_summary

from inelastic_helpers import (assert_budgets_close, assert_estimates_agree, hat_integral,
                               trapezoid_weights, z_of)

Z_MAX = 5.0
SEED = 20251126
BATCHES = 32
DEFAULTS = CdomFluorescence()


def hawes_yield(excitation_nm: float, a0: float, top_nm: float = 1000.0) -> float:
    """int_{l'}^{top} eta_Y dl by the trapezoid rule on 0.005 nm, eta_Y written from Hawes
    (1992) as the Ocean Optics Web Book prints it, with A1 0.470, A2 0.407, B1 8.077e-4,
    B2 -4.57e-4 (and no cut at 1000 nm)."""
    emission = np.arange(excitation_nm, top_nm + 1e-9, 0.005)
    centre = 0.470 / excitation_nm + 8.077e-4
    width = 0.6 * (0.407 / excitation_nm - 4.57e-4)
    return float(np.trapezoid(a0 * np.exp(-((1.0 / emission - centre) / width) ** 2), emission))


# --- 1. the optics -------------------------------------------------------------------------------

@pytest.mark.parametrize("excitation, emission, expected", [
    # evaluated by hand from the formula: A0 at a node of Hawes's table, between two nodes
    # (400 nm: (9.39 + 10.48) / 2 1e-5), in HydroLight's extension (520 nm: 2.5e-5)
    (370.0, 450.0, 8.599640e-05),
    (400.0, 520.0, 9.627578e-05),
    (450.0, 500.0, 9.953175e-05),
    (490.0, 600.0, 7.590654e-05),
    (520.0, 560.0, 2.164608e-05),
    (310.0, 700.0, 2.480092e-06),
    (450.0, 440.0, 0.0),            # no emission below the excitation
    (300.0, 450.0, 0.0),            # A0 = 0 below 310 nm ...
    (550.0, 600.0, 0.0),            # ... and from 550 nm on
    (400.0, 1001.0, 0.0),           # nothing counted beyond 1000 nm
])
def test_quantum_efficiency_at_hand_evaluated_points(excitation, emission, expected):
    eta = cdom.quantum_efficiency(np.array([excitation]), np.array([emission]))[0, 0]
    assert eta == pytest.approx(expected, rel=1e-6, abs=1e-15)


def test_quantum_yield_is_one_to_two_percent():
    excitation = np.arange(310.0, 491.0, 20.0)          # Hawes's measured wavelengths
    phi = cdom.quantum_yield(DEFAULTS, excitation)
    assert ((phi > 0.005) & (phi < 0.03)).all(), phi
    # against the trapezoid written here, with A0 from the table printed in Hawes (1992)
    a0 = 1e-5 * np.array([5.18, 6.34, 8.00, 9.89, 9.39, 10.48, 12.59, 13.48, 13.61, 9.27])
    reference = [hawes_yield(lam, a) for lam, a in zip(excitation, a0)]
    np.testing.assert_allclose(phi, reference, rtol=1e-8)
    print("Phi 310-490 nm:", np.round(phi, 4))
    # none outside 310-550 nm and outside the configured range; a0_scale scales it
    assert (cdom.quantum_yield(DEFAULTS, np.array([300.0, 550.0, 600.0])) == 0.0).all()
    narrow = CdomFluorescence(excitation_range_nm=(350.0, 450.0), a0_scale=2.0)
    np.testing.assert_allclose(cdom.quantum_yield(narrow, excitation),
                               np.where((excitation >= 350) & (excitation <= 450), 2 * phi, 0),
                               rtol=1e-12)
    # the largest yield (about 1.9% at 450 nm) times the largest a0_scale stays below 1
    assert 50 * cdom.quantum_yield(DEFAULTS, np.arange(310.0, 550.0, 0.5)).max() < 1.0


def test_emission_beyond_1000_nm_is_negligible():
    """The docstring's claim: beyond 1000 nm lies less than 0.1% of the emission of 310 nm
    excitation (measured 0.08%), less for longer ones."""
    for excitation in (310.0, 400.0, 490.0):
        held = hawes_yield(excitation, 1.0)
        beyond = hawes_yield(excitation, 1.0, 20_000.0) - held
        assert 0.0 < beyond < 1e-3 * held, (excitation, beyond / held)


def test_redistribution_integrates_to_one():
    """To 1 over l' <= l <= 1000 nm at every excitation wavelength, outside 310-550 nm too
    (where a hat of the traced grid reaches beyond the range), 0 below l'."""
    for excitation in (300.0, 310.0, 400.0, 490.0, 549.0, 600.0):
        emission = np.arange(excitation, 1000.0 + 1e-9, 0.01)
        f = cdom.redistribution(DEFAULTS, np.array([excitation]), emission)[0]
        assert (f >= 0.0).all()
        assert np.trapezoid(f, emission) == pytest.approx(1.0, abs=1e-6), excitation
        below = cdom.redistribution(DEFAULTS, np.array([excitation]), emission[:1] - 0.01)
        assert below[0, 0] == 0.0
    emission = np.arange(290.0, 1000.0 + 1e-9, 0.01)
    excitation = np.array([310.0, 400.0, 490.0])
    f = cdom.redistribution(DEFAULTS, excitation, emission)
    # inside 310-550 nm it is eta_Y / Phi
    eta = cdom.quantum_efficiency(excitation, emission)
    np.testing.assert_allclose(f * cdom.quantum_yield(DEFAULTS, excitation)[:, None], eta,
                               rtol=1e-12, atol=1e-20)


@pytest.fixture(scope="module")
def cdom_transfer():
    """T of CDOM fluorescence on a regular 2 nm grid 300-1000 nm (it holds all the emission)
    with a flat Ed0, for an exponential CDOM."""
    wl = np.arange(300.0, 1000.0 + 1e-9, 2.0)
    a_cdom = 0.2 * np.exp(-0.014 * (wl - 440.0))
    sigma = cdom.coefficient(DEFAULTS, SimpleNamespace(a_cdom=a_cdom), wl)
    return wl, a_cdom, sigma, transfer(cdom, DEFAULTS, wl, sigma, np.ones(len(wl)))


def test_transfer_conserves_photons(cdom_transfer):
    """The photons emitted from each excitation wavelength (summed over the grid by
    trapezoids) are Phi times those CDOM absorbs around it (its hat, a_CDOM and Phi
    interpolated linearly as the kernel's weights are), Phi from the quadrature written here:
    to 1e-4 (measured 8e-5 on a 1 nm grid, 1e-4 on 10 nm: the emission's step at l = l'),
    at the ends of the range too (their hats reach outside it)."""
    wl, a_cdom, sigma, t = cdom_transfer
    w = trapezoid_weights(wl)
    a0 = np.interp(wl, [310, 330, 350, 370, 390, 410, 430, 450, 470, 490, 510, 530, 550],
                   1e-5 * np.array([5.18, 6.34, 8.00, 9.89, 9.39, 10.48, 12.59, 13.48, 13.61,
                                    9.27, 4.00, 1.00, 0.0]), left=0.0, right=0.0)
    lit = np.nonzero(sigma > 0.0)[0]
    assert wl[lit[0]] == 310.0 and wl[lit[-1]] == 548.0
    worst = 0.0
    for j in lit[::6].tolist() + [lit[0], lit[-1]]:
        phi = hawes_yield(wl[j], a0[j])
        assert sigma[j] == pytest.approx(phi * a_cdom[j], rel=1e-8)
        emitted = float((t[j] * (wl / wl[j]) * w).sum())     # photons, in units of l_j's
        worst = max(worst, abs(emitted / hat_integral(wl, sigma, j) - 1.0))
        # light goes to longer wavelengths only (the hat reaches down to l_{j-1})
        assert (t[j][wl < wl[j - 1]] == 0.0).all()
    assert worst < 1e-4, worst
    # an excitation wavelength whose own coefficient is 0 takes nothing, so emits nothing
    assert (t[sigma == 0.0] == 0.0).all()


def test_cdom_absorption_of_the_constituents():
    """a_cdom: the cdom component's a_g and case1's covarying CDOM (0.2 a_p(440) e^-0.014
    (l - 440)), summed; a layer without CDOM has none, and its coefficient is 0."""
    wl = np.arange(400.0, 701.0, 10.0)
    config = oceanmc.load_config({
        "wavelengths_nm": [float(v) for v in wl],
        "water": {"layers": [
            {"thickness_m": 5.0, "components": [
                {"model": "pure_water"}, {"model": "case1", "chl_mg_m3": 0.5},
                {"model": "cdom", "a440": 0.1, "slope": 0.018}]},
            {"thickness_m": 5.0, "components": [
                {"model": "pure_water"}, {"model": "chlorophyll", "chl_mg_m3": 0.5}]}]},
        "bottom": {"model": "black"}})
    mixed, plain = column_iops(config)
    expected = case1.cdom_absorption(0.5, wl) + 0.1 * np.exp(-0.018 * (wl - 440.0))
    np.testing.assert_allclose(mixed.a_cdom, expected, rtol=1e-12)
    assert (mixed.a_cdom < mixed.a).all()
    assert plain.a_cdom is None
    assert (cdom.coefficient(DEFAULTS, plain, wl) == 0.0).all()


@pytest.mark.parametrize("requested, settings, first", [
    (np.arange(400.0, 701.0, 10.0), {}, 310.0),
    (np.arange(400.0, 701.0, 10.0), {"excitation_range_nm": (350.0, 500.0)}, 350.0),
    (np.array([440.0, 550.0, 670.0]), {}, 310.0),
])
def test_traced_grid_holds_the_excitation(requested, settings, first):
    traced = transport_grid(requested, Inelastic(cdom_fluorescence=settings))
    assert traced[0] == pytest.approx(first)
    assert all(np.isclose(traced, lam).any() for lam in requested)
    low, high = CdomFluorescence(**settings).excitation_range_nm
    inside = traced[(traced >= low) & (traced <= high)]
    assert np.diff(inside).max() <= 10.0 + 1e-9


# --- 2. a short kernel run -----------------------------------------------------------------------

def scene(inelastic: bool) -> dict:
    """20 m of water with CDOM (a440 0.3, slope 0.014) and a constant absorber and
    scatterer (a 0.05, b 0.5, Henyey-Greenstein 0.9) over a black bottom, sun at 30 deg, a
    flat Ed0 at 310-1000 nm every 10 nm, which holds the excitation and the emission; no pure
    water (its table stops at 800 nm)."""
    config = {
        "name": "CDOM fluorescence test", "photons": 20_000, "batches": BATCHES, "seed": SEED,
        "wavelengths_nm": {"start": 310, "stop": 1000, "step": 10},
        "illumination": {"sun_zenith_deg": 30},
        "surface": {"model": "flat"},
        "water": {"layers": [{"thickness_m": 20.0, "components": [
            {"model": "cdom", "a440": 0.3, "slope": 0.014},
            {"model": "constant", "a": 0.05, "b": 0.5,
             "phase": {"model": "henyey_greenstein", "g": 0.9}}]}]},
        "bottom": {"model": "black"},
        "tallies": {"depths_m": [0, 5], "nadir_estimator": "local"},
    }
    if inelastic:
        config["water"]["inelastic"] = {"cdom_fluorescence": {}}
    return config


@pytest.fixture(scope="module")
def whole():
    return oceanmc.simulate(scene(True), threads=2)


@pytest.fixture(scope="module")
def elastic_only():
    return oceanmc.simulate(scene(False), threads=2)


@pytest.fixture(scope="module")
def packets():
    """The run with each emission in a packet of its own (estimator.emitted_light)."""
    config = scene(True)
    config["estimator"] = {"emitted_light": "packets"}
    return oceanmc.simulate(config, threads=2)


@pytest.fixture(scope="module")
def packed():
    """(traced grid, Ed0, the layer, the CDOM channel) of the scene."""
    config = oceanmc.load_config(scene(True))
    (layer,) = column_iops(config)
    ed0 = illumination_spectrum(config)[0]
    (channel,) = channels(config, [layer], ed0)
    return np.asarray(config.wavelengths), ed0, layer, channel


def test_cdom_part_with_standard_errors(whole, tmp_path):
    assert whole.attrs["inelastic_parts"] == "elastic cdom_fluorescence"
    grid = np.asarray(whole.coords["wavelength"])
    for name in ("Ed", "Eu", "Lu", "air/Rrs_nadir", "budget/shifted_in", "budget/total"):
        quantity = whole.quantities[f"cdom_fluorescence/{name}"]
        assert quantity.batches.shape[:2] == (BATCHES, len(grid)), name
        np.testing.assert_allclose(quantity.batches + whole.quantities[f"elastic/{name}"].batches,
                                   whole.quantities[name].batches, rtol=1e-9, atol=1e-15)
    rrs = whole["cdom_fluorescence/air/Rrs_nadir"]
    se = whole.stderr("cdom_fluorescence/air/Rrs_nadir")
    # next to none at 310 nm (only excitation at 310 nm itself reaches it: the transfer's
    # fine grid gives it its endpoint's weight); a clear signal at 420-600 nm
    assert 0.0 <= rrs[0] < 1e-4 * rrs.max()
    lit = (grid >= 420.0) & (grid <= 600.0)
    assert (rrs[lit] > Z_MAX * se[lit]).all(), (rrs / np.where(se > 0, se, 1))[lit]
    loaded = oceanmc.load_result(whole.save(tmp_path / "cdom.h5"))
    np.testing.assert_array_equal(loaded.stderr("cdom_fluorescence/air/Rrs_nadir"), se)


def test_every_part_budget_closes(whole):
    worst = assert_budgets_close(whole, {"elastic": 1.0, "cdom_fluorescence": 0.0}, Z_MAX)
    assert whole["cdom_fluorescence/budget/shifted_in"].sum() > 0.0
    print("budget closure max |z|:", worst)


def test_elastic_part_is_the_run_without_it(packets, whole, elastic_only):
    """CDOM fluorescence adds no loss (CDOM's absorption is already in a). With emitted
    packets, which draw from their own random stream, the elastic part is the run without it,
    bit for bit; with the light carried on (the default) roulette weighs all the light a
    packet carries, and the elastic part agrees within |z| < Z_MAX."""
    for name in ("Ed", "Eu", "Lu", "Eo", "air/Rrs_nadir", "budget/water_leaving",
                 "budget/lost_below", "budget/absorbed_bottom"):
        np.testing.assert_array_equal(packets.quantities[f"elastic/{name}"].batches,
                                      elastic_only.quantities[name].batches, err_msg=name)
        z = z_of(whole[f"elastic/{name}"] - elastic_only[name],
                 np.hypot(whole.stderr(f"elastic/{name}"), elastic_only.stderr(name)), 0.0)
        assert (np.abs(z) < Z_MAX).all(), (name, z)
    # what it takes is booked out of the absorption (to rounding: (a - x) + x)
    np.testing.assert_allclose(
        packets.quantities["elastic/budget/absorbed_layer_1"].batches
        + packets.quantities["elastic/budget/shifted_out"].batches,
        elastic_only.quantities["budget/absorbed_layer_1"].batches, rtol=1e-13, atol=0.0)


def test_carried_light_agrees_with_emitted_packets(whole, packets):
    """Two estimators of the CDOM part, independent draws: |z| < Z_MAX where it is lit."""
    assert_estimates_agree(whole, packets, [f"cdom_fluorescence/{name}" for name in (
        "air/Rrs_nadir", "Ed", "Eu", "budget/shifted_in")], Z_MAX)


def test_take_is_yield_times_cdom_absorption(whole, packed):
    """Per excitation wavelength, what the process took (collision estimates, shifted_out)
    against Phi a_CDOM / a x all the light absorbed there (the settles' absorption plus the
    take), batch by batch: the difference of two estimators has mean 0."""
    grid, _, layer, _ = packed
    phi = cdom.quantum_yield(DEFAULTS, grid)
    q = whole.quantities
    out = q["budget/shifted_out"].batches
    absorbed = q["budget/absorbed_layer_1"].batches + out
    difference = out - phi * layer.a_cdom / layer.a * absorbed
    z = z_of(difference.mean(axis=0), difference.std(axis=0, ddof=1) / math.sqrt(BATCHES), 0.0)
    inside = (grid >= 310.0) & (grid < 550.0)
    assert (np.abs(z) < Z_MAX).all(), z
    assert (out[:, ~inside] == 0.0).all() and (out[:, inside] > 0.0).all()
    print("take against Phi a_CDOM / a x absorbed, max |z|:", float(np.abs(z).max()))


def test_emitted_photons_are_yield_times_cdom_absorbed_photons(whole, packed):
    """The photons the emitted light carries (the cdom_fluorescence part's shifted_in, in
    photons: weight x Ed0 x l, summed by trapezoids) against Phi x the photons CDOM absorbed
    (the whole budget's absorption x Phi a_CDOM / a; around each excitation wavelength as
    its hat and the interpolated coefficient take them: hat_integral), batch by batch: z <
    Z_MAX, and within 3% (5 of its standard errors, 0.6%; the transfer conserves photons to
    1e-4 on this grid; runs of 60,000 photons differed by 0.41 +- 0.37% and -0.01 +- 0.28%,
    one of 300,000 by -0.28 +- 0.16%)."""
    grid, ed0, layer, channel = packed
    phi = cdom.quantum_yield(DEFAULTS, grid)
    q = whole.quantities
    photons = ed0 * grid * trapezoid_weights(grid)
    emitted = q["cdom_fluorescence/budget/shifted_in"].batches @ photons
    sigma = channel.sigma[0]
    per_take = np.array([hat_integral(grid, sigma, j) if sigma[j] > 0.0 else 0.0
                         for j in range(len(grid))]) * ed0 * grid
    absorbed = q["budget/absorbed_layer_1"].batches + q["budget/shifted_out"].batches
    expected = (phi * layer.a_cdom / layer.a * absorbed) @ per_take
    difference = emitted - expected
    z = difference.mean() / (difference.std(ddof=1) / math.sqrt(BATCHES))
    relative = difference.mean() / expected.mean()
    print(f"emitted against Phi x CDOM-absorbed photons: z {z:.2f}, relative {relative:.2%}")
    assert abs(z) < Z_MAX and abs(relative) < 0.03, (z, relative)


def test_summary_names_cdom_fluorescence(whole):
    printed = format_summary(whole)
    flat = " ".join(printed.split())
    assert "inelastic light: CDOM fluorescence (Hawes 1992, quantum efficiency x 1, excited " \
        "310-550 nm)" in flat, flat
    assert "elastic/, cdom_fluorescence/" in flat
    assert "nm elastic share CDOM fluor. share" in flat
    assert max(map(len, printed.splitlines())) <= 100
    # every process has its label and its parts' description
    assert set(PART_LABELS) == set(PART_DESCRIPTIONS) == {"elastic", *PROCESSES}


# --- 3. bad values -------------------------------------------------------------------------------

@pytest.mark.parametrize("settings, needles", [
    ({"excitation_range_nm": [300, 550]}, ["excitation_range_nm", "[300, 550]", "[310, 550]"]),
    ({"excitation_range_nm": [310, 600]}, ["excitation_range_nm", "[310, 600]", "[310, 550]"]),
    ({"excitation_range_nm": [450, 400]}, ["excitation_range_nm", "[450, 400]", "increasing"]),
    ({"a0_scale": -1}, ["cdom_fluorescence.a0_scale", "-1", "allowed: a number 0 .. 50"]),
    ({"a0_scale": 60}, ["cdom_fluorescence.a0_scale", "60", "allowed: a number 0 .. 50"]),
    ({"quantum_yield": 0.01}, ["cdom_fluorescence.quantum_yield", "unknown key"]),
])
def test_bad_values_are_refused_with_one_clear_line(settings, needles):
    config = copy.deepcopy(scene(False))
    config["water"]["inelastic"] = {"cdom_fluorescence": settings}
    with pytest.raises(ConfigError) as info:
        oceanmc.load_config(config)
    message = str(info.value)
    assert "\n" not in message.strip(), message
    assert "water.inelastic.cdom_fluorescence" in message, message
    for needle in needles:
        assert needle in message, (needle, message)
