"""Validation case fraunhofer: the infilling of solar Fraunhofer lines by Raman scattering with
depth, against what Ge, Gordon & Voss (1993, Appl. Opt. 32, 4028-4036) found by Monte Carlo for
Case-1 water: the line at 656 nm fills in (disappears into the continuum) rapidly with depth,
the light there becoming all Raman light; the line at 486 nm keeps its depth in the downwelling
irradiance at every depth (Raman light never matters there); between them, the lines at 518
and 589 nm fill in with depth in clear water but not in water of high chlorophyll.

The solar spectrum (a `spectrum: {model: table}` written here) is flat with one line at each of
486, 518, 589 and 656 nm that halves the irradiance in its 1-nm band (traced at the line and
1 nm either side); the water is Case-1 (pure water and the case1 component) at chlorophyll
0.05 and 3 mg/m3, deep, sun at 30 deg, 20% cardioidal sky, flat sea, Raman scattering at its
defaults. A line's filling at a depth: (r - r_sun) / (1 - r_sun), r the irradiance at the line
over the mean of the two bands beside it, r_sun = 0.5 the sun's (0: the sun's line; 1: gone),
with a jackknife standard error over the batches."""
from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from ..context import Ctx
from ..stats import JK
from .common import Case, _plt, scene

LINES_NM = (486.0, 518.0, 589.0, 656.0)
LINE_DEPTH = 0.5     # the sun's irradiance in a line's band over the continuum's
DEPTHS_M = (0.0, 10.0, 25.0, 50.0, 75.0, 100.0)
CLEAR, GREEN = 0.05, 3.0   # chlorophyll, mg/m3
WELL_MEASURED = 0.2   # a line's irradiance with a larger relative standard error is not checked


def solar_table(folder: Path) -> Path:
    """A flat spectrum, 300-800 nm every 1 nm, with the lines, and a diffuse fraction of 0.2."""
    wavelengths = np.arange(300.0, 801.0, 1.0)
    ed0 = np.where(np.isin(wavelengths, LINES_NM), LINE_DEPTH, 1.0)
    path = folder / "sun_with_lines.csv"
    np.savetxt(path, np.c_[wavelengths, ed0, np.full_like(wavelengths, 0.2)], delimiter=",",
               header="wavelength_nm,Ed0,diffuse_fraction", comments="")
    return path


def water(chl: float, photons: int, table: Path) -> dict:
    config = scene(f"Fraunhofer lines, Chl {chl:g}", photons, layers=[{
        "thickness_m": float("inf"), "components": [{"model": "pure_water"},
                                                     {"model": "case1", "chl_mg_m3": chl}]}],
        bottom={"model": "none"}, sun=30.0, sky="cardioidal", depths=DEPTHS_M)
    del config["illumination"]["diffuse_fraction"]   # the table gives it
    config["illumination"]["spectrum"] = {"model": "table", "file": str(table)}
    config["wavelengths_nm"] = sorted(line + step for line in LINES_NM for step in (-1.0, 0.0, 1.0))
    config["water"]["inelastic"] = {"raman": {}, "max_step_nm": 5.0}
    return config


def filling(result, quantity: str) -> tuple[JK, np.ndarray]:
    """Each line's filling at each tally depth (lines x depths) and the relative standard
    error of the irradiance at the line."""
    grid = list(np.asarray(result.coords["wavelength"]))
    irradiance = JK.of(result, quantity)
    out, rel = [], []
    for line in LINES_NM:
        at, below, above = grid.index(line), grid.index(line - 1.0), grid.index(line + 1.0)
        with np.errstate(divide="ignore", invalid="ignore"):   # no light left: nan, unchecked
            ratio = irradiance[at] / ((irradiance[below] + irradiance[above]) * 0.5)
            out.append((ratio - LINE_DEPTH) * (1.0 / (1.0 - LINE_DEPTH)))
            rel.append(irradiance[at].stderr / np.abs(irradiance[at].value))
    return JK(np.array([f.value for f in out]), np.stack([f.loo for f in out], axis=1)), \
        np.array(rel)


