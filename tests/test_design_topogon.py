"""The derived lens ``topogon-like-pestrecov`` against Pestrecov 1958 (issue 4, section 2).

Targets (the issue): EFL = F0 = 153.706 mm (four air-spaced menisci about a central stop; the
shipped formula has even-asphere terms on its four outer surfaces, see the spec); traced
characteristic distortion D0 (object at infinity, Gaussian image plane) within 0.002 mm of
Table I at the nine angles; the two-point calibration at 37.5 and 45 deg gives F_c within
0.002 mm of Table II's 154.059 mm and D_c within 0.002 mm of Table II. Table I / II numbers:
tests/data/pestrecov_table1.csv and pestrecov_table2.csv (source: K. Pestrecov,
Photogrammetric Engineering 1958, Tables I and II).

The second library entry ``topogon-like-spherical`` (issue 19, item 4) is the same construction
with spherical surfaces only and catalog glasses, designed by the minimax spec
lenses/specs/topogon-like-spherical.toml; it misses the 3 µm target at seven of the nine angles
(max 5.90 µm), and the tests below hold each Table I entry to its measured error with the reason,
check the spec's operands against an independent trace and re-run the spec (section
"all-spherical lens"). The third, ``topogon-like-spherical-heights``, has the same construction,
glasses and rules, designed to Table I's image heights (F0 tan alpha + D0) with its EFL free;
its EFL is not the table's (section "all spherical, to image heights"). It meets 3 µm per entry
measured against the table's F0; Table II by two-point calibration to 3.72 µm. The edge and
|c| h rules, which both specs hold through fixed-height stand-ins, are checked at each lens's own
real-ray footprints.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from support import rim_footprints

from distortion.calibration import calibrate
from distortion.characteristic import characteristic_distortion
from distortion.tablefile import read_distortion_table
from raytrace.files.library import load_lens
from raytrace.optimize import apply, evaluate, merit, optimize, read_spec, start_lens
from raytrace.paraxial import paraxial

DATA = Path(__file__).parent / "data"
SPEC = Path(__file__).parents[1] / "lenses" / "specs" / "topogon-like-pestrecov.toml"
SPHERICAL_SPEC = Path(__file__).parents[1] / "lenses" / "specs" / "topogon-like-spherical.toml"
HEIGHTS_SPEC = SPHERICAL_SPEC.with_name("topogon-like-spherical-heights.toml")
SPHERICAL_NAMES = ("topogon-like-spherical", "topogon-like-spherical-heights")
SPECS = {"topogon-like-spherical": SPHERICAL_SPEC, "topogon-like-spherical-heights": HEIGHTS_SPEC}
F0 = 153.706  # Pestrecov 1958 Table I heading: F0 = EFL = 153.706 mm
FC = 154.059  # Pestrecov 1958 Table II heading: F_c = 154.059 mm


def _lens_and_curve(name: str, lens_fixture: str, curve_fixture: str):
    """Two module-scoped fixtures: ``lens_fixture``, the library lens ``name``, and
    ``curve_fixture``, curve 0 of its characteristic distortion at Table I's angles."""

    @pytest.fixture(scope="module", name=lens_fixture)
    def library_lens():
        return load_lens(name)

    @pytest.fixture(scope="module", name=curve_fixture)
    def curve(request, table1):
        lens = request.getfixturevalue(lens_fixture)
        return characteristic_distortion(lens, table1.fields).curve(0)

    return library_lens, curve


lens, traced = _lens_and_curve("topogon-like-pestrecov", "lens", "traced")


@pytest.fixture(scope="module")
def table1():
    return read_distortion_table(DATA / "pestrecov_table1.csv", F0)


@pytest.fixture(scope="module")
def table2():
    return np.loadtxt(DATA / "pestrecov_table2.csv", delimiter=",", comments="#", skiprows=4)


def test_efl_is_table1_f0(lens):
    assert paraxial(lens).efl == pytest.approx(F0, abs=1e-3)


def test_d0_reproduces_table1(traced, table1):
    err = traced.D0 - table1.D0
    assert np.max(np.abs(err)) <= 0.002, f"D0 - Table I (mm): {np.round(err, 4)}"


