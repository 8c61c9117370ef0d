"""Colour: lateral colour, longitudinal colour (the focal-shift curve) and distortion per
wavelength of a traced lens.

The colour channels of a camera see different image geometry: the chief ray of a field lands at
a height that depends on the wavelength (lateral colour, also called transverse chromatic
aberration or chromatic difference of magnification), and the focus moves along the axis with the
wavelength (longitudinal colour, the focal-shift curve). A calibration that fits one camera
constant for all channels measures each channel's distortion against that one constant.

Definitions (units: mm, nm, degrees):

``lateral_colour``
    ``Δy'(α) = y'(λ1) − y'(λ2)``, the difference of the real chief-ray heights (aimed at the
    centre of the real stop) of two wavelengths in the same image plane, for the same object
    point; relative: ``Δy'/y'(λ_ref)`` with ``y'(λ_ref)`` the reference wavelength's chief-ray
    height in that plane (0 on the axis). Default wavelengths: the shortest and the longest of
    the lens's own, or the hydrogen F and C lines (486.1327, 656.2725 nm) for a lens with one
    wavelength — then ``Δy' = y'_F − y'_C``.
``focal_shift``
    The image plane of each wavelength along the axis, from the reference wavelength's: the
    paraxial image (``kind="paraxial"``: the Gaussian image of the object, i.e. the paraxial back
    focus for an object at infinity) or the plane of least RMS spot radius of the on-axis
    point's rays (``kind="best-focus"``: a hexapolar grid over the reference wavelength's
    paraxial entrance pupil, the plane found in closed form from the final ray segments).
``characteristic_distortion(..., wavelengths=..., scale=...)``
    distortion per wavelength (:mod:`.characteristic`): by default every wavelength against the
    reference wavelength's F0/M0 (``scale="reference"``), on request against its own
    (``scale="own"``). Every output says which.

All wavelengths are traced in one kernel call, in planes and for object points resolved at the
lens's reference wavelength (``Lens.wavelength``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from raytrace.errors import TraceError
from raytrace.lens import Lens
from raytrace.materials import LAMBDA_C, LAMBDA_F

from .characteristic import ChromaticDistortion, characteristic_distortion
from .curve import relative_distortion, require_choice

FOCUS_KINDS = ("paraxial", "best-focus")
#: default sampling of the focal-shift curve when the lens has fewer than three wavelengths (nm)
DEFAULT_BAND_NM = (400.0, 700.0)
DEFAULT_CURVE_POINTS = 61


def default_pair(lens: Lens) -> tuple[float, float]:
    """The two wavelengths lateral colour compares by default: the shortest and the longest of
    the lens's wavelengths, or F and C for a lens with one wavelength (nm)."""
    wl = sorted(set(lens.wavelengths))
    if len(wl) >= 2:
        return wl[0], wl[-1]
    return LAMBDA_F, LAMBDA_C


@dataclass(frozen=True, eq=False)
class LateralColour:
    """Lateral colour of one lens and object in one or more image planes.

    name: lens name. wavelengths: (λ1, λ2) nm, ``linear = y'(λ1) − y'(λ2)``.
    reference_wavelength: nm (the planes, the object points and the relative measure use it).
    field_kind: ``"angle"``, ``"height"`` or ``"nominal-angle"``; fields (n,) as given.
    z_planes, s_prime, defocus (p,): the planes as absolute z, from the reference H' and from
    the reference Gaussian plane (mm). heights (3, p, n): chief-ray heights y' at λ1, λ2 and the
    reference wavelength (mm). linear (p, n): Δy' (mm); relative (p, n): Δy'/y'(λ_ref)
    (a fraction, 0 on the axis). status (3, n): trace status (0 = OK); NaN where not OK.
    distortion: the :class:`ChromaticDistortion` the heights come from (reference scale).
    """

    name: str
    wavelengths: tuple[float, float]
    reference_wavelength: float
    field_kind: str
    fields: np.ndarray
    z_planes: np.ndarray
    s_prime: np.ndarray
    defocus: np.ndarray
    heights: np.ndarray
    linear: np.ndarray
    relative: np.ndarray
    status: np.ndarray
    distortion: ChromaticDistortion

    @property
    def n_planes(self) -> int:
        return int(self.z_planes.size)

    def plane_label(self, i: int) -> str:
        return self.distortion.plane_label(i)

    def __repr__(self) -> str:
        with np.errstate(invalid="ignore"):
            worst = float(np.nanmax(np.abs(self.linear))) if np.isfinite(self.linear).any() else 0.0
        w1, w2 = self.wavelengths
        return (
            f"LateralColour({self.name!r}, y'({w1:g} nm) - y'({w2:g} nm), {self.fields.size} "
            f"fields, {self.n_planes} plane(s), max |dy'| = {worst:.6g} mm)"
        )


