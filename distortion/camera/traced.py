"""From a prescription to a camera model: real chief rays traced onto a sensor give the
correspondences (ideal direction ↔ image point) that the camera models of this package are
fitted to (docs/design.md, "Camera models from a prescription").

The correspondences of a lens, a :class:`~distortion.camera.setup.CameraSetup` and its
:class:`~distortion.camera.setup.CameraGeometry`:

**Image point** — the real chief ray (through the centre of the real stop;
:func:`raytrace.trace.chief_rays_2d`) meets the sensor plane at (x', y') mm in the lens frame (x
right, y up, looking along −z). The sensor's principal-point offset places the lens axis on the
sensor, so the photogrammetric image coordinates are (x', y') + offset and the pixels follow the
Sensor's conventions (:mod:`distortion.camera.conventions`; OpenCV pixels are the common frame).

**Ideal point** — the direction of the object-space chief ray, in OpenCV's camera frame (x right,
y down, z toward the object): for an object at infinity its direction tangents,
``x = tan αx = L/N``, ``y = −tan αy = −M/N``; for a finite object the direction from the
projection centre — the paraxial entrance pupil E0 at the reference wavelength — to the object
point (xo, yo, z_obj): ``x = xo / p``, ``y = −yo / p`` with ``p = z_obj − z_E0`` (< 0). The lens
+y axis is *down* in the camera's world (camera frame = lens frame turned 180° about y), so the
picture is upright (docs/design.md, "2-D distortion", Frames).

**Where the rays go** — the chief rays are aimed so that their image points form a regular grid
of pixels over the whole sensor, corners included (``CameraSetup.grid`` columns × rows, the grid
of :func:`distortion.camera.convert.sensor_grid`): the fields start at the ideal points and are
corrected a few times by t ← t + (target − traced)/c (c the paraxial camera constant, the
Jacobian of the map to first order); the image points are those of the final trace whatever the
remaining placement error (reported; a few 1e-4 px). A field the lens cannot pass keeps its
status and is left out of every fit.

**Fits** — :func:`fit_points` fits one model, or chooses among a family's candidates by the
stated criterion of :func:`~distortion.camera.fit.select_camera_model` (the simplest with RMS
≤ 0.001 px; otherwise each further term must lower the RMS by more than 10 %). Parameters a
candidate does not fit are held at the model's identity (zero distortion, b1 = b2 = 0), never at
a value of the starting camera. The residual (RMS and maximum of |model(ideal) − traced image
point|, pixels) is part of every result.

**Pupils** — the real entrance pupil moves with the field (pupil aberration). The result carries
:func:`distortion.telecentricity.pupil_analysis` along the meridian out to the sensor's farthest
corner at the reference wavelength: the shift of the real entrance pupil from E0 and the lateral
viewpoint offset per field. For a finite object the viewpoint offset seen from the object plane
is stated in pixels (first order: ``offset/|p| · c/pitch``) — the size of the parallax that a
single-centre camera model cannot represent when the object distance changes.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import DataError
from .convert import convert_camera_model, sensor_grid
from .fit import FAMILIES, CameraFit, ModelSelection, initial_camera, select_camera_model
from .models import OK, OPENCV_ORDERS, CameraModel, model_name, model_spec, project
from .sensor import Sensor
from .setup import CameraGeometry, CameraSetup, make_setup

#: placement iterations of the field grid (module docstring)
PLACEMENT_ITERATIONS = 4
#: pupil-analysis fields along the meridian
PUPIL_FIELDS = 11

#: model words a person may use → a family of fit.FAMILIES (chosen by the criterion)
FAMILY_WORDS = {
    "opencv": "opencv",
    "fisheye": "opencv_fisheye",
    "opencv_fisheye": "opencv_fisheye",
    "kannala-brandt": "opencv_fisheye",
    "colmap": "colmap",
    "colmap-fisheye": "colmap_fisheye",
    "colmap_fisheye": "colmap_fisheye",
    "metashape": "metashape",
    "australis": "australis",
    "brown": "australis",
}
#: how many coefficients n_coefficients may ask for, per family
COEFFICIENT_COUNTS = {"opencv": tuple(OPENCV_ORDERS), "opencv_fisheye": (1, 2, 3, 4)}
#: parameters never reset to the identity when a candidate does not fit them
_GEOMETRY = ("f", "fx", "fy", "cx", "cy", "c", "xp", "yp")


# ---- traced correspondences -------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class CameraPoints:
    """Real chief rays of a lens traced onto a sensor: the correspondences of the camera models.

    Arrays run over the grid's points, row by row (``shape`` = (rows, columns)); a point whose
    chief ray failed has a status and NaN.

    Attributes
    ----------
    setup : CameraSetup
    geometry : CameraGeometry
        Object plane, sensor plane, projection centre, camera constant.
    sensor : Sensor
    shape : (int, int)
        (rows, columns) of the grid.
    field_kind : str
        ``"angle"`` (fields in degrees, object at infinity) or ``"height"`` (object mm).
    fields_x, fields_y : ndarray
        The traced fields (deg or mm).
    ideal : ndarray
        (N, 2) ideal normalised coordinates X/Z, Y/Z (OpenCV camera frame, y down).
    image_mm : ndarray
        (N, 2) image points in the lens frame (mm, x right, y up).
    image_px : ndarray
        (N, 2) image points in OpenCV pixels.
    target_px : ndarray
        (N, 2) the pixel grid the chief rays were aimed at.
    status : ndarray
        (N,) trace status (0 = OK; :data:`raytrace.trace.STATUS_NAMES`).
    pupils : PupilAnalysis
        Real entrance pupil and viewpoint offset along the meridian (reference wavelength).
    """

    setup: CameraSetup
    geometry: CameraGeometry
    sensor: Sensor
    shape: tuple[int, int]
    field_kind: str
    fields_x: np.ndarray
    fields_y: np.ndarray
    ideal: np.ndarray
    image_mm: np.ndarray
    image_px: np.ndarray
    target_px: np.ndarray
    status: np.ndarray
    pupils: object

    @property
    def ok(self) -> np.ndarray:
        return self.status == 0

    @property
    def n_points(self) -> int:
        return int(np.count_nonzero(self.ok))

    @property
    def n_failed(self) -> int:
        return int(self.status.size - self.n_points)

    @property
    def placement_px(self) -> float:
        """Largest distance (px) between a traced image point and the grid point it was aimed
        at (how regularly the points fill the sensor)."""
        d = np.hypot(*(self.image_px[self.ok] - self.target_px[self.ok]).T)
        return float(d.max()) if d.size else math.nan

    @property
    def max_entrance_pupil_shift_mm(self) -> float:
        v = np.abs(self.pupils.entrance_pupil_shift)
        v = v[np.isfinite(v)]
        return float(v.max()) if v.size else math.nan

    @property
    def max_viewpoint_offset_mm(self) -> float:
        return float(self.pupils.max_abs_viewpoint_offset)

    @property
    def viewpoint_parallax_px(self) -> float:
        """The largest viewpoint offset seen from the object plane, in pixels (first order:
        offset/|p| · c/pitch; 0 for an object at infinity)."""
        g = self.geometry
        if g.infinite:
            return 0.0
        p = abs(-g.object_distance - g.z_projection_centre)
        pitch = min(self.sensor.pixel_size_mm)
        return self.max_viewpoint_offset_mm / p * g.camera_constant / pitch

    def valid(self) -> tuple[np.ndarray, np.ndarray]:
        """(ideal, image_px) of the points whose chief rays were traced."""
        return self.ideal[self.ok], self.image_px[self.ok]

    def __repr__(self) -> str:
        g = self.geometry
        return (
            f"CameraPoints({g.lens_name!r}, {self.shape[1]}x{self.shape[0]} chief rays on "
            f"{self.sensor!r}, object {g.object_label}, {g.focus}, {self.n_failed} failed)"
        )


def _object_words(g: CameraGeometry) -> str:
    return "at infinity" if g.infinite else f"{g.object_distance:g} mm from the first vertex"


def trace_camera_points(
    lens, setup: CameraSetup, *, iterations: int = PLACEMENT_ITERATIONS
) -> CameraPoints:
    """Trace the chief rays of ``lens`` onto the sensor of ``setup`` (module docstring).

    Parameters
    ----------
    lens : Lens
    setup : CameraSetup
        Sensor, focus, object plane, wavelength and the grid size.
    iterations : int
        Placement corrections of the fields (0: the ideal grid as it falls).

    Returns
    -------
    CameraPoints
    """
    from distortion.telecentricity import pupil_analysis
    from raytrace.errors import OrthoscopeError
    from raytrace.trace import aim_2d

    geo = setup.resolve(lens)
    sensor = setup.sensor
    nx, ny = setup.grid
    target_px = sensor_grid(sensor.width_px, sensor.height_px, (nx, ny))
    offset = np.asarray(sensor.principal_point_offset_mm, dtype=float)
    target_mm = sensor.pixels_to_mm(target_px) - offset
    c = geo.camera_constant
    finite = not geo.infinite
    z_obj = -geo.object_distance
    p = z_obj - geo.z_projection_centre  # from the projection centre to the object plane (< 0)
    if finite and not p < 0:
        raise DataError(
            f"{lens.name}: the object plane lies at or behind the entrance pupil E0 "
            f"(z_E0 = {geo.z_projection_centre:g} mm); a camera model needs the object in front "
            "of its projection centre"
        )
    t = target_mm / c
    kind = "height" if finite else "angle"

    def fields(tt):
        if finite:
            return tt[:, 0] * p, tt[:, 1] * p
        return np.degrees(np.arctan(tt[:, 0])), np.degrees(np.arctan(tt[:, 1]))

    for it in range(int(iterations) + 1):
        fx, fy = fields(t)
        if not finite and (np.any(np.abs(fx) >= 89.0) or np.any(np.abs(fy) >= 89.0)):
            raise DataError(
                f"{lens.name}: the sensor reaches a field beyond 89 deg; fields beyond 90 deg "
                "are out of scope for these camera models (use a smaller sensor)"
            )
        cr = aim_2d(lens, fx, fy, kind, geo.object_distance, geo.wavelength, setup.clip)
        pts = cr.positions_at(geo.z_image)
        ok = cr.ok
        if it == iterations:
            break
        step = (target_mm - pts) / c
        t = np.where(ok[:, None] & np.all(np.isfinite(step), axis=1)[:, None], t + step, t)
    if finite:
        ideal = np.column_stack([cr.x_start / p, -cr.y_start / p])
    else:
        tx, ty = cr.tan_start
        ideal = np.column_stack([tx, -ty])
    img_mm = np.where(ok[:, None], pts, np.nan)
    ideal = np.where(ok[:, None], ideal, np.nan)
    img_px = sensor.mm_to_pixels(img_mm + offset)
    # the pupils along the meridian out to the farthest traced field
    tmax = float(np.nanmax(np.hypot(*(target_mm / c).T)))
    mer = np.linspace(0.0, tmax, PUPIL_FIELDS)
    try:
        if finite:
            pupils = pupil_analysis(
                lens,
                object_heights_mm=mer * abs(p),
                object_distance=geo.object_distance,
                wavelength=geo.reference_wavelength,
                clip=setup.clip,
            )
        else:
            pupils = pupil_analysis(
                lens,
                fields_deg=np.degrees(np.arctan(mer)),
                object_distance=math.inf,
                wavelength=geo.reference_wavelength,
                clip=setup.clip,
            )
    except OrthoscopeError:  # the pupils are a report, not the model
        pupils = None
    return CameraPoints(
        setup=setup,
        geometry=geo,
        sensor=sensor,
        shape=(ny, nx),
        field_kind=kind,
        fields_x=fx,
        fields_y=fy,
        ideal=ideal,
        image_mm=img_mm,
        image_px=img_px,
        target_px=target_px,
        status=np.asarray(cr.status, dtype=np.int8).copy(),
        pupils=pupils,
    )


# ---- fitting ------------------------------------------------------------------------------------
def _identity_start(start: CameraModel, free: Sequence[str]) -> CameraModel:
    """``start`` with every parameter it does not fit (and that is not a focal length or a
    principal point) at the model's identity."""
    spec = start.spec
    held = {
        n: float(spec.identity.get(n, 0.0))
        for n in spec.params
        if n not in free and n not in _GEOMETRY
    }
    return start.replace(**held) if held else start


