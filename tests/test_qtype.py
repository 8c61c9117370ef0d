"""Forbes Q-type aspheres (raytrace.qtype, OpticStudio's QED_TYPE): the polynomials against
their published definitions and closed forms, the sag against optiland 0.6.3's
ForbesQNormalSlopeGeometry, the Thorlabs ASL5040-UV file (tests/data/corpus/SOURCES.md) against
optiland and its catalog focal length, the paraxial limit of real rays, the base conic when every
term is 0, and the readers and writers.

References:
- G. W. Forbes, "Shape specification for axially symmetric optical surfaces", Opt. Express 15,
  5218 (2007): Q_0^bfs = 1, Q_1^bfs = (13 − 16x)/√19; Q^con_m(x) = P_m^(0,4)(2x − 1) (Jacobi),
  Q_1^con = −(5 − 6x), Q_2^con = 15 − 14x(3 − 2x); the Qbfs are orthogonal in the slope of
  the departure u²(1 − u²) Q_m(u²) with the weight (1 − u²)^(−1/2), the property that defines
  them (checked below by quadrature, with the normalization π/2 that the published Q_0, Q_1
  have).
- scipy.special.eval_jacobi: an independent implementation of the Jacobi polynomials.
- optiland 0.6.3, optiland.geometries.forbes: Qbfs on a conic base (its ForbesQNormalSlope).
ray-optics 0.9.8 reads QED_TYPE as its base conic only (the Q terms are dropped:
rayoptics/zemax/zmxread.py handles XDAT for XOSPHERE alone), so it is no referee here.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from raytrace.errors import PrescriptionError
from raytrace.files.native import dumps, loads
from raytrace.files.zemax import dumps_zmx, loads_zmx, read_zmx
from raytrace.kernels.codes import KIND_QBFS, KIND_QCON, KIND_QUADRIC
from raytrace.lens import Aperture, Field, Lens, Surface
from raytrace.materials import fixed_index
from raytrace.packing import pack
from raytrace.paraxial import paraxial
from raytrace.qtype import QType, polynomials, qbfs_recurrence, qtype_sum, vertex_curvature
from raytrace.trace import chief_rays_2d, ray_paths, trace_rays

ROOT = Path(__file__).resolve().parents[1]
CORPUS = ROOT / "tests" / "data" / "corpus"
#: the Thorlabs file with the glass name the shipped catalogs resolve (FusedSilica → Misc
#: F_SILICA); the ray-optics copy names Corning's C79-80, which they do not hold
ASL5040 = CORPUS / "raytracing" / "ASL5040-UV-Zemax(ZMX).zmx"
#: the QED_TYPE surface of that file as written there (XDAT 2 = 6 terms, XDAT 3 = 27 mm,
#: XDAT 4..9 = a_0..a_5; CURV, CONI)
ASL_TERMS = (-0.8148370167576, -0.32311, 0.10591, -0.05058, 0.00987, -0.0022)
ASL_CURV = 5.756078762782423225e-02
ASL_CONI = -0.67609120640407927


def _asl() -> Lens:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the glass-name warning of FusedSilica
        return read_zmx(ASL5040)


# ------------------------------------------------------------------------------ polynomials
def _exact_coefficients(form: str, m: int) -> np.poly1d:
    """Q_m as an exact polynomial: interpolated at m + 1 Chebyshev points of [0, 1]."""
    x = 0.5 - 0.5 * np.cos(np.pi * (np.arange(m + 1) + 0.5) / (m + 1))
    return np.poly1d(np.polyfit(x, polynomials(form, m, x)[m], m))


def test_qbfs_low_orders_are_the_published_closed_forms():
    x = np.linspace(0.0, 1.0, 101)
    q = polynomials("qbfs", 2, x)
    assert np.max(np.abs(q[0] - 1.0)) == 0.0  # Forbes 2007
    assert np.max(np.abs(q[1] - (13.0 - 16.0 * x) / math.sqrt(19.0))) < 1e-14  # Forbes 2007
    # Q_2 by hand from Forbes 2010's recurrence: P_2 = 10 − 40x + 32x², h_0 = −1/2,
    # g_1 = −(5/4)/(√19/2), f_2² = 9 − g_1² − h_0² = 160/19, Q_2 = (P_2 − g_1 Q_1 − h_0 Q_0)/f_2
    q2 = 2.0 * (29.0 - 4.0 * x * (25.0 - 19.0 * x)) / math.sqrt(190.0)
    assert np.max(np.abs(q[2] - q2)) < 1e-14


def test_qbfs_recurrence_coefficients_equal_optiland():
    qp = pytest.importorskip("optiland.geometries.forbes.qpoly")
    f, g, h = qbfs_recurrence(12)
    assert max(abs(f[m] - qp.f_qbfs(m)) for m in range(12)) < 1e-15
    assert max(abs(g[m] - qp.g_qbfs(m)) for m in range(11)) < 1e-15
    assert max(abs(h[m] - qp.h_qbfs(m)) for m in range(10)) < 1e-15


def test_qbfs_are_orthonormal_in_the_slope_of_the_departure():
    """Forbes 2007's definition: D_m(u) = u²(1 − u²) Q_m(u²) has
    ∫₀¹ D_m' D_n' (1 − u²)^(−1/2) du = (π/2) δ_mn (u = sin θ turns it into a smooth integral
    over θ; Gauss–Legendre with 80 nodes is exact to round-off for these degrees). The
    derivatives come from the exact polynomial coefficients, not from our Clenshaw derivative."""
    M = 8
    t, w = np.polynomial.legendre.leggauss(80)
    th = 0.25 * np.pi * (t + 1.0)
    u = np.sin(th)
    d = []
    for m in range(M + 1):
        q = _exact_coefficients("qbfs", m)
        dq = q.deriv()
        x = u * u
        d.append((2.0 * u - 4.0 * u**3) * q(x) + u * u * (1.0 - u * u) * 2.0 * u * dq(x))
    G = np.array([[0.25 * np.pi * np.sum(w * d[i] * d[j]) for j in range(M + 1)]
                  for i in range(M + 1)])  # fmt: skip
    assert np.max(np.abs(G - 0.5 * np.pi * np.eye(M + 1))) < 1e-10


def test_qcon_are_jacobi_polynomials():
    special = pytest.importorskip("scipy.special")
    x = np.linspace(0.0, 1.0, 57)
    q = polynomials("qcon", 12, x)
    for m in range(13):
        ref = special.eval_jacobi(m, 0.0, 4.0, 2.0 * x - 1.0)
        assert np.max(np.abs(q[m] - ref)) <= 1e-12 * max(1.0, np.max(np.abs(ref))), m
    assert np.max(np.abs(q[1] + (5.0 - 6.0 * x))) < 1e-14  # Forbes 2007
    assert np.max(np.abs(q[2] - (15.0 - 14.0 * x * (3.0 - 2.0 * x)))) < 1e-13  # Forbes 2007


@pytest.mark.parametrize("form", ["qbfs", "qcon"])
def test_sum_derivative_is_the_derivative_of_the_exact_polynomial(form):
    rng = np.random.default_rng(7)
    a = rng.normal(size=9)
    x = np.linspace(0.0, 1.0, 41)
    s, ds = qtype_sum(QType(form, 1.0, tuple(a)), x)
    exact = np.poly1d([0.0])
    for m in range(9):
        exact = exact + _exact_coefficients(form, m) * float(a[m])
    scale = np.max(np.abs(exact.deriv()(x)))
    assert np.max(np.abs(s - exact(x))) <= 1e-11 * max(1.0, np.max(np.abs(exact(x))))
    assert np.max(np.abs(ds - exact.deriv()(x))) <= 1e-10 * scale


def test_qbfs_sum_and_slope_equal_optiland():
    qp = pytest.importorskip("optiland.geometries.forbes.qpoly")
    rng = np.random.default_rng(11)
    for n in (1, 2, 5, 12):
        a = rng.normal(size=n)
        u = np.linspace(0.0, 1.0, 33)
        s, ds = qtype_sum(QType("qbfs", 1.0, tuple(a)), u * u)
        so, dso = qp.compute_z_zprime_qbfs(list(a), u, u * u)
        assert np.max(np.abs(s - so)) < 1e-13
        assert np.max(np.abs(2.0 * u * ds - dso)) < 1e-12  # optiland: d/du = 2u d/dx


# ------------------------------------------------------------------------------ sag
def _forbes_geometry(c, k, qt):
    geometry = pytest.importorskip("optiland.geometries.forbes.geometry")
    from optiland.coordinate_system import CoordinateSystem

    cfg = geometry.ForbesSurfaceConfig(
        radius=1.0 / c, conic=k, norm_radius=qt.norm_radius,
        terms={m: a for m, a in enumerate(qt.terms)},
    )  # fmt: skip
    return geometry.ForbesQNormalSlopeGeometry(CoordinateSystem(), cfg)


def test_sag_and_normal_equal_optiland_on_random_radii():
    """Random Qbfs surfaces (curvature, conic, ρ_max, 1..10 terms) at random ρ ≤ ρ_max inside
    the conic's domain: Surface.sag (numpy) and the kernel's qtype_sag (z and the normal) against
    optiland 0.6.3's ForbesQNormalSlopeGeometry.sag / surface_normal."""
    from raytrace.kernels.surface import qtype_sag

    rng = np.random.default_rng(5)
    worst_z = worst_n = 0.0
    for _ in range(40):
        c = rng.uniform(-0.08, 0.08)
        k = rng.uniform(-3.0, 1.5)
        rn = rng.uniform(5.0, 30.0)
        if 1.0 - (1.0 + k) * c * c * rn * rn <= 0.05:
            continue
        qt = QType("qbfs", rn, tuple(rng.normal(scale=0.3, size=rng.integers(1, 11))))
        s = Surface(c, 1.0, conic=k, qtype=qt)
        geo = _forbes_geometry(c, k, qt)
        r = rn * np.sqrt(rng.random(50))
        phi = rng.uniform(0.0, 2.0 * np.pi, 50)
        x, y = r * np.cos(phi), r * np.sin(phi)
        worst_z = max(worst_z, float(np.max(np.abs(s.sag(r) - geo.sag(x, y)))))
        row = np.array([qt.packed_row()])
        nx, ny, nz = geo.surface_normal(_Rays(x, y))
        for i in range(r.size):
            z, dz, ok = qtype_sag(False, c, k, row, 0, r[i] * r[i])
            assert ok
            worst_z = max(worst_z, abs(z - float(geo.sag(x[i], y[i]))))
            n = np.array([-2.0 * x[i] * dz, -2.0 * y[i] * dz, 1.0])
            n /= np.linalg.norm(n)
            theirs = -np.array([nx[i], ny[i], nz[i]])  # optiland's normal points toward −z
            worst_n = max(worst_n, float(np.max(np.abs(n - theirs))))
    assert worst_z <= 1e-12
    assert worst_n <= 1e-12


