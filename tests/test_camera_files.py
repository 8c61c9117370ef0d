"""Calibration files: OpenCV YAML/JSON (``cv2.FileStorage`` is the referee of the layout),
COLMAP ``cameras.txt`` (pycolmap reads and writes it), Metashape and PhotoScan XML, and the
Australis-style text defined in distortion/camera/files.py.

Sources: the files OpenCV and pycolmap write themselves; the Metashape calibration XML layout
(<calibration> with projection, width, height, f, cx, cy, b1, b2, k1..k4, p1..p4) as in
Agisoft's exports and the chunk/sensor layout quoted in easyidp 2.0.4 ``metashape.py``
(``_decode_sensor_tag`` docstring); the older PhotoScan layout with fx, fy and an absolute cx.
"""

from __future__ import annotations

import numpy as np
import pytest
from support import (
    CAMERA_H,
    CAMERA_W,
    OPENCV_TERMS,
    australis_camera,
    fisheye_camera,
    metashape_camera,
)

from distortion.camera import (
    OPENCV_ORDERS,
    CameraModel,
    colmap_line,
    format_calibration,
    read_calibration,
    read_colmap_cameras,
    write_calibration,
)
from distortion.errors import DataError
from raytrace.errors import OutputError

W, H = CAMERA_W, CAMERA_H


def _opencv(n=14):
    return CameraModel.create(
        "opencv",
        W,
        H,
        fx=3210.25,
        fy=3190.5,
        cx=1523.4,
        cy=987.6,
        **{k: OPENCV_TERMS[k] for k in OPENCV_ORDERS[n]},
    )


FISHEYE = fisheye_camera(fx=900.0, fy=905.0)


@pytest.mark.parametrize("ext", ["yml", "json"])
@pytest.mark.parametrize(
    "cam",
    [_opencv(n) for n in OPENCV_ORDERS] + [FISHEYE],
    ids=lambda c: f"{c.model}{len(c.params)}-{sum(v != 0 for v in c.params)}",
)
def test_opencv_files_round_trip_and_cv2_reads_them(tmp_path, ext, cam):
    path = tmp_path / f"cal.{ext}"
    write_calibration(cam, path)
    back = read_calibration(path)
    assert back == cam
    cv2 = pytest.importorskip("cv2")
    fs = cv2.FileStorage(str(path), cv2.FILE_STORAGE_READ)
    k = fs.getNode("camera_matrix").mat()
    d = fs.getNode("distortion_coefficients").mat().ravel()
    assert int(fs.getNode("image_width").real()) == W
    fs.release()
    p = cam.as_dict()
    assert k[0, 0] == p["fx"] and k[1, 1] == p["fy"] and k[0, 2] == p["cx"]
    if cam.model == "opencv":
        assert d.size == cam.n_opencv_coefficients
        np.testing.assert_array_equal(d, [p[n] for n in OPENCV_ORDERS[d.size]])
    else:
        assert k[0, 1] == p["alpha"] * p["fx"]  # cv2.fisheye keeps the skew as alpha * fx


@pytest.mark.parametrize("ext", ["yml", "json"])
def test_we_read_what_cv2_filestorage_writes(tmp_path, ext):
    cv2 = pytest.importorskip("cv2")
    path = tmp_path / f"cv.{ext}"
    k = np.array([[3210.25, 0.0, 1523.4], [0.0, 3190.5, 987.6], [0.0, 0.0, 1.0]])
    d = np.array([[-0.08, 0.02, 4e-4, -6e-4, -0.003, 0.004, -0.002, 0.001]])
    fs = cv2.FileStorage(str(path), cv2.FILE_STORAGE_WRITE)
    fs.write("image_width", W)
    fs.write("image_height", H)
    fs.write("camera_matrix", k)
    fs.write("distortion_coefficients", d)
    fs.release()
    cam = read_calibration(path)
    assert cam.model == "opencv" and (cam.width, cam.height) == (W, H)
    assert cam["fx"] == 3210.25 and cam["cy"] == 987.6 and cam["k6"] == 0.001
    assert cam.n_opencv_coefficients == 8


