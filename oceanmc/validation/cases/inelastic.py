"""Validation case inelastic: Raman scattering and chlorophyll fluorescence (water.inelastic;
kernel/channels/inelastic.py) against an independent calculation that shares no code with the
kernel (validation/raman_reference.py: single scattering by quadrature, and a slow walk that
changes each photon's wavelength explicitly); the elastic part of a run against the same scene
without inelastic light (same seed); energy and photon closure of every part; chlorophyll and
CDOM fluorescence against their quantum yields; the Raman share of Rrs(550) in clear water."""
from __future__ import annotations

import numpy as np

from .. import raman_reference
from ... import config as cfg
from ...config.inelastic import CdomFluorescence, ChlorophyllFluorescence, Raman
from ...optics import column_iops
from ...optics.inelastic import cdom_fluorescence, raman
from ..context import Ctx
from .common import Case, _plt, scene

# the thin layer: dissolved absorption only (no elastic scattering), 2 m over a black bottom,
# the sun at the zenith through no interface (the reference's scene)
A440, SLOPE, DEPTH = 0.05, 0.005, 2.0
EMISSION = np.arange(450.0, 601.0, 25.0)
BOOSTED_B488 = 2.6e-2      # 100 x water's: Raman light abundant, all orders compared
PROCESSES = {"raman": {}, "chlorophyll_fluorescence": {}}
# the Raman share of Rrs against Lee et al. (2013)'s Eq. 11, relative: a fitted formula (the sun,
# sky and sea of its fit are not the case's); measured within 12% at 531-667 nm
LEE_2013_RTOL = 0.2
ELASTIC_QUANTITIES = ("Ed", "Eu", "Eo", "Lu", "air/Rrs_nadir", "air/Rrs_nadir_crossing",
                      "budget/water_leaving")


def absorption(wavelengths_nm):
    return A440 * np.exp(-SLOPE * (np.asarray(wavelengths_nm) - 440.0))


def thin_layer(name: str, photons: int, b488: float) -> dict:
    config = scene(name, photons, layers=[{"thickness_m": DEPTH, "components": [
        {"model": "cdom", "a440": A440, "slope": SLOPE}]}], bottom={"model": "black"},
        sun=0.0, surface="none", depths=[0.0, DEPTH])
    config["wavelengths_nm"] = {"start": 360.0, "stop": 600.0, "step": 5.0}
    config["water"]["inelastic"] = {"raman": {"b488_per_m": b488}}
    return config


def clear_water(name: str, photons: int, inelastic: dict | None, seed: int,
                extra_absorption=None) -> dict:
    """Chl 0.05 Case-1 water, deep, sun at 30 deg, flat sea, 400-700 nm (the traced grid when
    extra_absorption is given: the same scene without inelastic light, its Raman loss as a
    constant absorber)."""
    components = [{"model": "pure_water"}, {"model": "case1", "chl_mg_m3": 0.05}]
    if extra_absorption is not None:
        wavelengths, a = extra_absorption
        components.append({"model": "constant", "a": [float(v) for v in a], "b": 0.0})
    config = scene(name, photons, layers=[{"thickness_m": float("inf"),
                                           "components": components}],
                   bottom={"model": "none"}, sun=30.0, depths=[0.0, 10.0])
    config["wavelengths_nm"] = ({"start": 400.0, "stop": 700.0, "step": 10.0}
                                if extra_absorption is None else [float(w) for w in wavelengths])
    config["tallies"]["nadir_estimator"] = "local"
    config["seed"] = seed
    if inelastic is not None:
        config["water"]["inelastic"] = inelastic
    return config


