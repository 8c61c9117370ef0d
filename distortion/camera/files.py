"""Calibration files: OpenCV YAML / JSON, COLMAP ``cameras.txt``, Metashape / PhotoScan XML and an
Australis-style text file. Writers go through :func:`raytrace.files.output.write_atomic`.

Formats (``format=`` names; inferred from the file name when left out):

``opencv-yaml`` (``.yml``, ``.yaml``) and ``opencv-json`` (``.json``)
    The ``cv2.FileStorage`` layout of OpenCV's calibration sample: ``image_width``,
    ``image_height``, ``camera_matrix`` (3 × 3 ``!!opencv-matrix`` / ``"type_id":
    "opencv-matrix"``) and ``distortion_coefficients`` (1 × n, n = 4, 5, 8, 12 or 14:
    k1 k2 p1 p2 k3 k4 k5 k6 s1 s2 s3 s4 τx τy, τ in radians). A fisheye camera has 4
    coefficients k1..k4 and the key ``distortion_model: fisheye`` (our addition: OpenCV's files
    do not say which model they hold; a file without the key is read as the standard model), its
    skew α as camera_matrix[0][1] = α·fx as ``cv2.fisheye`` stores it. A standard-model file with
    a nonzero camera_matrix[0][1] is refused (``cv2.projectPoints`` ignores that element).
    Read also: the tutorials' key names ``cameraMatrix`` / ``distCoeffs`` (and ``K`` / ``D``),
    and the same layout in ``cv2.FileStorage``'s XML (``<opencv_storage>``, a ``.xml`` file).
``colmap`` (``cameras.txt``)
    COLMAP's text format: ``CAMERA_ID MODEL WIDTH HEIGHT PARAMS[]``, one camera a line, ``#``
    comments; parameters in COLMAP's order (pixel centres at +0.5).
``metashape`` (``.xml``)
    Agisoft Metashape calibration XML: ``<calibration>`` with ``projection`` = frame,
    ``width``, ``height``, ``f``, ``cx``, ``cy`` (offsets from the image centre), ``b1``, ``b2``,
    ``k1``..``k4``, ``p1``..``p4`` (Metashape's P1, P2: P1 = OpenCV p2). Missing coefficients
    are zero. A ``<calibration>`` inside a Metashape cameras/chunk XML is found too
    (``class="adjusted"`` preferred; image size from ``<resolution width= height=>``).
``photoscan`` (``.xml``, the older PhotoScan layout; detected by its ``<fx>``)
    ``fx``, ``fy``, absolute ``cx``, ``cy`` (pixels from the image's top-left corner), ``skew``,
    ``k1``..``k4``, ``p1``, ``p2``. Read as Metashape with f = fy, b1 = fx − fy, b2 = skew,
    cx = cx_abs − W/2, cy = cy_abs − H/2, assuming the distortion terms (and their P1/P2 order)
    are Metashape's. (That assumption is not checked against a PhotoScan installation.)
``australis`` (``.txt`` starting with ``format orthoscope-australis``, or ``.aus``)
    Defined here (Australis' own files are not documented publicly): ``#`` comments, then
    ``name value`` lines: ``format orthoscope-australis 1``, ``image_width``,
    ``image_height`` (px), ``pixel_width_mm``, ``pixel_height_mm``, and the model's parameters
    ``c xp yp K1 K2 K3 P1 P2 b1 b2`` (mm and mm⁻²ⁱ; image coordinates x right, y up, origin at
    the image centre; a correction measured → ideal, Fraser 1997).
"""

from __future__ import annotations

import json
import os
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from raytrace.files.output import write_atomic

from ..errors import DataError, read_text
from .convert import smallest_exact
from .models import OPENCV_ORDERS, CameraModel, NotRepresentable, model_spec

FORMATS = ("opencv-yaml", "opencv-json", "colmap", "metashape", "photoscan", "australis")
_AUS_MAGIC = "orthoscope-australis"


def _fmt(v: float) -> str:
    """Shortest text that reads back as the same double."""
    return repr(float(v))


