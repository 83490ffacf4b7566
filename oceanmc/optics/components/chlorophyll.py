"""Case-1 phytoplankton and the particles that covary with chlorophyll (Chl, mg/m3).

Absorption: a_ph(lambda) = A_phi(lambda) Chl^E_phi(lambda) (Bricaud et al. 1998, J. Geophys. Res.
103, 31033; the 2-nm table of A_phi, E_phi, 400-700 nm, in oceanmc/data), with Vasilkov et al.
(2005)'s ultraviolet shape below 400 nm (phytoplankton_absorption). It is all phytoplankton
absorption, so all of it may fluoresce (optics/inelastic/).
Scattering: b_p(lambda) = 0.416 Chl^0.766 (550 / lambda) (Morel & Maritorena 2001, J. Geophys.
Res. 106, 7163, after Loisel & Morel 1998).
Backscatter fraction: bb_p/b_p = 0.002 + 0.01 (0.5 - 0.25 log10 Chl) (lambda / 550)^nu, with
nu = 0.5 (log10 Chl - 0.3) for Chl < 2 mg/m3 and nu = 0 above (Morel et al. 2002, Appl. Opt. 41,
6289), carried by a Fournier-Forand phase function with that bb/b (Mobley et al. 2002).
Only what is proportional to Chl's pigments is here: CDOM is a component of its own."""
from __future__ import annotations

import math

import numpy as np

from ..tables import packaged
from . import Contribution, fournier_forand_by_ratio

BRICAUD = "chlorophyll_absorption_bricaud_1998.csv"            # A_p, E_p, A_phi, E_phi: 400-700 nm
HYDROLIGHT_TAILS = "particle_absorption_hydrolight_mid_uv.csv"  # A_p, E_p: 300-398, 715-1000 nm
VASILKOV = "phytoplankton_absorption_uv_vasilkov_2005.csv"      # a*_ph = A Chl^-B: 300-400 nm

TABLE_LOW_NM, TABLE_HIGH_NM = 400.0, 700.0        # Bricaud et al. (1998)'s range
UV_LOW_NM = 300.0                                  # where the ultraviolet tables start
# the span whose log-slope continues the particle table below UV_LOW_NM
EDGE_NM = 10.0


def _particle_table(chl: float, wavelengths_nm: np.ndarray) -> np.ndarray:
    """A_p Chl^E_p at 300-1000 nm: Bricaud et al. (1998) inside 400-700 nm, HydroLight's
    coefficient file of medium UV absorption (AEmidUVabs) outside it (0 from 720 nm; beyond
    1000 nm its last row, 0)."""
    table, tails = packaged(BRICAUD), packaged(HYDROLIGHT_TAILS)
    below, above = tails["wavelength_nm"] < TABLE_LOW_NM, tails["wavelength_nm"] > TABLE_HIGH_NM

    def joined(tail_column: str, table_column: str) -> np.ndarray:
        return np.concatenate([tails[tail_column][below], table[table_column],
                               tails[tail_column][above]])
    nodes = joined("wavelength_nm", "wavelength_nm")
    return (np.interp(wavelengths_nm, nodes, joined("A_p", "A_p"))
            * chl ** np.interp(wavelengths_nm, nodes, joined("E_p", "E_p")))


def particle_absorption(chl: float, wavelengths_nm: np.ndarray) -> np.ndarray:
    """a_p (1/m), all particles, Chl > 0: A_p Chl^E_p, Bricaud et al. (1998) at 400-700 nm and
    HydroLight's new Case 1 model's coefficients of medium ultraviolet absorption outside it
    (Mobley, Ocean Optics Web Book, AEmidUVabs.txt: 300-1000 nm, 0 from 720 nm), so that
    case1's particles are HydroLight's in the ultraviolet too; below 300 nm continued
    exponentially with the log-slope the table has over its first EDGE_NM (oceanmc's own rule:
    no published model reaches below 300 nm; never held flat)."""
    wl = np.asarray(wavelengths_nm, dtype=np.float64)
    out = _particle_table(chl, np.maximum(wl, UV_LOW_NM))
    below = wl < UV_LOW_NM
    if below.any():
        edge, inner = _particle_table(chl, np.array([UV_LOW_NM, UV_LOW_NM + EDGE_NM]))
        if edge > 0.0 and inner > 0.0:   # (both 0 where Chl^E underflows)
            slope = math.log(edge / inner) / -EDGE_NM        # d ln a / d lambda
            out[below] = edge * np.exp(slope * (wl[below] - UV_LOW_NM))
        else:
            out[below] = 0.0
    return out