def _free_of(model: str, free) -> tuple[str, ...]:
    spec = model_spec(model)
    if free is None:
        return spec.default_free
    if isinstance(free, int | np.integer):
        return ("fx", "fy", "cx", "cy", *OPENCV_ORDERS[int(free)])
    return tuple(free)


def _ladder(model: str, n_coefficients: int | None, free):
    """[(model name, free)] and whether it is a family (a choice) or one model."""
    word = str(model).strip()
    fam = FAMILY_WORDS.get(word.lower())
    if fam is not None and free is None:
        if n_coefficients is not None:
            counts = COEFFICIENT_COUNTS.get(fam)
            if counts is None or int(n_coefficients) not in counts:
                allowed = "; ".join(f"{k}: {', '.join(map(str, v))}" for k, v in
                                    COEFFICIENT_COUNTS.items())  # fmt: skip
                raise DataError(
                    f"n_coefficients={n_coefficients!r} does not apply to model {word!r} "
                    f"({allowed})"
                )
            n = int(n_coefficients)
            if fam == "opencv":
                return [("opencv", n)], False
            return [
                ("opencv_fisheye", ("fx", "fy", "cx", "cy", *(f"k{i}" for i in range(1, n + 1))))
            ], False
        return [(m, f) for m, f in FAMILIES[fam]], True
    name = model_name(word)  # DataError with the known names
    if n_coefficients is not None:
        if name != "opencv":
            raise DataError(f"n_coefficients applies to the opencv and fisheye models, not {name}")
        return [(name, int(n_coefficients))], False
    return [(name, free)], False


