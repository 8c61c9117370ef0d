"""Fixes of an adversarial review of the 2-D distortion grid, its fits and the certificate.

1. Fits on a grid too small to determine them (a 3x3 grid on a square sensor has two distinct
   nonzero field radii for the four radial unknowns c, K1, K2, K3): marked "not determined" with
   the reason (API, text, JSON), never numbers from a rank-deficient solve. Referee: the
   algebra of the model (a radial profile r (c + a1 r^2 + ...) with k unknowns is sampled at the
   distinct radii only) and, for the rank check, a grid on one line through the axis, where the
   decentering and thin-prism columns are proportional (P1: (3 r^2, 0), S1: (r^2, 0)).
2. A certificate format whose corners do not trace is refused, naming the largest traceable
   field; that field itself then gives a certificate (the message is usable as it stands).
3. Sensor sizes that are not positive, 4. non-integer grid counts, 7. grids over the command
   line's field limit: refused in the API where they enter.
5. Plots: arrows and the arrow key inside the picture; the tabulated points at the format's edge
   inside the certificate's axes.

Numbers of our own (F0 of the Cooke triplet, the 29.6 deg it traces to) are regression pins.
"""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest
from support import run_cli

from distortion.certificate import calibration_certificate
from distortion.errors import DataError
from distortion.grid import (
    decompose_distortion,
    distortion_grid,
    fit_brown_conrady,
    fit_brown_conrady_points,
    radial_by_azimuth,
    solve_linear,
)
from distortion.grid.decompose import UndeterminedFit, distinct_radii
from distortion.grid.field import MAX_GRID_FIELDS
from raytrace.errors import TraceError
from raytrace.files.library import load_lens


@pytest.fixture(scope="module")
def small(cooke):
    return distortion_grid(cooke, grid=(3, 3), sensor="24x24")


# ------------------------------------------------------------------ 1. undetermined fits
def test_distinct_radii_of_small_grids():
    def grid(nx, ny, w=24.0, h=24.0):
        x, y = np.meshgrid(np.linspace(-w / 2, w / 2, nx), np.linspace(-h / 2, h / 2, ny))
        return np.column_stack([x.ravel(), y.ravel()])

    assert distinct_radii(grid(3, 3)) == 2  # edge centres, corners
    assert distinct_radii(grid(4, 4)) == 3
    assert distinct_radii(grid(3, 3, 24.0, 16.0)) == 3  # 8, 12, 14.4
    assert distinct_radii(grid(5, 5)) == 5  # i^2 + j^2 = 1, 2, 4, 5, 8


def test_3x3_decomposition_is_not_determined(small):
    d = decompose_distortion(small)
    assert not d.determined
    assert "2 distinct nonzero field radii" in d.not_determined
    assert "c, K1, K2, K3" in d.not_determined and "5x5" in d.not_determined
    # no made-up numbers: the review saw c = 42.07 mm +- 5e-15 (F0 = 50.0003)
    assert all(math.isnan(v) for v in d.values.values())
    assert d.std_errors == {} and d.free == ()
    assert all(np.isnan(c).all() for c in d.components.values())
    assert "not determined" in repr(d)
    with pytest.raises(UndeterminedFit, match="2 distinct nonzero field radii"):
        t = np.stack([small.tx.ravel(), small.ty.ravel()], axis=1)
        solve_linear(t, small.actual[0].reshape(-1, 2))


def test_3x3_brown_conrady_is_not_determined(small):
    b = fit_brown_conrady(small)
    assert not b.determined
    assert "2 distinct nonzero field radii" in b.not_determined
    # the review saw c = 66.24 mm and an OpenCV refit k1 = -6.3, k2 = 33.4
    assert b.opencv is None and b.opencv_coefficients == {} and b.camera is None
    assert all(math.isnan(v) for v in b.values.values()) and b.std_errors == {}
    assert "not determined" in repr(b)


