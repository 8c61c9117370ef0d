"""Why distortion varies across image planes (distortion.telecentricity,
raytrace.paraxial.distortion_slope): chief-ray angle and telecentricity, the exact slope ∂D0/∂s',
the real pupils and the viewpoint offset — checked against analytic cases (a Cartesian
collimating surface, a lens symmetric about its stop, a ball lens with a central stop),
Pestrecov's Tables III-IV, and the linearity of D0 between two planes (Section V)."""

from __future__ import annotations

import json

import numpy as np
import pytest

import orthoscope as osc
from distortion.telecentricity import pupil_analysis
from raytrace import AIR, Aperture, Field, Lens, Surface, fixed_index
from raytrace.paraxial import orthoscopy_constant_slope


def _hyperbolic_telecentric(n: float = 1.5, R: float = 20.0, k: float | None = None) -> Lens:
    # stop at the front focal point of a plano-convex lens whose first surface is the Cartesian
    # surface imaging that point to infinity inside the glass: a hyperboloid of eccentricity n
    # (conic k = −n²; Descartes' ovals, e.g. Hecht, Optics, §5.2). Every chief ray (through the
    # stop centre = the focus) runs parallel to the axis in the glass and leaves the plane back
    # surface undeviated: CRA = 0 at every field, exactly. The focus is R/(n − 1) before the
    # vertex (the surface's front focal length).
    k = -n * n if k is None else k
    s = (
        Surface(0.0, R / (n - 1.0), AIR, stop=True),
        # 10 mm thick: the hyperboloid's sag at the 20-degree chief ray (h = 16.3 mm) is 5.6 mm,
        # so a thinner lens would have a negative edge there (the ray "backward", status 5)
        Surface(1.0 / R, 10.0, fixed_index(n), conic=k),
        Surface(0.0, 30.0, AIR),
    )
    return Lens("hyperbolic, stop at F", s, Aperture("fnumber", 8.0), Field("angle", 20.0))


def test_image_side_telecentric_lens_has_zero_chief_ray_angle():
    lens = _hyperbolic_telecentric()
    p = osc.paraxial(lens)
    assert p.z_F == pytest.approx(0.0, abs=1e-12)  # the stop is at the front focal point
    pa = pupil_analysis(lens, [0.0, 5.0, 10.0, 15.0, 20.0])
    assert np.all(pa.status == 0)
    assert pa.max_abs_cra_deg < 5e-14  # zero to round-off (measured 4.8e-15 deg)
    assert np.max(np.abs(pa.slope)) < 1e-15  # and so is dD0/ds' (1/m_e = 0)
    off = pa.x != 0
    assert np.all(np.abs(pa.exit_pupil_z[off]) > 1e12)  # the exit pupil is at infinity
    # the same lens with a spherical first surface is telecentric only paraxially: the real
    # chief rays leave at several degrees (the test could fail)
    sph = pupil_analysis(_hyperbolic_telecentric(k=0.0), [5.0, 10.0])
    assert np.all(np.abs(sph.cra_deg) > 0.1)


def test_cooke_triplet_with_a_stop_at_its_front_focal_point():
    # the brief's construction: the Cooke triplet with its stop moved to the front focal plane.
    # Paraxially telecentric (E0' at infinity); the real CRA is the pupil's spherical aberration,
    # of third order in the field with a fifth-order correction: CRA(2a)/CRA(a) = 8 + c a²
    cooke = osc.load_lens("cooke-triplet-f4")
    p = osc.paraxial(cooke)
    ffl = -p.z_F  # distance of F before the first vertex (> 0)
    surfaces = (Surface(0.0, ffl, AIR, stop=True),) + tuple(
        Surface(s.curvature, s.thickness, s.material, conic=s.conic) for s in cooke.surfaces
    )
    lens = Lens("Cooke, stop at F", surfaces, cooke.aperture, cooke.field)
    pt = osc.paraxial(lens)
    assert abs(pt.z_E0p) > 1e9  # paraxial exit pupil at infinity
    pa = pupil_analysis(lens, [0.125, 0.25, 0.5, 1.0, 2.0])
    ratio = pa.cra_deg[1:] / pa.cra_deg[:-1]
    assert ratio[0] == pytest.approx(8.0, rel=2e-3)  # measured 1.06e-3 (the c a² term)
    # measured: within 4.2e-4 of 4 (the next order); bound ~10x that
    np.testing.assert_allclose((ratio[1:] - 8.0) / (ratio[:-1] - 8.0), 4.0, rtol=5e-3)
    np.testing.assert_allclose(pa.cra_paraxial_deg, 0.0, atol=1e-12)


