"""Glossy microfacet BRDF: GGX / Trowbridge-Reitz normal distribution, height-correlated Smith
masking-shadowing and unpolarized Fresnel reflection at the facets, plus an optional Lambertian
term (Walter, Marschner, Li & Torrance 2007, EGSR, "Microfacet models for refraction through
rough surfaces"; Heitz 2014, JCGT 3(2), "Understanding the masking-shadowing function").

params = (alpha, n_ratio, rho_d, fresnel, scale):
  alpha    roughness (the GGX width, 0 < alpha <= 1; small: near-mirror)
  n_ratio  refractive index of the facet material relative to the water above it
  rho_d    reflectance of an added Lambertian term (0: pure microfacet reflection)
  fresnel  1: Fresnel reflectance at the facets; 0: F = 1 (perfectly reflecting facets, the
           "white furnace" configuration)
  scale    the albedo scale: f times it (bottom.albedo_scale, the largest over the run's
           wavelengths; kernel/spectral.py gives each wavelength its share)

f = scale [F(wi.h) D(h) G2(wi, wo) / (4 cos t_i cos t_o) + rho_d/pi], with h = (wi + wo)/|wi + wo|,
D(h) = alpha^2 / (pi ((h.n)^2 (alpha^2 - 1) + 1)^2),
G2 = 1/(1 + Lambda(wi) + Lambda(wo)), Lambda(v) = (sqrt(1 + alpha^2 tan^2 t_v) - 1)/2.
f is symmetric in wi and wo (reciprocal) and non-negative; single-scattering microfacet
reflection loses energy at large roughness (rho_dh < 1 even with F = 1), and rho_d added on top
can break energy conservation, which the scene check reports.

Sampling (the model's own sampler): with probability q_s the visible normals of GGX (Heitz 2018,
JCGT 7(4), "Sampling the GGX distribution of visible normals"), reflected about the sampled
normal, whose density is G1(wi) D(h) / (4 cos t_i); otherwise a cosine-weighted direction.
q_s = 1 without a Lambertian term, else max(0.2, F(t_i)/(F(t_i) + rho_d)). The weight is
f cos t_o / pdf with pdf the mixture density (one-sample multiple importance sampling), which for
pure microfacet reflection is scale F G2 / G1(wi) (<= 1 at scale <= 1). A reflected direction
below the horizon has f = 0: it comes back as (0, 0, 1) with weight 0."""
import math

from ..compile import kernel
from ..geometry import from_angles
from ..surface.fresnel import fresnel as fresnel_r

SCALE = 4   # params slot of the albedo scale


@kernel
def lam(alpha, vz):
    """Smith's Lambda for GGX at direction cosine vz > 0."""
    c2 = vz * vz
    if c2 <= 0.0:
        return math.inf
    t2 = max(0.0, 1.0 - c2) / c2
    return 0.5 * (math.sqrt(1.0 + alpha * alpha * t2) - 1.0)


@kernel
def distribution(alpha, hz):
    a2 = alpha * alpha
    d = hz * hz * (a2 - 1.0) + 1.0
    return a2 / (math.pi * d * d)


@kernel
def facet_reflectance(params, cos_h):
    if params[3] == 0.0:
        return 1.0
    return fresnel_r(1.0, params[1], min(1.0, max(0.0, cos_h)))[0]


@kernel
def half_vector(wix, wiy, wiz, wox, woy, woz):
    """The unit bisector of wi and wo; (0, 0, 0) when they are opposite."""
    hx = wix + wox
    hy = wiy + woy
    hz = wiz + woz
    norm = math.sqrt(hx * hx + hy * hy + hz * hz)
    if norm <= 0.0:
        return 0.0, 0.0, 0.0
    return hx / norm, hy / norm, hz / norm


@kernel
def specular(params, wix, wiy, wiz, wox, woy, woz):
    """The microfacet part of f (1/sr)."""
    if wiz <= 0.0 or woz <= 0.0:
        return 0.0
    hx, hy, hz = half_vector(wix, wiy, wiz, wox, woy, woz)
    if hz <= 0.0:
        return 0.0
    alpha = params[0]
    cos_h = wix * hx + wiy * hy + wiz * hz
    g2 = 1.0 / (1.0 + lam(alpha, wiz) + lam(alpha, woz))
    return facet_reflectance(params, cos_h) * distribution(alpha, hz) * g2 / (4.0 * wiz * woz)