def test_rectangular_3x3_and_4x4_are_not_determined(cooke):
    for kw, n in ((dict(grid=(3, 3), sensor="24x16"), 3), (dict(grid=(4, 4)), 3)):
        g = distortion_grid(cooke, **kw)
        for fit in (decompose_distortion(g), fit_brown_conrady(g, opencv=False)):
            assert not fit.determined
            assert f"{n} distinct nonzero field radii" in fit.not_determined


def test_5x5_is_determined_with_meaningful_errors(cooke):
    g = distortion_grid(cooke, grid=(5, 5), sensor="24x24")
    F0 = float(g.camera_constant[0])  # Pestrecov's constant: regression pin 50.000287 mm
    assert F0 == pytest.approx(50.000287, abs=1e-6)
    d = decompose_distortion(g)
    b = fit_brown_conrady(g, opencv=False)
    for fit in (d, b):
        assert fit.determined and fit.not_determined == ""
        assert abs(fit.values["c"] - F0) < 1e-3  # the distortion is ~80 um at the corners
        assert 0.0 < fit.std_errors["c"] < 1e-3


def test_rank_deficient_design_names_the_parameters():
    # fields on one line through the axis: many radii, but P1 ~ S1 and P2 ~ S2 there
    s = np.linspace(0.0, 0.4, 9)
    t = np.column_stack([s, np.zeros_like(s)])
    img = 50.0 * t * (1 + 0.01 * s[:, None] ** 2)
    with pytest.raises(UndeterminedFit, match=r"do not separate .*P1.*S1") as e:
        solve_linear(t, img)
    assert "rank" in str(e.value)
    b = fit_brown_conrady_points(t, img, opencv=False)
    assert not b.determined and "do not separate" in b.not_determined
    # radial only (no P, S): determined on the same points
    assert solve_linear(t, img, asymmetric=False).values["c"] == pytest.approx(50.0, abs=1e-9)


def test_cli_prints_the_grid_and_says_why_the_fits_are_missing():
    argv = ["distortion", "cooke-triplet-f4", "--grid", "3x3", "--sensor", "24x24"]
    rc, out, err = run_cli(argv)
    assert rc == 0, err
    assert "max |D| = 81.726 um" in out  # the grid itself (regression pin)
    assert out.count("not determined - the traced fields lie at 2 distinct") == 2
    assert "42.07" not in out and "66.24" not in out and "std error" not in out
    rc, out, err = run_cli([*argv, "--json"])
    assert rc == 0, err
    plane = json.loads(out)["distortion_grid"]["planes"][0]
    for fit in (plane["decomposition"][0], plane["brown_conrady"][0]):
        assert fit["determined"] is False
        assert "2 distinct nonzero field radii" in fit["not_determined"]
        assert all(v is None for v in fit["values"].values())
        assert fit["std_errors"] == {}
    assert "opencv" not in plane["brown_conrady"][0]


def test_undetermined_decomposition_has_no_parts_to_plot(small):
    from orthoscope.plots.common import offscreen_figures
    from orthoscope.plots.grid import plot_distortion_vectors

    with offscreen_figures(), pytest.raises(DataError, match="not determined"):
        plot_distortion_vectors(
            small, decomposition=decompose_distortion(small), component="radial"
        )


# ------------------------------------------------------------------ 2. certificate format
@pytest.mark.parametrize("kw", [dict(max_field_deg=80.0), dict(sensor="240x160")])
def test_certificate_refuses_a_format_beyond_the_traced_field(cooke, kw):
    with pytest.raises(DataError, match=r"trace only to 29\.\d deg") as e:
        calibration_certificate(cooke, **kw)
    lim = float(re.search(r"within (\d+\.\d) deg", str(e.value)).group(1))
    assert 29.0 <= lim < 30.0  # regression pin: the Cooke triplet traces to 29.6 deg
    # the field the message gives is a certificate; a little beyond it is refused
    c = calibration_certificate(cooke, max_field_deg=lim)
    assert np.isfinite(c.dense_mean_radial_um).all()
    assert not any("could not be traced" in n for n in c.notes)
    with pytest.raises(DataError, match="trace only to"):
        calibration_certificate(cooke, max_field_deg=lim + 0.2)


