"""The tolerance operands not exercised elsewhere — TFRN, TIRR, TASP, TCON, TIRX, TIRY: each
perturbed instance's surface (the arrays the instance kernels trace) is what the operand's
documented meaning says, and where optiland 0.6.3 can represent the perturbation, one instance's
real chief rays equal optiland's to ≤ 1e-9 mm (as tests/test_tolerance_model.py does for element
decenters and tilts).

The meanings are those docs/tolerance.md and raytrace/tolerance/model.py state for the
OpticStudio operands (OpticStudio manual, "Tolerancing", operand descriptions, as quoted there):

* TFRN — power in fringes at the test wavelength: the sag at the semi-diameter h changes by
  N λ/2 (one fringe of a double-pass test-plate interferogram is λ/2 of sag);
* TIRR — irregularity in fringes: Δsag = Zs ρ⁴ + Za ρ_y² (ρ = r/sd, ρ_y = y/sd) with
  Zs = Za = N λ/4, half spherical and half astigmatism, N λ/2 at the rim along y (our reading of
  OpticStudio's TIRR and its Irregular surface; not checked against OpticStudio);
* TASP — adds to the even-asphere coefficient of r^term; TCON — adds to the conic constant;
* TIRX / TIRY — surface tilt given as total indicator runout over the clear diameter 2·sd: an
  indicator moved parallel to the axis reads the tilted plane at x = ±sd (TIRX; y for TIRY), and
  the two readings differ by TIR, so tan θ = TIR / (2 sd) — the small-angle θ = TIR / clear
  diameter the operand is defined by. TIRX turns about y (the runout lies along x), TIRY about x.

The Cooke triplet has no semi-diameters in its file; these tests give every surface sd = 6.5 mm
(a value that only scales the operands, the rays are traced unclipped in both programs).
"""

from __future__ import annotations

import math
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from raytrace.files.library import load_lens
from raytrace.kernels.codes import G_ABS, G_ABST, G_ZV
from raytrace.kernels.instances import KIND_IRREGULAR
from raytrace.tolerance import aim_instances, nominal_aim, pack_instances, spec_from_dict

SD = 6.5  # mm, semi-diameter given to every surface (module docstring)
LAMBDA_TEST_MM = 632.8e-6  # the spec's default test wavelength (He-Ne), mm
AX = np.array([0.0, 0.0, 5.0, -7.0, 10.0, 0.0])  # chief-ray fields (deg), 2-D
AY = np.array([0.0, 14.0, 5.0, 12.0, -10.0, -20.0])


@pytest.fixture(scope="module")
def lens():
    base = load_lens("cooke-triplet-f4")
    surfaces = tuple(replace(s, semi_diameter=SD) for s in base.surfaces)
    return replace(base, surfaces=surfaces, image_solve=None)


def _spec(item: dict):
    return spec_from_dict({"tolerances": [item]})


def _sag(c: float, h: float) -> float:
    """Sag of a sphere of curvature c at height h, as R − sign(R)·√(R² − h²) (written here)."""
    if c == 0.0:
        return 0.0
    R = 1.0 / c
    return R - math.copysign(math.sqrt(R * R - h * h), R)


# ---------------------------------------------------------------------------- optiland
def _optic(lens):
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
    import optiland_adapter as ola

    op = ola.build_optic(lens)
    op.ray_tracer.set_aiming("iterative", max_iter=50, tol=1e-13)
    return op, ola.NEWTON_TOL


def _optiland_chief(op, lens) -> np.ndarray:
    fmax = float(op.fields.max_field)
    rays = op.trace_generic(Hx=AX / fmax, Hy=AY / fmax, Px=0.0, Py=0.0,
                            wavelength=lens.wavelength / 1000.0)  # fmt: skip
    return np.column_stack([np.asarray(rays.x), np.asarray(rays.y)])