def fit_correspondences(
    ideal,
    image_px,
    sensor: Sensor,
    model: str = "opencv",
    *,
    n_coefficients: int | None = None,
    free: Sequence[str] | None = None,
) -> tuple[CameraFit, ModelSelection | None, str]:
    """Fit a camera model (or choose one of a family) to correspondences on ``sensor``.

    Parameters
    ----------
    ideal : array_like
        (N, 2) ideal normalised coordinates (OpenCV camera frame: x right, y down).
    image_px : array_like
        (N, 2) image points in OpenCV pixels.
    sensor : Sensor
        Image size and pixel pitch.
    model : str
        A family — ``"opencv"``, ``"fisheye"`` (OpenCV fisheye / Kannala–Brandt),
        ``"colmap"``, ``"colmap-fisheye"``, ``"metashape"``, ``"australis"`` — chosen by the
        criterion of :func:`~distortion.camera.fit.select_camera_model`; or one model name
        (``"colmap:OPENCV"``, ``"colmap:OPENCV_FISHEYE"``, ...) fitted as it is.
    n_coefficients : int, optional
        Fix the coefficient count: 4, 5, 8, 12 or 14 for ``opencv``; 1–4 for ``fisheye``.
    free : sequence of str, optional
        The parameters to fit (one model only; default the model's own set).

    Returns
    -------
    (CameraFit, ModelSelection or None, criterion)
    """
    xy = np.asarray(ideal, dtype=float)
    uv = np.asarray(image_px, dtype=float)
    ok = np.all(np.isfinite(xy), axis=1) & np.all(np.isfinite(uv), axis=1)
    xy, uv = xy[ok], uv[ok]
    ladder, family = _ladder(model, n_coefficients, free)
    w, h, ps = sensor.width_px, sensor.height_px, sensor.pixel_size_mm
    need = max(len(_free_of(n, f)) for n, f in ladder)
    if xy.shape[0] * 2 <= need:  # before any start is fitted to too few points
        n, total = xy.shape[0], ok.size
        why = (
            f"the grid gives {total} points (a larger grid)"
            if n == total
            else f"only {n} of {total} chief rays reached the sensor (a sensor the lens covers, "
            "or a principal point inside its image)"
        )
        raise DataError(f"{need} free parameters need more than {need // 2} traced points: {why}")
    starts = []
    for name, fr in ladder:
        names = _free_of(name, fr)
        start = initial_camera(name, xy, uv, width=w, height=h, pixel_size_mm=ps)
        starts.append((_identity_start(start, names), fr if isinstance(fr, int) else names))
    sel = select_camera_model(xy, uv, starts, width=w, height=h, pixel_size_mm=ps)
    if family:
        return sel.chosen, sel, sel.criterion
    f = sel.chosen
    return f, None, f"one model asked for: {f.camera.model} with {', '.join(f.free)} free"


