"""Plots: Pestrecov 1958 Figs. 2, 3, 4, 6, Fraser & Shortis 1992 Figs. 2/5 style, the lens layout.

What is checked, and against what:

* the markers are exactly the input data (Pestrecov Tables I, II, V from tests/data, sources in
  those files); the line through a table is the monotone PCHIP spline: it passes through every
  tabulated point and never leaves the range of two neighbouring points (the Fritsch–Carlson
  property; a not-a-knot cubic through Table I would overshoot);
* the line through a traced result is a dense re-trace: it passes through the traced points, and
  its intermediate points equal separate ``characteristic_distortion`` calls at those fields;
* the layout's rays end on the surfaces (z = vertex + sag(y), ``Surface.sag``), never above the
  drawn semi-diameters (read back from the Line2D data), and end on the image plane;
* the matplotlib conventions: ``ax=`` draws into the given Axes and returns its Figure, no ``ax``
  makes a pyplot figure, two-panel composition, titles wrapped inside the figure after an Agg
  draw, mathtext symbols, no long floats in legends, no backend forced.
"""

from __future__ import annotations

import math
import re
from dataclasses import replace
from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

import orthoscope as osc
from distortion.calibration import calibrate
from distortion.curve import make_curve
from distortion.tablefile import read_distortion_table
from orthoscope.plots.common import offscreen_figures, wrap_text
from orthoscope.plots.distortion import (
    plot_calibrated,
    plot_characteristic,
    plot_distortion,
    plot_planes,
    plot_rotation,
    rotated_characteristic,
)
from orthoscope.plots.layout import layout_rays, plot_layout
from orthoscope.plots.save import save_figure
from orthoscope.plots.variation import plot_g, plot_profiles
from raytrace.errors import OutputError

DATA = Path(__file__).parent / "data"
TABLE1_FIELDS = [0, 10, 20, 25, 30, 35, 37.5, 40, 42.5, 45]  # Pestrecov Table I, alpha (deg)


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


@pytest.fixture(scope="module")
def table1():
    return read_distortion_table(
        DATA / "pestrecov_table1.csv", 153.706, name="154 mm f/6.3 Topogon"
    )


@pytest.fixture(scope="module")
def cal(table1):
    return calibrate(table1, "two-point", at=(37.5, 45))


@pytest.fixture(scope="module")
def traced(topogon):
    return osc.characteristic_distortion(topogon, TABLE1_FIELDS)


@pytest.fixture(scope="module")
def variation():
    from distortion.variation import Conjugate, trace_variation

    lens = osc.load_lens("cooke-triplet-f4")
    return trace_variation(
        lens, Conjugate.scale(12), [Conjugate.scale(n) for n in (8, 16, 20)], max_field_deg=18.0
    ).analysis


def plain(text: str) -> str:
    """Text with line breaks and no-break spaces as plain spaces."""
    return text.replace("\n", " ").replace("\u00a0", " ")


def markers(ax):
    """Marker-only lines (the tabulated points), in drawing order."""
    return [ln for ln in ax.get_lines() if ln.get_linestyle() == "None" and len(ln.get_xdata())]


def dense(ax, n=100):
    """Drawn lines with more than n points (the dense curves), in drawing order."""
    return [ln for ln in ax.get_lines() if ln.get_linestyle() != "None" and len(ln.get_xdata()) > n]


def assert_through(line, x, y, *, atol):
    """The line's data contain every (x, y): each x is a vertex and its y agrees to atol."""
    lx, ly = np.asarray(line.get_xdata(), float), np.asarray(line.get_ydata(), float)
    for xi, yi in zip(x, y, strict=True):
        k = np.nonzero(np.isclose(lx, xi, rtol=0, atol=1e-12 * max(1.0, abs(xi))))[0]
        assert k.size, f"x = {xi} is not a vertex of the line"
        assert abs(ly[k[0]] - yi) <= atol, (xi, ly[k[0]], yi)


