"""Case-1 phytoplankton and the particles that covary with chlorophyll (Chl, mg/m3).

Absorption: a_ph(lambda) = A_phi(lambda) Chl^E_phi(lambda) (Bricaud et al. 1998, J. Geophys. Res.
103, 31033; the 2-nm table of A_phi, E_phi, 400-700 nm, in oceanmc/data; continued beyond it by
bricaud()). It is all phytoplankton absorption, so all of it may fluoresce (optics/inelastic/).
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

BRICAUD = "chlorophyll_absorption_bricaud_1998.csv"


# the table span whose log-slope continues a Bricaud coefficient pair beyond each end of the table
EDGE_NM = 10.0


def _coefficients(wavelengths_nm: np.ndarray, a_column: str, e_column: str
                  ) -> tuple[np.ndarray, np.ndarray]:
    """A and E of one Bricaud column pair, interpolated linearly in the table (400-700 nm)."""
    table = packaged(BRICAUD)
    nodes = table["wavelength_nm"]
    return (np.interp(wavelengths_nm, nodes, table[a_column]),
            np.interp(wavelengths_nm, nodes, table[e_column]))


def bricaud(chl: float, wavelengths_nm: np.ndarray, a_column: str = "A_phi",
            e_column: str = "E_phi") -> np.ndarray:
    """A Chl^E (1/m) at any wavelength, Chl > 0: the Bricaud et al. (1998) table inside
    400-700 nm (A_phi, E_phi: phytoplankton; A_p, E_p: all particles), continued outside
    exponentially with the log-slope the table itself has over its last EDGE_NM at that Chl
    (in logarithms, which do not underflow), never held flat. Bricaud et al. publish no
    extension; this continuation is oceanmc's (HydroLight extends the table with a data file
    whose numbers are not published): in the red the absorption falls on, as it does beyond
    the 676 nm peak; in the ultraviolet (350-400 nm) it falls slowly (a_phi(350) = 0.7
    a_phi(400) at Chl 1), where CDOM, exponential everywhere, already outweighs it."""
    nodes = packaged(BRICAUD)["wavelength_nm"]
    low, high = float(nodes[0]), float(nodes[-1])
    wl = np.asarray(wavelengths_nm, dtype=np.float64)
    a_coef, e_coef = _coefficients(np.clip(wl, low, high), a_column, e_column)
    out = a_coef * chl ** e_coef
    for edge, inner, outside in ((low, low + EDGE_NM, wl < low), (high, high - EDGE_NM, wl > high)):
        if outside.any():
            a_pair, e_pair = _coefficients(np.array([edge, inner]), a_column, e_column)
            log_pair = np.log(a_pair) + e_pair * math.log(chl)     # ln a at edge and inner
            slope = (log_pair[0] - log_pair[1]) / (edge - inner)  # d ln a / d lambda
            out[outside] = np.exp(log_pair[0] + slope * (wl[outside] - edge))
    return out


def absorption(chl: float, wavelengths_nm: np.ndarray) -> np.ndarray:
    """a_ph (1/m): A_phi Chl^E_phi (Bricaud et al. 1998), continued beyond 400-700 nm
    (bricaud); 0 without chlorophyll."""
    if chl <= 0.0:
        return np.zeros(len(wavelengths_nm))
    return bricaud(chl, wavelengths_nm)


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
