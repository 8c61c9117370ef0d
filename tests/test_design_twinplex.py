"""The derived Twinplex-like 55/525 projection objective (orthoscope issue 4, section 3).

Source of every target: K. Pestrecov, "Radial Distortion: Its Calibration, Computation in
Non-Gaussian Image Planes, and Compensation", Photogrammetric Engineering (1958), Section V:
Table III (EFL 50.2832 mm, m_e 1.001700, HE0 -0.0853 mm, H'E0' -0.0856 mm), Table IV (setting
data, tests/data/pestrecov_table3_4.csv), the text (Gaussian-plane distortion spread 35 µm, max
21 µm; magnification -9.545455 at the nominal projection distance 525 mm; the spherical
aberration that makes the EFL 50.2832 instead of 49.7845). The lens is
lenses/twinplex-like-55-525.toml, derived by lenses/specs/twinplex-like-55-525.toml.

Setting data (Pestrecov Section V): the Gaussian setting has m0 = -9.545455 (Eq. 5 inverted:
s = f/m0 - f); the three projection planes s' = 425, 525, 625 mm share the object distance for
which M0 = -9.545455 at s' = 525 (Eq. 8 inverted).
"""

from __future__ import annotations

import csv
import math
import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

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
    # what the design actually holds (spec weights 1000 and 100): m_e to 1e-5, pupils to 2e-4.
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
def test_gaussian_plane_distortion_within_pestrecov_maximum(lens):
    # Pestrecov Section V: in the Gaussian plane the maximum |D0| is 21 µm (spread 35 µm) over
    # the nominal field 10-45 deg. Checked on a 1-deg grid, not only the spec's fields.
    fields = np.arange(10.0, 45.0 + 1e-9, 1.0)
    res = characteristic_distortion(
        lens,
        fields,
    )
    assert np.all(res.status == STATUS_OK)
    d0 = res.D0[0]
    assert np.max(np.abs(d0)) <= 0.021
    assert np.ptp(d0) <= 0.035
    # and the image is the real projection size: y' ~ M0 p0 tan 45 ~ 529 mm at 45 deg
    assert res.yp[0][-1] == pytest.approx(res.constant[0] * res.x[-1], rel=1e-4)


# --------------------------------------------------------------------------- best focus
def _best_focus(lens, od, aperture):
    op = Operand("best_focus", 525.0, 1.0, {"object_distance": od, "aperture": aperture})
    return evaluate(lens, (op,))[0].value


def test_best_focus_near_525_at_f8(lens, par):
    # The spec puts the least-RMS-spot focus of the full f/8 axial bundle from the diapositive
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
    # the Gaussian column (Gaussian setting) meets Pestrecov's 21 µm maximum
    assert np.max(np.abs(gauss.D0[0])) <= 0.021


# --------------------------------------------------------------------------- reproducibility
def _shipped_merit(lens) -> float:
    m = re.search(r"final merit ([0-9.eE+-]+)", lens.notes)
    assert m, "the lens notes must record the final merit"
    return float(m.group(1))


def test_shipped_lens_records_its_derivation(lens):
    assert lens.notes.startswith("provenance: derived")
    assert "lenses/specs/twinplex-like-55-525.toml" in lens.notes
    assert "2026-11-22" in lens.notes
    spec = read_spec(SPEC)
    # the shipped lens is the spec's optimum: evaluating the spec on it gives the recorded merit
    vals = evaluate(lens, spec.operands)
    merit = sum(v.residual**2 for v in vals)
    assert merit == pytest.approx(_shipped_merit(lens), rel=0.01)


def test_spec_reproduces_the_shipped_lens(lens):
    spec = read_spec(SPEC)
    res = optimize(start_lens(spec), spec)  # ~2-4 s on the 2-core machine
    assert res.converged, res.message
    assert res.merit == pytest.approx(_shipped_merit(lens), rel=0.01)
    p_new, p_old = paraxial(res.lens), paraxial(lens)
    assert p_new.efl == pytest.approx(p_old.efl, abs=1e-4)
    assert p_new.s == pytest.approx(p_old.s, abs=1e-4)
    new = replace(res.lens, image_solve=None)
    for a, b in zip(new.surfaces[:-1], lens.surfaces[:-1], strict=True):
        assert a.curvature == pytest.approx(b.curvature, abs=1e-4)
        assert a.thickness == pytest.approx(b.thickness, abs=1e-3)
    assert math.isfinite(res.merit)
