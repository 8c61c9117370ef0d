"""2-D distortion (distortion.grid): the ideal image of Pestrecov's Eq. 8 in 2-D, the decomposition
into radial, decentering and thin-prism parts, and the Brown–Conrady (Fraser 1997) fit.

Referees: the 1-D characteristic distortion (a centred lens has nothing but it along every
azimuth: an invariant); synthetic fields built here from the model formulas written out in this
file (Brown 1966 / Fraser 1997 Eq. 3 decentering, Weng et al. 1992 thin prism) or by the camera
module's Australis model; symmetry; optiland 0.6.3 real rays of a lens with a decentered element
(optiland places a surface with ``dy``), with an independent third-order prediction.

The decentered-element direction test — derivation of the expected direction, sign and slope
----------------------------------------------------------------------------------------------
Setting: the Cooke triplet (lenses/cooke-triplet-f4.toml) with its third element (surfaces 5, 6,
after the stop) decentered by d along +y; object at infinity; image plane normal to z; fields
t = (tan αx, tan αy) measured from the lens z axis; the distortion-form model of
distortion/grid/decompose.py (x right, y up): decentering P1 (r² + 2x², 2xy) + P2 (2xy, r² + 2y²),
thin prism S1 (r², 0) + S2 (0, r²); OpenCV (y down): p1 = −c P2, p2 = c P1, s3 = −c S2 (exact).

1. Direction (exact, by symmetry). The decentered lens is symmetric under the mirror x → −x, so
   its distortion field obeys Dx(−x, y) = −Dx(x, y), Dy(−x, y) = Dy(x, y). The P1 pattern has an
   x-part even in x, the S1 pattern too: both must vanish, P1 = S1 = 0, hence OpenCV p2 = 0 (and
   Brown/Fraser P1 = 0). P2 and S2 are allowed: OpenCV p1 ≠ 0 generically. The mirror y → −y maps
   the lens decentered by d onto the one decentered by −d and the P2 / S2 patterns onto their
   negatives: P2(−d) = −P2(d), S2(−d) = −S2(d) — odd in d, linear for small d.
2. Slope (third-order aberration theory of decentered systems: nodal aberration theory,
   Buchroeder 1976; Thompson 2005, JOSA A 22, 1389). Each surface j contributes third-order
   distortion E_j |H − σ_j|² (H − σ_j) (image mm, normalised field H = t / t1), centred on the
   field σ_j whose chief ray meets surface j at normal incidence: with the paraxial incidence of
   the optical-axis ray (the ray of t = 0 through the stop centre, traced with the decenters)
   i_O,j = u_O,j + (y_O,j − d_j) c_j, and of the chief ray per unit H, ī_j = ū_j + ȳ_j c_j,
   σ_j = −i_O,j / ī_j. Linear in σ: −E_j [2 (H·σ_j) H + |H|² σ_j] = −E_j σ_j (2 Hx Hy, |H|² + 2 Hy²)
   for σ_j along y: a pure P2 pattern, P2_NAT = −Σ_j E_j σ_j / h² (h = image height at H = 1).
   E_j = S_V,j / (2 n'_k u'_k) from the Seidel distortion sum S_V,j = (Ā_j / A_j)(S_III,j + S_IV,j),
   S_III = −Ā² y Δ(u/n), S_IV = −Λ² c Δ(1/n) (Λ the Lagrange invariant), with slopes u = dy/dz; in
   this slope convention the sign is the opposite of the textbook's −S_V/(2n'u'), and the sum
   Σ E_j is checked against the traced third-order distortion below.
   Real rays add a keystone part k (xy, y²) = k/2 [P2 pattern − S2 pattern] (a tilt of the
   image plane against the optical-axis ray in image space and the tilts of the decentered
   surfaces' frames do this); it moves P2 and S2 by equal and opposite amounts. So the
   prediction that holds for real rays is the keystone-free combination
       P2 + S2 = P2_NAT      (x right, y up; OpenCV: −(p1 + s3)/c),
   whose sign for this lens is +: the strongly curved last surface (σ_6 < 0, E_6 > 0) dominates.
   Measured with optiland today (11 × 11 grid to 5°, d = ±0.05 mm): P2 + S2 within 0.4 % of
   P2_NAT; the decomposition gives P2 = +4.7e-6, S2 = +1.6e-5 mm⁻¹ for d = +0.05 mm, both
   positive, and the Brown–Conrady fit (no prism term) OpenCV p1 = −4.5e-4 (negative), p2 = 0
   (its b1 = 3.9e-6 is then flagged: the thin-prism part it cannot hold leaks into it).
"""

