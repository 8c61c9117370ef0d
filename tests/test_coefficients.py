"""Photogrammetric radial coefficients and OpenCV conversion (analytic test cases).

Sources: exact polynomial profiles (the fit must return their coefficients), the exact relation
between a Gaussian and a balanced profile under a change of principal distance (Pestrecov 1958
Eq. 12 with F_c/F0 = c_b/c_g; derived in distortion/coefficients.py), and OpenCV's documented
radial model x_d = x(1 + k1 r² + k2 r⁴ + k3 r⁶) in normalised coordinates.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from distortion.coefficients import (
    balanced_to_gaussian,
    brown_to_opencv,
    evaluate_radial,
    fit_radial,
    gaussian_to_balanced,
    opencv_model,
    opencv_to_brown,
)
from distortion.errors import DataError
from orthoscope.report.coefficients import (
    format_opencv,
    format_radial_fit,
    opencv_to_dict,
    radial_fit_to_dict,
)

# An N120-like Gaussian profile: K in mm units (≈ 60 µm at r = 100 mm).
K_TRUE = (4.0e-8, -3.0e-12, 1.5e-16)
R = np.linspace(2.0, 140.0, 40)


def _dr_um(k0, k, r):
    return evaluate_radial(k0, k, r) * 1000.0


def test_gaussian_fit_recovers_known_k():
    # Exact polynomial profile → the fitted K1–K3 are the generating ones, residuals ~ 0.
    fit = fit_radial(R, _dr_um(0.0, K_TRUE, R))
    assert fit.form == "gaussian" and fit.k0 == 0.0
    # measured: K to 6.7e-16 relative, RMS 1.2e-14 um, max 4.2e-14 um; bounds ~10x that
    np.testing.assert_allclose(fit.k, K_TRUE, rtol=1e-14)
    assert fit.rms_um < 2e-13 and fit.max_abs_um < 5e-13
    d = radial_fit_to_dict(fit)
    json.dumps(d)
    assert set(d) >= {"K0", "K1", "K2", "K3", "rms_um", "max_abs_um", "form", "radius"}
    assert "K1 =" in format_radial_fit(fit)


def test_fit_residuals_reported():
    # A 9th-order term the 3-term model cannot represent leaves residuals; RMS and max agree
    # with the residual vector.
    dr = _dr_um(0.0, K_TRUE, R) + 1e-20 * R**9 * 1000.0
    fit = fit_radial(R, dr)
    assert fit.max_abs_um > 0.01
    assert fit.rms_um == pytest.approx(np.sqrt(np.mean(fit.residual_um**2)))
    assert fit.max_abs_um == pytest.approx(np.max(np.abs(fit.residual_um)))
    np.testing.assert_allclose(fit.residual_um, dr - _dr_um(0.0, fit.k, R), rtol=0, atol=1e-9)


@pytest.mark.parametrize("radius", ["measured", "ideal"])
def test_balanced_linear_term_matches_scale_change(radius):
    # A Gaussian profile recalibrated to c_b = q c_g (q = 1.0012: +0.12 % principal distance).
    # Measured radius: δr_b(r) = q δr_g(r) + (1 − q) r (exact) → K0 = 1 − q, K_b = q K_g.
    # Ideal radius: δr_b(r) = (1/q − 1) r + δr_g(r/q) → K0 = 1/q − 1, K_b,i = K_g,i q^-(2i+1).
    q = 1.0012
    if radius == "measured":
        dr_b = q * _dr_um(0.0, K_TRUE, R) + (1 - q) * R * 1000.0
    else:
        dr_b = (1 / q - 1) * R * 1000.0 + _dr_um(0.0, K_TRUE, R / q)
    fit = fit_radial(R, dr_b, form="balanced", radius=radius)
    k0_expected, kb_expected = gaussian_to_balanced(K_TRUE, q, radius)
    assert k0_expected == pytest.approx(1 - q if radius == "measured" else 1 / q - 1, rel=1e-12)
    # measured (both radius kinds): K0 to 4.4e-16, K to 2.3e-15, q to 0 relative; bounds ~10x
    assert fit.k0 == pytest.approx(k0_expected, rel=1e-14)
    np.testing.assert_allclose(fit.k, kb_expected, rtol=3e-14)
    assert fit.scale_ratio == pytest.approx(q, rel=1e-14)
    kg, q_back = balanced_to_gaussian(fit.k0, fit.k, radius)
    assert q_back == pytest.approx(q, rel=1e-14)
    np.testing.assert_allclose(kg, K_TRUE, rtol=3e-14)


def test_opencv_conversion_round_trips_exactly():
    # k_i = K_i c^(2i) and back; exact up to floating-point rounding.
    c = 121.37
    kcv = brown_to_opencv(K_TRUE, c)
    assert kcv[0] == pytest.approx(K_TRUE[0] * c**2, rel=1e-15)
    back = opencv_to_brown(kcv, c)
    np.testing.assert_allclose(back, K_TRUE, rtol=1e-14)
    np.testing.assert_allclose(brown_to_opencv(back, c), kcv, rtol=1e-14)


def test_opencv_model_reproduces_opencv_projection():
    # OpenCV's own forward model: ideal normalised radius ρ, distorted ρ(1 + k1ρ² + k2ρ⁴ + k3ρ⁶),
    # in mm on the sensor r = c ρ. Build a "measured-radius" profile from it (δr at the
    # distorted radius) and check the fitted k's are the generating ones.
    c, pitch = 120.0, 6.0
    k_cv = (0.05, -0.02, 0.004)
    rho = np.linspace(0.01, 0.6, 50)
    r_ideal = c * rho
    r_dist = c * rho * (1 + k_cv[0] * rho**2 + k_cv[1] * rho**4 + k_cv[2] * rho**6)
    dr_um = (r_dist - r_ideal) * 1000.0
    m = opencv_model(r_dist, dr_um, principal_distance_mm=c, pixel_pitch_um=pitch)
    # measured: k's to 6.8e-13 relative, RMS 3.7e-12 um; bounds ~10x that
    np.testing.assert_allclose((m.k1, m.k2, m.k3), k_cv, rtol=1e-11)
    assert m.fx_px == pytest.approx(c / 0.006)
    assert m.fit.rms_um < 5e-11
    # focal length in pixels + pitch gives the same model
    m2 = opencv_model(r_dist, dr_um, focal_length_px=20000.0, pixel_pitch_um=pitch)
    np.testing.assert_allclose((m2.k1, m2.k2, m2.k3), k_cv, rtol=1e-11)
    d = opencv_to_dict(m)
    json.dumps(d)
    assert d["dist_coeffs"] == [m.k1, m.k2, 0.0, 0.0, m.k3]
    assert "k1 =" in format_opencv(m)


def test_opencv_model_balanced_profile_uses_gaussian_principal_distance():
    # The same OpenCV camera, but the profile is balanced w.r.t. c_b = c_g/1.001 (ideal radius):
    # the balanced fit recovers c_g = c_b(1 + K0) and the generating k's.
    c_g, k_cv = 120.0, (0.05, -0.02, 0.004)
    c_b = c_g / 1.001
    rho = np.linspace(0.01, 0.6, 50)
    r_dist = c_g * rho * (1 + k_cv[0] * rho**2 + k_cv[1] * rho**4 + k_cv[2] * rho**6)
    dr_b_um = (r_dist - c_b * rho) * 1000.0
    m = opencv_model(r_dist, dr_b_um, principal_distance_mm=c_b, balanced=True)
    # measured: c_g exact to the last bit, k's to 9.9e-12 relative; bounds ~10x that
    assert m.principal_distance_mm == pytest.approx(c_g, rel=1e-14)
    np.testing.assert_allclose((m.k1, m.k2, m.k3), k_cv, rtol=1e-10)
    assert m.fx_px is None


def test_opencv_model_bad_input():
    with pytest.raises(DataError, match="needs the pixel pitch"):
        opencv_model(R, _dr_um(0.0, K_TRUE, R), focal_length_px=20000.0)
    with pytest.raises(DataError, match="principal distance in mm"):
        opencv_model(R, _dr_um(0.0, K_TRUE, R))
    with pytest.raises(DataError, match="need at least 4 profile points"):
        fit_radial(R[:3], _dr_um(0.0, K_TRUE, R[:3]), form="balanced")


def test_a_profile_with_distortion_as_large_as_its_radius_is_refused():
    # radii in metres (0.004 .. 0.028) against δr in µm: 100 % distortion and more is a unit slip
    from distortion.coefficients import fit_radial, opencv_model

    r = np.array([4.0, 8.0, 12.0, 16.0, 20.0, 24.0, 28.0]) / 1000.0
    dr = np.array([2.4, 18.7, 59.3, 128.5, 219.9, 313.1, 368.8])  # Fraser & Shortis Table 1, 1.5 m
    with pytest.raises(DataError, match="as large as the radius itself"):
        fit_radial(r, dr)
    with pytest.raises(DataError, match="looks like millimetres"):
        opencv_model(r * 1000, dr, focal_length_px=9000, pixel_pitch_um=0.005)
