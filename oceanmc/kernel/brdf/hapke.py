"""Hapke's bidirectional reflectance with the shadow-hiding opposition effect: a hot-spot
(retroreflective) model used for soils and sediments (Hapke 1981, J. Geophys. Res. 86, 3039;
Hapke 1993, Theory of Reflectance and Emittance Spectroscopy, Eqs. 8.89 and 8.81-8.83).

params = (w, xi, B0, h, scale):
  w   single-scattering albedo of the grains (0 < w <= 1)
  xi  Henyey-Greenstein asymmetry of the grains in Hapke's sign convention (xi < 0: backward)
  B0  amplitude of the opposition surge, h its angular width (rad-like, ~0.01-0.2)
  scale  the albedo scale: f times it (bottom.albedo_scale; kernel/spectral.py gives each
         wavelength its share)

With mu0 = cos t_i, mu = cos t_o and the phase angle g (cos g = wi . wo: g = 0 when the light
goes straight back towards the source, the hot spot):
  f = (w / 4 pi) / (mu0 + mu) [ (1 + B(g)) P(g) + H(mu0) H(mu) - 1 ]      (1/sr)
  P(g) = (1 - xi^2) / (1 + 2 xi cos g + xi^2)^(3/2)
  B(g) = B0 / (1 + tan(g/2) / h)
  H(x) = 1 / (1 - w x [r0 + (1 - 2 r0 x)/2 ln((1 + x)/x)]), r0 = (1 - g)/(1 + g),
  g = sqrt(1 - w)   (Hapke 2002, Icarus 157, 523, Eq. 13: within 1% of Chandrasekhar's H)
f is symmetric in wi and wo (reciprocal) and non-negative (H >= 1). With w = 1 and no surge
rho_dh is 0.986-0.991 (exactly 1 with the exact H; the 1981 form (1 + 2x)/(1 + 2 g x) gave up to
1.040). The opposition term adds light that Hapke's model does not take from elsewhere, so
rho_dh can exceed 1 for bright grains and a strong surge: the scene check reports it. No analytic inverse exists: the general
tabulated sampler (general.py) samples it."""
import math

from ..compile import kernel

SCALE = 4   # params slot of the albedo scale


@kernel
def chandrasekhar_h(w, r0, x):
    """Hapke's (2002) approximation to Chandrasekhar's H function for isotropic scatterers."""
    if x <= 0.0:
        return 1.0
    return 1.0 / (1.0 - w * x * (r0 + 0.5 * (1.0 - 2.0 * r0 * x) * math.log((1.0 + x) / x)))


@kernel
def evaluate(params, wix, wiy, wiz, wox, woy, woz):
    if wiz <= 0.0 or woz <= 0.0:
        return 0.0
    w = params[0]
    xi = params[1]
    b0 = params[2]
    h = params[3]
    cos_g = min(1.0, max(-1.0, wix * wox + wiy * woy + wiz * woz))
    p = (1.0 - xi * xi) / (1.0 + 2.0 * xi * cos_g + xi * xi) ** 1.5
    # tan(g/2) = sqrt((1 - cos g)/(1 + cos g)); B -> 0 as g -> pi
    if cos_g <= -1.0:
        b = 0.0
    else:
        b = b0 / (1.0 + math.sqrt((1.0 - cos_g) / (1.0 + cos_g)) / h)
    gamma = math.sqrt(max(0.0, 1.0 - w))
    r0 = (1.0 - gamma) / (1.0 + gamma)
    multiple = chandrasekhar_h(w, r0, wiz) * chandrasekhar_h(w, r0, woz) - 1.0
    return w / (4.0 * math.pi) / (wiz + woz) * ((1.0 + b) * p + multiple) * params[SCALE]
