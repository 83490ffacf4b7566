"""Inelastic light: `water.inelastic: {raman: {...}, chlorophyll_fluorescence: {...},
cdom_fluorescence: {...}}`, each optional, an empty mapping the published defaults (DESIGN.md
7.4; optics/inelastic/ computes them, kernel/channels/inelastic.py moves the light).

The wavelength grid must hold the light that excites what is reported: Raman light at 400 nm
comes from about 352 nm, chlorophyll fluorescence is excited from 370 nm, CDOM fluorescence from
310 nm. transport_grid() gives
the grid the run traces: the requested wavelengths, extended below them down to the lowest
excitation wavelength needed and with no gap wider than max_step_nm in the excitation range.
The run then reports every traced wavelength and its summary names those it added."""
from __future__ import annotations

import math
from typing import Annotated, Optional

import numpy as np
from pydantic import Field, model_serializer, model_validator

from .base import _Strict

Positive = Annotated[float, Field(gt=0.0, allow_inf_nan=False)]

# outside these wavenumber shifts (1/cm; centres 3250-3625, widths 140-210 FWHM: the outer
# lines at +-5 standard deviations) Walrafen's four Gaussians hold less than 1e-6 of the light
# and fall to 2e-6 of their peak
RAMAN_SHIFT_RANGE = (2800.0, 3950.0)
# CDOM fluorescence (optics/inelastic/cdom_fluorescence.py): Hawes (1992) measured the
# excitation 310-490 nm, HydroLight extends A0 to 0 at 550 nm; its emission is counted up to
# 1000 nm, where HydroLight's wavelength range ends
CDOM_EXCITATION_RANGE_NM = (310.0, 550.0)
CDOM_EMISSION_MAX_NM = 1000.0


class Raman(_Strict):
    """Raman scattering by water molecules. b_R(l') = b488_per_m (488 / l')^exponent, the loss
    at the excitation wavelength l' (HydroLight's default 2.6e-4 1/m and 5.5, energy units;
    Bartlett et al. 1998, Appl. Opt. 37, 3324, measured 2.7e-4 and 5.3 in photon units);
    Walrafen's (1967) four-Gaussian wavenumber redistribution; phase function
    (1 + phase_beta cos^2) normalised, phase_beta = (1 - rho) / (1 + 3 rho) = 0.55 for the
    depolarisation ratio rho = 0.17 (Mobley 1994, Light and Water, 5.13)."""
    b488_per_m: Annotated[float, Field(ge=0.0, le=1.0, allow_inf_nan=False)] = 2.6e-4
    exponent: Annotated[float, Field(ge=0.0, le=10.0, allow_inf_nan=False)] = 5.5
    phase_beta: Annotated[float, Field(ge=0.0, le=1.0, allow_inf_nan=False)] = 0.55

    def excitation_nm(self, emission_nm: float) -> tuple[float, float]:
        low, high = RAMAN_SHIFT_RANGE
        return 1e7 / (1e7 / emission_nm + high), 1e7 / (1e7 / emission_nm + low)

    def emits_at(self, emission_nm: float) -> bool:
        return True


class ChlorophyllFluorescence(_Strict):
    """Chlorophyll fluorescence: a share quantum_yield of the photons that phytoplankton
    absorb between excitation_nm[0] and excitation_nm[1] is re-emitted isotropically, in a
    Gaussian of standard deviation sigma_nm about peak_nm (HydroLight's defaults: 0.02, 685 nm,
    10.6 nm, 370-690 nm; published yields 0.005-0.07; Mobley 1994, Light and Water, 5.14)."""
    quantum_yield: Annotated[float, Field(ge=0.0, le=1.0, allow_inf_nan=False)] = 0.02
    peak_nm: Annotated[float, Field(ge=300.0, le=1000.0, allow_inf_nan=False)] = 685.0
    sigma_nm: Annotated[float, Field(ge=0.1, le=100.0, allow_inf_nan=False)] = 10.6
    excitation_range_nm: tuple[Positive, Positive] = (370.0, 690.0)

    @model_validator(mode="after")
    def _ordered(self) -> "ChlorophyllFluorescence":
        low, high = self.excitation_range_nm
        if not low < high:
            raise ValueError(f"excitation_range_nm = [{low}, {high}]; allowed: a lower bound "
                             "below the upper one, in nm")
        return self

    def excitation_nm(self, emission_nm: float) -> tuple[float, float]:
        return self.excitation_range_nm

    def emits_at(self, emission_nm: float) -> bool:
        """Whether the emission Gaussian reaches emission_nm (within 6 standard deviations)."""
        return abs(emission_nm - self.peak_nm) <= 6.0 * self.sigma_nm