def test_report_cli_refuses_with_one_line():
    rc, out, err = run_cli(["report", "cooke-triplet-f4", "--max-field", "80"])
    assert rc == 2 and out == ""
    assert len(err.strip().splitlines()) == 1
    assert "reaches 80 deg" in err and "give a format within 29." in err


# ------------------------------------------------------------------ 3, 4, 7. inputs
@pytest.mark.parametrize(
    "sensor,label",
    [("-24x16", "-24x16"), ("0x16", "0x16"), ("24x-16", "24x-16"), ((24.0, -16.0), "24x-16")],
)
def test_sensor_must_be_positive(cooke, sensor, label):
    msg = f"sensor {label}: width and height must be positive (mm)"
    with pytest.raises(DataError, match=re.escape(msg)):
        distortion_grid(cooke, grid=3, sensor=sensor)
    with pytest.raises(DataError, match=re.escape(msg)):
        calibration_certificate(cooke, sensor=sensor)


def test_sensor_that_is_not_a_size(cooke):
    for bad in ((float("nan"), 16.0), (float("inf"), 16.0)):
        with pytest.raises(DataError, match="must be positive"):
            distortion_grid(cooke, grid=3, sensor=bad)
    for bad in (True, 24.0, (24.0,)):
        with pytest.raises(DataError, match="sensor"):
            distortion_grid(cooke, grid=3, sensor=bad)


@pytest.mark.parametrize("argv", [["distortion", "cooke-triplet-f4", "--grid", "5x5"],
                                  ["report", "cooke-triplet-f4"]])  # fmt: skip
@pytest.mark.parametrize("size", ["-24x16", "0x16"])
def test_cli_sensor_must_be_positive(argv, size):
    rc, out, err = run_cli([*argv, "--sensor", size])
    assert rc == 2 and out == ""
    assert err.strip().endswith(f"sensor {size}: width and height must be positive (mm)")
    assert len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("grid", [(2.5, 3), (3, 2.5), (3.0, 3), (True, 3), True, "5x5", (3,)])
def test_grid_counts_are_whole_numbers(cooke, grid):
    with pytest.raises(DataError, match="whole numbers"):
        distortion_grid(cooke, grid=grid)


def test_grid_counts_accept_numpy_integers(cooke):
    g = distortion_grid(cooke, grid=(np.int64(3), np.int32(2)))
    assert g.shape == (2, 3)


def test_large_grids_need_allow_large(cooke):
    with pytest.raises(DataError, match=r"25000000 fields, more than 100000.*allow_large=True"):
        distortion_grid(cooke, grid=(5000, 5000))
    f = np.linspace(-10.0, 10.0, 400)
    with pytest.raises(DataError, match="allow_large=True"):
        distortion_grid(cooke, f, f)
    with pytest.raises(DataError, match="allow_large=True"):
        radial_by_azimuth(cooke, np.arange(0.0, 360.0, 0.1), np.linspace(0.0, 20.0, 400))
    assert MAX_GRID_FIELDS == 100_000  # the command line's MAX_FIELDS
    g = distortion_grid(cooke, grid=(2, 2), allow_large=True)
    assert g.shape == (2, 2)