def test_two_point_calibration_reproduces_table2(traced, table2):
    cal = calibrate(traced, "two-point", at=(37.5, 45))
    assert cal.Kc == pytest.approx(FC, abs=0.002)
    np.testing.assert_allclose(cal.curve.fields, table2[:, 0])
    err = cal.Dc - table2[:, 2]
    assert np.max(np.abs(err)) <= 0.002, f"D_c - Table II (mm): {np.round(err, 4)}"


def test_lens_is_four_menisci_about_a_central_stop(lens):
    s = lens.surfaces
    assert len(s) == 9 and s[4].stop and s[4].curvature == 0.0
    glass = [i for i, x in enumerate(s) if not x.material.is_air]
    assert glass == [0, 2, 5, 7]
    for i in glass:  # menisci: both radii of one sign
        assert s[i].curvature * s[i + 1].curvature > 0
        assert s[i].thickness >= 1.0 - 1e-12
    for i in (1, 6):
        assert s[i].thickness >= 0.1


def test_optimizer_converges_back_from_a_perturbed_start(lens):
    """The spec's optimizer problem has the shipped lens at its minimum: from a start perturbed by
    2e-4 (relative) in every variable, damped least squares returns to the shipped merit
    (regression pin: the shipped merit; the full design run from the patent start lens takes
    about 2 minutes and is described in lenses/specs/topogon-like-pestrecov.toml). A small
    problem (issue 19 item 5): the spec's operands with ten of its variables, the A4 and A6
    terms of the four outer surfaces (the only optimizer test of aspheric variables) and the
    outer curvatures (surfaces 1 and 9), about 4 s; all 24 variables took about 40 s and 8,560
    evaluations, and also ended below the shipped merit."""
    from dataclasses import replace

    from raytrace.optimize.solver import get_value

    spec = read_spec(SPEC)
    kept = [v for v in spec.variables if v.kind in ("A4", "A6")]
    kept += [v for v in spec.variables if v.kind == "curvature" and v.surface in (1, 9)]
    assert len(kept) == 10
    spec = replace(spec, variables=tuple(kept))
    shipped = merit(evaluate(lens, spec.operands))
    x = np.array([get_value(lens, v.kind, v.surface) for v in spec.variables])
    signs = np.where(np.arange(x.size) % 2 == 0, 1.0, -1.0)
    start = apply(lens, spec, x * (1.0 + 2e-4 * signs))
    assert merit(evaluate(start, spec.operands)) > 10 * shipped
    res = optimize(start, replace(spec, max_evaluations=400, merit_goal=None))
    assert res.merit <= 1.05 * shipped


# --------------------------------------------------------------------------- all-spherical lens
# lenses/topogon-like-spherical.toml (issue 19, item 4): four spherical menisci in catalog glass,
# the result of the minimax spec lenses/specs/topogon-like-spherical.toml (2026-11-27; it replaced
# the 2026-11-23 scratch-script design, 6.54 µm, whose rounding is the spec's start lens). It
# misses the 3 µm target at seven of Table I's nine angles: a minimax optimum, its errors
# are equal (5.90 µm) at five angles. The per-angle bounds below are the shipped lens's measured
# errors (REGRESSION PINS: our own design run, 2026-11-27, not published numbers) plus 0.05 µm,
# rounded up to 0.1 µm, each with its reason; the entries that meet 3 µm are held to 3 µm.
SPHERICAL_TABLE1_ERR_UM = {  # angle: (bound on |D0 - Table I| in µm, measured D0 - Table I)
    10.0: (6.0, -5.90),  # known miss: Table I's slow rise at 10-20 deg (see the lens notes)
    20.0: (5.9, -5.79),  # known miss: idem
    25.0: (3.0, +1.64),
    30.0: (6.0, +5.90),  # known miss: the t^3..t^9 minimax floor peaks here too (+6.70)
    35.0: (5.6, -5.46),  # known miss: the turn-over between 37.5 and 45 deg
    37.5: (6.0, -5.90),  # known miss: idem
    40.0: (3.3, +3.16),  # known miss: idem
    42.5: (6.0, +5.90),  # known miss: idem
    45.0: (3.0, +1.00),  # held >= +1 µm by the spec (its stand-in for Table II's F_c)
}
SPHERICAL_MAX_ERR_UM = 5.903  # regression pin: the spec's minimax merit on the shipped lens


spherical, spherical_traced = _lens_and_curve(
    "topogon-like-spherical", "spherical", "spherical_traced"
)


