"""Unit values of the air-water interface (Fresnel, Snell, total internal reflection) and of the
direction geometry, against DESIGN.md section 4 and independent formulas."""
import math

import numpy as np
import pytest
from scipy import integrate

import oceanmc
from oceanmc import scene
from oceanmc.kernel import models
from oceanmc.kernel.geometry import cos_sin_turn, from_angles, turn
from oceanmc.kernel.rng import batch_state
from oceanmc.kernel.surface.fresnel import fresnel, refract

from stats_helpers import fresnel_reference

N = 1.34
CRITICAL_DEG = math.degrees(math.asin(1.0 / N))


def R(n1, n2, theta_deg):
    return fresnel(n1, n2, math.cos(math.radians(theta_deg)))[0]


def test_normal_incidence():
    # ((n - 1)/(n + 1))^2 = 0.02111 for n = 1.34, the same from either side
    assert abs(fresnel(1.0, N, 1.0)[0] - 0.02111) < 5e-6
    assert abs(fresnel(N, 1.0, 1.0)[0] - 0.02111) < 5e-6
    assert fresnel(1.0, N, 1.0)[0] == pytest.approx(((N - 1.0) / (N + 1.0)) ** 2, rel=1e-12)
    assert fresnel(1.0, N, 1.0)[1] == pytest.approx(1.0, abs=1e-15)


@pytest.mark.parametrize("theta_deg, expected", [(60.0, 0.0610), (70.0, 0.135), (80.0, 0.350),
                                                 (85.0, 0.585)])
def test_air_to_water_table(theta_deg, expected):
    # the table is rounded to its last digit: allow 0.6 of a unit in that digit
    digits = len(f"{expected}".split(".")[1])
    assert abs(R(1.0, N, theta_deg) - expected) < 0.6 * 10.0 ** -digits


def test_matches_sine_tangent_form():
    """The kernel's cosine form against Born & Wolf's sine/tangent form on a fine grid, both
    directions, and for another index (1.333)."""
    for n in (1.34, 1.333, 1.5):
        for theta in np.linspace(0.0, 89.9, 300):
            t = math.radians(theta)
            assert fresnel(1.0, n, math.cos(t))[0] == pytest.approx(
                fresnel_reference(1.0, n, t), rel=1e-9, abs=1e-14)
            assert fresnel(n, 1.0, math.cos(t))[0] == pytest.approx(
                fresnel_reference(n, 1.0, t), rel=1e-9, abs=1e-14)


def test_total_internal_reflection():
    assert CRITICAL_DEG == pytest.approx(48.27, abs=0.005)
    assert math.degrees(math.asin(1.0 / 1.333)) == pytest.approx(48.61, abs=0.005)
    above = math.cos(math.radians(CRITICAL_DEG) + 1e-9)
    below = math.cos(math.radians(CRITICAL_DEG) - 1e-6)
    r_above, cos_t_above = fresnel(N, 1.0, above)
    r_below, cos_t_below = fresnel(N, 1.0, below)
    assert r_above == 1.0 and cos_t_above == 0.0
    assert r_below < 1.0
    assert cos_t_below > 0.0
    # R rises continuously to 1 at the critical angle (grazing refraction)
    assert r_below > 0.99
    for theta in (48.5, 60.0, 75.0, 89.0, 90.0):
        assert fresnel(N, 1.0, math.cos(math.radians(theta)))[0] == 1.0
    for theta in (0.0, 20.0, 40.0, 48.0):
        assert fresnel(N, 1.0, math.cos(math.radians(theta)))[0] < 1.0
    # from air there is never total reflection except at exactly grazing incidence
    assert fresnel(1.0, N, 0.0)[0] == pytest.approx(1.0)
    assert fresnel(1.0, N, 1e-3)[0] < 1.0


@pytest.mark.parametrize("n1, n2", [(1.0, N), (N, 1.0)])
def test_snell(n1, n2):
    for theta in np.linspace(0.0, 89.99, 200):
        t = math.radians(theta)
        r, cos_t = fresnel(n1, n2, math.cos(t))
        if r == 1.0:
            assert n1 / n2 * math.sin(t) >= 1.0 - 1e-12
            continue
        assert n1 * math.sin(t) == pytest.approx(n2 * math.sqrt(1.0 - cos_t ** 2), rel=1e-9,
                                                 abs=1e-12)


