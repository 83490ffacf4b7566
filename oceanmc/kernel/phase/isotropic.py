import math

from ..compile import kernel


@kernel
def sample(params, u):
    return 2.0 * u - 1.0


@kernel
def evaluate(params, cos_psi):
    return 1.0 / (4.0 * math.pi)