@pytest.mark.parametrize("name", SPHERICAL_NAMES)
def test_spherical_lens_is_four_spherical_menisci_in_catalog_glass(name):
    from raytrace.glass import lookup_glass

    spherical = load_lens(name)
    s = spherical.surfaces
    assert len(s) == 9 and s[4].stop and s[4].curvature == 0.0
    glass = [i for i, x in enumerate(s) if not x.material.is_air]
    assert glass == [0, 2, 5, 7]
    for x in s:  # spherical: no conic, no aspheric terms
        assert x.conic == 0.0 and not any(x.aspheric)
    for i in glass:
        m = s[i].material
        # a real catalog glass, the vendor's formula (not an nd/vd model glass)
        assert m.kind == "catalog"
        assert m == lookup_glass(m.name, [m.catalog]).material
    assert [s[i].material.name for i in glass] == ["N-SK11", "F2", "N-LAK12", "N-SF14"]
    # the Topogon construction (US 2,031,792): menisci concave toward the stop (front group
    # c > 0, rear group c < 0), outer elements positive, inner elements negative and thin
    n = [s[i].material.index(spherical.wavelength) for i in glass]
    for k, i in enumerate(glass):
        c1, c2, t = s[i].curvature, s[i + 1].curvature, s[i].thickness
        assert c1 * c2 > 0 and (c1 > 0) == (i < 4)
        power = (n[k] - 1) * (c1 - c2) + (n[k] - 1) ** 2 * t * c1 * c2 / n[k]
        assert (power > 0) == (k in (0, 3))
        assert t >= 1.2 - 1e-9  # shop rule of the design: negative elements >= 1.2 mm
        if k in (1, 2):
            assert t <= 3.0
    for i in (1, 6):  # the outer air spaces: thin, as in the patent
        assert 0.05 <= s[i].thickness <= 5.0
    # nearly symmetric about the stop (the notes' type rules): mirrored curvatures and the two
    # stop spaces within a factor 1.6
    for a, b in ((0, 8), (1, 7), (2, 6), (3, 5)):
        assert 1 / 1.6 <= s[a].curvature / -s[b].curvature <= 1.6, (a + 1, b + 1)
    assert 1 / 1.6 - 1e-12 <= s[3].thickness / s[4].thickness <= 1.6 + 1e-12


def test_spherical_efl_is_table1_f0(spherical):
    assert paraxial(spherical).efl == pytest.approx(F0, abs=1e-3)


@pytest.mark.parametrize("angle", sorted(SPHERICAL_TABLE1_ERR_UM))
def test_spherical_d0_per_table1_entry(spherical_traced, table1, angle):
    i = int(np.flatnonzero(np.isclose(table1.fields, angle))[0])
    err_um = 1e3 * (spherical_traced.D0[i] - table1.D0[i])
    bound, measured = SPHERICAL_TABLE1_ERR_UM[angle]
    assert abs(err_um) <= bound, f"D0 - Table I at {angle} deg: {err_um:+.2f} um"
    assert err_um == pytest.approx(measured, abs=0.05)  # regression pin of the shipped design


def test_spherical_two_point_calibration_near_table2(spherical_traced, table2):
    # Table II follows Table I: F_c within 3 µm of 154.059; D_c within the Table I misses
    # (measured, regression pins: F_c = 154.0568 mm, max |D_c - Table II| = 7.9 µm at 42.5 deg)
    cal = calibrate(spherical_traced, "two-point", at=(37.5, 45))
    assert cal.Kc == pytest.approx(FC, abs=0.003)
    err = cal.Dc - table2[:, 2]
    assert np.max(np.abs(err)) <= 0.008, f"D_c - Table II (mm): {np.round(err, 4)}"


