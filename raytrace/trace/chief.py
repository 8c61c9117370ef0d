"""Real chief rays, aimed at the centre of the real stop (docs/design.md, "Conventions").

Chief rays (Pestrecov 1958, Fig. 1: the principal ray through the centre of the real stop) are
found by iteration in :func:`raytrace.kernels.aim.aim_chief`: the meridional real ray whose
height at the stop surface is zero to an absolute tolerance ``1e-12 × max(1 mm, R_stop)``, where
``R_stop`` is the stop's semi-diameter when finite, otherwise the paraxial marginal-ray height at
the stop for the lens's aperture.

Field parameters:

- object at infinity, angle α: ray height at z = 0 with fixed direction (0, sin α, cos α);
- finite object, height y: ray from (0, y, −object_distance), unknown slope;
- finite object, angle α: the nominal angle of Pestrecov's §3, y = p0·tan α with
  p0 = z_object − z_E0 (< 0 for a real object left of the paraxial entrance pupil E0), then aimed
  as a height field.

Units: millimetres, field angles in degrees, first vertex at z = 0, light toward +z.
"""

from __future__ import annotations

import functools
import math
import warnings
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ..errors import LensError, TraceError
from ..lens import Lens, require_lens
from ..packing import PackedLens, pack
from ..paraxial.conjugates import checked_wavelength, resolve_object_distance
from ..paraxial.firstorder import aim_geometry
from ..paraxial.orthoscopy import nominal_heights
from .results import RayStatus, field_unit, object_words, status_name


class ApertureWarning(UserWarning):
    """The stop is smaller than the aperture specification asks it to pass."""


#: Fields per kernel call: a larger request is aimed in chunks (Ctrl-C stops between them).
AIM_CHUNK = 8192
#: the aim tolerance rule of docs/design.md, "Conventions": residual ≤ AIM_TOL × max(1 mm, R_stop)
AIM_TOL = 1e-12


def transfer(h: np.ndarray, z0: np.ndarray, slope: np.ndarray, z) -> np.ndarray:
    """Height (mm) on the plane(s) ``z`` of the straight ray segment through ``(z0, h)`` with
    slope ``dh/dz`` (a direction cosine ratio L/N or M/N): ``h + (z − z0)·slope``, broadcast.
    The one analytic transfer of a final segment to an image plane (docs/design.md, "Data
    flow")."""
    return h + (z - z0) * slope


@dataclass(frozen=True, eq=False)
class _AimSetup:
    packed: PackedLens  # at the wavelengths of the call
    z_E0: np.ndarray  # paraxial entrance pupil per wavelength (absolute z)
    r_stop: np.ndarray  # stop radius used for the tolerance, per wavelength
    tol: np.ndarray  # absolute aim tolerance per wavelength
    slope0: np.ndarray  # paraxial du/df at f = 0 per wavelength (kernel argument)
    hscale: np.ndarray  # scale of u for finite differences per wavelength
    z_E0_field: float  # entrance pupil that turns nominal angles into object heights


@functools.lru_cache(maxsize=256)
def _aim_setup(lens: Lens, wavelengths: tuple[float, ...], object_distance: float) -> _AimSetup:
    p = pack(lens, wavelengths=wavelengths)
    nw = len(wavelengths)
    z_E0 = np.empty(nw)
    r_stop = np.empty(nw)
    for i, wl in enumerate(wavelengths):
        z_E0[i], r_stop[i] = aim_pupil_and_stop(lens, p, object_distance, wl)
    slope0, hscale = aim_start(z_E0, object_distance, r_stop)
    # one wavelength: its own pupil (as a monochromatic lens); several: the reference
    # wavelength's, so that every wavelength traces the same object points
    z_field = z_E0[0] if nw == 1 else _aim_setup(lens, (lens.wavelength,), object_distance).z_E0[0]
    return _AimSetup(p, z_E0, r_stop, aim_tolerance(r_stop), slope0, hscale, float(z_field))


