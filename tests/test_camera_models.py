"""Camera models against the real libraries (issue "camera models", done-when 1 and 3).

Referees: OpenCV (``cv2.projectPoints``, ``cv2.fisheye.projectPoints``, ``cv2.undistortPoints``,
``cv2.fisheye.undistortPoints``; opencv-python-headless, version printed by the test ids) and
COLMAP (``pycolmap.Camera.img_from_cam`` / ``cam_from_img`` of the camera that pycolmap reads
from the ``cameras.txt`` we write). Every model gets random coefficients with every term nonzero,
an off-centre principal point and an odd, non-square image (3001 × 1999), so a swap of p1/p2 or
a flipped axis cannot hide; each comparison also shows that such a swap or flip FAILS it.

Metashape and the Australis (Brown / Fraser) model have no library here; they are checked
against independent transcriptions of their published formulas (Agisoft Metashape User Manual,
Appendix C, as also transcribed in easyidp 2.0.4 ``reconstruct.py``; Fraser 1997, ISPRS J.
Photogramm. 52, Eqs. 1-3), against OpenCV through exact conversion, and by a first-order sign
relation derived by hand below.
"""

from __future__ import annotations

import numpy as np
import pytest

from distortion.camera import (
    FOLDED,
    MODEL_NAMES,
    NOT_CONVERGED,
    OK,
    OPENCV_ORDERS,
    CameraModel,
    convert_camera_model,
    convert_exact,
    model_spec,
    project,
    project_jacobian,
    read_calibration,
    unproject,
    write_calibration,
)

W, H = 3001, 1999  # odd and non-square
TOL = 1e-9  # px, issue 17 done-when

# magnitude ranges of random coefficients (random sign unless noted); small enough that every
# map is one-to-one over the test field. The decentering and thin-prism terms of both kinds of
# model share one range each.
DECENTERING = (2e-4, 8e-4)
THIN_PRISM = (1e-4, 5e-4)
PERSPECTIVE = {
    "k1": (0.05, 0.1), "k2": (0.01, 0.03), "k3": (1e-3, 5e-3),  # OpenCV radial
    "k4": (1e-3, 5e-3), "k5": (1e-3, 3e-3), "k6": (1e-4, 1e-3),  # OpenCV rational
    **dict.fromkeys(("p1", "p2"), DECENTERING),
    **dict.fromkeys(("s1", "s2", "s3", "s4"), THIN_PRISM),
    "tau_x": (5e-3, 2e-2), "tau_y": (5e-3, 2e-2),  # OpenCV sensor tilt
    "k": (0.03, 0.08),  # COLMAP SIMPLE_RADIAL, DIVISION
}  # fmt: skip
FISHEYE = {
    "k0": (0.01, 0.04), "k1": (0.01, 0.04), "k2": (2e-3, 6e-3),  # theta polynomial
    "k3": (2e-4, 8e-4), "k4": (2e-5, 8e-5), "k5": (2e-6, 8e-6),
    **dict.fromkeys(("p0", "p1", "p2"), DECENTERING),
    **dict.fromkeys(("sx1", "sy1", "s0", "s1", "s2", "s3"), THIN_PRISM),
    "alpha": (1e-3, 3e-3),  # OpenCV fisheye skew
    "k": (0.01, 0.04),  # COLMAP SIMPLE_RADIAL_FISHEYE
}  # fmt: skip
POSITIVE = {"omega": (0.3, 0.9), "alpha": (0.3, 0.7), "beta": (0.8, 1.2)}  # FOV, EUCM