@dataclass(frozen=True, eq=False)
class TracedCamera:
    """A camera model fitted to the traced chief rays of a lens on a sensor.

    Attributes
    ----------
    camera : CameraModel
        The fitted model (its own units and conventions).
    points : CameraPoints
        The traced correspondences it was fitted to.
    fit : CameraFit
        The fit (residuals, standard errors, correlations).
    selection : ModelSelection or None
        The candidates of a family and their fits, when a family was asked for.
    criterion : str
        How the model (and its number of terms) was chosen.
    request : str
        The model asked for.
    """

    camera: CameraModel
    points: CameraPoints
    fit: CameraFit
    selection: ModelSelection | None
    criterion: str
    request: str

    @property
    def geometry(self) -> CameraGeometry:
        return self.points.geometry

    @property
    def sensor(self) -> Sensor:
        return self.points.sensor

    @property
    def rms_px(self) -> float:
        return float(self.fit.rms_px)

    @property
    def max_px(self) -> float:
        return float(self.fit.max_px)

    @property
    def model(self) -> str:
        return self.camera.model

    @property
    def coefficients(self) -> dict[str, float]:
        """The model's parameters by name (its own units)."""
        return self.camera.as_dict()

    @property
    def camera_matrix(self) -> np.ndarray:
        """3 × 3 OpenCV camera matrix (``opencv`` and ``opencv_fisheye`` models)."""
        p = self._opencv_params()
        skew = p.get("alpha", 0.0) * p["fx"]
        return np.array([[p["fx"], skew, p["cx"]], [0.0, p["fy"], p["cy"]], [0.0, 0.0, 1.0]])

    @property
    def dist_coeffs(self) -> np.ndarray:
        """OpenCV's distortion vector (4/5/8/12/14 elements; fisheye: k1..k4)."""
        p = self._opencv_params()
        if self.camera.model == "opencv_fisheye":
            return np.array([p[k] for k in ("k1", "k2", "k3", "k4")])
        return np.array([p[k] for k in OPENCV_ORDERS[self.camera.n_opencv_coefficients]])

    def _opencv_params(self) -> dict:
        if self.camera.model not in ("opencv", "opencv_fisheye"):
            raise DataError(
                f"camera_matrix / dist_coeffs are OpenCV's; this camera is {self.camera.model}: "
                "convert it with .convert('opencv')"
            )
        return self.camera.as_dict()

    def convert(self, target: str, **kw):
        """:func:`~distortion.camera.convert.convert_camera_model` of the fitted camera (exact
        where the terms allow, otherwise a refit with its residual)."""
        return convert_camera_model(self.camera, target, **kw)

    def colmap_line(self, camera_id: int = 1) -> str:
        """The camera as one COLMAP ``cameras.txt`` line (the smallest COLMAP model that holds
        it exactly)."""
        from .files import colmap_line

        return colmap_line(self.camera, camera_id)

    def calibration_text(self, format: str) -> str:
        """The camera as the text of a calibration file (``opencv-yaml``, ``opencv-json``,
        ``colmap``, ``metashape``, ``photoscan``, ``australis``)."""
        from .files import format_calibration

        return format_calibration(self.camera, format)

    def write(self, path, *, format: str | None = None, overwrite: bool = False, inputs=()):
        """Write the camera as a calibration file (format from the name or ``format=``)."""
        from .files import write_calibration

        return write_calibration(
            self.camera, path, format=format, overwrite=overwrite, inputs=inputs
        )

    def __repr__(self) -> str:
        g = self.geometry
        return (
            f"TracedCamera({g.lens_name!r}, {self.camera.model}, object {g.object_label}, "
            f"{g.focus}: RMS {self.rms_px:.3g} px, max {self.max_px:.3g} px over "
            f"{self.fit.n_points} chief rays)"
        )


