"""Distortion compensation camera → printer (Pestrecov 1958, Section VI, Eqs. 16–17).

Facts tested (Section VI): the compensation condition is invariant under recalibration of
either curve (Eq. 16 ⇔ Eq. 17; the print itself does not change); identical characteristic curves
in the negative plane with M = M2 compensate completely; the best M is a calibration fit.
The camera curve is Pestrecov's Table I (tests/data/pestrecov_table1.csv).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from distortion.compensation import compensate, printer_negative_distortion
from distortion.curve import DistortionCurve, make_curve
from distortion.errors import CalibrationError, DataError
from distortion.tablefile import read_distortion_table
from orthoscope.report.distortion import compensation_to_dict, format_compensation

DATA = Path(__file__).parent / "data"
M2 = -2.5  # made-up printer magnification (negative -> print)


@pytest.fixture(scope="module")
def camera():
    return read_distortion_table(DATA / "pestrecov_table1.csv", 153.706)  # Table I: F0 = 153.706


def matched_printer(camera: DistortionCurve, D2, M2: float = M2) -> DistortionCurve:
    """A printer curve whose object heights are the camera's actual negative heights y' and whose
    distortion, referred to the negative (D2 = −Dp/M2), is ``D2``."""
    h = camera.yp
    return make_curve(h, -M2 * np.asarray(D2), field_kind="height", constant=M2)


def recalibrated(curve: DistortionCurve, K: float) -> DistortionCurve:
    """The same physical curve expressed with another constant (Eq. 11): y' fixed, D' = y' − K x."""
    return make_curve(
        curve.fields, curve.yp - K * curve.x, field_kind=curve.field_kind, constant=K, x=curve.x
    )


def test_identical_curves_compensate(camera):
    printer = matched_printer(camera, camera.D0)  # D2 = D1 in the negative plane
    res = compensate(camera, printer)  # M = M2
    assert res.M == M2
    np.testing.assert_allclose(
        printer_negative_distortion(printer, camera.yp), camera.D0, atol=1e-15
    )
    assert res.max_abs <= 1e-13
    # reversing the sign of the printer curve (a "mirror" curve) does NOT compensate
    bad = compensate(camera, matched_printer(camera, -camera.D0))
    assert bad.max_abs == pytest.approx(2 * np.max(np.abs(camera.D0)), rel=1e-12)


def test_residual_is_eq16_and_print_is_invariant_under_recalibration(camera):
    # a printer that compensates only the cubic part of the camera's curve (a synthetic curve
    # through Table I's D0 = 0.272 mm at y0' = F0 = 153.706 mm, 45 deg; not a reference value)
    y = camera.yp
    printer = matched_printer(camera, 0.272 * (y / 153.706) ** 3)
    base = compensate(camera, printer, method="given", magnification=M2 * 1.001)
    # Eq. (16): R = D1 - D2 - (M/M2 - 1) F1 tan α
    tan_a = np.tan(np.radians(camera.fields))
    R = base.D1 - base.D2 - (base.M / M2 - 1.0) * camera.constant * tan_a
    np.testing.assert_allclose(base.residual, R, atol=1e-14)
    assert base.max_abs > 1e-3
    # recalibrate both curves with arbitrary F1', M2' (Eq. 11); the print's ideal size M F1 tan α
    # is fixed (y'' = M F1 tan α = M' F1' tan α) -> M' = M F1 / F1'
    # arbitrary constants (154.059 = Table II's F_c, the others made up)
    for F1p, M2p in ((154.059, -2.49), (153.0, -2.6), (155.5, -2.5)):
        cam2 = recalibrated(camera, F1p)
        # printer recalibrated in its own space: print heights fixed, new M2'
        pr2 = make_curve(
            printer.fields, printer.yp - M2p * printer.x, field_kind="height", constant=M2p
        )
        Mp = base.M * camera.constant / F1p
        new = compensate(cam2, pr2, method="given", magnification=Mp)
        # Eq. (17): the print itself (M2 R, print plane) is unchanged
        np.testing.assert_allclose(new.print_residual, base.print_residual, rtol=0, atol=1e-12)
        # and the residual in the negative plane scales with 1/M2 only
        np.testing.assert_allclose(new.residual * M2p, base.residual * M2, rtol=0, atol=1e-12)