def _ours(lens, spec, v) -> tuple[np.ndarray, np.ndarray]:
    """Chief rays of the instance ``v`` and of the nominal lens on the file's image plane."""
    aim = nominal_aim(lens, spec, AX, AY)
    out = []
    for vals in (np.atleast_2d(v), np.zeros((1, spec.n_items))):
        arr = pack_instances(lens, spec, vals)
        cr = aim_instances(arr, aim, parallel=False)
        assert cr.ok.all()
        out.append(cr.points_at(arr.image_z_stack)[0])
    return out[0], out[1]


def _compare(ours, nominal, theirs):
    # the perturbation matters: far more than the agreement asked for
    assert np.max(np.abs(ours - nominal)) > 1e-5
    assert np.max(np.abs(ours - theirs)) <= 1e-9


# ---------------------------------------------------------------------------- TFRN
@pytest.mark.parametrize("surface, fringes", [(1, 3.0), (6, -5.0)])
def test_tfrn_changes_the_rim_sag_by_n_half_waves(lens, surface, fringes):
    """The instance's curvature has the sag at h = sd changed by exactly N λ/2 (to 1e-15 mm),
    and Δ(1/R) is the paraxial fringe relation N λ / h² up to its next order,
    Δc·h²/(Nλ) = 1 − (3/4)(c h)² + O((c h)⁴) (from sag = c h²/2 · (1 + c²h²/4 + ...))."""
    spec = _spec({"type": "TFRN", "surface": surface, "limit": abs(fringes)})
    j = surface - 1
    c0 = lens.surfaces[j].curvature
    c1 = float(pack_instances(lens, spec, np.array([[fringes]])).c[0, j])
    assert _sag(c1, SD) - _sag(c0, SD) == pytest.approx(fringes * LAMBDA_TEST_MM / 2, abs=1e-15)
    ratio = (c1 - c0) * SD * SD / (fringes * LAMBDA_TEST_MM)
    ch2 = (c0 * SD) ** 2
    assert abs(ratio - 1.0) <= ch2  # the paraxial relation, to its first neglected order
    assert ratio == pytest.approx(1.0 - 0.75 * ch2, abs=ch2 * ch2)


@pytest.mark.filterwarnings("ignore")
def test_tfrn_instance_equals_optiland(lens):
    """TFRN 4 fringes on surface 3: the radius optiland is given is the sphere through the
    vertex and the rim point (h, sag + N λ/2), c' = 2 z'/(z'² + h²) (computed here)."""
    pytest.importorskip("optiland")
    N, j = 4.0, 2
    spec = _spec({"type": "TFRN", "surface": j + 1, "limit": N})
    ours, nominal = _ours(lens, spec, [N])
    z1 = _sag(lens.surfaces[j].curvature, SD) + N * LAMBDA_TEST_MM / 2
    c1 = 2.0 * z1 / (z1 * z1 + SD * SD)
    surfaces = list(lens.surfaces)
    surfaces[j] = replace(surfaces[j], curvature=c1)
    op, _ = _optic(replace(lens, surfaces=tuple(surfaces)))
    _compare(ours, nominal, _optiland_chief(op, lens))


# ---------------------------------------------------------------------------- TCON, TASP
def test_tcon_and_tasp_add_to_the_coefficients(lens):
    spec = spec_from_dict({"tolerances": [
        {"type": "TCON", "surface": 2, "limit": 0.5},
        {"type": "TASP", "surface": 4, "term": 6, "limit": 1e-7},
        {"type": "TASP", "surface": 4, "term": 4, "limit": 1e-5},
    ]})  # fmt: skip
    arr = pack_instances(lens, spec, np.array([[0.3, -4e-8, 2e-6]]))
    assert arr.k[0, 1] == lens.surfaces[1].conic + 0.3
    # asph[m] multiplies r^(2m + 4) (raytrace.packing): r^4 -> 0, r^6 -> 1
    assert arr.asph[0, 3, 0] == 2e-6 and arr.asph[0, 3, 1] == -4e-8
    assert np.all(arr.asph[0, [0, 1, 2, 4, 5]] == 0.0)


