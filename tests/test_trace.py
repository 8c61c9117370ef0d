"""Real-ray kernels and the public trace API (raytrace.kernels, raytrace.trace).

Every check is against something independent of the tracer: closed-form optics of a plate, the
aplanatic points of a sphere, the ball-lens focal length, Snell's law re-evaluated in numpy,
the surface sag formula of raytrace.lens, a paraxial y-nu trace written here, and the published
Topogon (US 2,031,792 Fig. 1) chief-ray heights.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import replace

import numpy as np
import pytest
from support import CORPUS

from raytrace.errors import TraceError
from raytrace.files.library import load_lens
from raytrace.kernels.codes import (
    STATUS_AIM_FAILED,
    STATUS_CLIPPED,
    STATUS_MISSED,
    STATUS_NAMES,
    STATUS_OK,
    STATUS_TIR,
)
from raytrace.lens import Aperture, Field, Lens, Surface
from raytrace.materials import AIR, fixed_index
from raytrace.packing import pack
from raytrace.trace import PARALLEL_THRESHOLD, chief_rays, trace_rays

TOPOGON = "topogon-us2031792-fig1"


NO_FIELD = Field("angle", 0.0)


def _lens(surfaces, *, object_material=AIR, object_distance=math.inf, field=NO_FIELD):
    return Lens(
        "test",
        tuple(surfaces),
        Aperture("epd", 1.0),
        field,
        object_distance=object_distance,
        object_material=object_material,
    )


def _one(packed, y, z, M, N, x=0.0, L=0.0, clip=True):
    return trace_rays(packed, ([x], [y], [z]), ([L], [M], [N]), clip=clip)


def _truncated(p, j):
    """The packed lens cut after surface j (0-based)."""
    s = slice(0, j + 1)
    return replace(
        p,
        kind=p.kind[s].copy(),
        c=p.c[s].copy(),
        k=p.k[s].copy(),
        asph=np.ascontiguousarray(p.asph[s]),
        zv=p.zv[s].copy(),
        n_in=p.n_in[s].copy(),
        n_out=p.n_out[s].copy(),
        sd=p.sd[s].copy(),
        stop=min(p.stop, j),
    )


def _ynu(lens, y, u, z_plane):
    """Paraxial y-nu trace (written here, independent of raytrace): ray of height y at the first
    vertex and slope u; returns its height on the plane z_plane behind the last surface."""
    p = pack(lens)
    nu = p.n_in[0] * u
    for j in range(p.n_surfaces):
        if j:
            y += (p.zv[j] - p.zv[j - 1]) * nu / p.n_in[j]
        nu -= y * p.c[j] * (p.n_out[j] - p.n_in[j])
    return y + (z_plane - p.zv[-1]) * nu / p.n_out[-1]


def _ynu_z_e0(lens):
    """Paraxial entrance pupil z from the y-nu trace up to the stop (independent helper)."""
    s = lens.stop_index
    cut = replace(lens, surfaces=lens.surfaces[: s + 1])
    z_stop = float(lens.vertex_z[s])
    ya = _ynu(cut, 1.0, 0.0, z_stop)
    yb = _ynu(cut, 0.0, 1.0, z_stop)
    return yb / ya


# --------------------------------------------------------------------------------------------
# Analytic cases
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("theta_deg", [5.0, 30.0, 60.0, 80.0])
def test_plate_lateral_shift(theta_deg):
    """Plane-parallel plate: lateral displacement d = t sin(θ − θ') / cos θ' (textbook)."""
    t, n = 7.5, 1.7
    lens = _lens([Surface(0.0, t, fixed_index(n), stop=True), Surface(0.0, 10.0)])
    th = math.radians(theta_deg)
    thp = math.asin(math.sin(th) / n)
    z0 = -3.0
    rb = _one(pack(lens), 0.0, z0, math.sin(th), math.cos(th))
    assert rb.status[0] == STATUS_OK
    assert rb.M[0] == pytest.approx(math.sin(th), abs=1e-15)
    # perpendicular distance of the emergent ray from the undeviated line through (0, z0)
    dy, dz = rb.y[0] - 0.0, rb.z[0] - z0
    d = abs(dy * math.cos(th) - dz * math.sin(th))
    assert d == pytest.approx(t * math.sin(th - thp) / math.cos(thp), rel=1e-13)


def test_sphere_aplanatic_points_exact_for_all_rays():
    """Young/Weierstrass aplanatic points of a refracting sphere (radius R, n → n'): every ray from
    the object point at s = R(1 + n'/n) leaves as if from s' = R(1 + n/n') (vertex distances)."""
    R, n, npr = -10.0, 1.0, 1.5
    lens = _lens([Surface(1.0 / R, 5.0, fixed_index(npr), stop=True)])
    s = R * (1.0 + npr / n)
    sp = R * (1.0 + n / npr)
    u = np.radians(np.linspace(-20.0, 20.0, 41))
    rb = trace_rays(pack(lens), (0.0, 0.0, s), (0.0, np.sin(u), np.cos(u)))
    assert np.all(rb.status == STATUS_OK)
    _, y = rb.at_plane(sp)
    assert np.max(np.abs(y)) <= 1e-12 * abs(R)
    # and the image really is aberration-free only there: a shifted plane is not
    _, y2 = rb.at_plane(sp + 0.1)
    assert np.max(np.abs(y2)) > 1e-3


def test_ray_through_centre_of_curvature_is_undeviated():
    R = 12.0
    lens = _lens([Surface(1.0 / R, 3.0, fixed_index(1.8), stop=True)])
    a = math.radians(25.0)
    # line through the centre (0, 0, R) with slope angle a, started left of the vertex
    z0 = -5.0
    y0 = (z0 - R) * math.tan(a)
    rb = _one(pack(lens), y0, z0, math.sin(a), math.cos(a))
    assert rb.status[0] == STATUS_OK
    assert rb.M[0] == pytest.approx(math.sin(a), abs=1e-15)
    assert rb.N[0] == pytest.approx(math.cos(a), abs=1e-15)


def test_ball_lens_paraxial_focus():
    """Ball lens of diameter D: EFL = n D / (4 (n − 1)), measured from the centre."""
    D, n = 10.0, 1.5168
    R = D / 2
    lens = _lens(
        [Surface(1 / R, D, fixed_index(n), stop=True), Surface(-1 / R, 20.0)],
    )
    h = np.array([1e-5, -2e-5]) * R
    rb = trace_rays(pack(lens), (0.0, h, -1.0), (0.0, 0.0, 1.0))
    assert np.all(rb.ok)
    z_cross = rb.z - rb.y * rb.N / rb.M
    efl = n * D / (4 * (n - 1))
    np.testing.assert_allclose(z_cross - R, efl, rtol=1e-8)


# --------------------------------------------------------------------------------------------
# Snell's law, unit directions, sag residual (re-checked in numpy, surface by surface)
# --------------------------------------------------------------------------------------------


def _normal(surface: Surface, x, y):
    """Unit surface normal (+z oriented) from the sag derivative, evaluated in numpy."""
    rho = x * x + y * y
    c, k = surface.curvature, surface.conic
    dz = 0.5 * c / np.sqrt(1 - (1 + k) * c * c * rho)
    pw = rho.copy()
    for j, a in enumerate(surface.aspheric):
        dz = dz + (j + 2) * a * pw
        pw = pw * rho
    nv = np.stack([-2 * x * dz, -2 * y * dz, np.ones_like(x)])
    return nv / np.linalg.norm(nv, axis=0)


ASPHERE = Surface(1 / 15.0, 4.0, fixed_index(1.58), conic=-2.5, aspheric=(2e-4, -3e-6, 4e-8))


def _check_lens_rays(lens, x, y, z, L, M, N):
    p = pack(lens)
    d_prev = np.stack([L, M, N]) / np.sqrt(L * L + M * M + N * N)
    alive = np.ones(x.shape, bool)
    for j, surf in enumerate(lens.surfaces):
        rb = trace_rays(_truncated(p, j), (x, y, z), (L, M, N), clip=False)
        alive &= rb.ok
        assert alive.sum() > 0.5 * x.size
        xs, ys, zs = rb.x[alive], rb.y[alive], rb.z[alive]
        d_out = np.stack([rb.L, rb.M, rb.N])[:, alive]
        d_in = d_prev[:, alive]
        # the point lies on the surface (sag formula of raytrace.lens)
        sag = surf.sag(np.hypot(xs, ys))
        assert np.max(np.abs(zs - p.zv[j] - sag)) <= 1e-12
        # unit direction cosines
        assert np.max(np.abs(np.linalg.norm(d_out, axis=0) - 1.0)) <= 1e-14
        # vector Snell: n (d × n̂) = n' (d' × n̂)
        nh = _normal(surf, xs, ys)
        res = p.n_in[j] * np.cross(d_in, nh, axis=0) - p.n_out[j] * np.cross(d_out, nh, axis=0)
        assert np.max(np.abs(res)) <= 1e-12
        d_prev = np.stack([rb.L, rb.M, rb.N])
    return alive


def test_snell_and_unit_directions_every_surface_cooke_triplet():
    lens = load_lens("cooke-triplet-f4")
    rng = np.random.default_rng(1)
    n = 2000
    a = np.radians(rng.uniform(-20, 20, n))
    b = np.radians(rng.uniform(-20, 20, n))
    d = np.stack([np.tan(a), np.tan(b), np.ones(n)])
    d /= np.linalg.norm(d, axis=0)
    x, y = rng.uniform(-5, 5, (2, n))
    _check_lens_rays(lens, x, y, np.full(n, -2.0), *d)


def test_even_asphere_intersection_on_surface_and_snell():
    """Strong even asphere (hyperbolic base, large r⁴..r⁸ terms): Newton intersection lies on the
    surface to ≤ 1e-12 mm and refraction obeys Snell's law."""
    lens = _lens([replace(ASPHERE, stop=True), Surface(0.0, 10.0)])
    # departure from the base conic is large (> 0.1 mm at r = 6)
    base = replace(ASPHERE, aspheric=())
    assert abs(ASPHERE.sag(6.0) - base.sag(6.0)) > 0.1
    rng = np.random.default_rng(2)
    n = 3000
    x, y = rng.uniform(-4.5, 4.5, (2, n))
    a, b = np.radians(rng.uniform(-25, 25, (2, n)))
    d = np.stack([np.sin(a), np.sin(b) * np.cos(a), np.cos(a) * np.cos(b)])
    alive = _check_lens_rays(lens, x, y, np.full(n, -1.0), *d)
    assert alive.mean() > 0.95


# --------------------------------------------------------------------------------------------
# Status codes
# --------------------------------------------------------------------------------------------


def test_status_missed_strongly_curved_surface():
    lens = _lens([Surface(1 / 5.0, 3.0, fixed_index(1.5), stop=True), Surface(0.0, 5.0)])
    rb = _one(pack(lens), 6.0, -1.0, 0.0, 1.0)  # parallel ray above a 5 mm sphere
    assert rb.status[0] == STATUS_MISSED and rb.surface[0] == 1
    assert np.isnan(rb.y[0])


def test_status_tir_beyond_critical_angle():
    n = 1.5
    lens = _lens([Surface(0.0, 5.0, AIR, stop=True)], object_material=fixed_index(n))
    crit = math.asin(1 / n)
    a = np.array([crit - 0.01, crit + 0.01])
    rb = trace_rays(pack(lens), (0.0, 0.0, -1.0), (0.0, np.sin(a), np.cos(a)))
    assert rb.status.tolist() == [STATUS_OK, STATUS_TIR]
    assert rb.surface.tolist() == [0, 1]


def test_status_clipped_by_semi_diameter():
    lens = _lens(
        [Surface(0.02, 3.0, fixed_index(1.5), semi_diameter=2.0, stop=True), Surface(0.0, 5.0)]
    )
    p = pack(lens)
    rb = trace_rays(p, (0.0, [1.9, 2.1], -1.0), (0.0, 0.0, 1.0))
    assert rb.status.tolist() == [STATUS_OK, STATUS_CLIPPED]
    assert rb.surface.tolist() == [0, 1]
    rb = trace_rays(p, (0.0, [1.9, 2.1], -1.0), (0.0, 0.0, 1.0), clip=False)
    assert rb.status.tolist() == [STATUS_OK, STATUS_OK]


def test_no_nan_without_status_and_parallel_equals_serial():
    lens = load_lens("cooke-triplet-f4")
    lens = replace(
        lens,
        surfaces=tuple(replace(s, semi_diameter=7.0) for s in lens.surfaces),
    )
    p = pack(lens)
    rng = np.random.default_rng(3)
    n = PARALLEL_THRESHOLD + 1000
    x, y = rng.uniform(-12, 12, (2, n))
    a, b = np.radians(rng.uniform(-60, 60, (2, n)))
    L, M, N = np.sin(a), np.sin(b) * np.cos(a), np.cos(a) * np.cos(b)
    par = trace_rays(p, (x, y, -3.0), (L, M, N))
    ser = trace_rays(p, (x, y, -3.0), (L, M, N), threads=1)
    codes = set(np.unique(par.status).tolist())
    assert {STATUS_OK, STATUS_CLIPPED} <= codes
    assert codes <= set(STATUS_NAMES)
    for arr in (par.x, par.y, par.z, par.L, par.M, par.N):
        assert np.all(np.isfinite(arr[par.ok]))
        assert np.all(np.isnan(arr[~par.ok]))
    assert np.all(par.surface[~par.ok] >= 1) and np.all(par.surface[par.ok] == 0)
    np.testing.assert_array_equal(par.status, ser.status)
    np.testing.assert_array_equal(par.y, ser.y)  # same arithmetic, bit for bit
    # analytic transfer to the image plane
    xi, yi = par.at_plane(p.z_image)
    ok = par.ok
    np.testing.assert_allclose(yi[ok], par.y[ok] + (p.z_image - par.z[ok]) * par.M[ok] / par.N[ok])


def test_trace_rays_rejects_bad_shapes():
    p = pack(load_lens("cooke-triplet-f4"))
    with pytest.raises(TraceError):
        trace_rays(p, (np.zeros(3), np.zeros(4), 0.0), (0.0, 0.0, 1.0))


# --------------------------------------------------------------------------------------------
# Chief-ray aiming
# --------------------------------------------------------------------------------------------


def _stop_heights(lens, cr):
    """Independent check of the aim: trace the object-space chief rays with trace_rays through the
    lens cut at the stop and return their heights at the stop surface."""
    p = pack(lens)
    cut = _truncated(p, p.stop)
    rb = trace_rays(cut, (0.0, cr.y_start, cr.z_start), (0.0, cr.M_start, cr.N_start), clip=False)
    assert np.all(rb.ok)
    return rb.y


def test_chief_ray_aim_topogon_wide_fields():
    lens = load_lens(TOPOGON)
    fields = np.array([0.0, 5.0, 15.0, 25.0, 35.0, 40.0, 45.0, 50.0, -30.0, -50.0])
    cr = chief_rays(lens, fields)
    assert np.all(cr.status == STATUS_OK)
    assert cr.stop_radius > 1.0
    assert np.max(np.abs(cr.stop_residual)) <= 1e-12 * cr.stop_radius
    assert np.max(np.abs(_stop_heights(lens, cr))) <= 1e-12 * cr.stop_radius
    # odd symmetry and the zero field on the axis
    i30, i50 = list(fields).index(-30.0), list(fields).index(-50.0)
    h = cr.heights_at(lens.image_z)
    assert h[0] == 0.0 and cr.entrance_pupil_z[0] == pytest.approx(_ynu_z_e0(lens), rel=1e-12)
    assert h[i50] == pytest.approx(-h[7], rel=1e-14)
    assert h[i30] < 0 < h[4]
    assert np.all(np.diff(h[:8]) > 0)


def test_chief_ray_aim_finite_object_and_equivalent_angles():
    """Object 400 mm away: height fields, and angle fields y = p0 tan α (p0 = z_obj − z_E0)
    give the same chief rays."""
    lens = load_lens(TOPOGON).with_object_distance(400.0)
    heights = np.array([-150.0, -40.0, 0.0, 60.0, 200.0])
    crh = chief_rays(lens, object_heights_mm=heights)
    assert np.all(crh.status == STATUS_OK)
    assert np.max(np.abs(crh.stop_residual)) <= 1e-12 * crh.stop_radius
    assert np.max(np.abs(_stop_heights(lens, crh))) <= 1e-12 * crh.stop_radius
    np.testing.assert_array_equal(crh.y_start, heights)
    assert np.all(crh.z_start == -400.0)
    p0 = -400.0 - _ynu_z_e0(lens)
    alpha = np.degrees(np.arctan(heights / p0))
    cra = chief_rays(lens, alpha)
    assert np.all(cra.status == STATUS_OK)
    np.testing.assert_allclose(cra.y_start, heights, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(cra.heights_at(lens.image_z), crh.heights_at(lens.image_z),
                               rtol=1e-11, atol=1e-11)  # fmt: skip
    # positive object height → inverted (negative) real image
    assert crh.heights_at(lens.image_z)[-1] < 0


def test_field_beyond_lens_gets_status_not_crash():
    lens = load_lens(TOPOGON)
    cr = chief_rays(lens, [10.0, 89.0, 75.0])
    assert cr.status[0] == STATUS_OK
    assert cr.status[1] in (STATUS_AIM_FAILED, STATUS_MISSED, STATUS_TIR)
    assert cr.status[2] in (STATUS_AIM_FAILED, STATUS_MISSED, STATUS_TIR)
    h = cr.heights_at(np.array([lens.image_z, lens.image_z + 1.0]))
    assert h.shape == (2, 3)
    assert np.all(np.isfinite(h[:, 0])) and np.all(np.isnan(h[:, 1:]))
    with pytest.raises(TraceError):
        chief_rays(lens, [90.0])
    with pytest.raises(TraceError):
        chief_rays(lens, object_heights_mm=[1.0])  # object at infinity


@pytest.mark.parametrize(
    ("kw", "value", "says"),
    [
        ("fields_deg", [0, 1j], "fields_deg: expected field angles in degrees (a number or a list "
         "of numbers), got [0, 1j] (a complex number)"),
        ("fields_deg", np.array([0, 10j]), "(a complex number)"),
        ("fields_deg", True, "fields_deg: expected field angles in degrees (a number or a list of "
         "numbers), got True (a bool, not a number)"),
        ("fields_deg", [True, False], "got [True, False] (a bool, not a number)"),
        ("fields_deg", [0, np.True_], "(a bool, not a number)"),
        ("fields_deg", [[0, 1], [2]], "fields_deg: expected field angles in degrees"),
        ("fields_deg", [], "no fields given: fields_deg is empty"),
        ("object_heights_mm", [0, 5j], "object_heights_mm: expected object heights in mm"),
        ("object_heights_mm", [], "no fields given: object_heights_mm is empty"),
    ],
)  # fmt: skip
def test_fields_that_are_no_numbers_are_refused_naming_the_keyword(cooke, kw, value, says):
    # [0, 1j] raised float()'s bare TypeError; True traced a field of 1 degree, [True, False]
    # fields of 1 and 0; [] returned an empty result where characteristic_distortion refuses
    od = {"object_distance": 1000} if kw == "object_heights_mm" else {}
    with pytest.raises(TraceError) as e:
        chief_rays(cooke, **{kw: value}, **od)
    assert says in str(e.value) and "\n" not in str(e.value), str(e.value)


def test_fields_as_numpy_scalars_ints_and_numeric_strings_are_traced(cooke):
    ref = chief_rays(cooke, [0.0, 10.0])
    for f in ([0, 10], np.array([0, 10]), [np.float32(0), np.int64(10)], ["0", "10"]):
        cr = chief_rays(cooke, f)
        np.testing.assert_array_equal(cr.fields, ref.fields)
        np.testing.assert_array_equal(cr.y_last, ref.y_last)
    for f in ("10", np.float64(10), np.array(10.0)):
        assert chief_rays(cooke, f).y_last[0] == ref.y_last[1]


@pytest.mark.parametrize(
    ("kw", "value", "says"),
    [
        ("field_deg", 1j, "field_deg: expected one field angle in degrees (a number), got 1j"),
        ("field_deg", np.True_, "field_deg: expected one field angle in degrees (a number), "
         "got np.True_ (a bool, not a number)"),
        ("object_height_mm", 2j, "object_height_mm: expected one object height in mm"),
    ],
)  # fmt: skip
def test_a_fan_field_that_is_no_number_names_the_keyword(cooke, kw, value, says):
    # ray_fan(lens, 1j) raised float()'s bare TypeError; np.True_ traced 1 degree
    from raytrace.trace import ray_fan, spot_diagram

    od = {"object_distance": 1000} if kw == "object_height_mm" else {}
    for f in (ray_fan, spot_diagram):
        with pytest.raises(TraceError) as e:
            f(cooke, **{kw: value}, **od)
        assert says in str(e.value), str(e.value)


def test_chief_rays_paraxial_limit():
    """Real chief rays at 1e-4 of the field reproduce the paraxial chief-ray heights (y-nu trace
    through the paraxial entrance pupil, written in this file) to 1e-9 relative."""
    lens = load_lens(TOPOGON)
    z_e0 = _ynu_z_e0(lens)
    alpha = 1e-4 * 45.0
    cr = chief_rays(lens, [alpha])
    u = math.tan(math.radians(alpha))
    y_par = _ynu(lens, -z_e0 * u, u, lens.image_z)
    assert cr.heights_at(lens.image_z)[0] == pytest.approx(y_par, rel=1e-9)
    assert cr.entrance_pupil_z[0] == pytest.approx(z_e0, rel=1e-6)
    # finite object, height field
    fin = lens.with_object_distance(300.0)
    z_e0 = _ynu_z_e0(fin)
    h = 1e-4 * 100.0
    cr = chief_rays(fin, object_heights_mm=[h])
    u = -h / (z_e0 + 300.0)  # slope of the paraxial ray from (h, −300) through E0
    y_par = _ynu(fin, h + 300.0 * u, u, fin.image_z)
    assert cr.heights_at(fin.image_z)[0] == pytest.approx(y_par, rel=1e-9)


def test_topogon_published_chief_ray_heights():
    """US 2,031,792 Fig. 1 (public lens-test fixture, d line): EFL 66.04, BFL 51.94, real chief-ray
    heights on the paraxial image plane 8.112, 16.495, 25.457, 35.382, 46.805 mm at 7..35°."""
    lens = load_lens(TOPOGON)
    y_last = _ynu(lens, 1.0, 0.0, lens.length)
    slope = _ynu(lens, 1.0, 0.0, lens.length + 1.0) - y_last
    efl = -1.0 / slope
    bfl = -y_last / slope
    assert round(efl, 2) == 66.04 and round(bfl, 2) == 51.94
    z_img = lens.length + bfl
    cr = chief_rays(lens, [7.0, 14.0, 21.0, 28.0, 35.0])
    expected = np.array([8.112, 16.495, 25.457, 35.382, 46.805])
    assert np.max(np.abs(cr.heights_at(z_img) - expected)) <= 0.001


def test_chief_rays_cheap_to_call_repeatedly():
    lens = load_lens(TOPOGON)
    f = np.linspace(0.0, 45.0, 50)
    a = chief_rays(lens, f)
    b = chief_rays(lens, f)
    np.testing.assert_array_equal(a.y_last, b.y_last)
    assert np.all(a.iterations[1:] < 40)


def test_chief_ray_continuation_takes_few_traces_per_field():
    """Regression pins of the aim's own cost (this project's algorithm, no outside source): the
    continuation of raytrace.kernels.aim starts each field from the quadratic through the last
    three solutions and from the last solve's slope, so a 50-field Topogon curve to 45° takes at
    most 4 traces to the stop per field, 3.5 on average (the forward-difference start of before
    took 4.5 on this Topogon, 3.9 on the Cooke triplet). An off-axis three-mirror system (CODE V
    file of ray-optics), whose paraxial slope is far from its real one, keeps within 4 per signed
    field: a curvature formed from that paraxial slope once took 1280 traces for one field
    there."""
    topogon = chief_rays(load_lens(TOPOGON), np.linspace(0.0, 45.0, 50))
    assert topogon.ok.all()
    assert topogon.iterations.max() <= 4 and topogon.iterations[1:].mean() <= 3.5
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the file's unsupported CODE V commands, named
        mirrors = load_lens(CORPUS / "rayoptics" / "threemir.seq")
    v = mirrors.field.value
    cr = chief_rays(mirrors, np.linspace(-v, v, 41))
    assert cr.ok.all()
    assert cr.iterations.max() <= 4


def test_chief_ray_continuation_stays_cheap_past_the_edge_and_on_close_fields():
    """Regression pins (this project's aim against its own earlier version, found by a review):
    a quadratic prediction formed over steps that halved toward the edge of the traceable
    fields, or over fields 1e-10° apart, was noise, and sent guesses far off. Fields beyond
    the lens's reach then cost up to the trace cap each (31 fields to 67.5° on the
    topogon-like-pestrecov: 8114 traces, against 513 before the quadratic and 497 now; the
    Cooke triplet to ±60°: 70,581 against 2503 and 2394), and a field after three close ones
    31–83 traces (now 7). The same fields fail as before."""
    lens = load_lens("topogon-like-pestrecov")
    cr = chief_rays(lens, np.linspace(0.0, 67.5, 31))
    assert (~cr.ok).sum() == 9 and cr.ok[:22].all()  # 49.5° and beyond fail, as before
    assert cr.iterations.sum() <= 600
    cooke = chief_rays(load_lens("cooke-triplet-f4"), np.linspace(-60.0, 60.0, 101))
    assert cooke.iterations.sum() <= 3000
    close = chief_rays(lens, [20.0, 20.0 + 1e-10, 20.0 + 2e-10, 45.0])
    assert close.ok.all() and close.iterations[-1] <= 10


def test_a_stop_smaller_than_the_aperture_says_so():
    from raytrace.trace.chief import ApertureWarning

    lens = load_lens("cooke-triplet-f4")
    s = list(lens.surfaces)
    s[3] = replace(s[3], semi_diameter=3.0)  # the f/4 aperture needs 4.75 mm at the stop
    small = replace(lens, surfaces=tuple(s))
    with pytest.warns(ApertureWarning, match="clipped at the stop"):
        chief_rays(small, [0.0, 10.0])
    s[3] = replace(s[3], semi_diameter=5.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error", ApertureWarning)
        chief_rays(replace(lens, surfaces=tuple(s)), [0.0, 10.0])
