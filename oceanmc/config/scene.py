"""SceneConfig: the whole scene, and the checks that involve more than one of its parts."""
from __future__ import annotations

import math
from typing import Annotated

import numpy as np

from pydantic import Field, PrivateAttr, field_validator, model_validator

from .base import (_Strict, allowed_numbers, non_finite_text, shown_value_error,
                   too_long_integer)
from .bottom import (Bottom, bottom_has_mirror, bottom_weight_bounded,
                     check_bottom_wavelengths, reflectance_keys)
from .estimator import AUTO_UPWARD_FRACTION, Estimator
from .illumination import Illumination
from .inelastic import transport_grid
from .surface import MAX_CAP_MSS, Surface
from .tallies import Tallies
from .water import Water
from .wavelengths import Wavelengths, check_increasing, grid

MAX_PHOTONS = 10**13
MAX_SEED = 2**63 - 1   # the seed is an int64 from here to the kernel


def readable_count(text: str) -> str:
    """A count beyond MAX_PHOTONS as a message shows it: a long integer by its first digits and
    how many there are (`9999999999... (400 digits)`, which float() makes inf), else in 3
    significant digits (`1e+20`, not 21 digits), else as written, cut (`photons` in the scene
    and `--photons` alike)."""
    digits = text.strip().lstrip("+").replace("_", "")
    if digits.isdigit() and len(digits) > 24:
        return f"{digits[:10]}... ({len(digits)} digits)"
    try:
        number = float(text)
    except ValueError:
        number = math.nan
    return f"{number:.3g}" if math.isfinite(number) else repr(text[:21] + "...")


def _shown_beyond(value: int | float, exact: bool = False) -> str:
    """A number beyond its key's range as a message shows it: by readable_count (exact, up to
    24 digits, where the bound is written exactly: seed's), or, for an integer too long for
    str(), in words."""
    try:
        digits = str(abs(value))
    except ValueError:
        return too_long_integer()
    return "-" * (value < 0) + (digits if exact and len(digits) <= 24
                                else readable_count(digits))


def _listed(wavelengths: list[float]) -> str:
    return ", ".join(f"{w:g}" for w in wavelengths)