def lateral_colour(
    lens: Lens,
    fields_deg: npt.ArrayLike | None = None,
    *,
    wavelengths: Sequence[float | str] | str | None = None,
    object_heights_mm: npt.ArrayLike | None = None,
    plane=None,
    s_prime: npt.ArrayLike | None = None,
    from_last_vertex: npt.ArrayLike | None = None,
    defocus: npt.ArrayLike | None = None,
    object_distance: float | str | None = None,
    object_s: float | None = None,
    object_scale: float | None = None,
    clip: bool = True,
) -> LateralColour:
    """Lateral colour ``y'(λ1) − y'(λ2)`` per field in one or more image planes (module
    docstring).

    Parameters
    ----------
    lens : Lens
    fields_deg, object_heights_mm
        Fields as in :func:`~distortion.characteristic.characteristic_distortion` (default: 11
        fields from 0 to the lens's field).
    wavelengths : (λ1, λ2), optional
        nm (or strings with a unit, line letters, ``"F,C"``); default :func:`default_pair`.
    plane, s_prime, from_last_vertex, defocus
        Image plane(s) as in ``characteristic_distortion``, resolved at the reference wavelength
        (default: its Gaussian plane of the object).
    object_distance, object_s, object_scale
        The object plane (default: the lens file's).
    clip : bool
        Apply the semi-diameters to the chief rays.

    Returns
    -------
    LateralColour
    """
    if wavelengths is None:
        pair = default_pair(lens)
    else:  # numbers, strings with units, line letters, or one string "F,C" (the one parser)
        from raytrace.units import UnitError, wavelengths_nm

        try:
            pair = wavelengths_nm(wavelengths)
        except UnitError as e:
            raise TraceError(str(e)) from None
    if len(pair) != 2:
        raise TraceError(f"lateral colour compares two wavelengths, got {len(pair)}")
    ref = float(lens.wavelength)
    cd = characteristic_distortion(
        lens,
        fields_deg,
        object_heights_mm=object_heights_mm,
        plane=plane,
        s_prime=s_prime,
        from_last_vertex=from_last_vertex,
        defocus=defocus,
        object_distance=object_distance,
        object_s=object_s,
        object_scale=object_scale,
        wavelengths=[pair[0], pair[1], ref],
        scale="reference",
        clip=clip,
    )
    yp = cd.yp  # (3, p, n)
    lin = yp[0] - yp[1]
    rel = relative_distortion(lin, yp[2], valid=np.isfinite(lin))
    r0 = cd[2]
    return LateralColour(
        name=lens.name,
        wavelengths=(float(cd.wavelengths[0]), float(cd.wavelengths[1])),
        reference_wavelength=ref,
        field_kind=r0.field_kind,
        fields=r0.fields,
        z_planes=r0.z_planes,
        s_prime=r0.s_prime,
        defocus=r0.defocus,
        heights=yp,
        linear=lin,
        relative=rel,
        status=cd.status,
        distortion=cd,
    )