def random_camera(name: str, seed_extra: int = 0) -> CameraModel:
    """Every parameter nonzero; principal point off-centre; fx != fy where the model has both."""
    spec = model_spec(name)
    rng = np.random.default_rng(sum(map(ord, name)) + seed_extra)
    fisheye = spec.projection == "equidistant"
    mags = FISHEYE if fisheye else PERSPECTIVE
    f = 900.0 if fisheye else 3200.0
    p = {}
    for n in spec.params:
        if n in ("f", "fx"):
            p[n] = f * rng.uniform(0.98, 1.02)
        elif n == "fy":
            p[n] = f * rng.uniform(1.03, 1.05)
        elif n in ("cx", "cy"):
            p[n] = rng.uniform(15.0, 40.0) * rng.choice([-1, 1])
        elif (
            spec.name.startswith("colmap:")
            and n in ("omega", "alpha", "beta")
            and (spec.name in ("colmap:FOV", "colmap:EUCM"))
        ):
            p[n] = rng.uniform(*POSITIVE[n])
        else:
            p[n] = rng.uniform(*mags[n]) * rng.choice([-1, 1])
    # the principal point: an offset from the centre in the model's own convention
    c0 = {"opencv": ((W - 1) / 2, (H - 1) / 2), "colmap": (W / 2, H / 2)}.get(spec.frame)
    if c0 is not None:
        p["cx"] += c0[0]
        p["cy"] += c0[1]
    return CameraModel.create(name, W, H, **p)


def perspective_points(n=400, seed=1):
    rng = np.random.default_rng(seed)
    xy = np.column_stack([rng.uniform(-0.45, 0.45, n), rng.uniform(-0.3, 0.3, n)])
    return np.vstack([xy, [[0.0, 0.0], [1e-7, -2e-7], [3e-3, 2e-3], [-0.45, 0.3]]])


def fisheye_directions(n=400, seed=2, max_deg=70.0):
    rng = np.random.default_rng(seed)
    th = np.radians(rng.uniform(0.0, max_deg, n))
    ph = rng.uniform(0.0, 2 * np.pi, n)
    d = np.column_stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)])
    return np.vstack([d, [[0.0, 0.0, 1.0], [1e-7, 2e-7, 1.0]]])


def _opencv_arrays(cam: CameraModel, n: int | None = None):
    d = cam.as_dict()
    k = np.array([[d["fx"], 0.0, d["cx"]], [0.0, d["fy"], d["cy"]], [0.0, 0.0, 1.0]])
    if cam.model == "opencv_fisheye":
        k[0, 1] = d["alpha"] * d["fx"]
        return k, np.array([d["k1"], d["k2"], d["k3"], d["k4"]])
    return k, np.array([d[name] for name in OPENCV_ORDERS[n or 14]])


def _cv_undistort(cv2, uv, k, dist):
    crit = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 100, 1e-14)
    src = uv[:, None, :].astype(np.float64)
    if hasattr(cv2, "undistortPointsIter"):  # OpenCV 4.x spelling
        out = cv2.undistortPointsIter(src, k, dist, np.eye(3), np.eye(3), crit)
    else:  # OpenCV 5: undistortPoints takes the criteria
        out = cv2.undistortPoints(src, k, dist, criteria=crit)
    return out[:, 0, :]


# ---- OpenCV standard ----------------------------------------------------------------------------
@pytest.mark.parametrize("n", sorted(OPENCV_ORDERS))
def test_opencv_standard_equals_cv2_projectPoints(n):
    cv2 = pytest.importorskip("cv2")
    cam = random_camera("opencv")
    cam = cam.replace(**{k: 0.0 for k in OPENCV_ORDERS[14] if k not in OPENCV_ORDERS[n]})
    assert cam.n_opencv_coefficients == n
    assert all(cam[k] != 0 for k in OPENCV_ORDERS[n])
    xy = perspective_points()
    k, dist = _opencv_arrays(cam, n)
    obj = np.column_stack([xy, np.ones(len(xy))])
    ref = cv2.projectPoints(obj, np.zeros(3), np.zeros(3), k, dist)[0][:, 0, :]
    ours = project(cam, xy)
    assert ours.ok.all()
    err = np.abs(ours.points - ref).max()
    assert err <= TOL, f"max |ours - cv2.projectPoints| = {err:.3g} px"
    # the comparison has teeth: p1/p2 swapped, or y flipped, is far off
    swapped = cam.replace(p1=cam["p2"], p2=cam["p1"])
    assert np.abs(project(swapped, xy).points - ref).max() > 0.1
    flipped = project(cam, xy * [1.0, -1.0]).points * [1.0, -1.0] + [0.0, 2 * cam["cy"]]
    assert np.abs(flipped - ref).max() > 0.1


