"""Real chief rays on a 2-D field grid (raytrace.trace.chief_rays_2d, raytrace.kernels.aim2d).

Referees: the meridional aim of raytrace.trace.chief_rays rotated to the field's azimuth (a
rotationally symmetric lens has no other chief ray: an invariant, not an earlier output), and
optiland 0.6.3 (an independent 3-D real-ray tracer with its own iterative ray aiming and its own
angle-field definition, tan(field_x), tan(field_y) — optiland/fields/field_types/angle.py).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from support import benchmark_module

from raytrace.errors import TraceError
from raytrace.files.library import load_lens
from raytrace.frames import Placement
from raytrace.paraxial import paraxial
from raytrace.trace import STATUS_AIM_FAILED, STATUS_OK, chief_rays, chief_rays_2d


def _grid(fmax: float, n: int = 9):
    """A square grid of field angles (deg) whose corners lie at ``fmax`` (tan-spaced)."""
    t = np.linspace(-1.0, 1.0, n) * math.tan(math.radians(fmax)) / math.sqrt(2.0)
    a = np.degrees(np.arctan(t))
    return np.meshgrid(a, a)


def _meridional_rotated(lens, X, Y, z, *, heights=False, **kw):
    """Image points of the meridional chief rays of the same fields, rotated to each azimuth."""
    if heights:
        r, phi = np.hypot(X, Y), np.arctan2(Y, X)
        cr = chief_rays(lens, object_heights_mm=r.ravel(), **kw)
    else:
        tx, ty = np.tan(np.radians(X)), np.tan(np.radians(Y))
        phi = np.arctan2(ty, tx)
        cr = chief_rays(lens, fields_deg=np.degrees(np.arctan(np.hypot(tx, ty))).ravel(), **kw)
    h = cr.heights_at(z).reshape((len(z),) + X.shape)
    return np.stack([h * np.cos(phi), h * np.sin(phi)], axis=-1)


@pytest.mark.parametrize(
    "name,od",
    [
        ("cooke-triplet-f4", math.inf),
        ("cooke-triplet-f4", 500.0),
        ("topogon-us2031792-fig1", math.inf),
        ("topogon-like-pestrecov", math.inf),
        ("super-angulon-de975637", math.inf),
    ],
)
def test_symmetric_lens_equals_the_meridional_chief_ray_rotated(name, od):
    lens = load_lens(name)
    par = paraxial(lens, od)
    X, Y = _grid(min(lens.field.value, 40.0) if lens.field.kind == "angle" else 20.0)
    # image planes: Gaussian and defocused by ±0.4 mm. (In a plane just behind the last vertex
    # the two differ by up to ~5e-12 mm: there a stop error moves the ray's point almost 1:1,
    # and the meridional referee stops at |stop residual| <= 1e-12 x R_stop without polishing.)
    z = np.array([par.z_gauss, par.z_gauss + 0.4, par.z_gauss - 0.4])
    cr = chief_rays_2d(lens, X, Y, object_distance=od)
    assert cr.shape == X.shape and np.all(cr.status == STATUS_OK)
    ref = _meridional_rotated(lens, X, Y, z, object_distance=od)
    np.testing.assert_allclose(cr.positions_at(z), ref, rtol=0, atol=1e-12)
    # the aim: the stop point is (0, 0) to the tolerance (1e-12 x max(1, R_stop))
    assert np.max(np.abs(cr.stop_residual_x)) <= cr.tolerance
    assert np.max(np.abs(cr.stop_residual_y)) <= cr.tolerance


def test_object_coordinates_equal_the_meridional_heights_rotated():
    lens = load_lens("cooke-triplet-f4")
    par = paraxial(lens, 500.0)
    a = np.linspace(-60.0, 60.0, 7)
    X, Y = np.meshgrid(a, a)
    z = np.array([par.z_gauss, par.z_gauss - 0.2])
    cr = chief_rays_2d(lens, object_x_mm=X, object_y_mm=Y, object_distance=500.0)
    np.testing.assert_allclose(cr.x_start, X, rtol=0, atol=0)  # the object point itself
    np.testing.assert_allclose(cr.z_start, -500.0)
    ref = _meridional_rotated(lens, X, Y, z, heights=True, object_distance=500.0)
    np.testing.assert_allclose(cr.positions_at(z), ref, rtol=0, atol=1e-12)


def test_finite_object_at_high_magnification_within_the_meridional_aim_error():
    # the Twinplex-like projector images at about 10x: the meridional aim's own stop error
    # (<= 1e-12 x max(1, R_stop) mm, not polished) is magnified to the image, so the bound is
    # relative: 1e-13 of the image radius (~3e-11 mm at the field edge; measured 3.5e-12 mm)
    lens = load_lens("twinplex-like-55-525")
    par = paraxial(lens)
    X, Y = _grid(40.0, 7)
    cr = chief_rays_2d(lens, X, Y)
    z = np.array([par.z_gauss])
    P = cr.positions_at(z)
    ref = _meridional_rotated(lens, X, Y, z)
    scale = np.maximum(1.0, np.hypot(ref[..., 0], ref[..., 1]))
    assert np.all(np.hypot(*np.moveaxis(P - ref, -1, 0)) <= 1e-13 * scale)


def test_field_convention_is_the_direction_tangents():
    # object at infinity: the object-space ray has direction ∝ (tan ax, tan ay, 1); a meridional
    # field (0, a) is the meridional chief ray's (0, sin a, cos a)
    lens = load_lens("cooke-triplet-f4")
    cr = chief_rays_2d(lens, [12.0, 0.0, -7.0], [5.0, 15.0, 9.0])
    tx, ty = cr.tan_start
    np.testing.assert_allclose(tx, np.tan(np.radians([12.0, 0.0, -7.0])), rtol=1e-15)
    np.testing.assert_allclose(ty, np.tan(np.radians([5.0, 15.0, 9.0])), rtol=1e-15)
    m = chief_rays(lens, fields_deg=[15.0])
    assert cr.M_start[1] == pytest.approx(m.M_start[0], abs=3e-16)  # (0, tan a, 1)/norm: ulps
    assert cr.N_start[1] == pytest.approx(m.N_start[0], abs=3e-16)
    # positive fields give positive image coordinates (docs/design.md, "Conventions")
    P = cr.positions_at(paraxial(lens).z_gauss)
    assert P[0, 0] > 0 and P[0, 1] > 0 and P[1, 1] > 0 and P[2, 0] < 0


def test_nominal_angles_with_a_finite_object_are_object_points_p0_tan():
    lens = load_lens("cooke-triplet-f4")
    par = paraxial(lens, 800.0)
    cr = chief_rays_2d(lens, 10.0, -6.0, object_distance=800.0)
    p0 = par.z_object - par.z_E0
    assert float(cr.x_start) == pytest.approx(p0 * math.tan(math.radians(10.0)), rel=1e-14)
    assert float(cr.y_start) == pytest.approx(p0 * math.tan(math.radians(-6.0)), rel=1e-14)


def test_rays_the_lens_cannot_pass_get_a_status_and_nan():
    lens = load_lens("cooke-triplet-f4")
    cr = chief_rays_2d(lens, [0.0, 10.0, 45.0, 70.0], [0.0, 10.0, 45.0, 10.0])
    assert list(cr.status[:2]) == [STATUS_OK, STATUS_OK]
    assert np.all(cr.status[2:] != STATUS_OK)
    assert np.all(np.isnan(cr.positions_at(60.0)[2:]))
    assert np.all(np.isfinite(cr.positions_at(60.0)[:2]))
    assert set(cr.status_names[2:]) <= {"aim_failed", "missed", "tir", "clipped"}
    assert STATUS_AIM_FAILED in cr.status or np.all(cr.surface[2:] > 0)


@pytest.mark.parametrize(
    "name,od,half",
    [("topogon-us2031792-fig1", math.inf, 30.0), ("cooke-triplet-f4", 500.0, 14.0)],
)
def test_grid_fields_start_from_their_neighbours_jacobian_and_agree_with_lone_aims(name, od, half):
    # The grid aim carries each solved field's Jacobian and slope du/df to its neighbours
    # (raytrace.kernels.aim2d): the Topogon's 21 x 21 grid to 39 deg took 10.5 traces to the
    # stop per field with a difference Jacobian in every Newton step, 5.9 now (regression pins,
    # benchmarks/ab.py's grid21_traces, 2026-11-28); the bound here fails on the old aim.
    lens = load_lens(name)
    X, Y = np.meshgrid(np.linspace(-half, half, 21), np.linspace(-half, half, 21))
    cr = chief_rays_2d(lens, X, Y, object_distance=od)
    assert np.all(cr.status == STATUS_OK)
    assert cr.iterations.mean() <= 7.0 and cr.iterations.max() <= 12
    # the polish (with the carried, Broyden-updated Jacobian) takes every field far below the
    # tolerance (here <= 0.007 of it; 0.0006 with a fresh difference Jacobian: regression pins),
    # so a field aimed alone (from the origin field's solution and Jacobian) lands on the same
    # image point
    i = [0, 17, 220, 303, 440]
    lone = [chief_rays_2d(lens, [X.flat[k]], [Y.flat[k]], object_distance=od) for k in i]
    z = paraxial(lens, od).z_gauss
    for k, one in zip(i, lone, strict=True):
        assert one.iterations[0] > 0
        np.testing.assert_allclose(
            one.positions_at(z)[0], cr.positions_at(z).reshape(-1, 2)[k], rtol=0, atol=1e-12
        )
    for r in (cr.stop_residual_x, cr.stop_residual_y):
        assert np.max(np.abs(r)) <= 0.05 * cr.tolerance


def test_fields_a_round_off_apart_leave_the_carried_slope_finite():
    # a review's reproducer: fields k x 2.3e-162 (tangents) on a triplet whose stop surface is
    # decentred and tilted; the slope du/df carried from field to field once divided by a
    # denormal |df|^2 and became inf/NaN, and 19 of the 20 fields failed (0 before carrying)
    cooke = load_lens("cooke-triplet-f4")
    s = list(cooke.surfaces)
    s[3] = dataclasses.replace(
        s[3], placement=Placement((-0.4, 0.7, 0.0), (-3.0, 4.0, 0.0)), after="return"
    )
    lens = dataclasses.replace(cooke, surfaces=tuple(s))
    f = np.degrees(np.arctan(np.arange(1, 21) * 2.3e-162))
    cr = chief_rays_2d(lens, f, np.zeros(20))
    assert np.all(cr.status == STATUS_OK)
    ref = chief_rays_2d(lens, [0.0], [0.0])
    np.testing.assert_allclose(cr.positions_at(60.0), np.repeat(ref.positions_at(60.0), 20, 0),
                               rtol=0, atol=1e-12)  # fmt: skip


def test_shapes_and_plane_stacks():
    lens = load_lens("cooke-triplet-f4")
    X, Y = _grid(15.0, 5)
    cr = chief_rays_2d(lens, X[:3], Y[:3])
    assert cr.positions_at(60.0).shape == (3, 5, 2)
    assert cr.positions_at([60.0, 61.0]).shape == (2, 3, 5, 2)
    one = chief_rays_2d(lens, fields_y_deg=[0.0, 5.0])  # a missing component is zero
    np.testing.assert_array_equal(one.x_last, 0.0)


def test_bad_requests():
    lens = load_lens("cooke-triplet-f4")
    with pytest.raises(TraceError, match="not both"):
        chief_rays_2d(lens, 1.0, 1.0, object_x_mm=1.0, object_distance=100.0)
    with pytest.raises(TraceError, match="finite object"):
        chief_rays_2d(lens, object_x_mm=[1.0], object_y_mm=[0.0])
    with pytest.raises(TraceError, match="90"):
        chief_rays_2d(lens, [90.0], [0.0])
    with pytest.raises(TraceError, match="broadcast"):
        chief_rays_2d(lens, [1.0, 2.0], [1.0, 2.0, 3.0])
    with pytest.raises(TraceError, match="give"):
        chief_rays_2d(lens)


@pytest.mark.parametrize(
    ("kw", "says"),
    [
        (dict(fields_x_deg=[], fields_y_deg=[]), "no fields given: fields_x_deg is empty"),
        (dict(fields_x_deg=0.0, fields_y_deg=[]), "no fields given: fields_y_deg is empty"),
        (dict(object_x_mm=[], object_distance=1000), "no fields given: object_x_mm is empty"),
        (dict(fields_x_deg=[0, 1j], fields_y_deg=[0, 5]), "fields_x_deg: expected field angles "
         "in degrees (a number or a list of numbers), got [0, 1j] (a complex number)"),
        (dict(fields_x_deg=[0, 5], fields_y_deg=True), "fields_y_deg: expected field angles in "
         "degrees (a number or a list of numbers), got True (a bool, not a number)"),
        (dict(object_x_mm=[0, 1], object_y_mm=[2j, 0], object_distance=1000),
         "object_y_mm: expected object coordinates in mm"),
    ],
)  # fmt: skip
def test_empty_fields_and_fields_that_are_no_numbers_are_refused(kw, says):
    # [] and [] returned an empty result (characteristic_distortion and distortion_grid refuse
    # "no fields given"); [0, 1j] raised float()'s bare TypeError; True traced 1 degree
    with pytest.raises(TraceError) as e:
        chief_rays_2d(load_lens("cooke-triplet-f4"), **kw)
    assert says in str(e.value), str(e.value)


def _optiland_chief_points(op, lens, X, Y):
    """optiland's chief-ray points (…, 2) on its image surface (mm) for the fields ``X``, ``Y`` in
    its field units (normalised by its max field), at the lens's wavelength."""
    fmax = float(op.fields.max_field)
    rays = op.trace_generic(
        Hx=(X / fmax).ravel(), Hy=(Y / fmax).ravel(), Px=0.0, Py=0.0,
        wavelength=lens.wavelength / 1000.0,
    )  # fmt: skip
    return np.stack([np.asarray(rays.x), np.asarray(rays.y)], -1).reshape(np.shape(X) + (2,))


