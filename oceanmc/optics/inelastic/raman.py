"""Raman scattering by water (DESIGN.md 7.4; ../shared/data/raman_coxmunk_notes.md).

b_R(l') = b488 (488 / l')^n, 1/m at the excitation wavelength l' (HydroLight's default b488 =
2.6e-4, n = 5.5, energy units; Bartlett et al. 1998, Appl. Opt. 37, 3324: 2.7e-4 and 5.3 in
photon units). It is the fraction of the light at l' that Raman scattering takes per metre,
the same fraction of energy as of photons; every photon taken reappears at the emission
wavelength l with energy times l' / l (packed by optics/inelastic transfer). It is added to
every layer's absorption at l' (loss), since pure-water absorption tables hold only what water
truly absorbs.

Wavenumber redistribution: Walrafen's (1967, J. Chem. Phys. 47, 114) four Gaussians in the
wavenumber shift dk = 1e7/l' - 1e7/l (1/cm): weights 0.41, 0.39, 0.10, 0.10, centres 3250, 3425,
3530, 3625, full widths at half maximum 210, 175, 140, 140 (Mobley 1994, Light and Water, Table
5.3), normalised to 1 over dk; per nm of emission f(l' -> l) = (1e7 / l^2) g(dk).

Phase function (1 + beta cos^2 psi) / (4 pi (1 + beta / 3)), beta = 0.55: 0.067 (1 + 0.55 cos^2)
(Mobley 1994, 5.13; from the depolarisation ratio 0.17)."""
from __future__ import annotations

import math

import numpy as np

WEIGHTS = np.array([0.41, 0.39, 0.10, 0.10])
CENTRES = np.array([3250.0, 3425.0, 3530.0, 3625.0])      # 1/cm
FWHM = np.array([210.0, 175.0, 140.0, 140.0])             # 1/cm
SIGMAS = FWHM / (2.0 * math.sqrt(2.0 * math.log(2.0)))


def coefficient_at(settings, wavelengths_nm: np.ndarray) -> np.ndarray:
    """b_R (1/m) at each excitation wavelength."""
    return settings.b488_per_m * (488.0 / np.asarray(wavelengths_nm, dtype=np.float64)) \
        ** settings.exponent


def coefficient(settings, layer, wavelengths_nm: np.ndarray) -> np.ndarray:
    """The water's Raman coefficient, the same in every layer."""
    return coefficient_at(settings, wavelengths_nm)


def loss(settings, wavelengths_nm: np.ndarray) -> np.ndarray:
    return coefficient_at(settings, wavelengths_nm)


def shift_density(shift: np.ndarray) -> np.ndarray:
    """g(dk) (cm): Walrafen's four Gaussians, integrating to 1 over dk."""
    z = (np.asarray(shift)[..., None] - CENTRES) / SIGMAS
    return (WEIGHTS / (SIGMAS * math.sqrt(2.0 * math.pi)) * np.exp(-0.5 * z * z)).sum(axis=-1) \
        / WEIGHTS.sum()


def redistribution(settings, excitation_nm: np.ndarray, emission_nm: np.ndarray) -> np.ndarray:
    """f(l' -> l) (1/nm), (n_exc, n_emi)."""
    exc = np.asarray(excitation_nm, dtype=np.float64)[:, None]
    emi = np.asarray(emission_nm, dtype=np.float64)[None, :]
    return 1e7 / emi ** 2 * shift_density(1e7 / exc - 1e7 / emi)


def phase_beta(settings) -> float:
    return float(settings.phase_beta)
