"""Tolerancing, the model side: spec errors, the batched paraxial data against
raytrace.paraxial, d EFL / d radius against the analytic derivative of the paraxial EFL, and one
perturbed instance (element decenters and tilts) against optiland 0.6.3."""

from __future__ import annotations

import math

import numpy as np
import pytest

from distortion.tolerance import evaluate, prepare, sensitivity
from raytrace.paraxial import paraxial
from raytrace.tolerance import (
    ToleranceSpecError,
    aim_instances,
    check_against_lens,
    draw_instances,
    nominal_aim,
    pack_instances,
    paraxial_batch,
    perturbed_lens,
    spec_from_dict,
)


# ---------------------------------------------------------------------------- spec errors
@pytest.mark.parametrize(
    "d, words",
    [
        ({"tolerances": [{"type": "TEDZ", "surfaces": [1, 2], "limit": 0.1}]}, "did you mean"),
        ({"tolerances": [{"type": "TRAD", "surface": 1, "min": 0.1, "max": -0.1}]}, "swap"),
        ({"tolerances": [{"type": "TRAD", "surface": 1}]}, "limit"),
        ({"tolerances": [{"type": "TTHI", "surface": 1, "limit": 0.1, "term": 4}]}, "TASP"),
        ({"tolerances": []}, "non-empty"),
        ({"tolerances": [{"type": "TRAD", "surface": 1, "limit": 0.1}], "colour": 1}, "unknown"),
    ],
)
def test_spec_errors_are_one_clear_line(d, words):
    with pytest.raises(ToleranceSpecError) as e:
        spec_from_dict(d, path="spec.toml")
    msg = str(e.value)
    assert "\n" not in msg and msg.startswith("spec.toml") and words in msg


@pytest.mark.parametrize(
    "item, words",
    [
        ({"type": "TRAD", "surface": 9, "limit": 0.1}, "does not exist"),
        ({"type": "TIND", "surface": 2, "limit": 0.001}, "air"),
        ({"type": "TFRN", "surface": 1, "limit": 2}, "semi-diameter"),
    ],
)
def test_spec_errors_against_the_lens(cooke, item, words):
    spec = spec_from_dict({"tolerances": [item]})
    with pytest.raises(ToleranceSpecError, match=words):
        check_against_lens(spec, cooke)


# ---------------------------------------------------------------------------- paraxial
def test_paraxial_batch_equals_paraxial_of_each_instance(cooke):
    """Radius, thickness and index changes: EFL, Gaussian image and K0 (= EFL in the Gaussian
    plane for an object at infinity, Pestrecov Eq. 8) of the batched trace equal
    raytrace.paraxial.paraxial of each perturbed Lens (an independent code path)."""
    spec = spec_from_dict({"tolerances": [
        {"type": "TRAD", "surface": 1, "limit": 0.5},
        {"type": "TTHI", "surface": 2, "adjust": 4, "limit": 0.2},
        {"type": "TIND", "surface": 3, "limit": 0.002},
        {"type": "TABB", "surface": 5, "limit": 1.0},
        {"type": "TEDY", "surfaces": [5, 6], "limit": 0.05},
    ]})  # fmt: skip
    v = draw_instances(spec, 3, range(6))
    arr = pack_instances(cooke, spec, v)
    pb = paraxial_batch(arr, math.inf)
    for i in range(6):
        p = paraxial(perturbed_lens(cooke, spec, v[i]).nominal())
        assert pb.efl[i] == pytest.approx(p.efl, rel=1e-13)
        assert pb.z_image[i] == pytest.approx(p.z_gauss, rel=1e-13)
        assert pb.k0_at(pb.z_image)[i] == pytest.approx(p.efl, rel=1e-12)


