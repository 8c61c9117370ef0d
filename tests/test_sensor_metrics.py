"""Picture metrics of a rectangular sensor (distortion.sensor_metrics): TV distortion (SMIA and
traditional), keystone, line straightness, anamorphic ratio.

Referees: closed forms derived here for synthetic fields laid on a real sensor grid (a pure-K1
radial field, a plane projective map, an anamorphic scale), the 1-D characteristic distortion of
a centred lens (distortion.characteristic, the 1-D chief-ray kernel: an independent path from
the 2-D aim), and invariants (a projective map keeps lines straight; a centred lens has no
keystone, straight centre lines and an anamorphic ratio of 1).

Closed form of the pure-K1 field (derived in distortion/sensor_metrics.py's docstring, repeated
here): about the picture centre, r' = r (1 + K1 r²); picture half-width a, half-height b.
Corners (±a, ±b) → (±a, ±b)(1 + K1 (a² + b²)); edge centres (0, ±b) → (0, ±b)(1 + K1 b²) and
(±a, 0) → (±a, 0)(1 + K1 a²). Heights A1 = A2 = 2b (1 + K1 (a² + b²)), B = 2b (1 + K1 b²):
    SMIA (A − B)/B = K1 a² / (1 + K1 b²),  traditional = half of it;
widths: horizontal SMIA = K1 b² / (1 + K1 a²).
Top edge: y(x) = b (1 + K1 (x² + b²)) at x' = x (1 + K1 (x² + b²)); its chord (the corners) is
at y = b (1 + K1 (a² + b²)); the largest distance is at x = 0: y_mid − y_chord = −K1 a² b, i.e.
+K1 a² b toward the centre (−y), over the chord 2a (1 + K1 (a² + b²)). Left edge likewise:
+K1 b² a over 2b (1 + K1 (a² + b²)).
Central scales: dx'/dx = dy'/dy = 1 at the centre → anamorphic ratio 1; the whole centre lines
give (W_c/W)/(H_c/H) = (1 + K1 a²)/(1 + K1 b²).
"""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest
from support import run_cli

from distortion.characteristic import characteristic_distortion
from distortion.errors import DataError
from distortion.grid import distortion_grid
from distortion.sensor_metrics import sensor_metrics, sensor_metrics_from_points
from orthoscope.cli import COMPILE_NOTICE


@pytest.fixture(scope="module")
def grid36(cooke):
    """A traced 36 x 24 mm sensor grid of 21 x 15 points (odd: the edge centres are points)."""
    return distortion_grid(cooke, sensor="36x24", grid=(21, 15))


def _with_actual(grid, fn):
    """The grid with its actual points replaced by fn(ideal) (one plane)."""
    ideal = grid.ideal[0]
    return dataclasses.replace(grid, actual=fn(ideal)[None])


def _pure_k1(k1):
    def fn(p):
        r2 = p[..., 0] ** 2 + p[..., 1] ** 2
        return p * (1.0 + k1 * r2)[..., None]

    return fn