def detect_format(path: str | os.PathLike, text: str | None = None) -> str:
    """The format of a calibration file from its name (and, for .txt/.xml, its content)."""
    p = Path(path)
    suf = p.suffix.lower()
    if suf in (".yml", ".yaml"):
        return "opencv-yaml"
    if suf == ".json":
        return "opencv-json"
    if suf in (".aus", ".australis"):
        return "australis"
    if suf == ".xml":
        if text is not None and re.search(r"<fx>", text) and not re.search(r"<f>", text):
            return "photoscan"
        return "metashape"
    if suf == ".txt":
        if text is not None:
            for line in text.splitlines():
                s = line.strip()
                if s and not s.startswith("#"):
                    return "australis" if s.split()[0:2] == ["format", _AUS_MAGIC] else "colmap"
        return "colmap"
    raise DataError(
        f"{p}: cannot tell the calibration format from the name; give format= one of "
        f"{', '.join(FORMATS)}"
    )


def _check_format(fmt: str) -> str:
    if fmt not in FORMATS:
        raise DataError(f"unknown calibration format {fmt!r}; use one of {', '.join(FORMATS)}")
    return fmt


# ---- reading ------------------------------------------------------------------------------------
def read_calibration(
    path: str | os.PathLike,
    *,
    format: str | None = None,
    camera_id: int | None = None,
    text: str | None = None,
) -> CameraModel:
    """Read a calibration file into a :class:`~distortion.camera.models.CameraModel`.

    ``camera_id`` chooses a camera of a COLMAP ``cameras.txt`` with several (default: the only
    one); it is refused for a file of another format (which holds one camera: the id would do
    nothing). Errors name the file and line and say what to fix (:class:`DataError`).

    Parameters
    ----------
    path : str or os.PathLike
        The calibration file.
    format : str, optional
        One of :data:`FORMATS` (``"opencv-yaml"``, ``"opencv-json"``, ``"colmap"``,
        ``"metashape"``, ``"photoscan"``, ``"australis"``). Default from the name: ``.yml``/
        ``.yaml``, ``.json``, ``.xml`` (Metashape, or legacy PhotoScan by its content), ``.txt``
        (COLMAP, or this package's Australis text by its first line), ``.aus``/``.australis``.
    camera_id : int, optional
        The COLMAP camera id to read (a COLMAP file only).
    text : str, optional
        The file's content, already read (``utf-8-sig``): it is parsed and the file is not read
        again; ``path`` still names the file in the messages and tells the format.

    Returns
    -------
    CameraModel
        In the file's own model, units and conventions.

    Raises
    ------
    DataError
        An unreadable file, an unknown format or one the name does not tell, a malformed file, a
        COLMAP file with several cameras and no ``camera_id``, an id it does not hold, or a
        ``camera_id`` for a file that is not COLMAP.
    """
    p = Path(path)
    if text is None:
        text = read_text(p, "a calibration file")
    fmt = _check_format(format) if format else detect_format(p, text)
    if camera_id is not None and fmt != "colmap":
        raise DataError(
            f"{p}: camera_id={camera_id!r} chooses a camera of a COLMAP cameras.txt, and this file "
            f"is {fmt}: leave out camera_id"
        )
    if fmt == "opencv-yaml":
        return _opencv_from_nodes(_parse_opencv_yaml(text, p), p)
    if fmt == "opencv-json":
        try:
            nodes = json.loads(text)
        except json.JSONDecodeError as e:
            raise DataError(f"{p}:{e.lineno}: not valid JSON: {e.msg}") from None
        return _opencv_from_nodes(nodes, p)
    if fmt == "colmap":
        cams = read_colmap_cameras(p, text=text)
        if camera_id is None:
            if len(cams) != 1:
                raise DataError(
                    f"{p}: holds {len(cams)} cameras ({', '.join(map(str, cams))}); choose one "
                    "with camera_id="
                )
            return next(iter(cams.values()))
        if camera_id not in cams:
            raise DataError(f"{p}: no camera {camera_id} (cameras: {', '.join(map(str, cams))})")
        return cams[camera_id]
    if fmt in ("metashape", "photoscan"):
        return _read_metashape(text, p)
    return _read_australis(text, p)


def _scalar(text: str):
    t = text.strip()
    if len(t) >= 2 and t[0] == t[-1] and t[0] in "\"'":
        return t[1:-1]
    try:
        return int(t)
    except ValueError:
        pass
    try:
        return float(t)
    except ValueError:
        return t


