"""Where the object and the image plane are: the one vocabulary of the project.

The same names are used as API keywords, CLI flags (with dashes) and JSON keys (with ``_mm``);
docs/design.md ("Vocabulary") has the table.

Object plane (give at most one; default: the lens file's object):

``object_distance``
    mm from the object plane to the FIRST VERTEX, a positive magnitude as in lens files, or
    ``inf``. (A string ``"12x"`` is accepted as the image scale below.)
``object_s``
    Pestrecov's signed ``s``: mm from the first principal point H, negative for a real object.
``object_scale``
    an image scale N ("N×"): the object distance at which the Gaussian magnification is −1/N,
    ``s = f/m0 − f = −f (1 + N)`` (Pestrecov Eq. 5 inverted).

Image plane (:class:`ImagePlane`; default: the Gaussian image plane of the object):

``s_prime``
    mm from the second principal point H' (Pestrecov's s', positive to the right);
``from_last_vertex``
    mm from the last vertex, positive to the right;
``defocus``
    mm from the Gaussian image plane of the object (+ = away from the lens);
``gaussian`` / ``file``
    the Gaussian image plane / the plane the lens file defines (its last thickness).
``gaussian_reference``
    the Gaussian image plane of the object at the lens's reference wavelength, whatever
    wavelength is traced: where a lens file's image solve (``t = "gaussian"``, CODE V ``PIM``)
    puts the plane for the traced object (the command line's default for such a file; for the
    file's own object it is ``file``, to round-off).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..errors import TraceError
from ..units import UnitError, plane_distance_mm
from .orthoscopy import object_distance_for_magnification

if TYPE_CHECKING:
    from ..lens import Lens
    from .firstorder import ParaxialResult

PLANE_KINDS = ("s_prime", "from_last_vertex", "defocus", "gaussian", "file", "gaussian_reference")


@dataclass(frozen=True)
class ImagePlane:
    """An image plane in the project's vocabulary (module docstring).

    kind:  ``"s_prime"`` | ``"from_last_vertex"`` | ``"defocus"`` | ``"gaussian"`` | ``"file"``
           | ``"gaussian_reference"``.
    value: the distance for the first three kinds (ignored for the others): a number in mm or a
           string with a length unit as the command line takes it (``"50.5mm"``, ``"5cm"``,
           :func:`raytrace.units.plane_distance_mm`); stored as a float in mm. TraceError,
           naming the kind, for a value that is not a length, not finite, or 1e10 mm or more
           (:data:`raytrace.units.PLANE_LIMIT_MM`).
    """

    kind: str
    value: float | str = 0.0

    def __post_init__(self) -> None:
        if self.kind not in PLANE_KINDS:
            raise TraceError(
                f"unknown image-plane kind {self.kind!r}; expected one of {', '.join(PLANE_KINDS)}"
            )
        try:  # the one parser of the command line's --s-prime / --from-last-vertex / --defocus
            object.__setattr__(self, "value", plane_distance_mm(self.value, self.kind))
        except UnitError as e:
            raise TraceError(str(e)) from None

    def z(self, par: ParaxialResult) -> float:
        """Absolute z (mm from the first vertex) of this plane for the paraxial data ``par``."""
        if self.kind == "s_prime":
            return float(par.z_from_s_prime(self.value))
        if self.kind == "from_last_vertex":
            return float(par.z_from_last_vertex(self.value))
        if self.kind == "defocus":
            return float(par.z_from_defocus(self.value))
        if self.kind == "file":
            return float(par.z_image_file)
        if self.kind == "gaussian_reference":
            return float(par.z_gauss_reference)
        return float(par.z_gauss)

    def describe(self) -> str:
        if self.kind in ("gaussian", "file", "gaussian_reference"):
            return {
                "gaussian": "the Gaussian image plane",
                "file": "the lens file's plane",
                "gaussian_reference": "the Gaussian image plane",  # of the reference wavelength
            }[self.kind]
        return f"{self.kind} = {self.value:g} mm"


def image_planes(
    plane: ImagePlane | Iterable[ImagePlane] | str | None = None,
    *,
    s_prime=None,
    from_last_vertex=None,
    defocus=None,
) -> list[ImagePlane]:
    """The image planes a call asks for: ``plane`` (an :class:`ImagePlane`, a list of them, or
    ``"gaussian"`` / ``"file"``) or ONE of the keywords ``s_prime`` / ``from_last_vertex`` /
    ``defocus`` (a distance or a sequence of them: numbers in mm or strings with a length unit,
    ``"50.5mm"``, as :class:`ImagePlane` takes them). Nothing → the Gaussian plane."""
    kw = {
        k: v
        for k, v in (
            ("s_prime", s_prime),
            ("from_last_vertex", from_last_vertex),
            ("defocus", defocus),
        )
        if v is not None
    }
    if len(kw) + (plane is not None) > 1:
        raise TraceError(
            "give the image plane(s) one way: plane=, s_prime=, from_last_vertex= or defocus="
        )
    if kw:
        ((kind, v),) = kw.items()
        # objects, not floats: a distance may be a string with its unit ("50.5mm"), read by
        # ImagePlane with the command line's parser
        items = np.asarray(v, dtype=object).ravel().tolist()
        if not items:
            raise TraceError(f"{kind}: no image plane given")
        return [ImagePlane(kind, x) for x in items]
    if plane is None:
        return [ImagePlane("gaussian")]
    if isinstance(plane, str):
        if plane not in ("gaussian", "file"):
            raise TraceError(
                f"plane={plane!r}: a string plane is 'gaussian' or 'file'; for a distance use "
                "s_prime=, from_last_vertex= or defocus= (mm)"
            )
        return [ImagePlane(plane)]
    if isinstance(plane, ImagePlane):
        return [plane]
    out = list(plane)
    if not out or not all(isinstance(p, ImagePlane) for p in out):
        raise TraceError("plane= takes an ImagePlane, a list of them, 'gaussian' or 'file'")
    return out


def plane_z(par: ParaxialResult, planes: list[ImagePlane]) -> np.ndarray:
    """Absolute z of ``planes``; refuses a plane on or before the last vertex (along the light:
    after an odd number of mirrors the image space runs toward −z, ``n_image < 0``; every
    distance stays signed along +z, as the thicknesses of Zemax and CODE V)."""
    kinds = {p.kind for p in planes}
    if len(kinds) == 1 and kinds <= {"s_prime", "from_last_vertex", "defocus"}:
        # distances from one origin (a sweep of planes): z = origin + distance, in one numpy pass
        origin = ImagePlane(planes[0].kind).z(par)
        z = origin + np.array([p.value for p in planes], dtype=float)
    else:
        z = np.array([p.z(par) for p in planes], dtype=float)
    if not np.all(np.isfinite(z)):
        raise TraceError("the Gaussian image is at infinity; give the image plane explicitly")
    direction = -1.0 if par.n_image < 0.0 else 1.0
    bad = np.nonzero((z - par.z_last) * direction <= 0.0)[0]
    if bad.size:
        i = int(bad[0])
        d = planes[i].describe()
        what = d if d.startswith("the ") else f"the image plane {d}"
        why = ""
        if planes[i].kind in ("gaussian", "gaussian_reference") and math.isfinite(
            par.object_distance
        ):
            # the object inside the front focal length: a virtual image
            why = (
                f" (the object, {par.object_distance:g} mm in front of the first vertex, is "
                "inside the front focal length: its image is virtual; lengths are in mm, "
                "1.5m for metres)"
            )
        raise TraceError(
            f"{what} lies {z[i] - par.z_last:+.4f} mm from the last vertex, on or before the last "
            f"surface; an image plane must be behind the lens{why}"
        )
    return z


def parse_scale(text: str) -> float | None:
    """``"12x"`` / ``"12X"`` / ``"12×"`` → 12.0; anything else → None."""
    t = str(text).strip()
    if t[-1:] in ("x", "X", "×"):
        try:
            n = float(t[:-1])
        except ValueError:
            return None
        return n
    return None


def object_distance_for_scale(lens: Lens, n: float, wavelength: float | None = None) -> float:
    """Object distance (mm from the first vertex) for the image scale "N×": Gaussian
    magnification −1/N, ``s = −f (1 + N)`` from H (Pestrecov Eq. 5 inverted)."""
    from .firstorder import paraxial

    if not (math.isfinite(n) and n > 0):
        raise TraceError(f"image scale {n!r}x: N must be a positive number (12x: m0 = -1/12)")
    par = paraxial(lens, math.inf, wavelength)
    if not par.efl > 0:
        raise TraceError(
            f"{lens.name}: an image scale {n:g}x (real object, magnification -1/{n:g}) needs a "
            f"positive focal length; this lens has EFL {par.efl:.6g} mm — give the object as "
            "object_distance (mm) instead"
        )
    s = object_distance_for_magnification(par.efl, -1.0 / n)
    return object_distance_for_s(lens, s, wavelength, _par=par)


def object_distance_for_s(
    lens: Lens, s: float, wavelength: float | None = None, *, _par: ParaxialResult | None = None
) -> float:
    """Object distance (mm from the first vertex) of Pestrecov's signed ``s`` (mm from H)."""
    from .firstorder import paraxial

    if not (math.isfinite(s) and s < 0):
        raise TraceError(f"object_s must be negative (a real object left of H), got {s!r}")
    par = _par if _par is not None else paraxial(lens, math.inf, wavelength)
    od = -(par.z_H + s)
    if not od > 0:
        raise TraceError(
            f"object_s {s!r} puts the object plane behind the first vertex (H lies "
            f"{par.z_H:.4f} mm from the first vertex)"
        )
    return float(od)