def _efl_derivative(lens, j: int) -> float:
    """Analytic d EFL / d R_j of the paraxial EFL (written here, independent of the code under
    test): with the system matrix M = M_after · P_j · M_before on (y, n u) and P_j = [[1, 0],
    [−φ_j, 1]], φ_j = (n'_j − n_j) c_j, the power Φ = −M[1, 0] has dΦ/dφ_j = y_j · D_after, where
    y_j is the height at surface j of the ray entering with (y, nu) = (1, 0) and D_after the
    (1, 1) element of the matrix after surface j; dφ_j/dR_j = −(n'_j − n_j)/R_j² and
    d EFL = −EFL² dΦ."""
    from raytrace.packing import pack

    p = pack(lens, lens.wavelength)
    n = lens.n_surfaces
    t = [s.thickness for s in lens.surfaces]

    def mat(a, b):  # surfaces a..b-1
        M = np.eye(2)
        for k in range(a, b):
            if k > a:
                M = np.array([[1.0, t[k - 1] / p.n_in[k]], [0.0, 1.0]]) @ M
            phi = (p.n_out[k] - p.n_in[k]) * p.c[k]
            M = np.array([[1.0, 0.0], [-phi, 1.0]]) @ M
        return M

    before = mat(0, j)
    y_j = (np.array([[1.0, t[j - 1] / p.n_in[j]], [0.0, 1.0]]) @ before)[0, 0] if j else 1.0
    after = mat(j + 1, n)
    after = after @ np.array([[1.0, t[j] / p.n_out[j]], [0.0, 1.0]])
    D_after = after[1, 1]
    M = mat(0, n)
    efl = -1.0 / M[1, 0]
    R = 1.0 / p.c[j]
    dphi_dR = -(p.n_out[j] - p.n_in[j]) / R**2
    return -(efl**2) * y_j * D_after * dphi_dR


@pytest.mark.parametrize("surface", [1, 4, 6])
def test_efl_sensitivity_to_a_radius_is_the_analytic_derivative(cooke, surface):
    h = 1e-4  # mm: central difference error O(h²) ~ 1e-10 relative
    spec = spec_from_dict({"tolerances": [{"type": "TRAD", "surface": surface, "limit": h}]})
    s = sensitivity(cooke, spec, fields_deg=np.linspace(0, 20, 5), grid_rings=())
    fd = s.slope("efl")[0]
    assert fd == pytest.approx(_efl_derivative(cooke, surface - 1), rel=1e-7)


