"""The illumination per wavelength: Ed(0+), its diffuse (sky) share and the sun's zenith angle
(config/illumination.py: spectrum flat, spectrl2 or table; sun_zenith_deg or sun_position)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .. import config as cfg
from ..config import ConfigError
from ..config.illumination import MAX_ED0, MIN_ED0
from ..config.wavelengths import MAX_WAVELENGTH_NM, MIN_WAVELENGTH_NM
from .tables import interpolate, read_table

# the day of year SPECTRL2's Earth-Sun distance correction uses when neither day_of_year nor
# sun_position is given: 4 April, when the distance is 1 AU to 0.1%
MEAN_DISTANCE_DAY = 94
# a spectrum table's columns and their ranges (Ed0 in any units, scaled by illumination.Ed0)
TABLE_COLUMNS = {"wavelength_nm": (MIN_WAVELENGTH_NM, MAX_WAVELENGTH_NM, "nm"),
                 "Ed0": (0.0, MAX_ED0, ""), "diffuse_fraction": (0.0, 1.0, "")}


def spectrl2(spectrum: cfg.Illumination, zenith_deg: float, day_of_year: int | None,
             wl: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(global horizontal irradiance W m-2 nm-1, diffuse share) of SPECTRL2 (Bird & Riordan
    1986) on a horizontal surface, by pvlib; relative air mass of Kasten & Young (1989)."""
    import pvlib
    model = spectrum
    airmass = pvlib.atmosphere.get_relative_airmass(zenith_deg)
    # ground_albedo 0: no multiple reflection between the surface and the sky (pvlib's default
    # 0.2 is land's; the sea's ~0.06 would add 1.5% to Ed0 at 400 nm, 0.3% at 700)
    out = pvlib.spectrum.spectrl2(
        apparent_zenith=zenith_deg, aoi=zenith_deg, surface_tilt=0.0, ground_albedo=0.0,
        surface_pressure=model.surface_pressure_pa, relative_airmass=airmass,
        precipitable_water=model.precipitable_water_cm, ozone=model.ozone_atm_cm,
        aerosol_turbidity_500nm=model.aerosol_turbidity_500nm, dayofyear=day_of_year,
        scattering_albedo_400nm=model.scattering_albedo_400nm, alpha=model.alpha,
        wavelength_variation_factor=model.wavelength_variation_factor,
        aerosol_asymmetry_factor=model.aerosol_asymmetry_factor)
    nodes = np.asarray(out["wavelength"], dtype=np.float64)
    total = np.ravel(out["poa_global"])
    diffuse = np.ravel(out["poa_sky_diffuse"])
    where = "illumination.spectrum"
    ed0 = interpolate(wl, nodes, total, where, "SPECTRL2 (Bird & Riordan 1986)")
    sky = interpolate(wl, nodes, diffuse, where, "SPECTRL2 (Bird & Riordan 1986)")
    return ed0, np.divide(sky, ed0, out=np.zeros_like(sky), where=ed0 > 0.0)


def illumination_spectrum(config: cfg.SceneConfig | dict | str | Path
                          ) -> tuple[np.ndarray, np.ndarray, float]:
    """(Ed0 (n_wl,), diffuse_fraction (n_wl,), sun_zenith_deg). config: a SceneConfig, or what
    load_config reads (a dict, a YAML path)."""
    if not isinstance(config, cfg.SceneConfig):
        config = cfg.load_config(config)
    wl = config.wavelengths
    light = config.illumination
    spectrum = light.spectrum
    zenith = float(light.sun_zenith_deg)
    if spectrum.model == "flat":
        return (np.full(len(wl), float(light.Ed0)), np.full(len(wl), float(light.diffuse_fraction)),
                zenith)
    if np.isnan(wl).any():
        raise ConfigError(f"illumination.spectrum.model = {spectrum.model!r} needs "
                          "wavelengths_nm")
    # (a wavelength outside a table: run/simulation.prepare says where it came from)
    if spectrum.model == "spectrl2":
        day = spectrum.day_of_year or (light.sun_position.time.timetuple().tm_yday
                                       if light.sun_position else MEAN_DISTANCE_DAY)
        ed0, diffuse = spectrl2(spectrum, zenith, day, wl)
    else:
        where = "illumination.spectrum.file"
        table = read_table(spectrum.file, where, TABLE_COLUMNS)
        ed0, diffuse = (interpolate(wl, table["wavelength_nm"], table[name], where,
                                    spectrum.file) for name in ("Ed0", "diffuse_fraction"))
    if np.any(ed0 <= 0.0):
        raise ConfigError(f"illumination.spectrum: Ed0 = 0 at {wl[ed0 <= 0.0][0]:g} nm; every "
                          "wavelength needs light")
    ed0 = float(light.Ed0) * ed0
    if ed0.max() > MAX_ED0:
        raise ConfigError(f"illumination.Ed0 = {light.Ed0:g} times the spectrum's Ed0 reaches "
                          f"{ed0.max():g} at {wl[np.argmax(ed0)]:g} nm; allowed: at most "
                          f"{MAX_ED0:g}")
    if ed0.min() < MIN_ED0:
        raise ConfigError(f"illumination.Ed0 = {light.Ed0:g} times the spectrum's Ed0 falls to "
                          f"{ed0.min():g} at {wl[np.argmin(ed0)]:g} nm; allowed: at least "
                          f"{MIN_ED0:g}")
    return ed0, diffuse, zenith


def monochromatic_illumination(config: cfg.SceneConfig,
                               spectrum: tuple[np.ndarray, np.ndarray] | None = None
                               ) -> cfg.Illumination:
    """The illumination of a one-wavelength scene as the flat one the packers take (Ed0 and
    diffuse_fraction of its spectrum at that wavelength; spectrum: illumination_spectrum's
    first two, if already computed)."""
    light = config.illumination
    if light.spectrum.model == "flat":
        return light
    ed0, diffuse = spectrum if spectrum is not None else illumination_spectrum(config)[:2]
    return light.model_copy(update={"Ed0": float(ed0[0]), "diffuse_fraction": float(diffuse[0]),
                                    "spectrum": cfg.FlatSpectrum(model="flat")})
