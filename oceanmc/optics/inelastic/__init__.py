"""Inelastic processes (water.inelastic; config/inelastic.py): what each takes from a
wavelength and where it puts it, packed for the kernel's inelastic channels
(kernel/channels/inelastic.py). One module per process, each with

    coefficient(settings, layer, wavelengths_nm) -> (n_wl,) 1/m
        sigma: the rate at which the process takes light from each wavelength (Raman: the
        water's b_R; fluorescence: the fluorescing absorption times the quantum yield, in
        photons), per unit of radiance and path length
    redistribution(settings, excitation_nm, emission_nm) -> (n_exc, n_emi) 1/nm
        f(l' -> l): the photons taken at l' that appear per nm at l
    phase_beta(settings) -> beta of the emission's phase function (1 + beta cos^2), 0 isotropic

and this module turns them into what the kernel multiplies (transfer).

Units. A packet's weight at a wavelength is a share of that wavelength's Ed0 (energy), and a
traced wavelength stands for the spectrum around it, linearly interpolated between the traced
wavelengths (hat functions, as HydroLight's bands stand for theirs). A process that takes x_j
(energy at l_j, per nm) emits at l_i the energy

    E_i = sum_j x_j T_ji,  T_ji = (1 / sigma_j) int hat_j(l') sigma(l') (l' / l_i) f(l' -> l_i) dl'
          x Ed0(l_j) / Ed0(l_i),

with sigma interpolated like the weights, l' / l_i the photon-to-energy factor (photons are
conserved: Raman keeps every one, fluorescence the quantum yield's share) and the Ed0 ratio
turning energy into the weight units of l_i. The integral runs on a fine grid (FINE_STEP_NM)."""
from __future__ import annotations

from dataclasses import dataclass
from importlib import import_module

import numpy as np

from ... import config as cfg
from ...config import ConfigError

FINE_STEP_NM = 0.02
# a transfer entry below this share of its row's largest is dropped (the Gaussian tails: Raman
# lines at more than 6 standard deviations, which hold less than 1e-8 of the light)
TAIL = 1e-9
# a transfer within this share of its largest entry of a product a_j b_i is taken as that
# product (factors): the rounding of its integral (about 1e-16) is far below it, the smallest
# entry of a transfer that depends on the excitation (Raman's, CDOM fluorescence's) far above
SEPARABLE_RTOL = 1e-12


@dataclass(frozen=True)
class Channel:
    """One inelastic process as the kernel's channel sees it."""
    name: str                   # its key in water.inelastic (its registry.CHANNEL name)
    phase_beta: float
    sigma: np.ndarray           # (n_layers, n_wl) 1/m
    transfer: np.ndarray        # (n_wl, n_wl): T_ji, excitation j, emission i


def _module(name: str):
    return import_module(f"{__name__}.{name}")


def hats(wavelengths_nm: np.ndarray, fine: np.ndarray) -> np.ndarray:
    """(n_wl, n_fine): the hat function of each traced wavelength on the fine grid (linear
    interpolation between traced wavelengths; none beyond them)."""
    eye = np.eye(len(wavelengths_nm))
    inside = (fine >= wavelengths_nm[0]) & (fine <= wavelengths_nm[-1])
    return np.array([np.where(inside, np.interp(fine, wavelengths_nm, row), 0.0) for row in eye])