class _Rays:
    """The two attributes optiland's surface_normal reads."""

    def __init__(self, x, y):
        self.x, self.y = x, y


# ------------------------------------------------------------------------------ the file
def test_asl5040_reads_its_qed_type_surface():
    lens = _asl()
    s = lens.surfaces[0]
    assert s.kind == KIND_QBFS and s.stop
    assert s.qtype == QType("qbfs", 27.0, ASL_TERMS)
    assert s.curvature == ASL_CURV and s.conic == ASL_CONI
    assert "Qbfs rn 27: -0.8148, -0.3231" in str(lens)


def test_asl5040_focal_length_is_the_catalog_value():
    """Thorlabs part ASL5040-UV: Ø50 mm, f = 40 mm (Thorlabs' ASL<diameter><focal length> part
    numbers; the catalog page is not in this repository), at the file's primary wavelength,
    405 nm. The Qbfs vertex curvature makes it: the base conic alone gives 37.0 mm (and so would
    the Qcon reading, whose departure starts at ρ⁴). The file's last thickness (DISZ
    19.687453, OpticStudio's solve with Corning C79-80 instead of the Misc F_SILICA read here)
    is the BFL to 5e-4 mm, an index difference of 6e-6."""
    lens = _asl()
    p = paraxial(lens)
    assert abs(p.efl - 40.0) < 1e-3
    assert abs(p.bfl - 19.687453064998852) < 1e-3
    base = paraxial(
        replace(lens, surfaces=(replace(lens.surfaces[0], qtype=None), lens.surfaces[1]))
    )
    assert abs(base.efl - 40.0) > 2.5
    s = lens.surfaces[0]
    c0 = s.curvature + 2.0 * qtype_sum(s.qtype, 0.0)[0] / 27.0**2
    assert s.vertex_curvature == pytest.approx(float(c0), rel=1e-15)


