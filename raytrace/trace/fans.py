"""Ray fans (transverse ray aberrations) and spot diagrams of one field in one image plane.

Rays fill the paraxial entrance pupil centred on the real chief ray (:mod:`.pupil`). In the image
plane every ray's intercept is taken relative to the real chief ray's: the transverse ray
aberration ``ε = (x, y)_ray − (x, y)_chief`` (mm). A tangential fan varies py (the meridional
y direction) and plots ε_y; a sagittal fan varies px and plots ε_x. A spot diagram's RMS radius
is taken about the spot's centroid; its geometric radius is the largest distance from the
centroid. Units: mm, degrees, nm.

Both take one field and raise :class:`FieldNotTracedError` (a :class:`TraceError`) when that field
cannot be traced: its real chief ray fails, or (spot diagrams) no ray reaches the image plane.
The command line catches it per field and reports the field as not traced.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import TraceError
from ..kernels.codes import STATUS_OK
from ..lens import Lens, require_lens
from ..paraxial import ImagePlane, image_planes, plane_z, resolve_paraxial
from ..paraxial.conjugates import checked_wavelength
from .chief import aim
from .pupil import aimed_bundle, pupil_points
from .rays import trace_rays
from .results import RayStatus, field_unit, status_name


class FieldNotTracedError(TraceError):
    """The one field of :func:`ray_fan` or :func:`spot_diagram` cannot be traced.

    Attributes
    ----------
    field, field_kind:
        The field (degrees or object mm) and ``"angle"`` / ``"height"``.
    status:
        The status code (:mod:`raytrace.kernels.codes`): the chief ray's when it failed, else
        the most frequent one of the rays (none of which reached the image plane).
    status_name:
        Its word (``"aim_failed"``, ``"clipped"``, ...).
    object_distance, z_plane, wavelength:
        The object plane, image plane (absolute z, mm) and wavelength (nm) asked for.
    rays:
        How many rays were traced about the chief ray (0 when the chief ray failed).
    """

    def __init__(self, message: str, *, status: int, rays: int, common: dict) -> None:
        super().__init__(message)
        self.status = int(status)
        self.status_name = status_name(status)
        self.rays = int(rays)
        self.field = common["field"]
        self.field_kind = common["field_kind"]
        self.object_distance = common["object_distance"]
        self.z_plane = common["z_plane"]
        self.wavelength = common["wavelength"]


def _field(lens: Lens, field_deg, object_height_mm, finite: bool) -> tuple[float, str]:
    if field_deg is not None and object_height_mm is not None:
        raise TraceError("give field_deg or object_height_mm, not both")
    for name, v in (("field_deg", field_deg), ("object_height_mm", object_height_mm)):
        if v is not None and (np.ndim(v) != 0 or isinstance(v, str | bool)):
            raise TraceError(
                f"{name}={v!r}: one field (a number); for several, call once per field, e.g. "
                f"[ray_fan(lens, a) for a in (0, 10, 20)]"
            )
    if object_height_mm is not None:
        if not finite:
            raise TraceError("object heights need a finite object distance")
        return _one_field(object_height_mm, "object_height_mm", "one object height in mm"), "height"
    if field_deg is None:
        return 0.0, "angle"
    return _one_field(field_deg, "field_deg", "one field angle in degrees"), "angle"


def _one_field(value, name: str, expected: str) -> float:
    """One field as a float (:func:`raytrace.units.real_number`; a numpy bool or a complex
    number is refused, naming the keyword)."""
    from ..units import real_number

    return real_number(value, name, f"{expected} (a number)", error=TraceError)


def _trace_field(
    lens,
    field_deg,
    object_height_mm,
    px,
    py,
    *,
    plane,
    s_prime,
    from_last_vertex,
    defocus,
    object_distance,
    object_s,
    object_scale,
    wavelength,
    clip,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, dict]:
    """Trace rays at pupil points (px, py) about the real chief ray of one field: (ε_x, ε_y,
    status) per ray in the image plane, and the keywords that :class:`RayFan` and
    :class:`SpotDiagram` share (field, field_kind, object_distance, z_plane, chief_height,
    wavelength)."""
    wavelength = checked_wavelength(wavelength)
    par = resolve_paraxial(lens, object_distance, object_s, object_scale, wavelength)
    od = par.object_distance
    f, kind = _field(lens, field_deg, object_height_mm, not par.infinite)
    planes = image_planes(
        plane, s_prime=s_prime, from_last_vertex=from_last_vertex, defocus=defocus
    )
    if len(planes) != 1:
        raise TraceError("ray fans and spot diagrams take one image plane")
    z = float(plane_z(par, planes)[0])
    where = dict(field=f, field_kind=kind, object_distance=od, z_plane=z, wavelength=par.wavelength)
    cr = aim(lens, np.array([f]), kind, od, wavelength, clip=False)
    if cr.status[0] != STATUS_OK:
        raise FieldNotTracedError(
            f"{lens.name}: the chief ray of field {f:g} {field_unit(kind)} "
            f"fails ({cr.status_names[0]}); no fan or spot about it",
            status=cr.status[0],
            rays=0,
            common=where,
        )
    b = aimed_bundle(
        lens, par, (cr.y_start[0], cr.z_start[0], cr.M_start[0], cr.N_start[0]), px, py
    )
    rb = trace_rays(lens, b.origins, b.directions, wavelength=wavelength, clip=clip)
    x, y = rb.at_plane(z)
    yc = float(cr.heights_at(z)[0])
    return x, y - yc, rb.status, {**where, "chief_height": yc}


@dataclass(frozen=True, eq=False)
class RayFan:
    """Transverse ray aberrations of one field along one pupil axis.

    pupil: normalised pupil coordinate (−1..1) along ``axis`` ("y": tangential, "x": sagittal);
    ex, ey: ε_x and ε_y (mm) in the image plane relative to the real chief ray (NaN where a ray
    failed); status: per ray; field, field_kind; z_plane: image plane (absolute z, mm);
    chief_height: the real chief ray's height there (mm); wavelength (nm).
    """

    pupil: np.ndarray
    ex: np.ndarray
    ey: np.ndarray
    status: np.ndarray
    axis: str
    field: float
    field_kind: str
    object_distance: float
    z_plane: float
    chief_height: float
    wavelength: float

    @property
    def aberration(self) -> np.ndarray:
        """ε along the fan's own axis: ε_y for a tangential fan, ε_x for a sagittal one (mm)."""
        return self.ey if self.axis == "y" else self.ex

    def __repr__(self) -> str:
        unit = field_unit(self.field_kind)
        e = self.aberration
        m = float(np.nanmax(np.abs(e))) if np.isfinite(e).any() else math.nan
        return (
            f"RayFan({'tangential' if self.axis == 'y' else 'sagittal'}, field {self.field:g} "
            f"{unit}, {self.pupil.size} rays, max |eps| = {m:.6g} mm, {self.wavelength:g} nm)"
        )


