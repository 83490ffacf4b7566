"""The wind-roughened surface (kernel/surface/cox_munk.py): its slope laws against independent
numerical integrals, conservation (reflected + transmitted = incident) and the flat limit from
both sides at incidence 0 to 89 deg, reciprocity of reflection and transmission, bad input.

Statistical checks use fixed streams and z-scores against binomial standard errors, |z| < 4."""
import math

import numba
import numpy as np
import pytest
import yaml
from scipy import integrate, special

import oceanmc
from oceanmc import config as cfg
from oceanmc.config.base import ConfigError
from oceanmc.kernel.rng import batch_state, uniform
from oceanmc.kernel.surface import cox_munk, dispatch
from oceanmc.kernel.surface.fresnel import fresnel
from oceanmc.scene import surface as surface_packer
from surface_helpers import cell_transfer, projected

N_WATER = 1.34
ANGLES = (0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 85.0, 89.0)


def rough(mss):
    return surface_packer.pack(cfg.Surface(model="cox_munk", mean_square_slope=mss), N_WATER)[0]


@numba.njit
def walks(surface, ux, uy, uz, n, rng):
    """n samples of the surface from direction (ux, uy, uz): (ox, oy, oz, weight, transmitted)."""
    out = np.empty((n, 5))
    for i in range(n):
        ox, oy, oz, w, t = dispatch.sample(surface, ux, uy, uz, uniform(rng), rng)
        out[i, 0], out[i, 1], out[i, 2], out[i, 3], out[i, 4] = ox, oy, oz, w, t
    return out


def test_smith_lambda_matches_its_defining_integral():
    """Lambda(theta) = integral over slopes q > cot(theta) of (q - cot) p(q) dq / cot (Smith
    1967; Walter et al. 2007 eq. 27 is its closed form), p the slope component's normal law of
    variance alpha^2 / 2, integrated by scipy; and Lambda(-w) = -1 - Lambda(w)."""
    alpha = 0.3
    for theta_deg in (10.0, 45.0, 70.0, 85.0, 89.0):
        t = math.radians(theta_deg)
        cot = 1.0 / math.tan(t)
        sd = alpha / math.sqrt(2.0)
        ref = integrate.quad(lambda q: (q - cot) * math.exp(-0.5 * (q / sd) ** 2)
                             / (sd * math.sqrt(2 * math.pi)), cot, np.inf)[0] / cot
        x, z = math.sin(t), math.cos(t)
        assert cox_munk.smith_lambda(alpha, alpha, x, 0.0, z) == pytest.approx(ref, rel=1e-9,
                                                                              abs=1e-14)
        assert cox_munk.smith_lambda(alpha, alpha, x, 0.0, -z) == pytest.approx(-1.0 - ref,
                                                                               rel=1e-12)


@pytest.mark.parametrize("a", [0.0, 0.05, 0.7, 2.0, 8.0, 30.0, math.inf])
def test_projected_slope_inverts_its_distribution_function(a):
    """The visible slope along the view azimuth: F(t(u)) = u for F(t) ~ a Phi(t) + phi(t)."""
    def cdf(t, a):
        if math.isinf(a):
            return special.ndtr(t)
        return (a * special.ndtr(t) + math.exp(-t * t / 2) / math.sqrt(2 * math.pi)) / (
            a * special.ndtr(min(a, 9.0)) + math.exp(-min(a, 9.0) ** 2 / 2)
            / math.sqrt(2 * math.pi))
    for u in (1e-9, 0.01, 0.3, 0.5, 0.77, 0.999, 1.0 - 1e-9):
        t = cox_munk.projected_slope(a, u)
        assert t <= a
        assert cdf(t, a) == pytest.approx(u, rel=1e-7, abs=1e-12)