def test_asl5040_focuses_a_collimated_beam_without_spherical_aberration():
    """An asphere made to focus a collimated beam: real rays over the whole 45.72 mm entrance
    pupil meet the paraxial image plane within 0.2 µm of the axis at 405 nm (0.074 µm measured)
    — with the conic-normal projection of the departure (raytrace.qtype). With Forbes 2007's
    sphere factor 1/√(1 − c²ρ²) on this conic the same terms miss by millimetres (5.5 mm at a
    height of 16 mm; beyond 17.4 mm it is not even real)."""
    lens = _asl()
    h = np.linspace(-22.86, 22.86, 41)
    o = np.column_stack([np.zeros_like(h), h, np.full_like(h, -1.0)])
    d = np.tile([0.0, 0.0, 1.0], (h.size, 1))
    b = trace_rays(lens, o, d, clip=False)
    assert b.ok.all()
    y = b.at_plane(paraxial(lens).z_Fp)[1]
    assert np.max(np.abs(y)) < 2e-4


def _optic(lens: Lens, fields_deg: float):
    """optiland 0.6.3 Optic of ``lens`` (Qbfs surfaces as forbes_qbfs; our indices as
    IdealMaterial at the lens's wavelength; Newton tolerance 1e-15)."""
    pytest.importorskip("optiland")
    from optiland.materials import IdealMaterial
    from optiland.optic import Optic

    p = pack(lens)
    op = Optic()
    op.surfaces.add(index=0, thickness=np.inf)
    for j, s in enumerate(lens.surfaces):
        n = float(p.n_out[j])
        radius = np.inf if s.curvature == 0.0 else 1.0 / s.curvature
        kw = dict(index=j + 1, thickness=float(s.thickness), is_stop=bool(s.stop),
                  material="air" if n == 1.0 else IdealMaterial(n=n), radius=radius,
                  conic=s.conic)  # fmt: skip
        if s.qtype is not None:
            kw.update(surface_type="forbes_qbfs", norm_radius=s.qtype.norm_radius, tol=1e-15,
                      radial_terms={m: a for m, a in enumerate(s.qtype.terms)})  # fmt: skip
        op.surfaces.add(**kw)
    op.surfaces.add(index=len(lens.surfaces) + 1)
    op.set_aperture(aperture_type="EPD", value=float(paraxial(lens).epd))
    op.fields.set_type("angle")
    op.fields.add(y=0.0)
    op.fields.add(y=fields_deg)
    op.wavelengths.add(value=lens.wavelength / 1000.0, is_primary=True)
    return op