@dataclass(frozen=True, eq=False)
class FocalShift:
    """Longitudinal colour: the image plane of each wavelength along the axis.

    name: lens name; kind: ``"paraxial"`` or ``"best-focus"`` (module docstring).
    wavelengths (m,): nm; reference_wavelength: nm. object_distance: mm from the first vertex
    (inf). from_last_vertex (m,): the image plane of each wavelength, mm from the last vertex
    (for ``"paraxial"`` and an object at infinity: the back focal length).
    shift (m,): ``from_last_vertex − from_last_vertex(λ_ref)`` (mm, + away from the lens).
    efl (m,): paraxial EFL per wavelength (mm). rms_radius (m,): RMS spot radius in the
    best-focus plane (mm; NaN for ``"paraxial"``). reference_plane: the reference wavelength's
    plane, mm from the last vertex.
    """

    name: str
    kind: str
    wavelengths: np.ndarray
    reference_wavelength: float
    object_distance: float
    from_last_vertex: np.ndarray
    shift: np.ndarray
    efl: np.ndarray
    rms_radius: np.ndarray
    reference_plane: float

    @property
    def range(self) -> float:
        """Largest minus smallest plane position over the wavelengths (mm)."""
        v = self.from_last_vertex[np.isfinite(self.from_last_vertex)]
        return float(v.max() - v.min()) if v.size else math.nan

    def __repr__(self) -> str:
        return (
            f"FocalShift({self.name!r}, {self.kind}, {self.wavelengths.size} wavelengths "
            f"{self.wavelengths.min():g}..{self.wavelengths.max():g} nm, reference "
            f"{self.reference_wavelength:g} nm, range {self.range:.6g} mm)"
        )


def default_curve_wavelengths(lens: Lens) -> np.ndarray:
    """Wavelengths (nm) for a focal-shift curve: 61 points over the lens's wavelengths when they
    span more than 50 nm, otherwise over 400–700 nm."""
    lo, hi = min(lens.wavelengths), max(lens.wavelengths)
    if hi - lo <= 50.0:
        lo, hi = DEFAULT_BAND_NM
    return np.linspace(lo, hi, DEFAULT_CURVE_POINTS)


def focal_shift(
    lens: Lens,
    wavelengths: npt.ArrayLike | str | None = None,
    *,
    kind: str = "paraxial",
    object_distance: float | str | None = None,
    object_s: float | None = None,
    object_scale: float | None = None,
    rings: int = 8,
) -> FocalShift:
    """The focal-shift curve (longitudinal colour) of ``lens`` (module docstring).

    Parameters
    ----------
    lens : Lens
    wavelengths : sequence of float or "lens", optional
        nm; default :func:`default_curve_wavelengths`.
    kind : {"paraxial", "best-focus"}
        The paraxial image of the object, or the plane of least RMS spot radius of the on-axis
        object point.
    object_distance, object_s, object_scale
        The object plane (default: the lens file's), resolved at the reference wavelength.
    rings : int
        ``"best-focus"``: rings of the hexapolar pupil grid (6 k rays on ring k, plus the axis);
        an integer from 1 (7 rays) up to the :data:`raytrace.limits.MAX_SAMPLES` rays of one
        spot (577 rings); checked for either kind.

    Returns
    -------
    FocalShift
    """
    from raytrace.paraxial import paraxial, resolve_object_distance
    from raytrace.trace.chief import resolve_wavelengths

    require_choice(kind, FOCUS_KINDS, "focus kind")
    rings = _check_rings(rings)
    if wavelengths is None:
        wls = tuple(float(w) for w in default_curve_wavelengths(lens))
    else:
        wls = resolve_wavelengths(lens, wavelengths)
    od = resolve_object_distance(
        lens, object_distance=object_distance, object_s=object_s, object_scale=object_scale
    )
    ref = float(lens.wavelength)
    par_ref = paraxial(lens, od)
    efl = np.array([paraxial(lens, od, w).efl for w in wls])
    if kind == "paraxial":
        planes = np.array([paraxial(lens, od, w).gaussian_image_distance for w in wls])
        ref_plane = float(par_ref.gaussian_image_distance)
        rms = np.full(len(wls), np.nan)
    else:
        z, rms = _best_focus(lens, par_ref, (*wls, ref), rings)
        planes = z[:-1] - par_ref.z_last
        ref_plane = float(z[-1] - par_ref.z_last)
        rms = rms[:-1]
    return FocalShift(
        name=lens.name,
        kind=kind,
        wavelengths=np.array(wls, dtype=float),
        reference_wavelength=ref,
        object_distance=float(od),
        from_last_vertex=planes,
        shift=planes - ref_plane,
        efl=efl,
        rms_radius=rms,
        reference_plane=ref_plane,
    )