@pytest.mark.parametrize("from_air", [True, False])
def test_conservation_and_the_flat_limit(from_air):
    """From 0 to 89 deg on both sides: every walk leaves on exactly one side with weight 1, on
    the right side of the surface (reflected + transmitted = incident), and with slopes of
    1e-6 the reflected fraction is the flat surface's exact Fresnel R (|z| < 4) and the
    directions are the flat mirror and Snell directions (within 0.5 deg)."""
    surface = rough(1e-6)
    n1, n2 = (1.0, N_WATER) if from_air else (N_WATER, 1.0)
    for k, theta_deg in enumerate(ANGLES):
        t = math.radians(theta_deg)
        ux, uz = math.sin(t), math.cos(t) * (1.0 if from_air else -1.0)
        n = 40_000
        out = walks(surface, ux, 0.0, uz, n, batch_state(11, k))
        assert np.all(out[:, 3] == 1.0)
        transmitted = out[:, 4] == 1.0
        # transmitted light keeps going the same vertical way, reflected light turns back
        assert np.all(np.sign(out[transmitted, 2]) == np.sign(uz))
        assert np.all(np.sign(out[~transmitted, 2]) == -np.sign(uz))
        r_flat, cos_t = fresnel(n1, n2, abs(uz))
        r = 1.0 - transmitted.mean()
        se = max(math.sqrt(r_flat * (1.0 - r_flat) / n), 1.0 / n)
        assert abs(r - r_flat) / se < 4.0, (theta_deg, r, r_flat)
        if (~transmitted).any():
            cos_r = np.abs(out[~transmitted, 2])
            assert np.all(np.abs(np.degrees(np.arccos(np.minimum(cos_r, 1.0))) - theta_deg)
                          < 0.5)
        if transmitted.any():
            cos_o = np.abs(out[transmitted, 2])
            assert np.all(np.abs(np.degrees(np.arccos(np.minimum(cos_o, 1.0)))
                                 - math.degrees(math.acos(cos_t))) < 0.5)


@pytest.mark.parametrize("from_air", [True, False])
def test_conservation_on_a_rough_sea(from_air):
    """A 10 m/s sea (mss 0.0542), 0 to 89 deg on both sides: weight 1, every walk ends on one
    side, heading away from the surface: reflected + transmitted = incident."""
    surface = surface_packer.pack(cfg.Surface(model="cox_munk", wind_speed_m_s=10.0,
                                              wind_direction_deg=30.0), N_WATER)[0]
    for k, theta_deg in enumerate(ANGLES):
        t = math.radians(theta_deg)
        uz = math.cos(t) * (1.0 if from_air else -1.0)
        out = walks(surface, math.sin(t) * 0.6, math.sin(t) * 0.8, uz, 20_000,
                    batch_state(12, k))
        assert np.all(out[:, 3] == 1.0)
        transmitted = out[:, 4] == 1.0
        assert np.all(out[transmitted, 2] * uz > 0.0)
        assert np.all(out[~transmitted, 2] * uz < 0.0)
        assert np.allclose(np.sum(out[:, :3] ** 2, axis=1), 1.0, atol=1e-12)


def test_normal_incidence_matches_the_single_reflection_integral():
    """At normal incidence from the air the facets met first are distributed as the slopes
    (projected area), so the reflected fraction is integral p(z) R_Fresnel(atan |z|) d2z
    (Cox & Munk 1954) plus multiple reflections, negligible at 5 m/s (facet tilts below
    ~25 deg send the reflected ray up and away): the scipy integral, |z| < 4."""
    mss = 0.003 + 5.12e-3 * 5.0
    ref = integrate.quad(lambda r: 2.0 * r / mss * math.exp(-r * r / mss)
                         * fresnel(1.0, N_WATER, 1.0 / math.sqrt(1.0 + r * r))[0], 0, np.inf)[0]
    n = 400_000
    out = walks(rough(mss), 0.0, 0.0, 1.0, n, batch_state(13, 0))
    r = 1.0 - out[:, 4].mean()
    assert abs(r - ref) / math.sqrt(ref * (1 - ref) / n) < 4.0, (r, ref)