def _front_stop(lens: Lens) -> Lens:
    """The ASL5040-UV with a stop 8 mm in front (EPD 30 mm): chief rays cross the Q-type
    surface off the axis."""
    s1, s2 = lens.surfaces
    ss = (Surface(0.0, 8.0, stop=True), replace(s1, stop=False), s2)
    return replace(lens, surfaces=ss, aperture=Aperture("epd", 30.0), field=Field("angle", 8.0))


@pytest.mark.parametrize("front_stop", [False, True])
def test_asl5040_chief_rays_on_a_field_grid_equal_optiland(front_stop):
    """Real chief rays (through the centre of the real stop) on a 7 × 7 grid of angle fields to
    ±5° (±8° with the stop in front), on the file's image plane: optiland 0.6.3's chief rays
    (its iterative aim, tolerance 1e-13) to ≤ 1e-9 mm."""
    lens = _asl()
    fmax = 8.0 if front_stop else 5.0
    if front_stop:
        lens = _front_stop(lens)
    op = _optic(lens, fmax)
    op.ray_tracer.set_aiming("iterative", max_iter=50, tol=1e-13)
    a = np.linspace(-fmax, fmax, 7)
    X, Y = np.meshgrid(a, a)
    cr = chief_rays_2d(lens, X, Y, clip=False)
    assert cr.ok.all()
    ours = cr.positions_at(lens.image_z)
    rays = op.trace_generic(Hx=(X / fmax).ravel(), Hy=(Y / fmax).ravel(), Px=0.0, Py=0.0,
                            wavelength=lens.wavelength / 1000.0)  # fmt: skip
    theirs = np.stack([np.asarray(rays.x), np.asarray(rays.y)], -1).reshape(ours.shape)
    assert np.max(np.abs(ours - theirs)) <= 1e-9
    if front_stop:  # the chief rays meet the Q-type surface well off its vertex
        start = np.stack([cr.x_start, cr.y_start, cr.z_start], -1).reshape(-1, 3)
        dirs = np.stack([cr.L_start, cr.M_start, cr.N_start], -1).reshape(-1, 3)
        p = ray_paths(lens, start, dirs, clip=False)
        assert np.max(np.hypot(p.x[:, 1], p.y[:, 1])) > 1.0