def assert_monotone_between(line, x, y):
    """Between two neighbouring points the line stays within their y range (no overshoot)."""
    lx, ly = np.asarray(line.get_xdata(), float), np.asarray(line.get_ydata(), float)
    order = np.argsort(x)
    xs, ys = np.asarray(x, float)[order], np.asarray(y, float)[order]
    for a in range(xs.size - 1):
        m = (lx > xs[a]) & (lx < xs[a + 1])
        assert m.any()
        lo, hi = min(ys[a], ys[a + 1]), max(ys[a], ys[a + 1])
        tol = 1e-12 * max(1.0, abs(hi))
        assert np.all(ly[m] >= lo - tol) and np.all(ly[m] <= hi + tol)


# ------------------------------------------------------------------ Pestrecov Figs. 2, 3, 4, 6


@pytest.mark.parametrize("ext", [".png", ".svg", ".pdf"])
def test_characteristic_table_markers_and_spline(tmp_path, table1, ext):
    p = tmp_path / f"fig2{ext}"
    fig = plot_characteristic(table1)
    save_figure(fig, p)
    assert p.stat().st_size > 1000
    ax, ax2 = fig.axes
    (m1,), (m2,) = markers(ax), markers(ax2)
    # markers: exactly Table I (y0', D0, Dr in %)
    np.testing.assert_array_equal(m1.get_xdata(), table1.y0p)
    np.testing.assert_array_equal(m1.get_ydata(), table1.D0)
    np.testing.assert_array_equal(m2.get_ydata(), 100.0 * table1.Dr)
    # lines: dense monotone spline through every tabulated point, no overshoot
    (l1,), (l2,) = dense(ax), dense(ax2)
    assert len(l1.get_xdata()) >= 200
    assert_through(l1, table1.y0p, table1.D0, atol=1e-15)
    assert_through(l2, table1.y0p, 100.0 * table1.Dr, atol=1e-13)
    assert_monotone_between(l1, table1.y0p, table1.D0)
    assert_monotone_between(l2, table1.y0p, 100.0 * table1.Dr)
    labels = [ax.get_xlabel(), ax.get_ylabel(), ax2.get_ylabel()]
    assert all("(mm)" in s or "(%)" in s for s in labels)
    assert "$D_0$" in ax.get_ylabel() and "$D_r$" in ax2.get_ylabel()
    assert "Topogon" in ax.get_title()
    assert "$F_{0}$ = 153.706 mm" in plain(ax.get_title())  # Table I: F0 = EFL = 153.706 mm


def test_not_a_knot_spline_would_overshoot_table1(table1):
    # the reason for PCHIP: a cubic spline through Table I leaves the range of neighbouring
    # points (so the no-overshoot assertion above can fail)
    from scipy.interpolate import CubicSpline

    x, y = table1.y0p, table1.D0
    xd = np.linspace(x[0], x[-1], 2001)
    yd = CubicSpline(x, y)(xd)
    over = False
    for a in range(x.size - 1):
        m = (xd > x[a]) & (xd < x[a + 1])
        over |= bool(np.any(yd[m] > max(y[a], y[a + 1]) + 1e-9))
        over |= bool(np.any(yd[m] < min(y[a], y[a + 1]) - 1e-9))
    assert over


def test_characteristic_traced_is_dense_trace(traced, topogon):
    fig = plot_characteristic(traced)
    ax = fig.axes[0]
    (m,) = markers(ax)
    c = traced.curve(0)
    np.testing.assert_array_equal(m.get_xdata(), c.y0p)
    np.testing.assert_array_equal(m.get_ydata(), c.D0)
    (line,) = dense(ax)
    # the dense trace passes through the traced points (chief-ray aim tolerance 1e-12 x stop)
    assert_through(line, c.y0p, c.D0, atol=1e-9)
    # intermediate points: separate traces at those fields (x = y0' = F0 tan(alpha))
    lx, ly = np.asarray(line.get_xdata()), np.asarray(line.get_ydata())
    pick = [17, 101, 203]
    alpha = np.degrees(np.arctan(lx[pick] / traced.constant[0]))
    ref = osc.characteristic_distortion(topogon, alpha).D0[0]
    np.testing.assert_allclose(ly[pick], ref, rtol=0, atol=1e-9)
    assert len(lx) >= 200 and np.all(np.diff(lx) > 0)