@pytest.mark.parametrize("from_air", [True, False])
def test_reflection_and_transmission_are_reciprocal(from_air):
    """f(a, b) = f(b, a) for reflection, f(a -> b) / n_b^2 = f(b -> a) / n_a^2 for
    transmission (Veach 1997, 5.2): for light arriving uniformly in projected solid angle from
    cell A, the fraction P(A -> B) reaching cell B satisfies P(A->B) C_A / n_B^2 =
    P(B->A) C_B / n_A^2 with C the cells' projected solid angles, whatever the cells' size.
    mss 0.1 (a rough sea, where multiple interactions matter), |z| < 4."""
    surface = rough(0.1)
    d = math.radians
    a = (d(15.0), d(30.0), d(0.0), d(20.0))
    b_reflect = (d(40.0), d(60.0), d(170.0), d(200.0))
    n = 400_000
    p_ab = cell_transfer(surface, None, from_air, a, b_reflect, n, batch_state(14, 0)) / n
    p_ba = cell_transfer(surface, None, from_air, b_reflect, a, n, batch_state(14, 1)) / n
    lhs, rhs = p_ab * projected(a), p_ba * projected(b_reflect)
    se = math.hypot(math.sqrt(p_ab / n) * projected(a), math.sqrt(p_ba / n) * projected(b_reflect))
    assert p_ab > 1e-3 and abs(lhs - rhs) / se < 4.0, (lhs, rhs)
    # transmission: A on this side to B on the other, and back from B's side
    n_a, n_b = (1.0, N_WATER) if from_air else (N_WATER, 1.0)
    b_cell = (d(10.0), d(25.0), d(170.0), d(200.0))
    b_transmit = tuple(-x for x in b_cell)
    a_transmit = tuple(-x for x in a)
    p_ab = cell_transfer(surface, None, from_air, a, b_transmit, n, batch_state(14, 2)) / n
    p_ba = cell_transfer(surface, None, not from_air, b_cell, a_transmit, n,
                         batch_state(14, 3)) / n
    lhs, rhs = p_ab * projected(a) / n_b ** 2, p_ba * projected(b_cell) / n_a ** 2
    se = math.hypot(math.sqrt(p_ab / n) * projected(a) / n_b ** 2,
                    math.sqrt(p_ba / n) * projected(b_cell) / n_a ** 2)
    assert p_ab > 1e-3 and abs(lhs - rhs) / se < 4.0, (lhs, rhs)


@pytest.mark.parametrize("surface, message", [
    ({"model": "cox_munk", "wind_speed_m_s": -1}, "surface.wind_speed_m_s = -1"),
    ({"model": "cox_munk", "mean_square_slope": 0.9}, "surface.mean_square_slope = 0.9"),
    ({"model": "cox_munk", "mean_square_slope": 0.02, "wind_direction_deg": 30},
     "surface.wind_direction_deg = 30.0 needs surface.wind_speed_m_s"),
    ({"model": "cox_munk"}, "exactly one of wind_speed_m_s"),
    ({"model": "flat", "wind_speed_m_s": 5}, "belong to surface.model = 'cox_munk'"),
])
def test_bad_surface_input_is_one_line(surface, message):
    with pytest.raises(ConfigError) as err:
        oceanmc.load_config({"surface": surface, "water": {"layers": [
            {"thickness_m": 1.0, "a": 0.1, "b": 0.1}]}, "bottom": {"model": "black"}})
    text = str(err.value)
    assert message in text and "\n" not in text


@pytest.mark.parametrize("given", [{}, {"n_water": 1.0}, {"n_water": 1.34}])
def test_no_interface_stores_the_index_it_uses(given):
    """surface.model none runs with n_water 1 (index-matched) whatever n_water says (a sweep
    over surface.model keeps the scene's n_water for its other models): the stored config
    says 1 and loads back as the same scene."""
    from oceanmc.config.loading import config_to_yaml
    water = {"layers": [{"thickness_m": 1.0, "a": 0.1, "b": 0.1}]}
    scene = oceanmc.load_config({"surface": {"model": "none", **given}, "water": water,
                                 "bottom": {"model": "black"}})
    assert scene.surface.n_water == 1.0 and scene.n_water == 1.0
    assert "n_water: 1.0\n" in config_to_yaml(scene)
    again = oceanmc.load_config(yaml.safe_load(config_to_yaml(scene)))
    assert again.surface == scene.surface


def test_wind_speed_gives_cox_munk_variances():
    """Cox & Munk (1954): isotropic mss 0.003 + 5.12e-3 U; with a direction, upwind 3.16e-3 U
    and crosswind 0.003 + 1.92e-3 U; packed as Beckmann alpha^2 = 2 variance."""
    s = surface_packer.pack(cfg.Surface(model="cox_munk", wind_speed_m_s=5.0), N_WATER)[0]
    assert s["alpha_u"] ** 2 + s["alpha_c"] ** 2 == pytest.approx(2 * (0.003 + 5.12e-3 * 5))
    s = surface_packer.pack(cfg.Surface(model="cox_munk", wind_speed_m_s=5.0,
                                        wind_direction_deg=90.0), N_WATER)[0]
    assert s["alpha_u"] ** 2 == pytest.approx(2 * 3.16e-3 * 5)
    assert s["alpha_c"] ** 2 == pytest.approx(2 * (0.003 + 1.92e-3 * 5))
    assert (s["wind_cos"], s["wind_sin"]) == pytest.approx((0.0, 1.0), abs=1e-15)