def test_asl5040_ray_bundles_equal_optiland():
    """2000 random rays (heights to 22 mm, directions to ±3°) through the file's lens, bulk trace
    (the Q-type surface through the scalar surface step, F_SCALAR) against optiland 0.6.3's
    trace of the same rays, on the image plane: ≤ 1e-9 mm."""
    lens = _asl()
    op = _optic(lens, 0.0)
    from optiland.rays import RealRays

    rng = np.random.default_rng(0)
    n = 2000
    r = 22.0 * np.sqrt(rng.random(n))
    t = 2.0 * np.pi * rng.random(n)
    tx, ty = np.tan(np.deg2rad(rng.uniform(-3.0, 3.0, (2, n))))
    N = 1.0 / np.sqrt(1.0 + tx * tx + ty * ty)
    L, M = tx * N, ty * N
    z = np.full(n, -5.0)
    x, y = r * np.cos(t) + 5.0 * tx, r * np.sin(t) + 5.0 * ty
    b = trace_rays(lens, np.column_stack([x, y, z]), np.column_stack([L, M, N]), clip=False)
    assert b.ok.all()
    ox, oy = b.at_plane(lens.image_z)
    rays = RealRays(x.copy(), y.copy(), z.copy(), L.copy(), M.copy(), N.copy(), np.ones(n),
                    np.full(n, lens.wavelength / 1000.0))  # fmt: skip
    op.surfaces.trace(rays, skip=1, record=False)
    assert np.max(np.hypot(ox - np.asarray(rays.x), oy - np.asarray(rays.y))) <= 1e-9
    # the scalar path of ray_paths gives the same final segments as the bulk trace
    p = ray_paths(lens, np.column_stack([x, y, z])[:50], np.column_stack([L, M, N])[:50],
                  clip=False)  # fmt: skip
    assert np.max(np.abs(p.x[:, -1] - b.x[:50])) <= 1e-12
    assert np.max(np.abs(p.y[:, -1] - b.y[:50])) <= 1e-12


# ------------------------------------------------------------------------------ paraxial limit
def _test_lenses() -> list[Lens]:
    glass = fixed_index(1.6)
    qbfs = QType("qbfs", 12.0, (0.05, -0.02, 0.004))
    qcon = QType("qcon", 12.0, (0.003, -0.001, 0.0004))
    out = []
    for q, k in ((qbfs, 0.0), (qbfs, -0.8), (qcon, -0.5)):
        ss = (
            Surface(1.0 / 40.0, 6.0, glass, stop=True, conic=k, qtype=q),
            Surface(-1.0 / 60.0, 40.0),
        )
        out.append(Lens("q test", ss, Aperture("epd", 10.0), Field("angle", 5.0), wavelength=550.0))
    return out


