"""The derived Twinplex-like 55/525 projection objective (orthoscope issue 4, section 3; redesigned
for issue 19 so that Table V holds too).

Source of every target: K. Pestrecov, "Radial Distortion: Its Calibration, Computation in
Non-Gaussian Image Planes, and Compensation", Photogrammetric Engineering (1958), Section V:
Table III (EFL 50.2832 mm, m_e 1.001700, HE0 -0.0853 mm, H'E0' -0.0856 mm), Table IV (setting
data, tests/data/pestrecov_table3_4.csv), Table V (D0 in four image planes,
tests/data/pestrecov_table5.csv), the text (Gaussian-plane distortion spread 35 µm, max 21 µm;
magnification -9.545455 at the nominal projection distance 525 mm; the spherical aberration that
makes the EFL 50.2832 instead of 49.7845; warpage "nearly one to one" in the three planes). The
lens is lenses/twinplex-like-55-525.toml, designed by a global search outside the spec language
and re-optimized by the minimax spec lenses/specs/twinplex-like-55-525-tablev.toml (its notes give
the method and merit; a test below re-runs the spec); lenses/specs/twinplex-like-55-525.toml
derives the earlier, first-order-only design, kept as the contrast (it misses Table V by ~0.2 mm).

Setting data (Pestrecov Section V): the Gaussian setting has m0 = -9.545455 (Eq. 5 inverted:
s = f/m0 - f); the three projection planes s' = 425, 525, 625 mm share the object distance for
which M0 = -9.545455 at s' = 525 (Eq. 8 inverted). Wavelength: the d line (the paper states none).
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
import pytest
from support import rim_footprints

from distortion.characteristic import characteristic_distortion
from raytrace.files.library import load_lens
from raytrace.kernels.codes import STATUS_OK
from raytrace.optimize import Operand, evaluate, optimize, read_spec, start_lens
from raytrace.packing import pack
from raytrace.paraxial import paraxial
from raytrace.paraxial.orthoscopy import (
    object_distance_for_magnification,
    object_distance_for_plane_magnification,
    plane_constants,
)
from raytrace.trace import trace_rays

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "lenses" / "specs" / "twinplex-like-55-525.toml"
TABLEV_SPEC = ROOT / "lenses" / "specs" / "twinplex-like-55-525-tablev.toml"
DATA = Path(__file__).parent / "data"

# Pestrecov 1958, Table III
EFL, M_E, HE0, HPE0P = 50.2832, 1.001700, -0.0853, -0.0856
# Pestrecov 1958, Section V: magnification at the nominal projection distance (= -525/55)
M_NOMINAL = -9.545455
PROJECTION_PLANES = (425.0, 525.0, 625.0)
NOMINAL_ANGLES = np.arange(10.0, 45.0 + 1e-9, 5.0)  # Table V rows


@pytest.fixture(scope="module")
def lens():
    return load_lens("twinplex-like-55-525")


@pytest.fixture(scope="module")
def par(lens):
    return paraxial(lens)


def projection_setting(lens, par):
    """(s, object distance from the first vertex) of the projection planes: M0 = -9.545455 at
    s' = 525 from the lens's own m_e, HE0, H'E0' (Pestrecov Eq. 8 inverted)."""
    s = object_distance_for_plane_magnification(M_NOMINAL, 525.0, par.m_e, par.HE0, par.HpE0p)
    return s, -(par.z_H + s)


def table_iv():
    """Pestrecov's Table IV rows: (plane, s, P0, s', P0', M0)."""
    rows = []
    with open(DATA / "pestrecov_table3_4.csv", encoding="utf-8") as fh:
        lines = [ln for ln in fh if not ln.startswith("#")]
    for r in list(csv.reader(lines, skipinitialspace=True))[1:]:
        rows.append((r[0].strip(), *(float(v) for v in r[1:])))
    return rows


# --------------------------------------------------------------------------- first-order targets
def test_first_order_targets_of_table_iii(par):
    assert par.efl == pytest.approx(EFL, abs=1e-3)
    assert abs(par.m_e - M_E) <= 0.0005
    assert abs(par.HE0 - (-0.085)) <= 0.03
    assert abs(par.HpE0p - (-0.086)) <= 0.03
    # what the design actually holds (merit weights 1e6 and 1e4): m_e to 1e-5, pupils to 2e-4.
    # Table III itself is paraxially inconsistent at the 1e-4 level: for pupils conjugate
    # about the principal planes H'E0' = f HE0 / (f + HE0) = -0.08544 from HE0 = -0.0853.
    assert par.m_e == pytest.approx(M_E, abs=1e-5)
    assert par.HE0 == pytest.approx(HE0, abs=2e-4)
    assert par.HpE0p == pytest.approx(HPE0P, abs=2e-4)
    assert par.HpE0p == pytest.approx(par.efl * par.HE0 / (par.efl + par.HE0), abs=1e-9)