def compare_batches(ctx: Ctx, label: str, one: np.ndarray, two: np.ndarray, labels) -> None:
    """Two estimates of the same quantities, batch by batch ((batches, members) each; one run's
    two estimators, or two runs of as many batches, correlated or not): z of each member from
    the batches' differences, and the joint test Hotelling's T^2 with their leave-one-batch-out
    covariance (members of one run share its photons: a chi-square of their z would count one
    deviation many times), on at most batches / 2 - 1 members spread over them."""
    n_batches, members = one.shape
    picked = np.arange(members)
    if members > n_batches // 2 - 1:
        picked = np.unique(np.linspace(0, members - 1, n_batches // 2 - 1).round().astype(int))
    difference = (one - two)[:, picked]
    ctx.compare(label, one.mean(axis=0)[picked],
                difference.std(axis=0, ddof=1) / np.sqrt(n_batches), two.mean(axis=0)[picked],
                labels=[labels[i] for i in picked],
                loo=(difference.sum(axis=0) - difference) / (n_batches - 1))


def compare_paired(ctx: Ctx, label: str, first, first_quantity: str, second,
                   second_quantity: str, lit: np.ndarray, grid) -> None:
    """compare_batches of a quantity of two results at its lit elements, labelled by their
    wavelengths."""
    lit = np.flatnonzero(np.ravel(lit))
    one = first.quantities[first_quantity].batches
    two = second.quantities[second_quantity].batches
    n_batches = one.shape[0]
    labels = [f"{w:g} nm" for w in np.asarray(grid)[np.unravel_index(lit, one.shape[1:])[0]]]
    compare_batches(ctx, label, one.reshape(n_batches, -1)[:, lit],
                    two.reshape(n_batches, -1)[:, lit], labels)


def at(result, wavelengths) -> np.ndarray:
    grid = result.coords["wavelength"]
    return np.array([int(np.argmin(np.abs(grid - w))) for w in wavelengths])


def case_inelastic(ctx: Ctx) -> None:
    compare_thin_layer(ctx)
    elastic, whole, seed = compare_elastic_part(ctx)
    check_fluorescence(ctx)
    compare_packets(ctx, whole, elastic, seed)
    check_fluorescence(ctx, "cdom_fluorescence")
    check_raman_share(ctx)   # last: the earlier scenes keep their places (seeds)
    check_closure(ctx, whole)
    plot(ctx, whole)
    ctx.note(
        "Thin layer: 2 m of dissolved absorber (a = 0.05 exp(-0.005 (l - 440)) 1/m, no elastic "
        "scattering) over a black bottom, the sun at the zenith through no interface, Raman "
        "light at 450-600 nm: oceanmc's raman/Eu(0), raman/Ed(2 m) and raman/Eou(0) against "
        "validation/raman_reference.py, which shares no code with the kernel: at water's b_R "
        "against single scattering by quadrature (second order is below a quarter of the "
        "standard errors), at 100 times b_R against its slow walk that changes each photon's "
        "wavelength explicitly and follows every order (z against both standard errors). "
        "Clear water (Chl 0.05 Case-1, deep): the elastic part of a run with Raman scattering "
        "and chlorophyll fluorescence against the same scene without them, its Raman loss "
        "given as a constant absorber, same seed: equal to rounding with each emission in a "
        "packet of its own (the emissions draw from a stream of their own), within the "
        "standard errors with the emitted light carried on by the emitting packet (the "
        "default; roulette then weighs all the light a packet carries); the carried light "
        "against the emitted packets, each inelastic part's Rrs, Ed, Eu and Eou (two "
        "estimators; the packets are the ones the thin layer checks: no elastic scattering "
        "there, so nothing carries light on); each part's budget closes (elastic 1, "
        "inelastic 0); the Raman "
        "share of Rrs in sunlit clear water (SPECTRL2 sun and sky, 7 m/s sea, Chl 0.03 and "
        "0.3) against the empirical Raman correction of Lee et al. (2013, J. Geophys. Res. "
        "Oceans 118, 4241, Eq. 11, with the coefficients NASA's l2gen applies), computed from "
        "the run's own Rrs(443) / Rrs(550), within 20% at 531, 551 and 667 nm; at 412-488 nm, "
        "whose Raman light is excited at 350-410 nm, oceanmc's share is 1.2-2.1x the formula's: "
        "its pure water absorbs less at 350-420 nm (IOCCG 2018: Morel et al. 2007) than the "
        "older values, and the blue shares follow that absorption (Chl 0.03, session 28, "
        "not checks here: with Smith & Baker 1981's water below 420 nm, added as an "
        "absorber, 0.98-1.15x the formula's at all six bands; with Smith & Baker below 380 "
        "nm and Pope & Fry above, 0.87x at 412 nm, 1.32x at 443 nm, 1.22x at 488 nm). Fluorescence (Chl 1, fluorescence alone): what it takes at each "
        "excitation wavelength equals the quantum yield times the share of the absorption "
        "that is phytoplankton's, two estimators of the same light (collisions, and the "
        "budget's absorption by settles); CDOM fluorescence (Chl 1, its case1 CDOM, alone) "
        "likewise against Hawes's quantum yield Phi(l') times CDOM's share. The Fraunhofer "
        "lines' infilling with depth (Ge, Gordon & Voss 1993): validation case fraunhofer.")


def compare_thin_layer(ctx: Ctx) -> None:
    photons = ctx.pick(4_000_000, 600_000)
    mu_cut = 0.01   # the kernel's grazing rule for scalar irradiance (tallies.grazing_mu_cut)
    for b488, label in ((Raman().b488_per_m, "water's b_R"), (BOOSTED_B488, "100 x b_R")):
        result = ctx.simulate(thin_layer(f"thin layer, {label}", photons, b488))
        k = at(result, EMISSION)
        if b488 == BOOSTED_B488:
            # the walk's light spans the kernel's traced grid, as the run's does: at 100 x b_R
            # the second and third Raman orders matter, and light below the grid (which the
            # run does not trace: the grid is extended for the first order only) would add
            # to them
            grid = result.coords["wavelength"]
            walk = raman_reference.reference_walk(
                EMISSION, DEPTH, absorption, b488=b488,
                excitation_range_nm=(float(grid[0]), float(grid[-1])),
                photons=ctx.pick(20_000_000, 4_000_000), seed=ctx.next_seed(), bin_nm=2.0,
                mu_cut=mu_cut)
            references = {name: walk[name] for name in ("Eu_top", "Ed_bottom", "Eou_top")}
            how = "the reference walk (every order)"
        else:
            single = raman_reference.single_scattering(EMISSION, DEPTH, absorption, b488=b488,
                                                       mu_cut=mu_cut)
            references = {name: (single[name], 0.0) for name in single}
            how = "single scattering by quadrature"
        for name, quantity, depth in (("Eu_top", "raman/Eu", 0), ("Ed_bottom", "raman/Ed", 1),
                                      ("Eou_top", "raman/Eou", 0)):
            value = result[quantity][k, depth]
            stderr = result.stderr(quantity)[k, depth]
            reference, ref_error = references[name]
            ctx.compare(f"thin layer, {label}: {quantity} against {how}", value, stderr,
                        reference, ref_error=ref_error,
                        labels=[f"{w:g} nm" for w in EMISSION], rel_cap=ctx.pick(0.05, 0.15))


def compare_elastic_part(ctx: Ctx):
    """The elastic part against the same scene without inelastic light (its Raman loss as an
    absorber, same seed): equal within the standard errors where the emitting packet carries
    the light on (the default: roulette then weighs all the light a packet carries, so the
    draws part; equal to rounding with emitted packets, compare_packets); local against
    crossing estimates of the inelastic parts."""
    photons = ctx.pick(1_000_000, 200_000)
    seed = ctx.next_seed()
    whole = ctx.simulate(clear_water("clear water, Raman and fluorescence", photons, PROCESSES,
                                     seed))
    grid = whole.coords["wavelength"]
    elastic = ctx.simulate(clear_water("clear water without inelastic light, Raman loss as "
                                       "absorption", photons, None, seed,
                                       (grid, raman.coefficient_at(Raman(), grid))))
    for quantity in ELASTIC_QUANTITIES:
        compare_paired(ctx, f"clear water, carried: elastic/{quantity} against {quantity} "
                       "without inelastic light (same seed, batch by batch)", whole,
                       f"elastic/{quantity}", elastic, quantity,
                       np.ones(np.shape(elastic[quantity]), dtype=bool), grid)
    for part in ("raman", "chlorophyll_fluorescence"):
        quantity = f"{part}/air/Rrs_nadir"
        crossing = quantity + "_crossing"
        # where the crossing estimate (photons leaving through the 5-degree cap: a handful a
        # batch) has a relative standard error below 20%: above it the batch means are far
        # from normal and their standard error unreliable (a heavy tail passes short tests)
        lit = (whole[quantity] > 1e-3 * whole[quantity].max()) & (
            whole.stderr(crossing) < 0.2 * np.abs(whole[crossing]))
        compare_paired(ctx, f"clear water: {quantity}, local estimate against the crossing "
                       "estimate", whole, quantity, whole, crossing, lit, grid)
    return elastic, whole, seed


def compare_packets(ctx: Ctx, whole, elastic, seed) -> None:
    """The same scene with each emission in a packet of its own (same seed; simulated last,
    so that the case's earlier scenes keep their places in the regression records): its
    elastic part equals the run without inelastic light to rounding (the emissions draw from
    a stream of their own), and the carried light agrees with it, two estimators of each
    inelastic part's Rrs, Ed, Eu and Eou."""
    config = clear_water("clear water, Raman and fluorescence, emitted packets",
                         ctx.pick(1_000_000, 200_000), PROCESSES, seed)
    config["estimator"] = {"emitted_light": "packets"}
    packets = ctx.simulate(config)
    for quantity in ELASTIC_QUANTITIES:
        ctx.exact(f"clear water, emitted packets: elastic/{quantity} = {quantity} without "
                  "inelastic light (same seed)", np.ravel(packets[f"elastic/{quantity}"]),
                  np.ravel(elastic[quantity]), rtol=1e-9, atol=1e-300)
    taken = packets["elastic/budget/absorbed_layer_1"] + packets["elastic/budget/shifted_out"]
    ctx.exact("clear water, emitted packets: elastic absorbed + shifted out = absorbed "
              "without inelastic light", taken, elastic["budget/absorbed_layer_1"], rtol=1e-9)
    grid = whole.coords["wavelength"]
    for part in ("raman", "chlorophyll_fluorescence"):
        for quantity in (f"{part}/air/Rrs_nadir", f"{part}/Ed", f"{part}/Eu", f"{part}/Eou"):
            # at the first tally depth (0-) for the irradiances
            reference = packets[quantity]
            lit = np.zeros(np.shape(reference), dtype=bool)
            first = (np.abs(reference) > 1e-3 * np.abs(reference).max()) if reference.ndim == 1 \
                else (np.abs(reference[:, 0]) > 1e-3 * np.abs(reference[:, 0]).max())
            if reference.ndim == 1:
                lit = first
            else:
                lit[:, 0] = first
            compare_paired(ctx, f"clear water: {quantity}, carried on by the emitting packet "
                           "against emitted packets (same seed, batch by batch)",
                           whole, quantity, packets, quantity, lit, grid)


def check_fluorescence(ctx: Ctx, process: str = "chlorophyll_fluorescence") -> None:
    """What a fluorescence (chlorophyll's, or CDOM's) takes at each excitation wavelength
    (collision estimates, the budget's shifted_out) against its quantum yield x the share of
    the absorption that fluoresces (a_ph / a; a_CDOM / a) x all the light absorbed there (the
    budget's absorption, booked by settles), batch by batch, in Chl 1 Case-1 water with that
    process alone."""
    label = "fluorescence" if process == "chlorophyll_fluorescence" else "CDOM fluorescence"
    config = clear_water(f"Chl 1, {label} alone", ctx.pick(400_000, 100_000), {process: {}},
                         ctx.next_seed())
    config["water"]["layers"][0]["components"][1]["chl_mg_m3"] = 1.0
    result = ctx.simulate(config)
    layer = column_iops(cfg.load_config(config))[0]
    grid = result.coords["wavelength"]
    if process == "chlorophyll_fluorescence":
        settings = ChlorophyllFluorescence()
        share = settings.quantum_yield * layer.a_phytoplankton / layer.a
        formula = "yield x a_ph / a"
    else:
        settings = CdomFluorescence()
        share = cdom_fluorescence.quantum_yield(settings, grid) * layer.a_cdom / layer.a
        formula = "Phi(l') x a_CDOM / a (Hawes 1992)"
    low, high = settings.excitation_range_nm
    inside = (grid >= low) & (grid <= high) & (share > 0.0)
    q = result.quantities
    out = q["elastic/budget/shifted_out"].batches[:, inside]
    absorbed = q["elastic/budget/absorbed_layer_1"].batches[:, inside] + out
    compare_batches(ctx, f"Chl 1: {label}'s take = {formula} x absorbed, per excitation "
                    "wavelength (two estimators, batch by batch)", out, share[inside] * absorbed,
                    [f"{w:g} nm" for w in grid[inside]])


def sunlit_clear_water(chl: float, photons: int) -> dict:
    """Case-1 water of chlorophyll chl, deep, under the SPECTRL2 sun and Harrison-Coombes sky of a
    June afternoon off Bermuda, a 7 m/s Cox-Munk sea, 400-700 nm, Raman scattering alone: the
    light Lee et al. (2013)'s Raman correction describes (the inelastic bench's scene)."""
    return {
        "name": f"sunlit clear water, Chl {chl:g}, Raman", "photons": photons,
        "wavelengths_nm": {"start": 400.0, "stop": 700.0, "step": 10.0},
        "illumination": {"sun_position": {"time": "2024-06-21T14:00:00Z", "latitude_deg": 31.7,
                                          "longitude_deg": -64.2},
                         "spectrum": {"model": "spectrl2"}, "sky": "harrison_coombes"},
        "surface": {"model": "cox_munk", "wind_speed_m_s": 7.0},
        "water": {"layers": [{"thickness_m": float("inf"), "components": [
            {"model": "pure_water"}, {"model": "case1", "chl_mg_m3": chl}]}],
            "inelastic": {"raman": {}}},
        "bottom": {"model": "none"},
        "tallies": {"depths_m": [0.0]},
    }


def check_raman_share(ctx: Ctx) -> None:
    """The Raman share of Rrs nadir against Lee et al. (2013)'s Eq. 11 (raman_reference.
    lee_2013_raman_share: from the run's own Rrs(443) / Rrs(550)) at the bands whose Raman light
    is excited above 420 nm (531, 551 and 667 nm); at 412-488 nm, excited at 350-410 nm, the
    share depends on pure water's ultraviolet absorption, which oceanmc takes from the IOCCG
    (2018) compilation (Morel et al. 2007 below 420 nm, clearer than the older values): there the
    ratios are reported, not checked."""
    for chl in (0.03, 0.3):
        result = ctx.simulate(sunlit_clear_water(chl, ctx.pick(400_000, 100_000)))
        grid = result.coords["wavelength"]
        rrs, raman_rrs = result["air/Rrs_nadir"], result["raman/air/Rrs_nadir"]
        rrs443, rrs550 = np.interp(443.0, grid, rrs), np.interp(550.0, grid, rrs)
        share = {band: np.interp(band, grid, raman_rrs) / np.interp(band, grid, rrs)
                 for band in raman_reference.LEE_2013_BANDS_NM}
        lee = {band: raman_reference.lee_2013_raman_share(rrs443, rrs550, band)
               for band in raman_reference.LEE_2013_BANDS_NM}
        checked = [band for band in share if band > 500.0]
        ctx.exact(f"sunlit clear water, Chl {chl:g}: Raman share of Rrs at "
                  f"{', '.join(f'{b:g}' for b in checked)} nm against Lee et al. (2013)'s Eq. "
                  "11 from the run's own Rrs(443) / Rrs(550)",
                  [share[b] for b in checked], [lee[b] for b in checked], rtol=LEE_2013_RTOL)
        ctx.note(f"Sunlit clear water, Chl {chl:g} (Rrs(443) / Rrs(550) = "
                 f"{rrs443 / rrs550:.2f}): Raman share of Rrs, oceanmc / Lee et al. (2013) Eq. "
                 "11: " + "; ".join(f"{b:g} nm {share[b]:.3f} / {lee[b]:.3f}" for b in share)
                 + ".")


def check_closure(ctx: Ctx, whole) -> None:
    """Each part's budget closes: every path books all its light, so the elastic part's total
    is 1 up to the noise of roulette and an inelastic part's 0 up to rounding (a chi-square
    of z would fail for being too good): within 5 of its largest standard error and 1e-9."""
    for part, source in (("elastic", 1.0), ("raman", 0.0), ("chlorophyll_fluorescence", 0.0)):
        total = whole[f"{part}/budget/total"]
        ctx.exact(f"clear water: {part} part's budget closes ({source:g}), within 5 standard "
                  "errors and 1e-9", total, source,
                  atol=5.0 * float(whole.stderr(f"{part}/budget/total").max()) + 1e-9)


def plot(ctx: Ctx, whole) -> None:
    plt = _plt()
    grid = whole.coords["wavelength"]
    fig, ax = plt.subplots(figsize=(6, 3.6))
    for name, label in (("air/Rrs_nadir", "whole"), ("elastic/air/Rrs_nadir", "elastic"),
                        ("raman/air/Rrs_nadir", "Raman"),
                        ("chlorophyll_fluorescence/air/Rrs_nadir", "chlorophyll fluorescence")):
        ax.errorbar(grid, whole[name], yerr=whole.stderr(name), fmt="o-", ms=3, label=label)
    ax.set_yscale("log")
    ax.set_ylim(1e-6, None)
    ax.set_xlabel("wavelength (nm)")
    ax.set_ylabel("Rrs nadir (1/sr)")
    ax.legend(fontsize=7)
    fig.tight_layout()
    ctx.figure(fig, "rrs_parts", "Rrs at nadir of clear Case-1 water (Chl 0.05, deep) and its "
               "parts: elastic light, Raman light and chlorophyll fluorescence.")


CASE = Case("inelastic", "Raman scattering and chlorophyll fluorescence", case_inelastic,
            "Raman light = an independent calculation (single scattering, a walk that changes "
            "wavelengths); elastic part = the run without inelastic light; budgets close")