from __future__ import annotations

import dataclasses
import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from distortion.characteristic import characteristic_distortion
from distortion.errors import DataError
from distortion.grid import (
    decompose_distortion,
    distortion_grid,
    fit_brown_conrady,
    fit_brown_conrady_points,
    radial_by_azimuth,
    solve_linear,
)
from raytrace.files.library import load_lens

ROOT = Path(__file__).resolve().parents[1]
BUNDLED = [
    "cooke-triplet-f4",
    "topogon-us2031792-fig1",
    "topogon-like-pestrecov",
    "super-angulon-de975637",
    "wide-field-ektar-us2518719",
    "tessar-fr1066698",
    "twinplex-like-55-525",
]


# ---------------------------------------------------------------- the model written out here
def brown_distortion(t, c, x0, y0, K=(), P=(0.0, 0.0), S=(0.0, 0.0)):
    """Image points of the distortion-form model (Brown 1966 decentering with Fraser's P1/P2
    placement, Weng et al. 1992 thin prism), written independently of distortion.grid:
    x = c tx, y = c ty; x' = x0 + x + x ΣK_i r^2i + P1 (r² + 2x²) + 2 P2 x y + S1 r²,
    y' = y0 + y + y ΣK_i r^2i + 2 P1 x y + P2 (r² + 2y²) + S2 r²."""
    x, y = c * t[:, 0], c * t[:, 1]
    r2 = x * x + y * y
    rad = sum(k * r2 ** (i + 1) for i, k in enumerate(K))
    xp = x0 + x + x * rad + P[0] * (r2 + 2 * x * x) + 2 * P[1] * x * y + S[0] * r2
    yp = y0 + y + y * rad + 2 * P[0] * x * y + P[1] * (r2 + 2 * y * y) + S[1] * r2
    return np.column_stack([xp, yp])


def square_t(n=15, tmax=0.5):
    a = np.linspace(-tmax, tmax, n)
    tx, ty = np.meshgrid(a, a)
    return np.column_stack([tx.ravel(), ty.ravel()])


# ---------------------------------------------------------------- centred lenses: the 1-D curve
@pytest.mark.parametrize(
    "name,kw",
    [
        ("cooke-triplet-f4", {}),
        ("topogon-like-pestrecov", {}),
        ("cooke-triplet-f4", {"object_distance": 500.0}),
    ],
)
def test_radial_part_per_azimuth_equals_the_1d_curve(name, kw):
    lens = load_lens(name)
    fields = np.linspace(0.0, lens.field.value, 9)
    planes = {"defocus": [0.0, 0.3, -0.2]}
    rb = radial_by_azimuth(lens, (0.0, 30.0, 90.0, 135.0, 250.0), fields, **planes, **kw)
    one = characteristic_distortion(lens, fields_deg=fields, **planes, **kw)
    for i in range(rb.azimuths_deg.size):
        np.testing.assert_allclose(rb.radial[:, i, :], one.D0, rtol=0, atol=1e-12)
    assert np.max(np.abs(rb.tangential)) <= 1e-12
    np.testing.assert_allclose(rb.ideal_radius, one.y0p, rtol=1e-14, atol=1e-14)