def fit_points(
    points: CameraPoints,
    model: str = "opencv",
    *,
    n_coefficients: int | None = None,
    free: Sequence[str] | None = None,
) -> TracedCamera:
    """Fit a camera model (or choose one of a family) to traced correspondences
    (:func:`fit_correspondences` for the words of ``model``)."""
    # every grid point, the failed ones NaN: the fit drops them and can say how many failed
    ideal = np.where(points.ok[:, None], points.ideal, np.nan)
    img = np.where(points.ok[:, None], points.image_px, np.nan)
    f, sel, crit = fit_correspondences(
        ideal, img, points.sensor, model, n_coefficients=n_coefficients, free=free
    )
    return TracedCamera(f.camera, points, f, sel, crit, str(model))


def camera_model(
    lens,
    sensor,
    model: str = "opencv",
    *,
    object_distance: float | str | None = None,
    object_s: float | str | None = None,
    object_scale: float | str | None = None,
    focus: float | str | None = None,
    focus_s: float | str | None = None,
    focus_scale: float | str | None = None,
    s_prime: float | str | None = None,
    from_last_vertex: float | str | None = None,
    defocus: float | str | None = None,
    wavelength: float | str | None = None,
    grid: tuple[int, int] | None = None,
    clip: bool | None = None,
    n_coefficients: int | None = None,
    free: Sequence[str] | None = None,
) -> TracedCamera:
    """The camera model of ``lens`` on ``sensor``: real chief rays traced onto the sensor and a
    model fitted to them by least squares (module docstring).

    Parameters
    ----------
    lens : Lens
    sensor : Sensor, CameraSetup or path
        The sensor (``Sensor.from_spec(size="36x24", pixels="6000x4000")``), a whole
        :class:`~distortion.camera.setup.CameraSetup`, or a TOML camera spec file; the keywords
        below replace what a setup holds.
    model : str
        ``"opencv"`` (4/5/8/12/14 coefficients, as many as the criterion needs), ``"fisheye"``
        (OpenCV fisheye / Kannala–Brandt), ``"colmap"`` (SIMPLE_RADIAL … FULL_OPENCV),
        ``"colmap-fisheye"``, ``"metashape"``, ``"australis"`` (Brown / Fraser, mm) — or one
        model name such as ``"colmap:OPENCV"``.
    object_distance, object_s, object_scale
        The object plane (docs/design.md, "Vocabulary"); default the lens file's.
    focus, focus_s, focus_scale
        The focused object (unit focusing: the sensor sits in its Gaussian image plane);
        ``focus`` in ``object_distance``'s words (mm from the first vertex, ``inf``, ``"12x"``,
        ``"2m"``).
    s_prime, from_last_vertex, defocus
        Or the sensor plane directly (mm). Default: focused on the object.
    wavelength : float or str, optional
        nm; default the lens's reference wavelength (focus is always set at the reference
        wavelength).
    grid : (int, int), optional
        Chief rays over the sensor, columns × rows (default 25 × 17).
    clip : bool, optional
        Apply the lens's semi-diameters (default True).
    n_coefficients : int, optional
        Fix the coefficient count (OpenCV 4/5/8/12/14, fisheye 1–4) instead of choosing.
    free : sequence of str, optional
        Parameters to fit for one named model.

    Returns
    -------
    TracedCamera
        ``.camera`` (the model), ``.rms_px``/``.max_px`` (residual against the traced points),
        ``.criterion``, ``.points`` (the correspondences, the geometry and the pupils).
    """
    setup = make_setup(
        sensor,
        {
            "object_distance": object_distance,
            "object_s": object_s,
            "object_scale": object_scale,
            "focus": focus,
            "focus_s": focus_s,
            "focus_scale": focus_scale,
            "s_prime": s_prime,
            "from_last_vertex": from_last_vertex,
            "defocus": defocus,
            "wavelength": wavelength,
            "grid": grid,
            "clip": clip,
        },
    )
    points = trace_camera_points(lens, setup)
    return fit_points(points, model, n_coefficients=n_coefficients, free=free)


