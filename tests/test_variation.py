"""Distortion variation models and the measured-data mode (Fraser & Shortis 1992, PE&RS 58(6)).

Sources written beside the numbers: the paper's text (γ values), its Tables 1–3 (copied into
lenses/ and tests/data/), and analytic constructions (synthetic profiles that follow a model).
"""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np
import pytest

from distortion.errors import DataError
from distortion.variation.analysis import (
    Profile,
    ProfileSet,
    analyze_variation,
    brown_implied_gaussian,
    estimate_g,
    summarize_g,
)
from distortion.variation.models import (
    Conjugate,
    brown_alpha,
    brown_alpha_scales,
    brown_gamma,
    brown_gamma_scales,
    brown_interpolate,
    distance_from_scale,
    fs_predict,
    scale_from_distance,
)
from distortion.variation.profiles import analyze_csv, read_profiles_csv
from orthoscope.plots.save import save_figure
from orthoscope.report.variation import format_g_table, format_variation, variation_to_dict

ROOT = Path(__file__).resolve().parents[1]
DATA = Path(__file__).parent / "data"
PENTAX = ROOT / "lenses" / "fraser-shortis-1992-table1-pentax.csv"

# --------------------------------------------------------------------------------------------
# Brown Eq. (1)-(4)
# --------------------------------------------------------------------------------------------


def test_brown_gamma_n120_paper_text():
    # Fraser & Shortis 1992, text under Fig. 2: f = 120 mm (N120) focused at 12x, object planes
    # 8x, 16x, 20x: "γ_ss' factors of 1.04, 0.98, and 0.97, respectively".
    f = 120.0
    s = distance_from_scale(12, f)  # thin lens, unit focusing: s = f(1 + N) = 1560 mm
    assert s == pytest.approx(1560.0)
    for n_obj, expected in ((8, 1.04), (16, 0.98), (20, 0.97)):
        gamma = brown_gamma(s, distance_from_scale(n_obj, f), f)
        assert round(gamma, 2) == expected
        assert brown_gamma_scales(12, n_obj) == pytest.approx(gamma, rel=1e-14)


def test_brown_gamma_limits_and_identity():
    # Eq. (2): γ_ss = 1; s = ∞ → s'/(s' − f); s' = ∞ → (s − f)/s.
    assert brown_gamma(1000.0, 1000.0, 50.0) == pytest.approx(1.0)
    assert brown_gamma(math.inf, 1000.0, 50.0) == pytest.approx(1000.0 / 950.0)
    assert brown_gamma(1000.0, math.inf, 50.0) == pytest.approx(950.0 / 1000.0)
    assert scale_from_distance(1560.0, 120.0) == pytest.approx(12.0)
    with pytest.raises(DataError, match="not beyond the focal length"):
        brown_gamma(100.0, 1000.0, 120.0)


def test_brown_alpha_endpoints_and_scale_form():
    # Eq. (4): α = 1 at s = s1, 0 at s = s2; the scale form equals the distance form.
    f = 65.0
    s1, s2, s = (distance_from_scale(n, f) for n in (8, 20, 12))
    assert brown_alpha(s1, s1, s2, f) == pytest.approx(1.0)
    assert brown_alpha(s2, s1, s2, f) == pytest.approx(0.0, abs=1e-15)
    direct = (s2 - s) / (s2 - s1) * (s1 - f) / (s - f)
    assert brown_alpha(s, s1, s2, f) == pytest.approx(direct, rel=1e-14)
    assert brown_alpha_scales(12, 8, 20) == pytest.approx(direct, rel=1e-14)


def test_brown_interpolation_exact_for_its_model():
    # Analytic: Eq. (4) is linear interpolation in 1/(s − f), so profiles
    # δr_s(r) = A(r) + B(r)/(s − f) are reproduced exactly by Eq. (3).
    f = 120.0
    r = np.linspace(0.0, 140.0, 29)
    a = 25.0 * (r / 100) ** 3 - 8.0 * (r / 100) ** 5
    b = 5.0e4 * ((r / 100) ** 3 - 0.7 * (r / 100) ** 5)

    def prof(s):
        return a + b / (s - f)

    s1, s2 = distance_from_scale(8, f), distance_from_scale(20, f)
    for n in (10.0, 12.0, 16.0, 30.0):
        s = distance_from_scale(n, f)
        pred = brown_interpolate(prof(s1), prof(s2), brown_alpha(s, s1, s2, f))
        np.testing.assert_allclose(pred, prof(s), rtol=0, atol=1e-11)


