"""p = (1 + beta cos^2) / (2 pi (2 + 2 beta / 3)); params[0] = beta.
beta = 1: Rayleigh-like (3/16 pi)(1 + cos^2); beta = 0.835: pure sea water 0.06225 (1 + 0.835 cos^2)
(Morel 1974; Mobley 1994, Light and Water, Eq. 3.30)."""
import math

from ..compile import kernel


@kernel
def sample(params, u):
    """Exact inversion of the CDF F(m) = (m + beta m^3/3 + 1 + beta/3) / (2 + 2 beta/3): the cubic
    m^3 + p m + q = 0 with p = 3/beta > 0 has one real root, taken in its hyperbolic form, which
    is free of the cancellation in Cardano's (Numerical Recipes 3rd ed., 5.6)."""
    beta = params[0]
    if beta <= 0.0:
        return 2.0 * u - 1.0
    rhs = u * (2.0 + 2.0 * beta / 3.0) - 1.0 - beta / 3.0
    p = 3.0 / beta
    q = -rhs * 3.0 / beta
    s = math.sqrt(p / 3.0)
    m = -2.0 * s * math.sinh(math.asinh(1.5 * q / (p * s)) / 3.0)
    return min(1.0, max(-1.0, m))


@kernel
def evaluate(params, cos_psi):
    beta = params[0]
    return (1.0 + beta * cos_psi * cos_psi) / (2.0 * math.pi * (2.0 + 2.0 * beta / 3.0))