@pytest.mark.parametrize("n", sorted(OPENCV_ORDERS))
def test_cv2_undistortPoints_inverts_ours(n):
    cv2 = pytest.importorskip("cv2")
    cam = random_camera("opencv")
    cam = cam.replace(**{k: 0.0 for k in OPENCV_ORDERS[14] if k not in OPENCV_ORDERS[n]})
    xy = perspective_points()
    uv = project(cam, xy).points
    k, dist = _opencv_arrays(cam, n)
    back = _cv_undistort(cv2, uv, k, dist)
    fx = cam["fx"]
    assert np.abs(back - xy).max() * fx <= TOL  # in pixels of the ideal image
    ours = unproject(cam, uv)
    assert ours.ok.all()
    assert np.abs(ours.points - back).max() * fx <= TOL
    assert ours.residual_px.max() <= 2e-11  # Newton converged (1e-12 px or the rounding floor)


def test_opencv_fisheye_equals_cv2_fisheye():
    cv2 = pytest.importorskip("cv2")
    cam = random_camera("opencv_fisheye")
    assert all(v != 0 for v in cam.params)
    dirs = fisheye_directions()
    k, dist = _opencv_arrays(cam)
    ref = cv2.fisheye.projectPoints(
        dirs[:, None, :], np.zeros(3), np.zeros(3), k, dist, alpha=cam["alpha"]
    )[0][:, 0, :]
    ours = project(cam, dirs)
    assert ours.ok.all()
    err = np.abs(ours.points - ref).max()
    assert err <= TOL, f"max |ours - cv2.fisheye.projectPoints| = {err:.3g} px"
    assert np.abs(project(cam.replace(alpha=0.0), dirs).points - ref).max() > 0.1


def test_cv2_fisheye_undistortPoints_inverts_ours():
    # cv2.fisheye.undistortPoints ignores the skew of K (OpenCV reads only fx, fy, cx, cy
    # there), so this inverse is checked with alpha = 0; the skew is covered by the forward test.
    cv2 = pytest.importorskip("cv2")
    cam = random_camera("opencv_fisheye").replace(alpha=0.0)
    dirs = fisheye_directions()
    ideal = dirs[:, :2] / dirs[:, 2:]
    uv = project(cam, dirs).points
    k, dist = _opencv_arrays(cam)
    crit = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 100, 1e-14)
    back = cv2.fisheye.undistortPoints(uv[:, None, :], k, dist, criteria=crit)[:, 0, :]
    assert np.abs(back - ideal).max() * cam["fx"] <= TOL
    ours = unproject(cam, uv)
    assert ours.ok.all()
    assert np.abs(ours.points - ideal).max() * cam["fx"] <= TOL


# ---- COLMAP -------------------------------------------------------------------------------------
COLMAP_MODELS = [m for m in MODEL_NAMES if m.startswith("colmap:")]


def _pycolmap_camera(pycolmap, cam: CameraModel, folder):
    """Write the cameras.txt line and let pycolmap read it back."""
    write_calibration(cam, folder / "cameras.txt")
    (folder / "images.txt").write_text("")
    (folder / "points3D.txt").write_text("")
    rec = pycolmap.Reconstruction()
    rec.read_text(str(folder))
    (cid,) = list(rec.cameras)
    return rec.cameras[cid]


