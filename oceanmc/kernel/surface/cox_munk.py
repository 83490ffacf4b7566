"""The wind-roughened sea surface: a random microsurface of facets with Gaussian slopes (Cox &
Munk 1954, J. Opt. Soc. Am. 44, 838: isotropic, or upwind/crosswind variances), each facet a
flat Fresnel/Snell interface, light followed facet by facet from the air and from the water.

The facet slope density is Beckmann's, p(zu, zc) = exp(-zu^2/au^2 - zc^2/ac^2) / (pi au ac),
with alpha^2 twice a slope component's variance (scene/surface.py). Shadowing and hiding follow
Smith's model (uncorrelated heights and slopes; Smith 1967, IEEE Trans. Antennas Propag. 15, 668;
Lambda of the Beckmann slopes: Walter et al. 2007, EGSR, eq. 27), and the light is followed
through every facet it meets by the microsurface random walk of Heitz, Hanika, d'Eon and
Dachsbacher (2016), "Multiple-scattering microfacet BSDFs with the Smith model", ACM Trans.
Graph. 35(4) 58, section 5 (dielectric): from its height h above a microsurface of uniform
height distribution (C1(h) = (h + 1)/2 on [-1, 1]), a ray travelling in direction w meets the
surface again with probability 1 - G1(w, h) = 1 - C1(h)^Lambda(w) (always, when it heads into
it), at a height drawn by inverting that law; there it meets a facet drawn from the visible
normal distribution D_w(m) ~ max(0, -w.m) D(m) (Heitz & d'Eon 2014, "Importance sampling
microfacet-based BSDFs using the distribution of visible normals", Comput. Graph. Forum 33(4),
103: stretch to alpha = 1, draw the slope along the view azimuth from its exact law, the one
across it from a normal law, unstretch); the facet reflects it with the exact Fresnel
probability R or refracts it by Snell's law (R = 1: total internal reflection), and the walk
goes on until the ray leaves the microsurface, above (reflected) or below (transmitted). Every
interaction keeps the weight: no light is made or lost (reflected + transmitted = incident), and
the walk is reciprocal (Heitz et al. 2016, section 5.3). As the slopes go to zero every facet
is horizontal and the walk is the flat surface's: one reflection or refraction.

The walk works in its own frame: x along the wind, y across it, z toward the side the light
comes from; the side the ray is on is `side` (+1: the incident side, -1: the other), and on the
other side the frame is mirrored (z -> -z, h -> -h) so that the same height and slope laws apply
(Gaussian slopes are symmetric). All draws come from the batch's stream rng (kernel/rng.py)."""
import math

from ..compile import kernel
from ..rng import uniform
from .fresnel import fresnel

INV_SQRT_PI = 1.0 / math.sqrt(math.pi)
SQRT2 = math.sqrt(2.0)
INV_SQRT_2PI = 1.0 / math.sqrt(2.0 * math.pi)
# a walk longer than this (never seen: below 1e-9 of walks at mean square slopes under 0.2) is
# ended where it is, its direction mirrored out of the surface if it heads in
MAX_INTERACTIONS = 256
ESCAPED = math.inf


@kernel
def smith_lambda(alpha_u, alpha_c, x, y, z):
    """Smith's Lambda(w) for Beckmann slopes (Walter et al. 2007, eq. 27, with the anisotropic
    alpha of the direction's azimuth, Heitz 2014, JCGT 3(2), eq. 87), signed for directions
    heading into the surface (z < 0): Lambda(-w) = -1 - Lambda(w)."""
    sin2 = x * x + y * y
    if sin2 <= 0.0:
        return 0.0 if z > 0.0 else -1.0
    alpha = math.sqrt((x * x * alpha_u * alpha_u + y * y * alpha_c * alpha_c) / sin2)
    a = z / (alpha * math.sqrt(sin2))
    if a == 0.0:
        return math.inf
    return -0.5 * math.erfc(a) + INV_SQRT_PI * math.exp(-a * a) / (2.0 * a)


@kernel
def next_height(alpha_u, alpha_c, h, x, y, z, u):
    """The height at which a ray from height h travelling (x, y, z) meets the microsurface next,
    or ESCAPED (Heitz et al. 2016, eqs. 30-34 with uniform heights: the ray is unoccluded up to
    height h' with probability (C1(h')/C1(h))^(-Lambda))."""
    if z == 0.0:
        return h
    c1 = min(1.0, max(0.0, 0.5 * (h + 1.0)))
    lam = smith_lambda(alpha_u, alpha_c, x, y, z)
    if z > 0.0 and (lam <= 0.0 or u >= 1.0 - c1 ** lam):
        return ESCAPED
    return 2.0 * c1 * (1.0 - u) ** (-1.0 / lam) - 1.0