@pytest.mark.filterwarnings("ignore")
def test_tcon_and_tasp_instance_equals_optiland(lens):
    """TCON on surface 2 and TASP r^4, r^6 on surface 5: optiland's standard surface with the
    conic k + Δk and its even asphere with the coefficients added (written here on the Lens
    given to the adapter; optiland's Newton intersection tightened to 1e-15 mm by it)."""
    pytest.importorskip("optiland")
    spec = spec_from_dict({"tolerances": [
        {"type": "TCON", "surface": 2, "limit": 2.0},
        {"type": "TASP", "surface": 5, "term": 4, "limit": 1e-5},
        {"type": "TASP", "surface": 5, "term": 6, "limit": 1e-7},
    ]})  # fmt: skip
    v = [1.5, 6e-6, -5e-8]
    ours, nominal = _ours(lens, spec, v)
    surfaces = list(lens.surfaces)
    surfaces[1] = replace(surfaces[1], conic=surfaces[1].conic + 1.5)
    surfaces[4] = replace(surfaces[4], aspheric=(6e-6, -5e-8))
    op, _ = _optic(replace(lens, surfaces=tuple(surfaces)))
    _compare(ours, nominal, _optiland_chief(op, lens))


# ---------------------------------------------------------------------------- TIRX, TIRY
def _axis_rotation(arr, j: int) -> tuple[np.ndarray, np.ndarray]:
    """(R, vertex) of surface j of instance 0: the rotation of its axis frame and the global
    position of its vertex (0, 0, zv) in that frame (raytrace.kernels.codes layout)."""
    g = arr.geo[0, j]
    R = g[G_ABS : G_ABS + 9].reshape(3, 3)
    o = g[G_ABST : G_ABST + 3]
    return R, o + R @ np.array([0.0, 0.0, g[G_ZV]])


@pytest.mark.parametrize("kind, tir", [("TIRX", 0.004), ("TIRY", -0.006)])
def test_tir_is_the_runout_over_the_clear_diameter(lens, kind, tir):
    """A plane through the tilted surface's vertex with its normal: an indicator moved parallel
    to the axis at ±sd along x (TIRX) or y (TIRY) reads z values differing by TIR (to round-off,
    1e-14 mm); the tilt angle is TIR / clear diameter to its first neglected order θ³/3; the
    vertex stays on the axis and the other surfaces do not move."""
    j = 3
    spec = _spec({"type": kind, "surface": j + 1, "limit": abs(tir)})
    arr = pack_instances(lens, spec, np.array([[tir]]))
    R, vertex = _axis_rotation(arr, j)
    nominal_z = sum(s.thickness for s in lens.surfaces[:j])
    assert np.allclose(vertex, [0.0, 0.0, nominal_z], atol=1e-14, rtol=0)
    n = R @ np.array([0.0, 0.0, 1.0])
    a = 0 if kind == "TIRX" else 1  # the runout direction

    def reading(u):  # z where the line x_a = u (parallel to the axis) meets the plane
        return vertex[2] - n[a] * (u - vertex[a]) / n[2]

    # right-handed turns (raytrace/frames.py): a positive TIRX (about y) raises the -x rim
    # toward +z, a positive TIRY (about x) the +y rim
    runout = reading(-SD) - reading(SD) if kind == "TIRX" else reading(SD) - reading(-SD)
    assert runout == pytest.approx(tir, abs=1e-14)  # ulp of z ~ 10 mm is 1.8e-15
    assert abs(n[1 - a]) < 1e-15  # the turn is about the other axis only
    theta = math.atan2(math.hypot(n[0], n[1]), n[2])
    small = abs(tir) / (2 * SD)
    assert theta == pytest.approx(small, abs=small**3 / 3 * 1.01)
    for k in range(arr.n_surfaces):
        if k != j:
            Rk, _ = _axis_rotation(arr, k)
            assert np.array_equal(Rk, np.eye(3))