def test_radial_part_with_object_heights_equals_the_1d_curve(cooke):
    # object points −r (cos φ, sin φ) image at azimuth φ; the 1-D curve at object height −r
    r = np.linspace(0.0, 60.0, 7)
    rb = radial_by_azimuth(cooke, (0.0, 60.0, 200.0), object_radii_mm=r, object_distance=500.0)
    one = characteristic_distortion(cooke, object_heights_mm=-r, object_distance=500.0)
    for i in range(3):
        np.testing.assert_allclose(rb.radial[0, i], one.D0[0], rtol=0, atol=1e-12)
    assert np.max(np.abs(rb.tangential)) <= 1e-12


def test_a_centred_grid_is_radial_about_coinciding_reference_points(cooke):
    g = distortion_grid(cooke, grid=(9, 7), defocus=[0.0, 0.5])
    assert g.shape == (7, 9) and np.all(g.ok)
    assert np.max(np.abs(g.tangential)) <= 1e-12
    for pts in (g.axial_xy, g.ppa_xy, g.ppbs_xy):
        assert np.max(np.abs(pts)) <= 1e-14
    # the ideal grid: the Pestrecov constant of each plane times (tan αx, tan αy)
    K0 = characteristic_distortion(cooke, fields_deg=[1.0], defocus=[0.0, 0.5]).constant
    np.testing.assert_allclose(g.constant, K0, rtol=1e-15)
    np.testing.assert_allclose(g.ideal[1, ..., 0], K0[1] * np.tan(np.radians(g.field_x)))
    # corners at the lens's field (a square inscribed in the field circle)
    assert math.degrees(math.atan(math.hypot(g.tx[0, 0], g.ty[0, 0]))) == pytest.approx(20.0)


def test_sensor_grid_fills_the_sensor_corner_to_corner(cooke):
    g = distortion_grid(cooke, sensor="24x16", grid=(7, 5))
    np.testing.assert_allclose(g.ideal[0, 0, 0], [-12.0, -8.0], rtol=0, atol=1e-9)
    np.testing.assert_allclose(g.ideal[0, -1, -1], [12.0, 8.0], rtol=0, atol=1e-9)
    # a principal-point offset (x right, y up from the sensor centre): the axis lies there, and
    # the Brown–Conrady principal point (photogrammetric frame, origin at the sensor centre) too
    from distortion.camera import Sensor

    s = Sensor.from_spec("24x16", pitch_um=4, principal_point_offset_mm=(1.0, 0.5))
    g = distortion_grid(cooke, sensor=s, grid=(9, 7))
    np.testing.assert_allclose(g.ideal[0, 0, 0], [-13.0, -8.5], rtol=0, atol=1e-9)
    fit = fit_brown_conrady(g, opencv=False)
    assert fit.values["xp"] == pytest.approx(1.0, abs=1e-6)  # misfit of an off-centre grid
    assert fit.values["yp"] == pytest.approx(0.5, abs=1e-6)


# ---------------------------------------------------------------- decomposition
def test_decomposition_recovers_a_synthetic_field_and_separates_its_parts():
    t = square_t()
    truth = dict(c=50.0, x0=0.02, y0=-0.013, K=(2e-5, -3e-9, 4e-13), P=(3e-6, -1.5e-6),
                 S=(-2e-6, 2.5e-6))  # fmt: skip
    img = brown_distortion(t, **truth)
    fit = solve_linear(t, img)
    v = fit.values
    r = 25.0 * math.sqrt(2)  # largest ideal radius (mm)
    assert v["c"] == pytest.approx(50.0, rel=1e-13)
    assert abs(v["x0"] - 0.02) < 1e-12 and abs(v["y0"] + 0.013) < 1e-12
    for i, k in enumerate(truth["K"], start=1):
        assert abs(v[f"K{i}"] - k) * r ** (2 * i + 1) < 1e-10  # its effect at the edge, mm
    for name, val in zip(("P1", "P2", "S1", "S2"), (*truth["P"], *truth["S"]), strict=True):
        assert abs(v[name] - val) * r * r < 1e-11
    assert fit.rms_mm < 1e-12
    # a pure decentering field has no thin prism, and the other way round
    dec = solve_linear(t, brown_distortion(t, 50.0, 0.0, 0.0, P=(4e-6, 1e-6)))
    assert max(abs(dec.values["S1"]), abs(dec.values["S2"])) * r * r < 1e-11
    pri = solve_linear(t, brown_distortion(t, 50.0, 0.0, 0.0, S=(4e-6, 1e-6)))
    assert max(abs(pri.values["P1"]), abs(pri.values["P2"])) * r * r < 1e-11