class SceneConfig(_Strict):
    name: str = "oceanmc scene"
    photons: Annotated[int, Field(gt=0, le=MAX_PHOTONS)] = 1_000_000
    seed: Annotated[int, Field(ge=0, le=MAX_SEED)] = 1
    batches: Annotated[int, Field(ge=2, le=100_000)] = 32
    illumination: Illumination = Field(default_factory=Illumination)
    surface: Surface = Field(default_factory=Surface)
    water: Water
    bottom: Bottom
    tallies: Tallies = Field(default_factory=Tallies)
    estimator: Estimator = Field(default_factory=Estimator)
    wavelengths_nm: Wavelengths | None = None
    # the grid a run with inelastic light traces (config/inelastic.py transport_grid: the
    # requested wavelengths_nm and those the excitation needs), set by the validator; the
    # config keeps (and a stored config writes) the requested grid, so that loading it again
    # gives the same traced grid. None: the requested grid is traced
    _traced: list[float] | None = PrivateAttr(default=None)

    @field_validator("wavelengths_nm")
    @classmethod
    def _increasing(cls, value: Wavelengths | None) -> Wavelengths | None:
        return check_increasing(value)

    @field_validator("name")
    @classmethod
    def _printable_name(cls, name: str) -> str:
        # The name is printed to the terminal and stored as an HDF5 (UTF-8) string: a NUL byte
        # or a lone surrogate cannot be stored, an escape sequence would reach the terminal.
        if len(name) > 200:
            raise ValueError(f"{len(name)} characters; allowed: at most 200")
        for char in name:
            if not char.isprintable() or 0xD800 <= ord(char) <= 0xDFFF:
                raise ValueError(f"contains the character {char!r}; allowed: printable text "
                                 "(no control characters)")
        return name

    @field_validator("photons", mode="before")
    @classmethod
    def _photons_in_e_notation(cls, value):
        # YAML 1.1 reads 1e6 (no decimal point) as a string; accept it as --photons does.
        if isinstance(value, str):
            try:
                number = float(value)
            except ValueError:
                return value
            problem = non_finite_text(value, [cls.model_fields["photons"].rebuild_annotation()])
            if problem is not None:   # `photons: nan`, which YAML 1.1 reads as text
                raise shown_value_error(value, problem)
            value = number if math.isfinite(number) else value
        if isinstance(value, float) and math.isfinite(value) and value == int(value):
            if abs(value) > MAX_PHOTONS:   # else shown as the 309 digits of int(1e308)
                raise ValueError(cls._allowed("photons"))
            return int(value)
        if isinstance(value, int) and not isinstance(value, bool) and abs(value) > MAX_PHOTONS:
            # (pydantic's message had every digit of the value and of the limit)
            raise shown_value_error(_shown_beyond(value), cls._allowed("photons"))
        return value

    @model_validator(mode="before")
    @classmethod
    def _seed_in_range(cls, data):
        # pydantic said "less than 9223372036854775808", or of a float beyond int64 "Unable to
        # parse input string as an integer, exceeded maximum size". Raised for the model, not
        # as a field validator of seed, which would take seed out of _Strict's check of a
        # quoted number (seed: '5')
        seed = data.get("seed") if isinstance(data, dict) else None
        number = (isinstance(seed, int) and not isinstance(seed, bool)) or \
            (isinstance(seed, float) and math.isfinite(seed))   # (nan: _Strict's message)
        if number and not 0 <= seed <= MAX_SEED:
            # exact, as the bound is
            raise shown_value_error(_shown_beyond(seed, exact=True), cls._allowed("seed"),
                                    "seed")
        return data

    @classmethod
    def _allowed(cls, key: str) -> str:
        """What a key's bounds allow, as the message of any number out of its range says."""
        return f"allowed: {allowed_numbers([cls.model_fields[key].rebuild_annotation()])}"

    @model_validator(mode="after")
    def _consistent(self) -> "SceneConfig":
        deep = math.isinf(self.water.layers[-1].thickness_m)
        if deep and self.bottom.model != "none":
            raise ValueError(f"water.layers[{len(self.water.layers) - 1}].thickness_m = .inf "
                             f"with bottom.model = {self.bottom.model!r}: no bottom lies below "
                             "an infinitely deep last layer; use bottom.model = 'none' or a "
                             "finite thickness_m")
        if not deep and self.bottom.model == "none":
            raise ValueError("bottom.model = 'none' needs an infinitely deep last layer "
                             "(thickness_m: .inf); a finite water column needs a bottom "
                             "(black, lambertian, minnaert, specular, lambertian_specular, "
                             "ggx, hapke, table, mixture)")
        spectral = self.wavelengths_nm is not None
        self._extend_for_inelastic(spectral)
        self.water.check_wavelength_count(len(self.wavelengths), spectral)
        check_bottom_wavelengths(self.bottom, len(self.wavelengths), spectral)
        depth = self.water.depth_m
        for d in self.tallies.depths_m:
            if d > depth * (1.0 + 1e-12):
                raise ValueError(f"tallies.depths_m contains {d} m, below the bottom at "
                                 f"{depth} m; allowed: 0 <= depth <= {depth}")
        if self.photons < 2 * self.batches:
            raise ValueError(f"photons = {self.photons}: need at least 2 per batch "
                             f"(batches = {self.batches})")
        if self.tallies.nadir_estimator == "local" and bottom_has_mirror(self.bottom):
            raise ValueError(f"tallies.nadir_estimator = 'local' with bottom.model = "
                             f"{self.bottom.model!r}: a mirror has no density for a local "
                             "estimate; use 'crossing' or 'auto'")
        if self.tallies.nadir_estimator == "local" and not self.surface.cap_lobe_tabulated():
            upwind, crosswind = self.surface.slope_variances()
            raise ValueError(
                "tallies.nadir_estimator = 'local' with surface.model = 'cox_munk' of "
                + (f"mean square slope {upwind + crosswind:g}" if upwind == crosswind else
                   f"wind_direction_deg = {self.surface.wind_direction_deg} (anisotropic "
                   "slopes)")
                + ": the polar-cap tables through waves need isotropic slopes of mean square "
                f"slope at most {MAX_CAP_MSS} (wind_speed_m_s without wind_direction_deg); use "
                "'crossing' or 'auto'")
        if self.tallies.local_directions_deg and bottom_has_mirror(self.bottom):
            raise ValueError(f"tallies.local_directions_deg with bottom.model = "
                             f"{self.bottom.model!r}: a mirror has no density for a local "
                             "estimate; use the quad radiances")
        if self.estimator.upward_fraction == "auto":
            # resolved here, so that the stored config says what ran; in a one-wavelength
            # implicit walk left to the scene's build, which decides the depth windows it goes
            # with (scene/weight_window.upward_fraction; the result's attribute says the value)
            if self.estimator.mode == "analog":
                self.estimator.upward_fraction = None
            elif len(self.wavelengths) > 1:
                self.estimator.upward_fraction = AUTO_UPWARD_FRACTION
        if self.estimator.mode == "analog" and self.estimator.upward_fraction is not None:
            raise ValueError(f"estimator.upward_fraction = {self.estimator.upward_fraction} "
                             "with estimator.mode = 'analog': the biased scattering changes "
                             "weights, which the analog walk keeps at 1; use "
                             "estimator.mode = 'implicit' or upward_fraction: null")
        inelastic = self.water.inelastic is not None and bool(self.water.inelastic.processes())
        if self.estimator.depth_splitting == "on" and inelastic:
            raise ValueError("estimator.depth_splitting = 'on' with water.inelastic: the depth "
                             "windows are set by the elastic light's attenuation and have not "
                             "been checked against the light inelastic processes emit; use "
                             "'auto' (off here) or 'off'")
        if self.estimator.mode == "analog" and not bottom_weight_bounded(self.bottom):
            raise ValueError(f"estimator.mode = 'analog' with bottom.model = "
                             f"{self.bottom.model!r} sampled by weight f cos/pdf, which can "
                             "exceed 1: analog bottom reflection (survival with probability = "
                             "weight) cannot carry it; use estimator.mode = 'implicit'")
        return self

    def _extend_for_inelastic(self, spectral: bool) -> None:
        """With inelastic light, the traced grid (transport_grid; `wavelengths`), or a
        one-line refusal naming the wavelengths needed where per-wavelength lists were given
        for the requested grid only."""
        inelastic = self.water.inelastic
        if inelastic is None or not inelastic.processes():
            return
        names = ", ".join(f"water.inelastic.{name}" for name, _ in inelastic.processes())
        if not spectral:
            raise ValueError(f"{names} moves light between wavelengths: it needs "
                             "wavelengths_nm (a list in nm, or {start, stop, step})")
        requested = grid(self.wavelengths_nm)
        traced = transport_grid(requested, inelastic)
        if len(traced) == len(requested):
            return
        added = [float(w) for w in traced if not np.isclose(requested, w).any()]
        # (their counts were checked against the requested grid: every list is one too short)
        lists = [key for key, value in (*self.water.spectral_values(),
                                        *reflectance_keys(self.bottom))
                 if isinstance(value, list)]
        if lists:
            raise ValueError(
                f"{names} needs the light of {_listed(added)} nm, which wavelengths_nm "
                f"lacks, and {', '.join(lists)} hold values for its {len(requested)} "
                "wavelengths only: add those to wavelengths_nm and give the lists values "
                "there, or give each one number")
        self._traced = [float(w) for w in traced]

    @property
    def added_wavelengths(self) -> list[float]:
        """The wavelengths (nm) added to the requested grid for inelastic light."""
        if self._traced is None:
            return []
        requested = grid(self.wavelengths_nm)
        return [w for w in self._traced if not np.isclose(requested, w).any()]

    @property
    def nadir_local(self) -> bool:
        """Whether Lu, Lw_nadir and Rrs_nadir come from the local (cap) estimator (auto: unless
        the bottom is a mirror, or the waves are anisotropic or steeper than the cap's tables
        allow: Surface.cap_lobe_tabulated). Measured in 31-band Case-1 scenes, deep and over a
        bottom, flat and at 7 m/s, with auto's upward bias: the local estimate's figure of
        merit for Rrs is several times the crossing estimate's in every band
        (benchmarks/real_scenes.md)."""
        mode = self.tallies.nadir_estimator
        return mode == "local" or (mode == "auto" and not bottom_has_mirror(self.bottom)
                                   and self.surface.cap_lobe_tabulated())

    @property
    def wavelengths(self):
        """The wavelength grid the run traces (nm, numpy array): wavelengths_nm, with what
        inelastic light's excitation needs; [nan] for a monochromatic scene."""
        if self._traced is not None:
            return np.array(self._traced)
        return grid(self.wavelengths_nm)

    @property
    def n_water(self) -> float:
        return self.surface.n_water   # (1 with surface.model none: config/surface.py)
