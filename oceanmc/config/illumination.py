"""Illumination: the sun, and the sky (a named model or a radiance map from a file)."""
from __future__ import annotations

from typing import Annotated, Literal, Union

from pydantic import Discriminator, Field, Tag, model_validator

from .base import Fraction, _Strict


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
    map: str
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


class Illumination(_Strict):
    """sky: uniform; cardioidal or overcast (the CIE standard overcast sky, L ~ 1 + 2 cos Z;
    Moon & Spencer 1942); harrison_coombes (clear sky, Harrison & Coombes 1988, with the sun at
    sun_zenith_deg); or {map: FILE} (sky_maps.py)."""
    Ed0: Annotated[float, Field(gt=0.0, allow_inf_nan=False)] = 1.0
    sun_zenith_deg: Annotated[float, Field(ge=0.0, lt=90.0, allow_inf_nan=False)] = 30.0
    diffuse_fraction: Fraction = 0.0
    sky: Annotated[Union[Annotated[Literal["uniform", "cardioidal", "overcast",
                                           "harrison_coombes"], Tag("sky_name")],
                         Annotated[SkyMap, Tag("SkyMap")]],
                   Discriminator(lambda v: "SkyMap" if isinstance(v, (dict, SkyMap))
                                 else "sky_name")] = "uniform"