@pytest.mark.parametrize("kind,ratio", [("decentering", 3.0), ("thin_prism", 1.0)])
def test_radial_to_tangential_ratio(kind, ratio):
    """The derivation of distortion/grid/decompose.py: along the axis ψ the radial part of a
    decentering field is 3 J r², across it the tangential part is J r² (3:1); thin prism 1:1."""
    psi = math.radians(35.0)
    amp = 2e-6
    a = (amp * math.cos(psi), amp * math.sin(psi))
    kw = {"P": a} if kind == "decentering" else {"S": a}
    r = 10.0
    for phi, comp, expect in ((psi, "radial", ratio * amp * r * r),
                              (psi + math.pi / 2, "tangential", -amp * r * r)):  # fmt: skip
        t = np.array([[r / 50.0 * math.cos(phi), r / 50.0 * math.sin(phi)]])
        d = brown_distortion(t, 50.0, 0.0, 0.0, **kw)[0] - 50.0 * t[0]
        er = np.array([math.cos(phi), math.sin(phi)])
        et = np.array([-math.sin(phi), math.cos(phi)])
        val = d @ (er if comp == "radial" else et)
        assert val == pytest.approx(expect, rel=1e-12)


def test_ppbs_is_the_centroid_on_a_symmetric_grid():
    rng = np.random.default_rng(1)
    t = square_t(9)
    img = 40.0 * t + rng.normal(0.0, 0.01, t.shape)  # any asymmetric distortion
    fit = solve_linear(t, img, asymmetric=False)
    assert fit.values["x0"] == pytest.approx(img[:, 0].mean(), abs=1e-15)
    assert fit.values["y0"] == pytest.approx(img[:, 1].mean(), abs=1e-15)


def test_a_turned_reference_direction_is_a_principal_point_shift_plus_decentering_and_prism():
    """decompose.py: an image obeying the model with directions t obeys it, to first order in ε,
    with the directions of a frame turned by ε about y, t' = t + ε (1 + tx², tx ty), and
    x0 − c ε, P1 − ε/(2c), S1 + ε/(2c)."""
    c, eps = 50.0, 1e-5
    t = square_t(11, 0.3)
    img = c * t  # distortion-free
    L, M, N = t[:, 0], t[:, 1], np.ones(len(t))
    ca, sa = math.cos(eps), math.sin(eps)
    Lr, Nr = ca * L + sa * N, -sa * L + ca * N  # the directions in the turned frame
    t_turned = np.column_stack([Lr / Nr, M / Nr])
    v = solve_linear(t_turned, img).values
    # measured relative errors 8.3e-11 (x0), 1.4e-10 (P1), 1.9e-9 (S1); bounds ~10x that
    assert v["x0"] == pytest.approx(-c * eps, rel=1e-9)
    assert v["P1"] == pytest.approx(-eps / (2 * c), rel=2e-9)
    assert v["S1"] == pytest.approx(eps / (2 * c), rel=2e-8)


def test_components_add_up_to_the_distortion(cooke):
    g = distortion_grid(cooke, grid=9, reference_point="ppbs")
    d = decompose_distortion(g, principal_point="ppa", camera_constant="characteristic")
    total = sum(d.components.values())
    np.testing.assert_allclose(total, g.D[0], rtol=0, atol=1e-14)
    assert "c" not in d.free and "x0" not in d.free
    d2 = decompose_distortion(g)
    assert d2.free[:3] == ("x0", "y0", "c") and d2.correlation.shape == (10, 10)
    np.testing.assert_allclose(np.diag(d2.correlation), 1.0)
    with pytest.raises(DataError, match="principal_point"):
        decompose_distortion(g, principal_point="centre")


