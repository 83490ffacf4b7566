"""Depth importance weight windows, packed (the kernel's part: kernel/weight_window.py).

Light deep in the water is a deep-penetration problem: over 10 attenuation depths it falls by
e^-10, and an implicit-capture walk sends ever fewer packets there, so that the relative
variance of a tally at depth z grows about as fast as the light falls. Splitting and Russian
roulette by importance keep the packet population even with depth (Kalos & Whitlock, Monte
Carlo Methods, 2nd ed. 2008, on splitting and Russian roulette; Booth, "A sample problem for
variance reduction in MCNP", LA-10363-MS, 1985): the water column is cut into depth segments,
each with a window weight W, and a packet that enters a segment far heavier than W is split
into copies near W (MCNP's weight windows: X-5 Monte Carlo Team, MCNP5 manual vol. I,
LA-UR-03-1987; OpenMC's the same), while packets that lose weight play roulette at a threshold
scaled by W (below). The importance of a packet for tallies at depth is the inverse of the
light expected there, so W falls with depth as the light does:

    W(z) = exp(-zeta(z)),  zeta(z) = integral_0^z K dz',
    K = min((a + b_b) / MEAN_COSINE, sqrt(3 a (a + b_b))),

K the diffuse attenuation from the scene's own IOPs, no user tuning: that of quasi-single
scattering (Gordon, Brown & Jacobs 1975, Appl. Opt. 14, 417; Gordon 1989, Limnol. Oceanogr. 34,
1389: K_d = (a + b_b) / mu_d) where absorption dominates, and where backscattering does (b_b
above 0.69 a) the asymptotic attenuation of diffusion theory, K_inf = sqrt(3 a (a + b (1 - g)))
(Ishimaru, Wave Propagation and Scattering in Random Media, 1978, ch. 9), with b_b in place of
b (1 - g), which it never exceeds (1 - g = integral (1 - cos) p >= the backward integral of p),
so that K errs low. Gordon's K alone grows with b_b without bound while the light of a turbid,
weakly absorbing layer falls far slower: b = 1000 1/m of particles over 1 m (K 25 1/m by
Gordon, 2.3 by diffusion) split every packet into e^15 copies (the fuzz test's run of 200
photons had not ended after 20 minutes). A window that falls too slowly only splits less.
Below the deepest tally depth nothing is tallied and W stays at its value there. The window is
the same for every wavelength of a spectral walk: that of the least attenuated one (the
largest W), the light that reaches deepest; each packet is weighed by its heaviest wavelength
(kernel/weight_window.py).

Segments are the walk's own (between its planes: layer boundaries, tally depths, the surface
and the bottom); where a segment above the deepest tally spans more than PLANE_STEP attenuation
depths, planes without tallies are added in it, so that W changes by at most a factor 2 from
one segment to the next and a packet is split or rouletted a little at a time.

When windows are on, Russian roulette at collisions below estimator.roulette_weight would kill
the deep packets the windows made (a weight W of e^-10 is far below 1e-3): its threshold
becomes ROULETTE_WEIGHT x W in each segment (max(roulette_weight, ROULETTE_WEIGHT) where a
larger roulette_weight is asked for), as MCNP scales its weight cutoff by the importance. A
packet that has lost most of its weight there is worth less than under a plain walk, since the
windows keep the population up with fresh copies: on the bench's deep scene (bench/deep.py,
upward bias 0.1, 3 interleaved runs of 300,000 photons) 0.01 W brought every Ed, Eou and Lu to
1% 1.8 times sooner than 0.001 W (the worst of them: 52 s against 94 s), and 0.03 W lost Lu by
1.8 times.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import config as cfg
from .. import optics
from ..config.estimator import AUTO_UPWARD_FRACTION

# estimator.depth_splitting auto: on when the deepest tally depth lies at least this many
# attenuation depths (zeta, at the least attenuated wavelength) down
AUTO_ATTENUATION_DEPTHS = 2.0
# the mean cosine of the diffuse downwelling light in K = (a + b_b) / MEAN_COSINE: with 0.75
# zeta matches ln(Ed(0-) / Ed(z)) of the bench's deep scene (benchmarks/deep.md) within 3%
# from 30 m (2.5 attenuation depths) to 110 m (10.9), and within 14% above. A K too small
# splits too little at depth, one too large more than needed (measured there, 2 runs each,
# roulette at 0.001 W: 0.65 took 2.6 times the events per photon of 0.75 and gained nothing;
# 0.9 half the events, and 2 to 5 times the worst time to 1% of Ed, Eou and Lu)
MEAN_COSINE = 0.75
# the largest step of the window from one segment to the next, in attenuation depths (W halves)
PLANE_STEP = math.log(2.0)
# the roulette threshold at collisions under windows, relative to the segment's window
ROULETTE_WEIGHT = 0.01
# the window falls no further than this many attenuation depths (e^-15 = 3e-7): each
# attenuation depth of windows costs about as much as the first, so a tally at 40 attenuation
# depths (validation realistic_phase's deepest, 1e-17 of the surface's light) made the case's
# run 70 times longer; the light below is still followed, by plain implicit capture
MAX_ATTENUATION_DEPTHS = 15.0


@dataclass(frozen=True)
class DepthWindows:
    """Whether the scene's packets follow depth windows, why (the run's attribute
    depth_splitting says it), and down to which depth the window falls."""
    on: bool
    why: str
    deepest_m: float


def attenuation_depths(layers: list[optics.LayerIOPs], z: np.ndarray) -> np.ndarray:
    """zeta at depths z (m) at the least attenuated wavelength: min over wavelengths of the
    integral of K (above) from the surface."""
    z = np.atleast_1d(np.asarray(z, dtype=np.float64))
    a = np.array([layer.a for layer in layers])
    bb = np.array([layer.bb for layer in layers])
    attenuation = np.minimum((a + bb) / MEAN_COSINE, np.sqrt(3.0 * a * (a + bb)))
    inside = np.clip(z - np.array([[layer.top_m] for layer in layers]), 0.0,
                     np.array([[layer.thickness_m] for layer in layers]))
    # (layers, wavelengths, depths), summed over the layers in their order, as a loop would
    return np.sum(attenuation[:, :, None] * inside[:, None, :], axis=0).min(axis=0)


def choose(config: cfg.SceneConfig, layers: list[optics.LayerIOPs]) -> DepthWindows:
    """The decision of estimator.depth_splitting for the scene."""
    mode = config.estimator.depth_splitting
    deepest = max(config.tallies.depths_m, default=0.0)
    if mode == "off":
        return DepthWindows(False, "off", deepest)
    zeta = float(attenuation_depths(layers, [deepest])[0])
    where = f"the deepest tally depth {deepest:g} m at {zeta:.2f} attenuation depths"
    if mode == "on":   # never with inelastic light (config/scene.py refuses it)
        return DepthWindows(deepest > 0.0, f"on ({where})", deepest)
    if config.estimator.mode == "analog":
        return DepthWindows(False, "off (auto: the analog walk)", deepest)
    if config.water.inelastic is not None and config.water.inelastic.processes():
        return DepthWindows(False, "off (auto: inelastic light)", deepest)
    if not any(layer.b.any() for layer in layers):
        # an implicit walk through water that does not scatter is exact: copies would only
        # repeat it
        return DepthWindows(False, "off (auto: no layer scatters)", deepest)
    on = zeta >= AUTO_ATTENUATION_DEPTHS
    return DepthWindows(on, f"{'on' if on else 'off'} (auto: {where}; on from "
                            f"{AUTO_ATTENUATION_DEPTHS:g})", deepest)


def upward_fraction(config: cfg.SceneConfig, windows: DepthWindows) -> float | None:
    """The upward bias the scene runs with: estimator.upward_fraction, whose auto config/scene.py
    leaves to the build in a one-wavelength implicit walk: AUTO_UPWARD_FRACTION where the depth
    windows are on, off elsewhere (the result's attribute upward_fraction says which; the
    stored config keeps auto, so that a rerun or a sweep's point is the same scene). The windows
    split packets on their way down; the bias sends some of them back up toward the
    nadir-viewing cap, whose local estimate otherwise keeps a heavy tail at every depth
    (benchmarks/deep.md, the bench's stratified column: Lu to 1% in 250 s at 45 m with the
    windows alone; every Ed, Eou and Lu within 27 s with both)."""
    value = config.estimator.upward_fraction
    if value == "auto":
        return AUTO_UPWARD_FRACTION if windows.on else None
    return value


def added_planes(windows: DepthWindows, layers: list[optics.LayerIOPs],
                 plane_z: np.ndarray) -> np.ndarray:
    """Depths of the planes to add above the deepest tally depth so that no segment spans more
    than PLANE_STEP attenuation depths (evenly in zeta within each segment that does)."""
    if not windows.on:
        return np.zeros(0)
    tops = plane_z[:-1][plane_z[:-1] < windows.deepest_m]
    bottoms = np.minimum(plane_z[1:len(tops) + 1], windows.deepest_m)
    added = []
    for top, bottom in zip(tops, bottoms):
        grid = np.linspace(top, bottom, 65)
        zeta = np.minimum(attenuation_depths(layers, grid), MAX_ATTENUATION_DEPTHS)
        steps = int(math.ceil((zeta[-1] - zeta[0]) / PLANE_STEP - 1e-9))
        if steps > 1:
            targets = zeta[0] + (zeta[-1] - zeta[0]) * np.arange(1, steps) / steps
            added.extend(np.interp(targets, zeta, grid))
    return np.array(added)


def segment_windows(windows: DepthWindows, layers: list[optics.LayerIOPs],
                    plane_z: np.ndarray) -> np.ndarray:
    """The window weight W of each segment between planes: exp(-zeta) at the segment's middle
    (at the deepest tally depth for the segments below it; no lower than at MAX_ATTENUATION_DEPTHS);
    1 everywhere when windows are off."""
    if not windows.on:
        return np.ones(len(plane_z) - 1)
    middle = np.minimum(0.5 * (plane_z[:-1] + np.minimum(plane_z[1:], windows.deepest_m)),
                        windows.deepest_m)
    return np.exp(-np.minimum(attenuation_depths(layers, middle), MAX_ATTENUATION_DEPTHS))
