"""Where photons come from: the sun's collimated beam and the sky's diffuse radiance, sampled in
proportion to their contribution to the downward plane irradiance just above the surface."""
import math

import numpy as np
from numba import njit

from .models import SKY_CARDIOIDAL


@njit(error_model="numpy", cache=True, inline="always")
def sky_cosine(sky_model):
    """Cosine of the travel direction's angle from nadir for a sky photon: density proportional to
    L(theta) cos(theta). Uniform L: cos = sqrt(u). Cardioidal L ~ 1 + 2 cos: the cosine-weighted
    draw is accepted with probability (1 + 2 cos)/3 (rejection, exact)."""
    if sky_model == SKY_CARDIOIDAL:
        while True:
            mu = math.sqrt(np.random.random())
            if 3.0 * np.random.random() < 1.0 + 2.0 * mu:
                return mu
    return math.sqrt(np.random.random())