@pytest.mark.parametrize(
    "name",
    [
        "cooke-triplet-f4",
        "topogon-us2031792-fig1",
        "topogon-like-pestrecov",
        # the image heights its notes compare with Pestrecov's Table I
        "topogon-like-spherical-heights",
    ],
)
def test_2d_chief_ray_image_points_agree_with_optiland(name):
    """optiland 0.6.3: its own chief rays (Px = Py = 0) aimed at the stop centre by its iterative
    aimer (tolerance 1e-13), for normalised fields Hx, Hy × its max field with its angle-field
    convention (direction tangents tan(field_x), tan(field_y)), on its image surface."""
    ola = benchmark_module("optiland_adapter", needs="optiland")
    lens = load_lens(name)
    op = ola.build_optic(lens)
    op.ray_tracer.set_aiming("iterative", max_iter=50, tol=1e-13)
    X, Y = _grid(lens.field.value, 9)
    cr = chief_rays_2d(lens, X, Y)
    ours = cr.positions_at(paraxial(lens).z_image_file)
    assert np.max(np.abs(ours - _optiland_chief_points(op, lens, X, Y))) <= 1e-9


def test_finite_object_heights_agree_with_optiland():
    ola = benchmark_module("optiland_adapter", needs="optiland")
    lens = load_lens("cooke-triplet-f4").with_object_distance(500.0)
    op = ola.build_optic(lens)
    op.fields.fields.clear()  # the adapter's angle fields → object heights (mm)
    op.fields.set_type("object_height")
    op.fields.add(y=0.0)
    op.fields.add(y=100.0)
    op.ray_tracer.set_aiming("iterative", max_iter=50, tol=1e-13)
    a = np.linspace(-60.0, 60.0, 5)
    X, Y = np.meshgrid(a, a)
    cr = chief_rays_2d(lens, object_x_mm=X, object_y_mm=Y)
    ours = cr.positions_at(paraxial(lens).z_image_file)
    assert np.max(np.abs(ours - _optiland_chief_points(op, lens, X, Y))) <= 1e-9


