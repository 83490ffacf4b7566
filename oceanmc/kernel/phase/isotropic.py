import math

from numba import njit


@njit(error_model="numpy", cache=True)
def sample(params, u):
    return 2.0 * u - 1.0


@njit(error_model="numpy", cache=True)
def evaluate(params, cos_psi):
    return 1.0 / (4.0 * math.pi)
