"""The air-water surface."""
from __future__ import annotations

from typing import Annotated, Literal, Optional

from pydantic import Field, model_validator

from .base import _Strict

# Cox & Munk (1954), J. Opt. Soc. Am. 44, 838, clean surface (wind speed U in m/s at 12.5 m):
# mean square slope sigma^2 = 0.003 + 5.12e-3 U; upwind 3.16e-3 U, crosswind 0.003 + 1.92e-3 U
CM_MSS = (0.003, 5.12e-3)
CM_UPWIND = (0.0, 3.16e-3)
CM_CROSSWIND = (0.003, 1.92e-3)
# the smallest mean square slope sampled by table by default: Cox & Munk's calm sea (0 m/s)
TABLE_MIN_MSS = CM_MSS[0]
# the largest mean square slope through which the nadir cap's local estimate is tabulated
# (kernel/rough_cap.py; 30 m/s gives 0.157)
MAX_CAP_MSS = 0.2


class Surface(_Strict):
    """flat: exact unpolarized Fresnel + Snell; none: no interface (index-matched, n = 1);
    cox_munk: the wind-roughened sea, Gaussian facet slopes (Cox & Munk 1954) from
    wind_speed_m_s (isotropic, or upwind/crosswind with wind_direction_deg: the azimuth the
    wind blows toward, from the sun's rays' azimuth) or from mean_square_slope.
    fresnel: schlick swaps in Schlick's approximation, for comparisons only (never exact).
    method (cox_munk): table samples a table of the facet walk's BSDF, built once per (slopes,
    n_water) and cached on disk (scene/surface_table.py; isotropic slopes only); walk follows
    every photon facet by facet (the reference, several times slower). Default: table, except
    walk when wind_direction_deg makes the slopes anisotropic or when mean_square_slope is
    below TABLE_MIN_MSS (a surface that near flat has a total-internal-reflection edge and
    lobes sharper than the table's incidence nodes, 1.4 deg apart, resolve)."""
    model: Literal["flat", "none", "cox_munk"] = "flat"
    n_water: Annotated[float, Field(ge=1.0, le=3.0, allow_inf_nan=False)] = 1.34
    fresnel: Literal["exact", "schlick"] = "exact"
    wind_speed_m_s: Optional[Annotated[float, Field(ge=0.0, le=30.0, allow_inf_nan=False)]] = None
    mean_square_slope: Optional[Annotated[float, Field(ge=1e-6, le=0.5,
                                                       allow_inf_nan=False)]] = None
    wind_direction_deg: Optional[Annotated[float, Field(ge=-360.0, le=360.0,
                                                        allow_inf_nan=False)]] = None
    method: Optional[Literal["table", "walk"]] = None

    @model_validator(mode="after")
    def _slopes_given_once(self) -> "Surface":
        if self.model == "none":
            # no interface: the water's index is 1 (index-matched) whatever n_water says, and
            # the stored config says 1. Not refused: a sweep over surface.model, or an
            # override of a scene's model, keeps the scene's n_water for its other models
            self.n_water = 1.0
        rough = (self.wind_speed_m_s, self.mean_square_slope, self.wind_direction_deg,
                 self.method)
        if self.model != "cox_munk":
            if any(v is not None for v in rough):
                raise ValueError(f"surface.model = {self.model!r} has no slopes: "
                                 "wind_speed_m_s, mean_square_slope, wind_direction_deg and "
                                 "method belong to surface.model = 'cox_munk'")
            return self
        if (self.wind_speed_m_s is None) == (self.mean_square_slope is None):
            raise ValueError("surface.model = 'cox_munk' needs exactly one of wind_speed_m_s "
                             "(0 to 30 m/s) and mean_square_slope (1e-6 to 0.5)")
        if self.wind_direction_deg is not None and self.wind_speed_m_s is None:
            raise ValueError(f"surface.wind_direction_deg = {self.wind_direction_deg} needs "
                             "surface.wind_speed_m_s (the upwind/crosswind variances are "
                             "functions of the wind speed); drop it with mean_square_slope")
        if self.method == "table" and self.wind_direction_deg is not None:
            raise ValueError("surface.method = 'table' with surface.wind_direction_deg: the "
                             "table is of isotropic slopes; use method 'walk' (the default "
                             "with a wind direction) or drop wind_direction_deg")
        if self.fresnel != "exact":
            raise ValueError("surface.fresnel = 'schlick' with surface.model = 'cox_munk': "
                             "the facets use exact Fresnel; allowed: 'exact'")
        return self

    def cap_lobe_tabulated(self) -> bool:
        """Whether the nadir polar cap's local estimate can see through this surface: flat,
        or waves of isotropic slopes with mean square slope at most MAX_CAP_MSS (the facets'
        shadowing is then nil for the cap's light: kernel/rough_cap.py)."""
        if self.model != "cox_munk":
            return True
        upwind, crosswind = self.slope_variances()
        return upwind == crosswind and upwind + crosswind <= MAX_CAP_MSS

    def tabulated(self) -> bool:
        """Whether the rough surface is sampled from its table (else by its facet walk)."""
        if self.model != "cox_munk":
            return False
        if self.method is not None:
            return self.method == "table"
        return self.wind_direction_deg is None and sum(self.slope_variances()) >= TABLE_MIN_MSS

    def slope_variances(self) -> tuple[float, float]:
        """(upwind, crosswind) slope variances; isotropic: half the mean square slope each."""
        if self.mean_square_slope is not None:
            return self.mean_square_slope / 2.0, self.mean_square_slope / 2.0
        u = self.wind_speed_m_s
        if self.wind_direction_deg is None:
            mss = max(CM_MSS[0] + CM_MSS[1] * u, 1e-6)
            return mss / 2.0, mss / 2.0
        return (max(CM_UPWIND[0] + CM_UPWIND[1] * u, 1e-6),
                CM_CROSSWIND[0] + CM_CROSSWIND[1] * u)