def test_a_stop_smaller_than_the_aperture_says_so_in_2d_too():
    # The 1-D aim warned (tests/test_trace.py) and the 2-D aim, behind distortion grids and
    # camera fits, did not: the same lens traced on a grid clipped its marginal rays silently.
    # The warning points at the caller of the public function (stacklevel).
    import warnings

    from raytrace.trace.chief import ApertureWarning

    lens = load_lens("cooke-triplet-f4")
    s = list(lens.surfaces)
    # 3.1 mm, not the 3.0 of tests/test_trace.py: the aims cache their setup per lens (and warn
    # once), so an equal lens traced here first would silence the warning there
    s[3] = dataclasses.replace(s[3], semi_diameter=3.1)  # f/4 needs 4.75 mm at the stop
    small = dataclasses.replace(lens, surfaces=tuple(s))
    for trace in (chief_rays_2d, chief_rays):
        with pytest.warns(ApertureWarning, match="clipped at the stop") as got:
            trace(small, [0.0, 10.0], [0.0, 5.0]) if trace is chief_rays_2d else trace(
                small, [0.0, 10.0]
            )
        assert got[0].filename == __file__, trace.__name__
    s[3] = dataclasses.replace(s[3], semi_diameter=5.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error", ApertureWarning)
        chief_rays_2d(dataclasses.replace(lens, surfaces=tuple(s)), [0.0, 10.0], [0.0, 5.0])