@pytest.mark.parametrize("name", COLMAP_MODELS)
def test_colmap_models_equal_pycolmap(name, tmp_path):
    pycolmap = pytest.importorskip("pycolmap")
    cam = random_camera(name)
    assert all(v != 0 for v in cam.params), cam
    ref_cam = _pycolmap_camera(pycolmap, cam, tmp_path)
    assert ref_cam.model.name == cam.spec.colmap_name
    np.testing.assert_array_equal(np.asarray(ref_cam.params), cam.params)
    fisheye = cam.spec.projection == "equidistant"
    dirs = (
        fisheye_directions()
        if fisheye
        else np.column_stack([perspective_points(), np.ones(len(perspective_points()))])
    )
    ref = np.asarray(ref_cam.img_from_cam(dirs))
    ours = project(cam, dirs)
    assert ours.ok.all()
    err = np.abs(ours.points - ref).max()
    assert err <= TOL, f"{name}: max |ours - pycolmap img_from_cam| = {err:.3g} px"
    back = np.asarray(ref_cam.cam_from_img(ours.points))
    mine = unproject(cam, ours.points)
    assert mine.ok.all()
    ideal = dirs[:, :2] / dirs[:, 2:]
    f = max(cam.as_dict().get("f", 0.0), cam.as_dict().get("fx", 0.0))
    assert np.abs(mine.points - ideal).max() * f <= TOL
    assert np.abs(back - ideal).max() * f <= 1e-6  # pycolmap's own inverse (iterative)
    if "p1" in cam.spec.params and "p2" in cam.spec.params:
        swapped = cam.replace(p1=cam["p2"], p2=cam["p1"])
        assert np.abs(project(swapped, dirs).points - ref).max() > 0.01
    # OpenCV pixels are COLMAP pixels - 0.5 (docs/design.md, Camera models)
    np.testing.assert_allclose(project(cam, dirs, pixels="opencv").points, ref - 0.5, atol=TOL)


def test_colmap_fov_series_branches_equal_pycolmap(tmp_path):
    # COLMAP switches to series when omega^2 < 1e-4 and when r^2 < 1e-4
    pycolmap = pytest.importorskip("pycolmap")
    pts = np.array([[0.0, 0.0, 1.0], [1e-3, -2e-3, 1.0], [5e-3, 4e-3, 1.0], [0.3, -0.2, 1.0]])
    for omega in (0.005, 0.7):
        cam = CameraModel.create(
            "colmap:FOV", W, H, fx=3200.0, fy=3300.0, cx=1523.0, cy=987.0, omega=omega
        )
        sub = tmp_path / f"w{omega}"
        sub.mkdir()
        ref = np.asarray(_pycolmap_camera(pycolmap, cam, sub).img_from_cam(pts))
        assert np.abs(project(cam, pts).points - ref).max() <= TOL


# ---- Metashape ----------------------------------------------------------------------------------
def _metashape_manual(p, w, h, x, y):
    """Agisoft Metashape User Manual, Appendix C (frame camera), written out independently:
    x' = x(1+K1r²+K2r⁴+K3r⁶+K4r⁸) + (P1(r²+2x²) + 2P2xy)(1+P3r²+P4r⁴),
    y' = y(1+K1r²+K2r⁴+K3r⁶+K4r⁸) + (P2(r²+2y²) + 2P1xy)(1+P3r²+P4r⁴),
    u = w·0.5 + cx + x'f + x'B1 + y'B2, v = h·0.5 + cy + y'f."""
    r2 = x * x + y * y
    rad = 1 + p["k1"] * r2 + p["k2"] * r2**2 + p["k3"] * r2**3 + p["k4"] * r2**4
    tm = 1 + p["p3"] * r2 + p["p4"] * r2**2
    xp = x * rad + (p["p1"] * (r2 + 2 * x * x) + 2 * p["p2"] * x * y) * tm
    yp = y * rad + (p["p2"] * (r2 + 2 * y * y) + 2 * p["p1"] * x * y) * tm
    u = w * 0.5 + p["cx"] + xp * p["f"] + xp * p["b1"] + yp * p["b2"]
    v = h * 0.5 + p["cy"] + yp * p["f"]
    return np.column_stack([u, v])