# --------------------------------------------------------------------------------------------
# Tables 2 and 3: mean g and its precision
# --------------------------------------------------------------------------------------------


def _read_table(name):
    with open(DATA / name, encoding="utf-8") as fh:
        rows = list(csv.reader(line for line in fh if not line.startswith("#")))
    head, body = rows[0], rows[1:]
    return [dict(zip(head, r, strict=True)) for r in body]


@pytest.mark.parametrize(
    ("name", "planes", "mean", "precision"),
    [
        # Table 2 caption: "Overall mean value for g_ss' is 0.44 with a precision of 0.02".
        ("fraser_shortis_1992_table2_n120.csv", ("8x", "16x", "20x"), 0.44, 0.02),
        # Table 3 caption: "Overall mean value for g_ss' is 0.31 with a precision of 0.04".
        ("fraser_shortis_1992_table3_r240.csv", ("10x", "16x", "20x"), 0.31, 0.04),
    ],
)
def test_tables_2_3_overall_mean_and_precision(name, planes, mean, precision):
    rows = _read_table(name)
    assert len(rows) == 8
    lens_means = []
    for row in rows:
        s = summarize_g([float(row[f"g_{p}"]) for p in planes])
        # the printed per-lens mean comes from unrounded g values: three values rounded to 0.01
        # give a mean within 0.005, the printed mean is itself rounded (another 0.005)
        assert abs(s.mean - float(row["mean"])) <= 0.01 + 1e-12
        lens_means.append(s.mean)
    overall = summarize_g(lens_means)
    assert round(overall.mean, 2) == mean
    # the paper's "precision" is the standard deviation over the eight lenses (text: "An overall
    # mean value and standard deviation are additionally given"); the standard error of the mean
    # would round differently (0.01 for both tables), so the test tells the two apart.
    assert round(overall.precision, 2) == precision
    assert round(overall.sem, 2) != precision
    # the same from the printed per-lens means
    printed = summarize_g([float(r["mean"]) for r in rows])
    assert (round(printed.mean, 2), round(printed.precision, 2)) == (mean, precision)


# --------------------------------------------------------------------------------------------
# Eq. (6): estimation of g
# --------------------------------------------------------------------------------------------

R = np.arange(0.0, 145.0, 5.0)


def _gauss_profile(n: float) -> np.ndarray:
    """Synthetic Gaussian profile (µm) at image scale n, following Brown's Eq. (3)–(4) model."""
    u = R / 100.0
    return 20.0 * u**3 - 6.0 * u**5 + (600.0 * u**3 - 350.0 * u**5) / n


def test_g_recovered_within_standard_error_coverage():
    # Synthetic: δr_ss' = δr_s + g(δr_s' − δr_s) exactly, then independent Gaussian noise of
    # σ = 0.3 µm on each of the three profiles; 300 fixed seeds. A correct standard error
    # covers the true g in ≈68 % (1σ) and ≈95 % (2σ) of the trials.
    g_true, sigma = 0.44, 0.3
    dr_s, dr_sp = _gauss_profile(12), _gauss_profile(8)
    within1 = within2 = 0
    n_trials = 300
    for seed in range(n_trials):
        rng = np.random.default_rng(seed)
        noisy = [p + rng.normal(0.0, sigma, R.size) for p in (dr_s, dr_sp)]
        ss = fs_predict(dr_s, dr_sp, g_true) + rng.normal(0.0, sigma, R.size)
        e = estimate_g(R, noisy[0], noisy[1], ss)
        assert e.determined
        z = abs(e.g - g_true) / e.se
        within1 += z <= 1.0
        within2 += z <= 2.0
    # binomial SD of a 68 % rate over 300 trials is 2.7 %: accept ±3 SD
    assert 0.60 <= within1 / n_trials <= 0.76
    assert within2 / n_trials >= 0.90


def test_g_exact_without_noise_both_methods():
    # Analytic: noise-free Eq. (6) profiles give g exactly and zero standard error.
    dr_s, dr_sp = _gauss_profile(12), _gauss_profile(20)
    ss = fs_predict(dr_s, dr_sp, 0.31)
    for method in ("lsq", "mean"):
        e = estimate_g(R, dr_s, dr_sp, ss, method=method)
        assert e.g == pytest.approx(0.31, abs=1e-12)
        assert e.se == pytest.approx(0.0, abs=1e-10)
        # small radii where the profiles differ by < 0.5 µm are excluded and reported
        assert e.n_excluded > 0
        assert np.all(np.abs(dr_sp - dr_s)[e.weak] < 0.5)
        assert 0.0 in e.excluded_r_mm


