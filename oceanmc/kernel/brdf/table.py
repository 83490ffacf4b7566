"""A measured BRDF on an angular grid, read from a file by brdf_tables.py and packed into the
bottom parameter array at offset params[BRDF_TABLE_AT]:

  [n_ti, n_pi, n_tr, n_ph, symmetric, 0, 0, 0,
   theta_i nodes (rad, n_ti), phi_i nodes (rad, n_pi), theta_r nodes (rad, n_tr),
   dphi nodes (rad, n_ph), f values (1/sr) in C order over (theta_i, phi_i, theta_r, dphi)]

dphi = phi_r - phi_i is the reflected azimuth relative to the azimuth of wi (the direction
towards the light): dphi = 0 sends light back towards the source (the hot spot), dphi = pi is
the mirror direction. An isotropic table has n_pi = 1. A symmetric table covers dphi 0..pi and
f(-dphi) = f(dphi); otherwise the nodes run from 0 to 2 pi (the 2 pi column a copy of the 0 one,
added when the table is packed), and so do the phi_i nodes of an anisotropic table.

params[4] is the albedo scale: f times it (bottom.albedo_scale; kernel/spectral.py gives each
wavelength its share).

f is multilinear in (theta_i, phi_i, theta_r, dphi) between the nodes and constant beyond the
first and last theta nodes (tables rarely reach grazing angles)."""
import math

from ..compile import kernel
from ..models import BRDF_TABLE_AT
from ..search import interval

HEADER = 8
SCALE = 4   # params slot of the albedo scale


@kernel
def locate(params, start, n, x):
    """(index of the node at or below x, fraction towards the next) on nodes params[start:start+n],
    clamped to the node range; a single node gives (0, 0)."""
    if n == 1:
        return 0, 0.0
    if x <= params[start]:
        return 0, 0.0
    if x >= params[start + n - 1]:
        return n - 2, 1.0
    lo = interval(params, start, 0, n - 1, x)
    x0 = params[start + lo]
    return lo, (x - x0) / (params[start + lo + 1] - x0)


@kernel
def evaluate(params, wix, wiy, wiz, wox, woy, woz):
    if wiz <= 0.0 or woz <= 0.0:
        return 0.0
    o = int(params[BRDF_TABLE_AT])
    n_ti = int(params[o])
    n_pi = int(params[o + 1])
    n_tr = int(params[o + 2])
    n_ph = int(params[o + 3])
    symmetric = params[o + 4] > 0.0
    ti_at = o + HEADER
    pi_at = ti_at + n_ti
    tr_at = pi_at + n_pi
    ph_at = tr_at + n_tr
    val_at = ph_at + n_ph
    two_pi = 2.0 * math.pi
    theta_i = math.acos(min(1.0, wiz))
    theta_r = math.acos(min(1.0, woz))
    phi_i = math.atan2(wiy, wix)
    dphi = math.atan2(woy, wox) - phi_i
    dphi = dphi - two_pi * math.floor(dphi / two_pi)
    if symmetric and dphi > math.pi:
        dphi = two_pi - dphi
    phi_i = phi_i - two_pi * math.floor(phi_i / two_pi)
    a, fa = locate(params, ti_at, n_ti, theta_i)
    b, fb = locate(params, pi_at, n_pi, phi_i)
    r, fr = locate(params, tr_at, n_tr, theta_r)
    c, fc = locate(params, ph_at, n_ph, dphi)
    total = 0.0
    for da in range(2):
        wa = fa if da == 1 else 1.0 - fa
        if wa == 0.0:
            continue
        for db in range(2):
            wb = fb if db == 1 else 1.0 - fb
            if wb == 0.0:
                continue
            for dr in range(2):
                wr = fr if dr == 1 else 1.0 - fr
                if wr == 0.0:
                    continue
                base = (((a + da) * n_pi + (b + db)) * n_tr + (r + dr)) * n_ph + c
                v0 = params[val_at + base]
                v1 = params[val_at + base + 1] if fc > 0.0 else 0.0
                total += wa * wb * wr * ((1.0 - fc) * v0 + fc * v1)
    return total * params[SCALE]