# ------------------------------------------------------------------ 5. plots
def test_vector_arrows_and_key_stay_in_the_picture(cooke):
    from matplotlib.quiver import Quiver, QuiverKey

    from orthoscope.plots.common import offscreen_figures
    from orthoscope.plots.grid import plot_distortion_vectors

    g = distortion_grid(cooke, grid=(5, 5))
    with offscreen_figures():
        fig = plot_distortion_vectors(g)
        fig.canvas.draw()
        ax = fig.axes[0]
        q = next(c for c in ax.get_children() if isinstance(c, Quiver))
        tips = q.get_offsets() + np.column_stack([q.U, q.V]) / q.scale
        (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
        assert (tips[:, 0] > x0).all() and (tips[:, 0] < x1).all()
        assert (tips[:, 1] > y0).all() and (tips[:, 1] < y1).all()
        key = next(c for c in ax.get_children() if isinstance(c, QuiverKey))
        at = ax.transAxes.transform((key.X, key.Y))
        length = ax.transData.transform((key.U / q.scale, 0.0)) - ax.transData.transform((0, 0))
        # matplotlib pins the key arrow by its label side: "W" at the tail, "E" at the tip
        start = {"W": 0.0, "E": -1.0, "N": -0.5, "S": -0.5}[key.labelpos]
        tail = at + start * length
        tip = tail + length
        w, h = fig.canvas.get_width_height()
        assert 0 < tail[0] < tip[0] < w and 0 < tip[1] < h


def test_certificate_edge_points_are_inside_the_axes():
    from orthoscope.plots.certificate import plot_certificate
    from orthoscope.plots.common import offscreen_figures

    cert = calibration_certificate(load_lens("topogon-like-pestrecov"), date="2026-01-31")
    edge = float(cert.fields_deg[-1])
    assert edge == pytest.approx(45.0)
    with offscreen_figures():
        fig = plot_certificate(cert)
    for ax in fig.axes:
        assert ax.get_xlim()[1] >= edge * 1.03  # a marker at the edge is drawn whole


def test_an_output_under_a_file_says_it_is_a_file(tmp_path):
    # 'report -o c.toml/x.pdf' with c.toml a file said "the folder ... does not exist"
    (tmp_path / "c.toml").write_text("")
    rc, out, err = run_cli(["report", "cooke-triplet-f4", "-o", str(tmp_path / "c.toml" / "x.pdf")])
    assert (rc, out) == (2, "") and f"{tmp_path / 'c.toml'} is a file, not a folder" in err


# ------------------------------------------- radial_by_azimuth / distortion_grid: empty, range
@pytest.mark.parametrize(
    "az", [[0, math.nan], [math.inf], [0, -math.inf], [1j], [0, True], np.array([0, 45j])]
)
def test_azimuths_that_are_no_angles_are_named(cooke, az):
    # [0, nan] said "fields must be finite numbers" (the wrong keyword); [1j] a TypeError;
    # [0, True] was traced at 0 and 1 degree, np.array([0, 45j]) at 0 and 0 (the imaginary
    # part dropped with a ComplexWarning)
    with pytest.raises(TraceError) as e:
        radial_by_azimuth(cooke, az, fields_deg=[0, 10])
    assert str(e.value).startswith("azimuths_deg must be finite angles in degrees"), str(e.value)


@pytest.mark.parametrize(
    ("call", "says"),
    [
        (lambda c: radial_by_azimuth(c, fields_deg=[]), "no fields given: fields_deg is empty"),
        (
            lambda c: radial_by_azimuth(c, object_radii_mm=[], object_distance=1000),
            "no fields given: object_radii_mm is empty",
        ),
        (
            lambda c: radial_by_azimuth(c, azimuths_deg=[], fields_deg=[0, 10]),
            "no azimuths given: azimuths_deg is empty",
        ),
        (
            lambda c: distortion_grid(c, fields_x_deg=[], fields_y_deg=[0, 5]),
            "no fields given: fields_x_deg is empty",
        ),
        (
            lambda c: distortion_grid(c, fields_x_deg=[0, 5], fields_y_deg=[]),
            "no fields given: fields_y_deg is empty",
        ),
        (
            lambda c: distortion_grid(c, object_x_mm=[], object_y_mm=[0], object_distance=1000),
            "no fields given: object_x_mm is empty",
        ),
    ],
)
def test_empty_fields_and_azimuths_are_refused(cooke, call, says):
    # were accepted: the radial result's repr raised "zero-size array ...", the grid said
    # "max |D| = nan mm"; characteristic_distortion refuses "no fields given"
    with pytest.raises(TraceError) as e:
        call(cooke)
    assert str(e.value) == says


@pytest.mark.parametrize("fields", [[0, 90], [0, 100], [0, 1e300], [0, 179]])
def test_radial_fields_at_or_beyond_90_degrees_are_refused(cooke, fields):
    # 100 and 1e300 were traced (tan of the total angle wraps) with 8 failed status flags
    with pytest.raises(TraceError, match="field angles must lie strictly between -90 and 90"):
        radial_by_azimuth(cooke, fields_deg=fields)
