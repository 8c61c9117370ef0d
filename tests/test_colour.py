"""Colour (distortion/colour.py, orthoscope colour, orthoscope distortion --wavelengths): the
focal-shift curve, lateral colour and distortion per wavelength, their reports and plots.

Reference numbers: closed-form paraxial optics of a thick N-BK7 singlet with the SCHOTT N-BK7
data-sheet Sellmeier coefficients (SCHOTT optical glass catalog as packaged in opticalglass 1.1.1,
SCHOTT.xls); paraxial limits of real rays; the Thorlabs AC254-100-A achromat file
(tests/data/corpus/raytracing, raytracing 1.4.7, see tests/data/corpus/SOURCES.md).
"""

from __future__ import annotations

import json
import math
import warnings
from pathlib import Path

import numpy as np
import pytest

import orthoscope as osc
from distortion.characteristic import characteristic_distortion
from distortion.colour import FocalShift, LateralColour, default_pair, focal_shift, lateral_colour
from orthoscope.cli import main
from raytrace.glass import lookup_glass
from raytrace.lens import Aperture, Field, Lens, Surface
from raytrace.materials import LAMBDA_C, LAMBDA_D, LAMBDA_F
from raytrace.paraxial import paraxial, paraxial_chief_heights
from raytrace.trace import trace_rays

AC254 = Path(__file__).parent / "data" / "corpus" / "raytracing" / "AC254-100-A-Zemax(ZMX).zmx"
NBK7_B = (1.03961212, 0.231792344, 1.01046945)  # SCHOTT N-BK7 data sheet
NBK7_C = (0.00600069867, 0.0200179144, 103.560653)


def nbk7(nm: float) -> float:
    l2 = (nm / 1000.0) ** 2
    return math.sqrt(1.0 + sum(b * l2 / (l2 - c) for b, c in zip(NBK7_B, NBK7_C, strict=True)))


def singlet(epd: float = 10.0) -> Lens:
    glass = lookup_glass("N-BK7", ["Schott"]).material
    return Lens(
        "N-BK7 singlet",
        (Surface(0.02, 5.0, glass, stop=True), Surface(-0.02, 45.0)),
        Aperture("epd", epd),
        Field("angle", 5.0),
    )


def achromat() -> Lens:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return osc.load_lens(AC254)


def run(capsys, *argv):
    rc = main(list(argv))
    out, err = capsys.readouterr()
    return rc, out, err


# ----------------------------------------------------------------------------- focal shift
def test_paraxial_focal_shift_is_the_thick_lens_back_focus():
    lens = singlet()
    wl = np.array([404.6561, 486.1327, 587.5618, 656.2725, 852.11])
    fs = focal_shift(lens, wl)
    c1, c2, t = 0.02, -0.02, 5.0
    for w, b, e in zip(wl, fs.from_last_vertex, fs.efl, strict=True):
        n = nbk7(w)
        f = 1.0 / ((n - 1) * (c1 - c2 + (n - 1) * t * c1 * c2 / n))
        assert e == pytest.approx(f, rel=1e-12)
        assert b == pytest.approx(f * (1.0 - (n - 1) * t * c1 / n), rel=1e-12)
    assert fs.shift[2] == 0.0 and fs.reference_wavelength == LAMBDA_D
    assert np.all(np.diff(fs.from_last_vertex) > 0)  # a singlet: monotonic (normal dispersion)


def test_best_focus_tends_to_paraxial_for_a_slow_lens_and_is_the_rms_minimum():
    slow = singlet(epd=0.005)  # f/~10000: spherical aberration (∝ aperture²) negligible
    par = focal_shift(slow, [LAMBDA_F, LAMBDA_C])
    best = focal_shift(slow, [LAMBDA_F, LAMBDA_C], kind="best-focus")
    np.testing.assert_allclose(best.from_last_vertex, par.from_last_vertex, rtol=0, atol=1e-6)
    # fast lens: the closed-form plane is the minimum of the RMS radius over a scan of planes
    lens = singlet()
    fs = focal_shift(lens, [LAMBDA_D], kind="best-focus", rings=6)
    from distortion.colour import _pupil_rays

    p = paraxial(lens)
    x, y, z, L, M, N = _pupil_rays(p, 6)
    rb = trace_rays(lens, (x, y, z), (L, M, N), clip=False)
    z_best = p.z_last + fs.from_last_vertex[0]

    def rms(zp):
        px, py = rb.at_plane(zp)
        return math.sqrt(np.mean((px - px.mean()) ** 2 + (py - py.mean()) ** 2))

    assert rms(z_best) == pytest.approx(fs.rms_radius[0], rel=1e-12)
    for dz in (-1e-3, 1e-3, -1e-2, 1e-2):
        assert rms(z_best + dz) > rms(z_best)


def test_achromat_focal_shift_turns_inside_the_visible():
    # an achromat brings two colours to one focus: its focal-shift curve has a minimum inside
    # the band (secondary spectrum), unlike the singlet's monotonic curve
    fs = focal_shift(achromat(), np.linspace(420.0, 700.0, 57))
    i = int(np.argmin(fs.shift))
    assert 450.0 < fs.wavelengths[i] < 600.0
    assert isinstance(fs, FocalShift) and "paraxial" in repr(fs)


