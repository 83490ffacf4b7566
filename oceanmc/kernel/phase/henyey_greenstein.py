"""Henyey-Greenstein, params[0] = g: p = (1 - g^2) / (4 pi (1 + g^2 - 2 g cos)^(3/2)), sampled by
cos = (1 + g^2 - ((1 - g^2)/(1 - g + 2 g u))^2) / (2 g) (Henyey & Greenstein 1941; Wang et al.
1995)."""
import math

from ..compile import kernel


@kernel
def sample(params, u):
    g = params[0]
    if abs(g) < 1e-6:
        return 2.0 * u - 1.0
    t = (1.0 - g * g) / (1.0 - g + 2.0 * g * u)
    return min(1.0, max(-1.0, (1.0 + g * g - t * t) / (2.0 * g)))


@kernel
def evaluate(params, cos_psi):
    g = params[0]
    return (1.0 - g * g) / (4.0 * math.pi * (1.0 + g * g - 2.0 * g * cos_psi) ** 1.5)