@pytest.mark.parametrize("n1, n2", [(1.0, N), (N, 1.0), (1.0, 1.333)])
def test_energy_conservation(n1, n2):
    """R + T = 1 with T from the amplitude transmission coefficients (Born & Wolf 1.5.3):
    T = (n2 cos t_t)/(n1 cos t_i) (ts^2 + tp^2)/2, an independent formula."""
    for theta in np.linspace(0.0, 89.5, 180):
        ci = math.cos(math.radians(theta))
        r, ct = fresnel(n1, n2, ci)
        if r == 1.0:
            continue
        ts = 2.0 * n1 * ci / (n1 * ci + n2 * ct)
        tp = 2.0 * n1 * ci / (n1 * ct + n2 * ci)
        t = n2 * ct / (n1 * ci) * 0.5 * (ts * ts + tp * tp)
        assert r + t == pytest.approx(1.0, abs=1e-12)
        assert 0.0 <= r <= 1.0


def test_reciprocity():
    """R is the same both ways at angles related by Snell's law."""
    for theta in np.linspace(0.0, 89.9, 200):
        ci = math.cos(math.radians(theta))
        r_aw, ct = fresnel(1.0, N, ci)
        r_wa, back = fresnel(N, 1.0, ct)
        assert r_wa == pytest.approx(r_aw, rel=1e-9, abs=1e-14)
        assert back == pytest.approx(ci, abs=1e-9)


def test_index_matched():
    for ci in (1.0, 0.5, 1e-3, 0.0):
        r, ct = fresnel(1.0, 1.0, ci)
        assert r == 0.0 and ct == ci


def test_refract_direction():
    rng = np.random.default_rng(11)
    for _ in range(200):
        mu = rng.uniform(0.0, 1.0)
        phi = rng.uniform(0.0, 2.0 * math.pi)
        ux, uy, uz = from_angles(mu, phi)
        r, ct = fresnel(1.0, N, uz)
        wx, wy, wz = refract(ux, uy, uz, 1.0 / N, ct)
        assert wx * wx + wy * wy + wz * wz == pytest.approx(1.0, abs=1e-12)
        assert wz == pytest.approx(ct, abs=1e-12) and wz >= 0.0
        # azimuth kept, tangential component scaled by n1/n2
        assert math.hypot(wx, wy) == pytest.approx(math.hypot(ux, uy) / N, abs=1e-12)
        if math.hypot(ux, uy) > 1e-6:
            assert math.atan2(wy, wx) == pytest.approx(math.atan2(uy, ux), abs=1e-9)
        # upward travel from water to air keeps its sign and obeys Snell
        r2, ct2 = fresnel(N, 1.0, wz)
        ox, oy, oz = refract(wx, wy, -wz, N, ct2)
        assert oz == pytest.approx(-uz, abs=1e-9)
        assert ox == pytest.approx(ux, abs=1e-9) and oy == pytest.approx(uy, abs=1e-9)


def _hemispherical(n1, n2, weight):
    """Reflectance for radiance L(mu) ~ weight(mu), cosine-weighted over the hemisphere, with the
    kernel's fresnel()."""
    muc = math.sqrt(max(0.0, 1.0 - (n2 / n1) ** 2)) if n1 > n2 else 0.0
    num = integrate.quad(lambda m: weight(m) * m * fresnel(n1, n2, m)[0], muc, 1.0,
                         epsabs=1e-13, epsrel=1e-12, limit=200)[0]
    num += integrate.quad(lambda m: weight(m) * m, 0.0, muc)[0] if muc > 0 else 0.0  # TIR
    den = integrate.quad(lambda m: weight(m) * m, 0.0, 1.0)[0]
    return num / den


