"""Chlorophyll fluorescence (DESIGN.md 7.4; Mobley 1994, Light and Water, 5.14; HydroLight's
defaults): of the photons that phytoplankton absorb between excitation_range_nm (370-690 nm),
the share quantum_yield (0.02; published 0.005-0.07) is re-emitted isotropically with the
Gaussian spectrum of standard deviation sigma_nm (10.6 nm) about peak_nm (685 nm), per nm of
emission wavelength, cut at 6 standard deviations. The absorption is the phytoplankton's (the chlorophyll component's a_ph,
the case1 component's a_phi, LayerIOPs.a_phytoplankton): it is already in the layer's
absorption, so fluorescence adds no loss; the energy emitted is the absorbed energy times the
yield times l' / l (optics/inelastic transfer)."""
from __future__ import annotations

import math

import numpy as np


def coefficient(settings, layer, wavelengths_nm: np.ndarray) -> np.ndarray:
    """quantum yield x a_phytoplankton inside the excitation range, 0 outside (1/m)."""
    if layer.a_phytoplankton is None:
        return np.zeros(len(wavelengths_nm))
    low, high = settings.excitation_range_nm
    wl = np.asarray(wavelengths_nm, dtype=np.float64)
    return np.where((wl >= low) & (wl <= high),
                    settings.quantum_yield * layer.a_phytoplankton, 0.0)


def loss(settings, wavelengths_nm: np.ndarray) -> np.ndarray:
    return np.zeros(len(wavelengths_nm))


def redistribution(settings, excitation_nm: np.ndarray, emission_nm: np.ndarray) -> np.ndarray:
    """f(l' -> l) (1/nm): the emission Gaussian, whatever the excitation wavelength. The
    excitation range is in the coefficient, which is interpolated linearly between traced
    wavelengths (optics/inelastic transfer), so that what it takes between a traced wavelength
    inside the range and one outside is re-emitted too (a redistribution cut at the range
    dropped 39% of an edge wavelength's take on a 10 nm grid: photons lost)."""
    exc = np.asarray(excitation_nm, dtype=np.float64)
    emi = np.asarray(emission_nm, dtype=np.float64)
    offset = (emi - settings.peak_nm) / settings.sigma_nm
    # cut at 6 standard deviations (1.5e-8 of the peak), as config.inelastic emits_at
    gauss = np.where(np.abs(offset) <= 6.0, np.exp(-0.5 * offset ** 2), 0.0) \
        / (settings.sigma_nm * math.sqrt(2.0 * math.pi))
    return np.ones(len(exc))[:, None] * gauss[None, :]


def phase_beta(settings) -> float:
    return 0.0