def test_calibrated_table_and_traced(cal, traced):
    fig = plot_calibrated(cal)
    ax, ax2 = fig.axes
    (m1,), (m2,) = markers(ax), markers(ax2)
    np.testing.assert_array_equal(m1.get_xdata(), cal.ycp)
    np.testing.assert_array_equal(m1.get_ydata(), cal.Dc)
    np.testing.assert_array_equal(m2.get_ydata(), 100.0 * cal.Drc)
    assert_through(dense(ax)[0], cal.ycp, cal.Dc, atol=1e-15)
    assert "$D_c$" in ax.get_ylabel() and "$D_{rc}$" in ax2.get_ylabel()
    assert "$F_{c}$ = 154.059" in plain(ax.get_title())  # Pestrecov Table II: F_c = 154.059 mm
    # traced: the dense calibrated curve is D_c = y' - F_c tan(alpha) at every dense field
    ct = calibrate(traced, "two-point", at=(37.5, 45))
    fig = plot_calibrated(ct)
    (line,) = dense(fig.axes[0])
    assert_through(line, ct.ycp, ct.Dc, atol=1e-9)
    lx, ly = np.asarray(line.get_xdata()), np.asarray(line.get_ydata())
    alpha = np.degrees(np.arctan(lx[[40, 150]] / ct.Kc))
    again = osc.characteristic_distortion(traced.lens, alpha)
    np.testing.assert_allclose(
        ly[[40, 150]], again.yp[0] - ct.Kc * np.tan(np.radians(alpha)), atol=1e-9
    )


def test_rotation_plot(tmp_path, cal):
    p = tmp_path / "fig4.svg"
    fig = plot_rotation(cal)
    save_figure(fig, p)
    assert p.stat().st_size > 1000
    rot, calc = markers(fig.axes[0])
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
    lr, lc = dense(fig.axes[0])
    assert_through(lr, Xp, Dp, atol=1e-15)
    assert_through(lc, cal.ycp, cal.Dc, atol=1e-15)
    # Pestrecov: "rotated through an angle of 24.67 degrees"
    assert "24.67°" in fig.axes[0].get_legend().get_texts()[0].get_text()


def _table5_curves():
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
    return t, sp, curves


def test_planes_plot_table5(tmp_path):
    t, sp, curves = _table5_curves()
    p = tmp_path / "fig6.png"
    fig = plot_planes(curves)
    save_figure(fig, p)
    assert p.stat().st_size > 1000
    ax = fig.axes[0]
    got = markers(ax)
    assert len(got) == 4
    lines = dense(ax)
    assert len(lines) == 4
    texts = [tx.get_text() for tx in ax.get_legend().get_texts()]
    for j in range(4):
        np.testing.assert_array_equal(got[j].get_xdata(), t[:, 0])
        np.testing.assert_array_equal(got[j].get_ydata(), t[:, j + 1])
        assert_through(lines[j], t[:, 0], t[:, j + 1], atol=1e-15)
        assert_monotone_between(lines[j], t[:, 0], t[:, j + 1])
        assert texts[j] == f"s' = {sp[j]} mm"
    assert "nominal field angle $\\alpha$ (deg)" == ax.get_xlabel()
    fig2 = plot_planes(curves, against="image")
    np.testing.assert_array_equal(markers(fig2.axes[0])[2].get_xdata(), curves[2].y0p)


def test_planes_traced_result_labels_and_dense():
    lens = osc.load_lens("twinplex-like-55-525")
    d = osc.characteristic_distortion(lens, [0, 10, 20, 30, 40, 45], s_prime=[425.0, 525.0])
    fig = plot_distortion(d)
    ax = fig.axes[0]
    texts = [plain(tx.get_text()) for tx in ax.get_legend().get_texts()]
    assert texts[0].startswith("$s'$ = 425 mm (defocus −105.")
    for j, line in enumerate(dense(ax)):
        assert_through(line, d.fields, d.D0[j], atol=1e-9)