def opencv_coefficients(lens, sensor, *, n_coefficients: int | None = None, **kw) -> TracedCamera:
    """OpenCV's camera matrix and distortion coefficients of ``lens`` on ``sensor``:
    :func:`camera_model` with ``model="opencv"`` (as many coefficients as the criterion needs,
    or ``n_coefficients``). ``.camera_matrix`` and ``.dist_coeffs`` are what ``cv2`` takes.

    Parameters
    ----------
    lens : Lens
    sensor : Sensor, CameraSetup or path
        The sensor, a whole camera setup, or a TOML camera spec file (as :func:`camera_model`).
    n_coefficients : int, optional
        Fix the OpenCV vector length (4, 5, 8, 12 or 14) instead of choosing it.
    **kw
        The other keywords of :func:`camera_model`: the object plane (``object_distance``,
        ``object_s``, ``object_scale``; mm, ``inf``, ``"2m"``, ``"12x"``), the focus (``focus``,
        ``focus_s``, ``focus_scale``, or ``s_prime``, ``from_last_vertex``, ``defocus`` in mm),
        ``wavelength`` (nm, ``"0.55um"``, ``"d"``), ``grid``, ``clip``, ``free``.

    Returns
    -------
    TracedCamera
        ``.camera`` (an ``opencv`` :class:`CameraModel`), the residuals in pixels, the traced
        points.

    Raises
    ------
    DataError, TraceError, LensError
        As :func:`camera_model`: a setup or keyword it refuses, a trace that fails.
    """
    return camera_model(lens, sensor, "opencv", n_coefficients=n_coefficients, **kw)