def _check_rings(rings) -> int:
    """``rings`` as an int: TraceError unless it is an integer >= 1 whose hexapolar grid
    (1 + 3 k (k + 1) rays) stays within :data:`raytrace.limits.MAX_SAMPLES`."""
    from raytrace.limits import MAX_SAMPLES
    from raytrace.trace.pupil import pupil_count
    from raytrace.units import is_whole

    if not is_whole(rings):
        raise TraceError(f"rings must be a whole number of pupil rings (>= 1), got {rings!r}")
    k = int(rings)
    if k < 1:
        raise TraceError(
            f"rings={k}: the best-focus pupil grid needs at least 1 ring (6 rays around the axis)"
        )
    n = pupil_count("hexapolar", k)
    if n > MAX_SAMPLES:
        raise TraceError(
            f"rings={k} makes {n} rays per wavelength, more than {MAX_SAMPLES}; a few rings (the "
            "default 8) are enough for the RMS focus"
        )
    return k


def _pupil_rays(par, rings: int) -> tuple[np.ndarray, ...]:
    """Rays from the axial object point over a hexapolar grid of the paraxial entrance pupil
    (reference wavelength): origins and directions, (n,) arrays each."""
    from raytrace.trace.pupil import pupil_points

    u, v = pupil_points("hexapolar", rings)
    px, py = u * (0.5 * par.epd), v * (0.5 * par.epd)
    n = px.size
    if par.infinite:
        z0 = min(par.z_E0, 0.0) - 1.0
        return px, py, np.full(n, z0), np.zeros(n), np.zeros(n), np.ones(n)
    z0 = par.z_object
    d = np.stack([px, py, np.full(n, par.z_E0 - z0)])
    d /= np.linalg.norm(d, axis=0)
    return np.zeros(n), np.zeros(n), np.full(n, z0), d[0], d[1], d[2]


def _best_focus(lens: Lens, par, wavelengths, rings: int) -> tuple[np.ndarray, np.ndarray]:
    """(z of least RMS spot radius, RMS radius there) per wavelength, for the axial object
    point. For rays of slopes s_i = (L, M)/N through points p_i on a plane z0, the spot at
    z is p_i + (z − z0) s_i about its centroid; Σ|Δp + (z − z0) Δs|² is least at
    z − z0 = −Σ Δp·Δs / Σ Δs·Δs."""
    from raytrace.trace import trace_rays

    if not math.isfinite(par.epd) or par.epd <= 0.0:
        raise TraceError("best focus needs a finite entrance pupil")
    x, y, z, L, M, N = _pupil_rays(par, rings)
    z0 = par.z_gauss
    zs, rms = np.empty(len(wavelengths)), np.empty(len(wavelengths))
    for i, w in enumerate(wavelengths):
        rb = trace_rays(lens, (x, y, z), (L, M, N), wavelength=w, clip=False)
        ok = rb.ok
        if np.count_nonzero(ok) < 3:
            zs[i] = rms[i] = np.nan
            continue
        px, py = rb.at_plane(z0)
        sx, sy = rb.L / rb.N, rb.M / rb.N
        px, py, sx, sy = px[ok], py[ok], sx[ok], sy[ok]
        dpx, dpy = px - px.mean(), py - py.mean()
        dsx, dsy = sx - sx.mean(), sy - sy.mean()
        den = float(np.sum(dsx * dsx + dsy * dsy))
        dz = -float(np.sum(dpx * dsx + dpy * dsy)) / den if den > 0.0 else 0.0
        zs[i] = z0 + dz
        rms[i] = math.sqrt(float(np.mean((dpx + dz * dsx) ** 2 + (dpy + dz * dsy) ** 2)))
    return zs, rms