@pytest.mark.parametrize("i", [0, 1, 2])
def test_real_rays_have_the_paraxial_limit(i):
    """Collimated real rays at heights h → 0 cross the axis at the paraxial focus (the error
    falls as h², spherical aberration), and their image-space slope gives the paraxial EFL:
    the paraxial layer uses the vertex curvature c + 2 S(0)/ρ_max² (Qbfs) or c (Qcon)."""
    lens = _test_lenses()[i]
    p = paraxial(lens)
    dz = []
    for h in (1e-2, 5e-3):
        o = np.array([[0.0, h, -1.0]])
        b = trace_rays(lens, o, np.array([[0.0, 0.0, 1.0]]))
        slope = b.M[0] / b.N[0]
        z_cross = b.z[0] - b.y[0] / slope
        dz.append(z_cross - p.z_Fp)
        assert -h / slope == pytest.approx(p.efl, rel=1e-5)
    assert abs(dz[1]) < 1e-5
    assert dz[0] / dz[1] == pytest.approx(4.0, rel=0.02)
    q = lens.surfaces[0].qtype
    expected = (
        1.0 / 40.0
        + (
            2.0 * 0.05 * 1.0
            + 2.0 * -0.02 * 13.0 / math.sqrt(19.0)
            + 2.0 * 0.004 * 58.0 / math.sqrt(190.0)
        )
        / 144.0
    )  # Q_m(0) above
    if q.form == "qbfs":
        assert vertex_curvature(q, 1.0 / 40.0) == pytest.approx(expected, rel=1e-14)
    else:
        assert vertex_curvature(q, 1.0 / 40.0) == 1.0 / 40.0


# ------------------------------------------------------------------------------ zero terms
def test_zero_terms_trace_bit_for_bit_like_the_base_conic():
    lens = _test_lenses()[1]
    s = lens.surfaces[0]
    zero = replace(lens, surfaces=(replace(s, qtype=QType("qbfs", 12.0, (0.0, 0.0))),
                                   lens.surfaces[1]))  # fmt: skip
    conic = replace(lens, surfaces=(replace(s, qtype=None), lens.surfaces[1]))
    assert zero.surfaces[0].kind == KIND_QUADRIC
    rng = np.random.default_rng(2)
    o = np.column_stack([rng.uniform(-4, 4, 300), rng.uniform(-4, 4, 300), np.full(300, -1.0)])
    d = np.column_stack([rng.normal(0, 0.05, 300), rng.normal(0, 0.05, 300), np.ones(300)])
    a, b = trace_rays(zero, o, d), trace_rays(conic, o, d)
    assert np.array_equal(a.positions, b.positions) and np.array_equal(a.directions, b.directions)
    pa, pb = pack(zero), pack(conic)
    for name in ("kind", "c", "k", "asph", "geo"):
        assert np.array_equal(getattr(pa, name), getattr(pb, name)), name
    assert paraxial(zero).efl == paraxial(conic).efl
    # the Q-type Newton path itself with zero coefficients lands on the conic to round-off
    q = pack(replace(zero, surfaces=(replace(s, qtype=QType("qbfs", 12.0, (1e-30,))),
                                     lens.surfaces[1])))  # fmt: skip
    asph = q.asph.copy()
    asph[0, 1:] = 0.0
    forced = replace(q, asph=asph)
    assert forced.kind[0] == KIND_QBFS
    c = trace_rays(forced, o, d)
    assert np.max(np.abs(c.positions - b.positions)) < 1e-12
    assert np.max(np.abs(c.directions - b.directions)) < 1e-14


# ------------------------------------------------------------------------------ files
def test_toml_round_trip_is_exact(tmp_path):
    import orthoscope as osc

    for lens in _test_lenses():
        text = dumps(lens)
        assert "qtype = { form =" in text
        assert loads(text) == lens
        path = tmp_path / f"{lens.surfaces[0].qtype.form}{lens.surfaces[0].conic}.toml"
        osc.save_lens(lens, path)
        assert osc.load_lens(path) == replace(lens, path=str(path))


