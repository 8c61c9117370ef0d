"""CLI: ``orthoscope variation`` and ``orthoscope coefficients`` (:mod:`orthoscope.cli.variation`,
:mod:`orthoscope.cli.coefficients`).

Sources: Fraser & Shortis (1992) Table 1 (Pentax, lenses/fraser-shortis-1992-table1-pentax.csv)
and the paper's text (γ = 1.04, 0.98, 0.97 for 12x with 8x, 16x, 20x); synthetic profiles with
known coefficients.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from orthoscope.cli import main

ROOT = Path(__file__).resolve().parents[1]
PENTAX = ROOT / "lenses" / "fraser-shortis-1992-table1-pentax.csv"
S65 = ["--lens", "super-angulon-de975637", "--scale-to-efl", "65"]


def run(capsys, *argv):
    rc = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return rc, out, err


def run_s65(capsys, objects, *argv):
    """``variation`` in prescription mode: S65 focused at 12x, the objects ``objects``, fields
    to 45°."""
    head = ["variation", *S65, "--focus", "12x", "--objects", objects, "--max-field", "45"]
    return run(capsys, *head, *argv)


def test_help_teaches_units_signs_and_image_scale(capsys):
    assert main(["variation", "--help"]) == 0
    out = " ".join(capsys.readouterr().out.split())
    for needle in (
        "micrometres",
        "positive OUTWARD",
        "magnification -1/N",
        "12x",
        "mm",
        "first principal point H",
        "unit focusing",
    ):
        assert needle in out


def test_pentax_one_focus_setting(capsys):
    # Table 1: one focus setting (8 m), four object planes, no Gaussian profile: no g possible.
    rc, out, err = run(capsys, "variation", PENTAX)
    assert rc == 0 and not err
    assert "one focus setting only (8 m)" in out
    assert "no g_ss' could be determined" in out
    assert "368.80" in out and "362.30" in out  # Table 1 at r = 28 mm: 1.5 m and 3.4 m


def test_pentax_json(capsys):
    rc, out, _ = run(capsys, "variation", PENTAX, "--json")
    d = json.loads(out)
    assert rc == 0 and d["mode"] == "data"
    assert d["variation"]["focal_length_mm"] == 45
    assert len(d["variation"]["profiles"]) == 4


def test_prescription_mode_csv_and_roundtrip(capsys, tmp_path):
    prof = tmp_path / "s65.csv"
    rc, out, err = run_s65(capsys, "8x,16x,20x", "--csv", "--profiles-csv", prof)
    assert rc == 0 and not err
    rows = out.strip().splitlines()
    assert rows[0].startswith("focus,object,gamma,g,se")
    assert len(rows) == 4
    gam = [round(float(r.split(",")[2]), 2) for r in rows[1:]]
    assert gam == [1.04, 0.98, 0.97]  # the paper's text (12x focus; 8x, 16x, 20x)
    g = [float(r.split(",")[3]) for r in rows[1:]]
    assert all(0 < v < 1 for v in g)
    # the written profiles read back in data mode give the same g (same radii: no resampling)
    rc, out2, _ = run(capsys, "variation", prof, "--csv")
    g2 = [float(r.split(",")[3]) for r in out2.strip().splitlines()[1:]]
    np.testing.assert_allclose(g2, g, rtol=1e-8)  # measured 6.8e-10 (the CSV's printed digits)


def test_prescription_mode_text_json_and_plots(capsys, tmp_path):
    p1, p2 = tmp_path / "p.png", tmp_path / "g.png"
    rc, out, _ = run_s65(capsys, "8x,20x", "--plot", p1, "--plot-g", p2)
    assert rc == 0
    assert "Prescription mode" in out and "Brown Eq. (1) prediction" in out
    assert "8×(12×)" in out and "mean g =" in out
    assert p1.stat().st_size > 1000 and p2.stat().st_size > 1000
    rc, out, _ = run_s65(capsys, "8x", "--json")
    d = json.loads(out)
    assert d["mode"] == "prescription" and d["efl_mm"] == pytest.approx(65.0)


@pytest.mark.parametrize(
    "argv, needle",
    [
        (["variation"], "give a CSV"),
        (["variation", PENTAX, "--lens", "cooke-triplet-f4"], "either"),
        (["variation", PENTAX, "--focus", "12x"], "only apply with --lens"),
        (["variation", "--lens", "cooke-triplet-f4", "--objects", "8x"], "needs --focus"),
        (["variation", "--lens", "cooke-triplet-f4", "--focus", "12x"], "needs --objects"),
        (["variation", "--lens", "cooke-triplet-f4", "--focus", "12q", "--objects", "8x"], "'12q'"),
        (
            ["variation", "--lens", "no-such-lens", "--focus", "12x", "--objects", "8x"],
            "no-such-lens",
        ),
        (
            ["variation", "--lens", "cooke-triplet-f4", "--focus", "12x", "--objects", "12x"],
            "one profile",
        ),
        (["variation", "/nonexistent/x.csv"], "cannot read"),
        (["variation", PENTAX, "--threshold-um", "-1"], "threshold"),
        (["coefficients", PENTAX], "--profile"),
        (["coefficients", PENTAX, "--profile", "8,9.9"], "no profile"),
        (["coefficients"], "give a CSV"),
    ],
)
def test_bad_input_exit_2_one_line(capsys, argv, needle):
    rc, out, err = run(capsys, *argv)
    assert rc == 2
    assert out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0]


def test_missing_columns_csv(capsys, tmp_path):
    p = tmp_path / "bad.csv"
    p.write_text("r_mm,dr_um,focus\n1,2,12x\n2,3,12x\n")
    rc, _, err = run(capsys, "variation", p)
    assert rc == 2 and "missing column" in err


def test_coefficients_from_csv_recovers_polynomial(capsys, tmp_path):
    # Exact Gaussian-form profile δr = K1 r^3 + K2 r^5 (mm): the fit must return K1, K2, K3 = 0.
    k1, k2 = -2.0e-5, 3.0e-9
    r = np.linspace(2, 40, 20)
    dr_um = 1000 * (k1 * r**3 + k2 * r**5)
    p = tmp_path / "one.csv"
    p.write_text(
        "r_mm,dr_um,focus,object\n"
        + "".join(f"{float(a)!r},{float(b)!r},12x,12x\n" for a, b in zip(r, dr_um, strict=True))
    )
    rc, out, _ = run(
        capsys,
        "coefficients",
        p,
        "--principal-distance-mm",
        "70",
        "--pixel-pitch-um",
        "5",
        "--json",
    )
    d = json.loads(out)
    assert rc == 0
    # measured: K1 to 2.2e-16, K2 to 1.6e-15 relative, K3 5e-27; bounds ~10x that
    assert d["gaussian_fit"]["K1"] == pytest.approx(k1, rel=1e-14)
    assert d["gaussian_fit"]["K2"] == pytest.approx(k2, rel=2e-14)
    assert abs(d["gaussian_fit"]["K3"]) < 1e-25
    cv = d["opencv"]
    assert cv["fx_px"] == pytest.approx(70 / 0.005)
    assert len(cv["dist_coeffs"]) == 5 and cv["dist_coeffs"][2:4] == [0.0, 0.0]


def test_coefficients_traced(capsys):
    rc, out, _ = run(
        capsys,
        "coefficients",
        *S65,
        "--focus",
        "12x",
        "--max-field",
        "40",
        "--focal-length-px",
        "10000",
        "--json",
    )
    d = json.loads(out)
    assert rc == 0
    c = d["profile"]["principal_distance_mm"]
    # Gaussian plane of 12x: principal distance F0 = p0'/m_e = m0 p0 ≈ f (1 + 1/12) = 70.4 mm
    # when the pupils are near the principal planes (Super-Angulon: nearly symmetric). Measured:
    # c = 70.598 mm, 0.26 % above f (1 + 1/12); tolerance 3 %, ~10x that.
    assert c == pytest.approx(65 * 13 / 12, rel=0.03)
    assert d["opencv"]["pixel_pitch_um"] == pytest.approx(c / 10000 * 1000)
    assert d["gaussian_fit"]["rms_um"] < 1.0
    rc, out, _ = run(capsys, "coefficients", *S65, "--focus", "12x", "--max-field", "40")
    assert rc == 0 and "OpenCV" in out and "K1" in out


# --------------------------------------------------------------------------------------------
# Values in the wrong unit (review 2026-11-27): the Pentax file of Fraser & Shortis (1992,
# Table 1) with one unit changed; each slip is said, not computed through
# --------------------------------------------------------------------------------------------


def _pentax_variant(tmp_path, name, row=lambda c: c, meta=lambda line: line, sep=","):
    """A copy of the Pentax file with every data row mapped by ``row`` (a list of the 4 cells)
    and every metadata line by ``meta``."""
    out = []
    for line in PENTAX.read_text(encoding="utf-8").splitlines():
        if line.startswith("#"):
            out.append(meta(line))
        elif line.startswith("r_mm"):
            out.append(line.replace(",", sep))
        else:
            out.append(sep.join(row(line.split(","))))
    p = tmp_path / name
    p.write_text("\n".join(out) + "\n", encoding="utf-8")
    return p


def _mm(c):
    return [c[0], c[1], str(float(c[2]) * 1000), str(float(c[3]) * 1000)]


def test_distances_in_mm_in_a_profile_csv_warn(capsys, tmp_path):
    p = _pentax_variant(tmp_path, "mm.csv", _mm)
    rc, _, err = run(capsys, "variation", p)
    assert rc == 0  # metres it says; the warning names the file, line, column and the slip
    assert f"{p}:11: focus '8000.0' is read as 8000 m" in err and "looks like millimetres" in err
    assert "object '1500.0' is read as 1500 m" in err


@pytest.mark.parametrize(
    ("name", "variant", "argv", "needle"),
    [
        (  # the focal length in metres
            "fm.csv",
            {"meta": lambda s: s.replace("focal_length_mm: 45", "focal_length_mm: 0.045")},
            [],
            "focal length 0.045 mm is 622 times smaller than the largest radius 28 mm",
        ),
        ("f.csv", {}, ["--focal-length", "0.045"], "is it in metres?"),
        (  # radii in metres: 18.7 µm of distortion at r = 0.008
            "rm.csv",
            {"row": lambda c: [str(float(c[0]) / 1000), *c[1:]]},
            [],
            ":12: distortion 18.7 µm at r = 0.008 mm is as large as the radius",
        ),
        ("semi.csv", {"sep": ";"}, [], "columns separated by ';': separate them with commas"),
        (  # one plane written two ways: the message names both, not a radius twice
            "dup.csv",
            {"row": lambda c: c[:3] + ["1.50" if c[3] == "2.1" else c[3]]},
            [],
            "object 1.50 is the same profile as focus 8, object 1.5 on line 11",
        ),
        ("r.csv", {}, ["--r-min", "20", "--r-max", "10"], "--r-min 20 must be below --r-max 10"),
    ],
)
def test_profile_csv_unit_slips_refused(capsys, tmp_path, name, variant, argv, needle):
    p = _pentax_variant(tmp_path, name, **variant)
    rc, out, err = run(capsys, "variation", p, *argv)
    assert (rc, out) == (2, "")
    assert len(err.strip().splitlines()) == 1 and needle in err


def test_prescription_mode_refuses_a_plane_twice(capsys):
    rc, _, err = run(capsys, "variation", *S65, "--focus", "12x", "--objects", "8x,8.0x")
    assert rc == 2 and "object plane 8.0x is given twice (as 8x)" in err


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (
            ["--principal-distance-mm", "0.045"],
            "principal distance 0.045 mm is 622 times smaller than the largest radius 28 mm",
        ),
        (
            ["--focal-length-px", "9000", "--pixel-pitch-um", "0.005"],
            "pixel pitch 0.005 µm looks like millimetres",
        ),
        (["--principal-distance-mm", "45", "--r-max", "-1"], "--r-max must be positive"),
        (["--principal-distance-mm", "45", "--r-max", "1"], "--r-max 1 mm keeps no point"),
    ],
)
def test_coefficients_unit_slips_refused(capsys, argv, needle):
    rc, out, err = run(capsys, "coefficients", PENTAX, "--profile", "8,1.5", *argv)
    assert (rc, out) == (2, "")
    assert len(err.strip().splitlines()) == 1 and needle in err


def test_coefficients_r_max_cuts_a_csv_profile(capsys):
    # --r-max was applied only to traced profiles; the Pentax 1.5 m profile has 7 radii to 28 mm
    rc, out, _ = run(capsys, "coefficients", PENTAX, "--profile", "8,1.5", "--json")
    rc2, out2, _ = run(
        capsys, "coefficients", PENTAX, "--profile", "8,1.5", "--r-max", "16", "--json"
    )
    assert rc == rc2 == 0
    full, cut = json.loads(out)["profile"]["r_mm"], json.loads(out2)["profile"]["r_mm"]
    assert max(full) > 16 and cut == [r for r in full if r <= 16]


def test_prescription_json_writes_an_infinite_scale_as_inf(capsys):
    # README, "JSON output": infinite values are the strings "inf" / "-inf", values that do not
    # exist are null. The image scale number N = s/f - 1 (distortion/variation/models.py) of an
    # object at infinity is infinite; the variation JSON wrote it as null.
    rc, out, _ = run(
        capsys, "variation", "--lens", "cooke-triplet-f4", "--focus", "2m", "--objects",
        "inf,1m,5m", "--json",
    )  # fmt: skip
    assert rc == 0
    gammas = json.loads(out)["variation"]["gamma"]
    at_inf = [g for g in gammas if g["object"]["value"] == "inf"]
    assert at_inf and all(g["scale_object"] == "inf" for g in at_inf)
    assert all(isinstance(g["scale_object"], float) for g in gammas if g not in at_inf)