@kernel
def projected_slope(a, u):
    """A standard normal slope t drawn with the density ~ (a - t) phi(t) on t < a (the slope
    along the view azimuth of a facet visible from a direction with a = sqrt(2) cot(theta) in the
    stretched alpha = 1 space; a = inf at normal view): its distribution function is
    a Phi(t) + phi(t), taken over max(a, 1) so that it stays finite, and inverted by Newton's
    method safeguarded by bisection."""
    c, d = (1.0, 1.0 / a) if a >= 1.0 else (a, 1.0)
    hi = min(a, 9.0)
    lo = -9.0
    target = u * (c * 0.5 * math.erfc(-hi / SQRT2) + d * INV_SQRT_2PI * math.exp(-0.5 * hi * hi))
    t = 0.0 if hi > 0.0 else 0.5 * (lo + hi)
    for _ in range(64):
        pdf = INV_SQRT_2PI * math.exp(-0.5 * t * t)
        g = c * 0.5 * math.erfc(-t / SQRT2) + d * pdf - target
        if g > 0.0:
            hi = t
        else:
            lo = t
        slope = (c - d * t) * pdf
        t_next = t - g / slope if slope > 0.0 else 0.5 * (lo + hi)
        if not lo < t_next < hi:
            t_next = 0.5 * (lo + hi)
        if abs(t_next - t) <= 1e-12 * (1.0 + abs(t)):
            return t_next
        t = t_next
    return t


@kernel
def visible_normal(alpha_u, alpha_c, vx, vy, vz, u1, u2, u3):
    """A facet normal (z > 0) drawn from the distribution of normals visible from direction
    (vx, vy, vz), vz > 0 (Heitz & d'Eon 2014, section 4: stretch, draw, rotate, unstretch), by
    the uniform draws u1 (the slope along the view azimuth), u2 and u3 (the one across it)."""
    sx = alpha_u * vx
    sy = alpha_c * vy
    sin_t = math.sqrt(sx * sx + sy * sy)
    if sin_t > 0.0:
        cos_p = sx / sin_t
        sin_p = sy / sin_t
        a = SQRT2 * vz / sin_t
    else:
        cos_p, sin_p, a = 1.0, 0.0, math.inf
    along = projected_slope(a, u1) / SQRT2
    # the slope across the view azimuth is N(0, 1/2) (Box-Muller)
    across = math.sqrt(-math.log(1.0 - u2)) * math.cos(2.0 * math.pi * u3)
    slope_u = alpha_u * (cos_p * along - sin_p * across)
    slope_c = alpha_c * (sin_p * along + cos_p * across)
    norm = 1.0 / math.sqrt(1.0 + slope_u * slope_u + slope_c * slope_c)
    return -slope_u * norm, -slope_c * norm, norm


@kernel
def facet(au, ac, n_incident, n_other, x, y, z, side, u1, u2, u3):
    """(mx, my, mz, cos_i, r, cos_t, ratio): the facet that a ray on side `side` travelling
    (x, y, z) (the walk's frame) meets, drawn from the visible normals by u1, u2, u3: its
    normal, the incidence cosine on it, its Fresnel reflectance, the refracted cosine and
    n1/n2."""
    mx, my, mz = visible_normal(au, ac, -x, -y, -side * z, u1, u2, u3)
    mz *= side
    cos_i = -(x * mx + y * my + z * mz)
    n1, n2 = (n_incident, n_other) if side > 0.0 else (n_other, n_incident)
    r, cos_t = fresnel(n1, n2, cos_i)
    return mx, my, mz, cos_i, r, cos_t, n1 / n2


@kernel
def leave_facet(x, y, z, mx, my, mz, cos_i, cos_t, ratio, reflected):
    """The unit direction of a ray (x, y, z) after the facet of normal m: mirrored, or
    refracted by Snell's law (ratio = n1/n2, cos_t the refracted cosine)."""
    if reflected:
        x += 2.0 * cos_i * mx
        y += 2.0 * cos_i * my
        z += 2.0 * cos_i * mz
    else:
        k = ratio * cos_i - cos_t
        x = ratio * x + k * mx
        y = ratio * y + k * my
        z = ratio * z + k * mz
    norm = 1.0 / math.sqrt(x * x + y * y + z * z)
    return x * norm, y * norm, z * norm


