"""Validation case spectral_history: all wavelengths in one photon history (kernel/spectral.py)
against an independent single-wavelength run of the same scene at each wavelength, for a clear
Case-1 water, a turbid coastal water and a shallow bottom; energy closure at every wavelength;
the spectral walk's other estimators (upward bias, splitting, analog) against the same
single-wavelength runs over the bottom."""
from __future__ import annotations

import numpy as np

from ..context import Ctx
from .common import Case, _plt, scene

WAVELENGTHS = [412.0, 443.0, 490.0, 555.0, 670.0]

# (key, water layers, bottom, tally depths)
SCENES = (
    ("clear Case-1 water (Chl 0.1 mg/m3), deep",
     [{"thickness_m": float("inf"), "components": [
         {"model": "pure_water"}, {"model": "chlorophyll", "chl_mg_m3": 0.1}]}],
     {"model": "none"}, [0.0, 2.0, 5.0]),
    ("turbid coastal water (Chl 5, CDOM, minerals), deep",
     [{"thickness_m": float("inf"), "components": [
         {"model": "pure_water"}, {"model": "chlorophyll", "chl_mg_m3": 5.0},
         {"model": "cdom", "a440": 0.3, "slope": 0.014},
         {"model": "particles", "b550": 2.0, "exponent": 0.8, "bb_ratio": 0.02, "a443": 0.05}]}],
     {"model": "none"}, [0.0, 1.0, 3.0]),
    ("shallow Lambertian bottom at 5 m (Chl 1)",
     [{"thickness_m": 5.0, "components": [
         {"model": "pure_water"}, {"model": "chlorophyll", "chl_mg_m3": 1.0}]}],
     {"model": "lambertian", "reflectance": 0.3}, [0.0, 2.0, 5.0]),
)

# quantity, label, per depth, cap on the median relative standard error (full, quick): the
# crossing estimate of the 5-degree nadir cap is the noisiest
QUANTITIES = (("Ed", "Ed", True, (0.05, 0.2)), ("Eu", "Eu", True, (0.05, 0.2)),
              ("Eo", "Eo", True, (0.05, 0.2)), ("air/Eu", "Eu(0+)", False, (0.05, 0.2)),
              ("Lu", "Lu (local estimate of the nadir cap)", True, (0.05, 0.2)),
              ("air/Rrs_nadir", "Rrs nadir (local estimate)", False, (0.05, 0.2)),
              ("air/Rrs_nadir_crossing", "Rrs nadir (crossing)", False, (0.1, 0.35)),
              ("budget/water_leaving", "budget water_leaving", False, (0.05, 0.2)))


# the spectral walk's other estimators, over the bottom, each against the default walk's
# single-wavelength runs
ESTIMATORS = (("upward bias 0.1", {"upward_fraction": 0.1}),
              ("splitting above weight 1.05", {"split_weight": 1.05}),
              ("analog walk", {"mode": "analog"}))
ESTIMATOR_QUANTITIES = ("Ed", "Eu", "Lu", "air/Rrs_nadir", "budget/water_leaving")


def spectral_config(name: str, photons: int, layers: list, bottom: dict, depths: list,
                    wavelengths: list[float]) -> dict:
    config = scene(name, photons, layers=layers, bottom=bottom, sun=30.0, diffuse=0.2,
                   depths=depths)
    config["wavelengths_nm"] = list(wavelengths)
    config["tallies"]["nadir_estimator"] = "local"   # and its crossing estimate beside it
    return config


def run_pair(ctx: Ctx, key: int, photons: int, mono_photons: int):
    """The spectral run of scene `key` and one single-wavelength run per wavelength."""
    name, layers, bottom, depths = SCENES[key]
    spectral = ctx.simulate(spectral_config(f"{name}, {len(WAVELENGTHS)} wavelengths", photons,
                                            layers, bottom, depths, WAVELENGTHS))
    singles = [ctx.simulate(spectral_config(f"{name}, {wl:g} nm alone", mono_photons, layers,
                                            bottom, depths, [wl]))
               for wl in WAVELENGTHS]
    return spectral, singles