def test_colmap_cameras_txt(tmp_path):
    text = (
        "# Camera list with one line of data per camera:\n"
        "1 SIMPLE_RADIAL 3001 1999 3200 1500.5 999.5 -0.05\n"
        "\n"
        "7 OPENCV_FISHEYE 3001 1999 900 905 1500.5 999.5 0.03 -0.006 0.001 -0.0001\n"
    )
    (tmp_path / "cameras.txt").write_text(text)
    cams = read_colmap_cameras(tmp_path / "cameras.txt")
    assert sorted(cams) == [1, 7]
    assert cams[1].model == "colmap:SIMPLE_RADIAL" and cams[1]["k"] == -0.05
    with pytest.raises(DataError, match="holds 2 cameras"):
        read_calibration(tmp_path / "cameras.txt")
    assert read_calibration(tmp_path / "cameras.txt", camera_id=7)["k4"] == -0.0001
    (tmp_path / "bad.txt").write_text("1 OPENCV 3001 1999 1 2 3\n")
    with pytest.raises(DataError, match=r"bad.txt:1: COLMAP OPENCV takes 8 parameters"):
        read_calibration(tmp_path / "bad.txt", format="colmap")
    (tmp_path / "bad2.txt").write_text("# x\n1 OPENCVV 3001 1999 1 2 3\n")
    with pytest.raises(DataError, match=r"bad2.txt:2: unknown camera model.*did you mean"):
        read_calibration(tmp_path / "bad2.txt", format="colmap")


def test_camera_id_is_refused_for_a_file_that_is_not_colmap(tmp_path):
    """camera_id chooses a camera of a COLMAP cameras.txt; any other file holds one camera and
    the id was silently ignored (the command line refused it; now both do)."""
    write_calibration(_opencv(5), tmp_path / "cam.yml")
    write_calibration(australis_camera(), tmp_path / "cam.txt", format="australis")
    write_calibration(_opencv(5), tmp_path / "cameras.txt", format="colmap", camera_id=3)
    for name, fmt in (("cam.yml", "opencv-yaml"), ("cam.txt", "australis")):
        with pytest.raises(DataError) as e:
            read_calibration(tmp_path / name, camera_id=1)
        assert str(e.value) == (
            f"{tmp_path / name}: camera_id=1 chooses a camera of a COLMAP cameras.txt, and this "
            f"file is {fmt}: leave out camera_id"
        )
        assert read_calibration(tmp_path / name).model in ("opencv", "australis")
    with pytest.raises(DataError, match="this file is opencv-yaml"):
        read_calibration(tmp_path / "cam.yml", format="opencv-yaml", camera_id=1)
    assert read_calibration(tmp_path / "cameras.txt", camera_id=3).model.startswith("colmap:")


def test_colmap_line_is_the_smallest_exact_model():
    cam = _opencv(5).replace(k3=0.0)
    assert colmap_line(cam).split()[1] == "OPENCV"
    assert colmap_line(_opencv(5)).split()[1] == "FULL_OPENCV"
    line = colmap_line(_opencv(4).replace(p1=0.0, p2=0.0, fy=3210.25, k2=0.0))
    assert line.split()[1] == "SIMPLE_RADIAL"
    # COLMAP pixels: cx is OpenCV's + 0.5
    assert float(line.split()[5]) == 1523.9


def test_pycolmap_written_cameras_txt_reads_back(tmp_path):
    pycolmap = pytest.importorskip("pycolmap")
    rec = pycolmap.Reconstruction()
    cam = pycolmap.Camera(
        model="FULL_OPENCV",
        width=W,
        height=H,
        params=[
            3210.25,
            3190.5,
            1523.9,
            988.1,
            -0.08,
            0.02,
            4e-4,
            -6e-4,
            -0.003,
            0.004,
            -0.002,
            0.001,
        ],
    )
    cam.camera_id = 3
    rec.add_camera(cam)
    rec.write_text(str(tmp_path))
    ours = read_calibration(tmp_path / "cameras.txt")
    assert ours.model == "colmap:FULL_OPENCV"
    np.testing.assert_array_equal(ours.params, cam.params)