def test_spherical_spec_operands_match_an_independent_trace(spherical, spherical_traced, table1):
    """The spec's operands, evaluated on the shipped lens: its distortion residuals (weight 1000
    per mm: µm) are this file's own D0 - Table I (characteristic_distortion, an independent code
    path) to 1e-3 µm, its targets are Table I, and every bound operand (the constraints: EFL, the
    D0(45) stand-in, RMS spot caps, BFL, edge thicknesses) is met."""
    spec = read_spec(SPHERICAL_SPEC)
    values = evaluate(spherical, spec.operands)
    err_um = {
        float(a): 1e3 * (d - t)
        for a, d, t in zip(table1.fields, spherical_traced.D0, table1.D0, strict=True)
    }
    targets = [v for v in values if v.operand.type == "distortion" and not v.operand.bounded]
    assert sorted(v.operand.params["field"] for v in targets) == sorted(SPHERICAL_TABLE1_ERR_UM)
    for v in targets:
        a = float(v.operand.params["field"])
        i = int(np.flatnonzero(np.isclose(table1.fields, a))[0])
        assert v.operand.target == pytest.approx(table1.D0[i], abs=1e-12)  # Table I itself
        assert v.operand.weight == 1000.0
        assert v.residual == pytest.approx(err_um[a], abs=1e-3), a
    assert max(abs(v.residual) for v in targets) == pytest.approx(SPHERICAL_MAX_ERR_UM, abs=1e-3)
    bounds = [v for v in values if v.operand.bounded]
    assert len(bounds) == len(values) - len(targets)
    for v in bounds:
        lo, hi = v.operand.limits
        violation = max(lo - v.value, v.value - hi, 0.0)
        assert violation <= 1e-9 and abs(v.residual) <= 1e-9, (v.operand, v.value)


#: How close a design re-run lands to the shipped lens, per curvature and thickness (relative).
#: The minimax optimum is flat, and where the run ends on it depends on the machine's floating
#: point (numba's code for the host CPU, the BLAS/LAPACK kernels scipy picks for it) and on the
#: numpy/scipy versions. Observed: within 1e-6 in the earlier sessions' runs and CI; on an AMD
#: EPYC VM (2026-11-28) 3.0e-5 in one thickness of the heights design (1.30934 against 1.30938
#: mm: 39 nm) with numpy 2.4 / scipy 1.17, and 1.0e-6 (one curvature) with Python 3.13, numpy
#: 2.5, scipy 1.18; on the oldest declared stack (numpy 1.24, scipy 1.10) 4e-6 and 1e-5.
#: 1e-4 keeps a margin over these: the same lens to four significant digits (far below any
#: shop tolerance), with the same max error (checked to 0.01 µm and 0.001 µm).
REPRODUCE_REL = 1e-4


def test_spherical_design_is_reproducible_from_its_spec(spherical):
    """The design run itself (about 3 s on one core, 773 evaluations): the spec's minimax from its
    start lens (the 2026-11-23 design, rounded) converges to the shipped lens, to 0.01 µm in its
    max error and REPRODUCE_REL (relative) in every curvature and thickness."""
    from raytrace.optimize.solver import get_value

    spec = read_spec(SPHERICAL_SPEC)
    assert spec.method == "minimax"
    res = optimize(start_lens(spec), spec)
    assert res.converged, res.message
    assert res.violation <= 1e-9
    shipped = max(
        abs(v.residual) for v in evaluate(spherical, spec.operands) if not v.operand.bounded
    )
    assert res.merit == pytest.approx(shipped, abs=0.01)
    for v in spec.variables:
        got, want = get_value(res.lens, v.kind, v.surface), get_value(spherical, v.kind, v.surface)
        assert got == pytest.approx(want, rel=REPRODUCE_REL), (v.kind, v.surface)
    for a, b in zip(res.lens.surfaces, spherical.surfaces, strict=True):
        assert a.curvature == pytest.approx(b.curvature, rel=REPRODUCE_REL)
        assert a.thickness == pytest.approx(b.thickness, rel=REPRODUCE_REL)


def _minimax_odd_fit(table1, lowest: int, top: int) -> tuple[float, np.ndarray]:
    """The minimax fit of Table I's nine non-zero D0 by a_lowest t^lowest + ... + a_top t^top
    (odd powers, t = tan alpha): (largest error in µm, the coefficients a in mm), by a linear
    programme over the published points."""
    from scipy.optimize import linprog

    keep = table1.fields > 0  # the nine non-zero angles of Table I
    t, y = np.tan(np.radians(table1.fields[keep])), table1.D0[keep]
    assert t.size == 9
    A = np.stack([t**k for k in range(lowest, top + 1, 2)], axis=1)
    m, ones = A.shape[1], np.ones((t.size, 1))
    res = linprog(
        np.r_[np.zeros(m), 1.0],
        A_ub=np.r_[np.c_[A, -ones], np.c_[-A, -ones]],
        b_ub=np.r_[y, -y],
        bounds=[(None, None)] * m + [(0.0, None)],
    )
    assert res.success
    return 1e3 * res.x[-1], res.x[:-1]