def test_lens_file_is_the_gaussian_setting(lens, par):
    # Table IV, Gaussian row: s = -55.5510, s' = 530.2592, m0 = -9.545455
    assert par.m0 == pytest.approx(M_NOMINAL, abs=1e-6)
    assert par.s == pytest.approx(object_distance_for_magnification(par.efl, M_NOMINAL), abs=1e-5)
    assert par.s == pytest.approx(-55.5510, abs=1e-4)
    assert par.s_prime_gauss == pytest.approx(530.2592, abs=2e-3)
    assert lens.image_solve == "gaussian"
    assert lens.field.kind == "angle" and lens.field.value == 45.0


# --------------------------------------------------------------------------- distortion target
def test_gaussian_plane_distortion_near_pestrecov_maximum(lens):
    # Pestrecov Section V: in the Gaussian plane the maximum |D0| is 21 µm (spread 35 µm) over
    # the nominal field 10-45 deg; his own Table V Gaussian column has 20.6 µm at 30 deg and a
    # spread of 35.2 µm. Checked on a 1-deg grid, not only the table's angles. This design
    # (measured 2026-11-27, a regression pin): max 21.40 µm at 30 deg, spread 37.99 µm -- it
    # misses the text's spread by 3 µm because it follows Table V's Gaussian column within its
    # per-entry errors below (-0.80 µm at 30 deg, +2.79 µm at 40 deg, +1.99 µm at 45 deg), and
    # Table V's own column spreads 35.2 µm over the coarser 5-deg rows only.
    fields = np.arange(10.0, 45.0 + 1e-9, 1.0)
    res = characteristic_distortion(lens, fields)
    assert np.all(res.status == STATUS_OK)
    d0 = res.D0[0]
    assert np.max(np.abs(d0)) <= 0.0215
    assert np.ptp(d0) <= 0.0390
    # and the image is the real projection size: y' ~ M0 p0 tan 45 ~ 529 mm at 45 deg
    assert res.yp[0][-1] == pytest.approx(res.constant[0] * res.x[-1], rel=1e-4)


# --------------------------------------------------------------------------- best focus
def _best_focus(lens, od, aperture):
    op = Operand("best_focus", 525.0, 1.0, {"object_distance": od, "aperture": aperture})
    return evaluate(lens, (op,))[0].value


def test_best_focus_near_525_at_f8(lens, par):
    # The design puts the least-RMS-spot focus of the full f/8 axial bundle from the diapositive
    # at the projection setting at s' = 525 (Pestrecov's nominal projection distance); it holds
    # it to < 1e-3 mm. Tolerance 0.05 mm: Table IV gives s to 1e-4 mm and dz'/dz ~ M^2 ~ 100,
    # so the printed setting itself is uncertain by ~0.005 mm in s'; a tracer or lens change
    # of 0.5 µm on the object side (0.05 mm on the image side) is caught.
    assert lens.aperture.kind == "fnumber" and lens.aperture.value == 8.0
    _, od = projection_setting(lens, par)
    assert _best_focus(lens, od, 1.0) == pytest.approx(525.0, abs=0.05)


def test_best_focus_by_brute_force_and_undercorrected_spherical_aberration(lens, par):
    # Independent of the operand's closed form: RMS spot of a dense square pupil grid scanned
    # along the axis. Then the physics Pestrecov relies on: under-corrected spherical aberration,
    # so best focus moves from the Gaussian image (586 mm for s = -55.0009) toward the lens
    # as the aperture opens.
    s, od = projection_setting(lens, par)
    pp = paraxial(lens, od)
    g = np.linspace(-1.0, 1.0, 61)
    px, py = np.meshgrid(g, g)
    keep = px**2 + py**2 <= 1.0
    px, py = px[keep] * pp.epd / 2, py[keep] * pp.epd / 2
    z0 = pp.z_object
    dx, dy, dz = px, py, pp.z_E0 - z0
    n = np.sqrt(dx * dx + dy * dy + dz * dz)
    batch = trace_rays(
        pack(lens), (np.zeros_like(px), np.zeros_like(py), np.full_like(px, z0)),
        (dx / n, dy / n, dz / n), clip=False,
    )  # fmt: skip
    assert np.all(batch.status == STATUS_OK)
    sp = np.linspace(515.0, 535.0, 201)
    rms = []
    for v in sp:
        x, y = batch.at_plane(pp.z_Hp + v)
        rms.append(np.sqrt(np.mean(x**2 + y**2)))
    best = sp[int(np.argmin(rms))]
    assert best == pytest.approx(525.0, abs=0.3)  # grid sampling differs from the operand's
    foci = [_best_focus(lens, od, a) for a in (0.25, 0.5, 0.75, 1.0)]
    assert np.all(np.diff(foci) < 0)
    assert pp.s_prime_gauss == pytest.approx(586.2, abs=0.1)
    assert foci[0] < pp.s_prime_gauss