def test_identical_focus_profiles_are_undetermined():
    # δr_s' = δr_s everywhere: Eq. (6) has no leverage; reported, never divided by zero.
    dr = _gauss_profile(12)
    with np.errstate(all="raise"):
        e = estimate_g(R, dr, dr.copy(), dr + 1.0)
    assert e.status == "undetermined"
    assert not e.determined
    assert math.isnan(e.g) and math.isnan(e.se)
    assert "undetermined" in e.message
    assert e.n_used == 0 and e.n_excluded == R.size


# --------------------------------------------------------------------------------------------
# Measured-data mode
# --------------------------------------------------------------------------------------------


def _write_csv(path: Path, rows, header="r_mm,dr_um,focus,object", meta=()):
    lines = [f"# {m}" for m in meta] + [header] + [",".join(map(str, r)) for r in rows]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def _synthetic_rows(g_true=0.45, radii=R, noise=0.0, seed=0):
    """N120-like data set: Gaussian profiles at 8x, 12x, 16x, 20x and object planes 8x, 16x, 20x
    with the lens focused at 12x, following Eq. (6) with g_true."""
    rng = np.random.default_rng(seed)
    rows = []
    base = {n: _gauss_profile(n) for n in (8, 12, 16, 20)}
    for n, prof in base.items():
        rows += [(r, f"{d:.6f}", f"{n}x", f"{n}x") for r, d in zip(radii, prof, strict=True)]
    for n in (8, 16, 20):
        ss = fs_predict(base[12], base[n], g_true) + rng.normal(0.0, noise, radii.size)
        rows += [(r, f"{d:.6f}", "12x", f"{n}x") for r, d in zip(radii, ss, strict=True)]
    return rows


def test_analysis_of_synthetic_csv(tmp_path):
    # Synthetic data following Eq. (6) with g = 0.45 and Brown's Eq. (3)–(4) model exactly.
    path = _write_csv(tmp_path / "n120.csv", _synthetic_rows(0.45))
    a = analyze_csv(path, r_min=20.0, r_max=140.0)  # the paper's radial range
    assert len(a.focus_summaries) == 1
    fs = a.focus_summaries[0]
    assert fs.focus.label == "12×"
    assert [p.obj.label for p in fs.planes] == ["8×", "16×", "20×"]
    for p in fs.planes:
        assert p.estimate.g == pytest.approx(0.45, abs=1e-6)
        assert p.rms_mean_g_um == pytest.approx(0.0, abs=1e-5)
        assert p.estimate.r_mm.min() >= 20.0 and p.estimate.r_mm.max() <= 140.0
    assert fs.summary.mean == pytest.approx(0.45, abs=1e-6)
    # γ from the paper's text for 12x focus (f-independent in image scales)
    assert [round(g.gamma, 2) for g in a.gammas] == [1.04, 0.98, 0.97]
    # Brown's Eq. (1) prediction is computed and, for data following Eq. (6), is far off
    assert len(a.brown) == 3 and all(b.rms_um > 1.0 for b in a.brown)
    # Eq. (3)-(4) check: 12x from 8x and 16x, 16x from 12x and 20x; exact for this model
    assert len(a.interpolation_checks) == 2
    assert all(c.rms_um < 1e-5 for c in a.interpolation_checks)
    text = format_variation(a)
    assert "Fraser–Shortis Eq. (6), focus 12×" in text and "0.450" in text
    json.dumps(variation_to_dict(a), allow_nan=False)
    table = format_g_table([("1", fs), ("2", fs)])
    assert "0.45" in table and "Overall mean g = 0.45" in table