def _parse_opencv_yaml(text: str, path: Path) -> dict:
    """The subset of YAML that ``cv2.FileStorage`` writes: top-level scalars and
    ``!!opencv-matrix`` blocks (rows, cols, dt, data: [ … ] over one or more lines)."""
    lines = text.splitlines()
    out: dict = {}
    i = 0
    while i < len(lines):
        raw = lines[i]
        s = raw.strip()
        if not s or s.startswith("%") or s in ("---", "...") or s.startswith("#"):
            i += 1
            continue
        if raw[0].isspace():
            raise DataError(f"{path}:{i + 1}: unexpected indented line {s!r}")
        key, sep, rest = s.partition(":")
        if not sep:
            raise DataError(f"{path}:{i + 1}: expected 'key: value', got {s!r}")
        rest = rest.strip()
        if rest.startswith("!!opencv-matrix"):
            node: dict = {"type_id": "opencv-matrix"}
            start = i + 1
            i += 1
            while i < len(lines) and (not lines[i].strip() or lines[i][0].isspace()):
                k2, _, v2 = lines[i].strip().partition(":")
                if k2 == "data":
                    buf = v2
                    while "]" not in buf:
                        i += 1
                        if i >= len(lines):
                            raise DataError(f"{path}:{start}: matrix data '[' is never closed")
                        buf += " " + lines[i]
                    inner = buf[buf.index("[") + 1 : buf.index("]")]
                    try:
                        node["data"] = [float(x) for x in inner.replace(",", " ").split()]
                    except ValueError:
                        raise DataError(f"{path}:{i + 1}: matrix data are not numbers") from None
                elif k2:
                    node[k2] = _scalar(v2)
                i += 1
            out[key.strip()] = node
        else:
            out[key.strip()] = _scalar(rest)
            i += 1
    return out


#: other names of the two matrices in files written by OpenCV's samples and tutorials
_MATRIX_NAMES = {
    "camera_matrix": ("cameraMatrix", "camera_matrix_K", "K"),
    "distortion_coefficients": ("distCoeffs", "dist_coeffs", "distortion_coeffs", "D"),
}


def _matrix(nodes: dict, key: str, path: Path) -> np.ndarray:
    node = next((nodes[k] for k in (key, *_MATRIX_NAMES.get(key, ())) if k in nodes), None)
    if node is None:
        raise DataError(
            f"{path}: no {key!r}; an OpenCV calibration has camera_matrix and "
            "distortion_coefficients"
        )
    if not isinstance(node, dict) or "data" not in node:
        raise DataError(f"{path}: {key} is not an opencv-matrix (rows, cols, dt, data)")
    data = np.asarray(node["data"], dtype=float)
    rows, cols = int(node.get("rows", 1)), int(node.get("cols", data.size))
    if rows * cols != data.size:
        raise DataError(f"{path}: {key} says {rows}x{cols} but holds {data.size} numbers")
    return data.reshape(rows, cols)


def _opencv_from_nodes(nodes: dict, path: Path) -> CameraModel:
    if not isinstance(nodes, dict):
        raise DataError(f"{path}: not an OpenCV calibration (expected a mapping of keys)")
    k = _matrix(nodes, "camera_matrix", path)
    d = _matrix(nodes, "distortion_coefficients", path).ravel()
    if k.shape != (3, 3):
        raise DataError(f"{path}: camera_matrix must be 3x3, got {k.shape[0]}x{k.shape[1]}")
    try:
        w, h = int(nodes["image_width"]), int(nodes["image_height"])
    except (KeyError, TypeError, ValueError):
        raise DataError(f"{path}: give image_width and image_height (pixels)") from None
    fx, skew = k[0, 0], k[0, 1]
    pinhole = {"fx": fx, "fy": k[1, 1], "cx": k[0, 2], "cy": k[1, 2]}
    kind = str(nodes.get("distortion_model", "")).lower()
    if kind in ("fisheye", "equidistant", "kannala_brandt", "opencv_fisheye"):
        if d.size != 4:
            raise DataError(f"{path}: a fisheye model has 4 coefficients k1..k4, got {d.size}")
        return CameraModel.create(
            "opencv_fisheye",
            w,
            h,
            **pinhole,
            alpha=skew / fx,
            k1=d[0],
            k2=d[1],
            k3=d[2],
            k4=d[3],
        )
    if kind not in ("", "opencv", "plumb_bob", "rational_polynomial", "standard"):
        raise DataError(f"{path}: unknown distortion_model {kind!r} (opencv or fisheye)")
    if skew != 0:
        raise DataError(
            f"{path}: camera_matrix[0][1] = {skew:g} (skew); cv2.projectPoints ignores it and the "
            "OpenCV standard model has none — set it to 0 or use a Metashape model (b2)"
        )
    if d.size not in OPENCV_ORDERS:
        raise DataError(f"{path}: {d.size} distortion coefficients; OpenCV takes 4, 5, 8, 12 or 14")
    return CameraModel.create(
        "opencv", w, h, **pinhole, **dict(zip(OPENCV_ORDERS[d.size], d, strict=True))
    )


