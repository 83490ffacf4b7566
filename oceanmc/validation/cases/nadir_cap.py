"""Validation case nadir_cap: the local (next-event) estimate of the nadir polar cap's radiance
(Lu, Lw_nadir, Rrs_nadir: kernel/local_estimate.py, scene/cap_tables.py; through the rough sea,
kernel/rough_cap.py) against the crossing estimate of the same cap average (photons that leave
through the cap) from independent runs, in spectral Case-1 waters of chlorophyll 0.03 to 10
mg/m3 under a flat and a 7 m/s sea, and over a 5 m sand-like bottom under waves; and the local
estimate's batch standard errors against the spread of repeated runs (DESIGN 7.6)."""
from __future__ import annotations

import numpy as np
from scipy import stats

from ..context import Ctx
from .common import Case, _plt, scene

WAVELENGTHS = [412.0, 443.0, 490.0, 555.0, 670.0]
DEEP = float("inf")

# (label, chlorophyll mg/m3, surface, bottom reflectance or None (deep))
SCENES = (
    ("Chl 0.03, flat", 0.03, {"model": "flat"}, None),
    ("Chl 0.03, 7 m/s", 0.03, {"model": "cox_munk", "wind_speed_m_s": 7.0}, None),
    ("Chl 0.3, flat", 0.3, {"model": "flat"}, None),
    ("Chl 0.3, 7 m/s", 0.3, {"model": "cox_munk", "wind_speed_m_s": 7.0}, None),
    ("Chl 10, flat", 10.0, {"model": "flat"}, None),
    ("Chl 10, 7 m/s", 10.0, {"model": "cox_munk", "wind_speed_m_s": 7.0}, None),
    ("Chl 0.3, 7 m/s, bottom 0.3 at 5 m", 0.3, {"model": "cox_munk", "wind_speed_m_s": 7.0},
     0.3),
)
REPEATS = 12


def cap_config(label: str, photons: int, chl: float, surface: dict, bottom: float | None,
               estimator: str) -> dict:
    layer = {"thickness_m": DEEP if bottom is None else 5.0, "components": [
        {"model": "pure_water"}, {"model": "chlorophyll", "chl_mg_m3": chl},
        {"model": "cdom", "a440": 0.0316 * chl ** 0.63}]}
    config = scene(label, photons, layers=[layer],
                   bottom={"model": "none"} if bottom is None else
                   {"model": "lambertian", "reflectance": bottom},
                   sun=30.0, diffuse=0.2, depths=[0.0, 2.0])
    config["wavelengths_nm"] = list(WAVELENGTHS)
    config["surface"] = {**surface, "n_water": 1.34}
    config["tallies"]["nadir_estimator"] = estimator
    config["estimator"] = {"upward_fraction": 0.1}
    return config