@pytest.mark.parametrize("k1", [-2e-5, -3e-4, 1.5e-5])
def test_pure_k1_field_gives_the_closed_form_tv_distortion(grid36, k1):
    m = sensor_metrics(_with_actual(grid36, _pure_k1(k1)))
    a, b = 18.0, 12.0  # the ideal picture: the 36 x 24 sensor
    smia = k1 * a * a / (1 + k1 * b * b)
    assert m.width_mm == pytest.approx(36.0, rel=1e-12)
    assert m.height_mm == pytest.approx(24.0, rel=1e-12)
    assert m.tv_distortion_smia == pytest.approx(smia, rel=1e-12)
    assert m.tv_distortion_traditional == pytest.approx(smia / 2, rel=1e-12)
    assert m.tv_distortion_smia_horizontal == pytest.approx(
        k1 * b * b / (1 + k1 * a * a), rel=1e-12
    )
    top, left = m.line("top"), m.line("left")
    assert top.sag_mm == pytest.approx(k1 * a * a * b, rel=1e-10)
    assert top.chord_mm == pytest.approx(2 * a * (1 + k1 * (a * a + b * b)), rel=1e-12)
    assert top.fraction == pytest.approx(k1 * a * b / (2 * (1 + k1 * (a * a + b * b))), rel=1e-10)
    assert left.sag_mm == pytest.approx(k1 * b * b * a, rel=1e-10)
    assert m.line("bottom").sag_mm == pytest.approx(top.sag_mm, rel=1e-10)
    assert abs(m.line("centre_row").sag_mm) < 1e-12 and abs(m.line("centre_column").sag_mm) < 1e-12
    assert abs(m.keystone_vertical) < 1e-13 and abs(m.keystone_horizontal) < 1e-13
    assert m.anamorphic_ratio == pytest.approx(1.0, abs=1e-12)
    assert m.mean_scale_ratio == pytest.approx((1 + k1 * a * a) / (1 + k1 * b * b), rel=1e-12)
    if k1 < 0:  # barrel: negative TV distortion, edges bowing outward (negative sag)
        assert m.tv_distortion_smia < 0 and top.sag_mm < 0


def test_the_closed_form_numbers_quoted_in_the_report(grid36):
    # the numbers of the helper's report: 36 x 24 mm, K1 = -2e-5 mm^-2
    m = sensor_metrics(_with_actual(grid36, _pure_k1(-2e-5)))
    closed = -2e-5 * 18.0**2 / (1 - 2e-5 * 12.0**2)  # = -0.0064987...
    # -0.00649871: the closed form above evaluated by hand (-0.00648 / 0.99712), as quoted
    assert abs(closed - (-0.00649871)) < 1e-8
    assert abs(m.tv_distortion_smia - closed) <= 1e-12 * abs(closed)


def test_grid_orientation_does_not_matter(grid36):
    ideal = grid36.ideal[0]
    actual = _pure_k1(-1e-4)(ideal)
    a = sensor_metrics_from_points(ideal, actual)
    b = sensor_metrics_from_points(ideal[::-1, ::-1], actual[::-1, ::-1])
    for f in ("tv_distortion_smia", "keystone_vertical", "anamorphic_ratio", "height_left_mm"):
        assert getattr(a, f) == pytest.approx(getattr(b, f), rel=1e-14, abs=1e-15)
    assert a.line("top").sag_mm == pytest.approx(b.line("top").sag_mm, rel=1e-14)


def test_projective_keystone_closed_form_and_straight_lines(grid36):
    """(x, y) → (x, y)/(1 + ε y): W_top = 2a/(1 + εb), W_bottom = 2a/(1 − εb), so
    (W_top − W_bottom)/mean = −2εb; mirror symmetry x → −x keeps the left and right heights
    equal; a projective map takes lines to lines (zero sag)."""
    eps = 2e-3
    m = sensor_metrics(_with_actual(grid36, lambda p: p / (1.0 + eps * p[..., 1:2])))
    assert m.keystone_vertical == pytest.approx(-2 * eps * 12.0, rel=1e-12)
    assert abs(m.keystone_horizontal) < 1e-14
    for s in m.straightness:
        assert abs(s.sag_mm) < 1e-12, s


def test_anamorphic_scales(grid36):
    sx, sy, k1 = 1.02, 0.99, -5e-5

    def fn(p):
        r2 = p[..., 0] ** 2 + p[..., 1] ** 2
        return np.stack([sx * p[..., 0], sy * p[..., 1]], axis=-1) * (1 + k1 * r2)[..., None]

    m = sensor_metrics(_with_actual(grid36, fn))
    assert m.scale_x == pytest.approx(sx, rel=1e-12)
    assert m.scale_y == pytest.approx(sy, rel=1e-12)
    assert m.anamorphic_ratio == pytest.approx(sx / sy, rel=1e-12)


