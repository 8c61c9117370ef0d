"""The frame builder (raytrace/frames.py): conventions of each source program, the decenter types,
coordinate breaks, and the placement table the kernels get.

Sources: the conventions are those stated in raytrace/frames.py with their sources — OpticStudio
coordinate breaks (right-handed tilts; order flag 0 = decenter, then tilt x, y, z; else tilt z, y,
x, then decenter), CODE V decenters (α, β left-handed, γ right-handed; DEC, DAR, BEN, REV) as
ray-optics 0.9.8 implements them. Referees: ray-optics' ``compute_global_coords`` for the CODE V
files of the corpus, optiland's surface coordinate systems for the Zemax files.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import replace

import numpy as np
import pytest
from support import CORPUS, benchmark_module

from raytrace.files import read_lens_file
from raytrace.files.library import load_lens
from raytrace.files.native import dumps, loads
from raytrace.files.zemax import dumps_zmx, loads_zmx
from raytrace.frames import (
    Placement,
    codev_tilt,
    compose,
    move,
    rot_x,
    rot_y,
    rot_z,
    surface_frames,
)
from raytrace.lens import Surface
from raytrace.packing import pack

CODEV_PLACED = [
    "rayoptics/dar_test.seq",
    "rayoptics/dec_rev_tilt_test.seq",
    "rayoptics/dec_test.seq",
    "rayoptics/dec_tilt_test.seq",
    "rayoptics/folded_lenses.seq",
    "rayoptics/tilt_test.seq",
    "rayoptics/threemir.seq",
]
ZEMAX_PLACED = [
    "optiland/one_mirror_up_45deg.zmx",
    "optiland/simple_fold_mirror_up.zmx",
    "rayoptics/HoO-V2C18Ex66.zmx",
    "pyzdde/ConcentricSpheres.zmx",
    "rayoptics/US08011793-1.zmx",
]


def _read(rel):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return read_lens_file(CORPUS / rel)


E = np.eye(3)


def test_rotations_are_right_handed():
    # a right-handed rotation by +90° turns +y into +z (about x), +z into +x (about y), +x into
    # +y (about z)
    assert np.allclose(rot_x(90.0) @ E[1], E[2], atol=1e-15)
    assert np.allclose(rot_y(90.0) @ E[2], E[0], atol=1e-15)
    assert np.allclose(rot_z(90.0) @ E[0], E[1], atol=1e-15)


def test_decenter_then_tilt_and_tilt_then_decenter():
    p = Placement((1.0, 2.0, 0.0), (10.0, 20.0, 30.0), "decenter-tilt")
    Q, d = move(p)
    assert np.allclose(Q, rot_x(10) @ rot_y(20) @ rot_z(30), atol=1e-15)
    assert np.array_equal(d, [1.0, 2.0, 0.0])
    q = Placement((1.0, 2.0, 0.0), (10.0, 20.0, 30.0), "tilt-decenter")
    Q2, d2 = move(q)
    assert np.allclose(Q2, rot_z(30) @ rot_y(20) @ rot_x(10), atol=1e-15)
    assert np.allclose(d2, Q2 @ [1.0, 2.0, 0.0], atol=1e-15)


@pytest.mark.parametrize("order", ["decenter-tilt", "tilt-decenter"])
def test_inverse_is_the_inverse_sequence(order):
    rng = np.random.default_rng(3)
    for _ in range(20):
        p = Placement(tuple(rng.normal(size=3)), tuple(rng.uniform(-80, 80, 3)), order)
        R, o = compose(compose((E, np.zeros(3)), move(p)), move(p.inverse()))
        assert np.allclose(R, E, atol=1e-14) and np.allclose(o, 0.0, atol=1e-14)
        # the OpticStudio statement: order 1 with negated values undoes order 0
        assert p.inverse().order != p.order


def test_negated_values_in_the_same_order_are_not_the_inverse():
    p = Placement((0.0, 1.0, 0.0), (30.0, 20.0, 0.0))
    naive = Placement((0.0, -1.0, 0.0), (-30.0, -20.0, 0.0))  # same order, negated
    R, o = compose(compose((E, np.zeros(3)), move(p)), move(naive))
    assert not np.allclose(R, E, atol=1e-6)


def test_codev_alpha_and_beta_are_left_handed():
    # CODE V: a positive alpha turns +z toward +y (ray-optics euler2opt: alpha, beta negated)
    a, b, c = codev_tilt(45.0, 0.0, 0.0)
    Q, _ = move(Placement((0, 0, 0), (a, b, c)))
    assert Q[1, 2] > 0.7 and Q[2, 2] > 0.7
    assert codev_tilt(1.0, 2.0, 3.0) == (-1.0, -2.0, 3.0)


def test_zemax_plus_45_about_x_folds_the_beam_up():
    # optiland/one_mirror_up_45deg.zmx (authored in OpticStudio, "mirror up"): CB +45° about x,
    # flat mirror at z = 40, CB +45°, 20 mm to the image: the image surface is at y = +20
    lens = _read("optiland/one_mirror_up_45deg.zmx")
    fr = surface_frames(lens)
    assert np.allclose(fr.image_surface_origin, [0.0, 20.0, 40.0], atol=1e-12)
    assert np.allclose(fr.image_surface_rotation[:, 2], [0.0, -1.0, 0.0], atol=1e-15)
    # the axial ray leaves the mirror toward +y
    from raytrace.trace import ray_paths

    rp = ray_paths(lens, ([0.0], [0.0], [-5.0]), ([0.0], [0.0], [1.0]))
    m = [i for i, s in enumerate(lens.surfaces) if s.mirror][0]
    assert np.allclose([rp.x[0, m], rp.y[0, m], rp.z[0, m]], [0.0, 0.0, 40.0], atol=1e-12)


def test_after_modes():
    t = 10.0
    p = Placement((0.0, 1.0, 0.0), (20.0, 0.0, 0.0))
    base = dict(curvature=0.0, thickness=t)

    def frames(after):
        ss = (
            Surface(**base, stop=True),
            Surface(**base, placement=p, after=after),
            Surface(**base),
        )
        from raytrace.lens import Aperture, Field, Lens

        return surface_frames(Lens("t", ss, Aperture("epd", 1.0), Field("angle", 0.0)))

    Q, d = move(p)
    # surface 2 arrives at z = 10. return (DAR): the next surface is on the original axis, t on
    f = frames("return")
    assert np.allclose(f.origin[2], [0.0, 0.0, 20.0], atol=1e-14)
    assert np.allclose(f.rotation[2], E, atol=1e-15)
    # stay (basic decenter): the thickness runs along the tilted axis
    f = frames("stay")
    assert np.allclose(f.origin[2], [0.0, 0.0, 10.0] + d + Q @ [0, 0, t], atol=1e-14)
    # bend: the axis turns by the tilt once more (2 × 20° about x)
    f = frames("bend")
    assert np.allclose(f.rotation[2], rot_x(40.0), atol=1e-14)
    # an explicit move after the surface
    f = frames(p.inverse())
    assert np.allclose(f.rotation[2], E, atol=1e-14)
    assert np.allclose(f.origin[2], [0.0, 0.0, 20.0], atol=1e-13)


def test_codev_reader_maps_the_decenter_types():
    lens = _read("rayoptics/dec_test.seq")
    # s 0 100; yde 25 (basic) / s 0 100; yde -75; ade 30 / s 0 10; rev; ade 30 / mirror, ben, ade 45
    s = lens.surfaces
    assert s[1].placement == Placement((0.0, 25.0, 0.0)) and s[1].after == "stay"
    assert s[2].placement == Placement((0.0, -75.0, 0.0), codev_tilt(30.0, 0, 0))
    assert s[3].placement is None
    assert s[3].after == Placement((0, 0, 0), codev_tilt(30.0, 0, 0)).inverse()
    assert s[4].mirror and s[4].after == "bend"
    dar = _read("rayoptics/dar_test.seq").surfaces
    # s 0 10 / s 0 10; ade 45; dar; yde 1 / s 0 10; ade 45; yde 1; dar: the order of the commands
    # after a surface line does not matter
    assert dar[1].after == "return" and dar[2].after == "return"
    assert dar[1].placement == dar[2].placement == Placement((0, 1.0, 0), codev_tilt(45.0, 0, 0))


def _assert_same_frame(rotation, origin, our_rotation, our_origin, origin_tol):
    """A referee's frame (rotation matrix, origin in mm) equals ours: rotation to 1e-12,
    origin to ``origin_tol`` mm."""
    assert np.max(np.abs(np.asarray(rotation) - our_rotation)) <= 1e-12
    assert np.max(np.abs(np.asarray(origin) - our_origin)) <= origin_tol


@pytest.mark.parametrize("rel", CODEV_PLACED)
def test_codev_frames_equal_rayoptics(rel):
    referees = benchmark_module("referees", needs="rayoptics")
    from rayoptics.elem.transform import compute_global_coords

    lens = _read(rel)
    fr = surface_frames(lens)
    opm, scale = referees.rayoptics_open(CORPUS / rel)
    tf = compute_global_coords(opm["seq_model"], glo=1)
    n = lens.n_surfaces
    for j in range(n):
        r, t = tf[j + 1]
        _assert_same_frame(r, np.asarray(t) * scale, fr.rotation[j], fr.origin[j], 1e-11)
    r, t = tf[n + 1]
    _assert_same_frame(
        r, np.asarray(t) * scale, fr.image_surface_rotation, fr.image_surface_origin, 1e-11
    )


@pytest.mark.parametrize("rel", ZEMAX_PLACED)
def test_zemax_frames_equal_optiland(rel):
    referees = benchmark_module("referees", needs="optiland")
    lens = _read(rel)
    fr = surface_frames(lens)
    op = referees.optiland_open(CORPUS / rel)
    theirs = op.surfaces.surfaces[1:-1]  # optiland folds the coordinate breaks away
    ours = [j for j, s in enumerate(lens.surfaces) if not s.coordinate_break]
    assert len(theirs) == len(ours)
    for srf, j in zip(theirs, ours, strict=True):
        t, R = srf.geometry.cs.get_effective_transform()
        _assert_same_frame(R, t, fr.rotation[j], fr.origin[j], 1e-10)


def test_centred_lens_has_exact_identity_frames_and_the_coaxial_table():
    lens = load_lens("cooke-triplet-f4")
    fr = surface_frames(lens)
    assert not fr.placed.any() and not fr.image_placed
    assert all(np.array_equal(r, E) for r in fr.axis_rotation)
    assert not np.any(fr.axis_origin)
    p = pack(lens)
    assert p.is_coaxial and p.n_surfaces == p.n_lens_surfaces == lens.n_surfaces
    # a mirror on the axis keeps the frames but flags the surfaces
    ss = list(lens.surfaces)
    ss[-1] = replace(ss[-1], mirror=True, thickness=-1.0, material=ss[-2].material)
    m = replace(lens, surfaces=tuple(ss), image_solve=None)
    assert m.is_centred and not pack(m).is_coaxial


def test_fold_adds_the_image_frame_pseudo_surface():
    lens = _read("optiland/one_mirror_up_45deg.zmx")
    p = pack(lens)
    assert p.n_surfaces == lens.n_surfaces + 1 and p.n_lens_surfaces == lens.n_surfaces


def test_coordinate_break_is_not_traced():
    # a 90° break would make a traced plane parallel to the ray (MISSED); it is only a frame
    from raytrace.lens import Aperture, Field, Lens
    from raytrace.trace import trace_rays

    cb = dict(curvature=0.0, coordinate_break=True)
    ss = (
        Surface(0.02, 5.0, material=load_lens("cooke-triplet-f4").surfaces[0].material, stop=True),
        Surface(-0.02, 10.0),
        Surface(**cb, thickness=0.0, placement=Placement((0, 0, 0), (90.0, 0, 0))),
        Surface(**cb, thickness=30.0, placement=Placement((0, 0, 0), (-90.0, 0, 0))),
    )
    lens = Lens("cb", ss, Aperture("epd", 4.0), Field("angle", 0.0))
    plain = replace(lens, surfaces=(ss[0], replace(ss[1], thickness=40.0)))
    out = trace_rays(lens, ([0.0, 1.0], [0.5, -1.0], [-1.0, -1.0]), ([0, 0], [0, 0], [1, 1]))
    assert np.all(out.ok)
    ref = trace_rays(plain, ([0.0, 1.0], [0.5, -1.0], [-1.0, -1.0]), ([0, 0], [0, 0], [1, 1]))
    a = out.at_plane(lens.image_z)
    b = ref.at_plane(lens.image_z)
    assert np.allclose(a, b, atol=1e-12)


@pytest.mark.parametrize("rel", CODEV_PLACED + ZEMAX_PLACED + ["rayoptics/zmax_37992.zmx"])
def test_placements_round_trip_through_toml_exactly(rel):
    lens = _read(rel)
    assert loads(dumps(lens)) == lens


@pytest.mark.parametrize("rel", ZEMAX_PLACED + ["rayoptics/zmax_37992.zmx"])
def test_zemax_placements_round_trip_through_zmx_exactly(rel):
    lens = _read(rel)
    back = loads_zmx(dumps_zmx(lens))
    assert back.surfaces == lens.surfaces and back.image_placement == lens.image_placement


@pytest.mark.parametrize("rel", CODEV_PLACED)
def test_codev_placements_written_to_zmx_trace_the_same(rel):
    from raytrace.trace.chief2d import chief_rays_2d

    lens = _read(rel)
    back = loads_zmx(dumps_zmx(lens))
    g = np.linspace(-0.05, 0.05, 3)
    X, Y = np.meshgrid(g, g)
    kw = (
        dict(fields_x_deg=X, fields_y_deg=Y)
        if math.isinf(lens.object_distance)
        else dict(object_x_mm=X, object_y_mm=Y)
    )
    a = chief_rays_2d(lens, **kw, clip=False).positions_at(lens.image_z)
    b = chief_rays_2d(back, **kw, clip=False).positions_at(back.image_z)
    assert np.max(np.abs(a - b)) <= 1e-12


def test_scaling_scales_decenters_not_tilts():
    lens = _read("rayoptics/dec_test.seq")
    s2 = lens.scaled(2.0)
    assert s2.surfaces[1].placement.decenter == (0.0, 50.0, 0.0)
    assert s2.surfaces[2].placement.tilt == lens.surfaces[2].placement.tilt


def test_invalid_placements_are_refused():
    with pytest.raises(ValueError):
        Placement((0.0, math.nan), (0, 0, 0))
    with pytest.raises(ValueError):
        Placement(order="zyx")
    with pytest.raises(ValueError):
        Surface(0.0, 1.0, after="dar")
    # a zero move is no move (equal lenses, one hash)
    assert Surface(0.0, 1.0, placement=Placement()) == Surface(0.0, 1.0)


def test_meridional_aim_of_a_lens_symmetric_about_its_y_z_plane():
    # the Cooke triplet with its last element decentered in y: the meridional aim (1-D) reaches
    # the stop centre for signed fields (no mirror symmetry y -> -y any more) and agrees with the
    # 2-D aim; decentered in x, the stop centre is off the meridional plane: AIM_FAILED, never a
    # silent number
    from raytrace.kernels.codes import STATUS_AIM_FAILED
    from raytrace.trace import chief_rays
    from raytrace.trace.chief2d import chief_rays_2d

    lens = load_lens("cooke-triplet-f4")
    ss = list(lens.surfaces)
    for k in (4, 5):
        ss[k] = replace(ss[k], placement=Placement((0.0, 0.1, 0.0)), after="return")
    dy = replace(lens, surfaces=tuple(ss))
    f = np.array([-15.0, -5.0, 0.0, 5.0, 15.0])
    one = chief_rays(dy, f, clip=False)
    two = chief_rays_2d(dy, np.zeros_like(f), f, clip=False)
    assert np.all(one.ok)
    assert np.max(np.abs(one.heights_at(dy.image_z) - two.positions_at(dy.image_z)[:, 1])) <= 1e-9
    assert abs(one.heights_at(dy.image_z)[0] + one.heights_at(dy.image_z)[-1]) > 1e-6  # asymmetric
    ss = list(lens.surfaces)
    for k in (0, 1):  # the first element, before the stop
        ss[k] = replace(ss[k], placement=Placement((0.1, 0.0, 0.0)), after="return")
    dx = replace(lens, surfaces=tuple(ss))
    cr = chief_rays(dx, [5.0], clip=False)
    assert cr.status[0] == STATUS_AIM_FAILED and np.isnan(cr.y_last[0])