def signed_random_camera(model: str, seed: int, ranges: dict, **fixed) -> CameraModel:
    """MODEL on the W x H sensor: the FIXED parameters as given, and each of RANGES a magnitude
    drawn uniformly from its (lo, hi) with a random sign (drawn in RANGES's order)."""
    rng = np.random.default_rng(seed)
    drawn = {n: rng.uniform(lo, hi) * rng.choice([-1, 1]) for n, (lo, hi) in ranges.items()}
    return CameraModel.create(model, W, H, **fixed, **drawn)


def random_metashape(seed=0):
    ranges = {
        "cx": (15, 40), "cy": (15, 40), "b1": (5, 20), "b2": (0.5, 2),
        "k1": (0.05, 0.1), "k2": (0.01, 0.03), "k3": (1e-3, 5e-3), "k4": (1e-4, 5e-4),
        "p1": (2e-4, 8e-4), "p2": (2e-4, 8e-4), "p3": (0.05, 0.2), "p4": (0.05, 0.2),
    }  # fmt: skip
    return signed_random_camera("metashape", 77 + seed, ranges, f=3200.0)


def test_metashape_equals_manual_formula():
    cam = random_metashape()
    assert all(v != 0 for v in cam.params)
    xy = perspective_points()
    ref = _metashape_manual(cam.as_dict(), W, H, xy[:, 0], xy[:, 1])
    assert np.abs(project(cam, xy).points - ref).max() <= TOL
    back = unproject(cam, ref)
    assert back.ok.all() and np.abs(back.points - xy).max() * 3200 <= TOL


def test_metashape_common_terms_equal_cv2_through_exact_conversion():
    # Metashape without its own extras (k4, p3, p4, b2) is OpenCV's 5-term model: P1 -> p2,
    # P2 -> p1, fx = f + b1, cx = W/2 + cx - 0.5. cv2 is the referee of the converted camera.
    cv2 = pytest.importorskip("cv2")
    cam = random_metashape().replace(k4=0.0, p3=0.0, p4=0.0, b2=0.0)
    cv = convert_exact(cam, "opencv")
    d = cv.as_dict()
    assert d["p1"] == cam["p2"] and d["p2"] == cam["p1"]
    assert d["fx"] == cam["f"] + cam["b1"] and d["cx"] == (W - 1) / 2 + cam["cx"]
    xy = perspective_points()
    k, dist = _opencv_arrays(cv, 5)
    ref = cv2.projectPoints(
        np.column_stack([xy, np.ones(len(xy))]), np.zeros(3), np.zeros(3), k, dist
    )[0][:, 0, :]
    assert np.abs(project(cam, xy, pixels="opencv").points - ref).max() <= TOL
    assert (
        np.abs(_metashape_manual(cam.as_dict(), W, H, xy[:, 0], xy[:, 1]) - 0.5 - ref).max() <= TOL
    )