def read_colmap_cameras(path: str | os.PathLike, *, text: str | None = None) -> dict:
    """All cameras of a COLMAP ``cameras.txt``: {camera_id: CameraModel}."""
    p = Path(path)
    if text is None:
        text = read_text(p, "a COLMAP cameras.txt")
    cams: dict[int, CameraModel] = {}
    for n, line in enumerate(text.splitlines(), start=1):
        s = line.strip()
        if not s or s.startswith("#"):
            continue
        f = s.split()
        if len(f) < 4:
            raise DataError(f"{p}:{n}: expected 'CAMERA_ID MODEL WIDTH HEIGHT PARAMS...'")
        try:
            cid, w, h = int(f[0]), int(f[2]), int(f[3])
            vals = [float(x) for x in f[4:]]
        except ValueError:
            raise DataError(
                f"{p}:{n}: camera id, width, height and parameters must be numbers"
            ) from None
        try:
            spec = model_spec("colmap:" + f[1])
        except DataError as e:
            raise DataError(f"{p}:{n}: {e}") from None
        if len(vals) != len(spec.params):
            raise DataError(
                f"{p}:{n}: COLMAP {f[1]} takes {len(spec.params)} parameters "
                f"({', '.join(spec.params)}), the line has {len(vals)}"
            )
        if cid in cams:
            raise DataError(f"{p}:{n}: camera {cid} appears twice")
        try:
            cams[cid] = CameraModel(spec.name, tuple(vals), w, h)
        except DataError as e:
            raise DataError(f"{p}:{n}: {e}") from None
    if not cams:
        raise DataError(f"{p}: no camera lines (CAMERA_ID MODEL WIDTH HEIGHT PARAMS...)")
    return cams


def _xml_number(el: ET.Element, tag: str, path: Path, default: float | None = 0.0) -> float:
    child = el.find(tag)
    if child is None or child.text is None or not child.text.strip():
        if default is None:
            raise DataError(f"{path}: <calibration> has no <{tag}>")
        return default
    try:
        return float(child.text)
    except ValueError:
        raise DataError(f"{path}: <{tag}> is not a number: {child.text!r}") from None


def _storage_nodes(root, path: Path) -> dict:
    """``<opencv_storage>`` children as the YAML reader's nodes: a matrix (``<rows>``,
    ``<cols>``, ``<data>``) as a dict, a scalar as its value."""
    out: dict = {}
    for child in root:
        if child.find("data") is not None:
            try:
                data = [float(v) for v in (child.findtext("data") or "").split()]
                out[child.tag] = {
                    "rows": int(child.findtext("rows") or 1),
                    "cols": int(child.findtext("cols") or len(data)),
                    "data": data,
                }
            except ValueError:
                raise DataError(f"{path}: <{child.tag}> holds something not a number") from None
        else:
            out[child.tag] = _scalar(child.text or "")
    return out


