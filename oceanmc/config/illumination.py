"""Illumination: the sun, and the sky (a named model or a radiance map from a file)."""
from __future__ import annotations

import datetime as dt
from typing import Annotated, Literal, Union

from pydantic import AfterValidator, Discriminator, Field, Tag, model_validator

from .base import Asymmetry, FilePath, Fraction, _Strict

# Ed(0+) in any units, bounded so that it times any tally (tallies hold up to ~1e6 x Ed0) and
# the batches' variances stay finite, and from below so that they do not underflow (at Ed0 =
# 1e-300 every standard error was 0: the squares of the batches' deviations fell below 1e-308);
# a spectrum's Ed0 times illumination.Ed0 is held to both too
MIN_ED0, MAX_ED0 = 1e-100, 1e100


class SkyMap(_Strict):
    """A sky radiance map from a file (sky_maps.py): an equirectangular (theta_view, phi_view)
    array in .npy, .npz or HDF5, or an OpenEXR image (.exr; the upper half of a 2:1 full-sphere
    image); its absolute scale is irrelevant (the sky's share of Ed0 is diffuse_fraction).
    dataset: the array in a .npz / HDF5 file; in an .exr, the channel to read (by default Y if
    present, else the Rec. 709 luminance of R, G, B). sampling: importance draws directions in
    proportion to L cos dOmega (every sky photon has the same weight); cosine draws them
    cosine-weighted over the hemisphere whatever L, each photon weighted by L(its cell) pi / E
    with E the integral of L cos dOmega: the same expectation, far more noise for a peaked map
    (for comparisons). layout (.exr only): what the image's rows cover: sphere (theta_view
    0..180 deg; the upper half is read), hemisphere (0..90 deg), or auto: sphere exactly when
    the image is twice as wide as it is high."""
    map: FilePath
    dataset: str = "radiance"
    sampling: Literal["importance", "cosine"] = "importance"
    layout: Literal["auto", "hemisphere", "sphere"] = "auto"

    @model_validator(mode="after")
    def _layout_is_for_images(self) -> "SkyMap":
        if self.layout != "auto" and not self.map.lower().endswith(".exr"):
            raise ValueError(f"layout = {self.layout!r} with map = {self.map!r}: layout applies "
                             "to .exr images; a .npy, .npz or HDF5 map covers theta_view "
                             "0..90 deg (or its own theta_edges_deg); leave layout out")
        return self


SPA_LAST_YEAR = 6000


def _sun_time(time: dt.datetime) -> dt.datetime:
    """A time with its zone (a clock time alone is hours off anywhere but at UTC: 13:00 taken
    as UTC put a Mediterranean noon sun at 88.7 deg), in the years SPA is valid for."""
    if time.tzinfo is None:
        raise ValueError(f"{time.isoformat()} has no time zone; allowed: an ISO 8601 time with "
                         f"its zone, e.g. {time.isoformat()}Z (UTC) or "
                         f"{time.isoformat()}+02:00")
    if time.year > SPA_LAST_YEAR:     # datetime's own years start at 1, within SPA's -2000
        raise ValueError(f"year {time.year}; allowed: up to {SPA_LAST_YEAR} (the years the solar "
                         "position algorithm is valid for, -2000 .. 6000)")
    return time


class SunPosition(_Strict):
    """The sun's zenith angle from the time (ISO 8601 with its zone: Z for UTC, or +hh:mm) and
    the place (degrees north, degrees east), by pvlib's solar position (NREL SPA, Reda & Andreas
    2004)."""
    time: Annotated[dt.datetime, AfterValidator(_sun_time)]
    latitude_deg: Annotated[float, Field(ge=-90.0, le=90.0, allow_inf_nan=False)]
    longitude_deg: Annotated[float, Field(ge=-180.0, le=180.0, allow_inf_nan=False)]


class FlatSpectrum(_Strict):
    """Ed0 and diffuse_fraction the same at every wavelength."""
    model: Literal["flat"]