def test_best_M_by_calibration_criteria(camera):
    printer = matched_printer(camera, 0.5 * camera.D0)
    results = {
        c: compensate(camera, printer, method=c, at=a)
        for c, a in (
            ("minimax", None),
            ("least-squares", None),
            ("two-point", (37.5, 45)),
            ("zero-at", (45,)),
        )
    }
    given = compensate(camera, printer)
    assert results["minimax"].max_abs <= given.max_abs
    assert results["minimax"].max_abs <= min(r.max_abs for r in results.values()) + 1e-15
    # the residual is linear in M: brute-force grid cannot beat the minimax M
    grid = M2 * (1 + np.linspace(-0.01, 0.01, 40001))
    worst = [np.max(np.abs(given.D1 - given.D2 - (m / M2 - 1) * given.y1)) for m in grid]
    assert results["minimax"].max_abs <= min(worst) + 1e-15
    assert results["zero-at"].residual[-1] == pytest.approx(0.0, abs=1e-12)
    r = results["two-point"].residual
    assert r[6] == pytest.approx(-r[9], abs=1e-12)
    d = compensation_to_dict(results["minimax"])
    assert d["M"] == results["minimax"].M
    assert "R (mm)" in format_compensation(results["minimax"])


def test_bad_input(camera):
    printer = matched_printer(camera, camera.D0)
    with pytest.raises(DataError, match="object at infinity"):
        compensate(printer, printer)
    with pytest.raises(DataError, match="finite conjugates"):
        compensate(camera, camera)
    short = make_curve([0.0, 10.0, 20.0], [0.0, 0.01, 0.02], field_kind="height", constant=M2)
    with pytest.raises(DataError, match="only covers object heights up to 20"):
        compensate(camera, short)
    with pytest.raises(CalibrationError, match="unknown method"):
        compensate(camera, printer, method="magic")


def test_flags_a_method_does_not_use_are_refused(capsys):
    # they were silently ignored: --at with 'given', --magnification with 'minimax', --fields
    # with a camera table
    from support import run_cli

    table = str(Path(__file__).parent / "data" / "pestrecov_table1.csv")
    pair = ["topogon-us2031792-fig1", "twinplex-like-55-525", "--fields", "0,10,20,30"]
    for argv, msg in (
        ([*pair, "--method", "given", "--at", "30"], "compensation (given) takes no --at fields"),
        ([*pair, "--method", "minimax", "--magnification", "-2"], "--magnification goes with"),
        ([table, "twinplex-like-55-525", "--fields", "0,10"], "--fields goes with a CAMERA lens"),
    ):
        rc, _, err = run_cli(["compensate", *argv])
        assert rc == 2 and msg in err, err
    assert run_cli(["compensate", *pair])[0] == 0  # the same pair runs without them


def test_magnification_of_the_other_sign_is_refused(camera):
    # Eq. 16 with M/M2 < 0 prints an inverted picture of the wrong size: a sign slip, refused
    printer = matched_printer(camera, camera.D0)
    with pytest.raises(CalibrationError, match=r"M = 2.5 has the other sign than the printer's"):
        compensate(camera, printer, magnification=2.5)


def test_a_table_in_micrometres_under_a_mm_header_is_refused(tmp_path):
    # Pestrecov's Table I with D0 written in µm under its 'D0_mm' header: 17 µm read as 17 mm is
    # a distortion of 63 % at 10° (not refused: could be a lens), 272 mm at 45° is 177 %
    rows = (DATA / "pestrecov_table1.csv").read_text().splitlines()
    out = []
    for line in rows:
        cells = line.split(",")
        if line.startswith("#") or not cells[0].strip()[0].isdigit():
            out.append(line)
            continue
        d0 = float(cells[2]) * 1000
        out.append(",".join([cells[0], cells[1], f"{d0:+.0f}"]))  # Dr dropped (it would differ)
    p = tmp_path / "table1_um.csv"
    p.write_text("\n".join(out).replace("D0_mm, Dr_pct", "D0_mm") + "\n")
    with pytest.raises(
        DataError, match=r"table1_um\.csv:\d+: D0 = \d+ mm is as large as the ideal"
    ):
        read_distortion_table(p)