# ---- checking a model against traced points -----------------------------------------------------
@dataclass(frozen=True, eq=False)
class Residual:
    """A camera model against traced correspondences: ``residual_px`` (N, 2) model − traced
    (OpenCV px; NaN where a point was not traced or the model cannot project it), RMS and
    maximum of its length, and the count of points compared."""

    residual_px: np.ndarray
    rms_px: float
    max_px: float
    n_points: int

    def __repr__(self) -> str:
        return f"Residual(RMS {self.rms_px:.3g} px, max {self.max_px:.3g} px, {self.n_points} pts)"


def camera_residual(camera: CameraModel, points: CameraPoints) -> Residual:
    """How well ``camera`` reproduces traced correspondences (e.g. a model fitted at one object
    distance against the chief rays traced at another, or on an independent grid)."""
    ok = points.ok
    res = np.full(points.image_px.shape, np.nan)
    proj = project(camera, points.ideal[ok], pixels="opencv")
    good = proj.status == OK
    r = proj.points - points.image_px[ok]
    r[~good] = np.nan
    res[ok] = r
    d = np.hypot(res[:, 0], res[:, 1])
    d = d[np.isfinite(d)]
    return Residual(
        res,
        float(np.sqrt(np.mean(d**2))) if d.size else math.nan,
        float(d.max()) if d.size else math.nan,
        int(d.size),
    )