def test_round_trip_opencv_metashape_colmap_opencv_through_files(tmp_path):
    # Done-when: OpenCV -> Metashape -> COLMAP -> OpenCV over their common terms (fx, fy, cx, cy,
    # k1, k2, k3, p1, p2) is exact algebra, each step through its file format; the referees are
    # cv2 (first and last) and pycolmap (the middle).
    cv2 = pytest.importorskip("cv2")
    pycolmap = pytest.importorskip("pycolmap")
    cam = random_camera("opencv").replace(
        **{k: 0.0 for k in OPENCV_ORDERS[14] if k not in OPENCV_ORDERS[5]}
    )
    write_calibration(cam, tmp_path / "a.yml")
    ms = convert_camera_model(read_calibration(tmp_path / "a.yml"), "metashape")
    assert ms.method == "exact" and ms.rms_px <= TOL
    write_calibration(ms.camera, tmp_path / "b.xml")
    col = convert_camera_model(read_calibration(tmp_path / "b.xml"), "colmap:FULL_OPENCV")
    assert col.method == "exact"
    (tmp_path / "c").mkdir()
    pc = _pycolmap_camera(pycolmap, col.camera, tmp_path / "c")
    back = convert_camera_model(read_calibration(tmp_path / "c" / "cameras.txt"), "opencv")
    write_calibration(back.camera, tmp_path / "d.yml")
    fs = cv2.FileStorage(str(tmp_path / "d.yml"), cv2.FILE_STORAGE_READ)
    k2, d2 = fs.getNode("camera_matrix").mat(), fs.getNode("distortion_coefficients").mat()
    fs.release()
    xy = perspective_points()
    obj = np.column_stack([xy, np.ones(len(xy))])
    k, dist = _opencv_arrays(cam, 5)
    first = cv2.projectPoints(obj, np.zeros(3), np.zeros(3), k, dist)[0][:, 0, :]
    last = cv2.projectPoints(obj, np.zeros(3), np.zeros(3), k2, d2)[0][:, 0, :]
    middle = np.asarray(pc.img_from_cam(obj)) - 0.5
    assert np.abs(last - first).max() <= TOL
    assert np.abs(middle - first).max() <= TOL
    assert np.abs(project(ms.camera, xy, pixels="opencv").points - first).max() <= TOL
    np.testing.assert_allclose(back.camera.params, cam.params, rtol=1e-13, atol=1e-13)


# ---- Australis (Brown / Fraser) -----------------------------------------------------------------
def random_australis():
    ranges = {
        "xp": (0.02, 0.1), "yp": (0.02, 0.1),
        "K1": (5e-5, 1e-4), "K2": (5e-8, 1e-7), "K3": (5e-11, 1e-10),
        "P1": (5e-6, 2e-5), "P2": (5e-6, 2e-5), "b1": (5e-5, 2e-4), "b2": (2e-5, 1e-4),
    }  # fmt: skip
    fixed = dict(pixel_size_mm=(0.0078, 0.0079), c=25.0)
    return signed_random_camera("australis", 1997, ranges, **fixed)


def test_australis_correction_is_fraser_1997():
    # Fraser 1997 Eqs. 1-3 written out: x - xp + dx = c X/Z (photo frame y up: y - yp + dy =
    # -c Y/Z in the camera frame whose y points down).
    cam = random_australis()
    p = cam.as_dict()
    rng = np.random.default_rng(4)
    xm = rng.uniform(-11.0, 11.0, 300)
    ym = rng.uniform(-7.5, 7.5, 300)
    xb, yb = xm - p["xp"], ym - p["yp"]
    r2 = xb**2 + yb**2
    rad = p["K1"] * r2 + p["K2"] * r2**2 + p["K3"] * r2**3
    dx = xb * rad + p["P1"] * (r2 + 2 * xb**2) + 2 * p["P2"] * xb * yb + p["b1"] * xb + p["b2"] * yb
    dy = yb * rad + 2 * p["P1"] * xb * yb + p["P2"] * (r2 + 2 * yb**2)
    expect = np.column_stack([(xb + dx) / p["c"], -(yb + dy) / p["c"]])
    got = unproject(cam, np.column_stack([xm, ym]))  # native frame: photo mm
    assert np.abs(got.points - expect).max() * p["c"] / 0.0078 <= TOL
    fwd = project(cam, expect)
    assert fwd.ok.all() and np.abs(fwd.points - np.column_stack([xm, ym])).max() / 0.0078 <= 2e-11


