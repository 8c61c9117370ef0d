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
    A key given twice, an image size or matrix rows/cols that is not a whole number, a
    camera_matrix that is not OpenCV's K ([fx s cx; 0 fy cy; 0 0 1]) and a matrix under two of
    its names are refused (not cut to an int, not the last or first value silently).
``colmap`` (``cameras.txt``)
    COLMAP's text format: ``CAMERA_ID MODEL WIDTH HEIGHT PARAMS[]``, one camera a line, ``#``
    comments; parameters in COLMAP's order (pixel centres at +0.5).
``metashape`` (``.xml``)
    Agisoft Metashape calibration XML: ``<calibration>`` with ``projection`` = frame,
    ``width``, ``height``, ``f``, ``cx``, ``cy`` (offsets from the image centre), ``b1``, ``b2``,
    ``k1``..``k4``, ``p1``..``p4`` (Metashape's P1, P2: P1 = OpenCV p2). Missing coefficients
    are zero; a tag given twice is refused. A ``<calibration>`` inside a Metashape cameras/chunk
    XML is found too (``class="adjusted"`` preferred; image size from ``<resolution width=
    height=>``).
``photoscan`` (``.xml``, the older PhotoScan layout; detected by its ``<fx>``)
    ``fx``, ``fy``, absolute ``cx``, ``cy`` (pixels from the image's top-left corner), ``skew``,
    ``k1``..``k4``, ``p1``, ``p2``. Read as Metashape with f = fy, b1 = fx − fy, b2 = skew,
    cx = cx_abs − W/2, cy = cy_abs − H/2, assuming the distortion terms (and their P1/P2 order)
    are Metashape's. (That assumption is not checked against a PhotoScan installation.)
``australis`` (``.txt`` starting with ``format orthoscope-australis``, or ``.aus``)
    Defined here (Australis' own files are not documented publicly): ``#`` comments, then
    ``name value`` lines: ``format orthoscope-australis 1`` (another version is refused),
    ``image_width``, ``image_height`` (px), ``pixel_width_mm``, ``pixel_height_mm``, and the
    model's parameters ``c xp yp K1 K2 K3 P1 P2 b1 b2`` (mm and mm⁻²ⁱ; image coordinates x
    right, y up, origin at the image centre; a correction measured → ideal, Fraser 1997).
"""

from __future__ import annotations

import json
import math
import os
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from raytrace.files.output import write_atomic
from raytrace.units import is_whole

from ..errors import DataError, read_text
from .convert import smallest_exact
from .models import OPENCV_ORDERS, CameraModel, NotRepresentable, model_spec

FORMATS = ("opencv-yaml", "opencv-json", "colmap", "metashape", "photoscan", "australis")
_AUS_MAGIC = "orthoscope-australis"
_AUS_VERSIONS = ("1",)  # the versions of the Australis-style text this reader knows


def _show(value, n: int = 40) -> str:
    """``value`` quoted for a message, cut to ``n`` characters (a file's text may be huge)."""
    t = str(value)
    return repr(t) if len(t) <= n else repr(t[:n]) + "…"


def _whole(value, what: str, where: str, unit: str = "", least: int = 1) -> int:
    """``value`` (a number or its text, as a file holds it) as a whole number, ``least`` or
    more; a DataError at ``where`` (the file, and its line where known) naming ``what``
    otherwise: a fraction, an infinity, a NaN or a true/false is not silently cut to an int."""
    v = value.strip() if isinstance(value, str) else value
    if isinstance(v, str):
        try:
            v = int(v)
        except ValueError:
            try:
                v = float(v)
            except ValueError:
                pass
    if isinstance(v, float) and math.isfinite(v) and v.is_integer():
        v = int(v)
    if not is_whole(v) or v < least:
        raise DataError(
            f"{where}: {what} must be a whole number{unit}, {least} or more; got {_show(value)}"
        )
    return v


def _create(where: str, model: str, width: int, height: int, **kw) -> CameraModel:
    """CameraModel.create, its DataError prefixed with ``where`` (the file, and a line)."""
    try:
        return CameraModel.create(model, width, height, **kw)
    except DataError as e:
        raise DataError(f"{where}: {e}") from None


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
        return _opencv_from_nodes(*_parse_opencv_yaml(text, p), p)
    if fmt == "opencv-json":

        def no_twice(pairs):
            out = {}
            for k, v in pairs:
                if k in out:
                    raise DataError(f"{p}: key {_show(k)} appears twice; keep one")
                out[k] = v
            return out

        try:
            nodes = json.loads(text, object_pairs_hook=no_twice)
        except json.JSONDecodeError as e:
            raise DataError(f"{p}:{e.lineno}: not valid JSON: {e.msg}") from None
        except RecursionError:
            raise DataError(
                f"{p}: JSON nested too deeply; an OpenCV calibration is one mapping of keys"
            ) from None
        except ValueError:  # an integer of more digits than Python converts to an int
            raise DataError(
                f"{p}: holds an integer thousands of digits long; no calibration value is that long"
            ) from None
        return _opencv_from_nodes(nodes, {}, p)
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


def _parse_opencv_yaml(text: str, path: Path) -> tuple[dict, dict]:
    """The subset of YAML that ``cv2.FileStorage`` writes: top-level scalars and
    ``!!opencv-matrix`` blocks (rows, cols, dt, data: [ … ] over one or more lines). Returns
    the nodes and {top-level key: its line}; a key given twice is refused."""
    lines = text.splitlines()
    out: dict = {}
    where: dict[str, int] = {}

    def once(seen: dict, key: str, n: int, at: dict | None = None) -> None:
        if key in seen:
            first = f" (first on line {at[key]})" if at and key in at else ""
            raise DataError(f"{path}:{n}: {_show(key)} appears twice{first}; keep one")

    i = 0
    while i < len(lines):
        raw = lines[i]
        s = raw.strip()
        if not s or s.startswith("%") or s in ("---", "...") or s.startswith("#"):
            i += 1
            continue
        if raw[0].isspace():
            raise DataError(f"{path}:{i + 1}: unexpected indented line {_show(s)}")
        key, sep, rest = s.partition(":")
        if not sep:
            raise DataError(f"{path}:{i + 1}: expected 'key: value', got {_show(s)}")
        key, rest = key.strip(), rest.strip()
        once(out, key, i + 1, where)
        where[key] = i + 1
        if rest.startswith("!!opencv-matrix"):
            node: dict = {}
            start = i + 1
            i += 1
            while i < len(lines) and (not lines[i].strip() or lines[i][0].isspace()):
                k2, _, v2 = lines[i].strip().partition(":")
                if k2:
                    once(node, k2, i + 1)
                if k2 == "data":
                    if not v2.strip().startswith("["):
                        raise DataError(f"{path}:{i + 1}: matrix data must be a list [ … ]")
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
            node["type_id"] = "opencv-matrix"
            out[key] = node
        else:
            out[key] = _scalar(rest)
            i += 1
    return out, where


#: other names of the two matrices in files written by OpenCV's samples and tutorials
_MATRIX_NAMES = {
    "camera_matrix": ("cameraMatrix", "camera_matrix_K", "K"),
    "distortion_coefficients": ("distCoeffs", "dist_coeffs", "distortion_coeffs", "D"),
}


def _matrix(nodes: dict, key: str, path: Path, lines: dict) -> tuple[np.ndarray, str]:
    """The matrix ``key`` (or an other name of it) as rows × cols, and where it is in the file
    (the file, and its line where the format has lines)."""
    names = [k for k in (key, *_MATRIX_NAMES.get(key, ())) if k in nodes]
    if not names:
        raise DataError(
            f"{path}: no {key!r}; an OpenCV calibration has camera_matrix and "
            "distortion_coefficients"
        )
    if len(names) > 1:
        raise DataError(f"{path}: holds {' and '.join(names)}, two names of one matrix; keep one")
    name = names[0]
    node, at = nodes[name], f"{path}:{lines[name]}" if name in lines else str(path)
    if not isinstance(node, dict) or "data" not in node:
        raise DataError(f"{at}: {name} is not an opencv-matrix (rows, cols, dt, data)")
    raw = node["data"]
    try:
        if not isinstance(raw, list) or not all(
            isinstance(v, (int, float)) and not isinstance(v, bool) for v in raw
        ):
            raise TypeError
        data = np.asarray(raw, dtype=float)
        if not np.isfinite(data).all():
            raise ValueError
    except (TypeError, ValueError, OverflowError):
        raise DataError(
            f"{at}: {name} data must be a flat list of finite numbers [ a, b, … ]"
        ) from None
    rows = _whole(node.get("rows", 1), f"{name} rows", at, least=0)
    cols = _whole(node.get("cols", data.size), f"{name} cols", at, least=0)
    if rows * cols != data.size:
        raise DataError(f"{at}: {name} says {rows}x{cols} but holds {data.size} numbers")
    return data.reshape(rows, cols), at


def _opencv_from_nodes(nodes: dict, lines: dict, path: Path) -> CameraModel:
    """A camera from the nodes of an OpenCV file; ``lines``: {key: its line} where the
    format has lines (YAML), for the messages."""
    if not isinstance(nodes, dict):
        raise DataError(f"{path}: not an OpenCV calibration (expected a mapping of keys)")
    k, at_k = _matrix(nodes, "camera_matrix", path, lines)
    d, at_d = _matrix(nodes, "distortion_coefficients", path, lines)
    d = d.ravel()
    if k.shape != (3, 3):
        raise DataError(f"{at_k}: camera_matrix must be 3x3, got {k.shape[0]}x{k.shape[1]}")
    if k[1, 0] != 0 or list(k[2]) != [0, 0, 1]:
        raise DataError(
            f"{at_k}: camera_matrix must read [fx s cx; 0 fy cy; 0 0 1] (OpenCV's K), got "
            f"[1][0] = {k[1, 0]:g} and last row {' '.join(f'{v:g}' for v in k[2])}"
        )
    if "image_width" not in nodes or "image_height" not in nodes:
        raise DataError(f"{path}: give image_width and image_height (pixels)")
    w, h = (
        _whole(nodes[n], n, f"{path}:{lines[n]}" if n in lines else str(path), " of pixels")
        for n in ("image_width", "image_height")
    )
    if not (k[0, 0] > 0 and k[1, 1] > 0):
        raise DataError(
            f"{at_k}: camera_matrix fx = [0][0] and fy = [1][1] (the focal lengths, pixels) "
            f"must be positive, got fx = {k[0, 0]:g}, fy = {k[1, 1]:g}"
        )
    fx, skew = k[0, 0], k[0, 1]
    pinhole = {"fx": fx, "fy": k[1, 1], "cx": k[0, 2], "cy": k[1, 2]}
    kind = nodes.get("distortion_model", "")
    at_m = f"{path}:{lines['distortion_model']}" if "distortion_model" in lines else str(path)
    if not isinstance(kind, str):
        raise DataError(
            f"{at_m}: distortion_model must be a name (opencv or fisheye), got a "
            f"{type(kind).__name__}"
        )
    kind = kind.lower()
    if kind in ("fisheye", "equidistant", "kannala_brandt", "opencv_fisheye"):
        if d.size != 4:
            raise DataError(f"{at_d}: a fisheye model has 4 coefficients k1..k4, got {d.size}")
        return _create(
            str(path),
            "opencv_fisheye",
            w,
            h,
            **pinhole,
            alpha=float(skew) / float(fx),  # a Python float: an overflow is inf, no warning
            k1=d[0],
            k2=d[1],
            k3=d[2],
            k4=d[3],
        )
    if kind not in ("", "opencv", "plumb_bob", "rational_polynomial", "standard"):
        raise DataError(f"{at_m}: unknown distortion_model {_show(kind)} (opencv or fisheye)")
    if skew != 0:
        raise DataError(
            f"{at_k}: camera_matrix[0][1] = {skew:g} (skew); cv2.projectPoints ignores it and the "
            "OpenCV standard model has none — set it to 0 or use a Metashape model (b2)"
        )
    if d.size not in OPENCV_ORDERS:
        raise DataError(f"{at_d}: {d.size} distortion coefficients; OpenCV takes 4, 5, 8, 12 or 14")
    return _create(
        str(path), "opencv", w, h, **pinhole, **dict(zip(OPENCV_ORDERS[d.size], d, strict=True))
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
        v = float(child.text)
    except ValueError:
        raise DataError(f"{path}: <{tag}> is not a number: {_show(child.text)}") from None
    if not math.isfinite(v):
        raise DataError(f"{path}: <{tag}> is not a finite number: {_show(child.text.strip())}")
    return v


def _storage_nodes(root, path: Path) -> dict:
    """``<opencv_storage>`` children as the YAML reader's nodes: a matrix (``<rows>``,
    ``<cols>``, ``<data>``) as a dict, a scalar as its value."""
    out: dict = {}
    for child in root:
        if child.tag in out:
            raise DataError(f"{path}: <{child.tag[:40]}> appears twice; keep one")
        if child.find("data") is not None:
            try:
                data = [float(v) for v in (child.findtext("data") or "").split()]
            except ValueError:
                raise DataError(
                    f"{path}: <{child.tag[:40]}> holds something not a number"
                ) from None
            out[child.tag] = {"data": data}
            for n in ("rows", "cols"):  # as the file has them: _matrix reads them
                if child.findtext(n) is not None:
                    out[child.tag][n] = child.findtext(n)
        else:
            out[child.tag] = _scalar(child.text or "")
    return out


def _read_metashape(text: str, path: Path) -> CameraModel:
    try:
        root = ET.fromstring(text)
    except ET.ParseError as e:
        raise DataError(f"{path}:{e.position[0]}: not valid XML: {e}") from None
    if root.tag == "opencv_storage":  # cv2.FileStorage's XML: the nodes of its YAML
        return _opencv_from_nodes(_storage_nodes(root, path), {}, path)
    cals = [root] if root.tag == "calibration" else list(root.iter("calibration"))
    if not cals:
        raise DataError(f"{path}: no <calibration> element")
    adjusted = [c for c in cals if c.get("class") == "adjusted"]
    cal = (adjusted or cals)[0]
    tags = [c.tag for c in cal]
    twice = next((t for t in tags if tags.count(t) > 1), None)
    if twice is not None:
        raise DataError(f"{path}: <{twice[:40]}> appears twice in <calibration>; keep one")
    proj = (cal.findtext("projection") or cal.get("type") or "frame").strip()
    if proj != "frame":
        raise DataError(
            f"{path}: Metashape projection {_show(proj)} is not supported; only frame cameras"
        )
    w, h, tags = cal.findtext("width"), cal.findtext("height"), ("<width>", "<height>")
    if w is None or h is None:
        res = cal.find("resolution")
        if res is not None:
            w, h = res.get("width"), res.get("height")
            tags = ("<resolution width>", "<resolution height>")
    if w is None or h is None:
        raise DataError(f"{path}: the calibration needs the image <width> and <height>")
    w, h = (_whole(v, t, str(path), " of pixels") for v, t in zip((w, h), tags, strict=True))
    co = {t: _xml_number(cal, t, path) for t in ("k1", "k2", "k3", "k4", "p1", "p2", "p3", "p4")}
    if cal.find("fx") is not None and cal.find("f") is None:  # PhotoScan (older) layout
        fx = _xml_number(cal, "fx", path, None)
        fy = _xml_number(cal, "fy", path, None)
        return _create(
            str(path),
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
    return _create(
        str(path),
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
    meta: dict[str, int | float] = {}
    at: dict[str, int] = {}  # name: its line
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
            if len(f) != 3 or f[2] not in _AUS_VERSIONS:
                got = f"version {_show(' '.join(f[2:]))} is unknown" if f[2:] else "has no version"
                raise DataError(
                    f"{path}:{n}: the format line's {_AUS_MAGIC} {got}; this reader reads version "
                    f"{', '.join(_AUS_VERSIONS)} (a first line 'format {_AUS_MAGIC} "
                    f"{_AUS_VERSIONS[-1]}')"
                )
            continue
        if len(f) != 2:
            raise DataError(f"{path}:{n}: expected 'name value', got {_show(s)}")
        name = lower.get(key.lower(), key) if key.lower() in ("xp", "yp", "c") else key
        if name in at:
            raise DataError(f"{path}:{n}: {key} appears twice (first on line {at[name]}); keep one")
        if name in spec.params:
            try:
                vals[name] = float(f[1])
            except ValueError:
                raise DataError(f"{path}:{n}: {key} is not a number: {_show(f[1])}") from None
            if not math.isfinite(vals[name]):
                raise DataError(f"{path}:{n}: {key} is not a finite number: {_show(f[1])}")
        elif key in ("image_width", "image_height"):
            meta[key] = _whole(f[1], key, f"{path}:{n}", " of pixels")
        elif key in ("pixel_width_mm", "pixel_height_mm"):
            try:
                meta[key] = float(f[1])
            except ValueError:
                meta[key] = math.nan
            if not (math.isfinite(meta[key]) and meta[key] > 0):
                raise DataError(
                    f"{path}:{n}: {key} must be a positive number (mm), got {_show(f[1])}"
                )
        else:
            raise DataError(
                f"{path}:{n}: unknown name {_show(key)} (parameters: {', '.join(spec.params)}; "
                "image_width, image_height, pixel_width_mm, pixel_height_mm)"
            )
        at[name] = n
    missing = [
        k
        for k in ("image_width", "image_height", "pixel_width_mm", "pixel_height_mm")
        if k not in meta
    ] + [k for k in ("c",) if k not in vals]
    if missing:
        raise DataError(f"{path}: missing {', '.join(missing)}")
    if not vals["c"] > 0:
        raise DataError(f"{path}:{at['c']}: c (the principal distance, mm) must be positive")
    vals.setdefault("xp", 0.0)
    vals.setdefault("yp", 0.0)
    return _create(
        str(path),
        "australis",
        meta["image_width"],
        meta["image_height"],
        pixel_size_mm=(meta["pixel_width_mm"], meta["pixel_height_mm"]),
        **vals,
    )


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