def test_bad_format(tmp_path, table1):
    with pytest.raises(OutputError, match="unsupported plot format"):
        save_figure(plot_characteristic(table1), tmp_path / "x.bmpx")


# ------------------------------------------------------------------ ax= and composition


def _all_plots(table1, cal, traced, topogon, variation):
    return {
        "plot_characteristic": lambda ax: plot_characteristic(table1, ax=ax),
        "plot_calibrated": lambda ax: plot_calibrated(cal, ax=ax),
        "plot_rotation": lambda ax: plot_rotation(cal, ax=ax),
        "plot_planes": lambda ax: plot_planes(_table5_curves()[2], ax=ax),
        "plot_distortion": lambda ax: plot_distortion(traced, ax=ax),
        "plot_profiles": lambda ax: plot_profiles(variation, ax=ax),
        "plot_g": lambda ax: plot_g(variation, ax=ax),
        "plot_layout": lambda ax: plot_layout(topogon, ax=ax),
    }


def test_every_plot_takes_ax_and_returns_its_figure(table1, cal, traced, topogon, variation):
    for name, fn in _all_plots(table1, cal, traced, topogon, variation).items():
        # without ax: a pyplot figure (plt.show() and Jupyter display it)
        before = set(plt.get_fignums())
        fig = fn(None)
        assert isinstance(fig, Figure), name
        assert plt.fignum_exists(fig.number) and fig.number not in before, name
        # with ax: drawn into that Axes, its figure returned, no new pyplot figure
        host, (a, b) = plt.subplots(1, 2, figsize=(12, 4))
        n = len(plt.get_fignums())
        got = fn(b)
        assert got is host, name
        assert len(plt.get_fignums()) == n, name
        assert b.get_lines() and not a.get_lines(), name
        plt.close("all")


def test_offscreen_figures_bypass_pyplot(table1):
    before = plt.get_fignums()
    with offscreen_figures():
        fig = plot_characteristic(table1)
    assert plt.get_fignums() == before
    assert fig.canvas.manager is None


def test_two_panel_composition(tmp_path, traced, topogon):
    # the newcomer's composed figure (README): three lines after `import orthoscope as osc`
    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 4.5), layout="constrained")
    assert osc.plot_distortion(traced, ax=a) is fig
    assert osc.plot_layout(topogon, ax=b) is fig
    # the twin per-cent axis was made on `a`, nothing else was added
    assert len(fig.axes) == 3
    twin = [x for x in fig.axes if x not in (a, b)][0]
    assert twin.get_shared_x_axes().joined(twin, a)
    save_figure(fig, tmp_path / "two.png")
    assert (tmp_path / "two.png").stat().st_size > 10_000


def test_no_backend_forced():
    src = Path(osc.__file__).parent / "plots"
    for f in src.glob("*.py"):
        text = f.read_text()
        assert "matplotlib.use(" not in text and "switch_backend" not in text, f.name


# ------------------------------------------------------------------ titles, symbols, digits


def test_long_titles_wrap_inside_the_figure(table1, topogon):
    name = "A very long lens name " * 8 + "f/6.3"
    long_lens = replace(topogon, name=name)
    with offscreen_figures():
        figs = [
            plot_characteristic(replace(table1, name=name)),
            plot_layout(long_lens),
        ]
    for fig in figs:
        FigureCanvasAgg(fig)
        fig.canvas.draw()
        title = fig.axes[0].title
        assert "\n" in title.get_text()
        bb = title.get_window_extent()
        fb = fig.bbox
        assert fb.x0 <= bb.x0 and bb.x1 <= fb.x1 and fb.y0 <= bb.y0 and bb.y1 <= fb.y1
    # in a panel of a composed figure the title keeps to its own panel's width
    fig = Figure(figsize=(10, 4), layout="constrained")
    FigureCanvasAgg(fig)
    a, b = fig.subplots(1, 2)
    plot_characteristic(replace(table1, name=name), ax=a)
    plot_characteristic(table1, ax=b)
    fig.canvas.draw()
    ta = a.title.get_window_extent()
    assert ta.x1 <= b.get_window_extent().x0 + 1.0
    assert fig.bbox.x0 <= ta.x0


