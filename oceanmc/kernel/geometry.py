"""Direction frames and rotations."""
import math

from numba import njit


@njit(error_model="numpy", cache=True)
def turn(ux, uy, uz, cos_t, phi):
    """The direction at polar angle acos(cos_t) and azimuth phi about (ux, uy, uz), renormalised
    (the MCML rotation; Wang, Jacques & Zheng 1995, Comput. Meth. Prog. Bio. 47, 131)."""
    sin_t = math.sqrt(max(0.0, 1.0 - cos_t * cos_t))
    cp = math.cos(phi)
    sp = math.sin(phi)
    # the horizontal length from ux, uy (not sqrt(1 - uz^2), which cancels near the vertical), so
    # the general formula stays exact down to tilts of 1e-12 rad; MCML's shortcut for
    # |uz| > 0.99999 ignored tilts up to 0.26 deg and so misplaced the scattering angle by as much
    tmp = math.sqrt(ux * ux + uy * uy)
    if tmp < 1e-12:
        nx = sin_t * cp
        ny = sin_t * sp
        nz = cos_t if uz > 0.0 else -cos_t
    else:
        nx = sin_t * (ux * uz * cp - uy * sp) / tmp + ux * cos_t
        ny = sin_t * (uy * uz * cp + ux * sp) / tmp + uy * cos_t
        nz = -sin_t * cp * tmp + uz * cos_t
    norm = 1.0 / math.sqrt(nx * nx + ny * ny + nz * nz)
    return nx * norm, ny * norm, nz * norm


@njit(error_model="numpy", cache=True)
def from_angles(cos_t, phi):
    """Unit vector with polar cosine cos_t about +z and azimuth phi from +x."""
    sin_t = math.sqrt(max(0.0, 1.0 - cos_t * cos_t))
    return sin_t * math.cos(phi), sin_t * math.sin(phi), cos_t