def _read_metashape(text: str, path: Path) -> CameraModel:
    try:
        root = ET.fromstring(text)
    except ET.ParseError as e:
        raise DataError(f"{path}:{e.position[0]}: not valid XML: {e}") from None
    if root.tag == "opencv_storage":  # cv2.FileStorage's XML: the nodes of its YAML
        return _opencv_from_nodes(_storage_nodes(root, path), path)
    cals = [root] if root.tag == "calibration" else list(root.iter("calibration"))
    if not cals:
        raise DataError(f"{path}: no <calibration> element")
    adjusted = [c for c in cals if c.get("class") == "adjusted"]
    cal = (adjusted or cals)[0]
    proj = (cal.findtext("projection") or cal.get("type") or "frame").strip()
    if proj != "frame":
        raise DataError(
            f"{path}: Metashape projection {proj!r} is not supported; only frame cameras"
        )
    w = cal.findtext("width")
    h = cal.findtext("height")
    if w is None or h is None:
        res = cal.find("resolution")
        if res is not None:
            w, h = res.get("width"), res.get("height")
    try:
        w, h = int(w), int(h)
    except (TypeError, ValueError):
        raise DataError(f"{path}: the calibration needs the image <width> and <height>") from None
    co = {t: _xml_number(cal, t, path) for t in ("k1", "k2", "k3", "k4", "p1", "p2", "p3", "p4")}
    if cal.find("fx") is not None and cal.find("f") is None:  # PhotoScan (older) layout
        fx = _xml_number(cal, "fx", path, None)
        fy = _xml_number(cal, "fy", path, None)
        return CameraModel.create(
            "metashape",
            w,
            h,
            f=fy,
            b1=fx - fy,
            b2=_xml_number(cal, "skew", path),
            cx=_xml_number(cal, "cx", path, None) - w / 2.0,
            cy=_xml_number(cal, "cy", path, None) - h / 2.0,
            **co,
        )
    return CameraModel.create(
        "metashape",
        w,
        h,
        f=_xml_number(cal, "f", path, None),
        cx=_xml_number(cal, "cx", path),
        cy=_xml_number(cal, "cy", path),
        b1=_xml_number(cal, "b1", path),
        b2=_xml_number(cal, "b2", path),
        **co,
    )


def _read_australis(text: str, path: Path) -> CameraModel:
    spec = model_spec("australis")
    vals: dict[str, float] = {}
    meta: dict[str, str] = {}
    lower = {n.lower(): n for n in spec.params}
    for n, line in enumerate(text.splitlines(), start=1):
        s = line.split("#", 1)[0].strip()
        if not s:
            continue
        f = s.split()
        key = f[0]
        if key == "format":
            if f[1:2] != [_AUS_MAGIC]:
                raise DataError(f"{path}:{n}: not an orthoscope Australis-style file")
            continue
        if len(f) != 2:
            raise DataError(f"{path}:{n}: expected 'name value', got {s!r}")
        if key in spec.params or key.lower() in ("xp", "yp", "c"):
            name = key if key in spec.params else lower[key.lower()]
            try:
                vals[name] = float(f[1])
            except ValueError:
                raise DataError(f"{path}:{n}: {key} is not a number: {f[1]!r}") from None
        elif key in ("image_width", "image_height", "pixel_width_mm", "pixel_height_mm"):
            meta[key] = f[1]
        else:
            raise DataError(
                f"{path}:{n}: unknown name {key!r} (parameters: {', '.join(spec.params)}; "
                "image_width, image_height, pixel_width_mm, pixel_height_mm)"
            )
    missing = [
        k
        for k in ("image_width", "image_height", "pixel_width_mm", "pixel_height_mm")
        if k not in meta
    ] + [k for k in ("c",) if k not in vals]
    if missing:
        raise DataError(f"{path}: missing {', '.join(missing)}")
    try:
        w, h = int(meta["image_width"]), int(meta["image_height"])
        ps = (float(meta["pixel_width_mm"]), float(meta["pixel_height_mm"]))
    except ValueError:
        raise DataError(f"{path}: image size and pixel size must be numbers") from None
    vals.setdefault("xp", 0.0)
    vals.setdefault("yp", 0.0)
    return CameraModel.create("australis", w, h, pixel_size_mm=ps, **vals)


# ---- writing ------------------------------------------------------------------------------------
#: the model family each calibration file format holds (what ``write`` needs of a camera)
FORMAT_FAMILY = {
    "opencv-yaml": "opencv",
    "opencv-json": "opencv",
    "colmap": "colmap",
    "metashape": "metashape",
    "photoscan": "metashape",
    "australis": "australis",
}