# ----------------------------------------------------------------------------- lateral colour
def test_lateral_colour_near_the_axis_is_the_paraxial_chromatic_magnification():
    lens = osc.load_lens("cooke-triplet-f4")
    lc = lateral_colour(lens, [0.0, 0.01])
    assert lc.wavelengths == (LAMBDA_F, LAMBDA_C) == default_pair(lens)
    z = paraxial(lens).z_gauss
    yF, yC, yd = (
        paraxial_chief_heights(paraxial(lens, wavelength=w), [0.01], "angle", z)[0]
        for w in (LAMBDA_F, LAMBDA_C, LAMBDA_D)
    )
    assert lc.linear[0, 1] == pytest.approx(yF - yC, rel=1e-5)
    assert lc.relative[0, 1] == pytest.approx((yF - yC) / yd, rel=1e-5)
    assert lc.linear[0, 0] == 0.0 and lc.relative[0, 0] == 0.0
    # linear = the chief-ray height difference in the same plane
    np.testing.assert_array_equal(lc.linear, lc.heights[0] - lc.heights[1])


def test_lateral_colour_defaults_to_the_lens_wavelengths_and_any_plane():
    lens = achromat()
    lc = lateral_colour(lens, [0.0, 1.0, 2.0], defocus=[-0.5, 0.0, 0.5])
    assert lc.wavelengths == (486.1, 656.3)  # shortest and longest of the file's
    assert lc.linear.shape == (3, 3) and isinstance(lc, LateralColour)
    # the planes are the reference wavelength's: defocus measured from its Gaussian plane
    np.testing.assert_allclose(lc.defocus, [-0.5, 0.0, 0.5], atol=1e-12)


# ----------------------------------------------------------------------------- reports, plots
def test_reports_state_the_scale():
    from orthoscope.report.colour import (
        chromatic_distortion_to_dict,
        format_chromatic_distortion,
        format_focal_shift,
        format_lateral_colour,
    )
    from orthoscope.report.jsonout import dumps

    lens = osc.load_lens("cooke-triplet-f4")
    ref = characteristic_distortion(lens, [0, 10, 20], wavelengths="F,d,C")
    own = characteristic_distortion(lens, [0, 10, 20], wavelengths="F,d,C", scale="own")
    assert "every wavelength against the reference wavelength's F0 (587.562 nm)" in (
        format_chromatic_distortion(ref)
    )
    assert "each wavelength against its own F0" in format_chromatic_distortion(own)
    d = json.loads(dumps(chromatic_distortion_to_dict(own)))
    assert d["scale"] == "own" and len(d["planes"][0]["D0_mm"]) == 3
    assert "y'(486.133 nm) − y'(656.273 nm)" in format_lateral_colour(lateral_colour(lens))
    assert "shift (um)" in format_focal_shift(focal_shift(lens, "F,d,C"))


def test_plots_return_figures():
    from orthoscope.plots.colour import (
        plot_colour_summary,
        plot_distortion_by_wavelength,
        plot_focal_shift,
        plot_lateral_colour,
    )
    from orthoscope.plots.common import offscreen_figures

    lens = osc.load_lens("cooke-triplet-f4")
    fs, lc = focal_shift(lens), lateral_colour(lens)
    cd = characteristic_distortion(lens, wavelengths="F,d,C")
    with offscreen_figures():
        for fig in (
            plot_focal_shift(fs),
            plot_lateral_colour(lc, relative=True),
            plot_distortion_by_wavelength(cd),
            plot_colour_summary(fs, lc, cd),
        ):
            assert fig.axes and fig.axes[0].lines
        fig = plot_focal_shift(fs)
        fig2 = plot_lateral_colour(lc, ax=fig.axes[0])
        assert fig2 is fig


# ----------------------------------------------------------------------------- command line
def test_cli_colour_text_json_and_plot(capsys, tmp_path):
    rc, out, _ = run(capsys, "colour", "cooke-triplet-f4", "--fields", "0,10,20")
    assert rc == 0
    assert "longitudinal colour" in out and "lateral colour" in out
    assert "distortion per wavelength" in out and "scale: every wavelength" in out
    rc, out, _ = run(
        capsys, "colour", str(AC254), "--fields", "0,1", "--json", "--scale", "own", "--focus",
        "best-focus",
    )  # fmt: skip
    d = json.loads(out)
    assert d["distortion"]["scale"] == "own"
    assert d["focal_shift"]["wavelength_nm"] == [486.1, 587.6, 656.3]
    png = tmp_path / "c.png"
    rc, _, _ = run(capsys, "colour", "cooke-triplet-f4", "--plot", str(png))
    assert rc == 0 and png.stat().st_size > 1000


def test_cli_wavelengths_refuses_micrometres(capsys):
    rc, _, err = run(capsys, "colour", "cooke-triplet-f4", "--wavelengths", "0.4861,0.6563")
    assert rc == 2 and "looks like micrometres: write 0.4861um or 486.1nm" in err
    rc, _, err = run(capsys, "distortion", "cooke-triplet-f4", "--wavelengths", "0.5876")
    assert rc == 2 and "looks like micrometres" in err


def test_cli_distortion_wavelengths(capsys):
    rc, out, _ = run(
        capsys, "distortion", "cooke-triplet-f4", "--fields", "0,10", "--wavelengths", "F,d,C"
    )
    assert rc == 0 and "D0 486.133 (mm)" in out and "reference wavelength's F0" in out
    rc, _, err = run(
        capsys, "distortion", "cooke-triplet-f4", "--wavelengths", "F,C", "--calibrate", "minimax"
    )
    assert rc == 2 and "does not combine with --calibrate" in err