def test_table1_polynomial_floor_quoted_in_the_notes(spherical, table1):
    """The evidence the lens notes give for the miss, recomputed from Table I alone: the minimax
    fit of D0 by a3 t^3 + ... + a9 t^9 (t = tan alpha) leaves 6.70 µm, with t^11 4.25 µm, with
    t^13 1.39 µm (linear programme over the nine published points)."""
    floors = [_minimax_odd_fit(table1, 3, top)[0] for top in (9, 11, 13)]
    np.testing.assert_allclose(floors, [6.70, 4.25, 1.39], atol=0.01)
    assert "6.70 um" in spherical.notes and "5.19 um" in spherical.notes


# --------------------------------------------------------------------------- real-ray footprints
# Both spherical specs hold the edge-thickness and stop-clearance rules (at the clear
# semi-diameter + 0.5 mm) through edge_thickness operands at FIXED heights, and |c| h <= 0.975
# through curvature bounds; the stand-ins are sound only if the lens's own footprints lie inside
# them. Footprints as the specs define them: the rim of the paraxial entrance pupil scaled by the
# notes' vignetting model (full f/6.3 beam to 30 deg, 0.75 of the pupil at 37.5, 0.5 at 45,
# linear between), 0-45 deg in 0.5 deg steps, every ray passing.


def _footprints(lens) -> np.ndarray:
    """Largest ray height (mm) on each surface over the vignetted rim beams (72 rays each)."""
    beams = [
        (a, float(np.interp(a, [0, 30, 37.5, 45], [1.0, 1.0, 0.75, 0.5])))
        for a in np.arange(0.0, 45.01, 0.5)
    ]
    return rim_footprints(lens, paraxial(lens), beams, 72)


@pytest.mark.parametrize("name", SPHERICAL_NAMES)
def test_edge_and_curvature_rules_hold_on_the_real_footprints(name):
    """The rules themselves, at each lens's own clear semi-diameters (footprints) + 0.5 mm: the
    edge thickness of every glass (>= 1.0 mm) and air space (>= 0.1 mm), the stop clearances
    (surface 4 to the stop plane, the stop plane to surface 6, >= 0.5 mm), each with the minimum
    its spec's stand-in operand states; |c| h <= 0.975 at the footprint; and the spec's own
    curvature bounds keep |c| h <= 0.975 too (but the c2 / c8 boxes, which stand in for the
    mirrored-curvature rule)."""
    lens = load_lens(name)
    s, h = lens.surfaces, _footprints(lens)
    spec = read_spec(SPECS[name])
    edges = [o for o in spec.operands if o.type == "edge_thickness"]
    assert sorted(int(o.params["surface"]) for o in edges) == list(range(1, 9))
    for o in edges:
        k = int(o.params["surface"]) - 1  # the gap after surface k (0-based)
        foot = {3: h[3], 4: h[5]}.get(k, max(h[k], h[k + 1]))
        he = foot + 0.5
        edge = s[k].thickness + s[k + 1].sag(he) - s[k].sag(he)
        assert edge >= o.limits[0], (name, k + 1, he, edge)
        assert he <= o.params["height"]  # and the stand-in's height lies outside the footprint
    for v in spec.variables:
        if v.kind == "curvature":
            i = v.surface - 1
            assert abs(s[i].curvature) * h[i] <= 0.975, (v.surface, h[i])
            if v.surface not in (2, 8):
                assert max(abs(v.lower), abs(v.upper)) * h[i] <= 0.975, (v.surface, h[i])


# ------------------------------------------------------------- all spherical, to image heights
# lenses/topogon-like-spherical-heights.toml (issue 19, item 4): the construction, glasses and
# rules of topogon-like-spherical, designed to Table I read as image heights y' = F0 tan(alpha)
# + D0 (F0 = 153.706, the table's) with the EFL free: the lens's distortion against F0 = 153.706
# (the 'given' calibration) is Table I's D0 column, and Table II's two-point calibration follows
# from y' alone. Its EFL (153.774) is not the table's F0, so its characteristic distortion is not
# Table I's (the notes say why). The measured numbers below are REGRESSION PINS of our own design
# run (2026-11-28), not published values; the published ones are Tables I and II.
HEIGHTS_MAX_ERR_UM = 2.711  # regression pin: the spec's minimax merit on the shipped lens
HEIGHTS_EFL = 153.77398  # regression pin


