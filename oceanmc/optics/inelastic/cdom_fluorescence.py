"""CDOM fluorescence (DESIGN.md 7.4): Hawes's (1992) fluorescence quantum efficiency function of
a fulvic acid (his sample FA7), as HydroLight uses it (Mobley & Sundman 2013, HydroLight 5.2
Technical Documentation, Sequoia Scientific; Mobley, Ocean Optics Web Book, "CDOM
fluorescence", https://www.oceanopticsbook.info/view/scattering/level-2/cdom-fluorescence):

    eta_Y(l', l) = A0(l') exp{-[(1/l - A1/l' - B1) / (0.6 (A2/l' + B2))]^2}   (1/nm)

the photons emitted per nm at the emission wavelength l per photon CDOM absorbs at the
excitation wavelength l' (both in nm). Hawes (1992, Table 3): A1 = 0.470, A2 = 0.407,
B1 = 8.077e-4 1/nm, B2 = -4.57e-4 1/nm, and A0(l') at 310, 330, .., 490 nm; HydroLight extends
A0 with 4.00e-5 at 510 nm, 1.00e-5 at 530 nm and 0 at 550 nm (and 0 below 310 nm), linear in
between. Emission is isotropic.

Emission only at l >= l' (re-emission at a longer wavelength, as the Web Book describes it):
the Gaussian in 1/l reaches below l' (0.3% of it for l' = 310 nm, 3% for 490 nm, 7% near
550 nm), which is not emitted. It is counted up to CDOM_EMISSION_MAX_NM (1000 nm, where
HydroLight's range ends; beyond it lies less than 0.1% of the emission of 310 nm excitation and
less for longer ones: tests/test_cdom_fluorescence.py). The quantum yield, photons emitted per
photon absorbed, is then

    Phi(l') = int_{l'}^{1000 nm} eta_Y(l', l) dl     (0.94-1.90% for 310-490 nm, then to 0 at 550)

and the process takes sigma = a_CDOM(l') Phi(l') (in photons: the kernel re-emits every photon
it takes) and spreads it as f(l' -> l) = eta_Y / Phi, normalised per excitation wavelength, in
which A0 cancels. a_CDOM is the layer's CDOM absorption (LayerIOPs.a_cdom: the `cdom`
component's a_g and the CDOM of `case1`); it is already in the layer's absorption, so the
process adds no loss."""
from __future__ import annotations

import numpy as np

from ...config.inelastic import CDOM_EMISSION_MAX_NM, CDOM_EXCITATION_RANGE_NM

A1 = 0.470
A2 = 0.407
B1 = 8.077e-4             # 1/nm
# Hawes (1992) Table 3; one secondary source prints -4.18e-4, but -4.57e-4 is what three
# independent implementations of HydroLight's model use
B2 = -4.57e-4             # 1/nm
WIDTH_FACTOR = 0.6
# A0(l') (1/nm): Hawes (1992) at 310-490 nm, then HydroLight's extension at 510, 530, 550 nm
A0_EXCITATION_NM = np.array([310.0, 330.0, 350.0, 370.0, 390.0, 410.0, 430.0, 450.0, 470.0,
                             490.0, 510.0, 530.0, 550.0])
A0_PER_NM = 1e-5 * np.array([5.18, 6.34, 8.00, 9.89, 9.39, 10.48, 12.59, 13.48, 13.61, 9.27,
                             4.00, 1.00, 0.0])
# Gauss-Legendre nodes for the emission integral in u = 1/l, where the integrand is a Gaussian
# times 1/u^2, smooth over the interval: 32 nodes give it to rounding (within 1e-14 of 400
# nodes at 310-550 nm, and of a 0.005 nm trapezoid in l to its own error, 1e-10)
LEGENDRE = np.polynomial.legendre.leggauss(32)


def a0(excitation_nm: np.ndarray) -> np.ndarray:
    """A0(l') (1/nm), linear between the tabulated excitation wavelengths, 0 outside them."""
    return np.interp(excitation_nm, A0_EXCITATION_NM, A0_PER_NM, left=0.0, right=0.0)