def test_australis_decentering_and_radial_signs_against_opencv():
    # First order, derived by hand (docs/design.md, Camera models): Brown's correction gives the
    # ideal point; OpenCV's terms give the distorted one, with y down. A measured point is
    # ideal - Δ(ideal) to first order, so in OpenCV normalised coordinates (x = x̄/c, y = -ȳ/c):
    #   K1 (radial)      ->  k1 = -K1 c²
    #   P2 (on ȳ's r²+2ȳ²) -> y_d = y + c P2 (r² + 2y²), x_d = x + 2 c P2 x y  =>  p1 = +c P2
    #   P1 (on x̄'s r²+2x̄²) -> x_d = x - c P1 (r² + 2x²), y_d = y - 2 c P1 x y  =>  p2 = -c P1
    c = 25.0
    for terms, expect in (
        ({"K1": 2e-6}, {"k1": -2e-6 * c**2}),
        ({"P2": 4e-7}, {"p1": c * 4e-7}),
        ({"P1": 4e-7}, {"p2": -c * 4e-7}),
    ):
        cam = CameraModel.create(
            "australis", W, H, pixel_size_mm=(0.0078, 0.0078), c=c, xp=0.05, yp=-0.04, **terms
        )
        cv = convert_camera_model(cam, "opencv", free=5).camera
        for name, value in expect.items():
            assert cv[name] == pytest.approx(value, rel=2e-3), (terms, cv)
        others = [n for n in ("k1", "p1", "p2") if n not in expect]
        scale = abs(next(iter(expect.values())))
        assert all(abs(cv[n]) < 2e-3 * scale for n in others), (terms, cv)


# ---- every model: Jacobian, inverse, status ------------------------------------------------------
def _all_cameras():
    out = [
        random_camera("opencv"),
        random_camera("opencv_fisheye"),
        random_metashape(),
        random_australis(),
    ]
    out += [random_camera(m) for m in COLMAP_MODELS]
    return out


@pytest.mark.parametrize("cam", _all_cameras(), ids=lambda c: c.model)
def test_jacobian_matches_central_differences(cam):
    # An independent numerical check of every analytic Jacobian.
    fisheye = cam.spec.projection == "equidistant"
    pts = (
        (fisheye_directions(40)[:, :2] / fisheye_directions(40)[:, 2:])
        if fisheye
        else perspective_points(40)[:40]
    )
    j = project_jacobian(cam, pts)
    h = 1e-6
    for axis in (0, 1):
        step = np.zeros(2)
        step[axis] = h
        num = (project(cam, pts + step).points - project(cam, pts - step).points) / (2 * h)
        np.testing.assert_allclose(j[:, :, axis], num, rtol=1e-6, atol=1e-6 * np.abs(num).max())


@pytest.mark.parametrize("cam", _all_cameras(), ids=lambda c: c.model)
def test_inverse_round_trip(cam):
    fisheye = cam.spec.projection == "equidistant"
    ideal = (
        (fisheye_directions()[:, :2] / fisheye_directions()[:, 2:])
        if fisheye
        else perspective_points()
    )
    img = project(cam, ideal)
    assert img.ok.all()
    back = unproject(cam, img.points)
    assert back.ok.all()
    j = project_jacobian(cam, ideal)
    scale = np.abs(j).max()
    assert np.abs(back.points - ideal).max() * scale <= TOL


def test_points_beyond_the_fold_get_a_status_not_a_number():
    # k1 = -0.5: r_d = r (1 - r²/2) has its maximum r_d = 0.5443 at r = 0.8165; image radii beyond
    # it have no preimage, and the branch past the maximum folds back.
    cam = CameraModel.create("opencv", W, H, fx=1000.0, fy=1000.0, cx=1500.0, cy=999.0, k1=-0.5)
    rd = np.array([0.1, 0.5, 0.54, 0.56, 0.7])
    uv = np.column_stack([1500.0 + 1000.0 * rd, np.full(rd.size, 999.0)])
    m = unproject(cam, uv)
    assert list(m.status[:3]) == [OK, OK, OK]
    assert all(s in (NOT_CONVERGED, FOLDED) for s in m.status[3:])
    assert np.all(np.isnan(m.points[3:]))
    r = m.points[:3, 0]
    np.testing.assert_allclose(r * (1 - 0.5 * r**2), rd[:3], rtol=0, atol=1e-14)