def test_diffuse_reflectances():
    """Uniform sky 0.0675, cardioidal sky (1 + 2 cos) 0.0522, uniform upwelling radiance from
    below 0.4807 with TIR, and the identity r_wa = 1 - (1 - r_aw)/n^2."""
    r_aw = _hemispherical(1.0, N, lambda m: 1.0)
    r_card = _hemispherical(1.0, N, lambda m: 1.0 + 2.0 * m)
    r_wa = _hemispherical(N, 1.0, lambda m: 1.0)
    assert abs(r_aw - 0.0675) < 6e-5
    assert abs(r_card - 0.0522) < 6e-5
    assert abs(r_wa - 0.4807) < 6e-5
    assert r_wa == pytest.approx(1.0 - (1.0 - r_aw) / N ** 2, abs=1e-9)


def test_diffuse_reflectance_monte_carlo():
    """Direct Monte Carlo of fresnel() over cosine-weighted directions from below (mu = sqrt(u)):
    the mean of R is r_wa = 0.4807 within its standard error."""
    rng = np.random.default_rng(5)
    mu = np.sqrt(rng.random(200_000))
    r = np.array([fresnel(N, 1.0, m)[0] for m in mu])
    mean, se = r.mean(), r.std(ddof=1) / math.sqrt(r.size)
    assert abs(mean - 0.4807) < 4.0 * se
    assert se < 2e-3


def test_schlick_is_not_the_default():
    config = oceanmc.load_config({"water": {"layers": [{"thickness_m": 1.0, "a": 0.1, "b": 0.0}]},
                                  "bottom": {"model": "black"}})
    surface = scene.build(config).surface[0]
    assert not surface["schlick"]
    assert surface["model"] == models.SURFACE_FLAT and surface["n_water"] == 1.34


# --- the surface as a BSDF (kernel/surface/) ------------------------------------------------

def surface_record(model="flat", n=1.34, schlick=0):
    from oceanmc import config
    from oceanmc.scene import surface
    return surface.pack(config.Surface(model=model, fresnel="schlick" if schlick else "exact"),
                        n)[0]


@pytest.mark.parametrize("theta_deg, up", [(0.0, False), (40.0, False), (85.0, False),
                                           (20.0, True), (47.0, True), (60.0, True)])
def test_flat_surface_sample_chooses_by_fresnel_with_unit_weight(theta_deg, up):
    """sample(): reflection for u < R (exact Fresnel from the air or the water), the mirror or
    Snell direction, weight f cos / pdf = 1 either way; split() gives the same R and both
    directions, and reflected + transmitted shares add up to 1 (energy conservation)."""
    from oceanmc.kernel.surface import dispatch
    surface = surface_record()
    t = math.radians(theta_deg)
    ux, uy, uz = math.sin(t), 0.0, (-1.0 if up else 1.0) * math.cos(t)
    n1, n2 = (1.34, 1.0) if up else (1.0, 1.34)
    r_ref, cos_t = fresnel(n1, n2, abs(uz))
    r, rx, ry, rz, tx, ty, tz = dispatch.split(surface, ux, uy, uz)
    assert r == pytest.approx(r_ref, abs=1e-15)
    assert (rx, ry, rz) == pytest.approx((ux, uy, -uz), abs=1e-15)
    u = (np.arange(20_000) + 0.5) / 20_000
    rng = batch_state(1, 0)   # unused by a delta surface: u decides
    picks = [dispatch.sample(surface, ux, uy, uz, v, rng) for v in u]
    reflected = np.array([not p[4] for p in picks])
    assert all(p[3] == 1.0 for p in picks)
    assert reflected.mean() == pytest.approx(r_ref, abs=1e-4)
    if r_ref < 1.0:
        ox, oy, oz = next(p[:3] for p in picks if p[4])
        assert n1 * math.sin(t) == pytest.approx(n2 * math.hypot(ox, oy), rel=1e-12)
        assert math.copysign(1.0, oz) == math.copysign(1.0, uz)
    else:
        assert reflected.all()   # total internal reflection (48.3 deg from the water)
    assert dispatch.evaluate(surface, ux, uy, uz, rx, ry, rz) == 0.0   # a delta BSDF
    assert dispatch.pdf(surface, ux, uy, uz, rx, ry, rz) == 0.0