def test_metashape_xml_current_and_photoscan_legacy(tmp_path):
    cam = metashape_camera()
    write_calibration(cam, tmp_path / "m.xml")
    assert read_calibration(tmp_path / "m.xml") == cam
    text = format_calibration(cam.replace(p3=0.0, p4=0.0, k4=0.0), "photoscan")
    assert "<fx>3212.0</fx>" in text and "<fy>3200.0</fy>" in text
    assert f"<cx>{W / 2 + 23.4!r}</cx>" in text and "<skew>1.5</skew>" in text
    (tmp_path / "p.xml").write_text(text)
    back = read_calibration(tmp_path / "p.xml")
    np.testing.assert_allclose(
        back.params, cam.replace(p3=0.0, p4=0.0, k4=0.0).params, rtol=1e-15, atol=1e-12
    )


def test_metashape_calibration_inside_a_chunk_xml(tmp_path):
    # the sensor layout quoted in easyidp 2.0.4 metashape.py (_decode_sensor_tag)
    xml = """<?xml version="1.0" encoding="UTF-8"?>
<document><chunk><sensors>
  <sensor id="0" label="FC6310S" type="frame">
    <resolution width="5472" height="3648"/>
    <property name="pixel_width" value="0.0024"/>
    <calibration type="frame" class="initial"><resolution width="5472" height="3648"/>
      <f>3600</f></calibration>
    <calibration type="frame" class="adjusted">
      <resolution width="5472" height="3648"/>
      <f>3648.2</f><cx>12.5</cx><cy>-7.25</cy>
      <k1>0.002</k1><k2>-0.01</k2><k3>0.012</k3>
      <p1>-0.0011379213280524752</p1><p2>-0.0014457166089453365</p2>
    </calibration>
  </sensor>
</sensors></chunk></document>
"""
    (tmp_path / "cameras.xml").write_text(xml)
    cam = read_calibration(tmp_path / "cameras.xml")
    assert (cam.width, cam.height) == (5472, 3648)
    assert cam["f"] == 3648.2 and cam["cx"] == 12.5 and cam["p2"] == -0.0014457166089453365
    (tmp_path / "fe.xml").write_text(
        "<calibration><projection>fisheye</projection><width>10</width><height>10</height>"
        "<f>5</f></calibration>"
    )
    with pytest.raises(DataError, match="only frame cameras"):
        read_calibration(tmp_path / "fe.xml")


def test_australis_text_round_trip_and_errors(tmp_path):
    cam = australis_camera()
    write_calibration(cam, tmp_path / "cam.txt", format="australis")
    assert read_calibration(tmp_path / "cam.txt") == cam  # detected by its 'format' line
    (tmp_path / "bad.aus").write_text("format orthoscope-australis 1\nimage_width 10\nQ1 3\n")
    with pytest.raises(DataError, match=r"bad.aus:3: unknown name 'Q1'"):
        read_calibration(tmp_path / "bad.aus")


def test_an_x_ray_panel_calibration_with_a_pitch_above_0_1_mm_reads(tmp_path):
    """Review of cfa9e08 (F1): this file (a PerkinElmer XRD 1621 panel, 2048 x 2048 pixels of
    200 µm, c = 1000 mm; the reviewer's xray.aus) read before cfa9e08 and was then refused for
    its pitch above 0.1 mm. It reads again, with no warning."""
    import warnings

    keys = ["image_width 2048", "image_height 2048", "pixel_width_mm 0.2", "pixel_height_mm 0.2"]
    keys += ["c 1000.0", "xp 0.0", "yp -0.0"] + [f"{k} 0.0" for k in "K1 K2 K3 P1 P2 b1 b2".split()]
    path = tmp_path / "xray.aus"
    path.write_text("format orthoscope-australis 1\n" + "\n".join(keys) + "\n")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        cam = read_calibration(path)
    assert (cam.model, cam.width, cam.height) == ("australis", 2048, 2048)
    assert cam.pixel_size_mm == (0.2, 0.2) and cam["c"] == 1000.0


