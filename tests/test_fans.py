"""Ray fans and spot diagrams (raytrace.trace.fans): checked against an analytic case, against
optiland as an independent tracer, and against their own definitions."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import orthoscope as osc
from raytrace.errors import TraceError

ROOT = Path(__file__).resolve().parents[1]


def test_fan_is_centred_on_the_real_chief_ray(cooke):
    # the middle ray of an odd fan is the chief ray itself: zero aberration to the aim tolerance,
    # also far off axis where the real chief ray misses the paraxial pupil centre
    for field in (0.0, 14.0, 20.0):
        fan = osc.ray_fan(cooke, field, n=21)
        assert fan.pupil[10] == 0.0
        assert abs(fan.ey[10]) < 1e-9 and abs(fan.ex[10]) < 1e-12
        sag = osc.ray_fan(cooke, field, n=21, axis="x")
        assert np.allclose(sag.ex, -sag.ex[::-1], atol=1e-12)  # sagittal fan is odd in px
        assert np.all(sag.status == 0)


def test_bundle_fills_the_paraxial_pupil_about_the_real_chief_ray(cooke):
    # object at infinity: every ray parallel to the real chief ray, crossing the paraxial
    # entrance-pupil plane at the chief ray's crossing + (px, py) EPD/2
    par = osc.paraxial(cooke)
    cr = osc.chief_rays(cooke, fields_deg=[17.0])
    from raytrace.trace import aimed_bundle, pupil_points

    px, py = pupil_points("hexapolar", 4)
    b = aimed_bundle(
        cooke, par, (cr.y_start[0], cr.z_start[0], cr.M_start[0], cr.N_start[0]), px, py
    )
    L, M, N = b.directions
    assert np.allclose(L, 0.0) and np.allclose(M, cr.M_start[0]) and np.allclose(N, cr.N_start[0])
    x0, y0, z0 = b.origins
    t = (par.z_E0 - z0) / N
    y_chief = cr.y_start[0] + (par.z_E0 - cr.z_start[0]) * cr.M_start[0] / cr.N_start[0]
    np.testing.assert_allclose(x0 + t * L, px * par.epd / 2, atol=1e-12)
    np.testing.assert_allclose(y0 + t * M - y_chief, py * par.epd / 2, atol=1e-12)
    assert np.all(z0 < 0.0)  # every ray starts before the first vertex
    # finite object: every ray leaves the object point
    fin = osc.paraxial(cooke, 500.0)
    crf = osc.chief_rays(cooke, object_heights_mm=[-60.0], object_distance=500.0)
    bf = aimed_bundle(
        cooke, fin, (crf.y_start[0], crf.z_start[0], crf.M_start[0], crf.N_start[0]), px, py
    )
    (x0, y0, z0), (L, M, N) = bf.origins, bf.directions
    t = (-500.0 - z0) / N
    np.testing.assert_allclose(x0 + t * L, 0.0, atol=1e-9)
    np.testing.assert_allclose(y0 + t * M, -60.0, atol=1e-9)


def test_on_axis_fan_and_spot_agree_with_optiland(cooke):
    pytest.importorskip("optiland")
    sys.path.insert(0, str(ROOT / "benchmarks"))
    import optiland_adapter as ola

    op = ola.build_optic(cooke)
    p = osc.paraxial(cooke)
    px, py = osc.spot_diagram(cooke, 0.0, n=6).px, osc.spot_diagram(cooke, 0.0, n=6).py
    spot = osc.spot_diagram(cooke, 0.0, n=6, from_last_vertex=p.gaussian_image_distance)
    # optiland: same rays (parallel to the axis through the paraxial pupil at radius EPD/2)
    rays = op.trace_generic(Hx=0.0, Hy=0.0, Px=px, Py=py, wavelength=cooke.wavelength / 1000.0)
    ox, oy = np.asarray(rays.x), np.asarray(rays.y)
    # optiland's image surface is at the lens file's image plane: the Gaussian plane here
    np.testing.assert_allclose(spot.x, ox, rtol=0, atol=1e-9)
    np.testing.assert_allclose(spot.y, oy, rtol=0, atol=1e-9)


def test_spot_statistics_follow_their_definitions(cooke):
    s = osc.spot_diagram(cooke, 20.0, pattern="rings", n=6)
    ok = s.status == 0
    cx, cy = s.x[ok].mean(), s.y[ok].mean()
    assert s.centroid_x == pytest.approx(cx) and s.centroid_y == pytest.approx(cy)
    r = np.hypot(s.x[ok] - cx, s.y[ok] - cy)
    assert s.rms_radius == pytest.approx(np.sqrt(np.mean(r**2)))
    assert s.geometric_radius == pytest.approx(r.max())
    assert abs(s.centroid_x) < 1e-12  # meridional symmetry


def test_least_rms_focus_beats_the_gaussian_plane(cooke):
    # defocus scan: the RMS spot radius is a parabola-like function of defocus whose minimum is
    # not above the Gaussian-plane value (here for the undercorrected on-axis bundle)
    dz = np.linspace(-0.3, 0.3, 13)
    rms = [osc.spot_diagram(cooke, 0.0, defocus=v).rms_radius for v in dz]
    assert min(rms) <= rms[6]


def test_bad_requests(cooke):
    with pytest.raises(TraceError, match="axis"):
        osc.ray_fan(cooke, 10.0, axis="z")
    with pytest.raises(TraceError, match="finite object"):
        osc.ray_fan(cooke, object_height_mm=1.0)
    with pytest.raises(TraceError, match="pattern"):
        osc.spot_diagram(cooke, 0.0, pattern="spiral")
    with pytest.raises(TraceError, match="one image plane"):
        osc.spot_diagram(cooke, 0.0, s_prime=[40.0, 41.0])


def test_fan_and_spot_json_carry_the_field_unit_in_a_key(capsys):
    # README "JSON output": lengths and angles carry their unit in the key
    import json

    from orthoscope.cli import main

    assert main(["spot", "cooke-triplet-f4", "--fields", "0,20", "--json"]) == 0
    spots = json.loads(capsys.readouterr().out)["spots"]
    assert [(s["field"], s["angle_deg"], s["field_kind"]) for s in spots] == [
        (0.0, 0.0, "angle"),
        (20.0, 20.0, "angle"),
    ]
    assert main(["fan", "cooke-triplet-f4", "--field", "14", "--json"]) == 0
    fans = json.loads(capsys.readouterr().out)["fans"]
    assert all(f["angle_deg"] == 14.0 and "object_height_mm" not in f for f in fans)