heights, heights_traced = _lens_and_curve(
    "topogon-like-spherical-heights", "heights", "heights_traced"
)


def test_heights_lens_measured_against_table1_f0_is_table1(heights, heights_traced, table1):
    assert paraxial(heights).efl == pytest.approx(HEIGHTS_EFL, abs=1e-5)
    cal = calibrate(heights_traced, "given", value=F0)  # D_c = y' - F0 tan(alpha)
    err_um = 1e3 * (cal.Dc - table1.D0)
    assert np.all(np.abs(err_um) <= 3.0), np.round(err_um, 2)  # the 3 µm per entry
    assert np.max(np.abs(err_um)) == pytest.approx(HEIGHTS_MAX_ERR_UM, abs=1e-3)


def test_heights_two_point_calibration_reproduces_table2(heights_traced, table2):
    cal = calibrate(heights_traced, "two-point", at=(37.5, 45))
    assert cal.Kc == pytest.approx(FC, abs=0.001)  # within 1 µm of Table II (measured 154.0596)
    err = cal.Dc - table2[:, 2]
    # measured max 3.72 µm at 42.5 deg (regression pin): the 2.71 µm of y', Table II's F_c
    # rounded to 154.059 and its D_c rounded to 1 µm add there
    assert np.max(np.abs(err)) <= 0.00375, f"D_c - Table II (mm): {np.round(err, 4)}"


def test_heights_spec_operands_match_an_independent_trace(heights, heights_traced, table1):
    """The spec's targets are Table I's image heights F0 tan(alpha) + D0, its residuals (weight
    1000 per mm: µm) this file's D_c - Table I with the given calibration, and every bound
    operand (EFL range, the y'(45) stand-in, RMS caps, BFL, edge thicknesses) is met."""
    spec = read_spec(HEIGHTS_SPEC)
    values = evaluate(heights, spec.operands)
    cal = calibrate(heights_traced, "given", value=F0)
    targets = [v for v in values if v.operand.type == "image_height" and not v.operand.bounded]
    assert len(targets) == 9
    for v in targets:
        i = int(np.flatnonzero(np.isclose(table1.fields, v.operand.params["field"]))[0])
        y_table = F0 * np.tan(np.radians(table1.fields[i])) + table1.D0[i]
        assert v.operand.target == pytest.approx(y_table, abs=1e-6)  # written to 1e-6 mm
        assert v.operand.weight == 1000.0
        assert v.residual == pytest.approx(1e3 * (cal.Dc[i] - table1.D0[i]), abs=2e-3)
    assert max(abs(v.residual) for v in targets) == pytest.approx(HEIGHTS_MAX_ERR_UM, abs=1e-3)
    for v in values:
        if v.operand.bounded:
            assert abs(v.residual) <= 1e-9, (v.operand, v.value)


def test_heights_design_is_reproducible_from_its_spec(heights):
    """The design run itself (about 4 s on one core, 989 evaluations): the spec's minimax from its
    start lens (the global-search design, rounded) converges to the shipped lens."""
    spec = read_spec(HEIGHTS_SPEC)
    res = optimize(start_lens(spec), spec)
    assert res.converged, res.message
    assert res.violation <= 1e-9
    assert res.merit == pytest.approx(HEIGHTS_MAX_ERR_UM, abs=1e-3)
    for a, b in zip(res.lens.surfaces, heights.surfaces, strict=True):
        assert a.curvature == pytest.approx(b.curvature, rel=REPRODUCE_REL)
        assert a.thickness == pytest.approx(b.thickness, rel=REPRODUCE_REL)


def test_table1_scale_term_quoted_in_the_notes(heights, table1):
    """The evidence the notes give, recomputed from Table I alone: allowing a term a1 tan(alpha)
    (a reference scale that is not the lens's paraxial EFL) in the minimax odd-polynomial fit
    lowers the floor from 6.70 to 3.22 µm (to t^9) and from 4.25 to 2.65 µm (to t^11), with a1 =
    0.075 / 0.067 mm; near the axis Table I rises as D0(10)/D0(20) = 0.193, a cubic as 0.114."""
    fits = [_minimax_odd_fit(table1, 1, top) for top in (9, 11)]
    np.testing.assert_allclose([f for f, _ in fits], [3.22, 2.65], atol=0.005)  # to 0.01 µm
    np.testing.assert_allclose([a[0] for _, a in fits], [0.075, 0.067], atol=5e-4)  # to 1 µm
    d0, t = table1.D0[1:3], np.tan(np.radians(table1.fields[1:3]))  # 10 and 20 deg
    assert table1.fields[1:3].tolist() == [10.0, 20.0]
    assert d0[0] / d0[1] == pytest.approx(0.193, abs=5e-4)
    assert (t[0] / t[1]) ** 3 == pytest.approx(0.114, abs=5e-4)
    for quoted in ("3.22 and 2.65 um", "a1 = 0.075 and 0.067 mm", "153.774", "0.193"):
        assert quoted in heights.notes, quoted


