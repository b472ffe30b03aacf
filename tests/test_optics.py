"""Physical invariants of the dielectric optics (SPEC section 5), and the kernels' Fresnel
against the numpy oracle written from the SPEC (tests/optics_oracle.py)."""
from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from engine.tracer.kernels import materials
from tests.optics_oracle import beer_lambert, critical_angle_deg, fresnel_dielectric, reflect, refract


def test_the_kernels_fresnel_is_the_specs_at_every_angle_grazing_and_past_the_critical_one():
    cos_i = np.concatenate([np.linspace(0.0, 1.0, 401), [1e-12, 1e-9, 1e-6, 1.0 - 1e-12]])
    for eta in (1.0 / 1.5, 1.0 / 1.33, 1.0, 1.33, 1.5, 1.33 / 1.5, 1.5 / 1.33, 2.4):
        want_r, want_t = fresnel_dielectric(cos_i, eta)
        got = np.array([materials.fresnel_dielectric(float(c), eta) for c in cos_i])
        assert np.allclose(got[:, 0], want_r, rtol=0.0, atol=1e-14), eta
        assert np.allclose(got[:, 1], want_t, rtol=0.0, atol=1e-14), eta


def test_normal_incidence_reflectance_is_four_percent_for_n_1_5():
    r, cos_t = fresnel_dielectric(1.0, 1.5)
    assert abs(float(r) - 0.04) < 1e-12
    assert float(cos_t) == 1.0
    # The same from the dense side.
    r_back, _ = fresnel_dielectric(1.0, 1.0 / 1.5)
    assert abs(float(r_back) - 0.04) < 1e-12


def test_total_internal_reflection_starts_at_the_critical_angle():
    crit = critical_angle_deg(1.5, 1.0)
    assert abs(crit - math.degrees(math.asin(1 / 1.5))) < 1e-12
    below = math.cos(math.radians(crit - 0.01))
    above = math.cos(math.radians(crit + 0.01))
    r_below, ct_below = fresnel_dielectric(below, 1 / 1.5)
    r_above, ct_above = fresnel_dielectric(above, 1 / 1.5)
    assert float(r_below) < 1.0 and float(ct_below) > 0.0
    assert float(r_above) == 1.0 and float(ct_above) == 0.0


def test_grazing_incidence_reflects_everything():
    r, _ = fresnel_dielectric(0.0, 1.5)
    assert float(r) == 1.0


@settings(max_examples=200, deadline=None)
@given(cos_i=st.floats(0.0, 1.0), eta=st.floats(0.3, 3.0))
def test_reflectance_is_a_probability_and_reciprocal(cos_i, eta):
    r, cos_t = fresnel_dielectric(cos_i, eta)
    assert 0.0 <= float(r) <= 1.0
    if float(r) < 1.0 and float(cos_t) > 1e-6 and cos_i > 1e-6:
        # Stokes reciprocity: the same interface seen from the other side reflects the same.
        r_back, cos_back = fresnel_dielectric(float(cos_t), 1.0 / eta)
        assert abs(float(r_back) - float(r)) < 1e-9
        assert abs(float(cos_back) - cos_i) < 1e-9


def test_refraction_obeys_snell_and_reflection_mirrors():
    rng = np.random.default_rng(3)
    n = np.tile([[0.0, 0.0, 1.0]], (500, 1))
    d = rng.normal(size=(500, 3))
    d[:, 2] = -np.abs(d[:, 2]) - 0.05
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    cos_i = -d[:, 2]
    eta = 1.33
    r, cos_t = fresnel_dielectric(cos_i, eta)
    t = refract(d, n, cos_i, cos_t, np.full(500, eta))
    sin_i = np.hypot(d[:, 0], d[:, 1])
    sin_t = np.hypot(t[:, 0], t[:, 1])
    assert np.allclose(sin_i, eta * sin_t, atol=1e-12)
    assert np.all(t[:, 2] < 0)  # continues through the surface
    m = reflect(d, n, cos_i)
    assert np.allclose(np.linalg.norm(m, axis=1), 1.0)
    assert np.allclose(m[:, :2], d[:, :2]) and np.allclose(m[:, 2], -d[:, 2])


def test_beer_lambert_multiplies_over_path_pieces():
    sigma = np.array([0.07, 0.03, 0.005])
    whole = beer_lambert(sigma, 10.0)
    parts = beer_lambert(sigma, 4.0) * beer_lambert(sigma, 6.0)
    assert np.allclose(whole, parts)
    assert np.all(whole <= 1.0) and np.all(beer_lambert(sigma, 0.0) == 1.0)
    assert abs(whole[0] - math.exp(-0.7)) < 1e-15