@kernel
def wander(au, ac, n_incident, n_other, x, y, z, h, side, start, u, rng):
    """(x, y, z, side): where a ray at height h on side `side` travelling (x, y, z) leaves the
    microsurface, reflected or refracted at every facet it meets with the Fresnel probability,
    counting its interactions from `start` (the facets already met). u is the draw of the next
    height, rng the stream for the others."""
    for interaction in range(start, MAX_INTERACTIONS):
        h_side = next_height(au, ac, side * h, x, y, side * z,
                             u if interaction == start else uniform(rng))
        if h_side == ESCAPED:
            break
        h = side * h_side
        mx, my, mz, cos_i, r, cos_t, ratio = facet(au, ac, n_incident, n_other, x, y, z, side,
                                                   uniform(rng), uniform(rng), uniform(rng))
        reflected = uniform(rng) < r
        x, y, z = leave_facet(x, y, z, mx, my, mz, cos_i, cos_t, ratio, reflected)
        if not reflected:
            side = -side
    else:
        if side * z < 0.0:
            z = -z
    return x, y, z, side


@kernel
def walk(surface, ux, uy, uz, u, rng):
    """(ox, oy, oz, transmitted) for a photon travelling (ux, uy, uz) that meets the surface,
    from the air when uz > 0, from the water when uz < 0: the direction it leaves in, reflected
    (back to its side) or transmitted, after every facet it meets. u is the first draw (the
    height of the first facet met), rng the stream for the others."""
    n = surface.n_water
    wc, ws = surface.wind_cos, surface.wind_sin
    from_air = uz > 0.0
    n_incident = 1.0 if from_air else n
    n_other = n if from_air else 1.0
    x, y, z, side = wander(surface.alpha_u, surface.alpha_c, n_incident, n_other,
                           ux * wc + uy * ws, -ux * ws + uy * wc, -abs(uz), ESCAPED, 1.0, 0, u,
                           rng)
    oz = -z if from_air else z
    return x * wc - y * ws, x * ws + y * wc, oz, side < 0.0


@kernel
def glint_single(surface, sun_x, sun_y, sun_z, ox, oy, oz):
    """The single-reflection glint: radiance leaving in the upward direction o per unit solar
    irradiance on a plane normal to the beam travelling (sun_x, sun_y, sun_z):
    F(i.m) p(zu, zc) G2 / (4 cos^4(theta_m) |oz|) (Cox & Munk 1954, eq. for the glitter
    radiance; the microfacet form of Walter et al. 2007, eq. 20, with D = p / cos^4), m the
    half vector and G2 = 1 / (1 + Lambda(i) + Lambda(o)) (Smith, height-correlated: the single
    reflections of the walk above; Heitz 2014, JCGT 3(2), eq. 99). In oceanmc's frame (z down)."""
    n = surface.n_water
    # the walk's frame: x along the wind, z up; both vectors pointing away from the surface
    wc, ws = surface.wind_cos, surface.wind_sin
    ix, iy, iz = -(sun_x * wc + sun_y * ws), -(-sun_x * ws + sun_y * wc), sun_z
    vx, vy, vz = ox * wc + oy * ws, -ox * ws + oy * wc, -oz
    hx, hy, hz = ix + vx, iy + vy, iz + vz
    norm = math.sqrt(hx * hx + hy * hy + hz * hz)
    if hz <= 0.0 or norm == 0.0 or vz <= 0.0 or iz <= 0.0:
        return 0.0
    hx, hy, hz = hx / norm, hy / norm, hz / norm
    au, ac = surface.alpha_u, surface.alpha_c
    zu, zc = -hx / hz, -hy / hz
    p = math.exp(-(zu * zu / (au * au) + zc * zc / (ac * ac))) / (math.pi * au * ac)
    g2 = 1.0 / (1.0 + smith_lambda(au, ac, ix, iy, iz) + smith_lambda(au, ac, vx, vy, vz))
    r = fresnel(1.0, n, ix * hx + iy * hy + iz * hz)[0]
    return r * p * g2 / (4.0 * hz ** 4 * vz)