def case_fraunhofer(ctx: Ctx) -> None:
    photons = ctx.pick(400_000, 100_000)
    fillings = {}
    with tempfile.TemporaryDirectory() as folder:
        table = solar_table(Path(folder))
        for chl in (CLEAR, GREEN):
            result = ctx.simulate(water(chl, photons, table))
            for quantity in ("Ed", "Eu"):
                fillings[chl, quantity] = filling(result, quantity)
    line = {wavelength: i for i, wavelength in enumerate(LINES_NM)}
    depth = {d: i for i, d in enumerate(DEPTHS_M)}

    def well_measured(chl, quantity, wavelength):
        """The indices of the tally depths where the line's irradiance is well measured."""
        rel = fillings[chl, quantity][1]
        return [k for k in range(len(DEPTHS_M)) if rel[line[wavelength], k] < WELL_MEASURED]

    def measured(chl, quantity, wavelength, depths):
        """The line's filling and its standard error at those of `depths` where it is well
        measured."""
        f = fillings[chl, quantity][0]
        keep = [k for k in well_measured(chl, quantity, wavelength) if DEPTHS_M[k] in depths]
        return f.value[line[wavelength], keep], f.stderr[line[wavelength], keep]

    def check(label, value, stderr, reference, atol):
        """A deterministic check of a filling (or a difference of two) against a band, its
        standard errors and its distance to the band's edge in them in the note."""
        value, stderr = np.atleast_1d(value), np.atleast_1d(stderr)
        margin = np.min((atol - np.abs(value - reference)) / np.maximum(stderr, 1e-300))
        ctx.exact(label, value, reference, atol=atol,
                  note=f"|diff| <= {atol:g}; jackknife standard errors <= {stderr.max():.2g}, "
                       f"the band's edge >= {margin:.1f} of them away")

    for chl in (CLEAR, GREEN):
        surface = [measured(chl, "Ed", w, [0.0]) for w in LINES_NM]
        check(f"Chl {chl:g}: every line's filling in Ed at 0- is below 0.01 (the sun's lines "
              "enter the water whole)", np.concatenate([v for v, _ in surface]),
              np.concatenate([e for _, e in surface]), 0.0, 0.01)
        check(f"Chl {chl:g}: the 486 nm line's filling in Ed stays below 0.05 at every "
              "well-measured depth to 100 m (nearly independent of depth)",
              *measured(chl, "Ed", 486.0, DEPTHS_M), 0.0, 0.05)
        check(f"Chl {chl:g}: the 656 nm line has filled in, in Eu at 25 and 50 m (filling "
              "within 0.1 of 1: the light there is Raman light)",
              *measured(chl, "Eu", 656.0, [25.0, 50.0]), 1.0, 0.1)
    check(f"Chl {CLEAR:g}: the 656 nm line has filled in, in Ed at 50-100 m",
          *measured(CLEAR, "Ed", 656.0, [50.0, 75.0, 100.0]), 1.0, 0.1)
    # the changes with depth and between waters, with the jackknife error of the difference
    f = fillings[CLEAR, "Eu"][0]
    ok = well_measured(CLEAR, "Eu", 518.0)
    grow = f[line[518.0], ok[-1]] - f[line[518.0], 0]
    check(f"Chl {CLEAR:g}: the 518 nm line fills in with depth: its filling in Eu grows by "
          "at least 0.3 from 0- to the deepest well-measured depth", grow.value, grow.stderr,
          0.65, 0.35)
    f = fillings[GREEN, "Eu"][0]
    ok = well_measured(GREEN, "Eu", 518.0)
    change = f[line[518.0], ok] - f[line[518.0], 0]
    check(f"Chl {GREEN:g}: the 518 nm line does not fill in with depth: its filling in Eu "
          "changes by less than 0.05 down to the deepest well-measured depth", change.value,
          change.stderr, 0.0, 0.05)
    clear, green = fillings[CLEAR, "Eu"][0], fillings[GREEN, "Eu"][0]
    # (two runs of as many batches: their batch pairs are independent, JK combines them)
    more = clear[line[589.0], depth[25.0]] - green[line[589.0], depth[25.0]]
    check("the 589 nm line's filling in Eu at 25 m depends on chlorophyll: at least 0.3 more "
          f"at Chl {CLEAR:g} than at Chl {GREEN:g}", more.value, more.stderr, 0.65, 0.35)
    plot(ctx, fillings)
    ctx.note(
        "Raman light fills in the Fraunhofer lines of sunlight with depth (Ge, Gordon & Voss "
        "1993, Appl. Opt. 32, 4028: Monte Carlo for Case-1 water): a flat solar spectrum with "
        "a line halving the irradiance in the 1-nm band at each of 486, 518, 589 and 656 nm "
        "(`spectrum: {model: table}`; traced at the line and 1 nm either side, the excitation "
        "range filled every 5 nm), Case-1 water of chlorophyll 0.05 and 3 mg/m3, deep, sun at "
        "30 deg, 20% cardioidal sky, flat sea, Raman scattering at its defaults. Filling: "
        "(r - 0.5) / 0.5, r the irradiance at the line over the mean of the two bands beside "
        "it (0: the sun's line, 1: gone). As the paper found: the 656 nm line disappears with "
        "depth (Raman light dominates below a few tens of metres), the 486 nm line keeps its "
        "depth in Ed, and the 518 nm line fills in with depth in clear water but not at high "
        "chlorophyll, where the excitation near 440 nm is absorbed faster than the light at "
        "518 nm; the 589 nm line's filling depends on chlorophyll. Checked where the line's "
        f"irradiance has a relative standard error below {WELL_MEASURED:g}; the thresholds "
        "(deterministic checks) are far from the values measured: at least 60 jackknife "
        "standard errors in quick mode, 110 in full (each check's note says how many).")


def plot(ctx: Ctx, fillings) -> None:
    plt = _plt()
    fig, axes = plt.subplots(1, 2, figsize=(8, 3.6), sharey=True)
    for ax, chl in zip(axes, (CLEAR, GREEN)):
        for i, wavelength in enumerate(LINES_NM):
            for quantity, style in (("Ed", "o-"), ("Eu", "s--")):
                f, rel = fillings[chl, quantity]
                ok = rel[i] < WELL_MEASURED
                ax.errorbar(np.asarray(DEPTHS_M)[ok], f.value[i, ok], yerr=f.stderr[i, ok],
                            fmt=style, ms=3, color=f"C{i}",
                            label=f"{quantity} {wavelength:g} nm")
        ax.set_title(f"Chl {chl:g} mg/m3", fontsize=9)
        ax.set_xlabel("depth (m)")
    axes[0].set_ylabel("line filling")
    axes[1].legend(fontsize=6, ncol=2)
    fig.tight_layout()
    ctx.figure(fig, "line_filling", "Filling of four Fraunhofer lines by Raman light with depth "
               "(0: the sun's line; 1: filled in), in Ed and Eu, in clear and in green Case-1 "
               "water.")


CASE = Case("fraunhofer", "Fraunhofer lines filled in by Raman light with depth", case_fraunhofer,
            "Raman light fills the 656 nm line with depth, not the 486 nm one; 518 and 589 nm "
            "depend on chlorophyll (Ge, Gordon & Voss 1993)")
