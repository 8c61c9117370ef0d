"""Prescription mode of the distortion-variation analysis (distortion.variation_trace).

Sources beside the numbers: Fraser & Shortis (1992), PE&RS 58(6) 851-855 (the paper's text), and
analytic cases (a zero-thickness lens with the stop at its vertex is orthoscopic; linear
interpolation in t = 1/N has an O(h^2) error; equal object and focus distances give the Gaussian
plane).
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from scipy.interpolate import CubicSpline

from distortion.characteristic import characteristic_distortion
from distortion.errors import DataError, UnitWarning
from distortion.variation.models import Conjugate, brown_alpha_scales
from distortion.variation.traced import (
    conjugate_geometry,
    parse_conjugate,
    trace_setting,
    trace_variation,
)
from orthoscope.report.variation import format_traced_variation, traced_variation_to_dict
from raytrace.files.library import load_lens
from raytrace.lens import Aperture, Field, Lens, Surface
from raytrace.materials import model_glass
from raytrace.paraxial import paraxial


@pytest.fixture(scope="module")
def s65():
    """The bundled Super-Angulon (f' = 100) scaled to f = 65 mm: the paper's S65."""
    lens = load_lens("super-angulon-de975637")
    return lens.scaled(65.0 / paraxial(lens, math.inf).efl)


@pytest.fixture(scope="module")
def s65_study(s65):
    # The paper's S65 experiment (Fig. 3, Fig. 7): focused at 12x, object planes 8x, 16x, 20x.
    return trace_variation(
        s65, Conjugate.scale(12), [Conjugate.scale(n) for n in (8, 16, 20)], max_field_deg=45
    )


def test_parse_conjugate():
    assert parse_conjugate("12x") == Conjugate(12.0, "x")
    assert parse_conjugate("12×") == Conjugate(12.0, "x")
    assert parse_conjugate("1.5") == Conjugate(1.5, "m")
    assert parse_conjugate("1.5m") == Conjugate(1.5, "m")
    assert math.isinf(parse_conjugate("inf").value)
    for bad in ("", "12q", "-3x", "0", "x", "mm"):
        with pytest.raises(DataError):
            parse_conjugate(bad)
    # the rest of orthoscope speaks millimetres: a unit written out is converted
    assert parse_conjugate("1500mm") == Conjugate(1.5, "m")
    assert parse_conjugate("150cm") == Conjugate(1.5, "m")
    # a plain number is metres here (Fraser & Shortis); one this large looks like millimetres
    with pytest.warns(UnitWarning, match=r"'2000' is read as 2000 m .* write 2000mm, or 2000m"):
        assert parse_conjugate("2000") == Conjugate(2000.0, "m")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a unit written out, or a small plain number: silent
        assert parse_conjugate("2000m").value == 2000.0
        assert parse_conjugate("30").value == 30.0


def test_image_scale_is_gaussian_magnification(s65):
    # "12x" means Gaussian magnification -1/12 (docs/design.md, "Vocabulary"); Pestrecov Eq. (5)
    # m0 = f/(f + s).
    for n in (8.0, 12.0, 20.0):
        geo = conjugate_geometry(s65, Conjugate.scale(n))
        par = paraxial(s65, geo.object_distance)
        assert par.m0 == pytest.approx(-1.0 / n, rel=1e-12)
        assert par.s == pytest.approx(geo.s, rel=1e-12)  # s measured from H
        assert geo.scale == pytest.approx(n, rel=1e-12)


def test_metres_from_h_equal_image_scale(s65):
    # A distance in metres is measured from H: f(1 + N) mm from H is the same plane as N x.
    f = paraxial(s65, math.inf).efl
    fields = np.linspace(0, 30, 7)
    a = trace_setting(s65, Conjugate.scale(12), Conjugate.scale(8), fields)
    b = trace_setting(s65, Conjugate.metres(f * 13 / 1000), Conjugate.metres(f * 9 / 1000), fields)
    np.testing.assert_allclose(b.dr_um, a.dr_um, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(b.r_mm, a.r_mm, rtol=1e-12)


def test_same_object_and_focus_is_the_gaussian_profile_exactly(s65):
    # δr_ss' with s' = s must equal δr_s: the image plane of focus s IS the Gaussian plane of s.
    fields = np.linspace(0, 45, 31)
    st = trace_setting(s65, Conjugate.scale(12), Conjugate.scale(12), fields)
    geo = conjugate_geometry(s65, Conjugate.scale(12))
    cd = characteristic_distortion(
        s65, fields, object_distance=geo.object_distance
    )  # default plane: the Gaussian plane
    assert st.gaussian and st.defocus == pytest.approx(0.0, abs=1e-12)
    np.testing.assert_allclose(st.r_mm, np.abs(cd.yp[0]), rtol=0, atol=1e-12)
    np.testing.assert_allclose(st.dr_um, 1000 * cd.D0[0] * np.sign(cd.y0p[0]), rtol=0, atol=1e-9)


def test_non_gaussian_plane_is_the_focus_plane(s65_study):
    # Unit focusing: every profile at focus 12x uses the Gaussian image plane of 12x.
    st = {s.label: s for s in s65_study.settings}
    z = st["12×"].from_last_vertex
    for lab in ("8×(12×)", "16×(12×)", "20×(12×)"):
        assert st[lab].from_last_vertex == z
        assert st[lab].defocus != 0.0
    # an object closer than the focus (8x) images behind the plane: the plane is before it
    assert st["8×(12×)"].defocus < 0 < st["20×(12×)"].defocus


def test_common_grid_interpolation_error_is_small(s65):
    # The spline of the 121-field trace, evaluated at the radii of the fields halfway between
    # its samples, against a trace at those fields (the module docstring's claim: < 1e-4 µm;
    # measured 2.1e-6 µm, bound ~10x that).
    dense = np.linspace(0, 45, 241)
    st = trace_setting(s65, Conjugate.scale(12), Conjugate.scale(8), dense[::2])
    mid = trace_setting(s65, Conjugate.scale(12), Conjugate.scale(8), dense[1::2])
    r, d = st.valid()
    pred = CubicSpline(r, d)(mid.r_mm[1:-1])
    assert np.max(np.abs(pred - mid.dr_um[1:-1])) < 2e-5


def test_s65_prediction_g_between_0_and_1(s65_study):
    # Fraser & Shortis: "The distortion values for the object plane at i x with the lens focused
    # at j x fall between the corresponding values for focused distances of i x and j x"
    # (S65, N120, R240), i.e. 0 < g < 1 — checked here on the traced S65, plane by plane and
    # radius by radius (weak radii excluded).
    fs = s65_study.analysis.focus_summaries[0]
    assert [p.obj.label for p in fs.planes] == ["8×", "16×", "20×"]
    for p in fs.planes:
        e = p.estimate
        assert e.determined
        assert 0.0 < e.g < 1.0
        strong = e.g_pointwise[~e.weak]
        assert np.all((strong > 0) & (strong < 1))
        assert e.se < 0.1


def test_s65_brown_eq1_worse_than_eq6(s65_study):
    # The paper's central claim: Brown's Eq. (1) with γ_ss' does not describe the variation,
    # Eq. (6) with the mean g does. Traced truth: RMS of Eq. (1) > RMS of Eq. (6) per plane.
    a = s65_study.analysis
    brown = {b.obj.label: b.rms_um for b in a.brown}
    for p in a.focus_summaries[0].planes:
        assert p.rms_mean_g_um < brown[p.obj.label]
    # γ values of the paper's text for 12x with 8x, 16x, 20x: 1.04, 0.98, 0.97 (f-independent)
    assert [round(g.gamma, 2) for g in a.gammas] == [1.04, 0.98, 0.97]


def test_brown_eq3_4_on_traced_profiles_converges_quadratically(s65):
    # Brown's Eq. (3)-(4) is linear interpolation in t = 1/N (variation.py docstring), exact
    # for δr = A(r) + B(r) t. For a smooth δr(t) the error is f''(t)/2 (t - t1)(t - t2): halving
    # a symmetric bracket t ± h must divide it by 4 (Taylor; the h^4 term makes it 4.011 here,
    # measured; tolerance 3 %, ~10x that).
    fields = np.linspace(0, 40, 81)
    grid = np.linspace(3, 55, 20)

    def gauss(n):
        st = trace_setting(s65, Conjugate.scale(n), Conjugate.scale(n), fields)
        r, d = st.valid()
        return CubicSpline(r, d)(grid)

    t = 1 / 12
    truth = gauss(12)
    errs = []
    for h in (1 / 24, 1 / 48):
        n1, n2 = 1 / (t + h), 1 / (t - h)
        a = brown_alpha_scales(12, n1, n2)
        errs.append(np.max(np.abs(a * gauss(n1) + (1 - a) * gauss(n2) - truth)))
    assert errs[0] / errs[1] == pytest.approx(4.0, rel=0.03)


def test_s65_interpolation_checks_reported(s65_study):
    checks = {c.s.label: c for c in s65_study.analysis.interpolation_checks}
    assert set(checks) == {"12×", "16×"}  # Gaussian profiles bracketed by two others
    c = checks["12×"]
    assert c.alpha == pytest.approx(1 / 3)  # α = (1/12 − 1/16)/(1/8 − 1/16)
    assert c.max_abs_um == pytest.approx(np.max(np.abs(c.predicted_um - c.measured_um)))
    # better than taking the nearer calibrated neighbour (8x) unchanged: Eq. (3) earns its keep
    prof = {p.label: p for p in s65_study.profile_set.profiles}
    assert c.max_abs_um < np.max(np.abs(prof["8×"].dr_um - prof["12×"].dr_um))


def test_thin_lens_stop_at_lens_is_distortion_free_and_g_undetermined():
    # A zero-thickness lens with the stop at its vertex: the chief ray passes undeviated through
    # H = H' = E0 = E0' (m_e = 1), so y' = p0' tan α exactly: no distortion in ANY plane, and
    # Eq. (6) has no leverage: g must be reported undetermined, not divided by zero.
    g = model_glass(1.5168, 64.17)
    thin = Lens(
        "thin",
        (Surface(0.01, 0.0, g, stop=True), Surface(-0.01, 97.0)),
        Aperture("fnumber", 8.0),
        Field("angle", 30.0),
    )
    tv = trace_variation(thin, Conjugate.scale(12), [Conjugate.scale(n) for n in (8, 16, 20)])
    for p in tv.profile_set.profiles:
        assert np.max(np.abs(p.dr_um)) < 1e-6
    fs = tv.analysis.focus_summaries[0]
    assert all(p.estimate.status == "undetermined" for p in fs.planes)
    assert math.isnan(fs.summary.mean)
    assert any("no g_ss' could be determined" in m for m in tv.analysis.messages)


def test_output_text_and_json(s65_study):
    txt = format_traced_variation(s65_study)
    for needle in ("unit focusing", "characteristic distortion", "8×(12×)", "mean g =", "γ"):
        assert needle in txt
    d = traced_variation_to_dict(s65_study)
    assert d["mode"] == "prescription"
    assert len(d["settings"]) == 7
    assert len(d["variation"]["g"][0]["planes"]) == 3


def test_bad_requests(s65):
    with pytest.raises(DataError, match="focal length"):
        trace_variation(s65, Conjugate.metres(0.05), [Conjugate.scale(8)])
    with pytest.raises(DataError, match="one profile"):
        trace_variation(s65, Conjugate.scale(12), [Conjugate.scale(12)])
    with pytest.raises(DataError, match="beyond the largest radius"):
        trace_variation(s65, Conjugate.scale(12), [Conjugate.scale(8)], r_max=1000.0)
    with pytest.raises(DataError, match="field angle"):
        trace_variation(s65, Conjugate.scale(12), [Conjugate.scale(8)], max_field_deg=95)