def test_zmx_round_trip_and_refusals():
    lens = _test_lenses()[1]
    back = loads_zmx(dumps_zmx(lens))
    assert back.surfaces[0].qtype == lens.surfaces[0].qtype
    assert paraxial(back).efl == paraxial(lens).efl
    asl = _asl()
    assert loads_zmx(dumps_zmx(asl)).surfaces[0] == replace(asl.surfaces[0], line=None)
    with pytest.raises(PrescriptionError, match="Qcon surface cannot be written to .zmx"):
        dumps_zmx(_test_lenses()[2])
    text = ASL5040.read_bytes().decode("utf-16")
    with pytest.raises(PrescriptionError, match=r"QED_TYPE extra data 1 = 1\.0: only 0 is read"):
        loads_zmx(text.replace("XDAT 1 0.000000000000E+00", "XDAT 1 1.000000000000E+00"))
    with pytest.raises(
        PrescriptionError,
        match=r"extra data 3 \(the normalization radius\) = 0.0: must be positive",
    ):
        loads_zmx(text.replace("XDAT 3 2.700000000000E+01", "XDAT 3 0.0"))
    with pytest.raises(PrescriptionError, match="PARM 2 = 0.5: a parameter on a Q-type"):
        loads_zmx(text.replace("  XDAT 1 ", "  PARM 2 0.5\n  XDAT 1 ", 1))


def test_model_errors_are_one_line():
    with pytest.raises(ValueError, match="norm_radius must be a positive"):
        QType("qbfs", 0.0, (1.0,))
    with pytest.raises(ValueError, match="form must be one of"):
        QType("q2d", 1.0, (1.0,))
    from raytrace.errors import LensError

    with pytest.raises(LensError, match="either qtype or aspheric"):
        Lens("x", (Surface(0.01, 1.0, fixed_index(1.5), stop=True, aspheric=(1e-6,),
                           qtype=QType("qbfs", 5.0, (0.1,))), Surface(0.0, 10.0)),
             Aperture("epd", 2.0), Field("angle", 1.0))  # fmt: skip
    with pytest.raises(PrescriptionError, match="either asph or qtype"):
        loads('name = "x"\naperture = { epd = 2 }\nfield = { angle = 1 }\nsurfaces = [\n'
              '{ r = 50, t = 2, n = 1.5, stop = true, asph = [1e-6], '
              'qtype = { form = "qbfs", norm_radius = 5, a = [0.1] } },\n'
              '{ r = "inf", t = 10 },\n]\n')  # fmt: skip
    from raytrace.tolerance import ToleranceSpecError, check_against_lens, spec_from_dict

    spec = spec_from_dict({"tolerances": [{"type": "TTHI", "surface": 1, "limit": 0.01}]})
    with pytest.raises(ToleranceSpecError, match="surface 1 is a Q-type"):
        check_against_lens(spec, _test_lenses()[0])


def test_scaled_lens_scales_the_q_terms():
    lens = _test_lenses()[0]
    assert paraxial(lens.scaled(2.0)).efl == pytest.approx(2.0 * paraxial(lens).efl, rel=1e-13)
    assert lens.scaled(2.0).surfaces[0].sag(3.0) == pytest.approx(
        2.0 * lens.surfaces[0].sag(1.5), rel=1e-13
    )


def test_pack_flags_q_surfaces_for_the_scalar_path():
    from raytrace.kernels.codes import F_SCALAR, G_FLAGS, G_LENS, L_COAXIAL, L_SYMMETRIC

    p = pack(_test_lenses()[1])
    assert p.kind[0] == KIND_QBFS
    assert int(p.geo[0, G_FLAGS]) == F_SCALAR and p.geo[1, G_FLAGS] == 0.0
    assert int(p.geo[0, G_LENS]) == L_SYMMETRIC and not int(p.geo[0, G_LENS]) & L_COAXIAL
    assert p.asph[0, 0] == 1.0 / 144.0
    p = pack(_test_lenses()[2])
    assert p.kind[0] == KIND_QCON and int(p.geo[0, G_FLAGS]) == F_SCALAR