def test_profiles_at_different_radii_are_interpolated(tmp_path):
    # Profiles sampled at different radii (as at different image scales): the Gaussian
    # profiles are sampled at a grid offset by 2.5 mm, the object-plane profiles at R.
    # PCHIP interpolation of these smooth curves, noise-free, returns g = 0.45 to within the
    # interpolation error (measured: |Δg| ≤ 4.2e-4 for the three planes; bound 1e-3).
    rows = []
    r_off = np.arange(-2.5, 150.0, 5.0).clip(0.0)
    u = r_off / 100.0
    for n in (8, 12, 16, 20):
        prof = 20.0 * u**3 - 6.0 * u**5 + (600.0 * u**3 - 350.0 * u**5) / n
        rows += [
            (r, f"{d:.6f}", f"{n}x", f"{n}x") for r, d in zip(r_off[1:], prof[1:], strict=True)
        ]
    base = {n: _gauss_profile(n) for n in (8, 12, 16, 20)}
    for n in (8, 16, 20):
        ss = fs_predict(base[12], base[n], 0.45)
        rows += [(r, f"{d:.6f}", "12x", f"{n}x") for r, d in zip(R, ss, strict=True)]
    a = analyze_csv(_write_csv(tmp_path / "offset.csv", rows), r_min=20.0, r_max=140.0)
    for p in a.focus_summaries[0].planes:
        assert abs(p.estimate.g - 0.45) < 1e-3
        assert "PCHIP" in a.interpolation


def test_undetermined_plane_in_analysis(tmp_path):
    # Gaussian profile at the object plane identical to that at the focus: undetermined,
    # reported in the messages, others still estimated.
    rows = _synthetic_rows(0.4)
    prof12 = _gauss_profile(12)
    rows = [r for r in rows if r[2:] != ("16x", "16x")]
    rows += [(r, f"{d:.6f}", "16x", "16x") for r, d in zip(R, prof12, strict=True)]
    a = analyze_csv(_write_csv(tmp_path / "u.csv", rows))
    planes = {p.obj.label: p for p in a.focus_summaries[0].planes}
    assert planes["16×"].estimate.status == "undetermined"
    assert math.isnan(planes["16×"].estimate.g)
    assert planes["8×"].estimate.g == pytest.approx(0.4, abs=1e-6)
    assert a.focus_summaries[0].summary.n == 2
    assert any("16×(12×)" in m and "undetermined" in m for m in a.messages)
    json.dumps(variation_to_dict(a), allow_nan=False)


def test_pentax_table1_one_focus_setting():
    # Fraser & Shortis Table 1 (Pentax 645VL, 45 mm, fixed focus 8 m; object planes 1.5, 2.1,
    # 2.6, 3.4 m): one focus setting, no profile at the focus -> no g, no Brown prediction,
    # γ computable, within-field variation available.
    ps = read_profiles_csv(PENTAX)
    assert ps.focal_length_mm == 45.0
    assert len(ps.profiles) == 4
    a = analyze_variation(ps)
    assert a.focus_summaries == () and a.brown == ()
    # image scales N = s/f − 1 (thin lens, unit focusing): 1500/45 − 1 = 32.3, 2100/45 − 1 =
    # 45.7, 2600/45 − 1 = 56.8, 3400/45 − 1 = 74.6 — analytic; the paper's text rounds them to
    # "approximately 33x, 45x, 56x, and 75x" (and 8000/45 − 1 = 176.8 to "175x"), i.e. the
    # expected list below is our formula, within ±1 of the paper's approximate values
    scales = [g.scale_object for g in a.gammas]
    assert [round(s) for s in scales] == [32, 46, 57, 75]
    assert max(abs(s - p) for s, p in zip(scales, (33, 45, 56, 75), strict=True)) < 1.0
    assert a.gammas[0].scale_focus == pytest.approx(8000 / 45 - 1)
    assert all(1.0 < g.gamma < 1.03 for g in a.gammas)
    # within-field variation: Table 1 at r = 28 mm, 369.5 (2.1 m) − 362.3 (3.4 m) = 7.2 µm
    fv = a.field_variation[0]
    assert fv.r_mm[-1] == 28.0
    assert fv.spread_um[-1] == pytest.approx(369.5 - 362.3)
    assert fv.spread_um[0] == pytest.approx(2.5 - 2.4)  # Table 1 at r = 4 mm: 2.5 (2.1 m) − 2.4
    text = " ".join(a.messages)
    assert "one focus setting only (8 m)" in text
    assert "g_ss' needs profiles at two focus settings" in text
    assert "no g_ss' could be determined" in text
    implied = brown_implied_gaussian(a)
    # Table 1, r = 28 mm, object plane 1.5 m: 368.8 um
    assert implied["1.5 m (8 m)"][-1] == pytest.approx(368.8 * a.gammas[0].gamma)
    json.dumps(variation_to_dict(a), allow_nan=False)