class CdomFluorescence(_Strict):
    """CDOM fluorescence after Hawes (1992), as HydroLight uses it (optics/inelastic/
    cdom_fluorescence.py has the formula and its constants): of the photons CDOM absorbs at
    l' in excitation_range_nm, the quantum yield Phi(l') (0.94-1.90% from 310 to 490 nm,
    falling to 0 at 550 nm) is re-emitted isotropically at l' <= l <= 1000 nm. a0_scale
    multiplies Hawes's quantum efficiency (his A0 table) for a CDOM that fluoresces more or
    less than his fulvic acid; at most 50, which keeps Phi below 1 (0.95).
    excitation_range_nm: where absorbed light fluoresces, within Hawes's A0 table and
    HydroLight's extension of it, 310-550 nm (the default: all of it; below 420 nm pure-water
    absorption comes from Morel et al. 2007 and Jonasz & Fournier 2007, tabulated down to
    180 nm)."""
    a0_scale: Annotated[float, Field(ge=0.0, le=50.0, allow_inf_nan=False)] = 1.0
    excitation_range_nm: tuple[Positive, Positive] = CDOM_EXCITATION_RANGE_NM

    @model_validator(mode="after")
    def _within_hawes(self) -> "CdomFluorescence":
        low, high = self.excitation_range_nm
        lowest, highest = CDOM_EXCITATION_RANGE_NM
        if not lowest <= low < high <= highest:
            raise ValueError(f"excitation_range_nm = [{low:g}, {high:g}]; allowed: an "
                             f"increasing pair within [{lowest:g}, {highest:g}] nm, where "
                             "Hawes's (1992) quantum efficiency is tabulated (with HydroLight's "
                             "extension to 550 nm)")
        return self

    def excitation_nm(self, emission_nm: float) -> tuple[float, float]:
        return self.excitation_range_nm[0], min(self.excitation_range_nm[1], emission_nm)

    def emits_at(self, emission_nm: float) -> bool:
        """Emission at l comes from excitation at l' <= l, up to CDOM_EMISSION_MAX_NM."""
        return self.excitation_range_nm[0] < emission_nm <= CDOM_EMISSION_MAX_NM


class Inelastic(_Strict):
    """The inelastic processes of the water; each off unless given. max_step_nm: the widest
    gap the traced grid may have where it excites light (the excitation spectrum is
    interpolated linearly between traced wavelengths)."""
    raman: Optional[Raman] = None
    chlorophyll_fluorescence: Optional[ChlorophyllFluorescence] = None
    cdom_fluorescence: Optional[CdomFluorescence] = None
    max_step_nm: Annotated[float, Field(ge=0.5, le=50.0, allow_inf_nan=False)] = 10.0

    @model_validator(mode="before")
    @classmethod
    def _no_blank_process(cls, data):
        # `raman:` with nothing after it is YAML's null, which would turn Raman scattering off
        # while the user asked for it: refused; the stored config leaves out the processes that
        # are off (_without_processes_off), so it never writes a null here
        if isinstance(data, dict):
            if not any(name in data for name in PROCESSES):
                # (`inelastic: {}` would run the scene elastic, silently)
                raise ValueError(f"no process named: give one or more of {', '.join(PROCESSES)} "
                                 "({} for a process's published defaults), or leave "
                                 "water.inelastic out")
            for name in PROCESSES:
                if name in data and data[name] is None:
                    raise ValueError(f"{name} = null (nothing after '{name}:'): give {{}} for "
                                     "its published defaults, or leave the key out to turn it "
                                     "off")
        return data

    @model_serializer(mode="wrap")
    def _without_processes_off(self, handler):
        return {k: v for k, v in handler(self).items() if not (k in PROCESSES and v is None)}

    def processes(self) -> list[tuple[str, object]]:
        """(name, settings) of the processes that are on, in the order of their channels."""
        return [(name, getattr(self, name)) for name in PROCESSES
                if getattr(self, name) is not None]


# the processes in channel order (kernel/channels/: channel k + 1 is process k)
PROCESSES = ("raman", "chlorophyll_fluorescence", "cdom_fluorescence")


def transport_grid(requested: np.ndarray, inelastic: Inelastic) -> np.ndarray:
    """The wavelengths a run with inelastic light traces: the requested ones, and below and
    between them what the excitation of the requested ones needs (see the module)."""
    low = math.inf
    high = -math.inf
    for _, process in inelastic.processes():
        for emission in requested:
            if process.emits_at(float(emission)):
                lo, hi = process.excitation_nm(float(emission))
                low, high = min(low, lo), max(high, min(hi, float(emission)))
    if not math.isfinite(low):
        return requested
    step = inelastic.max_step_nm
    diffs = np.diff(requested)
    regular = len(requested) > 1 and np.allclose(diffs, diffs[0], rtol=1e-9) \
        and diffs[0] <= step
    below_step = float(diffs[0]) if regular else step
    nodes = list(requested)
    first = float(requested[0])
    k = 1
    while first - (k - 1) * below_step > low:
        nodes.append(first - k * below_step)
        k += 1
    nodes = np.unique(np.round(np.array(nodes, dtype=np.float64), 9))
    # no gap wider than step inside the excitation range
    filled = [nodes[0]]
    for a, b in zip(nodes[:-1], nodes[1:]):
        if b - a > step * (1.0 + 1e-9) and a < high and b > low:
            pieces = math.ceil((b - a) / step)
            filled += list(a + (b - a) * np.arange(1, pieces) / pieces)
        filled.append(b)
    return np.array(filled, dtype=np.float64)