def test_real_lens_tv_distortion_equals_the_1d_curve(cooke):
    """A centred lens: the corner's image lies on the diagonal at r_c + D0(θ_c), the edge centre's
    at b + D0(θ_b); D0 from the 1-D characteristic distortion (the 1-D chief-ray kernel)."""
    g = distortion_grid(cooke, sensor="24x16", grid=(21, 15))
    m = sensor_metrics(g)
    F0 = float(g.constant[0])
    a, b = 12.0, 8.0
    rc = math.hypot(a, b)
    th = np.degrees(np.arctan([b / F0, rc / F0, a / F0]))
    D0 = characteristic_distortion(cooke, fields_deg=th).D0[0]
    A = 2 * (rc + D0[1]) * b / rc
    B = 2 * (b + D0[0])
    # measured: both TV distortions agree to 2.2e-16 relative; bounds ~50x that
    assert m.tv_distortion_smia == pytest.approx((A - B) / B, rel=1e-14)
    Wt = 2 * (rc + D0[1]) * a / rc
    Wc = 2 * (a + D0[2])
    assert m.tv_distortion_smia_horizontal == pytest.approx((Wt - Wc) / Wc, rel=1e-14)
    # pincushion of the Cooke triplet: positive, and the edges bow inward (positive sag)
    assert m.tv_distortion_smia > 0 and m.line("top").sag_mm > 0
    assert abs(m.keystone_vertical) < 1e-12 and abs(m.keystone_horizontal) < 1e-12
    assert abs(m.line("centre_row").sag_mm) < 1e-12
    # the central scales interpolate 15 points about the centre (error ~ step^14; measured
    # 3.6e-15)
    assert m.anamorphic_ratio == pytest.approx(1.0, abs=5e-14)


def test_errors_name_the_fix(grid36, cooke):
    g = distortion_grid(cooke, sensor="24x16", grid=(6, 5))
    with pytest.raises(DataError, match="odd number"):
        sensor_metrics(g)
    ideal = grid36.ideal[0].copy()
    ideal[3, 4, 0] += 0.1  # no longer a lattice
    with pytest.raises(DataError, match="rectangular lattice"):
        sensor_metrics_from_points(ideal, grid36.actual[0])
    with pytest.raises(DataError, match="plane="):
        sensor_metrics(grid36, plane=3)


#: the Cooke triplet's sensor metrics on a 24 x 16 mm sensor, 13 x 9 grid
METRICS_ARGV = [
    "distortion",
    "cooke-triplet-f4",
    "--sensor",
    "24x16",
    "--grid",
    "13x9",
    "--sensor-metrics",
]


def test_cli_sensor_metrics_json_equals_the_api(cooke):
    rc, out, err = run_cli([*METRICS_ARGV, "--json"])
    assert rc == 0, err
    js = json.loads(out)["sensor_metrics"][0]
    m = sensor_metrics(distortion_grid(cooke, sensor="24x16", grid=(13, 9)))
    assert js["tv_distortion_smia"] == m.tv_distortion_smia
    assert js["straightness"]["top"]["sag_mm"] == m.line("top").sag_mm
    rc, out, err = run_cli(METRICS_ARGV)
    assert rc == 0 and "SMIA 1.0" in out and f"{100 * m.tv_distortion_smia:+.4f} %" in out


@pytest.mark.parametrize(
    "argv,words",
    [
        (["--grid", "13x9", "--sensor-metrics"], "needs --sensor"),
        (["--sensor", "24x16", "--grid", "12x9", "--sensor-metrics"], "odd counts"),
    ],
)
def test_cli_refuses_with_one_line(argv, words):
    rc, out, err = run_cli(["distortion", "cooke-triplet-f4", *argv])
    lines = [ln for ln in err.splitlines() if COMPILE_NOTICE not in ln]
    assert rc == 2 and len(lines) == 1 and words in lines[0] and ": error:" in lines[0], err