def ray_fan(
    lens: Lens,
    field_deg: float | None = None,
    *,
    object_height_mm: float | None = None,
    n: int = 21,
    axis: str = "y",
    plane: ImagePlane | str | None = None,
    s_prime: float | str | None = None,
    from_last_vertex: float | str | None = None,
    defocus: float | str | None = None,
    object_distance: float | str | None = None,
    object_s: float | None = None,
    object_scale: float | None = None,
    wavelength: float | None = None,
    clip: bool = True,
    allow_large: bool = False,
) -> RayFan:
    """A fan of real rays aimed about the real chief ray of one field.

    Parameters
    ----------
    lens : Lens
    field_deg, object_height_mm : float
        The field: an angle in degrees (default 0) or an object height in mm (finite objects).
    n : int
        Rays across the pupil, from −1 to 1 (a whole number, at least 1).
    axis : {"y", "x"}
        "y": tangential fan (pupil coordinate py, aberration ε_y); "x": sagittal (px, ε_x).
    plane, s_prime, from_last_vertex, defocus
        The image plane (docs/design.md, "Vocabulary"); default the Gaussian plane. Distances
        in mm, or strings with a length unit as the command line takes them (``"50.5mm"``).
    object_distance, object_s, object_scale
        The object plane; default the lens's.
    wavelength : float, optional
        nm; default the lens's.
    clip : bool
        Apply semi-diameters (vignetted rays get a status and NaN).
    allow_large : bool
        Trace more than :data:`raytrace.limits.MAX_SAMPLES` rays (refused by default).

    Returns
    -------
    RayFan
        Pupil coordinates and transverse aberrations ε (mm) relative to the real chief ray.

    Raises
    ------
    FieldNotTracedError
        The field's real chief ray fails (its ``status_name`` says how).
    """
    require_lens(lens)
    if axis not in ("x", "y"):
        raise TraceError(f"axis must be 'y' (tangential) or 'x' (sagittal), got {axis!r}")
    px, py = pupil_points("fan_y" if axis == "y" else "fan_x", n, allow_large=allow_large)
    x, dy, st, common = _trace_field(
        lens, field_deg, object_height_mm, px, py, plane=plane, s_prime=s_prime,
        from_last_vertex=from_last_vertex, defocus=defocus, object_distance=object_distance,
        object_s=object_s, object_scale=object_scale, wavelength=wavelength, clip=clip,
    )  # fmt: skip
    return RayFan(pupil=py if axis == "y" else px, ex=x, ey=dy, status=st, axis=axis, **common)