def transfer(process, settings, wavelengths_nm: np.ndarray, sigma_shape: np.ndarray,
             ed0: np.ndarray) -> np.ndarray:
    """T (n_wl, n_wl) of the module docstring for a process whose coefficient has the spectral
    shape sigma_shape (n_wl; its layers' coefficients are multiples of it, or the shape is
    what matters between traced wavelengths: it is interpolated like the weights)."""
    wl = np.asarray(wavelengths_nm, dtype=np.float64)
    # only the shape matters: scaled to a largest value of 1, so that a tiny coefficient
    # (1e-308) neither underflows in the integral nor overflows in its inverse
    top = float(np.max(sigma_shape, initial=0.0))
    sigma_shape = sigma_shape / top if top > 0.0 else sigma_shape
    count = int(np.ceil((wl[-1] - wl[0]) / FINE_STEP_NM)) + 1
    fine = np.linspace(wl[0], wl[-1], count)
    step = fine[1] - fine[0] if count > 1 else 0.0
    weights = np.full(count, step)
    weights[[0, -1]] *= 0.5                                   # trapezoid rule
    hat = hats(wl, fine)                                      # (n_wl, n_fine)
    sigma_fine = np.interp(fine, wl, sigma_shape)
    f = process.redistribution(settings, fine, wl)            # (n_fine, n_emi) 1/nm
    energy = fine[:, None] / wl[None, :]                      # l' / l_i
    integrand = (sigma_fine * weights)[:, None] * energy * f  # (n_fine, n_emi)
    # (n_exc, n_emi), each row over its hat's support, by numpy's own loops, never BLAS, as
    # everything a scene packs: a BLAS product's sums depend on its thread count (OpenBLAS on
    # one thread and on two differed in the last bit here, so a sweep's Dask workers, whose
    # BLAS runs on one, did not reproduce a single run of the same point bit for bit; a user's
    # review, 2026-11-29)
    out = np.zeros((len(wl), integrand.shape[1]))
    for j, row in enumerate(hat):
        support = np.flatnonzero(row)
        if len(support):
            part = slice(support[0], support[-1] + 1)
            out[j] = np.einsum("f,fi->i", row[part], integrand[part])
    per_sigma = np.divide(1.0, sigma_shape, out=np.zeros_like(sigma_shape),
                          where=sigma_shape > 0.0)
    out *= per_sigma[:, None] * ed0[:, None] / ed0[None, :]
    # the lines' far tails (below TAIL of a row's largest entry) are dropped, so that each
    # row is a band the kernel reads alone (band), and so are whole rows below TAIL of the
    # transfer's largest entry: excitations whose lines fall beyond the grid, of which only
    # those tails reach it (Raman from 590 nm up on a 340-700 nm grid: a third of the rows,
    # each read at every collision, none above 1e-12 of the largest)
    rows = out.max(axis=1, keepdims=True)
    out[(out < TAIL * rows) | (rows < TAIL * out.max(initial=0.0))] = 0.0
    return out


def factors(transfer: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """(a, b) with T_ji = a_j b_i to SEPARABLE_RTOL of T's largest entry, when every row is a
    multiple of one (fluorescence's: its emission spectrum does not depend on the excitation
    wavelength, and the tails are cut at a share of each row's largest entry, so every row
    keeps the same columns); else None. The kernel then emits E_i = b_i sum_j x_j a_j."""
    if transfer.size == 0 or transfer.max() <= 0.0:
        return None
    row, column = np.unravel_index(np.argmax(transfer), transfer.shape)
    b = transfer[row] / transfer[row, column]
    a = transfer[:, column].copy()
    if np.abs(transfer - np.outer(a, b)).max() > SEPARABLE_RTOL * transfer.max():
        return None
    return a, b


def band(transfer: np.ndarray) -> np.ndarray:
    """(n_wl, 2): each excitation row's first emission column with light and the one after
    its last (0, 0 for a row that emits nothing)."""
    out = np.zeros((transfer.shape[0], 2), dtype=np.int64)
    for j, row in enumerate(transfer):
        lit = np.nonzero(row > 0.0)[0]
        if len(lit):
            out[j] = lit[0], lit[-1] + 1
    return out


def channels(config: cfg.SceneConfig, layers: list, ed0: np.ndarray) -> list[Channel]:
    """The scene's inelastic channels, in channel order (config/inelastic.py PROCESSES)."""
    inelastic = config.water.inelastic
    if inelastic is None or not inelastic.processes():
        return []
    wl = config.wavelengths
    ed0 = np.asarray(ed0, dtype=np.float64)
    if not (ed0 > 0.0).all():
        at = wl[np.argmin(ed0 > 0.0)]
        raise ConfigError(f"illumination: Ed0 is 0 at {at:g} nm; water.inelastic moves light "
                          "between wavelengths, whose weights are shares of each wavelength's "
                          "Ed0: allowed: Ed0 > 0 at every traced wavelength")
    out = []
    for name, settings in inelastic.processes():
        process = _module(name)
        sigma = np.array([process.coefficient(settings, layer, wl) for layer in layers])
        shape = sigma.max(axis=0)
        out.append(Channel(name, process.phase_beta(settings), sigma,
                           transfer(process, settings, wl, shape, ed0)))
    return out


def extra_attenuation(config: cfg.SceneConfig) -> np.ndarray | None:
    """(n_wl,) 1/m that the processes add to every layer's absorption (Raman scattering takes
    light out of the water's elastic field; fluorescence takes light that a constituent has
    already absorbed), or None."""
    inelastic = config.water.inelastic
    if inelastic is None or not inelastic.processes():
        return None
    total = np.zeros(len(config.wavelengths))
    for name, settings in inelastic.processes():
        total += _module(name).loss(settings, config.wavelengths)
    return total