def test_heights_notes_quote_the_lens_as_it_is(heights):
    """The BFL, vertex length and clear semi-diameters the notes quote are this lens's."""
    par = paraxial(heights)
    assert f"BFL {par.bfl:.2f} mm" in heights.notes
    length = sum(x.thickness for x in heights.surfaces[:-1])
    assert f"vertex length {length:.1f} mm" in heights.notes
    h = _footprints(heights)
    quoted = ", ".join(f"{x:.1f}" + (" (stop)" if i == 4 else "") for i, x in enumerate(h))
    assert f"clear semi-diameters {quoted} mm" in heights.notes


def test_a_film_plane_off_gaussian_adds_no_scale_term(spherical):
    """Pestrecov's constant of orthoscopy follows the plane, so under his definition a defocus
    adds no scale term to D0 (lenses/README.md, the film-plane reading of Table I): D0 moves by
    delta * dD0/ds' (pupil aberration only; exact, D0 is affine in s'). Checked against the slope
    of ``pupil_analysis``; the µm the README quotes for a 0.07 mm defocus (-0.01 at 10 deg, -4.9
    at 45 deg) are regression pins of this run."""
    from distortion.telecentricity import pupil_analysis

    fields, delta = np.array([10.0, 45.0]), 0.07
    gauss = characteristic_distortion(spherical, fields).curve(0).D0
    moved = characteristic_distortion(spherical, fields, defocus=delta).curve(0).D0
    change = (moved - gauss) * 1000  # µm
    slope = pupil_analysis(spherical, fields).slope
    np.testing.assert_allclose(change, delta * slope * 1000, atol=1e-6)
    assert [round(change[0], 2), round(change[1], 1)] == [-0.01, -4.9]  # pin, as quoted
    a1 = 0.068 * np.tan(np.radians(fields)) * 1000  # the heights lens's scale term, µm
    assert np.all(np.abs(change) < 0.1 * a1)
    readme = (Path(__file__).parents[1] / "lenses" / "README.md").read_text(encoding="utf-8")
    assert "Gaussian plane by −0.01 µm at 10° and −4.9 µm at 45°" in " ".join(readme.split())


def test_a_film_plane_with_f0_held_at_the_efl_is_the_heights_reading(heights, table1):
    """The other film-plane reading (lenses/README.md): holding F0 at the Gaussian EFL in a plane
    delta behind it adds (delta / m_e) tan(alpha) to y' - F0 tan(alpha), the image-heights
    reading again. The heights lens scaled to EFL = F0 with the film 0.068 mm behind its Gaussian
    plane is within 4.2 µm of Table I (the README's number: a regression pin of this run); the
    change from the Gaussian plane is that scale term plus delta * dD0/ds' (pupil aberration,
    at most 7 % of it here)."""
    lens = heights.scaled(F0 / paraxial(heights).efl)
    par = paraxial(lens)
    assert par.efl == pytest.approx(F0, abs=1e-9)
    t = np.tan(np.radians(table1.fields))
    y = [characteristic_distortion(lens, table1.fields, defocus=d).curve(0).yp for d in (0, 0.068)]
    assert round(np.max(np.abs(y[1] - F0 * t - table1.D0)) * 1000, 1) == 4.2  # pin, as quoted
    from distortion.telecentricity import pupil_analysis

    slope = pupil_analysis(lens, table1.fields).slope  # dD0/ds' = tan(alpha') - tan(alpha)/m_e
    np.testing.assert_allclose(y[1] - y[0], 0.068 * (t / par.m_e + slope), atol=1e-9)
    assert np.all(np.abs(slope) <= 0.07 * t / par.m_e)  # the scale term dominates
