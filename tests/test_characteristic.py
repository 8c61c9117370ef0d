"""Characteristic distortion of traced lenses in any image plane (Pestrecov 1958, Eqs. 8–9).

Sources of the expected facts:
- Pestrecov Section III: in the Gaussian plane M0 = m0 and F0 = f (Eq. 7 into Eq. 8).
- Classical orthoscopy (symmetry principle): a lens symmetric about its stop used at −1× has zero
  distortion — the chief ray crosses the stop centre, and by symmetry leaves at the angle it came
  in with, at the mirror height, so y' = −y exactly.
- docs/design.md, "Equations": the named reference definitions agree in the Gaussian plane and
  differ away from it.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

from distortion.calibration import calibrate
from distortion.characteristic import REFERENCES, characteristic_distortion
from orthoscope.report.distortion import characteristic_to_dict, format_characteristic
from raytrace.errors import TraceError
from raytrace.files.native import read_lens
from raytrace.lens import Aperture, Field, Lens, Surface
from raytrace.materials import model_glass
from raytrace.paraxial import paraxial

LENSES = Path(__file__).resolve().parents[1] / "lenses"


@pytest.fixture(scope="module")
def triplet():
    return read_lens(LENSES / "cooke-triplet-f4.toml")


def symmetric_lens(object_distance: float = math.inf) -> Lens:
    """A made-up meniscus doublet, mirror-symmetric about a central plane stop (air-spaced)."""
    g = model_glass(1.62, 60.3)
    r1, r2, t, a = 18.0, 30.0, 4.0, 5.0
    s = (
        Surface(1 / r1, t, g),
        Surface(1 / r2, a),
        Surface(0.0, a, stop=True),
        Surface(-1 / r2, t, g),
        Surface(-1 / r1, 50.0),
    )
    return Lens(
        "symmetric doublet", s, Aperture("fnumber", 8.0), Field("angle", 20.0), object_distance
    )


def unit_conjugate_distance(lens: Lens) -> float:
    """Object distance (from the first vertex) whose Gaussian image lies as far behind the last
    vertex: the symmetric −1× conjugates."""
    return brentq(
        lambda d: paraxial(lens, object_distance=d).gaussian_image_distance - d,
        60.0,
        400.0,
        xtol=1e-14,
    )


def test_symmetric_lens_at_unit_magnification_is_orthoscopic():
    lens = symmetric_lens()
    d = unit_conjugate_distance(lens)
    par = paraxial(lens, object_distance=d)
    assert par.m0 == pytest.approx(-1.0, abs=1e-12)
    heights = np.linspace(0.0, 12.0, 13)
    res = characteristic_distortion(lens, object_heights_mm=heights, object_distance=d)
    assert np.all(res.status == 0)
    assert res.constant[0] == pytest.approx(-1.0, abs=1e-12)
    # y' = -y and D0 = 0 to round-off at every field (measured: |D0| <= 5.9e-16 of the image
    # height, |y' + y| <= 3.6e-15 mm; bounds ~10x that)
    assert np.max(np.abs(res.D0[0])) <= 1e-14 * np.max(np.abs(res.yp[0]))
    np.testing.assert_allclose(res.yp[0], -heights, rtol=0, atol=3e-15 * 12.0)
    # the same lens at infinity is not orthoscopic: the test can fail
    inf = characteristic_distortion(lens, [0.0, 10.0, 20.0], object_distance=math.inf)
    assert abs(inf.D0[0][-1]) > 1e-4


@pytest.mark.parametrize("od", [math.inf, 400.0])
def test_gaussian_plane_constants_and_references_agree(triplet, od):
    kind = "angle"
    fields = (
        np.array([0.0, 5.0, 10.0, 15.0, 20.0])
        if math.isinf(od)
        else np.array([0.0, -20.0, -40.0, -60.0])
    )
    if not math.isinf(od):
        kind = "height"
    res = {
        ref: characteristic_distortion(
            triplet,
            **({"fields_deg": fields} if kind == "angle" else {"object_heights_mm": fields}),
            object_distance=od,
            reference=ref,
        )
        for ref in REFERENCES
    }
    c = res["characteristic"]
    par = c.paraxial
    # Pestrecov Section III: in the Gaussian plane M0 = m0, F0 = f
    expected = par.efl if math.isinf(od) else par.m0
    assert c.constant[0] == pytest.approx(expected, rel=1e-12)
    assert c.defocus[0] == 0.0
    h = np.max(np.abs(c.yp[0]))
    # measured: D0 agree to 8.2e-15 h, scales to 8.1e-15 (relative); bounds ~10x that
    for ref in REFERENCES[1:]:
        np.testing.assert_allclose(res[ref].D0[0], c.D0[0], rtol=0, atol=1e-13 * h)
        np.testing.assert_allclose(res[ref].scale, c.scale, rtol=1e-13)


def test_away_from_gaussian_plane_references_differ(triplet):
    fields = [0.0, 5.0, 10.0, 15.0, 20.0]
    dz = [-0.5, 0.5]
    c = characteristic_distortion(triplet, fields, defocus=dz)
    t = characteristic_distortion(triplet, fields, defocus=dz, reference="real-chief-transport")
    d = characteristic_distortion(triplet, fields, defocus=dz, reference="distortion-focal-length")
    g = characteristic_distortion(triplet, fields)
    # real-chief-transport keeps the Gaussian-plane linear distortion in every plane...
    np.testing.assert_allclose(t.D0, np.vstack([g.D0[0], g.D0[0]]), rtol=0, atol=1e-12)
    # ...while the characteristic distortion changes with the plane (here by > 1 µm at 20°)
    assert np.all(np.abs(c.D0[:, -1] - g.D0[0, -1]) > 1e-3)
    assert np.all(np.abs(t.D0[:, -1] - c.D0[:, -1]) > 1e-3)
    # Eq. (8) is the paraxial limit of y'/tan α in ANY plane, so the extrapolated distortion focal
    # length reproduces F0 away from the Gaussian plane as well (the ε² term is extrapolated out)
    # (measured: 8.3e-15 relative; bound ~10x that)
    np.testing.assert_allclose(d.scale, c.constant, rtol=1e-13)
    # and F0 moves with the plane as p0'/m_e does (Eq. 8). NB: this restates the formula the
    # code itself evaluates (bit-identical today); the independent check is the line above.
    par = c.paraxial
    np.testing.assert_allclose(c.constant, (c.s_prime - par.HpE0p) / par.m_e, rtol=1e-13)


def test_many_planes_from_one_trace_equal_separate_traces(triplet):
    fields = np.linspace(0.0, 20.0, 9)
    sp = np.array([45.0, 49.0, 50.0, 52.5])
    many = characteristic_distortion(triplet, fields, s_prime=sp)
    for i, v in enumerate(sp):
        one = characteristic_distortion(triplet, fields, s_prime=v)
        np.testing.assert_allclose(many.D0[i], one.D0[0], rtol=0, atol=1e-13)
        np.testing.assert_allclose(many.constant[i], one.constant[0], rtol=1e-15)
        assert many.s_prime[i] == pytest.approx(v, abs=1e-12)
    # the three ways of naming a plane agree
    par = many.paraxial
    a = characteristic_distortion(triplet, fields, from_last_vertex=sp + par.z_Hp - par.z_last)
    b = characteristic_distortion(triplet, fields, defocus=sp + par.z_Hp - par.z_gauss)
    np.testing.assert_allclose(a.D0, many.D0, rtol=0, atol=1e-11)
    np.testing.assert_allclose(b.D0, many.D0, rtol=0, atol=1e-11)


def test_nominal_angle_fields_for_finite_object(triplet):
    od = 400.0
    a = characteristic_distortion(triplet, [0.0, 5.0, 10.0], object_distance=od)
    par = a.paraxial
    y = par.p0 * np.tan(
        np.radians([0.0, 5.0, 10.0])
    )  # y = p0 tan α (docs/design.md, "Conventions")
    h = characteristic_distortion(triplet, object_heights_mm=y, object_distance=od)
    assert a.field_kind == "nominal-angle"
    np.testing.assert_allclose(a.x, y, rtol=1e-15)
    np.testing.assert_allclose(a.D0, h.D0, rtol=0, atol=1e-10)


def test_curve_calibration_and_output(triplet):
    res = characteristic_distortion(triplet, [0.0, 5.0, 10.0, 15.0, 20.0], defocus=[0.0, 0.3])
    cal = calibrate(res.curve(1), "minimax")
    assert cal.symbol == "F" and cal.Dc_max_abs < np.max(np.abs(res.D0[1]))
    text = format_characteristic(res)
    assert "s'=" in text and "Gaussian plane" in text
    d = characteristic_to_dict(res)
    from raytrace.kernels.codes import STATUS_NAMES, STATUS_OK

    assert len(d["planes"]) == 2 and d["status"] == [STATUS_NAMES[STATUS_OK]] * 5


def test_untraced_fields_are_named_with_their_status_in_the_text(triplet):
    # 60° is beyond the triplet's field (aim fails); the words are the kernels' status table's
    from distortion.telecentricity import pupil_analysis
    from orthoscope.report.telecentricity import format_pupils
    from raytrace.trace.results import status_name

    res = characteristic_distortion(triplet, [0.0, 10.0, 60.0])
    assert res.status[2] != 0 and not res.status[:2].any()
    line = f"fields not traced: 60: {status_name(res.status[2])}"
    assert format_characteristic(res).splitlines()[-1] == line
    pa = pupil_analysis(triplet, [0.0, 10.0, 60.0])
    assert line in format_pupils(pa).splitlines()
    assert "not traced" not in format_characteristic(characteristic_distortion(triplet, [10.0]))


def test_bad_requests(triplet):
    with pytest.raises(TraceError, match="unknown distortion reference"):
        characteristic_distortion(triplet, [10.0], reference="zemax")
    with pytest.raises(TraceError, match="behind the lens"):
        characteristic_distortion(triplet, [10.0], from_last_vertex=-1.0)
    with pytest.raises(TraceError, match="one way"):
        characteristic_distortion(triplet, [10.0], s_prime=50.0, defocus=0.0)
    with pytest.raises(TraceError, match="finite object"):
        characteristic_distortion(triplet, object_heights_mm=[1.0])


@pytest.mark.parametrize(
    ("analysis", "kw", "value", "says"),
    [
        ("characteristic_distortion", "fields_deg", [0, 1j], "fields_deg: expected field angles "
         "in degrees (a number or a list of numbers), got [0, 1j] (a complex number)"),
        ("characteristic_distortion", "fields_deg", True, "fields_deg: expected field angles in "
         "degrees (a number or a list of numbers), got True (a bool, not a number)"),
        ("characteristic_distortion", "object_heights_mm", [0, np.True_],
         "object_heights_mm: expected object heights in mm"),
        ("characteristic_distortion", "fields_deg", [], "no fields given: fields_deg is empty"),
        ("pupil_analysis", "fields_deg", [0, 1j], "fields_deg: expected field angles in degrees"),
        ("lateral_colour", "fields_deg", [False, True], "(a bool, not a number)"),
        ("radial_by_azimuth", "fields_deg", [0, 1j], "fields_deg: expected field angles"),
        ("radial_by_azimuth", "object_radii_mm", [0, 1j], "object_radii_mm: expected object radii"),
    ],
)  # fmt: skip
def test_fields_that_are_no_numbers_are_refused_by_every_1d_analysis(
    cooke, analysis, kw, value, says
):
    # [0, 1j] raised float()'s bare TypeError from requested_fields; True traced a field of 1
    # degree (the 1-D analyses all convert their fields in requested_fields)
    import orthoscope as osc

    od = {"object_distance": 1000} if kw != "fields_deg" else {}
    with pytest.raises(TraceError) as e:
        getattr(osc, analysis)(cooke, **{kw: value}, **od)
    assert says in str(e.value) and "\n" not in str(e.value), str(e.value)