# ---------------------------------------------------------------- Brown–Conrady (Fraser 1997)
def test_brown_conrady_fit_recovers_a_synthetic_field():
    """A field made by the camera module's Australis model (Fraser 1997, Eqs. 1–3) with known
    K1, K2, P1, P2, b1, b2 and an offset principal point: the fit recovers every parameter to
    round-off (effect at the field edge below 1e-10 mm; the synthetic points themselves are
    Newton solutions to ~1e-12 px of 1 µm)."""
    from distortion.camera import CameraModel, project

    truth = dict(c=50.0, xp=0.012, yp=-0.007, K1=-2e-5, K2=3e-9, K3=0.0, P1=4e-6, P2=-2.5e-6,
                 b1=2e-5, b2=-1e-5)  # fmt: skip
    cam = CameraModel.create("australis", 60001, 60001, pixel_size_mm=(1e-3, 1e-3), **truth)
    t = square_t(21, 0.4)
    m = project(cam, np.column_stack([t[:, 0], -t[:, 1]]), pixels="photo_mm")
    assert np.all(m.ok)
    fit = fit_brown_conrady_points(t, m.points, opencv=False)
    r = fit.r_max_mm
    powers = {"c": 0, "xp": 0, "yp": 0, "K1": 3, "K2": 5, "K3": 7, "P1": 2, "P2": 2, "b1": 1,
              "b2": 1}  # fmt: skip
    for k, v in truth.items():
        assert abs(fit.values[k] - v) * r ** powers[k] < 1e-10, k
    assert fit.rms_mm < 1e-12
    assert any("b1" in w for w in fit.warnings) and any("b2" in w for w in fit.warnings)


@pytest.mark.parametrize("name", BUNDLED)
def test_centred_bundled_lenses_give_no_decentering_and_no_affinity(name):
    lens = load_lens(name)
    g = distortion_grid(lens, grid=11)
    fit = fit_brown_conrady(g, opencv=False)
    r = fit.r_max_mm
    bound = 1e-14 * r  # round-off: ~100 ulp of the field radius
    assert abs(fit.values["P1"]) * r * r < bound and abs(fit.values["P2"]) * r * r < bound
    assert abs(fit.values["b1"]) * r < bound and abs(fit.values["b2"]) * r < bound
    assert abs(fit.values["xp"]) < bound and abs(fit.values["yp"]) < bound
    assert fit.warnings == ()
    d = decompose_distortion(g)
    for k in ("P1", "P2", "S1", "S2"):
        assert abs(d.values[k]) * r * r < bound


def test_brown_conrady_opencv_coefficients_come_from_the_camera_module(cooke):
    g = distortion_grid(cooke, grid=11)
    fit = fit_brown_conrady(g)
    oc = fit.opencv_coefficients
    assert set(oc) == {"k1", "k2", "p1", "p2", "k3"}
    # docs/design.md, "Camera models": k1 ≈ −K1 c² (correction vs distortion)
    c = fit.values["c"]
    assert oc["k1"] == pytest.approx(-fit.values["K1"] * c * c, rel=0.05)
    assert fit.opencv.rms_px * fit.pixel_mm < 1e-4  # refit residual < 0.1 µm


# ---------------------------------------------------------------- a decentered element
def _prescription(lens):
    c = np.array([s.curvature for s in lens.surfaces])
    t = np.array([s.thickness for s in lens.surfaces], dtype=float)
    idx = lens.indices((lens.wavelength,))[0]
    return c, t, idx[:-1], idx[1:]


