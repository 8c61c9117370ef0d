"""The operands of single elements and surfaces (raytrace.optimize.operands): ``ray_height``, where
one real ray of a field meets a surface (the footprint bound a shop rule at a clear aperture
needs), and ``element_power``, the paraxial power of an element or a run of surfaces.

Reference values are computed here, independently of the tracer, from closed forms: the
intersection of a straight line with a sphere (vertex at z_v, curvature c: the centre on the axis
at z_v + 1/c) and the vector form of Snell's law, n' (d' × m) = n (d × m) for the unit normal m
(e.g. Welford, *Aberrations of Optical Systems*, §4.2), and the thick-lens power (Hecht,
*Optics*, 4th ed., Eq. 6.2). The rays' definition (the spot operands'
bundles: through the paraxial entrance pupil, centred on the axis, from the object point or
parallel at the field angle) is the one docs/spec.md states.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from support import singlet

from raytrace import AIR, Aperture, Field, Lens, Surface, fixed_index
from raytrace.errors import TraceError
from raytrace.files.library import load_lens
from raytrace.optimize import DesignSpec, Operand, SpecError, Variable, evaluate, optimize
from raytrace.optimize.spec import operand_problems
from raytrace.paraxial import paraxial


def _hit_sphere(p, d, z_v: float, c: float) -> np.ndarray:
    """The nearer intersection of the line p + s d (s > 0 along d) with the sphere through the
    vertex z_v of curvature c (a plane where c = 0)."""
    p, d = np.asarray(p, float), np.asarray(d, float)
    if c == 0:
        return p + (z_v - p[2]) / d[2] * d
    centre = np.array([0.0, 0.0, z_v + 1.0 / c])
    q = p - centre
    b = float(q @ d)
    disc = b * b - float(q @ q - 1.0 / c**2)
    roots = (-b - math.sqrt(disc), -b + math.sqrt(disc))
    # the branch of the sphere nearest the vertex: |z - z_v| smallest
    return min((p + s * d for s in roots), key=lambda x: abs(x[2] - z_v))


def _refract(d, point, z_v: float, c: float, n1: float, n2: float) -> np.ndarray:
    """Snell's law in vector form at a sphere (unit normal toward the centre's side)."""
    m = np.array([0.0, 0.0, 1.0]) if c == 0 else -(point - [0.0, 0.0, z_v + 1.0 / c]) * c
    m = m / np.linalg.norm(m)
    if m @ d < 0:
        m = -m
    cos_i = float(m @ d)
    mu = n1 / n2
    cos_t = math.sqrt(1.0 - mu * mu * (1.0 - cos_i * cos_i))
    return mu * d + (cos_t - mu * cos_i) * m


def test_ray_height_against_line_sphere_intersections_object_at_infinity():
    lens = singlet(n=1.5, f=100.0, t=4.0, fnum=5.0)  # stop on surface 1: pupil at its vertex
    c1, c2 = lens.surfaces[0].curvature, lens.surfaces[1].curvature
    a = paraxial(lens).epd / 2.0
    theta = math.radians(10.0)
    d0 = np.array([0.0, math.sin(theta), math.cos(theta)])
    for px, py in ((0.0, 1.0), (0.0, -1.0), (1.0, 0.0), (0.6, -0.3)):
        ops = tuple(
            Operand("ray_height", 0.0, 1.0, {"surface": s, "field": 10.0, "pupil": [px, py]})
            for s in (1, 2)
        )
        got = [v.value for v in evaluate(lens, ops)]
        # the ray crosses the pupil plane (the first vertex, z = 0) at (a px, a py)
        p1 = _hit_sphere([a * px, a * py, 0.0], d0, 0.0, c1)
        d1 = _refract(d0, p1, 0.0, c1, 1.0, 1.5)
        p2 = _hit_sphere(p1, d1, 4.0, c2)
        want = [math.hypot(p1[0], p1[1]), math.hypot(p2[0], p2[1])]
        assert got == pytest.approx(want, rel=1e-12, abs=1e-12)


def test_ray_height_from_a_finite_object_point():
    # the Twinplex-like at Pestrecov's projection setting (Table IV, s = -55.0009 mm): the 45 deg
    # rim rays leave the object point p0 tan 45 deg (nominal angle) for the rim of the paraxial
    # entrance pupil and meet surface 1, a sphere
    from raytrace.paraxial import resolve_object_distance

    lens = load_lens("twinplex-like-55-525")
    ops = tuple(
        Operand(
            "ray_height",
            0.0,
            1.0,
            {"surface": 1, "field": 45.0, "pupil": [0, py], "object_s": -55.0009},
        )
        for py in (1.0, -1.0)
    )
    got = [v.value for v in evaluate(lens, ops)]
    od = resolve_object_distance(lens, object_s=-55.0009)
    par = paraxial(lens, od)
    a = par.epd / 2.0
    y_obj = par.p0 * math.tan(math.radians(45.0))
    obj = np.array([0.0, y_obj, par.z_object])
    c1 = lens.surfaces[0].curvature
    want = []
    for py in (1.0, -1.0):
        d = np.array([0.0, a * py, par.z_E0]) - obj
        p1 = _hit_sphere(obj, d / np.linalg.norm(d), 0.0, c1)
        want.append(abs(p1[1]))
    assert got == pytest.approx(want, rel=1e-12)
    assert max(got) > 25.0  # the front element's footprint at 45 deg (a pin of scale, not value)


def _stop_and_lens(d: float) -> Lens:
    """A stop, then after an air gap d (mm) a plano-convex lens with its flat side first."""
    return Lens(
        "stop-gap-lens",
        (
            Surface(0.0, d, AIR, stop=True),
            Surface(0.0, 5.0, fixed_index(1.5)),
            Surface(-0.01, 150.0, AIR),
        ),
        Aperture("epd", 10.0),
        Field("angle", 20.0),
        image_solve=None,
    )


def test_a_ray_height_bound_holds_a_footprint_in_minimax():
    # the upper rim ray of the 20 deg field crosses the stop at y = 5 and meets the flat surface
    # 2 at y = 5 + d tan 20 deg: the bound y <= 12 mm allows d <= 7 / tan 20 deg = 19.2324 mm.
    # A target d = 40 pulls against it, so the minimax optimum sits on the bound.
    d_max = 7.0 / math.tan(math.radians(20.0))
    spec = DesignSpec(
        start="(built in test)",
        variables=(Variable("thickness", 1, 1.0, 60.0),),
        operands=(
            Operand("center_thickness", 40.0, 1.0, {"surface": 1}),
            Operand("ray_height", 0.0, 1.0, {"surface": 2, "field": 20.0, "max": 12.0}),
        ),
        method="minimax",
        max_evaluations=400,
    )
    res = optimize(_stop_and_lens(10.0), spec)
    assert res.converged, res.message
    assert res.x == pytest.approx([d_max], rel=1e-8)
    assert res.merit == pytest.approx(40.0 - d_max, rel=1e-8)
    (bound,) = [o for o in res.operands if o.operand.bounded]
    assert bound.value == pytest.approx(12.0, rel=1e-9)


def test_a_ray_that_misses_its_surface_is_an_error():
    # the 20 deg upper rim ray meets the flat surface 2 at y = 5 + 10 tan 20 deg = 8.6 mm and
    # the rear surface about 1 mm higher: a rear sphere of radius 6.7 mm does not reach there
    from dataclasses import replace

    lens = _stop_and_lens(10.0)
    s = list(lens.surfaces)
    s[2] = replace(s[2], curvature=-0.15)
    lens = replace(lens, surfaces=tuple(s))
    op = Operand("ray_height", 0.0, 1.0, {"surface": 3, "field": 20.0})
    with pytest.raises(TraceError, match=r"ray_height.*does not reach surface 3"):
        evaluate(lens, (op,))
    # the Cooke triplet's f/4 upper rim ray at 40 deg reaches surface 4 and is totally
    # reflected there: said so, not "does not reach"
    tir = Operand("ray_height", 0.0, 1.0, {"surface": 4, "field": 40.0, "pupil": [0, 1]})
    with pytest.raises(TraceError, match=r"the ray is totally reflected at surface 4 \(total"):
        evaluate(load_lens("cooke-triplet-f4"), (tir,))


def test_ray_height_parameters_are_checked():
    assert operand_problems("ray_height", {"surface": 2, "pupil": [0.9, 0.9]}, 0.0, 1.0) == [
        "'pupil' must be two numbers [px, py] inside the unit circle (fractions of the "
        "entrance-pupil radius), got [0.9, 0.9]"
    ]
    assert operand_problems("ray_height", {"field": 5.0}, 0.0, 1.0) == [
        "operand ray_height needs a 'surface'"
    ]
    assert operand_problems("ray_height", {"surface": 2, "pupil": [0, -1], "max": 3}, 0, 1) == []
    from raytrace.optimize.solver import check_spec

    spec = DesignSpec(
        start="(built in test)",
        variables=(Variable("thickness", 1, 1.0, 60.0),),
        operands=(Operand("ray_height", 0.0, 1.0, {"surface": 4, "max": 12.0}),),
    )
    with pytest.raises(
        SpecError, match=r"\(ray_height\(surface=4, max=12.0\)\): surface 4 does not exist \(1\.\.3"
    ):
        check_spec(_stop_and_lens(10.0), spec)


# --------------------------------------------------------------------------- element_power
def test_element_power_is_the_thick_lens_formula():
    # each element of the Cooke triplet in air: phi = (n - 1)(c1 - c2) + (n - 1)^2 t c1 c2 / n
    # (Hecht, Optics, 4th ed., Eq. 6.2), n the element's glass index at the lens's wavelength
    lens = load_lens("cooke-triplet-f4")
    n_after = lens.indices(lens.wavelength)[0][1:]
    glass = [i for i, s in enumerate(lens.surfaces[:-1]) if not s.material.is_air]
    assert len(glass) == 3
    ops = tuple(Operand("element_power", 0.0, 1.0, {"surface": i + 1}) for i in glass)
    got = [v.value for v in evaluate(lens, ops)]
    for i, g in zip(glass, got, strict=True):
        s1, s2 = lens.surfaces[i], lens.surfaces[i + 1]
        n, c1, c2, t = n_after[i], s1.curvature, s2.curvature, s1.thickness
        want = (n - 1) * (c1 - c2) + (n - 1) ** 2 * t * c1 * c2 / n
        assert g == pytest.approx(want, rel=1e-12)
    assert [math.copysign(1, g) for g in got] == [1, -1, 1]  # the triplet's + - +
    # the whole lens as one run of surfaces: 1 / EFL
    (whole,) = evaluate(lens, (Operand("element_power", 0.0, 1.0, {"surface": 1, "last": 6}),))
    assert whole.value == pytest.approx(1.0 / paraxial(lens).efl, rel=1e-12)


def test_element_power_parameters_are_checked():
    from raytrace.optimize.solver import check_spec

    assert operand_problems("element_power", {"surface": 3, "last": 2}, 0.0, 1.0) == [
        "'last' must be an integer surface number (1-based) not before 'surface', got 2"
    ]
    lens = _stop_and_lens(10.0)  # 3 surfaces
    for params, msg in (
        ({"surface": 3}, r"surface 3 is the last; it needs the next surface \(give 'last'"),
        ({"surface": 1, "last": 4}, r"last surface 4 does not exist \(the lens has 3\)"),
    ):
        spec = DesignSpec(
            start="(built in test)",
            variables=(Variable("thickness", 1, 1.0, 60.0),),
            operands=(Operand("element_power", 0.0, 1.0, {**params, "min": 0.0}),),
        )
        with pytest.raises(SpecError, match=msg):
            check_spec(lens, spec)


def test_evaluate_checks_what_it_is_given():
    # the API path (no check_spec before it): a surface the lens lacks is an error naming the
    # operand, never another surface's value (surface 0 read as Python's index -1 once)
    lens = load_lens("cooke-triplet-f4")  # 6 surfaces
    for params, msg in (
        ({"surface": 0}, r"operands\[0\] \(ray_height\(surface=0\)\): surface 0 does not exist"),
        ({"surface": -1}, r"surface -1 does not exist"),
        ({"surface": 7}, r"surface 7 does not exist \(1\.\.6"),
        ({"surface": 1.7}, r"'surface' must be an integer"),
        ({"surface": True}, r"'surface' must be an integer"),
        ({"surface": 2, "pupil": [0, 0, 1]}, r"'pupil' must be two numbers"),
        ({"surface": 2, "field": 90.0}, r"field 90 deg: field angles lie strictly between"),
        ({"surface": 2, "field": 5.0, "field_kind": "height"}, r"needs a finite object distance"),
    ):
        with pytest.raises(SpecError, match=msg):
            evaluate(lens, (Operand("ray_height", 0.0, 1.0, params),))
    with pytest.raises(SpecError, match=r"'surface' must be an integer \(1-based\), got 1.5"):
        evaluate(lens, (Operand("element_power", 0.0, 1.0, {"surface": 1.5, "last": 3}),))
    # numpy numbers are numbers (an API user's loop variables)
    numpy_params = {"surface": np.int64(1), "pupil": np.array([0.0, 1.0])}
    (v,) = evaluate(lens, (Operand("ray_height", 0.0, 1.0, numpy_params),))
    (w,) = evaluate(lens, (Operand("ray_height", 0.0, 1.0, {"surface": 1, "pupil": [0.0, 1.0]}),))
    assert v.value == w.value


def test_element_power_default_refuses_a_cemented_element():
    # Tessar surfaces 6-7: the flint of the cemented rear group. Its power "in its media" (air in
    # front, the crown behind) is not the element's power in air (the thick-lens formula gives a
    # negative element): the default 'element' is refused and 'last' names the run meant.
    lens = load_lens("tessar-fr1066698")
    assert lens.surfaces[5].material.is_air is False and lens.surfaces[6].material.is_air is False
    with pytest.raises(SpecError, match=r"surfaces 6-7 are not an element in air .* give 'last'"):
        evaluate(lens, (Operand("element_power", 0.0, 1.0, {"surface": 6}),))
    (group,) = evaluate(lens, (Operand("element_power", 0.0, 1.0, {"surface": 6, "last": 8}),))
    assert math.isfinite(group.value)


def test_failed_evaluations_are_counted_and_named(tmp_path):
    # a thickness pushed against the wall where the rim ray starts to fail: the run says how many
    # trial lenses could not be traced and why the first one failed
    from raytrace.optimize.solver import EvaluationLog

    log = EvaluationLog()
    assert log.note() == ""
    log.n, log.failed, log.first_failure = 10, 3, "ray_height(surface=2): travels backwards"
    assert log.note() == (
        "; 3 of 10 evaluations failed (trial lenses that cannot be traced; the first: "
        "ray_height(surface=2): travels backwards)"
    )
    # the Cooke triplet's first element thinned towards 0.5 mm: below about 1.8 mm its edge
    # closes and the 20 deg lower rim ray meets surface 2 before surface 1 (travels backwards)
    from dataclasses import replace

    lens = load_lens("cooke-triplet-f4")
    spec = DesignSpec(
        start="cooke-triplet-f4",
        variables=(Variable("thickness", 1, 0.1),),
        operands=(
            Operand("center_thickness", 0.5, 10.0, {"surface": 1}),
            Operand("ray_height", 0.0, 1.0, {"surface": 2, "field": 20.0, "pupil": [0, -0.8],
                                             "max": 100.0}),
        ),
        max_evaluations=30,
    )  # fmt: skip
    for method in ("least_squares", "minimax"):
        res = optimize(lens, replace(spec, method=method))
        n_failed = int(res.message.split(" evaluations failed")[0].split("; ")[-1].split(" of ")[0])
        assert n_failed > 0, res.message
        assert "the first: ray_height(surface=2, field=20.0, pupil=[0, -0.8]" in res.message
        assert "travels backwards to surface 2" in res.message
        assert res.lens.surfaces[0].thickness > 1.8  # the best traceable design is kept


def test_a_coordinate_break_is_no_element_and_no_footprint():
    # a coordinate break is a frame, not a surface rays meet (docs/design.md): both operands
    # refuse it instead of giving the next surface's power / a meaningless height
    from raytrace.frames import Placement

    cooke = load_lens("cooke-triplet-f4")
    cb = Surface(0.0, 0.0, coordinate_break=True, placement=Placement((0, 0.5, 0), (0, 0, 0)))
    lens = Lens("cb", (cb, *cooke.surfaces), cooke.aperture, cooke.field)
    for op, msg in (
        (Operand("element_power", 0.0, 1.0, {"surface": 1}), "name the element's first surface"),
        (Operand("ray_height", 0.0, 1.0, {"surface": 1}), "name a surface rays meet"),
    ):
        with pytest.raises(
            SpecError, match=r"surface 1 is a coordinate break \(not traced\); " + msg
        ):
            evaluate(lens, (op,))