def aim_pupil_and_stop(
    lens: Lens, p: PackedLens, object_distance: float, wavelength: float
) -> tuple[float, float]:
    """``(z_E0, R_stop)`` of a chief-ray aim at ``wavelength`` (nm) through ``lens`` (packed as
    ``p``): the paraxial entrance pupil (absolute z, mm;
    :func:`raytrace.paraxial.firstorder.aim_geometry`, its LensError as TraceError) and the stop
    radius of the tolerance rule (:func:`aim_tolerance`): the stop's semi-diameter (mm) when
    finite, else the paraxial marginal-ray height at the stop.

    :class:`ApertureWarning` when the stop's semi-diameter is smaller than that marginal-ray
    height, which the lens's aperture asks it to pass: the chief rays are still aimed at its
    centre, but the marginal rays are clipped. The warning points at the caller of the public
    tracing function (the aims' setups are three frames below it)."""
    try:
        z_E0, r_par = aim_geometry(lens, object_distance, wavelength)
    except LensError as e:
        raise TraceError(str(e)) from None
    sd_stop = float(p.sd[p.stop])
    if math.isfinite(sd_stop) and r_par > sd_stop * (1.0 + 1e-9):
        warnings.warn(
            f"{lens.name}: the stop (surface {p.stop + 1}) has a semi-diameter of "
            f"{sd_stop:g} mm but the aperture ({lens.aperture.kind} {lens.aperture.value:g}) "
            f"asks it to pass {r_par:.6g} mm: the marginal rays are clipped at the stop — "
            "enlarge the stop's semi-diameter or reduce the aperture",
            ApertureWarning,
            stacklevel=5,
        )
    return z_E0, (sd_stop if math.isfinite(sd_stop) else r_par)


def aim_tolerance(r_stop: np.ndarray | float) -> np.ndarray | float:
    """The absolute aim tolerance (mm) of docs/design.md, "Conventions": the chief ray meets the
    stop surface within ``AIM_TOL × max(1 mm, R_stop)`` of its centre, ``R_stop`` (mm) the stop's
    semi-diameter when finite, else the paraxial marginal-ray height at the stop."""
    return AIM_TOL * np.maximum(1.0, r_stop)