def _ynu(c, t, n0, n1, y, u, dec=None):
    """Paraxial trace with slopes u = dy/dz; a surface decentered by dec[j] refracts about its own
    axis: n'u' = n u − (y − dec_j) (n' − n) c_j. Returns heights, slopes before, slopes after."""
    m = len(c)
    dec = np.zeros(m) if dec is None else dec
    Y, U, Up = np.empty(m), np.empty(m), np.empty(m)
    for j in range(m):
        Y[j], U[j] = y, u
        u = (n0[j] * u - (y - dec[j]) * (n1[j] - n0[j]) * c[j]) / n1[j]
        Up[j] = u
        if j < m - 1:
            y = y + t[j] * u
    return Y, U, Up


def third_order_decentering(lens, dec):
    """(P2_NAT, Σ E_j / h³): the module docstring's third-order prediction of P2 + S2 (mm⁻¹) for
    surface decenters ``dec`` (mm along +y), and the third-order radial coefficient."""
    c, t, n0, n1 = _prescription(lens)
    stop = lens.stop_index
    ym, um, upm = _ynu(c, t, n0, n1, 1.0, 0.0)  # marginal ray (its scale cancels)
    a = _ynu(c, t, n0, n1, 1.0, 0.0)[0][stop]
    b = _ynu(c, t, n0, n1, 0.0, 1.0)[0][stop]
    t1 = 0.1
    yc, uc, upc = _ynu(c, t, n0, n1, -t1 * b / a, t1)  # chief ray through the stop centre
    A, Ab = n0 * (um + ym * c), n0 * (uc + yc * c)
    du = upm / n1 - um / n0
    lag = n0[0] * (uc[0] * ym[0] - um[0] * yc[0])
    s3 = -(Ab**2) * ym * du
    s4 = -(lag**2) * c * (1.0 / n1 - 1.0 / n0)
    sv = np.where(A != 0.0, Ab / np.where(A != 0.0, A, 1.0) * (s3 + s4), 0.0)
    E = sv / (2.0 * n1[-1] * upm[-1])
    h = yc[-1] + t[-1] * upc[-1]

    def ystop(y_in):
        return _ynu(c, t, n0, n1, y_in, 0.0, dec)[0][stop]

    y_in = -ystop(0.0) / (ystop(1.0) - ystop(0.0))
    yo, uo, _ = _ynu(c, t, n0, n1, y_in, 0.0, dec)
    sigma = -(uo + (yo - dec) * c) / (uc + yc * c)
    return float(-np.sum(E * sigma) / h**2), float(np.sum(E) / h**3)


def test_third_order_distortion_sum_matches_the_traced_lens(cooke):
    # the Seidel sum of the derivation (its sign convention) against the traced distortion
    _, k1_third = third_order_decentering(cooke, np.zeros(6))
    f = np.array([0.5, 1.0, 1.5, 2.0])
    one = characteristic_distortion(cooke, fields_deg=f)
    y0, D0 = one.y0p[0], one.D0[0]
    k1_traced = np.polyfit(y0**2, D0 / y0**3, 1)[1]  # D0/y³ = K1 + K2 y² + …
    assert k1_third == pytest.approx(k1_traced, rel=3e-5)  # measured 2.3e-6


def _optiland_decentered(lens, dec):
    """optiland Optic of ``lens`` with surface j's vertex at y = dec[j] (optiland's ``dy``)."""
    sys.path.insert(0, str(ROOT / "benchmarks"))
    import optiland_adapter as ola

    op = ola.build_optic(lens)
    for j, d in enumerate(dec):
        if d:
            op.surfaces[j + 1].geometry.cs.y = float(d)
    op.ray_tracer.set_aiming("iterative", max_iter=50, tol=1e-13)
    return op


def _optiland_chief_points(op, lens, X, Y):
    fmax = float(op.fields.max_field)
    rays = op.trace_generic(
        Hx=(X / fmax).ravel(), Hy=(Y / fmax).ravel(), Px=0.0, Py=0.0,
        wavelength=lens.wavelength / 1000.0,
    )  # fmt: skip
    return np.column_stack([np.asarray(rays.x), np.asarray(rays.y)])