def test_wrap_keeps_mathtext_whole():
    out = wrap_text("alpha beta $F_{c} = 154.059$ mm gamma delta epsilon", 60.0, 10.0)
    assert "$F_{c} = 154.059$" in out.replace("\n", " ")
    assert all(line.count("$") % 2 == 0 for line in out.split("\n"))


def test_legends_keep_sensible_digits(table1, cal, traced, topogon, variation):
    long_float = re.compile(r"\d\.\d{7,}")
    for name, fn in _all_plots(table1, cal, traced, topogon, variation).items():
        fig = fn(None)
        for ax in fig.axes:
            texts = [ax.get_title(), ax.get_xlabel(), ax.get_ylabel()]
            if ax.get_legend():
                texts += [t.get_text() for t in ax.get_legend().get_texts()]
            for t in texts:
                assert not long_float.search(t), (name, t)
        plt.close(fig)


def test_variation_symbols_and_markers(variation):
    fig = plot_g(variation)
    ax = fig.axes[0]
    assert "$g_{ss'}$" in ax.get_ylabel() and "$g_{ss'}$" in ax.get_title()
    fig = plot_profiles(variation)
    ax = fig.axes[0]
    assert "$\\delta r$" in ax.get_ylabel() and "(µm)" in ax.get_ylabel()
    m = markers(ax)
    assert len(m) == len(variation.profiles)
    for line, mk, p in zip(dense(ax, 50), m, variation.profiles, strict=True):
        np.testing.assert_array_equal(mk.get_xdata(), p.r_mm)
        np.testing.assert_array_equal(mk.get_ydata(), p.dr_um)
        assert_through(line, p.r_mm, p.dr_um, atol=1e-12)


# ------------------------------------------------------------------ layout


def _layout_lenses():
    cooke = osc.load_lens("cooke-triplet-f4")
    # a file with semi-diameters: the Cooke triplet with a small front lens (vignetting)
    s = list(cooke.surfaces)
    s[0] = replace(s[0], semi_diameter=7.0)
    s[5] = replace(s[5], semi_diameter=8.0)
    small = replace(cooke, surfaces=tuple(s), name="Cooke triplet, sd 7 mm front")
    return [
        (cooke, {}),
        (small, {}),
        (osc.load_lens("topogon-like-pestrecov"), {}),
        (osc.load_lens("super-angulon-de975637"), {"fields_deg": [0, 25, 40, 50]}),
        (osc.load_lens("twinplex-like-55-525"), {"s_prime": [425.0, 525.0]}),
    ]