def case_spectral_history(ctx: Ctx) -> None:
    photons = ctx.pick(2_000_000, 200_000)
    mono_photons = ctx.pick(1_000_000, 100_000)
    figure_data = []
    for key, (name, _, _, depths) in enumerate(SCENES):
        spectral, singles = run_pair(ctx, key, photons, mono_photons)
        for quantity, label, per_depth, caps in QUANTITIES:
            value = spectral[quantity].ravel()
            stderr = spectral.stderr(quantity).ravel()
            reference = np.array([s[quantity] for s in singles]).ravel()
            ref_error = np.array([s.stderr(quantity) for s in singles]).ravel()
            labels = [f"{wl:g} nm" + (f" z {d:g} m" if per_depth else "")
                      for wl in WAVELENGTHS for d in (depths if per_depth else [None])]
            ctx.compare(f"{name}: {label}, one history vs one run per wavelength", value, stderr,
                        reference, ref_error=ref_error, labels=labels,
                        rel_cap=ctx.pick(*caps))
        ctx.compare(f"{name}: energy closure per wavelength (budget total = 1)",
                    spectral["budget/total"], spectral.stderr("budget/total"), 1.0,
                    labels=[f"{wl:g} nm" for wl in WAVELENGTHS])
        figure_data.append((name, spectral, singles))
    compare_estimators(ctx, photons, singles)
    plt = _plt()
    fig, axes = plt.subplots(1, len(figure_data), figsize=(12, 3.6))
    for ax, (name, spectral, singles) in zip(axes, figure_data):
        ax.errorbar(WAVELENGTHS, spectral["air/Rrs_nadir"], yerr=spectral.stderr("air/Rrs_nadir"),
                    fmt="o-", ms=4, label="one history")
        ax.errorbar(np.array(WAVELENGTHS) + 3.0, [s["air/Rrs_nadir"] for s in singles],
                    yerr=[s.stderr("air/Rrs_nadir") for s in singles], fmt="s", ms=4,
                    label="one run per wavelength")
        ax.set_title(name, fontsize=8)
        ax.set_xlabel("wavelength (nm)")
        ax.set_ylabel("Rrs nadir (1/sr)")
        ax.legend(fontsize=7)
    fig.tight_layout()
    ctx.figure(fig, "rrs", "Rrs at nadir (local estimate) of each scene: all wavelengths in "
               "one photon history (circles) against an independent run per wavelength "
               "(squares, shifted 3 nm).")
    ctx.note("Each scene is run once with all five wavelengths in one photon history (hero "
             "wavelength per photon, spectral multiple importance sampling with the balance "
             "heuristic; every wavelength's weight at most n_wl = 5 times what its own walk "
             "carries) and once per wavelength on its own (wavelengths_nm with one entry: the "
             "monochromatic walk), with other seeds. Compared: Ed, Eu, Eo and Lu (local estimate "
             "of the nadir cap: each wavelength's weight, phase function and optical depths from "
             "the same collisions) at every depth, Eu(0+), Rrs nadir (local and crossing "
             "estimates in both) and the water-leaving fraction at every wavelength, z against "
             "both standard errors (Bonferroni bound per group); energy "
             "closure: the budget adds up to 1 at every wavelength. Over the bottom, the "
             "one-history walk is also run with the upward bias, with splitting of packets "
             "heavier than 1.05 (the split stack carries each copy's spectral state) and as "
             "the analog walk (the hero's absorption and reflections drawn), each against the "
             "same single-wavelength runs of the default walk.")


def compare_estimators(ctx: Ctx, photons: int, singles: list) -> None:
    """The last scene (the bottom) by each of ESTIMATORS in one history, against its default
    single-wavelength runs, and its energy closure."""
    name, layers, bottom, depths = SCENES[-1]
    for label, estimator in ESTIMATORS:
        config = spectral_config(f"{name}, {len(WAVELENGTHS)} wavelengths, {label}", photons,
                                 layers, bottom, depths, WAVELENGTHS)
        config["estimator"] = dict(estimator)
        run = ctx.simulate(config)
        for quantity in ESTIMATOR_QUANTITIES:
            per_depth = run[quantity].ndim > 1
            labels = [f"{wl:g} nm" + (f" z {d:g} m" if per_depth else "")
                      for wl in WAVELENGTHS for d in (depths if per_depth else [None])]
            ctx.compare(f"{name}, {label}: {quantity}, one history vs one run per wavelength",
                        run[quantity].ravel(), run.stderr(quantity).ravel(),
                        np.array([s[quantity] for s in singles]).ravel(),
                        ref_error=np.array([s.stderr(quantity) for s in singles]).ravel(),
                        labels=labels, rel_cap=ctx.pick(0.08, 0.3))
        # the analog walk plays no roulette: every photon closes its budget, to rounding
        ctx.compare(f"{name}, {label}: energy closure per wavelength", run["budget/total"],
                    np.maximum(run.stderr("budget/total"), 1e-12), 1.0,
                    labels=[f"{wl:g} nm" for wl in WAVELENGTHS])


CASE = Case("spectral_history", "All wavelengths in one photon history", case_spectral_history,
            "each wavelength of a spectral run = an independent single-wavelength run; budget "
            "= 1 per wavelength")
