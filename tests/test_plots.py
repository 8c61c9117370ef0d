"""Plots in the style of Pestrecov 1958 Figs. 2, 3, 4, 6: files are written, and the plotted data
are exactly the input arrays (Table I / II / V data from tests/data, sources in those files)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from distortion.calibration import calibrate
from distortion.curve import make_curve
from distortion.tablefile import read_distortion_table
from orthoscope.plots.distortion import (
    plot_calibrated,
    plot_characteristic,
    plot_planes,
    plot_rotation,
    rotated_characteristic,
)
from orthoscope.plots.save import save_figure
from raytrace.errors import OutputError

DATA = Path(__file__).parent / "data"


@pytest.fixture(scope="module")
def cal():
    c = read_distortion_table(DATA / "pestrecov_table1.csv", 153.706, name="154 mm f/6.3 Topogon")
    return calibrate(c, "two-point", at=(37.5, 45))


def lines(fig):
    return [ln for ax in fig.axes for ln in ax.get_lines() if len(ln.get_xdata()) > 2]


@pytest.mark.parametrize("ext", [".png", ".svg", ".pdf"])
def test_characteristic_plot(tmp_path, cal, ext):
    p = tmp_path / f"fig2{ext}"
    fig = plot_characteristic(cal.curve)
    save_figure(fig, p)
    assert p.stat().st_size > 1000
    a, b = lines(fig)
    np.testing.assert_array_equal(a.get_xdata(), cal.curve.y0p)
    np.testing.assert_array_equal(a.get_ydata(), cal.curve.D0)
    np.testing.assert_array_equal(b.get_ydata(), 100.0 * cal.curve.Dr)
    labels = [fig.axes[0].get_xlabel(), fig.axes[0].get_ylabel(), fig.axes[1].get_ylabel()]
    assert all("(mm)" in s or "(%)" in s for s in labels)
    assert "Topogon" in fig.axes[0].get_title()


def test_calibrated_plot(tmp_path, cal):
    p = tmp_path / "fig3.png"
    fig = plot_calibrated(cal)
    save_figure(fig, p)
    assert p.stat().st_size > 1000
    a, b = lines(fig)
    np.testing.assert_array_equal(a.get_xdata(), cal.ycp)
    np.testing.assert_array_equal(a.get_ydata(), cal.Dc)
    np.testing.assert_array_equal(b.get_ydata(), 100.0 * cal.Drc)


def test_rotation_plot(tmp_path, cal):
    p = tmp_path / "fig4.svg"
    fig = plot_rotation(cal)
    save_figure(fig, p)
    assert p.stat().st_size > 1000
    rot, calc = lines(fig)
    Xp, Dp = rotated_characteristic(cal)
    # Section IV.A: X' = X/cos ρk − Y sin ρk with X = y0', Y = k D0
    rk = math.atan(200.0 * (cal.Kc / 153.706 - 1.0))
    np.testing.assert_allclose(
        Xp, cal.curve.y0p / math.cos(rk) - 200.0 * cal.curve.D0 * math.sin(rk), rtol=1e-15
    )
    np.testing.assert_array_equal(rot.get_xdata(), Xp)
    np.testing.assert_array_equal(rot.get_ydata(), Dp)
    np.testing.assert_array_equal(calc.get_xdata(), cal.ycp)
    np.testing.assert_array_equal(calc.get_ydata(), cal.Dc)
    # the ordinate is that of a rigid rotation by -ρk: with X'' = X cos ρk + Y sin ρk the point
    # keeps its distance from the origin (plot units)
    X, Y = cal.curve.y0p, 200.0 * cal.curve.D0
    Xr = X * math.cos(rk) + Y * math.sin(rk)
    np.testing.assert_allclose(np.hypot(Xr, 200.0 * Dp), np.hypot(X, Y), rtol=1e-13)


def test_planes_plot_table5(tmp_path):
    rows = [ln for ln in (DATA / "pestrecov_table5.csv").read_text().splitlines() if ln[:1] != "#"]
    t = np.loadtxt(rows[1:], delimiter=",")
    # Table IV: p0 = -54.9156 (non-Gaussian), -55.4657 (Gaussian); M0 per plane; y = p0 tan α
    p0 = [-54.9156, -54.9156, -55.4657, -54.9156]
    M0 = [-7.727571, -9.545455, -9.545455, -11.363342]
    sp = [425.0, 525.0, 530.3, 625.0]
    curves = [
        make_curve(
            t[:, 0],
            t[:, j + 1],
            field_kind="nominal-angle",
            x=p0[j] * np.tan(np.radians(t[:, 0])),
            constant=M0[j],
            name="55/525 projector objective",
            plane=f"s' = {sp[j]} mm",
        )
        for j in range(4)
    ]
    p = tmp_path / "fig6.png"
    fig = plot_planes(curves)
    save_figure(fig, p)
    assert p.stat().st_size > 1000
    got = lines(fig)
    assert len(got) == 4
    for ln, j in zip(got, range(4), strict=True):
        np.testing.assert_array_equal(ln.get_xdata(), t[:, 0])
        np.testing.assert_array_equal(ln.get_ydata(), t[:, j + 1])
        assert ln.get_label() == f"s' = {sp[j]} mm"
    fig2 = plot_planes(curves, against="image")
    np.testing.assert_array_equal(lines(fig2)[2].get_xdata(), curves[2].y0p)


def test_bad_format(tmp_path, cal):
    with pytest.raises(OutputError, match="unsupported plot format"):
        save_figure(plot_characteristic(cal.curve), tmp_path / "x.bmpx")