def test_writers_refuse_to_overwrite_and_to_lose_terms(tmp_path):
    cam = _opencv(5)
    write_calibration(cam, tmp_path / "a.yml")
    with pytest.raises(OutputError, match="exists"):
        write_calibration(cam, tmp_path / "a.yml")
    write_calibration(cam.replace(k1=-0.07), tmp_path / "a.yml", overwrite=True)
    assert read_calibration(tmp_path / "a.yml")["k1"] == -0.07
    with pytest.raises(DataError, match="convert_camera_model"):
        write_calibration(_opencv(14), tmp_path / "m.xml")  # prism/tilt: a refit, not a rename
    with pytest.raises(DataError, match="format"):
        write_calibration(cam, tmp_path / "a.cal")


@pytest.mark.parametrize(
    "suffix,names",
    [
        (".xml", ("camera_matrix", "distortion_coefficients")),  # cv2.FileStorage's XML
        (".yml", ("cameraMatrix", "distCoeffs")),  # the names of OpenCV's tutorials
    ],
)
def test_files_cv2_writes_in_other_forms_are_read(tmp_path, suffix, names):
    # written by cv2.FileStorage itself (the referee): the same camera as the matrices given
    cv2 = pytest.importorskip("cv2")
    k = np.array([[6000.0, 0, 1499.5], [0, 6000.0, 999.5], [0, 0, 1]])
    d = np.array([[-0.1, 0.01, 0.001, -0.002, 0.0]])
    path = str(tmp_path / f"cal{suffix}")
    fs = cv2.FileStorage(path, cv2.FILE_STORAGE_WRITE)
    fs.write("image_width", 3000)
    fs.write("image_height", 2000)
    fs.write(names[0], k)
    fs.write(names[1], d)
    fs.release()
    cam = read_calibration(path)
    assert cam.model == "opencv" and (cam.width, cam.height) == (3000, 2000)
    got = cam.as_dict()
    assert (got["fx"], got["fy"], got["cx"], got["cy"]) == (6000.0, 6000.0, 1499.5, 999.5)
    assert [got[n] for n in ("k1", "k2", "p1", "p2", "k3")] == [-0.1, 0.01, 0.001, -0.002, 0.0]


# ---- bad input: one DataError naming the file (and the line where the format has lines) ----
#: cv2.FileStorage's XML layout of an OpenCV calibration (``<opencv_storage>``)
_CV_XML = (
    '<?xml version="1.0"?>\n<opencv_storage>\n'
    f"<image_width>{W}</image_width>\n<image_height>{H}</image_height>\n"
    '<camera_matrix type_id="opencv-matrix"><rows>3</rows><cols>3</cols><dt>d</dt>'
    "<data>3210.25 0 1523.4 0 3190.5 987.6 0 0 1</data></camera_matrix>\n"
    '<distortion_coefficients type_id="opencv-matrix"><rows>1</rows><cols>5</cols><dt>d</dt>'
    "<data>-0.1 0.01 0.001 -0.002 0</data></distortion_coefficients>\n</opencv_storage>\n"
)


def _bad_file(tmp_path, name, old, new):
    """A good calibration file ``name`` (its format from the suffix; ``cv.xml``: cv2's XML)
    with the text ``old`` replaced by ``new`` (``old`` must be in it)."""
    path = tmp_path / name
    if name == "cv.xml":
        text = _CV_XML
    else:
        cam = {".aus": australis_camera(), ".xml": metashape_camera()}.get(path.suffix, _opencv(5))
        text = format_calibration(cam, FORMATS_BY_SUFFIX[path.suffix])
    assert old in text, (old, text)
    path.write_text(text.replace(old, new, 1))
    return path


FORMATS_BY_SUFFIX = {
    ".yml": "opencv-yaml",
    ".json": "opencv-json",
    ".xml": "metashape",
    ".aus": "australis",
}