def test_plots_written(tmp_path):
    from orthoscope.plots.variation import plot_g, plot_profiles

    a = analyze_csv(_write_csv(tmp_path / "n.csv", _synthetic_rows(0.45, noise=0.2)))
    p1, p2 = tmp_path / "profiles.png", tmp_path / "g.png"
    fig1 = plot_profiles(a)
    save_figure(fig1, p1)
    fig2 = plot_g(a)
    save_figure(fig2, p2)
    assert p1.stat().st_size > 10_000 and p2.stat().st_size > 10_000
    assert fig1.axes[0].get_xlabel() == "radial distance r (mm)"
    assert "µm" in fig1.axes[0].get_ylabel()
    labels = [t.get_text() for t in fig1.axes[0].get_legend().get_texts()]
    assert "8×(12×)" in labels and "12×" in labels
    assert "g_{ss'}" in fig2.axes[0].get_ylabel()


# --------------------------------------------------------------------------------------------
# Bad input
# --------------------------------------------------------------------------------------------


def _read_fails(path: Path) -> str:
    """The message of the DataError that reading the profiles CSV ``path`` raises."""
    with pytest.raises(DataError) as ei:
        read_profiles_csv(path)
    return str(ei.value)


def test_csv_missing_focus_object_columns(tmp_path):
    path = _write_csv(tmp_path / "a.csv", [(1, 2.0), (2, 3.0)], header="r_mm,dr_um")
    msg = _read_fails(path)
    assert msg.startswith(f"{path}:1:")
    assert "missing column(s) 'focus', 'object'" in msg


def test_csv_unit_not_stated(tmp_path):
    path = _write_csv(tmp_path / "b.csv", [(1, 2.0, 8, 8)], header="r,dr,focus,object")
    with pytest.raises(DataError, match=r"'r_mm' \(state the unit: 'r_mm'\)"):
        read_profiles_csv(path)


def test_csv_single_profile(tmp_path):
    path = _write_csv(tmp_path / "c.csv", [(10, 2.0, "12x", "8x"), (20, 5.0, "12x", "8x")])
    msg = _read_fails(path)
    assert "1 profile(s) (focus 12x, object 8x)" in msg
    assert "needs at least two profiles" in msg


def test_csv_mixed_units_in_a_column(tmp_path):
    rows = [(10, 2.0, "12x", "8x"), (20, 5.0, "12x", "8x"), (10, 2.0, "12x", 1.5)]
    path = _write_csv(tmp_path / "d.csv", rows)
    msg = _read_fails(path)
    assert msg.startswith(f"{path}:4:")
    assert "column 'object' mixes units: metres ('1.5') here, image scales ('8x') on line 2" in msg


def test_csv_non_numeric(tmp_path):
    rows = [(10, 2.0, "12x", "8x"), (20, "abc", "12x", "8x")]
    path = _write_csv(tmp_path / "e.csv", rows)
    with pytest.raises(DataError, match=r"e\.csv:3: column 'dr_um': 'abc' is not a number"):
        read_profiles_csv(path)


def test_mixed_units_across_columns_need_focal_length(tmp_path):
    rows = [(10, 2.0, 8, "12x"), (20, 5.0, 8, "12x"), (10, 2.5, 8, "20x"), (20, 5.5, 8, "20x")]
    path = _write_csv(tmp_path / "f.csv", rows)
    with pytest.raises(DataError, match="focal length is needed"):
        analyze_csv(path)


def test_profile_set_in_memory_needs_two_profiles():
    p = Profile(Conjugate.scale(12), Conjugate.scale(8), R, _gauss_profile(8))
    with pytest.raises(DataError, match="at least two profiles"):
        analyze_variation(ProfileSet((p,)))


def test_analyze_variation_takes_a_path_and_checks_its_options(tmp_path):
    path = _write_csv(tmp_path / "n120.csv", _synthetic_rows(0.45))
    a = analyze_variation(str(path), r_min=20.0, r_max=140.0)
    assert [p.estimate.g for p in a.focus_summaries[0].planes] == pytest.approx([0.45] * 3)
    with pytest.raises(TypeError, match="a ProfileSet or the path of a profile CSV"):
        analyze_variation([1, 2])
    for kw, msg in (
        ({"r_min": 100.0, "r_max": 20.0}, "r_min=100 must be below r_max=20"),
        ({"threshold_um": math.nan}, "threshold_um= must be >= 0"),
        ({"threshold_um": -1.0}, "threshold_um= must be >= 0"),
    ):
        with pytest.raises(DataError, match=msg):
            analyze_variation(path, **kw)