def _small_grid(amax=5.0, n=11):
    a = np.degrees(np.arctan(np.linspace(-1.0, 1.0, n) * math.tan(math.radians(amax))))
    X, Y = np.meshgrid(a, a)
    t = np.column_stack([np.tan(np.radians(X)).ravel(), np.tan(np.radians(Y)).ravel()])
    return X, Y, t


@pytest.mark.filterwarnings("ignore")
def test_decentered_element_with_optiland_follows_the_derivation(cooke):
    """The module docstring's expectations checked today on optiland's real rays of the Cooke
    triplet with its third element decentered (optiland 0.6.3 places surfaces with dy), through
    our decomposition and Brown–Conrady fit."""
    pytest.importorskip("optiland")
    X, Y, t = _small_grid()
    out = {}
    for d in (0.05, -0.05):
        dec = np.array([0.0, 0.0, 0.0, 0.0, d, d])
        op = _optiland_decentered(cooke, dec)
        img = _optiland_chief_points(op, cooke, X, Y)
        v = solve_linear(t, img).values
        pred, _ = third_order_decentering(cooke, dec)
        r = 50.0 * math.tan(math.radians(5.0)) * math.sqrt(2)
        assert abs(v["P1"]) * r * r < 1e-13 and abs(v["S1"]) * r * r < 1e-13  # symmetry
        assert v["P2"] + v["S2"] == pytest.approx(pred, rel=0.02)  # third order
        bc = fit_brown_conrady_points(t, img)
        oc = bc.opencv_coefficients
        assert abs(bc.values["P1"]) * r * r < 1e-13 and abs(oc["p2"]) < 1e-12
        assert abs(oc["p1"]) > 1e-5
        out[d] = (v["P2"], v["S2"], oc["p1"], pred)
    # odd in d; for this lens P2, S2 > 0 and OpenCV p1 < 0 for d > 0 (measured: odd to 8e-13)
    p, m = out[0.05], out[-0.05]
    for i in range(3):
        assert p[i] == pytest.approx(-m[i], rel=1e-11)
    assert p[3] > 0 and p[0] > 0 and p[1] > 0 and p[2] < 0


def _decentered(lens, element: int, dy: float):
    """``lens`` with its ``element``-th element (1-based; its two surfaces) decentered by ``dy``
    mm along +y: each of the two surfaces moved by dy with the axis returning after it (CODE V's
    decenter-and-return, raytrace.frames), the same lens optiland gets from ``_optiland_decentered``
    (each surface's coordinate system moved by dy)."""
    from raytrace.frames import Placement

    j = 2 * (element - 1)
    ss = list(lens.surfaces)
    for k in (j, j + 1):
        ss[k] = dataclasses.replace(ss[k], placement=Placement((0.0, dy, 0.0)), after="return")
    return dataclasses.replace(lens, surfaces=tuple(ss))


@pytest.mark.filterwarnings("ignore")
def test_decentered_element_gives_decentering_on_the_y_side_only(cooke):
    """One element decentered along +y: P1 = S1 = 0 (OpenCV p2 = 0, Brown P1 = 0) to round-off,
    P2 + S2 equal to the third-order prediction, odd and linear in d, OpenCV p1 < 0 for d > 0
    (module docstring), and the traced chief rays equal optiland's to 1e-9 mm."""
    X, Y, t = _small_grid()
    results = {}
    for d in (0.05, -0.05, 0.1):
        lens_d = _decentered(cooke, 3, d)
        g = distortion_grid(lens_d, fields_x_deg=X[0], fields_y_deg=Y[:, 0])
        dec = decompose_distortion(g)
        r = g.camera_constant[0] * math.tan(math.radians(5.0)) * math.sqrt(2)
        assert abs(dec.values["P1"]) * r * r < 1e-13 and abs(dec.values["S1"]) * r * r < 1e-13
        pred, _ = third_order_decentering(cooke, np.array([0, 0, 0, 0, d, d], dtype=float))
        assert dec.values["P2"] + dec.values["S2"] == pytest.approx(pred, rel=0.02)
        bc = fit_brown_conrady(g)
        assert abs(bc.values["P1"]) * r * r < 1e-13
        assert abs(bc.opencv_coefficients["p2"]) < 1e-12
        assert np.sign(bc.opencv_coefficients["p1"]) == -np.sign(d)
        results[d] = dec.values["P2"] + dec.values["S2"]
        if pytest.importorskip("optiland"):
            op = _optiland_decentered(cooke, np.array([0, 0, 0, 0, d, d], dtype=float))
            theirs = _optiland_chief_points(op, cooke, X, Y)
            ours = g.actual[0].reshape(-1, 2)
            assert np.max(np.abs(ours - theirs)) <= 1e-13  # measured 6.2e-15 mm
    # measured: odd in d to 6.4e-13, linear (0.1 vs 2 x 0.05) to 2.4e-5; bounds ~10x that
    assert results[0.05] == pytest.approx(-results[-0.05], rel=1e-11)
    assert results[0.1] == pytest.approx(2 * results[0.05], rel=3e-4)


