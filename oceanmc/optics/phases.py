"""The backscatter fraction bb/b of each schema phase function (config/phase.py)."""
from __future__ import annotations

import math

from .. import config as cfg
from ..scene import phase_tables


def henyey_greenstein_bb(g: float) -> float:
    """Backscatter fraction of Henyey-Greenstein: the integral of its density over the backward
    hemisphere, (1 - g)/(2g) ((1 + g)/sqrt(1 + g^2) - 1) (Toublanc 1996, Appl. Opt. 35, 3270,
    Eq. 6); 1/2 as g -> 0."""
    if abs(g) < 1e-8:
        return 0.5
    return (1.0 - g) / (2.0 * g) * ((1.0 + g) / math.sqrt(1.0 + g * g) - 1.0)


BACKSCATTER = {
    "isotropic": lambda phase: 0.5,
    "rayleigh": lambda phase: 0.5,      # symmetric about 90 deg
    "pure_water": lambda phase: 0.5,    # symmetric about 90 deg
    "henyey_greenstein": lambda phase: henyey_greenstein_bb(phase.g),
    "two_term_hg": lambda phase: (phase.alpha * henyey_greenstein_bb(phase.g1)
                                  + (1.0 - phase.alpha) * henyey_greenstein_bb(phase.g2)),
    "fournier_forand": lambda phase: phase.bb_ratio,
    "petzold": lambda phase: phase_tables.moments(*phase_tables.petzold_table()[:2])[1],
    "table": lambda phase: phase_tables.moments(*phase_tables.user_table(phase.file)[:2])[1],
}


def backscatter_fraction(phase: cfg.BasicPhase) -> float:
    """bb/b of one (non-mixture) phase function, as the kernel samples it."""
    return float(BACKSCATTER[phase.model](phase))