@pytest.mark.filterwarnings("ignore")
def test_tirx_and_tiry_instance_equals_optiland(lens):
    """TIRX on surface 2 and TIRY on surface 5: optiland's surface coordinate system turned
    about its own vertex by atan(TIR / 2 sd), about y (TIRX) and x (TIRY), right-handed
    (optiland's CoordinateSystem rx, ry: the mapping tests/test_tolerance_model.py checks for
    element tilts); the other surfaces stay."""
    pytest.importorskip("optiland")
    spec = spec_from_dict({"tolerances": [
        {"type": "TIRX", "surface": 2, "limit": 0.01},
        {"type": "TIRY", "surface": 5, "limit": 0.01},
    ]})  # fmt: skip
    v = [0.008, -0.006]
    ours, nominal = _ours(lens, spec, v)
    op, _ = _optic(lens)
    op.surfaces[2].geometry.cs.ry = math.atan(0.008 / (2 * SD))
    op.surfaces[5].geometry.cs.rx = math.atan(-0.006 / (2 * SD))
    _compare(ours, nominal, _optiland_chief(op, lens))


# ---------------------------------------------------------------------------- TIRR
def test_tirr_is_half_spherical_half_astigmatism(lens):
    """The instance's irregular surface: Zs = Za = N λ/4 normalised to the semi-diameter, so
    the added sag is N λ/2 at the rim along y, N λ/4 along x, 0 at the vertex."""
    N, j = 2.0, 2
    arr = pack_instances(lens, _spec({"type": "TIRR", "surface": j + 1, "limit": N}),
                         np.array([[N]]))  # fmt: skip
    assert arr.kind[0, j] == KIND_IRREGULAR
    zs, za, rn = arr.irr[0, j]
    assert rn == SD
    assert zs == pytest.approx(N * LAMBDA_TEST_MM / 4, rel=1e-15)
    assert za == pytest.approx(N * LAMBDA_TEST_MM / 4, rel=1e-15)

    def added(x, y):
        rho2 = (x * x + y * y) / rn**2
        return zs * rho2 * rho2 + za * y * y / rn**2

    assert added(0.0, SD) == pytest.approx(N * LAMBDA_TEST_MM / 2, rel=1e-14)
    assert added(SD, 0.0) == pytest.approx(N * LAMBDA_TEST_MM / 4, rel=1e-14)
    assert np.all(arr.irr[0, [0, 1, 3, 4, 5], :2] == 0.0)


@pytest.mark.filterwarnings("ignore")
def test_tirr_instance_equals_optiland_xy_polynomial(lens):
    """TIRR of 20 fringes on surface 3 (large, so that the rays move by more than the bound):
    optiland's XY-polynomial surface (sphere + Σ C_ij x^i y^j) with the irregularity written as
    its coefficients, Zs ρ⁴ + Za ρ_y² = Zs (x⁴ + 2x²y² + y⁴)/sd⁴ + Za y²/sd², Newton tolerance
    1e-15 mm."""
    pytest.importorskip("optiland")
    from optiland.geometries import PolynomialGeometry

    N, j = 20.0, 2
    spec = _spec({"type": "TIRR", "surface": j + 1, "limit": N})
    ours, nominal = _ours(lens, spec, [N])
    zs = za = N * LAMBDA_TEST_MM / 4
    C = np.zeros((5, 5))
    C[4, 0] = C[0, 4] = zs / SD**4
    C[2, 2] = 2 * zs / SD**4
    C[0, 2] = za / SD**2
    op, tol = _optic(lens)
    old = op.surfaces[j + 1].geometry
    op.surfaces[j + 1].geometry = PolynomialGeometry(old.cs, old.radius, old.k, tol=tol,
                                                     max_iter=100, coefficients=C)  # fmt: skip
    _compare(ours, nominal, _optiland_chief(op, lens))