_SUGGEST = {
    "opencv": "opencv",
    "colmap": "colmap:FULL_OPENCV",
    "metashape": "metashape",
    "australis": "australis",
}


def _for_format(camera: CameraModel, fmt: str) -> CameraModel:
    family = FORMAT_FAMILY[fmt]
    try:
        return smallest_exact(camera, family)
    except NotRepresentable as e:
        raise DataError(
            f"a camera of model {camera.model} cannot be written as {fmt} exactly ({e}); "
            f"convert it first with convert_camera_model(camera, {_SUGGEST[family]!r}) and check "
            "the conversion's residual"
        ) from None


def format_calibration(camera: CameraModel, format: str, *, camera_id: int = 1) -> str:
    """The text of a calibration file for ``camera`` (converted exactly to the format's model
    family when needed; DataError when only a refit could do it)."""
    fmt = _check_format(format)
    cam = _for_format(camera, fmt)
    if fmt in ("opencv-yaml", "opencv-json"):
        return _opencv_text(cam, fmt)
    if fmt == "colmap":
        return _colmap_text({camera_id: cam})
    if fmt in ("metashape", "photoscan"):
        return _metashape_text(cam, legacy=fmt == "photoscan")
    return _australis_text(cam)


def write_calibration(
    camera: CameraModel,
    path: str | os.PathLike,
    *,
    format: str | None = None,
    camera_id: int = 1,
    overwrite: bool = False,
    inputs=(),
) -> Path:
    """Write ``camera`` as a calibration file (format from ``format=`` or the file name; a
    ``.txt`` is COLMAP unless ``format="australis"``). Goes through ``write_atomic``: an
    existing file is replaced only with ``overwrite=True``.

    Parameters
    ----------
    camera : CameraModel
        Converted exactly to the format's model family when needed.
    path : str or os.PathLike
        The file to write.
    format : str, optional
        One of :data:`FORMATS`; default from the file name (as :func:`read_calibration`).
    camera_id : int
        The camera id written in a COLMAP ``cameras.txt`` (default 1).
    overwrite : bool
        Replace an existing file.
    inputs : iterable of paths
        Files the output must not be (the files the camera was read from).

    Returns
    -------
    Path
        The file written.

    Raises
    ------
    DataError
        An unknown format, a name that does not tell it, a camera only a refit could convert to
        the format.
    OutputError
        The path is one of ``inputs``, exists without ``overwrite``, is a folder, its folder is
        missing or not writable, or the write fails.
    """
    fmt = _check_format(format) if format else detect_format(path)
    return write_atomic(
        path,
        format_calibration(camera, fmt, camera_id=camera_id),
        inputs=inputs,
        overwrite=overwrite,
    )


def _opencv_text(cam: CameraModel, fmt: str) -> str:
    p = cam.as_dict()
    if cam.model == "opencv_fisheye":
        kmat = [p["fx"], p["alpha"] * p["fx"], p["cx"], 0.0, p["fy"], p["cy"], 0.0, 0.0, 1.0]
        dist = [p["k1"], p["k2"], p["k3"], p["k4"]]
        extra = {"distortion_model": "fisheye"}
    else:
        kmat = [p["fx"], 0.0, p["cx"], 0.0, p["fy"], p["cy"], 0.0, 0.0, 1.0]
        dist = [p[k] for k in OPENCV_ORDERS[cam.n_opencv_coefficients]]
        extra = {}
    if fmt == "opencv-json":
        doc = {
            "image_width": cam.width,
            "image_height": cam.height,
            "camera_matrix": {
                "type_id": "opencv-matrix",
                "rows": 3,
                "cols": 3,
                "dt": "d",
                "data": [float(v) for v in kmat],
            },
            "distortion_coefficients": {
                "type_id": "opencv-matrix",
                "rows": 1,
                "cols": len(dist),
                "dt": "d",
                "data": [float(v) for v in dist],
            },
            **extra,
        }
        return json.dumps(doc, indent=4) + "\n"

    def mat(name, rows, cols, vals):
        data = ", ".join(_fmt(v) for v in vals)
        return (
            f"{name}: !!opencv-matrix\n   rows: {rows}\n   cols: {cols}\n   dt: d\n"
            f"   data: [ {data} ]\n"
        )

    out = [
        "%YAML:1.0\n---\n",
        f"image_width: {cam.width}\n",
        f"image_height: {cam.height}\n",
        mat("camera_matrix", 3, 3, kmat),
        mat("distortion_coefficients", 1, len(dist), dist),
    ]
    for k, v in extra.items():
        out.append(f'{k}: "{v}"\n')
    return "".join(out)


