"""No interface (surface model `none`): water and air have the same index, light crosses
unchanged and nothing is reflected."""
from numba import njit


@njit(error_model="numpy", cache=True)
def split(surface, ux, uy, uz):
    return 0.0, ux, uy, -uz, ux, uy, uz


@njit(error_model="numpy", cache=True)
def transmittance(surface, mu):
    return 1.0
