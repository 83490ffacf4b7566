"""The sun's zenith angle from time and place: pvlib's solar position algorithm (NREL SPA, Reda &
Andreas 2004, Solar Energy 76, 577), the apparent (refracted) zenith at sea level."""
from __future__ import annotations

import datetime as dt


def zenith_deg(position) -> float:
    import pandas as pd
    import pvlib
    time = position.time if position.time.tzinfo else position.time.replace(tzinfo=dt.timezone.utc)
    solar = pvlib.solarposition.get_solarposition(pd.DatetimeIndex([time]),
                                                  position.latitude_deg, position.longitude_deg)
    return float(solar["apparent_zenith"].iloc[0])