# --------------------------------------------------------------------------- Table IV
def test_table_iv_setting_data(lens, par):
    s_p, od_p = projection_setting(lens, par)
    rows = table_iv()
    assert [r[0] for r in rows] == ["non-gaussian", "non-gaussian", "gaussian", "non-gaussian"]
    for plane, s, P0, sp, P0p, M0 in rows:
        if plane == "gaussian":
            c = plane_constants(par.efl, par.m_e, par.HE0, par.HpE0p, par.s, None)
            assert c.s_prime == pytest.approx(sp, abs=2e-3)
        else:
            c = plane_constants(par.efl, par.m_e, par.HE0, par.HpE0p, s_p, sp)
        # s: Table IV rounds to 1e-4; the design's m_e (1e-6) and HE0 (1e-4) move s by < 1e-4
        assert c.s == pytest.approx(s, abs=1e-4)
        # P0, P0': the design's HE0 / H'E0' differ from Table III by < 2e-4 (Table III is
        # itself inconsistent by 1.6e-4, see above)
        assert c.p0 == pytest.approx(P0, abs=2e-4)
        assert c.p0p == pytest.approx(P0p, abs=2e-4)
        assert c.constant == pytest.approx(M0, abs=1e-5)
        # Fig. 1 and Eqs. 7-8: P0 = s - HE0, P0' = s' - H'E0', M0 = P0' / (m_e P0)
        assert c.p0 == pytest.approx(c.s - par.HE0, abs=1e-12)
        assert c.p0p == pytest.approx(c.s_prime - par.HpE0p, abs=1e-12)
        assert c.constant == pytest.approx(c.p0p / (par.m_e * c.p0), rel=1e-12)
        if plane == "gaussian":
            # Eq. 7: P0g' = m_e m0 p0, and M0 = m0 in the Gaussian plane
            assert c.p0p == pytest.approx(par.m_e * par.m0 * c.p0, abs=1e-9)
            assert c.constant == pytest.approx(par.m0, rel=1e-12)


def test_table_iv_constants_agree_with_the_real_near_axis_chief_ray(lens, par):
    # Eq. 8 is the limit of p' tan a' / p tan a: the traced scale of a near-axis real chief ray
    # (reference "distortion-focal-length") must equal M0 in every plane, Gaussian or not.
    _, od_p = projection_setting(lens, par)
    for od, planes in ((od_p, list(PROJECTION_PLANES)), (lens.object_distance, None)):
        kw = {} if planes is None else {"s_prime": planes}
        a = characteristic_distortion(lens, [45.0], object_distance=od, **kw)
        b = characteristic_distortion(lens, [45.0], object_distance=od,
            reference="distortion-focal-length", **kw,
        )  # fmt: skip
        np.testing.assert_allclose(b.scale, a.constant, rtol=1e-7)


# --------------------------------------------------------------------------- Table V analog
def test_table_v_analog_one_trace(lens, par):
    s_p, od_p = projection_setting(lens, par)
    proj = characteristic_distortion(
        lens, NOMINAL_ANGLES, object_distance=od_p, s_prime=PROJECTION_PLANES
    )
    gauss = characteristic_distortion(
        lens,
        NOMINAL_ANGLES,
    )
    assert np.all(proj.status == STATUS_OK) and np.all(gauss.status == STATUS_OK)
    np.testing.assert_allclose(proj.constant, [-7.727571, -9.545455, -11.363342], atol=1e-5)
    # straight final segments and M0 linear in s' (Eq. 8): D0 is linear in s' for one object
    # setting, so the nominal plane is the mean of the equally spaced near and far planes
    np.testing.assert_allclose(proj.D0[1], 0.5 * (proj.D0[0] + proj.D0[2]), atol=1e-9)
    # one trace of many planes = separate traces of each plane
    for i, sp in enumerate(PROJECTION_PLANES):
        one = characteristic_distortion(lens, NOMINAL_ANGLES, object_distance=od_p, s_prime=sp)
        np.testing.assert_allclose(one.D0[0], proj.D0[i], atol=1e-10)