# ---------------------------------------------------------------- plots, report, command line
def test_plots_keep_the_ax_convention(cooke):
    import matplotlib

    matplotlib.use("Agg", force=False)
    from matplotlib.figure import Figure

    from orthoscope.plots.grid import (
        plot_distortion_vectors,
        plot_grid_distortion,
        plot_radial_by_azimuth,
    )

    g = distortion_grid(cooke, grid=7)
    d = decompose_distortion(g)
    rb = radial_by_azimuth(cooke, fields_deg=np.linspace(0, 20, 5))
    fig = Figure()
    ax = fig.subplots()
    assert plot_grid_distortion(g, exaggeration=20, ax=ax) is fig
    assert "20" in ax.get_title() and "exaggerated" in ax.get_title()
    fig2 = Figure()
    ax2 = fig2.subplots()
    assert plot_distortion_vectors(g, decomposition=d, component="radial", ax=ax2) is fig2
    fig3 = Figure()
    ax3 = fig3.subplots()
    assert plot_radial_by_azimuth(rb, ax=ax3) is fig3
    assert len(ax3.get_lines()) >= 2 * rb.azimuths_deg.size
    with pytest.raises(DataError, match="decomposition"):
        plot_distortion_vectors(g, component="decentering")


def test_report_and_json(cooke):
    from orthoscope.report.grid import format_grid, grid_to_dict
    from orthoscope.report.jsonout import dumps

    g = distortion_grid(cooke, grid=5)
    d = [decompose_distortion(g)]
    b = [fit_brown_conrady(g)]
    text = format_grid(g, d, b)
    assert "PPBS" in text and "Brown-Conrady" in text and "OpenCV" in text
    data = json.loads(dumps(grid_to_dict(g, d, b)))
    plane = data["planes"][0]
    assert np.array(plane["D_mm"]).shape == (5, 5, 2)
    assert set(plane["brown_conrady"][0]["values"]) >= {"c", "K1", "P1", "P2", "b1", "b2"}


def test_cli_grid(tmp_path, capsys):
    from orthoscope.cli import main

    png = tmp_path / "grid.png"
    vec = tmp_path / "vec.svg"
    rc = main(
        ["distortion", "cooke-triplet-f4", "--grid", "5x5", "--json", "--plot-grid", str(png),
         "--plot-vectors", str(vec)]
    )  # fmt: skip
    assert rc in (0, None)
    data = json.loads(capsys.readouterr().out)
    assert data["distortion_grid"]["shape"] == [5, 5]
    assert png.stat().st_size > 0 and vec.stat().st_size > 0
    assert main(["distortion", "cooke-triplet-f4", "--grid", "5x5", "--calibrate", "minimax"]) == 2
    assert "does not combine" in capsys.readouterr().err
    # --at and --value (calibration flags) were ignored with --grid
    for flag, value in (("--at", "5"), ("--value", "50")):
        assert main(["distortion", "cooke-triplet-f4", "--grid", "5x5", flag, value]) == 2
        assert f"--grid (2-D distortion) does not combine with {flag}" in capsys.readouterr().err