def _colmap_text(cams: dict) -> str:
    lines = [
        "# Camera list with one line of data per camera:",
        "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]",
        f"# Number of cameras: {len(cams)}",
    ]
    for cid, cam in cams.items():
        lines.append(
            " ".join(
                [
                    str(int(cid)),
                    cam.spec.colmap_name,
                    str(cam.width),
                    str(cam.height),
                    *(_fmt(v) for v in cam.params),
                ]
            )
        )
    return "\n".join(lines) + "\n"


def colmap_line(camera: CameraModel, camera_id: int = 1) -> str:
    """One ``cameras.txt`` line for ``camera`` (converted exactly to the smallest COLMAP model
    that holds it)."""
    return _colmap_text({camera_id: _for_format(camera, "colmap")}).splitlines()[-1]


def _metashape_text(cam: CameraModel, legacy: bool) -> str:
    p = cam.as_dict()
    rows = [
        "<projection>frame</projection>",
        f"<width>{cam.width}</width>",
        f"<height>{cam.height}</height>",
    ]
    if legacy:
        rows += [
            f"<fx>{_fmt(p['f'] + p['b1'])}</fx>",
            f"<fy>{_fmt(p['f'])}</fy>",
            f"<cx>{_fmt(cam.width / 2.0 + p['cx'])}</cx>",
            f"<cy>{_fmt(cam.height / 2.0 + p['cy'])}</cy>",
        ]
        if p["b2"]:
            rows.append(f"<skew>{_fmt(p['b2'])}</skew>")
    else:
        rows += [f"<f>{_fmt(p['f'])}</f>", f"<cx>{_fmt(p['cx'])}</cx>", f"<cy>{_fmt(p['cy'])}</cy>"]
        rows += [f"<{k}>{_fmt(p[k])}</{k}>" for k in ("b1", "b2") if p[k]]
    always = ("k1", "k2", "k3", "p1", "p2")
    rows += [
        f"<{k}>{_fmt(p[k])}</{k}>"
        for k in ("k1", "k2", "k3", "k4", "p1", "p2", "p3", "p4")
        if k in always or p[k]
    ]
    body = "\n".join("  " + r for r in rows)
    return f'<?xml version="1.0" encoding="UTF-8"?>\n<calibration>\n{body}\n</calibration>\n'


def _australis_text(cam: CameraModel) -> str:
    px, py = cam.pixel_size_mm
    head = [
        "# orthoscope Australis-style calibration: Brown/Fraser 10-parameter model (Fraser 1997)",
        "# image coordinates in mm, x right, y up, origin at the image centre (the centre of the",
        "# pixel array); a correction measured -> ideal, xbar = x - xp, ybar = y - yp:",
        "#   x_ideal = xbar + xbar (K1 r^2 + K2 r^4 + K3 r^6) + P1 (r^2 + 2 xbar^2)"
        " + 2 P2 xbar ybar + b1 xbar + b2 ybar",
        "#   y_ideal = ybar + ybar (K1 r^2 + K2 r^4 + K3 r^6) + 2 P1 xbar ybar"
        " + P2 (r^2 + 2 ybar^2)",
        "#   x_ideal = c X/Z, y_ideal = -c Y/Z (camera frame x right, y down, z forward)",
        f"format {_AUS_MAGIC} 1",
        f"image_width {cam.width}",
        f"image_height {cam.height}",
        f"pixel_width_mm {_fmt(px)}",
        f"pixel_height_mm {_fmt(py)}",
    ]
    return "\n".join(head + [f"{k} {_fmt(v)}" for k, v in cam.as_dict().items()]) + "\n"