# --------------------------------------------------------------------------- Table V per entry
def table_v():
    """Pestrecov's Table V: angles (deg) and D0 (mm) in columns s' = 425, 525, 530.3 (Gaussian
    plane, Gaussian setting), 625."""
    t = np.loadtxt(DATA / "pestrecov_table5.csv", delimiter=",", comments="#", skiprows=5)
    return t[:, 0], t[:, 1:]


# The target: 3 µm per entry (issue 19, item 3). The design's minimax reached 2.794 µm
# over the 24 independent entries (lens notes).
TOL_UM = 3.0
COLUMNS = ("425", "525", "gaussian", "625")


@pytest.fixture(scope="module")
def table_v_traced(lens, par):
    _, od_p = projection_setting(lens, par)
    angles, _ = table_v()
    proj = characteristic_distortion(lens, angles, object_distance=od_p, s_prime=PROJECTION_PLANES)
    gauss = characteristic_distortion(lens, angles)
    assert np.all(proj.status == STATUS_OK) and np.all(gauss.status == STATUS_OK)
    return np.vstack([proj.D0[0], proj.D0[1], gauss.D0[0], proj.D0[2]]).T  # (angle, column)


@pytest.mark.parametrize("column", ["425", "gaussian", "625"])
@pytest.mark.parametrize("angle", list(NOMINAL_ANGLES))
def test_table_v_entry(table_v_traced, column, angle):
    # Pestrecov 1958, Table V, row `angle`, column `column` (the 24 independent entries)
    angles, t5 = table_v()
    i, j = int(np.flatnonzero(angles == angle)[0]), COLUMNS.index(column)
    err_um = 1e3 * (table_v_traced[i, j] - t5[i, j])
    assert abs(err_um) <= TOL_UM, f"D0 - Table V = {err_um:+.2f} um"


def test_table_v_nominal_column_is_the_mean_and_within_3_um(table_v_traced):
    # the 525 column is the mean of the 425 and 625 columns for one object setting (Pestrecov's
    # own table: to 0.15 µm in all eight rows); ours exactly, and within 3 µm of Table V
    angles, t5 = table_v()
    np.testing.assert_allclose(t5[:, 1], 0.5 * (t5[:, 0] + t5[:, 3]), atol=0.15e-3)
    d = table_v_traced
    np.testing.assert_allclose(d[:, 1], 0.5 * (d[:, 0] + d[:, 3]), atol=1e-9)
    assert np.max(np.abs(d[:, 1] - t5[:, 1])) <= TOL_UM * 1e-3


def test_warpage_nearly_one_to_one_in_the_three_planes(table_v_traced):
    # Pestrecov Section V: the warpage z = s' dx / d (dx proportional to the distortion spread
    # over 10-45 deg) is "nearly one to one" in the planes 425, 525, 625 (his spreads 74, 58,
    # 46 µm: ratios 1.03 : 1 : 0.94). The first-order-only design had 1.15 : 1 : 4.1.
    d = table_v_traced
    spread = np.ptp(d[:, [0, 1, 3]], axis=0)
    z = np.array(PROJECTION_PLANES) * spread
    ratios = z / z[1]
    assert np.all(np.abs(ratios - 1.0) <= 0.1), ratios
    # and the D0 slope at 45 deg (the pupil aberration) is Pestrecov's, -20.65 µm per 100 mm
    angles, t5 = table_v()
    slope = (d[-1, 3] - d[-1, 0]) / 200.0
    assert slope == pytest.approx((t5[-1, 3] - t5[-1, 0]) / 200.0, abs=3e-5)


# --------------------------------------------------------------------------- realism
def test_spherical_surfaces_catalog_glasses_and_shop_thicknesses(lens):
    from raytrace.glass import lookup_glass

    glass = [s for s in lens.surfaces if not s.material.is_air]
    assert len(glass) == 7
    for s in lens.surfaces:
        assert s.conic == 0.0 and not any(s.aspheric)
    for s in glass:
        m = s.material
        assert m.kind == "catalog"  # a vendor glass with its formula, not an nd/vd model glass
        assert m == lookup_glass(m.name, [m.catalog]).material
        assert s.thickness >= 1.0 - 5e-4  # the design's shop rule (met to 0.3 µm)
    for s in lens.surfaces[:-1]:
        if s.material.is_air:
            assert s.thickness >= 0.1 - 1e-6