def phytoplankton_absorption(chl: float, wavelengths_nm: np.ndarray) -> np.ndarray:
    """a_ph (1/m), Chl > 0: A_phi Chl^E_phi (Bricaud et al. 1998) at 400-700 nm; below 400 nm
    with the spectral shape of Vasilkov et al. (2005, Appl. Opt. 44, 2863, Table 1: a*_ph = A
    Chl^-B, 300-400 nm, which rises into the ultraviolet: 1.16 a_ph(400) at 350 nm at Chl 0.03,
    1.36 at Chl 1), joined to Bricaud's a_ph at 400 nm (the table's own A(400) is twice
    Bricaud's A_phi(400): other samples); above 700 nm and below 300 nm with the shape of the
    particles' absorption (particle_absorption: HydroLight's, which falls to 0 at 720 nm, and
    its continuation), joined at 700 and 300 nm, so that below 300 nm its share of a_p stays
    what it is there (the two tables' slopes, continued apart, would put a_ph above a_p below
    190-290 nm)."""
    wl = np.asarray(wavelengths_nm, dtype=np.float64)
    table = packaged(BRICAUD)
    nodes, inside = table["wavelength_nm"], np.clip(wl, TABLE_LOW_NM, TABLE_HIGH_NM)
    out = np.interp(inside, nodes, table["A_phi"]) * chl ** np.interp(inside, nodes,
                                                                      table["E_phi"])
    uv = wl < TABLE_LOW_NM
    if uv.any():
        vasilkov = packaged(VASILKOV)

        def shape(at: np.ndarray) -> np.ndarray:     # a*_ph = A Chl^-B (Vasilkov et al. 2005)
            return (np.interp(at, vasilkov["wavelength_nm"], vasilkov["A"])
                    * chl ** -np.interp(at, vasilkov["wavelength_nm"], vasilkov["B"]))
        out[uv] *= shape(np.maximum(wl[uv], UV_LOW_NM)) / shape(np.array([TABLE_LOW_NM]))
    for edge_nm, beyond in ((TABLE_HIGH_NM, wl > TABLE_HIGH_NM), (UV_LOW_NM, wl < UV_LOW_NM)):
        if beyond.any():   # (out holds a_ph at the edge there)
            edge = particle_absorption(chl, np.array([edge_nm]))[0]
            # (0 where Chl^E underflows at the edge, as a_ph there does)
            out[beyond] = out[beyond] * (particle_absorption(chl, wl[beyond]) / edge) \
                if edge > 0.0 else 0.0
    return out


def absorption(chl: float, wavelengths_nm: np.ndarray) -> np.ndarray:
    """a_ph (1/m) of the chlorophyll component (phytoplankton_absorption); 0 without
    chlorophyll."""
    if chl <= 0.0:
        return np.zeros(len(wavelengths_nm))
    return phytoplankton_absorption(chl, wavelengths_nm)


def scattering(chl: float, wavelengths_nm: np.ndarray) -> np.ndarray:
    return 0.416 * chl ** 0.766 * (550.0 / wavelengths_nm)


def backscatter_ratio(chl: float, wavelengths_nm: np.ndarray) -> np.ndarray:
    log_chl = math.log10(chl)
    nu = 0.5 * (log_chl - 0.3) if chl < 2.0 else 0.0
    return 0.002 + 0.01 * (0.5 - 0.25 * log_chl) * (wavelengths_nm / 550.0) ** nu


def iops(component, wavelengths_nm: np.ndarray, where: str) -> Contribution:
    chl = float(component.chl_mg_m3)
    a = absorption(chl, wavelengths_nm)
    if chl <= 0.0:
        phases, weights = fournier_forand_by_ratio(np.full(len(wavelengths_nm), 0.0183))
        return Contribution(a, np.zeros_like(a), phases, weights, a_phytoplankton=a)
    phases, weights = fournier_forand_by_ratio(backscatter_ratio(chl, wavelengths_nm))
    return Contribution(a, scattering(chl, wavelengths_nm), phases, weights, a_phytoplankton=a)
