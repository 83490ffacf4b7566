"""Optics: the inherent optical properties of the water column and the illumination, per
wavelength, resolved from the scene's config (constants, per-wavelength lists, constituents,
depth profiles, spectral skies, bottom reflectance spectra). Pure Python and numpy; the packers (oceanmc/scene) turn them into
the kernel's records.

    wavelengths(config) -> (n_wl,) nm
    column_iops(config) -> [LayerIOPs, ...] top to bottom
    illumination_spectrum(config) -> (Ed0 (n_wl,), diffuse_fraction (n_wl,), sun_zenith_deg)
    bottom_spectrum(bottom, wavelengths) -> (n_wl,) the bottom's reflectance, or None
"""
from .bottom import spectrum as bottom_spectrum
from .column import LayerIOPs, column_iops, iops_table, wavelengths
from .illumination import illumination_spectrum, monochromatic_illumination
from .phases import backscatter_fraction

__all__ = ["wavelengths", "LayerIOPs", "column_iops", "illumination_spectrum",
           "backscatter_fraction", "monochromatic_illumination", "iops_table",
           "bottom_spectrum"]