@pytest.mark.parametrize(
    "ps, match",
    [
        ((3.9, 3.9), r"camera model opencv: pixel_size_mm=\(3.9, 3.9\): a pixel pitch of 3.9 mm is "
         r"above 1 mm; micrometres\? give \(0.0039, 0.0039\) mm"),
        # 0.8 µm given in µm: inside the pitch range (X-ray panels reach 0.2 mm), but 6000 px of
        # 0.8 mm make a 4.8 m sensor
        ((0.8, 0.8), r"camera model opencv: pixel_size_mm=\(0.8, 0.8\): 6000x4000 pixels of that "
         r"pitch make a 4800x3200 mm sensor, larger than 1000 mm; micrometres\? give "
         r"\(0.0008, 0.0008\) mm$"),
        ((0.2, 0.2), r"6000x4000 pixels of that pitch make a 1200x800 mm sensor, larger than "
         r"1000 mm; check the pitch \(mm\) and the image size \(pixels\)$"),
        ((6e-6, 6e-6), r"pixel_size_mm=\(6e-06, 6e-06\): a pixel pitch of 6e-06 mm is below "
         r"0.0003 mm; metres\? give \(0.006, 0.006\) mm"),
        ((0.0, 0.006), r"pixel_size_mm=\(0, 0.006\): give \(pitch_x, pitch_y\) in mm"),
        (0.006, r"pixel_size_mm=0.006: give \(pitch_x, pitch_y\) in mm"),
    ],
)  # fmt: skip
def test_a_pixel_size_in_the_wrong_unit_is_refused_by_the_camera(ps, match):
    """The pitch range of Sensor.from_spec (0.3..1000 µm), said in mm where the keyword is mm;
    above 0.1 mm the sensor the pitch makes stays within Sensor's 1000 mm."""
    with pytest.raises(Exception, match=match) as e:
        CameraModel.create("opencv", 6000, 4000, pixel_size_mm=ps, fx=8333.0, fy=8333.0,
                           cx=2999.5, cy=1999.5)  # fmt: skip
    from distortion.errors import DataError

    assert e.type is DataError


@pytest.mark.parametrize(
    "model, size, ps, c_px",
    [
        ("opencv", (3072, 3072), (0.139, 0.139), 7000.0),  # Varex PaxScan 4343 (139 µm)
        ("australis", (2048, 2048), (0.2, 0.2), 5000.0),  # PerkinElmer XRD 1621 (200 µm)
        ("opencv", (1800, 1800), (0.127, 0.127), 1200.0),  # film scanned at 200 dpi (127 µm)
    ],
)
def test_an_x_ray_panel_or_scanned_film_pitch_is_taken(model, size, ps, c_px, tmp_path):
    """Review of cfa9e08 (F1): a pitch above 0.1 mm was refused, so X-ray flat panels and film
    scanned at 200 dpi could not be built, written or read back; now they are, silently."""
    import warnings

    from distortion.camera import pinhole_camera

    w, h = size
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        cam = pinhole_camera(model, w, h, c_px, c_px, (w - 1) / 2, (h - 1) / 2, pixel_size_mm=ps)
        assert cam.pixel_size_mm == ps
        path = tmp_path / ("c.aus" if model == "australis" else "c.json")
        write_calibration(cam, path)
        back = read_calibration(path)
    if model == "australis":  # the pitch is in the file and the model
        assert back.pixel_size_mm == ps and back["c"] == pytest.approx(c_px * ps[0])