def test_image_quality_no_worse_than_the_first_design(lens, par):
    # RMS spot radius at s' = 525 for the object at the projection setting, full f/8 bundle on
    # the axis and at 15 and 30 deg, 0.75 of the pupil at 37.5 deg and 0.5 at 45 deg (a
    # projector's vignetting). Limits: the first-order-only design's values (regression pins of
    # lenses/twinplex-like-55-525.toml before issue 19: 0.05168, 0.56209, 2.54789, 3.20506,
    # 3.31400 mm). The redesign held the axis and 15 deg as caps (0.0517 and 0.56209 mm: 0.04 %
    # and 0.002 % over the pins' last digit, inside the 5e-4 allowance) and is better outside
    # (1.70, 1.70, 1.71 mm).
    _, od = projection_setting(lens, par)
    first = {(0.0, 1.0): 0.05168, (15.0, 1.0): 0.56209, (30.0, 1.0): 2.54789,
             (37.5, 0.75): 3.20506, (45.0, 0.5): 3.31400}  # fmt: skip
    for (field, aperture), limit in first.items():
        op = Operand("rms_spot", 0.0, 1.0, {"field": field, "aperture": aperture,
                     "object_distance": od, "plane": {"s_prime": 525.0}})  # fmt: skip
        rms = evaluate(lens, (op,))[0].value
        assert rms <= limit * (1 + 5e-4), (field, rms, limit)


# --------------------------------------------------------------------------- provenance
def test_shipped_lens_records_its_design(lens):
    assert lens.notes.startswith("provenance: derived")
    merit = "Merit of this file (the minimax objective): max |D0 - Table V| = 2.794 um"
    for text in ("Table V", merit, "Seven spherical elements", "d line"):
        assert text in lens.notes


def test_first_order_spec_converges_and_misses_table_v():
    """The spec lenses/specs/twinplex-like-55-525.toml (Tables III-IV and the Gaussian plane only)
    still converges to its recorded merit (regression pin 1.2046e-4, the spec's comments); its
    lens reproduces Table III but not Table V: the reason for the redesign (issue 19)."""
    spec = read_spec(SPEC)
    res = optimize(start_lens(spec), spec)  # ~2-4 s on the 2-core machine
    assert res.converged, res.message
    assert res.merit == pytest.approx(1.2046e-4, rel=0.01)
    first = res.lens
    p = paraxial(first)
    assert p.efl == pytest.approx(EFL, abs=1e-3) and p.m_e == pytest.approx(M_E, abs=1e-5)
    _, od_p = projection_setting(first, p)
    proj = characteristic_distortion(first, [45.0], object_distance=od_p, s_prime=[625.0])
    _, t5 = table_v()
    assert abs(proj.D0[0][0] - t5[-1, 3]) > 0.1  # 0.229 mm off at 45 deg, s' = 625
    assert math.isfinite(res.merit)


def test_table_v_spec_targets_are_the_shipped_lens_errors(lens, par, table_v_traced):
    """The minimax spec lenses/specs/twinplex-like-55-525-tablev.toml states Table V as 24
    distortion targets (weight 1000: residuals in µm) at fixed object distances from the first
    vertex, computed for its start lens's H (the previous design). Evaluated on the shipped lens
    (no optimization), its residuals are the shipped lens's D0 - Table V by this file's own path
    (characteristic_distortion, the projection setting from Eq. 8 for the lens's own constants,
    1.2e-6 mm from the spec's fixed one): the spec's targets, planes and object settings are
    Pestrecov's, and the shipped lens meets them within 3 µm. Its Table III / IV bounds (EFL,
    m_e, the pupils, the m0 pin) hold on the shipped lens too."""
    spec = read_spec(TABLEV_SPEC)
    assert spec.method == "minimax"
    targets = tuple(o for o in spec.operands if o.type == "distortion" and not o.bounded)
    assert len(targets) == 24 and all(o.weight == 1000.0 for o in targets)
    _, od_p = projection_setting(lens, par)
    residual = {}
    for v in evaluate(lens, targets):
        p = v.operand.params
        column = "gaussian" if p["plane"] == "gaussian" else f"{p['plane']['s_prime']:g}"
        od = lens.object_distance if column == "gaussian" else od_p
        assert p["object_distance"] == pytest.approx(od, abs=2e-6)
        residual[(column, float(p["field"]))] = v.residual
    angles, t5 = table_v()
    assert sorted(residual) == sorted(
        (c, float(a)) for c in ("425", "625", "gaussian") for a in angles
    )
    for (column, angle), r in residual.items():
        i, j = int(np.flatnonzero(angles == angle)[0]), COLUMNS.index(column)
        assert r == pytest.approx(1e3 * (table_v_traced[i, j] - t5[i, j]), abs=1e-3)
    assert max(abs(r) for r in residual.values()) <= TOL_UM
    first_order = tuple(
        o for o in spec.operands if o.type in ("efl", "m_e", "HE0", "HpE0p", "image_height")
    )
    assert len(first_order) == 5
    assert all(abs(v.residual) <= 1e-6 for v in evaluate(lens, first_order))