@kernel
def evaluate(params, wix, wiy, wiz, wox, woy, woz):
    if wiz <= 0.0 or woz <= 0.0:
        return 0.0
    f = specular(params, wix, wiy, wiz, wox, woy, woz) + params[2] / math.pi
    return f * params[SCALE]


@kernel
def specular_share(params, wiz):
    if params[2] <= 0.0:
        return 1.0
    fs = facet_reflectance(params, wiz)
    return max(0.2, fs / (fs + params[2]))


@kernel
def specular_pdf(params, wix, wiy, wiz, wox, woy, woz):
    """Density of the reflected visible-normal sample: G1(wi) D(h) / (4 cos t_i)."""
    if wiz <= 0.0 or woz <= 0.0:
        return 0.0
    hz = half_vector(wix, wiy, wiz, wox, woy, woz)[2]
    if hz <= 0.0:
        return 0.0
    alpha = params[0]
    g1 = 1.0 / (1.0 + lam(alpha, wiz))
    return g1 * distribution(alpha, hz) / (4.0 * wiz)


@kernel
def pdf(params, wix, wiy, wiz, wox, woy, woz):
    if wiz <= 0.0 or woz <= 0.0:
        return 0.0
    q = specular_share(params, wiz)
    return q * specular_pdf(params, wix, wiy, wiz, wox, woy, woz) + (1.0 - q) * woz / math.pi


@kernel
def visible_normal(alpha, wix, wiy, wiz, u1, u2):
    """A microfacet normal drawn from GGX's distribution of visible normals seen from wi (Heitz
    2018, listing 1)."""
    vx = alpha * wix
    vy = alpha * wiy
    vz = wiz
    vn = 1.0 / math.sqrt(vx * vx + vy * vy + vz * vz)
    vx *= vn
    vy *= vn
    vz *= vn
    lensq = vx * vx + vy * vy
    if lensq > 0.0:
        inv = 1.0 / math.sqrt(lensq)
        t1x = -vy * inv
        t1y = vx * inv
    else:
        t1x = 1.0
        t1y = 0.0
    # T2 = V x T1 (T1 has no z component)
    t2x = -vz * t1y
    t2y = vz * t1x
    t2z = vx * t1y - vy * t1x
    r = math.sqrt(u1)
    phi = 2.0 * math.pi * u2
    p1 = r * math.cos(phi)
    p2 = r * math.sin(phi)
    s = 0.5 * (1.0 + vz)
    p2 = (1.0 - s) * math.sqrt(max(0.0, 1.0 - p1 * p1)) + s * p2
    p3 = math.sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2))
    nx = p1 * t1x + p2 * t2x + p3 * vx
    ny = p1 * t1y + p2 * t2y + p3 * vy
    nz = p2 * t2z + p3 * vz
    hx = alpha * nx
    hy = alpha * ny
    hz = max(1e-300, nz)
    hn = 1.0 / math.sqrt(hx * hx + hy * hy + hz * hz)
    return hx * hn, hy * hn, hz * hn


@kernel
def sample(params, wix, wiy, wiz, u1, u2):
    if wiz <= 0.0:
        return 0.0, 0.0, 1.0, 0.0
    q = specular_share(params, wiz)
    if u1 < q:
        hx, hy, hz = visible_normal(params[0], wix, wiy, wiz, min(1.0, u1 / q), u2)
        d = 2.0 * (wix * hx + wiy * hy + wiz * hz)
        wox = d * hx - wix
        woy = d * hy - wiy
        woz = d * hz - wiz
        norm = 1.0 / math.sqrt(wox * wox + woy * woy + woz * woz)
        wox *= norm
        woy *= norm
        woz *= norm
    else:
        wox, woy, woz = from_angles(math.sqrt(min(1.0, (u1 - q) / (1.0 - q))),
                                    2.0 * math.pi * u2)
    if woz <= 0.0:
        return 0.0, 0.0, 1.0, 0.0
    dens = pdf(params, wix, wiy, wiz, wox, woy, woz)
    if dens <= 0.0:
        return wox, woy, woz, 0.0
    return wox, woy, woz, evaluate(params, wix, wiy, wiz, wox, woy, woz) * woz / dens