@dataclass(frozen=True, eq=False)
class SpotDiagram(RayStatus):
    """The spot of one field: ray intercepts relative to the real chief ray (mm).

    x, y: intercepts minus the chief ray's (mm; NaN where a ray failed); px, py: their pupil
    coordinates; status: per ray; centroid_x, centroid_y (mm, relative to the chief ray);
    rms_radius: RMS distance from the centroid (mm); geometric_radius: largest distance from the
    centroid (mm); field, field_kind, object_distance, z_plane, chief_height, wavelength.
    """

    x: np.ndarray
    y: np.ndarray
    px: np.ndarray
    py: np.ndarray
    status: np.ndarray
    centroid_x: float
    centroid_y: float
    rms_radius: float
    geometric_radius: float
    field: float
    field_kind: str
    object_distance: float
    z_plane: float
    chief_height: float
    wavelength: float

    @property
    def n_ok(self) -> int:
        """How many rays reached the image plane."""
        return self.status.size - self.n_failed

    def __repr__(self) -> str:
        unit = field_unit(self.field_kind)
        return (
            f"SpotDiagram(field {self.field:g} {unit}, {self.n_ok}/{self.x.size} rays, "
            f"RMS radius {self.rms_radius * 1000:.4g} um, geometric radius "
            f"{self.geometric_radius * 1000:.4g} um, {self.wavelength:g} nm)"
        )


def spot_diagram(
    lens: Lens,
    field_deg: float | None = None,
    *,
    object_height_mm: float | None = None,
    pattern: str = "hexapolar",
    n: int = 8,
    plane: ImagePlane | str | None = None,
    s_prime: float | str | None = None,
    from_last_vertex: float | str | None = None,
    defocus: float | str | None = None,
    object_distance: float | str | None = None,
    object_s: float | None = None,
    object_scale: float | None = None,
    wavelength: float | None = None,
    clip: bool = True,
    allow_large: bool = False,
) -> SpotDiagram:
    """The spot diagram of one field: real rays over the pupil, aimed about the real chief ray.

    Parameters
    ----------
    lens : Lens
    field_deg, object_height_mm : float
        The field: an angle in degrees (default 0) or an object height in mm (finite objects).
    pattern : {"hexapolar", "rings", "square"}
        Pupil sampling (:mod:`raytrace.trace.pupil`); ``n`` rings (or points across: at least
        3 for ``"square"``), a whole number.
    plane, s_prime, from_last_vertex, defocus
        The image plane; default the Gaussian plane. Distances in mm, or strings with a length
        unit (``"50.5mm"``).
    object_distance, object_s, object_scale
        The object plane; default the lens's.
    wavelength : float, optional
        nm; default the lens's.
    clip : bool
        Apply semi-diameters.
    allow_large : bool
        Trace more than :data:`raytrace.limits.MAX_SAMPLES` rays (refused by default).

    Returns
    -------
    SpotDiagram
        Intercepts relative to the chief ray (mm), centroid, RMS and geometric radius (mm).

    Raises
    ------
    FieldNotTracedError
        The field's real chief ray fails, or no ray reaches the image plane (its
        ``status_name`` says how).
    """
    require_lens(lens)
    if pattern not in ("hexapolar", "rings", "square"):
        raise TraceError(f"pattern must be hexapolar, rings or square, got {pattern!r}")
    px, py = pupil_points(pattern, n, allow_large=allow_large)
    x, dy, st, common = _trace_field(
        lens, field_deg, object_height_mm, px, py, plane=plane, s_prime=s_prime,
        from_last_vertex=from_last_vertex, defocus=defocus, object_distance=object_distance,
        object_s=object_s, object_scale=object_scale, wavelength=wavelength, clip=clip,
    )  # fmt: skip
    ok = st == STATUS_OK
    if not ok.any():
        codes, counts = np.unique(st, return_counts=True)
        order = np.argsort(-counts, kind="stable")
        how = ", ".join(f"{counts[i]} {status_name(codes[i])}" for i in order)
        raise FieldNotTracedError(
            f"{lens.name}: no ray of field {common['field']:g} {field_unit(common['field_kind'])} "
            f"reaches the image plane ({st.size} rays: {how})",
            status=codes[order[0]],
            rays=st.size,
            common=common,
        )
    cx, cy = float(np.mean(x[ok])), float(np.mean(dy[ok]))
    r2 = (x[ok] - cx) ** 2 + (dy[ok] - cy) ** 2
    return SpotDiagram(
        x=x,
        y=dy,
        px=px,
        py=py,
        status=st,
        centroid_x=cx,
        centroid_y=cy,
        rms_radius=float(np.sqrt(np.mean(r2))),
        geometric_radius=float(np.sqrt(np.max(r2))),
        **common,
    )
