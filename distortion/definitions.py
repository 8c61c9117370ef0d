"""Named reference definitions of distortion beside Pestrecov's: F-tanθ, F-θ, their calibrated
variants and the fisheye projections (docs/design.md, "Distortion definitions and pupils").

Every definition measures the real chief-ray image height ``y'`` in an image plane against a
reference height ``y_ref = f·g(θ)``, linear ``D = y' − y_ref`` (mm) and relative
``Dr = D / y_ref`` (a fraction; 0 on the axis), where θ is the field angle of the object-space
chief ray from a point at infinity (the direction the chief ray is launched with, so θ = the
field angle α given; the real chief ray then passes through the centre of the real stop,
docs/design.md "Conventions").

Projections ``g(θ)`` (:data:`PROJECTIONS`):

``rectilinear``      ``tan θ``        (F-tanθ; the gnomonic, distortion-free pinhole mapping)
``equidistant``      ``θ``            (F-θ; the equidistant fisheye, scanner lenses)
``equisolid-angle``  ``2 sin(θ/2)``   (equal-area fisheye)
``stereographic``    ``2 tan(θ/2)``   (conformal fisheye)
``orthographic``     ``sin θ``

Focal lengths ``f`` (:data:`FOCALS`), per image plane and wavelength:

``paraxial``
    Pestrecov's constant of orthoscopy of the plane, ``F0 = p0'/m_e`` (Eq. 8): the EFL in the
    Gaussian plane, and in any plane the limit ``y'/tan θ`` (= ``y'/θ``) of a near-axis real chief
    ray. That limit is how OpticStudio's F-Tan(Theta) and F-Theta distortion and optiland 0.6.3's
    ``optiland.analysis.Distortion`` ("f-tan", "f-theta"; ``RotationalDistortionModel.fit``: one
    chief ray at 1e-10 of the maximum field) fix their scale, so F-tanθ here is optiland's f-tan
    and, for an object at infinity, identical to Pestrecov's characteristic distortion (Eq. 9).
``least-squares``
    ``f = Σ g_i y'_i / Σ g_i²`` over the traced fields (status OK): the f minimising
    ``Σ (y'_i − f g_i)²`` of the linear heights, through the origin. It depends on the fields
    given (their number and spacing), so every output lists them. **Calibrated F-tanθ and F-θ.**
    OpticStudio offers "Cal. F-Tan(Theta)" and "Cal. F-Theta" distortion (the ZOS-API enumeration
    ``Distortions.Cal_F_TanTheta`` / ``Cal_F_Theta``, in zospy 2.2.0's API stubs) but no package
    available here documents the criterion it fits the focal length with, and optiland has no
    calibrated variant; the calibrated definitions here are therefore this clearly named
    least-squares calibration, NOT a reproduction of OpticStudio's numbers.

Definitions (:data:`DEFINITIONS`): ``f-tan-theta`` (rectilinear, paraxial f), ``f-theta``
(equidistant, paraxial f), ``calibrated-f-tan-theta`` and ``calibrated-f-theta`` (the same with the
least-squares f), and the fisheye projections ``equidistant``, ``equisolid-angle``,
``stereographic``, ``orthographic`` with the least-squares f by default or the paraxial f on
request (``focal="paraxial"``; ``equidistant`` with the paraxial f is ``f-theta``).

Finite objects are refused: θ is a direction from a point at infinity, and the image of a plane
object at a finite distance is measured against ``M0·y`` (Pestrecov's characteristic
distortion, :func:`distortion.characteristic.characteristic_distortion`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from raytrace.errors import TraceError
from raytrace.lens import Lens
from raytrace.paraxial import ImagePlane

from .curve import plane_label, relative_distortion, require_choice

FOCALS = ("paraxial", "least-squares")


@dataclass(frozen=True)
class Projection:
    """A mapping ``y_ref = f·g(θ)`` (θ in radians)."""

    name: str
    formula: str  # "f tan(theta)"
    g: Callable[[np.ndarray], np.ndarray]


def _equisolid(t: np.ndarray) -> np.ndarray:
    return 2.0 * np.sin(0.5 * t)


def _stereographic(t: np.ndarray) -> np.ndarray:
    return 2.0 * np.tan(0.5 * t)


def _equidistant(t: np.ndarray) -> np.ndarray:
    return np.asarray(t, dtype=float).copy()


#: the projections g(θ); each formula exists here only
PROJECTIONS: dict[str, Projection] = {
    p.name: p
    for p in (
        Projection("rectilinear", "f tan(theta)", np.tan),
        Projection("equidistant", "f theta", _equidistant),
        Projection("equisolid-angle", "2 f sin(theta/2)", _equisolid),
        Projection("stereographic", "2 f tan(theta/2)", _stereographic),
        Projection("orthographic", "f sin(theta)", np.sin),
    )
}


@dataclass(frozen=True)
class Definition:
    """A named reference definition: a projection and how its focal length is chosen.

    name: the registry key; title: how outputs print it; projection: a key of
    :data:`PROJECTIONS`; focal: the default of :data:`FOCALS`; fixed_focal: True when the name
    itself fixes the focal length (the F-tanθ / F-θ family), so ``focal=`` may not change it.
    """

    name: str
    title: str
    projection: str
    focal: str
    fixed_focal: bool


#: the registry of named definitions (beside ``distortion.characteristic.REFERENCES``)
DEFINITIONS: dict[str, Definition] = {
    d.name: d
    for d in (
        Definition("f-tan-theta", "F-tan(theta)", "rectilinear", "paraxial", True),
        Definition("f-theta", "F-theta", "equidistant", "paraxial", True),
        Definition(
            "calibrated-f-tan-theta",
            "calibrated F-tan(theta)",
            "rectilinear",
            "least-squares",
            True,
        ),
        Definition(
            "calibrated-f-theta", "calibrated F-theta", "equidistant", "least-squares", True
        ),
        Definition("equidistant", "equidistant fisheye", "equidistant", "least-squares", False),
        Definition(
            "equisolid-angle", "equisolid-angle fisheye", "equisolid-angle", "least-squares", False
        ),
        Definition(
            "stereographic", "stereographic fisheye", "stereographic", "least-squares", False
        ),
        Definition("orthographic", "orthographic fisheye", "orthographic", "least-squares", False),
    )
}


def definition(name: str) -> Definition:
    """The registry entry ``name``; a one-line :class:`TraceError` naming the choices otherwise."""
    require_choice(name, DEFINITIONS, "distortion definition")
    return DEFINITIONS[name]


# ------------------------------------------------------------------ the formula layer (arrays)


def projection_heights(projection: str, theta_rad: npt.ArrayLike) -> np.ndarray:
    """``g(θ)`` of ``projection`` (a key of :data:`PROJECTIONS`) at θ in radians: the reference
    height per unit focal length."""
    require_choice(projection, PROJECTIONS, "projection")
    return PROJECTIONS[projection].g(np.asarray(theta_rad, dtype=float))


def least_squares_focal_length(g: npt.ArrayLike, yp: npt.ArrayLike) -> np.ndarray:
    """``f = Σ g_i y'_i / Σ g_i²`` along the last axis over the finite ``y'`` (the f minimising
    ``Σ (y'_i − f g_i)²``); NaN where no field off the axis has a finite height."""
    g = np.asarray(g, dtype=float)
    y = np.asarray(yp, dtype=float)
    g = np.broadcast_to(g, y.shape)
    ok = np.isfinite(y) & (g != 0.0)
    num = np.sum(np.where(ok, g * y, 0.0), axis=-1)
    den = np.sum(np.where(ok, g * g, 0.0), axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(den > 0.0, num / np.where(den > 0.0, den, 1.0), np.nan)


def linear_and_relative(yp: npt.ArrayLike, y_ref: npt.ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """``(D, Dr)``: ``D = y' − y_ref`` (mm) and ``Dr = D / y_ref`` (fraction; 0 where
    ``y_ref = 0``, i.e. on the axis; NaN where ``y'`` is NaN)."""
    yp = np.asarray(yp, dtype=float)
    yr = np.asarray(y_ref, dtype=float)
    D = yp - yr
    return D, relative_distortion(D, yr, valid=np.isfinite(yp))


# ------------------------------------------------------------------ the traced result


@dataclass(frozen=True, eq=False)
class ProjectionDistortion:
    """Distortion of a lens (object at infinity) against one named definition, per wavelength
    and image plane (arrays: wavelengths × planes × fields).

    name: lens name. definition: the key of :data:`DEFINITIONS` asked for; title: its printed
    name; projection, formula: the mapping ``y_ref = f·g(θ)``; focal_basis: ``"paraxial"`` or
    ``"least-squares"`` (module docstring) — the f that ``D`` and ``Dr`` use.
    fields (n,): θ in degrees; theta (n,): radians; g (n,): ``g(θ)``.
    wavelengths (w,): nm; reference_wavelength: the lens's (nm); scale: ``""`` (one wavelength,
    analysed as a monochromatic lens), ``"reference"`` (every wavelength against the reference
    wavelength's f — its F0, or the least-squares f of its heights) or ``"own"``.
    z_planes, s_prime, from_last_vertex, defocus (p,): the planes (mm; absolute z, from H', from
    the last vertex, from the Gaussian plane of the (reference) wavelength).
    paraxial_focal_length, least_squares_focal_length (w, p): both candidate f's (mm);
    focal_length (w, p): the one used. efl (w,): each wavelength's paraxial EFL (mm).
    yp, y_ref, D (w, p, n): mm; Dr (w, p, n): fraction. status (w, n): trace status per field
    (``raytrace.trace.STATUS_*``); NaN values where not OK.
    """

    name: str
    definition: str
    title: str
    projection: str
    formula: str
    focal_basis: str
    fields: np.ndarray
    theta: np.ndarray
    g: np.ndarray
    wavelengths: np.ndarray
    reference_wavelength: float
    scale: str
    z_planes: np.ndarray
    s_prime: np.ndarray
    from_last_vertex: np.ndarray
    defocus: np.ndarray
    paraxial_focal_length: np.ndarray
    least_squares_focal_length: np.ndarray
    focal_length: np.ndarray
    efl: np.ndarray
    yp: np.ndarray
    y_ref: np.ndarray
    D: np.ndarray
    Dr: np.ndarray
    status: np.ndarray

    @property
    def n_planes(self) -> int:
        return int(self.z_planes.size)

    @property
    def n_wavelengths(self) -> int:
        return int(self.wavelengths.size)

    @property
    def focal_description(self) -> str:
        """How f is chosen, in words."""
        if self.focal_basis == "paraxial":
            return "f = paraxial F0 of the plane (Pestrecov Eq. 8; the EFL in the Gaussian plane)"
        return (
            "f = least-squares fit sum(g y')/sum(g^2) over the traced fields "
            "(our criterion; OpticStudio's calibration criterion is not documented here)"
        )

    def describe(self) -> str:
        """One line naming the definition: its mapping and its focal length."""
        return f"{self.title}: y_ref = {self.formula}, {self.focal_description}"

    def plane_label(self, i: int) -> str:
        return plane_label(self.s_prime[i], self.defocus[i])

    def __repr__(self) -> str:
        with np.errstate(invalid="ignore"):
            worst = float(np.nanmax(np.abs(self.Dr))) if np.isfinite(self.Dr).any() else math.nan
        wl = ", ".join(f"{w:g}" for w in self.wavelengths)
        return (
            f"ProjectionDistortion({self.name!r}, {self.definition} ({self.focal_basis} f), "
            f"{self.fields.size} fields {self.fields.min():g}..{self.fields.max():g} deg, "
            f"{self.n_planes} plane(s), [{wl}] nm, max |Dr| = {100 * worst:.6g} %)"
        )


def projection_distortion(
    lens: Lens,
    fields_deg: npt.ArrayLike | None = None,
    *,
    definition: str = "f-tan-theta",
    focal: str | None = None,
    plane: ImagePlane | Sequence[ImagePlane] | str | None = None,
    s_prime: npt.ArrayLike | None = None,
    from_last_vertex: npt.ArrayLike | None = None,
    defocus: npt.ArrayLike | None = None,
    object_distance: float | str | None = None,
    wavelength: float | str | None = None,
    wavelengths: npt.ArrayLike | str | None = None,
    scale: str = "reference",
    clip: bool = True,
) -> ProjectionDistortion:
    """Distortion of ``lens`` against a named reference definition (module docstring), from one
    trace of the real chief rays, in one or more image planes and at one or more wavelengths.

    Parameters
    ----------
    lens : Lens
    fields_deg : array_like, optional
        Field angles θ in degrees (object-space chief-ray angle, object at infinity). Default:
        11 fields from 0 to the lens's field. The least-squares f is fitted over these fields.
    definition : str
        A key of :data:`DEFINITIONS`: ``f-tan-theta`` (default), ``f-theta``,
        ``calibrated-f-tan-theta``, ``calibrated-f-theta``, ``equidistant``,
        ``equisolid-angle``, ``stereographic``, ``orthographic``.
    focal : {"paraxial", "least-squares"}, optional
        The focal length of a fisheye projection (default ``"least-squares"``); the F-tanθ / F-θ
        names fix it (``calibrated-*`` = least squares).
    plane, s_prime, from_last_vertex, defocus
        The image plane(s), as in :func:`distortion.characteristic.characteristic_distortion`
        (default: the Gaussian plane).
    object_distance : float or "inf", optional
        Must be infinite (default: the lens file's object; a lens with a finite object needs
        ``object_distance=inf``).
    wavelength, wavelengths, scale
        One wavelength (nm; default the lens's reference), or several (``"lens"`` for the lens's
        own) measured in the reference wavelength's planes, each against the reference
        wavelength's f (``scale="reference"``) or its own (``"own"``), as in
        :func:`~distortion.characteristic.characteristic_distortion`.
    clip : bool
        Apply the lens's semi-diameters to the chief rays.

    Returns
    -------
    ProjectionDistortion
        ``D`` (mm) and ``Dr`` (fraction) per wavelength, plane and field, both candidate focal
        lengths, and the definition's name, mapping and focal basis.

    Raises
    ------
    TraceError
        An unknown definition or focal choice, a finite object, no traced field off the axis for
        a least-squares f.
    """
    from raytrace.paraxial import paraxial, resolve_object_distance

    from .characteristic import ChromaticDistortion, characteristic_distortion

    d = _definition_with_focal(definition, focal)
    basis = d.focal if focal is None else focal
    od = resolve_object_distance(lens, object_distance=object_distance)
    if math.isfinite(od):
        raise TraceError(
            f"definition {d.name!r} needs an object at infinity (theta is the angle of the "
            f"object-space chief ray from a point at infinity), but the object is {od:g} mm from "
            "the first vertex; give object_distance=inf (--object-distance inf), or use the "
            "characteristic distortion D0 = y' - M0 y for a finite object"
        )
    common = dict(
        fields_deg=fields_deg,
        plane=plane,
        s_prime=s_prime,
        from_last_vertex=from_last_vertex,
        defocus=defocus,
        object_distance=math.inf,
        reference="characteristic",
        clip=clip,
    )
    res = characteristic_distortion(
        lens, **common, wavelength=wavelength, wavelengths=wavelengths, scale=scale
    )
    members = list(res) if isinstance(res, ChromaticDistortion) else [res]
    first = members[0]
    theta_deg = first.fields
    theta = np.radians(theta_deg)
    g = projection_heights(d.projection, theta)
    yp = np.stack([m.yp for m in members])  # (w, p, n)
    paraxial_f = np.stack([m.constant for m in members])  # (w, p): F0 (reference's or own)
    lsq = least_squares_focal_length(g, yp)  # each wavelength's own heights
    chromatic = isinstance(res, ChromaticDistortion)
    if chromatic and scale == "reference":
        ref = float(lens.wavelength)
        hit = np.nonzero(res.wavelengths == ref)[0]
        ref_yp = (
            members[int(hit[0])].yp
            if hit.size
            else characteristic_distortion(lens, **common, wavelength=ref).yp
        )
        lsq = np.broadcast_to(least_squares_focal_length(g, ref_yp), lsq.shape).copy()
    if basis == "least-squares" and not np.all(np.isfinite(lsq)):
        raise TraceError(
            f"definition {d.name!r}: the least-squares focal length needs at least one traced "
            "field off the axis; give fields_deg with nonzero angles"
        )
    f = paraxial_f if basis == "paraxial" else lsq
    y_ref = f[:, :, None] * g[None, None, :]
    D, Dr = linear_and_relative(yp, y_ref)
    wls = (
        np.asarray(res.wavelengths, dtype=float)
        if chromatic
        else np.array([first.wavelength], dtype=float)
    )
    return ProjectionDistortion(
        name=lens.name,
        definition=d.name,
        title=d.title,
        projection=d.projection,
        formula=PROJECTIONS[d.projection].formula,
        focal_basis=basis,
        fields=theta_deg,
        theta=theta,
        g=g,
        wavelengths=wls,
        reference_wavelength=float(lens.wavelength),
        scale=scale if chromatic else "",
        z_planes=first.z_planes,
        s_prime=first.s_prime if not chromatic else first.z_planes - res.reference_paraxial.z_Hp,
        from_last_vertex=first.from_last_vertex,
        defocus=first.defocus if not chromatic else first.z_planes - res.reference_paraxial.z_gauss,
        paraxial_focal_length=paraxial_f,
        least_squares_focal_length=lsq,
        focal_length=f,
        efl=np.array([paraxial(lens, math.inf, float(w)).efl for w in wls], dtype=float),
        yp=yp,
        y_ref=y_ref,
        D=D,
        Dr=Dr,
        status=np.stack([m.status for m in members]),
    )


def _definition_with_focal(name: str, focal: str | None) -> Definition:
    d = definition(name)
    if focal is None:
        return d
    if focal not in FOCALS:
        raise TraceError(f"unknown focal-length choice {focal!r}; expected one of {FOCALS}")
    if d.fixed_focal and focal != d.focal:
        other = {
            "f-tan-theta": "calibrated-f-tan-theta",
            "f-theta": "calibrated-f-theta",
            "calibrated-f-tan-theta": "f-tan-theta",
            "calibrated-f-theta": "f-theta",
        }[d.name]
        raise TraceError(
            f"definition {d.name!r} fixes the {d.focal} focal length; for the {focal} one use "
            f"definition {other!r}"
        )
    return d