@pytest.mark.parametrize("fields", [[0.0, 10.0, 15.0, 20.0, 25.0, 30.0, 35.0, 40.0, 45.0]])
def test_slope_reproduces_d0_between_the_section_v_planes(fields):
    # Pestrecov Section V: the Twinplex-like lens at the projection setting s = −55.0009 mm, image
    # planes s' = 425 and 625 mm (Table IV). D0 is affine in s', so (D0(625) − D0(425))/200 is
    # the slope at every field, to round-off (the two sides come from different code paths:
    # Eq. 8 in each plane vs. tan α' − x dM0/ds')
    lens = osc.load_lens("twinplex-like-55-525")
    d = osc.characteristic_distortion(lens, fields, object_s=-55.0009, s_prime=[425.0, 625.0])
    pa = pupil_analysis(lens, fields, object_s=-55.0009)
    diff = (d.D0[1] - d.D0[0]) / 200.0
    tol = 16 * np.spacing(np.nanmax(np.abs(d.yp))) / 200.0  # a few ulp of y' ~ 500 mm
    np.testing.assert_allclose(pa.slope, diff, rtol=0, atol=tol)
    assert np.max(np.abs(pa.slope)) > 1e-4  # the lens does change its distortion with s'
    # a third plane lies on the same straight line
    d3 = osc.characteristic_distortion(lens, fields, object_s=-55.0009, s_prime=525.0)
    np.testing.assert_allclose(d3.D0[0], d.D0[0] + 100.0 * pa.slope, rtol=0, atol=64 * tol)


def test_slope_at_infinity_matches_two_planes():
    lens = osc.load_lens("super-angulon-de975637")
    f = np.linspace(0.0, 50.0, 11)
    d = osc.characteristic_distortion(lens, f, defocus=[-0.5, 0.7])
    pa = pupil_analysis(lens, f)
    np.testing.assert_allclose(pa.slope, (d.D0[1] - d.D0[0]) / 1.2, rtol=0, atol=1e-13)


def test_constant_slope_against_pestrecov_tables_iii_and_iv():
    # Table IV: M0 = −7.727571 at s' = 425, −11.363342 at s' = 625 (p0 = −54.9156 mm);
    # Table III: m_e = 1.001700. dM0/ds' = 1/(m_e p0). Printed rounding: the two M0 (±5e-7
    # each) allow 5e-9 in the difference quotient, p0 (±5e-5 mm) and m_e (±5e-7) another
    # 0.0182 (9.1e-7 + 5e-7) = 2.6e-8; measured 2.8e-9
    table = (-11.363342 - -7.727571) / 200.0
    assert orthoscopy_constant_slope(1.001700, -54.9156) == pytest.approx(table, abs=2e-8)
    assert orthoscopy_constant_slope(1.0017) == pytest.approx(1 / 1.0017, rel=1e-15)


def _mirror(front: list[tuple[float, object, float]], image: float = 40.0) -> Lens:
    """A lens symmetric about its stop: the front group ``(radius, medium after, thickness
    after)`` (the last thickness reaches the stop), the stop, then its mirror image (radii change
    sign; media and thicknesses in reverse order)."""
    s = [Surface(1.0 / r, t, m) for r, m, t in front]
    s.append(Surface(0.0, front[-1][2], front[-1][1], stop=True))
    for i in range(len(front) - 1, -1, -1):
        after = front[i - 1][1] if i > 0 else AIR
        t = front[i - 1][2] if i > 0 else image
        s.append(Surface(-1.0 / front[i][0], t, after))
    return Lens("symmetric", tuple(s), Aperture("fnumber", 6.0), Field("angle", 40.0))