# ---- a measured calibration against the prescription ------------------------------------------
def prediction_like(measured: CameraModel, points: CameraPoints) -> TracedCamera:
    """The prescription's prediction in the form of a measured calibration: ``measured``'s model
    fitted to the traced points with the same terms free (its focal lengths and principal
    point, and every coefficient it holds away from the model's identity), so that the two are
    compared like for like."""
    if (measured.width, measured.height) != points.sensor.image_size:
        raise DataError(
            f"the calibration is for a {measured.width}x{measured.height} px image, the sensor "
            f"has {points.sensor.width_px}x{points.sensor.height_px} px; give the sensor of the "
            "calibrated camera"
        )
    spec = measured.spec
    if measured.model == "opencv":
        return fit_points(points, "opencv", n_coefficients=measured.n_opencv_coefficients)
    d = measured.as_dict()
    free = [  # every term it holds away from identity, also those its own fits keep fixed
        n  # (Metashape's b1 affinity is not in default_free)
        for n in spec.params
        if (n in _GEOMETRY and n in spec.default_free)
        or (n not in _GEOMETRY and d[n] != float(spec.identity.get(n, 0.0)))
    ]
    return fit_points(points, measured.model, free=free)


def sensor_for_calibration(
    calibration: CameraModel,
    sensor: Sensor | None = None,
    *,
    size=None,
    pitch_um=None,
    principal_point_offset_mm=(0.0, 0.0),
) -> Sensor:
    """The Sensor of a calibrated camera: its pixel count with the physical size from
    ``sensor`` (checked), ``size`` (mm), ``pitch_um`` or the calibration's own pixel size."""
    if sensor is not None:
        if sensor.image_size != (calibration.width, calibration.height):
            raise DataError(
                f"the sensor has {sensor.width_px}x{sensor.height_px} px but the calibration is "
                f"for {calibration.width}x{calibration.height} px"
            )
        return sensor
    pixels = (calibration.width, calibration.height)
    if size is not None or pitch_um is not None:
        return Sensor.from_spec(
            size=size,
            pixels=pixels,
            pitch_um=pitch_um,
            principal_point_offset_mm=principal_point_offset_mm,
        )
    if calibration.pixel_size_mm is not None:
        px, py = calibration.pixel_size_mm
        return Sensor(pixels[0] * px, pixels[1] * py, pixels[0], pixels[1],
                      principal_point_offset_mm)  # fmt: skip
    raise DataError(
        f"the {calibration.model} calibration holds pixels only: give the sensor size (e.g. "
        "'36x24' mm) or the pixel pitch (um) so that the lens's millimetres land on its pixels"
    )


def compare_calibration(lens, calibration: CameraModel, sensor, *, label: str = "measured", **kw):
    """Compare a measured calibration with the prescription's prediction at the same focus and
    object distance (:func:`distortion.camera.compare.compare_cameras`; Fraser & Shortis 1992
    compare measured and predicted distortion profiles the same way).

    Parameters
    ----------
    lens : Lens
    calibration : CameraModel
        The measured camera (:func:`~distortion.camera.files.read_calibration`).
    sensor : Sensor, CameraSetup or path
        The calibrated camera's sensor (its pixel count must be the calibration's), or a whole
        setup; ``kw`` are :func:`camera_model`'s setup keywords (object, focus, wavelength, grid).

    Returns
    -------
    CameraComparison
        With ``prediction`` (the :class:`TracedCamera` fitted like the calibration) and notes
        stating the projection centre and the geometry.
    """
    from dataclasses import replace as dc_replace

    from .compare import compare_cameras

    setup = make_setup(sensor, kw)
    points = trace_camera_points(lens, setup)
    pred = prediction_like(calibration, points)
    g = points.geometry
    notes = (
        f"predicted: {calibration.model} fitted to {pred.fit.n_points} real chief rays of "
        f"{g.lens_name} ({pred.criterion}); fit residual RMS {pred.rms_px:.3g} px",
        f"object {_object_words(g)}, {g.focus}; sensor plane {g.from_last_vertex:.6g} mm from "
        "the last vertex",
        g.projection_centre,
    )
    cmp = compare_cameras(
        calibration,
        pred.camera,
        pixel_size_mm=points.sensor.pixel_size_mm,
        label_measured=label,
        label_predicted=f"predicted ({g.lens_name})",
        notes=notes,
    )
    return dc_replace(cmp, prediction=pred)