def test_surface_transmittance_for_local_estimates():
    """What the local estimates ask of the surface: 1 - R from the water for the flat surface
    (0 beyond the critical angle), 1 without an interface."""
    from oceanmc.kernel.surface import dispatch
    for mu in (1.0, 0.9, 0.7, 0.66, 0.5, 0.1):
        assert dispatch.transmittance(surface_record(), mu) == pytest.approx(
            1.0 - fresnel(1.34, 1.0, mu)[0], abs=1e-15)
        assert dispatch.transmittance(surface_record("none", 1.0), mu) == 1.0


# --- direction geometry ----------------------------------------------------------------------

def test_turn_keeps_the_scattering_angle():
    rng = np.random.default_rng(3)
    cases = [(0.0, 0.0, 1.0), (0.0, 0.0, -1.0), (1e-7, 0.0, math.sqrt(1 - 1e-14)),
             (0.0, 1.0, 0.0)]
    # nearly vertical directions, tilted by 1e-10 .. 0.3 deg (a forward-peaked phase function
    # keeps photons there): the scattering angle must still be measured from the photon's own
    # direction, not from the vertical
    for tilt in (1e-10, 1e-6, 1e-4, 2e-3, 4.2e-3, 5e-3):
        for sign in (1.0, -1.0):
            cases.append((math.sin(tilt) * 0.6, math.sin(tilt) * 0.8, sign * math.cos(tilt)))
    for _ in range(300):
        v = rng.normal(size=3)
        cases.append(tuple(v / np.linalg.norm(v)))
    for ux, uy, uz in cases:
        for cos_t in (1.0, 0.9999, 0.5, 0.0, -0.3, -1.0, float(rng.uniform(-1, 1))):
            nx, ny, nz = turn(ux, uy, uz, cos_t, float(rng.random()))
            assert nx * nx + ny * ny + nz * nz == pytest.approx(1.0, abs=1e-12)
            assert nx * ux + ny * uy + nz * uz == pytest.approx(cos_t, abs=1e-9)


def test_cos_sin_turn_is_exact_to_rounding():
    """The table + Taylor azimuth against libm over random u, every table node, the cells' last
    values and the largest u below 1: within 8 ulp of 1 (libm and the rounding of 2 pi u
    included), and on the unit circle."""
    rng = np.random.default_rng(12)
    nodes = np.arange(1024) / 1024
    u = np.concatenate([rng.random(200_000), nodes, np.nextafter(nodes[1:], 0.0),
                        [np.nextafter(1.0, 0.0)]])
    cos_sin = np.array([cos_sin_turn(float(x)) for x in u])
    phi = 2.0 * np.pi * u
    assert np.abs(cos_sin[:, 0] - np.cos(phi)).max() <= 8 * np.finfo(float).eps
    assert np.abs(cos_sin[:, 1] - np.sin(phi)).max() <= 8 * np.finfo(float).eps
    assert np.abs((cos_sin ** 2).sum(axis=1) - 1.0).max() <= 8 * np.finfo(float).eps


def test_turn_keeps_unit_length_over_many_turns():
    """The Newton renormalisation (no sqrt) holds the length at 1 over a long walk."""
    rng = np.random.default_rng(13)
    ux, uy, uz = 0.0, 0.0, 1.0
    for _ in range(100_000):
        ux, uy, uz = turn(ux, uy, uz, float(rng.uniform(0.999, 1.0)), float(rng.random()))
    assert abs(ux * ux + uy * uy + uz * uz - 1.0) < 1e-15


def test_turn_azimuth_is_uniform():
    """For a fixed direction and scattering angle, a uniform phi gives new directions spread
    uniformly around the old one: the component along a fixed perpendicular axis has the
    arcsine distribution, mean 0 and mean square sin^2/2."""
    u = np.array([0.3, -0.5, 0.8])
    u /= np.linalg.norm(u)
    e1 = np.cross(u, [0.0, 0.0, 1.0])
    e1 /= np.linalg.norm(e1)
    rng = np.random.default_rng(8)
    cos_t = 0.6
    proj = np.array([np.dot(turn(u[0], u[1], u[2], cos_t, x), e1)
                     for x in rng.random(20_000)])
    sin2 = 1.0 - cos_t ** 2
    assert abs(proj.mean()) < 4.0 * math.sqrt(sin2 / 2 / proj.size)
    assert (proj ** 2).mean() == pytest.approx(sin2 / 2.0, rel=0.03)