def test_lens_symmetric_about_its_stop_has_cra_equal_to_the_field_and_no_slope():
    # symmetry: the chief ray through the stop centre leaves at the angle it came in (α' = α)
    # and m_e = 1, so dD0/ds' = tan α − tan α = 0; the real entrance and exit pupils move by
    # mirror amounts
    g = fixed_index(1.62)
    lens = _mirror([(18.0, g, 4.0), (40.0, AIR, 2.0), (-60.0, fixed_index(1.58), 1.0),
                    (25.0, AIR, 3.0)])  # fmt: skip
    f = np.array([0.0, 10.0, 20.0, 30.0])
    pa = pupil_analysis(lens, f)
    assert np.all(pa.status == 0)
    # to the aim tolerance: the chief ray meets the stop within 1e-12 mm (docs/design.md)
    # (measured: CRA − α within 5.4e-13 deg, slope 1.1e-14; bounds ~10-20x that)
    np.testing.assert_allclose(pa.cra_deg, f, rtol=0, atol=1e-11)
    np.testing.assert_allclose(pa.slope, 0.0, atol=2e-13)
    z_stop = float(lens.vertex_z[lens.stop_index])
    np.testing.assert_allclose(  # measured 2.2e-12 mm
        pa.entrance_pupil_z - z_stop, -(pa.exit_pupil_z - z_stop), rtol=0, atol=3e-11
    )
    assert np.max(np.abs(pa.entrance_pupil_shift)) > 1e-3  # pupils do move with field here


def test_ball_lens_with_central_stop_is_a_single_viewpoint_camera():
    # every chief ray passes through the centre: the entrance pupil does not move, no offset
    n, R = 1.6, 10.0
    g = fixed_index(n)
    s = (Surface(1.0 / R, R, g), Surface(0.0, R, g, stop=True), Surface(-1.0 / R, 20.0, AIR))
    lens = Lens("ball", s, Aperture("fnumber", 8.0), Field("angle", 60.0))
    pa = pupil_analysis(lens, [0.0, 20.0, 40.0, 60.0])
    np.testing.assert_allclose(pa.entrance_pupil_z, R, atol=1e-12)
    np.testing.assert_allclose(pa.viewpoint_offset, 0.0, atol=1e-12)
    np.testing.assert_allclose(pa.cra_deg, [0.0, 20.0, 40.0, 60.0], atol=1e-12)


def test_viewpoint_quantities_follow_their_geometric_definitions():
    lens = osc.load_lens("super-angulon-de975637")
    f = np.linspace(0.0, 50.0, 6)
    pa = pupil_analysis(lens, f)
    cr = osc.chief_rays(lens, f)
    z_E0 = pa.paraxial.z_E0
    # distance from E0 = (0, z_E0) to the line through the start point along (M, N): |cross|
    dist = np.abs(cr.y_start * cr.N_start - (cr.z_start - z_E0) * cr.M_start)
    np.testing.assert_allclose(np.abs(pa.viewpoint_offset), dist, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(pa.theta_object_deg, f, atol=1e-12)  # θ = α at infinity
    # the chief ray's height in the E0 plane by transfer of the object-space ray
    h = cr.y_start + (z_E0 - cr.z_start) * cr.M_start / cr.N_start
    np.testing.assert_allclose(pa.height_at_E0, h, rtol=0, atol=1e-13)
    # the real exit pupil: the final segment's height is zero there
    off = f > 0
    y_at_x = cr.y_last + (pa.exit_pupil_z - cr.z_last) * cr.M_last / cr.N_last
    np.testing.assert_allclose(y_at_x[off], 0.0, atol=1e-12)


def test_cli_pupils_json_and_plot(tmp_path, capsys):
    from orthoscope.cli import main

    assert main(["pupils", "cooke-triplet-f4", "--fields", "0,10,20", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)["pupils"]
    pa = pupil_analysis(osc.load_lens("cooke-triplet-f4"), [0.0, 10.0, 20.0])
    assert d["cra_deg"] == pytest.approx(pa.cra_deg.tolist(), abs=0)
    assert d["distortion_slope"] == pytest.approx(pa.slope.tolist(), abs=0)
    out = tmp_path / "pupils.png"
    assert main(["pupils", "cooke-triplet-f4", "--plot", str(out)]) == 0
    assert out.stat().st_size > 10_000
    txt = capsys.readouterr().out
    assert "CRA (deg)" in txt and "viewpoint offset" in txt


def test_plots_keep_the_ax_convention():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from orthoscope.plots.telecentricity import (
        plot_chief_ray_angle,
        plot_distortion_slope,
        plot_entrance_pupil,
        plot_pupils,
    )

    pa = pupil_analysis(osc.load_lens("cooke-triplet-f4"))
    fig, axs = plt.subplots(1, 3)
    for fn, ax in zip(
        (plot_chief_ray_angle, plot_distortion_slope, plot_entrance_pupil), axs, strict=True
    ):
        assert fn(pa, ax=ax) is fig
    assert len(plot_pupils(pa).axes) >= 3
    plt.close("all")
