"""Calibrated distortion (Pestrecov 1958, Eqs. 10–15) and the Table III → IV constants (Eqs. 5–8).

Reference numbers: K. Pestrecov, Photogrammetric Engineering 1958, Tables I–IV and Section IV.B
(copied into tests/data/pestrecov_table1.csv and pestrecov_table2.csv with their source lines).
"Printed rounding, ±1 in the last digit" means |computed − printed| ≤ one unit of the last printed
digit.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

from distortion.calibration import CRITERIA, calibrate, fit_scale
from distortion.curve import make_curve
from distortion.errors import CalibrationError, DataError
from distortion.tablefile import read_distortion_table
from orthoscope.report.distortion import format_calibration
from raytrace.errors import OrthoscopeError
from raytrace.paraxial.orthoscopy import (
    exit_pupil_to_gaussian_image,
    gaussian_image_distance,
    gaussian_magnification,
    object_distance_for_magnification,
    object_distance_for_plane_magnification,
    plane_constants,
)

DATA = Path(__file__).parent / "data"
F0_TABLE1 = 153.706  # Table I heading: "F0 = EFL = 153.706 mm."


@pytest.fixture(scope="module")
def table1():
    return read_distortion_table(DATA / "pestrecov_table1.csv", F0_TABLE1)


@pytest.fixture(scope="module")
def table2():
    lines = [ln for ln in (DATA / "pestrecov_table2.csv").read_text().splitlines() if ln[:1] != "#"]
    return np.loadtxt(lines[1:], delimiter=",")


@pytest.fixture(scope="module")
def paper_cal(table1):
    return calibrate(table1, "two-point", at=(37.5, 45.0))


# ---------------------------------------------------------------- Table I -> Table II


def test_two_point_focal_length(paper_cal):
    # Section IV.B: Fc = 154.059 mm (the text's 154.069 is a typo: 154.059 is used in the
    # rho computation and heads Table II).
    assert abs(paper_cal.Kc - 154.059) <= 0.0005
    assert paper_cal.symbol == "F"


def test_table2_reproduced(paper_cal, table2):
    alpha, ycp, dc, drc = table2.T
    np.testing.assert_array_equal(paper_cal.curve.fields, alpha)
    # every printed value to +-1 in the last (third) decimal
    assert np.max(np.abs(paper_cal.ycp - ycp)) <= 0.001
    assert np.max(np.abs(paper_cal.Dc - dc)) <= 0.001
    assert np.max(np.abs(100.0 * paper_cal.Drc - drc)) <= 0.001


def test_rho_and_summary(paper_cal):
    # Section IV.B: tan rho_k = 200 (154.059/153.706 - 1) = 0.4594, rho = 24.67 deg
    assert abs(paper_cal.rho_k_deg - 24.67) <= 0.01
    given = calibrate(paper_cal.curve, "given", value=154.059)
    assert abs(math.tan(math.radians(given.rho_k_deg)) - 0.4594) <= 0.0001
    assert abs(given.rho_k_deg - 24.67) <= 0.005
    # D_rc on the axis = -0.230 % (constant term of Eq. 15)
    assert abs(100.0 * paper_cal.Drc_axis - (-0.230)) <= 0.001
    assert abs(100.0 * paper_cal.Drc[0] - (-0.230)) <= 0.001
    # max |D_c| reduced from 0.355 to 0.081 mm, spread from 0.355 to 0.162 mm
    assert abs(paper_cal.D0_max_abs - 0.355) <= 0.0005
    assert abs(paper_cal.D0_spread - 0.355) <= 0.0005
    assert abs(paper_cal.Dc_max_abs - 0.081) <= 0.001
    assert abs(paper_cal.Dc_spread - 0.162) <= 0.001
    # "equal magnitude, opposite sign" at the two chosen fields
    assert paper_cal.Dc[6] == pytest.approx(-paper_cal.Dc[9], abs=1e-12)
    # spread of per-cent distortion: 0.298 % (characteristic); the calibrated spread is the same
    # within the factor F0/Fc of Eq. (15) (the paper's 0.299 % is the difference of its two
    # printed, rounded values +0.069 and -0.230, so it is not checked to the last digit)
    assert abs(100 * paper_cal.Dr_spread - 0.298) <= 0.001
    assert abs(100 * paper_cal.Drc_spread - 0.298) <= 0.001


def test_calibration_changes_nothing_physical(paper_cal):
    c = paper_cal.curve
    np.testing.assert_allclose(paper_cal.yp, c.y0p + c.D0, rtol=0, atol=1e-12)
    # Eq. (12) equals Eq. (10)
    np.testing.assert_allclose(
        paper_cal.Dc, c.D0 - (paper_cal.Kc / c.constant - 1.0) * c.y0p, rtol=0, atol=1e-12
    )
    # Eq. (15): D_rc spread = D_r spread * F0/Fc, and D_rc = y'/y_c' - 1 off the axis
    assert paper_cal.Drc_spread == pytest.approx(
        paper_cal.Dr_spread * c.constant / paper_cal.Kc, rel=1e-12
    )
    eq15 = c.Dr * c.constant / paper_cal.Kc + (c.constant / paper_cal.Kc - 1.0)
    np.testing.assert_allclose(paper_cal.Drc, eq15, rtol=0, atol=1e-15)


def test_report_text_contains_table2(paper_cal):
    text = format_calibration(paper_cal, layout="paper")
    assert "154.059" in text  # Table II heading: F_c = 154.059 mm
    # Table II as printed: Y_c' at 10 deg, D_c at 10 and 20 deg, Y_c' and D_c at 37.5 deg
    for v in ("27.165", "-0.045", "-0.041", "118.214", "+0.081"):
        assert v in text


# ---------------------------------------------------------------- other criteria


def test_minimax_beats_every_grid_candidate(table1):
    res = calibrate(table1, "minimax")
    assert res.Dc_max_abs <= calibrate(table1, "two-point", at=(37.5, 45)).Dc_max_abs + 1e-12
    grid = np.linspace(153.5, 154.6, 200001)  # step 5.5e-6 mm
    worst = np.max(np.abs(table1.yp[None, :] - grid[:, None] * table1.x[None, :]), axis=1)
    assert res.Dc_max_abs <= worst.min() + 1e-12
    # equioscillation: the max |D_c| is attained with both signs
    m = res.Dc_max_abs
    assert np.any(np.isclose(res.Dc, m, rtol=1e-9)) and np.any(np.isclose(res.Dc, -m, rtol=1e-9))


def test_minimax_random_curves_against_pairs():
    rng = np.random.default_rng(3)
    for _ in range(20):
        x = np.sort(rng.uniform(-1.0, 2.0, 15))
        r = 3.0 * x + rng.normal(0.0, 0.1, x.size)
        k = fit_scale(x, r, "minimax")
        best = np.max(np.abs(r - k * x))
        # exact optimum = the best value over all pair-wise equal-|residual| candidates
        cands = [
            (r[i] + r[j]) / (x[i] + x[j]) for i in range(15) for j in range(15) if x[i] + x[j] != 0
        ]
        cands += [(r[i] - r[j]) / (x[i] - x[j]) for i in range(15) for j in range(i)]
        opt = min(np.max(np.abs(r - c * x)) for c in cands)
        assert best <= opt * (1 + 1e-12)


def test_least_squares_normal_equation(table1):
    res = calibrate(table1, "least-squares")
    expected = float(np.sum(table1.x * table1.yp) / np.sum(table1.x**2))
    assert res.Kc == pytest.approx(expected, rel=1e-14)
    # any other constant gives a larger sum of squares
    for d in (-1e-4, 1e-4):
        assert np.sum(res.Dc**2) < np.sum((table1.yp - (res.Kc + d) * table1.x) ** 2)


def test_zero_at_and_given(table1):
    res = calibrate(table1, "zero-at", at=(30,))
    assert res.Dc[4] == pytest.approx(0.0, abs=1e-12)
    g = calibrate(table1, "given", value=F0_TABLE1)
    np.testing.assert_allclose(g.Dc, table1.D0, atol=1e-12)
    assert g.Drc_axis == 0.0


def test_finite_conjugates_use_M():
    y = np.array([0.0, -2.0, -4.0, -6.0])
    M0 = -9.5
    D0 = 1e-3 * (y / 6.0) ** 3
    c = make_curve(y, D0, field_kind="height", constant=M0)
    res = calibrate(c, "zero-at", at=(-6.0,))
    assert res.symbol == "M"
    assert res.Kc == pytest.approx((M0 * -6.0 + D0[-1]) / -6.0, rel=1e-14)
    assert res.Dc[-1] == pytest.approx(0.0, abs=1e-13)


# ---------------------------------------------------------------- bad input


def test_bad_requests(table1):
    with pytest.raises(CalibrationError, match="unknown calibration method"):
        calibrate(table1, "best")
    with pytest.raises(CalibrationError, match="outside"):
        calibrate(table1, "two-point", at=(37.5, 50))
    with pytest.raises(CalibrationError, match="not one of the curve's field points"):
        calibrate(table1, "two-point", at=(37.5, 44))
    with pytest.raises(CalibrationError, match="exactly 2"):
        calibrate(table1, "two-point", at=(37.5,))
    with pytest.raises(CalibrationError, match="off-axis"):
        calibrate(table1, "zero-at", at=(0,))
    with pytest.raises(CalibrationError, match="needs the calibrated constant"):
        calibrate(table1, "given")
    one = make_curve([0.0, 10.0], [0.0, 0.01], constant=100.0)
    with pytest.raises(CalibrationError, match="at least two off-axis"):
        calibrate(one, "minimax")
    # the axis is no calibration field (D_c = 0 there for every constant): it gave zero-at-45
    with pytest.raises(CalibrationError, match="two different off-axis fields"):
        calibrate(table1, "two-point", at=(0, 45))
    # a value with a method that chooses the constant itself was ignored
    with pytest.raises(CalibrationError, match=r"value= goes with method 'given'"):
        calibrate(table1, "least-squares", value=154.0)
    # a calibration rescales the image; a constant of the other sign would flip it
    with pytest.raises(CalibrationError, match=r"F_c = -154.0 must have the sign of F0"):
        calibrate(table1, "given", value=-154.0)


def test_spreads_include_the_axis_whether_or_not_the_table_lists_it(table1):
    # Pestrecov's Table I: the spreads of D0 and Dr run from the axis (0) to the largest value,
    # 0.355 mm at 40 deg and 0.298 % at 35 / 37.5 deg (the table's printed maxima)
    on = table1.fields != 0.0
    no_axis = make_curve(table1.fields[on], table1.D0[on], constant=table1.constant)
    for c in (table1, no_axis):
        cal = calibrate(c, "two-point", at=(37.5, 45))
        assert cal.D0_spread == pytest.approx(0.355, abs=1e-12)
        assert 100 * cal.Dr_spread == pytest.approx(0.298, abs=5e-4)
        assert cal.Drc_spread >= abs(cal.Drc_axis)  # the axis value of D_rc is in it


def test_a_field_copied_from_the_listing_is_found():
    # fields with more digits than the error message lists (6 significant): the listed value
    # names the field, as long as it names only one
    x = np.array([0.0, -38.452312, -54.915634])
    c = make_curve(x, [0.0, 0.01, 0.02], constant=-3.0, field_kind="height")
    with pytest.raises(CalibrationError, match=r"\(0, -38.4523, -54.9156\)"):
        calibrate(c, "two-point", at=(-38.45, -54.9156))
    got = calibrate(c, "two-point", at=(-38.4523, -54.9156))
    assert got.at == (-38.4523, -54.9156) and math.isfinite(got.Kc)


def test_a_height_table_rounded_to_its_printed_digits_is_read(tmp_path):
    # a projector's table: object heights y computed for given image sizes and printed to 4
    # decimals, as y0' is; y0' = M0·y holds to the rounding of both columns, not of y0' alone
    m0 = -7.727571
    y = np.array([0.0, -9.683123, -14.714617, -19.987613])
    rows = [f"{v:.4f}, {m0 * v:.4f}, {0.001 * i:+.5f}" for i, v in enumerate(y)]
    (tmp_path / "t.csv").write_text("y_mm, y0p_mm, D0_mm\n" + "\n".join(rows) + "\n")
    curve = read_distortion_table(tmp_path / "t.csv")
    assert curve.constant == pytest.approx(m0, rel=1e-5)
    # a y0' off by more than the rounding still fails
    rows[2] = rows[2].replace(f"{m0 * y[2]:.4f}", f"{m0 * y[2] + 0.01:.4f}")
    (tmp_path / "u.csv").write_text("y_mm, y0p_mm, D0_mm\n" + "\n".join(rows) + "\n")
    with pytest.raises(DataError, match=r"u.csv:[34]: y0' = .* is inconsistent with M0"):
        read_distortion_table(tmp_path / "u.csv")
    assert issubclass(CalibrationError, DataError) and issubclass(CalibrationError, ValueError)
    assert issubclass(CalibrationError, OrthoscopeError)
    assert set(CRITERIA) == {"two-point", "minimax", "least-squares", "zero-at", "given"}


# ---------------------------------------------------------------- Table III -> Table IV

# Table III: EFL 50.2832 mm, m_e 1.001700, HE0 -0.0853 mm, H'E0' -0.0856 mm
EFL, ME, HE0, HPE0P = 50.2832, 1.001700, -0.0853, -0.0856
# Section V: magnification -9.545455 (= -525/55) required at the nominal projection distance
M_SPEC = -525.0 / 55.0


def test_table4_object_distances():
    # non-Gaussian planes: s from the required M0 at s' = 525 by Eq. (8) -> printed -55.0009
    s = object_distance_for_plane_magnification(M_SPEC, 525.0, ME, HE0, HPE0P)
    assert round(s, 4) == -55.0009
    # Gaussian plane: s from m0 = -9.545455 by Eq. (5) -> printed -55.5510,
    # s' by Eq. (1) -> 530.2592
    sg = object_distance_for_magnification(EFL, M_SPEC)
    assert round(sg, 4) == -55.5510
    assert round(gaussian_image_distance(EFL, sg), 4) == 530.2592
    assert round(gaussian_magnification(EFL, sg), 6) == -9.545455


@pytest.mark.parametrize(
    "s_prime, P0p, M0",
    [(425.0, 425.0856, -7.727571), (525.0, 525.0856, -9.545455), (625.0, 625.0856, -11.363342)],
)
def test_table4_non_gaussian_rows(s_prime, P0p, M0):
    # the paper computed with its printed (rounded) s = -55.0009
    row = plane_constants(EFL, ME, HE0, HPE0P, -55.0009, s_prime)
    assert round(row.p0, 4) == -54.9156
    assert round(row.p0p, 4) == P0p
    if s_prime != 525.0:
        assert round(row.constant, 6) == M0  # exactly the printed digits
    else:
        # the 525 row prints the specified -9.545455 (= -525/55); rounding s to 4 decimals moves
        # M0 by at most |dM0/ds| * 5e-5 = |M0/p0| * 5e-5 = 8.7e-6
        assert abs(row.constant - M0) <= abs(M0 / row.p0) * 5e-5
        s_exact = object_distance_for_plane_magnification(M_SPEC, 525.0, ME, HE0, HPE0P)
        exact = plane_constants(EFL, ME, HE0, HPE0P, s_exact, s_prime)
        assert round(exact.constant, 6) == M0


def test_table4_gaussian_row():
    sg = object_distance_for_magnification(EFL, M_SPEC)
    row = plane_constants(EFL, ME, HE0, HPE0P, sg)  # s' = None -> Gaussian plane, Eq. (1)
    assert round(row.s_prime, 4) == 530.2592
    assert round(row.p0, 4) == -55.4657
    assert round(row.p0p, 4) == 530.3448
    assert round(row.gaussian_constant, 6) == -9.545455  # m0, Eq. (5)
    assert row.defocus == 0.0
    # Eq. (8) in the Gaussian plane gives m0 up to the rounding of Table III's m_e (5e-7),
    # HE0 and H'E0' (5e-5 mm each): |dM0| <= |M0| (5e-7/m_e + 5e-5/|p0| + 5e-5/p0')
    bound = abs(row.constant) * (5e-7 / ME + 5e-5 / abs(row.p0) + 5e-5 / row.p0p)
    assert abs(row.constant - (-9.545455)) <= bound
    # Eq. (7): P0g' = m_e m0 p0 equals p0' of the Gaussian plane within the same rounding
    P0g = exit_pupil_to_gaussian_image(ME, m0=row.gaussian_constant, p0=row.p0)
    assert abs(P0g - row.p0p) <= row.p0p * (5e-7 / ME + 5e-5 / abs(row.p0) + 5e-5 / row.p0p)


def test_constants_infinite_object():
    # object at infinity: F0 = p0'/m_e, and = f in the Gaussian plane (Eq. 7 -> Eq. 8)
    f, me, hpe = 100.0, 1.25, -3.0
    row = plane_constants(f, me, 0.0, hpe, -math.inf)
    assert row.s_prime == f
    assert row.constant == pytest.approx((f - hpe) / me)
    # with the exit pupil where Eq. (7) puts it (P0g' = m_e f), F0 = f exactly
    row2 = plane_constants(f, me, 0.0, f - me * f, -math.inf)
    assert row2.constant == pytest.approx(f, rel=1e-15)
    assert row2.symbol == "F0"


# ---------------------------------------------------------------- table reader / writers

GOOD = (
    "# made-up rows for reader tests\nalpha_deg,y0p_mm,D0_mm\n"
    "0,0,0\n10,17.633,0.01\n20,36.397,0.02\n"
)


@pytest.mark.parametrize(
    "text, message",
    [
        ("alpha_deg,D0_mm\n10,0.1\n20,0.2\n", r"t\.csv:1: missing column\(s\): y0p_mm"),
        (
            "alpha_deg,y0p_mm,D0_mm\n10,17.633,0.01\n20,36.397,0.02\n15,26.795,0\n",
            r"t\.csv:4: field values must",
        ),
        (
            "alpha_deg,y0p_mm,D0_mm\n10,17.633,nan\n20,36.397,0.02\n",
            r"t\.csv:2: 'nan' is not a finite",
        ),
        ("alpha_deg,y0p_mm,D0_mm\n0,0,0\n10,17.633,0.01\n", r"at least two off-axis"),
        (
            "alpha_deg,y0p_mm,D0_mm\n10,17.633,0.0x1\n20,36.397,0.02\n",
            r"t\.csv:2: cannot read '0\.0x1'",
        ),
        ("alpha_deg,y0p_mm,D0_mm\n10,17.633\n20,36.397,0.02\n", r"t\.csv:2: 2 value\(s\)"),
        ("alpha_deg,y0p_mm,D0_mm,foo\n", r"t\.csv:1: unknown column 'foo'"),
        ("alpha_deg;y0p_mm;D0_mm\n", r"columns separated by ';': separate them with commas"),
        ("alpha_deg,y0p_mm,D0_mm,\n", r"unknown column '' \(an empty column: a trailing comma"),
        ("# only a comment\n", r"no header"),
        (
            "alpha_deg,y0p_mm,D0_mm\n10,17.633,0.01\n20,36.500,0.02\n",
            r"t\.csv:2: y0' .* inconsistent",
        ),
        (
            "alpha_deg,y0p_mm,D0_mm,Dr_pct\n10,17.633,0.01,0.5\n20,36.397,0.02,0.055\n",
            r"t\.csv:2: Dr",
        ),
    ],
)
def test_table_reader_errors(tmp_path, text, message):
    p = tmp_path / "t.csv"
    p.write_text(text)
    with pytest.raises(DataError, match=message):
        read_distortion_table(p, 100.0 if "36.500" not in text else None)


def test_table_reader_missing_file(tmp_path):
    with pytest.raises(DataError, match="cannot read"):
        read_distortion_table(tmp_path / "nope.csv")


def test_table_reader_infers_constant_and_roundtrips(tmp_path, table1):
    p = tmp_path / "t.csv"
    p.write_text(GOOD)
    c = read_distortion_table(p)
    assert c.constant == pytest.approx(
        100.0, abs=2e-3
    )  # 100 tan 10° = 17.633, 100 tan 20° = 36.397
    assert c.field_kind == "angle" and not c.finite
    inferred = read_distortion_table(DATA / "pestrecov_table1.csv")
    # Table I heading F0 = 153.706 mm, to half a unit of its last digit (measured: 1.1e-4 mm)
    assert abs(inferred.constant - F0_TABLE1) <= 0.0005
    # CSV writer -> reader round trip, and the finite (height) table kind
    from distortion.tablefile import dumps_table
    from orthoscope.report.distortion import curve_to_dict, format_curve

    q = tmp_path / "rt.csv"
    q.write_text(dumps_table(table1))
    back = read_distortion_table(q, table1.constant)
    np.testing.assert_allclose(back.D0, table1.D0, atol=1e-9)
    np.testing.assert_allclose(back.fields, table1.fields)
    h = tmp_path / "h.csv"
    h.write_text("y (mm), y0' (mm), D0 (mm)\n0,0,0\n-2,19,0.001\n-4,38,0.003\n")
    hc = read_distortion_table(h)
    assert hc.finite and hc.symbol == "M" and hc.constant == pytest.approx(-9.5)
    d = curve_to_dict(table1)
    assert d["F0"] == F0_TABLE1 and len(d["D0_mm"]) == 10
    paper = format_curve(table1, layout="paper")
    rows = format_curve(table1, layout="rows")
    # Table I as printed: F0 = 153.706 mm, D0 = +0.355 mm at 40 deg
    assert "153.706" in paper and "+0.355" in paper and len(rows.splitlines()) == 14


# ---------------------------------------------------------------- the bundled Table I


def test_bundled_table1_is_the_test_table_and_calibrate_takes_its_name(tmp_path, monkeypatch):
    """lenses/pestrecov-1958-table1-topogon.csv ships Table I with the package, so that
    ``orthoscope calibrate pestrecov-1958-table1-topogon`` (the help's example) works from any
    folder: the same rows as tests/data/pestrecov_table1.csv, the same result by name as by
    path, and an existing file of that name wins over the bundled one."""
    from support import run_cli

    from orthoscope.cli.calibrate import PESTRECOV_TABLE_I
    from raytrace.files.library import library_dir

    shipped = library_dir() / f"{PESTRECOV_TABLE_I}.csv"
    # a copy, source lines included (the reader keeps them as the curve's source)
    assert shipped.read_bytes() == (DATA / "pestrecov_table1.csv").read_bytes()

    def cal(table):
        return ["calibrate", table, "--method", "two-point", "--at", "37.5,45", "--json"]

    def result(out):
        d = json.loads(out)
        assert d["characteristic"].pop("name") in ("pestrecov_table1", PESTRECOV_TABLE_I)
        return d

    rc, by_path, err = run_cli(cal(str(DATA / "pestrecov_table1.csv")))
    assert rc == 0, err
    monkeypatch.chdir(tmp_path)
    for word in (PESTRECOV_TABLE_I, f"{PESTRECOV_TABLE_I}.csv"):
        rc, by_name, err = run_cli(cal(word))
        assert rc == 0, err
        assert result(by_name) == result(by_path)
    changed = shipped.read_text().replace("42.5, 140.846, +0.330, +0.234\n", "")
    (tmp_path / f"{PESTRECOV_TABLE_I}.csv").write_text(changed)
    rc, local, err = run_cli(cal(f"{PESTRECOV_TABLE_I}.csv"))
    assert rc == 0, err
    assert len(json.loads(local)["Dc_mm"]) == len(json.loads(by_path)["Dc_mm"]) - 1


# ------------------------------------------------- input checks of make_curve and calibrate


@pytest.mark.parametrize(
    "kw, needle",
    [
        ({"D0": [0.0, math.nan, 0.001, 0.002]}, r"D0\[1\] = nan \(field 10\)"),
        ({"fields": [0.0, math.nan, 20.0, 30.0]}, r"fields\[1\] = nan"),
        ({"constant": math.nan}, r"constant = nan"),
        ({"constant": math.inf}, r"constant = inf"),
        ({"x": [0.0, 0.1, math.inf, 0.3]}, r"x\[2\] = inf"),
        ({"y0p": [0.0, 1.0, -math.inf, 3.0]}, r"y0p\[2\] = -inf"),
    ],
)
def test_make_curve_refuses_non_finite_inputs_naming_them(kw, needle):
    # a NaN field, D0 or constant reached scipy's linprog ("b_ub must not contain values inf,
    # nan") or a curve of NaN; now make_curve names the input (defect #3 of the units sweep)
    args = {"fields": [0.0, 10.0, 20.0, 30.0], "D0": [0.0, 0.0005, 0.001, 0.002]}
    args.update({k: v for k, v in kw.items() if k in args})
    rest = {k: v for k, v in kw.items() if k not in args}
    with pytest.raises(ValueError, match=needle) as e:
        calibrate(make_curve(args["fields"], args["D0"], **{"constant": 154.0, **rest}))
    assert "linprog" not in str(e.value) and "\n" not in str(e.value)


def test_make_curve_refuses_field_angles_beyond_90_and_a_zero_constant():
    # tan(100°) made y0' = −873 mm and calibrate completed; constant=0 printed "F0 = 0 …
    # D_rc = -100 %" (defect #4). The tracer's own check refuses the same angles.
    with pytest.raises(ValueError, match=r"fields\[2\] = 100: field angles must lie strictly "):
        make_curve([0, 10, 100], [0, 0.001, 0.002], constant=154)
    with pytest.raises(ValueError, match=r"fields\[1\] = -90: field angles"):
        make_curve([0, -90], [0, 0.001], constant=154)
    with pytest.raises(ValueError, match=r"fields\[1\] = 95: field angles"):  # α of y = p0 tan α
        make_curve([0, 95], [0, 1e-3], field_kind="nominal-angle", x=[0, 1], constant=-2.0)
    for kind in ("angle", "height"):
        with pytest.raises(ValueError, match="constant = 0 is not a finite nonzero number"):
            make_curve([0, 10, 20], [0, 0.001, 0.002], field_kind=kind, constant=0)
    # what the curve allows stays allowed: negative and large fields, heights of any size, an
    # M0 of either sign, and a negative F0 (an erecting system with an intermediate image traces
    # to one: two f = 100 mm lenses 300 mm apart give F0 = −99.3 mm)
    assert len(make_curve([-30, 0, 30, 89.9], [-0.1, 0, 0.1, 1.0], constant=154)) == 4
    assert make_curve([0, 10, 20], [0, 1e-3, 2e-3], constant=-99.3).y0p[1] < 0
    for M0 in (-9.5, 0.25):
        c = make_curve([-500.0, 0.0, 1e4], [0.0, 0.0, 0.5], field_kind="height", constant=M0)
        assert c.constant == M0


def test_given_constant_that_looks_like_another_unit_is_refused(table1):
    # F0 = 153.706 mm and value=0.154 (metres) gave max |D_c| = 153.8 mm, D_rc = +99 709 %
    # (defect #5); every criterion gives a constant within the curve's own scales y'/x
    with pytest.raises(CalibrationError, match=r"value=0\.154 .*looks like metres.*value=154\)"):
        calibrate(table1, "given", value=0.154)
    with pytest.raises(CalibrationError, match=r"value=154000 .*looks like micrometres"):
        calibrate(table1, "given", value=154e3)
    with pytest.raises(CalibrationError, match=r"value=40 is 0\.26.* times F0"):
        calibrate(table1, "given", value=40.0)
    for bad in (0.0, math.nan, math.inf):
        with pytest.raises(CalibrationError, match=r"^calibration \(given\): value= must be a "):
            calibrate(table1, "given", value=bad)
    with pytest.raises(CalibrationError, match=r"value= must be a finite nonzero number.*'154'"):
        calibrate(table1, "given", value="154")
    # real calibrated constants pass: the paper's F_c, and a fisheye's minimax constant, which is
    # far from F0 (y' = F0·θ against x = tan θ to 85°: K_c ≈ 0.19 F0) but within the curve's scales
    assert calibrate(table1, "given", value=154.059).Kc == 154.059
    th = np.radians(np.arange(0.0, 86.0, 5.0))
    fisheye = make_curve(np.degrees(th), 100.0 * (th - np.tan(th)), constant=100.0)
    kc = calibrate(fisheye, "minimax").Kc
    assert 15.0 < kc < 25.0
    assert calibrate(fisheye, "given", value=kc).Kc == kc
    m = make_curve([0.0, -2.0, -4.0], [0.0, 1e-4, 3e-4], field_kind="height", constant=-9.5)
    assert calibrate(m, "given", value=-9.49).Kc == -9.49
    with pytest.raises(CalibrationError, match=r"value=-0\.0095 is 0\.001 times M0 = -9\.5"):
        calibrate(m, "given", value=-0.0095)


def _one_line_error(argv, *needles):
    from support import run_cli

    rc, out, err = run_cli(argv)
    assert rc == 2, (out, err)
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
    for n in needles:
        assert n in err, err
    return err


def test_given_constant_in_metres_is_refused_by_both_commands():
    # `calibrate TABLE --method given --value 0.154` and `distortion LENS --calibrate given
    # --value 0.154` ran (D_rc = +99 709 %); both now refuse it in one line naming --value
    table = str(DATA / "pestrecov_table1.csv")
    _one_line_error(
        ["calibrate", table, "--method", "given", "--value", "0.154"],
        "calibration (given): --value 0.154 is 0.001002 times F0 = 153.706 mm: it looks like "
        "metres; F_c is in mm (--value 154)",
    )
    cooke = ["distortion", "cooke-triplet-f4", "--fields", "0,10,20", "--calibrate", "given"]
    _one_line_error([*cooke, "--value", "0.05"], "--value 0.05 is 0.001", "looks like metres")
    _one_line_error(["calibrate", table, "--method", "given", "--value", "nan"], "--value must")


def test_distortion_at_fields_are_the_calibrate_commands_check():
    # --at 0.65,0.79 (radians for 37.5°, 45°) was added to the traced fields and calibrated at
    # 0.65° and 0.79°, while `calibrate` and osc.calibrate refused them (defect #15): --at
    # values are still traced with the run's fields, except one that looks like radians, which
    # the one check (distortion.calibration.match_fields) then refuses, saying so
    table = str(DATA / "pestrecov_table1.csv")
    listing = "(0, 10, 20, 25, 30, 35, 37.5, 40, 42.5, 45)"
    common = (
        "field 0.65 is not one of the curve's field points",
        "0.65 looks like radians (0.65 rad = 37.24°): the fields are in degrees",
    )
    e1 = _one_line_error(
        ["calibrate", table, "--method", "two-point", "--at", "0.65,0.79"], *common
    )
    fields = "0,10,20,25,30,35,37.5,40,42.5,45"
    e2 = _one_line_error(
        ["distortion", "topogon-like-pestrecov", "--fields", fields, "--calibrate", "two-point",
         "--at", "0.65,0.79"], *common, listing)  # fmt: skip
    assert e1.split("error: ", 1)[1] == e2.split("error: ", 1)[1]  # the same message
    # the same without --fields: 0.79 rad = 45.26° lands on the default fields' 45 (0.65 rad =
    # 37.24° lands on none of 0, 4.5, … 45: it is a field of 0.65° as far as anyone can tell)
    _one_line_error(
        ["distortion", "topogon-like-pestrecov", "--calibrate", "two-point", "--at", "0.65,0.79"],
        "field 0.79 is not one of the curve's field points (0, 0.65, 4.5, 9,",
        "0.79 looks like radians (0.79 rad = 45.26°): the fields are in degrees",
    )
    # fields in degrees are traced too (37.5 is no default field); 0.65 in --fields is taken as
    # degrees (the user said so); 1 on a lens of 55° (1 rad = 57.3°, no field) is a field of 1°
    for argv in (
        ["topogon-like-pestrecov", "--calibrate", "two-point", "--at", "37.5,45"],
        ["topogon-like-pestrecov", "--calibrate", "two-point", "--fields", "0,0.65,20,45"]
        + ["--at", "0.65,45"],
        ["super-angulon-de975637", "--max-field", "55", "--calibrate", "zero-at", "--at", "1"],
    ):
        from support import run_cli

        rc, out, err = run_cli(["distortion", *argv, "--json"])
        assert rc == 0, err
        at = [float(a) for a in argv[-1].split(",")]
        fields = json.loads(out)["distortion"]["fields"]
        assert all(a in fields for a in at), (at, fields)
    with pytest.raises(CalibrationError, match=re.escape(common[1])):
        calibrate(read_distortion_table(table), "zero-at", at=0.65)
    # --wavelengths takes no calibration: its --at was traced as one more field, now refused
    _one_line_error(
        ["distortion", "cooke-triplet-f4", "--wavelengths", "F,d,C", "--at", "5"],
        "--wavelengths does not combine with --at",
    )