def _centre_and_width(excitation_nm: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The Gaussian's centre A1/l' + B1 and width 0.6 (A2/l' + B2) in 1/l (1/nm), those of
    the nearest end of 310-550 nm outside it (the width would vanish at 891 nm)."""
    exc = np.clip(excitation_nm, *CDOM_EXCITATION_RANGE_NM)
    return A1 / exc + B1, WIDTH_FACTOR * (A2 / exc + B2)


def emission_shape(excitation_nm: np.ndarray, emission_nm: np.ndarray) -> np.ndarray:
    """eta_Y / A0 (n_exc, n_emi): the exponential of the formula, 0 outside
    l' <= l <= CDOM_EMISSION_MAX_NM."""
    exc = np.asarray(excitation_nm, dtype=np.float64)[:, None]
    emi = np.asarray(emission_nm, dtype=np.float64)[None, :]
    centre, width = _centre_and_width(exc)
    inside = (emi >= exc) & (emi <= CDOM_EMISSION_MAX_NM)
    return np.where(inside, np.exp(-((1.0 / emi - centre) / width) ** 2), 0.0)


def quantum_efficiency(excitation_nm: np.ndarray, emission_nm: np.ndarray) -> np.ndarray:
    """eta_Y(l', l) (1/nm), (n_exc, n_emi)."""
    return a0(np.asarray(excitation_nm, dtype=np.float64))[:, None] \
        * emission_shape(excitation_nm, emission_nm)


def shape_integral(excitation_nm: np.ndarray) -> np.ndarray:
    """int emission_shape(l', l) dl over l' <= l <= CDOM_EMISSION_MAX_NM (nm), by
    Gauss-Legendre in u = 1/l (dl = du / u^2), where the shape is a Gaussian."""
    exc = np.asarray(excitation_nm, dtype=np.float64)
    x, weights = LEGENDRE
    low, high = 1.0 / CDOM_EMISSION_MAX_NM, 1.0 / exc[:, None]
    half = 0.5 * (high - low)
    u = low + half * (x[None, :] + 1.0)
    centre, width = _centre_and_width(exc[:, None])
    integrand = np.exp(-((u - centre) / width) ** 2) / (u * u)
    # (numpy's own sum, not BLAS's, whose result depends on its threads: inelastic transfer)
    return np.where(exc < CDOM_EMISSION_MAX_NM, np.einsum("ek,k->e", half * integrand, weights),
                    0.0)


def quantum_yield(settings, excitation_nm: np.ndarray) -> np.ndarray:
    """Phi(l') = a0_scale int eta_Y dl (photons emitted per photon CDOM absorbs) inside the
    excitation range, 0 outside."""
    exc = np.asarray(excitation_nm, dtype=np.float64)
    low, high = settings.excitation_range_nm
    inside = (exc >= low) & (exc <= high)
    return np.where(inside, settings.a0_scale * a0(exc) * shape_integral(exc), 0.0)


def coefficient(settings, layer, wavelengths_nm: np.ndarray) -> np.ndarray:
    """Phi x a_CDOM (1/m): the photons the process takes; 0 in a layer without CDOM."""
    if layer.a_cdom is None:
        return np.zeros(len(wavelengths_nm))
    return quantum_yield(settings, wavelengths_nm) * layer.a_cdom


def loss(settings, wavelengths_nm: np.ndarray) -> np.ndarray:
    return np.zeros(len(wavelengths_nm))


def redistribution(settings, excitation_nm: np.ndarray, emission_nm: np.ndarray) -> np.ndarray:
    """f(l' -> l) = eta_Y / Phi (1/nm), integrating to 1 over the emission, at every
    excitation wavelength below CDOM_EMISSION_MAX_NM: the excitation range is in the
    coefficient, which is interpolated linearly between traced wavelengths (optics/inelastic
    transfer), so that what it takes between a traced wavelength inside the range and one
    outside is re-emitted too (a redistribution cut at the range would drop up to half of an
    edge wavelength's take), with the shape of the range's nearest end outside 310-550 nm."""
    exc = np.asarray(excitation_nm, dtype=np.float64)
    total = shape_integral(exc)
    per_total = np.divide(1.0, total, out=np.zeros_like(total), where=total > 0.0)
    return per_total[:, None] * emission_shape(exc, emission_nm)


def phase_beta(settings) -> float:
    return 0.0