def test_vertex_curvature_reproduces_code_v_first_order_data():
    """CODE V's listing of a three-mirror system with a Qbfs surface, shipped by ray-optics
    0.9.8 (rayoptics/codev/tests/threemrc_qbfs.lis): surface 5 ``RDY -449.67012``, ``SPS QBF``
    with ``NRADIUS 1.8986E+02``, ``QB4 4.2605E-01``, ``QB6 -1.6782E-02``, ``QB8 8.2673E-04``,
    ``QB10 -4.4487E-05``, ``QB12 2.5242E-06``, ``QB14 -1.3595E-07``; first-order ``EFL
    -395.3803`` (CODE V's EFL is n'/Φ: ``ParaxialResult.f_image``). Its first-order trace ignores
    the decenters and tilts, so the centred system below is what it computed. With QB4 … QB14 =
    a_0 … a_5 the vertex curvature c + 2 Σ a_m Q_m(0)/ρ_max² gives that EFL within the listing's
    5 digits of ρ_max and a_m (≈ 3e-4 mm); the best-fit radius alone gives −390.10."""
    q = QType("qbfs", 189.86, (0.42605, -0.016782, 8.2673e-4, -4.4487e-5, 2.5242e-6, -1.3595e-7))
    ss = (
        Surface(0.0, 300.0),
        Surface(-1.0 / 1058.98937, -276.006853, conic=-1.314566, mirror=True),
        Surface(0.0, -0.981318, stop=True),
        Surface(-1.0 / 324.065, 319.160560, conic=0.889123, mirror=True),
        Surface(-1.0 / 449.67012, -321.621031, mirror=True, qtype=q),
    )
    lens = Lens(
        "3 mirror compact", ss, Aperture("epd", 100.0), Field("angle", 2.0), wavelength=500.0
    )
    assert paraxial(lens).f_image == pytest.approx(-395.3803, abs=1e-3)
    bfs = replace(lens, surfaces=(*ss[:4], replace(ss[4], qtype=None)))
    assert abs(paraxial(bfs).f_image + 395.3803) > 5.0


def test_qcon_in_the_kernels_basis_and_traced_on_its_sag():
    """The kernels evaluate a Qcon sum in the basis P_m of the Qbfs evaluation
    (raytrace.qtype.qcon_to_p_basis): Σ b_m P_m equals Σ a_m Q_m^con by scipy's Jacobi
    polynomials to 1e-14 relative (13 terms), and the points where traced rays meet a Qcon
    surface lie on Surface.sag (the Clenshaw sum of the Jacobi recurrence) to 1e-12 mm."""
    special = pytest.importorskip("scipy.special")
    from raytrace.qtype import p_basis, qcon_to_p_basis

    rng = np.random.default_rng(9)
    a = rng.normal(scale=1e-2, size=13)
    b = np.array(qcon_to_p_basis(a))
    x = np.linspace(0.0, 1.0, 41)
    ref = sum(a[m] * special.eval_jacobi(m, 0.0, 4.0, 2.0 * x - 1.0) for m in range(13))
    assert np.max(np.abs(b @ p_basis(x, 13) - ref)) <= 1e-14 * np.max(np.abs(ref))
    base = _test_lenses()[2]
    q = QType("qcon", 12.0, tuple(a))
    lens = replace(base, surfaces=(replace(base.surfaces[0], qtype=q), base.surfaces[1]))
    n = 200
    o = np.column_stack([rng.uniform(-5, 5, n), rng.uniform(-5, 5, n), np.full(n, -1.0)])
    d = np.tile([0.0, 0.0, 1.0], (n, 1))
    p = ray_paths(lens, o, d)
    r = np.hypot(p.x[:, 0], p.y[:, 0])
    assert np.max(np.abs(p.z[:, 0] - lens.surfaces[0].sag(r))) <= 1e-12
    # the departure is not negligible here: a kernel that dropped it would fail the check above
    assert (
        np.max(np.abs(lens.surfaces[0].sag(r) - replace(lens.surfaces[0], qtype=None).sag(r)))
        > 1e-4
    )
    # the kernel's slope dz/dρ (ρ = r²) against a central difference of its sag
    from raytrace.kernels.surface import qtype_sag

    row = np.array([q.packed_row()])
    s0 = lens.surfaces[0]
    for rho in (1.0, 20.0, 90.0, 140.0):
        h = 1e-4  # mm²: the central difference is then good to ~3e-10 (its error falls as h²)
        z1, _, _ = qtype_sag(True, s0.curvature, s0.conic, row, 0, rho + h)
        z0, _, _ = qtype_sag(True, s0.curvature, s0.conic, row, 0, rho - h)
        _, dz, ok = qtype_sag(True, s0.curvature, s0.conic, row, 0, rho)
        assert ok and dz == pytest.approx((z1 - z0) / (2.0 * h), rel=1e-8)
