"""Case-1 water from chlorophyll alone (Chl, mg/m3): every non-water IOP, following HydroLight's
"new Case 1" IOP model whole (Mobley & Sundman 2013, HydroLight 5.2 Technical Documentation,
Sequoia Scientific, the IOP routine abnewcase1; Mobley, Ocean Optics Web Book, "A New IOP Model
for Case 1 Water", oceanopticsbook.info). Pure water is not in it: add {model: pure_water}.

Particles (phytoplankton and the detritus that covaries with them), absorption:
    a_p(l) = A_p(l) Chl^E_p(l)
  Bricaud et al. (1998), J. Geophys. Res. 103, 31033, total particulate absorption (the A_p, E_p
  columns of oceanmc/data/chlorophyll_absorption_bricaud_1998.csv, 400-700 nm at 2 nm). Its
  phytoplankton part is A_phi Chl^E_phi (same table); the rest, a_p - a_phi, is the detritus.
CDOM, covarying with the particles:
    a_CDOM(l) = 0.2 a_p(440) exp(-0.014 (l - 440))
  (HydroLight's f_CDOM = 0.2 and S_CDOM = 0.014 1/nm; Bricaud et al. 1998 wrote 0.2 (a_w(440) +
  a_p(440)), HydroLight drops a_w so that Chl = 0 is pure water, and so do we). It is CDOM,
  and fluoresces as the `cdom` component's does (optics/inelastic/cdom_fluorescence.py): CDOM
  fluorescence takes what CDOM absorbs, all of it (Mobley, Ocean Optics Web Book, "CDOM
  fluorescence": its inelastic scattering coefficient b_Y is a_Y).
Particle scattering (Loisel & Morel 1998 via Morel & Maritorena 2001, J. Geophys. Res. 106, 7163;
spectral shape of Morel et al. 2002, Appl. Opt. 41, 6289):
    b_p(l) = 0.416 Chl^0.766 (l / 550)^nu,
    nu = 0.5 (log10 Chl - 0.3) for 0.02 <= Chl <= 2, -1 below 0.02 (Mie theory), 0 above 2.
Backscatter: two populations (Morel et al. 2002): a share alpha = 0.855 (0.5 - 0.25 log10 Chl),
  clipped to 0..1, of b_p is small particles, the rest large. Their backscatter fractions are
  those that make the mixture's Morel et al. (2002) bb_p/b_p = 0.002 + 0.01 (0.5 - 0.25 log10
  Chl): large 0.002, small 0.002 + 0.01/0.855 = 0.01370. Each population scatters by a
  Fournier-Forand phase function with its fraction (HydroLight uses Morel's two tabulated
  small- and large-particle phase functions, which oceanmc does not ship; Fournier-Forand with
  the same bb/b is what oceanmc's other particle models use, Mobley et al. 2002).

Beyond 400-700 nm (the range of the Bricaud table): HydroLight's own coefficients for its
medium choice of ultraviolet absorption (Mobley, Ocean Optics Web Book, the new Case 1 IOP
model's AEmidUVabs.txt, 300-1000 nm: after Morrison & Nelson 2004 and Vasilkov et al. 2005
below 400 nm; 0 from 720 nm; chlorophyll.particle_absorption), continued below 300 nm with the table's own
log-slope. The living part, a_ph, is Bricaud's A_phi, E_phi with Vasilkov et al. (2005)'s
ultraviolet shape (chlorophyll.phytoplankton_absorption), held at most a_p (at Chl below about
0.002 mg/m3 the two tables would put it above a_p at 300 nm and below)."""
from __future__ import annotations

import math

import numpy as np

from . import Contribution, chlorophyll, fournier_forand_by_ratio
# a_p (1/m) at any wavelength, Chl > 0: HydroLight's Case-1 particles
from .chlorophyll import particle_absorption

F_CDOM = 0.2
S_CDOM = 0.014          # 1/nm
B550_COEF, B550_EXPONENT = 0.416, 0.766
SMALL_SHARE_COEF = 0.855
BB_LARGE = 0.002
BB_SMALL = BB_LARGE + 0.01 / SMALL_SHARE_COEF


def phytoplankton_absorption(chl: float, wavelengths_nm: np.ndarray) -> np.ndarray:
    """a_phi = A_phi Chl^E_phi (Bricaud et al. 1998), continued likewise: the living part of
    a_p, which fluoresces (optics/inelastic/), at most a_p."""
    return np.minimum(chlorophyll.phytoplankton_absorption(chl, wavelengths_nm),
                      particle_absorption(chl, wavelengths_nm))


def cdom_absorption(chl: float, wavelengths_nm: np.ndarray) -> np.ndarray:
    ap440 = particle_absorption(chl, np.array([440.0]))[0]
    return F_CDOM * ap440 * np.exp(-S_CDOM * (np.asarray(wavelengths_nm) - 440.0))


def spectral_exponent(chl: float) -> float:
    if chl > 2.0:
        return 0.0
    if chl < 0.02:
        return -1.0
    return 0.5 * (math.log10(chl) - 0.3)


def scattering(chl: float, wavelengths_nm: np.ndarray) -> np.ndarray:
    return (B550_COEF * chl ** B550_EXPONENT
            * (np.asarray(wavelengths_nm) / 550.0) ** spectral_exponent(chl))


def small_share(chl: float) -> float:
    return min(1.0, max(0.0, SMALL_SHARE_COEF * (0.5 - 0.25 * math.log10(chl))))


def iops(component, wavelengths_nm: np.ndarray, where: str) -> Contribution:
    chl = float(component.chl_mg_m3)
    n_wl = len(wavelengths_nm)
    # phases sorted by backscatter fraction: large particles (0.002) first, small (0.0137) next
    phases, _ = fournier_forand_by_ratio(np.array([BB_LARGE, BB_SMALL]))
    if chl <= 0.0:
        zero = np.zeros(n_wl)
        return Contribution(zero, zero.copy(), phases, np.tile([1.0, 0.0], (n_wl, 1)))
    a_cdom = cdom_absorption(chl, wavelengths_nm)
    alpha = small_share(chl)
    return Contribution(particle_absorption(chl, wavelengths_nm) + a_cdom,
                        scattering(chl, wavelengths_nm), phases,
                        np.tile([1.0 - alpha, alpha], (n_wl, 1)),
                        a_phytoplankton=phytoplankton_absorption(chl, wavelengths_nm),
                        a_cdom=a_cdom)