def aim_start(
    z_E0: np.ndarray, object_distance: float, r_stop: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The aim kernels' first-guess arguments per wavelength, from the paraxial entrance pupil.

    Parameters
    ----------
    z_E0 : ndarray
        (n_w,) paraxial entrance pupil, absolute z (mm).
    object_distance : float
        mm from the object plane to the first vertex (inf for infinity).
    r_stop : ndarray
        (n_w,) stop radius (mm) used for the tolerance.

    Returns
    -------
    slope0 : ndarray
        (n_w,) paraxial d(unknown)/d(field) at field 0: ``−1/(z_E0 − z_object)`` (1/mm) for a
        finite object (0 when the pupil lies in the object plane), ``−z_E0`` (mm/rad) at infinity.
    hscale : ndarray
        (n_w,) scale of the unknown for finite differences: 1 (a slope), or
        ``max(1 mm, R_stop)`` (a height) at infinity.
    """
    if math.isfinite(object_distance):
        den = z_E0 + object_distance  # z_E0 − z_obj
        slope0 = np.array([-1.0 / d if d != 0.0 else 0.0 for d in den])
        return slope0, np.ones(len(z_E0))
    return -z_E0, np.maximum(1.0, r_stop)


def aim_outputs(nw: int, n: int, dims: int) -> tuple[np.ndarray, ...]:
    """The empty output arrays of the aim kernels (:mod:`raytrace.kernels.aim`, ``dims`` = 1,
    and :mod:`raytrace.kernels.aim2d`, ``dims`` = 2) for ``nw`` wavelengths × ``n`` fields:
    ``start`` and ``last`` (nw, 4, n) rays (y, z, M, N) or (nw, 6, n) (x, y, z, L, M, N),
    ``status`` (nw, n) int8, ``surface`` and ``evals`` (nw, n) int32, ``residual`` (nw, n) or
    (nw, 2, n)."""
    ray = (nw, 2 + 2 * dims, n)
    return (
        np.empty(ray),
        np.empty(ray),
        np.empty((nw, n), dtype=np.int8),
        np.empty((nw, n), dtype=np.int32),
        np.empty((nw, n), dtype=np.int32),
        np.empty((nw, n) if dims == 1 else (nw, 2, n)),
    )


@dataclass(frozen=True, eq=False)
class ChiefRays(RayStatus):
    """Real chief rays (meridional plane x = 0), arrays over fields in the order given.

    Attributes
    ----------
    fields : ndarray
        The field values as given: degrees (``field_kind="angle"``) or object heights in mm
        (``"height"``).
    field_kind : str
        ``"angle"`` or ``"height"``; angles with a finite object are nominal angles.
    object_distance : float
        mm from the object plane to the first vertex (positive; inf for infinity).
    wavelength : float
        nm.
    y_start, z_start, M_start, N_start : ndarray
        Object-space ray: a point (mm) and direction cosines; for an object at infinity the point
        is on the plane z = 0, else the object point.
    y_last, z_last, M_last, N_last : ndarray
        Final segment: point on the last surface (mm) and direction after it.
    status : ndarray of int8
        Status code per field (``raytrace.kernels.codes``; names in :attr:`status_names`).
    surface : ndarray of int32
        1-based surface where the ray failed (0 when OK).
    iterations : ndarray of int32
        Residual evaluations (traces to the stop) the aim used.
    stop_residual : ndarray
        Height of the ray at the stop surface (mm): the aiming error.
    entrance_pupil_z : ndarray
        Real entrance pupil: where the object-space chief ray crosses the axis (absolute z, mm);
        the paraxial z_E0 for the zero field; inf when parallel to the axis.
    stop_radius, tolerance : float
        The stop radius (mm) and the absolute aim tolerance (mm) used.
    """

    fields: np.ndarray
    field_kind: str
    object_distance: float
    wavelength: float
    y_start: np.ndarray
    z_start: np.ndarray
    M_start: np.ndarray
    N_start: np.ndarray
    y_last: np.ndarray
    z_last: np.ndarray
    M_last: np.ndarray
    N_last: np.ndarray
    status: np.ndarray
    surface: np.ndarray
    iterations: np.ndarray
    stop_residual: np.ndarray
    entrance_pupil_z: np.ndarray
    stop_radius: float
    tolerance: float

    @property
    def status_names(self) -> list[str]:
        """Status per field as words (``"ok"``, ``"aim_failed"``, ...)."""
        return [status_name(s) for s in self.status]

    @property
    def tan_out(self) -> np.ndarray:
        """Image-space slope tan α' = M_last / N_last."""
        return self.M_last / self.N_last

    @property
    def landing_angle_deg(self) -> np.ndarray:
        """Image-space chief-ray angle with the axis (degrees, signed like M_last)."""
        return np.degrees(np.arctan2(self.M_last, self.N_last))

    def heights_at(self, z_planes: float | npt.ArrayLike) -> np.ndarray:
        """Chief-ray heights (mm) on plane(s) z = z_planes (absolute z, mm) by analytic transfer of
        the final segment: shape (n_fields,) for a scalar, (n_planes, n_fields) for an array.
        NaN only where status != OK."""
        zp = np.asarray(z_planes, dtype=np.float64)
        t = self.M_last / self.N_last
        if zp.ndim == 0:
            return transfer(self.y_last, self.z_last, t, float(zp))
        return transfer(self.y_last[None, :], self.z_last[None, :], t, zp.reshape(-1)[:, None])

    def __len__(self) -> int:
        return int(self.fields.size)

    def __repr__(self) -> str:
        unit, obj = field_unit(self.field_kind), object_words(self.object_distance)
        fl = ", ".join(f"{v:g}" for v in self.fields[:6]) + (", ..." if len(self) > 6 else "")
        return (
            f"ChiefRays({len(self)} fields [{fl}] {unit}, object {obj}, "
            f"{self.wavelength:g} nm, {self.n_failed} failed)"
        )


@dataclass(frozen=True, eq=False)
class ChromaticChiefRays(RayStatus):
    """Real chief rays at several wavelengths, aimed in one kernel call (wavelength × field).

    ``rays[i]`` is the :class:`ChiefRays` at ``wavelengths[i]``; every wavelength has the same
    object points (``fields``, ``field_kind``, ``object_distance``; a nominal angle with a finite
    object is turned into an object height with the reference wavelength's paraxial entrance
    pupil). Stacked attributes have shape (n_wavelengths, n_fields).

    Attributes
    ----------
    rays : tuple of ChiefRays
    wavelengths : ndarray
        nm, in the order asked for.
    reference_wavelength : float
        nm: the lens's reference wavelength (it need not be among ``wavelengths``).
    """

    rays: tuple[ChiefRays, ...]
    wavelengths: np.ndarray
    reference_wavelength: float

    @property
    def fields(self) -> np.ndarray:
        return self.rays[0].fields

    @property
    def field_kind(self) -> str:
        return self.rays[0].field_kind

    @property
    def object_distance(self) -> float:
        return self.rays[0].object_distance

    @property
    def n_wavelengths(self) -> int:
        return len(self.rays)

    def __getitem__(self, i: int) -> ChiefRays:
        return self.rays[i]

    def __iter__(self):
        return iter(self.rays)

    def at(self, wavelength: float) -> ChiefRays:
        """The rays at ``wavelength`` (nm; one of :attr:`wavelengths`)."""
        return self.rays[wavelength_index(self.wavelengths, wavelength, "the traced wavelengths")]

    def stacked(self, name: str) -> np.ndarray:
        """Attribute ``name`` of every wavelength's :class:`ChiefRays`, stacked: (n_w, n)."""
        return np.stack([getattr(r, name) for r in self.rays])

    @property
    def status(self) -> np.ndarray:
        return self.stacked("status")

    @property
    def y_last(self) -> np.ndarray:
        return self.stacked("y_last")

    @property
    def tan_out(self) -> np.ndarray:
        return self.stacked("tan_out")

    def heights_at(self, z_planes: float | npt.ArrayLike) -> np.ndarray:
        """Chief-ray heights (mm) on plane(s) z (absolute, mm): (n_wavelengths, n_fields) for a
        scalar, (n_wavelengths, n_planes, n_fields) for an array."""
        return np.stack([r.heights_at(z_planes) for r in self.rays])

    def __repr__(self) -> str:
        wl = ", ".join(f"{w:g}" for w in self.wavelengths)
        return (
            f"ChromaticChiefRays({self.fields.size} fields x {self.n_wavelengths} wavelengths "
            f"[{wl}] nm, reference {self.reference_wavelength:g} nm, {self.n_failed} failed)"
        )


def wavelength_index(wavelengths: np.ndarray, wavelength: float, among: str) -> int:
    """The index of ``wavelength`` (nm) in ``wavelengths`` (nm; the first match). Raises
    :class:`TraceError` listing them when it is none of them: "... is not one of ``among``"."""
    hit = np.nonzero(wavelengths == float(wavelength))[0]
    if hit.size == 0:
        raise TraceError(
            f"{wavelength:g} nm is not one of {among} "
            f"({', '.join(f'{w:g}' for w in wavelengths)} nm)"
        )
    return int(hit[0])


def chief_rays(
    lens: Lens,
    fields_deg: npt.ArrayLike | None = None,
    *,
    object_heights_mm: npt.ArrayLike | None = None,
    object_distance: float | str | None = None,
    object_s: float | None = None,
    object_scale: float | None = None,
    wavelength: float | str | None = None,
    wavelengths: npt.ArrayLike | None = None,
    clip: bool = True,
) -> ChiefRays | ChromaticChiefRays:
    """Aim real chief rays through the centre of the real stop (one kernel call for all fields
    and wavelengths).

    Parameters
    ----------
    lens : Lens
    fields_deg : array_like, optional
        Field angles α in degrees: the object-space chief-ray slope angle (a positive α gives a
        positive image height for an object at infinity). With a finite object these are
        Pestrecov's nominal angles, object height ``y = p0 tan α``.
    object_heights_mm : array_like, optional
        Object heights in mm (signed; finite objects). Give this or ``fields_deg``; neither →
        the lens file's field as 0 and its maximum.
    object_distance, object_s, object_scale
        The object plane (at most one): mm from the first vertex (or ``inf`` / ``"12x"``),
        Pestrecov's signed s from H (mm), or an image scale N ("N×"). Default: the lens's.
        Resolved with the paraxial data at the reference wavelength.
    wavelength : float or str, optional
        nm (or a string with a unit, ``"0.5876um"``); default the lens's reference wavelength.
        A bare number below 100 is refused as looking like µm.
    wavelengths : sequence of float, optional
        Several wavelengths (nm) in one kernel call, or ``"lens"`` for the lens's own; returns a
        :class:`ChromaticChiefRays`. Give ``wavelength`` or ``wavelengths``, not both.
    clip : bool
        Apply semi-diameters to the aimed ray (status CLIPPED); aiming itself is unclipped.

    Returns
    -------
    ChiefRays or ChromaticChiefRays
        Named arrays per field (per wavelength and field), with a status per ray; a failed ray
        has NaN coordinates.
    """
    require_lens(lens)
    if wavelength is not None and wavelengths is not None:
        raise TraceError("give wavelength= or wavelengths=, not both")
    od = resolve_object_distance(
        lens,
        object_distance=object_distance,
        object_s=object_s,
        object_scale=object_scale,
        wavelength=None if wavelengths is not None else checked_wavelength(wavelength),
    )
    if fields_deg is not None and object_heights_mm is not None:
        raise TraceError("give fields_deg or object_heights_mm, not both")
    if fields_deg is None and object_heights_mm is None:
        fk = lens.field.kind
        f = np.array([0.0, lens.field.value])
    else:
        fk = "angle" if fields_deg is not None else "height"
        name = "fields_deg" if fk == "angle" else "object_heights_mm"
        f = np.atleast_1d(field_values(fields_deg if fk == "angle" else object_heights_mm, name))
        if f.size == 0:  # as characteristic_distortion: no field, no chief ray
            raise TraceError(f"no fields given: {name} is empty")
    if wavelengths is not None:
        return aim(lens, f, fk, od, clip=clip, wavelengths=wavelengths)
    return aim(lens, f, fk, od, wavelength, clip)


def field_values(value: npt.ArrayLike, name: str) -> np.ndarray:
    """The fields given as keyword ``name`` (``fields_deg``, ``object_heights_mm``,
    ``fields_x_deg``, ...) as a float64 array of their shape: the one conversion of the field
    keywords of every trace (:func:`raytrace.units.real_array`). Numbers and numeric strings
    (``"10"``) are read; None becomes NaN (refused by :func:`checked_aim_request` as not
    finite).

    Raises
    ------
    TraceError
        A bool, a complex number, a ragged list or a value that is no number, naming the
        keyword: ``fields_deg: expected field angles in degrees (a number or a list of
        numbers), got [0, 1j] (a complex number)``.
    """
    from ..units import real_array

    unit = {
        "object_heights_mm": "object heights in mm",
        "object_radii_mm": "object radii in mm",
        "object_x_mm": "object coordinates in mm",
        "object_y_mm": "object coordinates in mm",
    }.get(name, "field angles in degrees")
    return real_array(value, name, f"{unit} (a number or a list of numbers)", error=TraceError)


def resolve_wavelengths(lens: Lens, wavelengths) -> tuple[float, ...]:
    """``wavelengths`` (nm; a sequence, a number, a string such as ``"F,d,C"`` or
    ``"486.1,656.3"``, or ``"lens"`` for the lens's own) as a tuple of checked floats
    (:func:`raytrace.units.wavelengths_nm`)."""
    from ..units import UnitError, wavelengths_nm

    if isinstance(wavelengths, str) and wavelengths.strip().lower() == "lens":
        return tuple(lens.wavelengths)
    if not isinstance(wavelengths, str):
        wavelengths = np.atleast_1d(np.asarray(wavelengths, dtype=object)).ravel().tolist()
    try:
        return wavelengths_nm(wavelengths)
    except UnitError as e:
        raise TraceError(str(e)) from None


def checked_aim_request(
    field_kind: str, object_distance: float, *fields: np.ndarray, heights: str = "object heights"
) -> float:
    """Check the resolved arguments of a chief-ray aim (:func:`aim`,
    :func:`raytrace.trace.aim_2d`) before any tracing.

    Parameters
    ----------
    field_kind : str
        ``"angle"`` or ``"height"``.
    object_distance : float
        mm from the object plane to the first vertex: positive, or inf.
    *fields : ndarray
        The field arrays (degrees for angles, mm for object coordinates): finite, and angles
        strictly within ±90°.
    heights : str
        What object heights are called in the message (``"object coordinates"`` in 2-D).

    Returns
    -------
    float
        The object distance (mm, or inf).

    Raises
    ------
    TraceError
        The first argument that is out of range, named.
    """
    if field_kind not in ("angle", "height"):
        raise TraceError(f"field kind must be 'angle' or 'height', got {field_kind!r}")
    od = float(object_distance)
    if not (od > 0.0):
        raise TraceError(f"object distance must be a positive magnitude or inf, got {od}")
    # the largest |field| of each array: NaN or inf when any value is not finite (max propagates
    # NaN); one reduction per array, this runs on every aim (a few fields, microseconds count)
    big = [
        float(np.abs(np.asarray(f, dtype=np.float64)).max()) if np.size(f) else 0.0 for f in fields
    ]
    if not all(math.isfinite(b) for b in big):
        raise TraceError("fields must be finite numbers")
    if field_kind == "height" and not math.isfinite(od):
        raise TraceError(f"{heights} need a finite object distance")
    if field_kind == "angle" and any(b >= 90.0 for b in big):
        raise TraceError("field angles must lie strictly between -90 and 90 degrees")
    return od


def aim(
    lens: Lens,
    fields: np.ndarray,
    field_kind: str,
    object_distance: float,
    wavelength: float | None = None,
    clip: bool = True,
    *,
    wavelengths=None,
) -> ChiefRays | ChromaticChiefRays:
    """:func:`chief_rays` for fields already resolved: ``fields`` (deg or mm) of ``field_kind``
    ``"angle"`` | ``"height"``, ``object_distance`` mm from the first vertex (inf). With
    ``wavelengths`` (a sequence, nm) all wavelengths are aimed in one kernel call and a
    :class:`ChromaticChiefRays` is returned."""
    # absolute: a relative import resolves the package on every call (3 µs, 2 % of a 50-field
    # aim; benchmarks/ab.py's chief-ray curve)
    import raytrace.kernels.aim as kernel

    fk = field_kind
    f = np.atleast_1d(np.asarray(fields, dtype=np.float64))
    if f.ndim != 1:
        raise TraceError("fields must be a scalar or a 1-D array")
    od = checked_aim_request(fk, object_distance, f)
    finite = math.isfinite(od)
    chromatic = wavelengths is not None
    if chromatic:
        if wavelength is not None:
            raise TraceError("give wavelength= or wavelengths=, not both")
        wls = resolve_wavelengths(lens, wavelengths)
    else:
        wls = (lens.wavelength if wavelength is None else checked_wavelength(wavelength),)
    su = _aim_setup(lens, wls, od)
    z_obj = -od if finite else 0.0
    nw = len(wls)
    if not finite:
        kf = np.radians(f)
    elif fk == "angle":
        kf = nominal_heights(z_obj - su.z_E0_field, f)  # nominal angle → object height
    else:
        kf = f
    n = f.size
    kf = np.ascontiguousarray(kf, dtype=np.float64)
    outs = start, last, status, surface, evals, residual = aim_outputs(nw, n, 1)
    # the fields in order of |field|: the kernel's continuation order
    order = np.argsort(np.abs(kf), kind="stable")
    if n <= AIM_CHUNK:
        kernel.aim_chief(su.packed.lens_arrays, su.packed.stop, 1 if finite else 0, z_obj, kf,
                  order, su.slope0, su.tol, su.hscale, bool(clip), *outs)  # fmt: skip
    else:
        # chunks of fields in that order, so that Ctrl-C stops a long aim within a fraction of
        # a second
        for i0 in range(0, n, AIM_CHUNK):
            idx = order[i0 : i0 + AIM_CHUNK]
            part = tuple(np.empty(a.shape[:-1] + (idx.size,), dtype=a.dtype) for a in outs)
            kernel.aim_chief(su.packed.lens_arrays, su.packed.stop, 1 if finite else 0, z_obj,
                      np.ascontiguousarray(kf[idx]), np.arange(idx.size), su.slope0, su.tol,
                      su.hscale, bool(clip), *part)  # fmt: skip
            for a, b in zip(outs, part, strict=True):
                a[..., idx] = b
    rays = []
    for i in range(nw):
        y0, z0, M0, N0 = start[i]
        # where the chief ray crosses the axis: z0 - y0 N0 / M0 (inf for a ray parallel to it;
        # the paraxial pupil on axis); in place, the fewest numpy calls (microseconds count)
        with np.errstate(divide="ignore", invalid="ignore"):
            zE = z0 - y0 * N0 / M0
        zE[M0 == 0.0] = np.inf
        zE[kf == 0.0] = su.z_E0[i]
        rays.append(
            ChiefRays(
                fields=f,
                field_kind=fk,
                object_distance=od,
                wavelength=wls[i],
                y_start=y0,
                z_start=z0,
                M_start=M0,
                N_start=N0,
                y_last=last[i, 0],
                z_last=last[i, 1],
                M_last=last[i, 2],
                N_last=last[i, 3],
                status=status[i],
                surface=surface[i],
                iterations=evals[i],
                stop_residual=residual[i],
                entrance_pupil_z=zE,
                stop_radius=float(su.r_stop[i]),
                tolerance=float(su.tol[i]),
            )
        )
    if not chromatic:
        return rays[0]
    return ChromaticChiefRays(tuple(rays), np.array(wls), float(lens.wavelength))