def test_table_v_design_is_reproducible_from_its_spec(lens):
    """The design run itself (3-6 s on one core, 401 evaluations): the spec's minimax from its
    start lens (the 2026-11-24 design) converges to the shipped lens, with every bound met, to
    0.01 µm in its max error and 1e-6 (relative) in every curvature and thickness."""
    spec = read_spec(TABLEV_SPEC)
    res = optimize(start_lens(spec), spec)
    assert res.converged, res.message
    assert res.violation <= 1e-9
    shipped = max(abs(v.residual) for v in evaluate(lens, spec.operands) if not v.operand.bounded)
    assert shipped <= TOL_UM
    assert res.merit == pytest.approx(shipped, abs=0.01)
    for a, b in zip(res.lens.surfaces, lens.surfaces, strict=True):
        assert a.curvature == pytest.approx(b.curvature, rel=1e-6)
        assert a.thickness == pytest.approx(b.thickness, rel=1e-6)


#: the design's shop rules (lens notes): clear semi-diameter = the largest real-ray height of the
#: f/8 bundles at the projection setting (full pupil to 30 deg, 0.75 at 37.5, 0.5 at 45: a
#: projector's vignetting), edges and stop clearance at it + 0.3 mm
VIGNETTING = ((0.0, 1.0), (10.0, 1.0), (20.0, 1.0), (30.0, 1.0), (37.5, 0.75), (45.0, 0.5))
MARGIN, MIN_EDGE, MIN_STOP_GAP, MAX_CH = 0.3, 0.8, 0.3, 0.975


def test_shop_rules_hold_on_the_lens_own_footprints(lens, par):
    """Every shop rule of the notes, on the shipped lens's own rays: footprints from full rims of
    the paraxial entrance pupil (144 rays a field, aimed here from the object point), glass edges
    >= 0.8 mm and the stop clearance >= 0.3 mm at the clear semi-diameter + 0.3 mm, |c| h <= 0.975
    there; and the spec's ray_height bounds (14 surfaces, 6 rim rays each) hold the full rims."""
    _, od = projection_setting(lens, par)
    foot = rim_footprints(lens, paraxial(lens, od), VIGNETTING, 144)
    h = foot + MARGIN
    s = lens.surfaces

    def edge(i: int, height: float) -> float:  # axial gap at `height` after surface i (1-based)
        return s[i - 1].thickness + s[i].sag(height) - s[i - 1].sag(height)

    for i in (1, 3, 8, 10, 12, 14):  # the elements (5-6 below)
        assert edge(i, max(h[i - 1], h[i])) >= MIN_EDGE - 1e-6, i
    # the thin meniscus 5-6: its front footprint lies beyond the rear sphere; its rear face's
    assert edge(5, h[5]) >= MIN_EDGE
    assert edge(6, h[5]) >= MIN_STOP_GAP - 1e-6  # surface 6 to the stop plane
    assert edge(7, h[7]) >= MIN_STOP_GAP - 1e-6  # the stop plane to surface 8
    ch = [abs(x.curvature) * hh for x, hh in zip(s, h, strict=True)]
    assert max(ch) <= MAX_CH + 1e-6
    # the spec's footprint bounds are the extreme rays: the full rims stay inside them
    spec = read_spec(TABLEV_SPEC)
    limit = {}
    for o in spec.operands:
        if o.type == "ray_height":
            limit[o.params["surface"]] = o.limits[1]
    assert len(limit) == 14 and 7 not in limit
    for k, hmax in limit.items():
        assert foot[k - 1] <= hmax + 1e-6, (k, foot[k - 1], hmax)