def test_deeply_nested_json_is_a_data_error(tmp_path):
    """json.loads raised a raw RecursionError on 100,000 '[' (an internal error at the CLI)."""
    (tmp_path / "deep.json").write_text("[" * 100_000 + "\n")
    with pytest.raises(DataError, match=r"deep.json: JSON nested too deeply"):
        read_calibration(tmp_path / "deep.json")
    (tmp_path / "deep.yml").write_text("[" * 100_000 + "\n")  # the echoed line is cut short
    with pytest.raises(DataError, match=r"deep.yml:1: expected 'key: value'") as e:
        read_calibration(tmp_path / "deep.yml")
    assert len(str(e.value)) < 200


@pytest.mark.parametrize(
    "name,old,new,msg",
    [
        # 1e400 is an infinity: int() raised a raw OverflowError
        (
            "c.yml",
            f"image_width: {W}",
            "image_width: 1e400",
            r"c.yml:3: image_width must be a whole",
        ),
        ("c.json", f'"image_width": {W}', '"image_width": 1e400', r"c.json: image_width must be"),
        ("cv.xml", f"<image_width>{W}<", "<image_width>1e400<", r"cv.xml: image_width must be"),
        # a fraction was cut to an int: 3000.5 read as 3000
        ("c.yml", f"image_width: {W}", "image_width: 3000.5", r"whole number of pixels.*'3000.5'"),
        ("c.json", f'"image_height": {H}', '"image_height": 1999.5', r"image_height must be a who"),
        ("m.xml", f"<width>{W}<", "<width>3000.5<", r"m.xml: <width> must be a whole number"),
        ("a.aus", f"image_width {W}", "image_width 3000.5", r"a.aus:8: image_width must be a who"),
        ("c.json", f'"image_width": {W}', '"image_width": true', r"image_width must be a whole"),
    ],
)
def test_whole_number_fields_refuse_infinities_and_fractions(tmp_path, name, old, new, msg):
    with pytest.raises(DataError, match=msg):
        read_calibration(_bad_file(tmp_path, name, old, new))


@pytest.mark.parametrize(
    "name,old,new,msg",
    [
        ("c.json", '"data": [\n            3210.25', '"data": "abc", "x": [3210.25', r"flat list"),
        ("c.json", "3210.25,", "[3210.25, 1],", r"c.json: camera_matrix data must be a flat list"),
        ("c.json", '"rows": 3', '"rows": 1e400', r"c.json: camera_matrix rows must be a whole"),
        ("c.yml", "rows: 3", "rows: .inf", r"c.yml:5: camera_matrix rows must be a whole number"),
        ("c.yml", "rows: 3\n   cols: 3", "rows: -3\n   cols: -3", r"c.yml:5: camera_matrix rows"),
        ("c.yml", "data: [", "data: 1, 2 ]\n   x: [", r"c.yml:9: matrix data must be a list"),
    ],
)
def test_malformed_opencv_matrices_are_data_errors(tmp_path, name, old, new, msg):
    """np.asarray / int() on a matrix raised a raw ValueError / OverflowError."""
    with pytest.raises(DataError, match=msg):
        read_calibration(_bad_file(tmp_path, name, old, new))