def case_nadir_cap(ctx: Ctx) -> None:
    local_photons = ctx.pick(400_000, 40_000)
    crossing_photons = ctx.pick(4_000_000, 200_000)
    figure = []
    for label, chl, surface, bottom in SCENES:
        local = ctx.simulate(cap_config(label, local_photons, chl, surface, bottom, "local"))
        crossing = ctx.simulate(cap_config(label, crossing_photons, chl, surface, bottom,
                                           "crossing"))
        for quantity in ("air/Rrs_nadir", "Lu"):
            per_depth = local[quantity].ndim > 1
            labels = [f"{wl:g} nm" + (f" z {d:g} m" if per_depth else "")
                      for wl in WAVELENGTHS for d in ([0.0, 2.0] if per_depth else [None])]
            # the bands (and depths) of one run share its photons: their joint test is
            # Hotelling's, with the local run's leave-one-batch-out covariance
            batches = local.quantities[quantity].batches.reshape(
                local.quantities[quantity].batches.shape[0], -1)
            loo = (batches.sum(axis=0) - batches) / (batches.shape[0] - 1)
            ctx.compare(f"{label}: {quantity}, local estimate vs crossing estimate",
                        local[quantity].ravel(), local.stderr(quantity).ravel(),
                        crossing[quantity].ravel(),
                        ref_error=crossing.stderr(quantity).ravel(), labels=labels,
                        rel_cap=ctx.pick(0.1, 0.4), loo=loo)
        figure.append((label, local, crossing))
    repeated_runs(ctx)
    plt = _plt()
    fig, axes = plt.subplots(1, 2, figsize=(11, 3.8))
    for label, local, crossing in figure:
        ratio = local["air/Rrs_nadir"] / crossing["air/Rrs_nadir"]
        err = ratio * np.hypot(local.stderr("air/Rrs_nadir") / local["air/Rrs_nadir"],
                               crossing.stderr("air/Rrs_nadir") / crossing["air/Rrs_nadir"])
        axes[0].errorbar(WAVELENGTHS, ratio, yerr=err, fmt="o-", ms=3, label=label)
        axes[1].semilogy(WAVELENGTHS, local.stderr("air/Rrs_nadir") / local["air/Rrs_nadir"],
                         "o-", ms=3, label=label)
    axes[0].axhline(1.0, color="k", lw=0.5)
    axes[0].set_ylabel("Rrs nadir: local / crossing")
    axes[1].set_ylabel(f"local estimate's relative standard error ({local_photons:,} photons)")
    for ax in axes:
        ax.set_xlabel("wavelength (nm)")
    axes[0].legend(fontsize=6)
    fig.tight_layout()
    ctx.figure(fig, "nadir_cap", "Left: Rrs nadir by the local estimate of the 5-degree polar cap "
               "over the crossing estimate of the same cap (independent runs), with the "
               "combined standard error. Right: the local estimate's relative standard error.")
    ctx.note("Five-band Case-1 waters (pure water, Bricaud phytoplankton with Morel particle "
             "scattering, CDOM a440 = 0.0316 Chl^0.63), sun at 30 deg with a 20% uniform sky, "
             "upward bias 0.1, deep or over a Lambertian bottom of 0.3 at 5 m. The local "
             "estimate of the polar cap (through waves: the facets' transmission lobe "
             "tabulated once per scene, kernel/rough_cap.py) is compared with the crossing "
             "estimate of the same cap average from an independent run with 10 times the "
             "photons, z against both standard errors; then its batch standard errors against "
             f"the spread of {REPEATS} repeated runs.")


def repeated_runs(ctx: Ctx) -> None:
    """REPEATS runs of the windy Chl 0.3 scene with their own seeds: the sample variance of
    Rrs across runs over the mean squared batch standard error is F-distributed (REPEATS - 1
    and the runs' pooled batch degrees of freedom) when the standard errors are right; both
    tails are checked per wavelength, and the pooled ratio over the wavelengths."""
    label, chl, surface, bottom = SCENES[3]
    photons = ctx.pick(100_000, 20_000)
    runs = [ctx.simulate(cap_config(f"{label}, repeat {k + 1}", photons, chl, surface, bottom,
                                    "local")) for k in range(REPEATS)]
    values = np.array([r["air/Rrs_nadir"] for r in runs])
    stderr = np.array([r.stderr("air/Rrs_nadir") for r in runs])
    ratio = values.var(axis=0, ddof=1) / np.mean(stderr ** 2, axis=0)
    dof_batches = REPEATS * (ctx.batches - 1)
    # each ratio is F(REPEATS - 1, dof_batches); as a z from its two-sided p-value
    p = 2.0 * np.minimum(stats.f.cdf(ratio, REPEATS - 1, dof_batches),
                         stats.f.sf(ratio, REPEATS - 1, dof_batches))
    z = stats.norm.isf(np.clip(p, 1e-300, 1.0) / 2.0)
    ctx.compare(f"{label}: spread of {REPEATS} repeated runs vs the batch standard errors, "
                "Rrs nadir (local), as z of the F ratio", z * np.sign(ratio - 1.0), 1.0, 0.0,
                labels=[f"{wl:g} nm, ratio {r:.2f}" for wl, r in zip(WAVELENGTHS, ratio)])


CASE = Case("nadir_cap", "The nadir cap's local estimate, flat and rough, Chl 0.03-10",
            case_nadir_cap, "local estimate of the nadir cap = crossing estimate of the same cap "
            "(|z| bound), flat and 7 m/s, Chl 0.03-10, deep and over a bottom; its standard "
            "errors = the spread of repeated runs")