def resolve_object_distance(
    lens: Lens,
    *,
    object_distance: float | str | None = None,
    object_s: float | None = None,
    object_scale: float | None = None,
    wavelength: float | None = None,
) -> float:
    """The object distance (positive mm from the first vertex, or ``inf``) from at most one of
    ``object_distance`` (mm, ``inf`` or ``"12x"``), ``object_s`` (signed mm from H) and
    ``object_scale`` (N of "N×"); none → the lens file's object."""
    given = [
        k
        for k, v in (
            ("object_distance", object_distance),
            ("object_s", object_s),
            ("object_scale", object_scale),
        )
        if v is not None
    ]
    if len(given) > 1:
        raise TraceError(f"give the object one way, not {' and '.join(given)}")
    from ..units import OBJECT_DISTANCE_FORMS, UnitError, image_scale, length_mm, real_number

    if object_s is not None:  # a number (mm) or a length with its unit ("-1.5m")
        return object_distance_for_s(lens, length_mm(object_s, "object_s"), wavelength)
    if object_scale is not None:  # 12 or "12x"
        return object_distance_for_scale(
            lens, image_scale(object_scale, "object_scale"), wavelength
        )
    if object_distance is None:
        return float(lens.object_distance)
    if isinstance(object_distance, str):
        t = object_distance.strip().lower()
        if t in ("inf", "infinity"):
            return math.inf
        n = parse_scale(t)
        if n is not None:
            return object_distance_for_scale(lens, n, wavelength)
        try:  # mm, or a length with its unit ("1.5m", "250mm")
            object_distance = length_mm(t, "object_distance", allow_inf=True)
        except UnitError:
            raise TraceError(
                f"object_distance {object_distance!r}: expected {OBJECT_DISTANCE_FORMS}"
            ) from None
    od = real_number(object_distance, "object_distance", OBJECT_DISTANCE_FORMS, error=TraceError)
    if not od > 0:
        raise TraceError(
            f"object_distance must be a positive magnitude (mm from the object plane to the "
            f"first vertex) or inf, got {od!r}; for Pestrecov's signed s use object_s="
        )
    return od