# ---------------------------------------------------------------------------- optiland
def _optiland_instance(lens, moves):
    """optiland Optic of ``lens`` with each element (a, b) of ``moves`` decentered by (dx, dy)
    and tilted by tx about x (or ty about y) about its front vertex, the surfaces after it
    returning — OpticStudio's TEDX/TEDY/TETX/TETY. Each surface's coordinate system gets its
    global vertex ``(dx, dy, z_a) + Q (0, 0, z_j − z_a)`` and rotation Q (optiland's
    CoordinateSystem: global = origin + Rx(rx) v, right-handed; rotate_x in optiland.rays)."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
    import optiland_adapter as ola

    op = ola.build_optic(lens)
    zv = np.concatenate([[0.0], np.cumsum([s.thickness for s in lens.surfaces[:-1]])])
    for (a, b), (dx, dy, tx, ty) in moves.items():
        assert tx == 0.0 or ty == 0.0  # one axis: Q needs no rotation order
        ax, ay = math.radians(tx), math.radians(ty)
        for j in range(a - 1, b):
            dz = zv[j] - zv[a - 1]
            # Q (0, 0, dz) for Q = Rx(ax) or Ry(ay), right-handed
            qx = dz * math.sin(ay)
            qy = -dz * math.sin(ax)
            qz = dz * math.cos(ax) * math.cos(ay)
            cs = op.surfaces[j + 1].geometry.cs
            cs.x, cs.y, cs.z = float(dx + qx), float(dy + qy), float(zv[a - 1] + qz)
            cs.rx, cs.ry = ax, ay
    op.ray_tracer.set_aiming("iterative", max_iter=50, tol=1e-13)
    return op


@pytest.mark.filterwarnings("ignore")
def test_one_instance_with_element_decenters_and_tilts_equals_optiland(cooke):
    """Elements 1 (surfaces 1-2) and 3 (5-6) of the Cooke triplet decentered and tilted about
    their front vertices: the instance kernel's chief rays on the nominal image plane equal
    optiland 0.6.3's (iterative aim through the real stop centre) to ≤ 1e-9 mm."""
    pytest.importorskip("optiland")
    spec = spec_from_dict({"tolerances": [
        {"type": "TEDX", "surfaces": [1, 2], "limit": 0.05},
        {"type": "TEDY", "surfaces": [1, 2], "limit": 0.05},
        {"type": "TETX", "surfaces": [1, 2], "limit": 0.2},
        {"type": "TEDY", "surfaces": [5, 6], "limit": 0.05},
        {"type": "TETY", "surfaces": [5, 6], "limit": 0.2},
    ]})  # fmt: skip
    v = np.array([[0.03, -0.04, 0.15, 0.02, -0.12]])
    moves = {(1, 2): (0.03, -0.04, 0.15, 0.0), (5, 6): (0.0, 0.02, 0.0, -0.12)}
    ax = np.array([0.0, 0.0, 5.0, -7.0, 10.0, 0.0])
    ay = np.array([0.0, 14.0, 5.0, 12.0, -10.0, -20.0])
    aim = nominal_aim(cooke, spec, ax, ay)
    arr = pack_instances(cooke, spec, v)
    cr = aim_instances(arr, aim, parallel=False)
    assert cr.ok.all()
    z_img = float(paraxial(cooke).z_gauss)
    ours = cr.points_at(z_img)[0]
    op = _optiland_instance(cooke, moves)
    fmax = float(op.fields.max_field)
    rays = op.trace_generic(Hx=ax / fmax, Hy=ay / fmax, Px=0.0, Py=0.0,
                            wavelength=cooke.wavelength / 1000.0)  # fmt: skip
    theirs = np.column_stack([np.asarray(rays.x), np.asarray(rays.y)])
    # the decenters matter: the instance differs from the nominal lens by far more than 1e-9
    nominal = aim_instances(pack_instances(cooke, spec, 0 * v), aim, parallel=False)
    assert np.max(np.abs(nominal.points_at(z_img)[0] - ours)) > 1e-3
    assert np.max(np.abs(ours - theirs)) <= 1e-9


def test_instance_outputs_equal_the_perturbed_lens_traced_alone(cooke):
    """The batched outputs of one instance equal its perturbed Lens (placements of
    raytrace.frames, packed by raytrace.packing) traced by the 2-D chief-ray aim of
    raytrace.trace.chief2d — another kernel and another packing path — to round-off."""
    from raytrace.trace.chief2d import aim_2d

    spec = spec_from_dict({"tolerances": [
        {"type": "TEDY", "surfaces": [3, 4], "limit": 0.05},
        {"type": "TETX", "surfaces": [5, 6], "limit": 0.2},
        {"type": "TRAD", "surface": 2, "limit": 2.0},
    ]})  # fmt: skip
    v = np.array([[0.04, -0.15, 1.5]])
    fields = np.linspace(0, 20, 9)
    st = prepare(cooke, spec, fields_deg=fields, grid_rings=())
    a = evaluate(st, v, parallel=False)
    pl = perturbed_lens(cooke, spec, v[0])
    cr = aim_2d(pl, np.zeros_like(fields), fields, "angle", math.inf, clip=False)
    assert np.all(cr.ok)
    y = cr.y_last + (a.image_z[0] - cr.z_last) * cr.M_last / cr.N_last
    D = (y - a.k0[0] * np.tan(np.radians(fields))) * 1e3
    assert np.max(np.abs(D - a.D_um[0])) < 1e-8