class Spectrl2Spectrum(_Strict):
    """The clear-sky spectral model SPECTRL2 (Bird & Riordan 1986, J. Clim. Appl. Meteorol. 25,
    87), by pvlib.spectrum.spectrl2, on a horizontal surface at sea level (300-4000 nm): Ed0(l)
    the global horizontal irradiance (W m-2 nm-1, times illumination.Ed0), diffuse_fraction(l)
    its diffuse share. The atmosphere's parameters are SPECTRL2's (defaults: pvlib's and Bird &
    Riordan's)."""
    model: Literal["spectrl2"]
    # generous bounds of Earth's clear atmospheres: the pressure at any lake or sea surface
    # (the highest lakes, ~6000 m, ~47 kPa; sea-level records 87-108.5 kPa); precipitable water
    # (records ~7.5 cm); ozone (0.1-0.6 atm-cm observed); aerosol optical depth at 500 nm (dense
    # smoke or dust ~5); the Angstrom exponent (0-2.5 observed); Bird & Riordan's omega' (0.095)
    surface_pressure_pa: Annotated[float, Field(ge=40_000.0, le=110_000.0,
                                                allow_inf_nan=False)] = 101325.0
    precipitable_water_cm: Annotated[float, Field(ge=0.0, le=10.0, allow_inf_nan=False)] = 1.42
    ozone_atm_cm: Annotated[float, Field(ge=0.0, le=1.0, allow_inf_nan=False)] = 0.344
    aerosol_turbidity_500nm: Annotated[float, Field(ge=0.0, le=10.0,
                                                    allow_inf_nan=False)] = 0.1
    scattering_albedo_400nm: Fraction = 0.945
    alpha: Annotated[float, Field(ge=0.0, le=4.0, allow_inf_nan=False)] = 1.14
    wavelength_variation_factor: Fraction = 0.095
    aerosol_asymmetry_factor: Asymmetry = 0.65
    # else sun_position's day, else 4 April (Earth-Sun distance 1 AU)
    day_of_year: Annotated[int, Field(ge=1, le=366)] | None = None


class TableSpectrum(_Strict):
    """A CSV with columns wavelength_nm, Ed0 (times illumination.Ed0) and diffuse_fraction,
    linearly interpolated."""
    model: Literal["table"]
    file: FilePath


Spectrum = Annotated[Union[FlatSpectrum, Spectrl2Spectrum, TableSpectrum],
                     Field(discriminator="model")]


class Illumination(_Strict):
    """sky: uniform; cardioidal or overcast (the CIE standard overcast sky, L ~ 1 + 2 cos Z;
    Moon & Spencer 1942); harrison_coombes (clear sky, Harrison & Coombes 1988, with the sun at
    sun_zenith_deg); or {map: FILE} (sky_maps.py)."""
    # (below MIN_ED0 the variances of the tallies underflow to 0)
    Ed0: Annotated[float, Field(ge=MIN_ED0, le=MAX_ED0, allow_inf_nan=False)] = 1.0
    sun_zenith_deg: Annotated[float, Field(ge=0.0, lt=90.0, allow_inf_nan=False)] = 30.0
    diffuse_fraction: Fraction = 0.0
    sky: Annotated[Union[Annotated[Literal["uniform", "cardioidal", "overcast",
                                           "harrison_coombes"], Tag("sky_name")],
                         Annotated[SkyMap, Tag("SkyMap")]],
                   Discriminator(lambda v: "SkyMap" if isinstance(v, (dict, SkyMap))
                                 else "sky_name")] = "uniform"
    # spectral illumination (oceanmc/optics/illumination.py); with spectrl2 or table, Ed0 scales
    # the spectrum and diffuse_fraction comes from it
    spectrum: Spectrum = Field(default_factory=lambda: FlatSpectrum(model="flat"))
    sun_position: SunPosition | None = None

    @model_validator(mode="after")
    def _sun_and_spectrum(self) -> "Illumination":
        if self.spectrum.model != "flat" and self.diffuse_fraction != 0.0:
            raise ValueError(f"diffuse_fraction = {self.diffuse_fraction} with spectrum.model = "
                             f"{self.spectrum.model!r}, which gives the diffuse share per "
                             "wavelength; leave diffuse_fraction out")
        if self.sun_position is not None:
            from ..optics.sun import zenith_deg   # pvlib: imported only when used
            zenith = zenith_deg(self.sun_position)
            if zenith >= 90.0:
                raise ValueError(f"sun_position: the sun is {zenith - 90.0:.2f} deg below the "
                                 f"horizon at {self.sun_position.time.isoformat()} (latitude "
                                 f"{self.sun_position.latitude_deg}, longitude "
                                 f"{self.sun_position.longitude_deg}); allowed: a daytime sun")
            if "sun_zenith_deg" in self.model_fields_set \
                    and abs(self.sun_zenith_deg - zenith) > 1e-6:
                raise ValueError(f"sun_zenith_deg = {self.sun_zenith_deg} and sun_position "
                                 f"(zenith {zenith:.6f} deg) both given; give one")
            self.sun_zenith_deg = zenith
        return self