@pytest.mark.parametrize(
    "name,old,new,msg",
    [
        ("c.yml", f"image_width: {W}", "image_width: -3000", r":3: image_width must be a whole"),
        ("c.yml", "data: [ 3210.25", "data: [ 0.0", r":5: camera_matrix fx = \[0\]\[0\] and fy"),
        ("c.json", "3210.25,", "1e999,", r"camera_matrix data must be a flat list of finite"),
        ("m.xml", "<f>3200.0<", "<f>inf<", r"<f> is not a finite number: 'inf'"),
        ("m.xml", "<f>3200.0<", "<f>-1<", r"camera model metashape: f must be positive"),
        ("m.xml", f"<width>{W}<", "<width>-3000<", r"<width> must be a whole number"),
        ("a.aus", "pixel_width_mm 0.0078", "pixel_width_mm 0", r":10: pixel_width_mm must be"),
        ("a.aus", "c 25.0", "c 0", r":12: c \(the principal distance, mm\) must be positive"),
        ("a.aus", "K1 8e-05", "K1 inf", r":15: K1 is not a finite number"),
    ],
)
def test_camera_model_checks_name_the_file(tmp_path, name, old, new, msg):
    """The model's own checks were raised as 'camera model opencv: fx must be positive' with
    no file; now every message starts with the file (and its line where the format has lines)."""
    path = _bad_file(tmp_path, name, old, new)
    with pytest.raises(DataError, match=msg) as e:
        read_calibration(path)
    assert str(e.value).startswith(f"{path}")


@pytest.mark.parametrize(
    "name,old,new,msg",
    [
        (
            "c.yml",
            f"image_width: {W}\n",
            f"image_width: {W}\nimage_width: 10\n",
            r"c.yml:4: 'image_wid",
        ),
        ("c.yml", "   cols: 3\n", "   cols: 3\n   cols: 3\n", r"c.yml:8: 'cols' appears twice"),
        ("c.json", f'"image_width": {W},', f'"image_width": {W}, "image_width": 10,', r"twice"),
        ("cv.xml", "<image_height>", "<image_width>10</image_width><image_height>", r"<image_wid"),
        ("a.aus", "c 25.0\n", "c 25.0\nC 26\n", r"a.aus:13: C appears twice \(first on line 12\)"),
    ],
)
def test_a_key_given_twice_is_refused(tmp_path, name, old, new, msg):
    """The last of two values was silently taken."""
    with pytest.raises(DataError, match=msg):
        read_calibration(_bad_file(tmp_path, name, old, new))


def test_australis_format_version_is_checked(tmp_path):
    for head, msg in (
        (
            "format orthoscope-australis 99",
            r":7: .*version '99' is unknown; this reader reads vers",
        ),
        ("format orthoscope-australis", r":7: .* has no version; this reader reads version 1"),
    ):
        path = _bad_file(tmp_path, "a.aus", "format orthoscope-australis 1", head)
        with pytest.raises(DataError, match=msg):
            read_calibration(path)


def test_a_file_not_utf8_is_named_so(tmp_path):
    """Regression pin (distortion.errors.read_text gave this wording already)."""
    (tmp_path / "latin.yml").write_bytes("%YAML:1.0\n# café\nimage_width: 3000\n".encode("latin-1"))
    with pytest.raises(DataError, match=r"latin.yml: not UTF-8 text; a calibration file"):
        read_calibration(tmp_path / "latin.yml")


@pytest.mark.parametrize(
    "old,new,msg",
    [
        # a K whose last row is not 0 0 1 (or with [1][0] set) was read as if it were
        ("0.0,\n            1.0\n", "0.0,\n            2.0\n",
         r"c.json: camera_matrix must read .* last row 0 0 2"),
        ("1523.4,\n            0.0,", "1523.4,\n            0.5,", r"\[1\]\[0\] = 0.5"),
        # two names of one matrix: the first found was used, the other ignored
        ('"camera_matrix": {', '"K": {"rows": 1, "cols": 1, "data": [1]}, "camera_matrix": {',
         r"c.json: holds camera_matrix and K, two names of one matrix; keep one"),
    ],
)  # fmt: skip
def test_a_camera_matrix_that_is_not_opencvs_k_is_refused(tmp_path, old, new, msg):
    with pytest.raises(DataError, match=msg):
        read_calibration(_bad_file(tmp_path, "c.json", old, new))


def test_a_metashape_tag_given_twice_is_refused(tmp_path):
    # the first <f> was used and the second ignored
    path = _bad_file(tmp_path, "m.xml", "<f>3200.0</f>", "<f>3200.0</f><f>3300.0</f>")
    with pytest.raises(DataError, match=r"m.xml: <f> appears twice in <calibration>; keep one"):
        read_calibration(path)