def checked_wavelength(value: float | str | None, what: str = "wavelength") -> float | None:
    """A wavelength keyword through the one check (:func:`raytrace.units.wavelength_nm`).

    Parameters
    ----------
    value : float, str or None
        nm, or a string with a unit (``"0.5876um"``); ``None`` passes through (the caller's
        default, usually the lens's reference wavelength).
    what : str
        The name used in the error message.

    Returns
    -------
    float or None
        The wavelength in nm, or ``None``.

    Raises
    ------
    TraceError
        A value the check refuses (e.g. a bare number below 100, which looks like µm).
    """
    if value is None:
        return None
    from ..units import UnitError, wavelength_nm

    try:
        return wavelength_nm(value, what)
    except UnitError as e:
        raise TraceError(str(e)) from None


def resolve_paraxial(
    lens: Lens,
    object_distance: float | str | None = None,
    object_s: float | None = None,
    object_scale: float | None = None,
    wavelength: float | str | None = None,
    *,
    nominal: bool = False,
) -> ParaxialResult:
    """The paraxial data of ``lens`` for an object given in the project's vocabulary.

    Checks ``wavelength`` (:func:`checked_wavelength`), resolves the object plane
    (:func:`resolve_object_distance`) at that wavelength and runs
    :func:`raytrace.paraxial.paraxial` there: the one path from the API keywords to a
    :class:`ParaxialResult`.

    Parameters
    ----------
    lens : Lens
    object_distance, object_s, object_scale
        The object plane (at most one): mm from the first vertex (or ``inf`` / ``"12x"``),
        Pestrecov's signed s from H (mm, negative for a real object), or an image scale N
        ("N×"). Default: the lens file's object.
    wavelength : float or str, optional
        nm (or a string with a unit); default the lens's reference wavelength.
    nominal : bool
        Take the first-order data of the lens's centred nominal (``lens.nominal()``), for a lens
        with decentred or tilted surfaces; the object is still resolved with ``lens``.

    Returns
    -------
    ParaxialResult
        Its ``object_distance`` (mm from the first vertex, or inf) and ``wavelength`` (nm) are
        the resolved ones.
    """
    from .firstorder import paraxial

    wl = checked_wavelength(wavelength)
    obj = dict(object_distance=object_distance, object_s=object_s, object_scale=object_scale)
    od = resolve_object_distance(lens, **obj, wavelength=wl)
    return paraxial(lens.nominal() if nominal else lens, object_distance=od, wavelength=wl)