@pytest.mark.parametrize("k", range(5))
def test_layout_rays_stop_at_surfaces_inside_semi_diameters(k):
    lens, kw = _layout_lenses()[k]
    with offscreen_figures():
        fig = plot_layout(lens, **kw)
    ax = fig.axes[0]
    by_gid: dict[str, list] = {}
    for ln in ax.get_lines():
        by_gid.setdefault(ln.get_gid(), []).append(ln)
    rays = by_gid["chief ray"] + by_gid.get("rim ray", [])
    assert len(by_gid["chief ray"]) >= 2 and rays
    zv = lens.vertex_z
    st = lens.stop_index
    # drawn semi-diameter of each surface: its profile line; the stop: the inner end of its bars
    sd = {}
    for j in range(lens.n_surfaces):
        lines = by_gid.get(f"surface {j + 1}")
        if lines:
            sd[j] = float(np.max(np.abs(lines[0].get_ydata())))
            if math.isfinite(lens.surfaces[j].semi_diameter):  # the file's, exactly
                assert sd[j] == pytest.approx(lens.surfaces[j].semi_diameter, rel=1e-12)
    stop_inner = min(float(np.min(np.abs(b.get_ydata()))) for b in by_gid["stop"])
    z_image = max(float(ln.get_xdata()[0]) for ln in by_gid["image plane"])
    z_front = min(
        float(np.min(ln.get_xdata()))
        for g, ls in by_gid.items()
        if g and g.startswith("surface")
        for ln in ls
    )
    for ray in rays:
        z, y = np.asarray(ray.get_xdata()), np.asarray(ray.get_ydata())
        assert z.size == lens.n_surfaces + 2  # start, every surface, image plane
        assert z[0] <= z_front  # starts before the lens (object plane or in front)
        assert z[-1] == pytest.approx(z_image, abs=1e-9)  # ends on the image plane
        assert np.all(np.diff(z) > -1e-9)  # light travels toward +z
        for j in range(lens.n_surfaces):
            # on the surface: z = vertex + sag(y) (raytrace.lens.Surface.sag)
            assert z[j + 1] == pytest.approx(
                zv[j] + float(lens.surfaces[j].sag(y[j + 1])), abs=1e-7
            )
            limit = sd.get(j, stop_inner if j == st else math.inf)
            assert abs(y[j + 1]) <= limit * (1 + 1e-9), (lens.name, j, y[j + 1], limit)


def test_layout_semi_diameters_from_rays_and_vignetting():
    cooke, small = (lens for lens, _ in _layout_lenses()[:2])
    full = layout_rays(cooke)
    h = np.max(np.abs(full.y[:, 1:-1]), axis=0)
    # no file semi-diameters: every drawn surface reaches past the largest ray height there
    assert not full.from_file.any()
    assert np.all(full.semi_diameters >= h * (1 - 1e-12))
    # the file's 7 mm front semi-diameter vignettes the oblique beam: its rim rays come closer to
    # the chief ray than without it
    vig = layout_rays(small)
    assert vig.semi_diameters[0] == 7.0
    assert np.max(np.abs(vig.y[:, 1])) <= 7.0 * (1 + 1e-12)
    w_full = np.ptp(full.y[full.field_index == 2][:, -1])
    w_vig = np.ptp(vig.y[vig.field_index == 2][:, -1]) if (vig.field_index == 2).any() else 0.0
    assert w_vig < w_full


def test_layout_default_fields_legend_and_frame(topogon):
    fig = plot_layout(topogon)
    ax = fig.axes[0]
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    # fields 0, 0.7 and 1 x the lens's 45 deg, a colour each; the stop; the image plane
    assert texts[:3] == ["$\\alpha$ = 0°", "$\\alpha$ = 31.5°", "$\\alpha$ = 45°"]
    assert any(t.startswith("aperture stop") for t in texts)
    assert any(t.startswith("image plane $s'$ = 153.706") for t in texts)
    colours = {ln.get_color() for ln in ax.get_lines() if ln.get_gid() == "chief ray"}
    assert len(colours) == 3
    assert ax.get_aspect() == 1.0
    # the frame hugs the drawing: every drawn line inside, and < 10 % margin on each side
    xs = np.concatenate([ln.get_xdata() for ln in ax.get_lines() if ln.get_gid() != "axis"])
    ys = np.concatenate([ln.get_ydata() for ln in ax.get_lines() if ln.get_gid() != "axis"])
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    assert x0 <= xs.min() and xs.max() <= x1 and y0 <= ys.min() and ys.max() <= y1
    assert (xs.min() - x0) + (x1 - xs.max()) < 0.1 * (x1 - x0)
    assert (ys.min() - y0) + (y1 - ys.max()) < 0.1 * (y1 - y0)


def test_matplotlib_rc_untouched(table1):
    def rc():
        return {k: v for k, v in matplotlib.rcParams.items() if k != "backend"}

    before = rc()
    plot_characteristic(table1)
    assert rc() == before
