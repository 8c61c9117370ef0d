"""First-order (paraxial, y-nu) optics of a centred lens: cardinal points, pupils, m_e.

All distances are in mm and signed per docs/design.md ("Conventions") / Pestrecov Fig. 1:

* absolute positions ``z_*`` are measured along the axis from the first vertex (light toward +z);
* ``s`` is the object-plane distance from the first principal (nodal) point H, negative for a real
  object; ``s'`` the image-plane distance from H', positive for a real image;
* ``HE0 = z_E0 - z_H`` and ``H'E0' = z_E0' - z_H'`` locate the paraxial pupils; ``p0 = s - HE0``
  (object plane from E0, negative) and ``p0' = s' - H'E0'`` (image plane from E0').

The paraxial ray is traced in the reduced form ``n'u' = n u - y φ`` (refraction, ``φ = (n'-n) c``)
and ``y₂ = y₁ + t u'`` (transfer), with ``u`` the slope dy/dz. Everything follows from the 2×2
system matrix and two rays; the chief ray is the paraxial ray through the centre of the stop.

Pestrecov's Eq. (6), ``m_e = lim tan α / tan α'`` (object- over image-space slope of the
paraxial chief ray), and Eq. (5), the Gaussian magnification, are computed here; the constants of
orthoscopy in any image plane (Eqs. 7–8) are in :mod:`.orthoscopy`.

Mirrors (centred mirror systems: Cassegrain, Mangin, catadioptric lenses): the trace is the same
y-nu trace with the index after a mirror taken as ``n' = −n`` and every index after an odd number
of mirrors negative (the convention of Zemax and CODE V, whose thicknesses are then negative:
``y₂ = y₁ + t u'`` with u' = n'u'/n' keeps working, and positions stay absolute z along the
axis). So ``n_image`` is negative after an odd number of mirrors; a concave mirror (R < 0 facing
the light) has a positive focal length. A lens that is not centred (decenters, tilts, folds:
``Lens.is_centred``) has no first-order data here: :func:`paraxial` refuses it in one line, and
``lens.nominal()`` gives the centred lens without its moves.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..errors import LensError
from ..lens import Lens, require_lens
from ..units import OBJECT_DISTANCE_FORMS, WAVELENGTH_RANGE_NM, real_number


@dataclass(frozen=True)
class ParaxialResult:
    """First-order data of a lens for one object distance and wavelength (mm, signed; see module).

    efl:       equivalent focal length 1/Φ (in air equal to the focal lengths f = f').
    f_object, f_image:  object-side focal length ``-n/Φ`` (negative for a positive lens) and
               image-side focal length ``n'/Φ``.
    bfl:       last vertex → F' ;  ffl: first vertex → F (signed; negative when F lies to the left).
    z_F, z_Fp, z_H, z_Hp, z_N, z_Np:  focal, principal and nodal points (absolute z).
    z_E0, z_E0p, epd, xpd:  paraxial entrance / exit pupil positions and diameters.
    pupil_magnification: xpd / epd.
    m_e:       Pestrecov Eq. (6): object- over image-space slope of the paraxial chief ray.
    lagrange:  Lagrange invariant n (u_c y_m − u_m y_c) for the lens's full field and aperture.
    stop_radius: paraxial radius of the stop that the aperture specification implies.
    HE0, HpE0p: pupil positions from the principal points (Pestrecov Table III).
    object_distance: positive magnitude, first vertex to object plane (inf for infinity).
    z_object:  object plane (−inf for infinity); s: object plane from H (−inf for infinity).
    z_gauss:   Gaussian image plane; s_prime_gauss: it from H'; gaussian_image_distance: from the
               last vertex; m0: Gaussian lateral magnification (Eq. 5; 0 for an object at infinity).
    p0:        s − HE0 (−inf for infinity); working_fnumber: 1/(2 n' |u'_marginal|).
    z_last:    z of the last vertex; z_image_file: the image plane the lens file defines.
    z_gauss_reference: the Gaussian image plane of this object at the lens's reference
               wavelength (``z_gauss`` when ``wavelength`` is the reference): where an image solve
               (``Lens.image_solve``, ``t = "gaussian"``, CODE V ``PIM``) puts the image plane for
               this object, whatever wavelength is traced (solves use the reference wavelength,
               as OpticStudio's and CODE V's do); NaN when there is no finite Gaussian image there.
    n_object, n_image: indices of object and image space.
    chief_height_last, chief_slope_image: the paraxial chief ray of unit object-space slope
               (tan α = 1) at the last vertex: its height (mm) and image-space slope — what
               Eq. (8) reduces to when the exit pupil is at infinity (image-space telecentric).
    """

    efl: float
    f_object: float
    f_image: float
    bfl: float
    ffl: float
    z_F: float
    z_Fp: float
    z_H: float
    z_Hp: float
    z_N: float
    z_Np: float
    z_E0: float
    z_E0p: float
    epd: float
    xpd: float
    pupil_magnification: float
    m_e: float
    lagrange: float
    stop_radius: float
    HE0: float
    HpE0p: float
    object_distance: float
    z_object: float
    s: float
    z_gauss: float
    s_prime_gauss: float
    gaussian_image_distance: float
    m0: float
    p0: float
    working_fnumber: float
    z_last: float
    z_image_file: float
    n_object: float
    n_image: float
    wavelength: float
    chief_height_last: float = math.nan
    chief_slope_image: float = math.nan
    z_gauss_reference: float = math.nan

    @property
    def f_number(self) -> float:
        """The f-number |EFL| / EPD of the lens's aperture (inf for a zero EPD); the working
        f-number of a finite object is :attr:`working_fnumber`."""
        return abs(self.efl) / self.epd if self.epd else math.inf

    def __repr__(self) -> str:
        obj = (
            "object at infinity"
            if self.infinite
            else f"object {self.object_distance:g} mm (s = {self.s:.6g} mm, m0 = {self.m0:.6g})"
        )
        return (
            f"ParaxialResult(EFL {self.efl:.6f} mm, BFL {self.bfl:.6f} mm, EPD {self.epd:.6g} mm, "
            f"m_e {self.m_e:.6f}, HE0 {self.HE0:.6g} mm, H'E0' {self.HpE0p:.6g} mm, {obj}, "
            f"{self.wavelength:g} nm)"
        )

    @property
    def infinite(self) -> bool:
        """True for an object at infinity."""
        return math.isinf(self.object_distance)

    # --- image-plane conversions (all return an absolute z) -----------------------------------
    def z_from_s_prime(self, s_prime: float | np.ndarray) -> float | np.ndarray:
        """Image plane given as s' from H' (Pestrecov) → absolute z."""
        return _shift(self.z_Hp, s_prime)

    def z_from_last_vertex(self, d: float | np.ndarray) -> float | np.ndarray:
        """Image plane given as a distance from the last vertex → absolute z."""
        return _shift(self.z_last, d)

    def z_from_defocus(self, dz: float | np.ndarray) -> float | np.ndarray:
        """Image plane given as a defocus from the Gaussian image plane (+ = away from lens)."""
        return _shift(self.z_gauss, dz)

    def s_prime_of(self, z_image: float | np.ndarray) -> float | np.ndarray:
        """s' (from H') of an absolute image-plane position."""
        return z_image - self.z_Hp


def _shift(origin: float, d: float | np.ndarray) -> float | np.ndarray:
    """origin + d, keeping a Python float for a scalar."""
    return origin + np.asarray(d, dtype=float) if np.ndim(d) else origin + float(d)


def _system(lens: Lens, wavelength: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Curvatures at the vertices (a Q-type surface's paraxial one, ``Surface.vertex_curvature``),
    thicknesses (between vertices), indices before and after each surface; after an odd number
    of mirrors the indices are negative (n' = −n at a mirror; module docstring)."""
    ss = lens.surfaces
    c = np.array([s.vertex_curvature for s in ss], dtype=float)
    t = np.array([s.thickness for s in ss[:-1]], dtype=float)
    idx = np.array(lens.indices(wavelength)[0])  # object space, then after each surface
    if lens.has_mirrors:
        sign = np.cumprod([-1.0 if s.mirror else 1.0 for s in ss])
        idx[1:] *= sign
    return c, t, idx[:-1], idx[1:]


def require_centred(lens: Lens) -> None:
    """Raise :class:`LensError` (one line, naming the surface and the fix) unless ``lens`` is
    centred: first-order optics need a common axis."""
    j = lens.first_placed()
    if j is None:
        return
    where = "the image surface" if j == 0 else f"surface {j}"
    raise LensError(
        f"{lens.name}: {where} is decentered or tilted: first-order (paraxial) data need a "
        "centred lens; use lens.nominal() for the data of the lens without its decenters and "
        "tilts, or real rays (chief_rays_2d) for the lens as it is"
    )


#: a number for one lens, or an (I,) array over instances (:func:`ynu_trace`)
Scalars = float | np.ndarray


def ynu_trace(
    c: np.ndarray,
    t: np.ndarray,
    n_in: np.ndarray,
    n_out: np.ndarray,
    y: Scalars,
    nu: Scalars,
    upto: int,
    start: int = 0,
) -> tuple[Scalars, Scalars]:
    """Paraxial trace of (y, n·u) through surfaces [start, upto): transfer ``y += t n'u' / n'``
    to each surface, then refraction ``n'u' = n u − y (n' − n) c`` (the module's y-nu trace, the
    one implementation).

    ``c``, ``t``, ``n_in``, ``n_out`` are indexed by surface first (curvatures 1/mm, thicknesses
    mm, indices before and after each surface, as :func:`_system` gives them): ``c[i]`` is a
    number for one lens, or an (I,) array for I instances traced at once (``y``, ``nu`` a number
    or (I,), broadcast). (y, nu) is the ray at the first vertex for ``start`` = 0, else just
    after surface ``start-1`` (refracted there, not yet transferred), as a trace with
    ``upto=start`` returns it. Returns (y, n'u') just after surface ``upto-1``: the height on
    that surface (mm) and the reduced slope after it.
    """
    for i in range(start, upto):
        if i:
            y = y + t[i - 1] * nu / n_out[i - 1]
        nu = nu - y * (n_out[i] - n_in[i]) * c[i]
    return y, nu


def ynu_matrix(
    c: np.ndarray, t: np.ndarray, n_in: np.ndarray, n_out: np.ndarray, upto: int
) -> tuple[tuple[Scalars, Scalars], tuple[Scalars, Scalars]]:
    """``((A, B), (C, D))``: the 2×2 matrix mapping (y, nu) at the first vertex to (y, n'u')
    after surface ``upto-1`` — :func:`ynu_trace` of (1, 0) and (0, 1); numbers, or (I,) arrays
    over instances (arguments as in :func:`ynu_trace`)."""
    a = ynu_trace(c, t, n_in, n_out, 1.0, 0.0, upto)
    b = ynu_trace(c, t, n_in, n_out, 0.0, 1.0, upto)
    return (a[0], b[0]), (a[1], b[1])


def _entrance_pupil(c, t, n_in, n_out, stop: int) -> tuple[float, float, float]:
    """(a, b, z_E0): the stop height ``a y1 + b n u1`` of a paraxial ray per unit height / unit
    reduced slope at the first vertex, and the paraxial entrance pupil (absolute z; inf for an
    object-space telecentric stop)."""
    (a, b), _ = ynu_matrix(c, t, n_in, n_out, stop + 1)
    z_E0 = math.inf if a == 0.0 else float(b * n_in[0] / a)
    return float(a), float(b), z_E0


def entrance_pupil_diameter(
    lens: Lens, efl: float, n0: float, z_E0: float, z_obj: float, *, system=None
) -> float:
    """The paraxial entrance-pupil diameter the lens's aperture specification implies (mm) — the
    one conversion in the project (:class:`raytrace.lens.Aperture` lists the kinds).

    ``fnumber`` N: ``EPD = |EFL| / N`` (infinite-conjugate f-number); ``epd``: as given;
    ``na`` (object-space n sin U of the axial marginal ray): the marginal ray leaves the axial
    object point at the real angle ``U = asin(NA/n)`` toward the paraxial pupil edge,
    ``EPD = 2 |z_E0 − z_obj| tan(asin(NA/n))`` — optiland's convention
    (``ObjectNAAperture.compute_epd``), checked against optiland in tests/test_paraxial.py;
    ``cone_angle`` U (degrees): the same with U given, ``EPD = 2 |z_E0 − z_obj| tan U``;
    ``float`` (stop semi-diameter r): the paraxial marginal ray meets the stop at height r;
    ``working_fnumber`` W: the paraxial marginal ray leaves the last surface with
    ``|n' u'| = 1/(2 W)``. The last two are linear in the EPD and scale a unit trace;
    ``system`` = ``(c, t, n_in, n_out)`` of :func:`_system` (default: at the lens's wavelength).
    """
    ap = lens.aperture
    if ap.kind == "fnumber":
        if not math.isfinite(efl):
            raise LensError(f"{lens.name}: an f-number aperture needs a finite focal length")
        return abs(efl) / ap.value
    if ap.kind == "epd":
        return ap.value
    if ap.kind in ("float", "working_fnumber"):
        c, t, n_in, n_out = system if system is not None else _system(lens, lens.wavelength)
        y1, nu1 = _marginal_start(lens, 2.0, n0, z_E0, z_obj)  # EPD 2: unit pupil radius
        if ap.kind == "float":
            a, b, _ = _entrance_pupil(c, t, n_in, n_out, lens.stop_index)
            h = abs(a * y1 + b * nu1)
            if not h > 0.0:
                raise LensError(f"{lens.name}: float by stop size: the stop is at an image")
            return 2.0 * ap.value / h
        _, nuk = ynu_trace(c, t, n_in, n_out, y1, nu1, len(c))
        if nuk == 0.0:
            raise LensError(f"{lens.name}: a working F/# needs a lens that is not afocal")
        return 2.0 * (1.0 / (2.0 * abs(nuk))) / ap.value
    if ap.kind == "na" and ap.value >= n0:
        raise LensError(f"{lens.name}: NA {ap.value} must be below the object index {n0}")
    if math.isinf(z_obj):
        raise LensError(f"{lens.name}: an object-space NA needs a finite object distance")
    if math.isinf(z_E0):
        raise LensError(f"{lens.name}: entrance pupil at infinity with an object-space NA")
    if ap.kind == "cone_angle":
        return 2.0 * abs(z_E0 - z_obj) * math.tan(math.radians(ap.value))
    return 2.0 * abs(z_E0 - z_obj) * math.tan(math.asin(ap.value / n0))


def _marginal_start(
    lens: Lens, epd: float, n0: float, z_E0: float, z_obj: float
) -> tuple[float, float]:
    """(y1, n u1) at the first vertex of the paraxial marginal ray to the pupil edge."""
    if math.isinf(z_obj):
        return epd / 2.0, 0.0
    if math.isinf(z_E0):
        raise LensError(f"{lens.name}: entrance pupil at infinity with a finite object")
    um = (epd / 2.0) / (z_E0 - z_obj)
    return um * (0.0 - z_obj), n0 * um


def aim_geometry(
    lens: Lens, object_distance: float, wavelength: float | None = None
) -> tuple[float, float]:
    """(z_E0, stop radius) in mm for chief-ray aiming: the paraxial entrance pupil and the
    paraxial marginal-ray height at the stop. Unlike :func:`paraxial` it works for an afocal lens
    whose aperture is not an f-number, and for a lens that is not centred it uses the centred
    lens ``lens.nominal()`` (first guesses and the tolerance scale of the aim only)."""
    wl = lens.wavelength if wavelength is None else float(wavelength)
    lens = lens.nominal()  # decentered/tilted: the centred lens gives the first guesses
    c, t, n_in, n_out = _system(lens, wl)
    a, b, z_E0 = _entrance_pupil(c, t, n_in, n_out, lens.stop_index)
    if a == 0.0:
        raise LensError(f"{lens.name}: the stop is at a paraxial image of the object-space axis")
    z_obj = -math.inf if math.isinf(object_distance) else -float(object_distance)
    efl = math.nan
    if lens.aperture.kind == "fnumber":
        (_, _), (C, _) = ynu_matrix(c, t, n_in, n_out, len(c))
        efl = -1.0 / C if C != 0.0 else math.inf
    epd = entrance_pupil_diameter(
        lens, efl, float(n_in[0]), z_E0, z_obj, system=(c, t, n_in, n_out)
    )
    ym1, num1 = _marginal_start(lens, epd, float(n_in[0]), z_E0, z_obj)
    return z_E0, abs(a * ym1 + b * num1)


def gaussian_solved(lens: Lens) -> Lens:
    """The lens with its last thickness solved to put the image plane at the paraxial (Gaussian)
    image of its own object, marked ``image_solve = "gaussian"`` (what a lens file's image solve
    means; an optimizer or a lens edit keeps it after every change)."""
    d = paraxial(lens).gaussian_image_distance
    return replace(lens.with_image_distance(d), image_solve="gaussian")


def _checked_wavelength(wavelength: float | str | None) -> float | None:
    """``wavelength`` through the one check of every wavelength keyword
    (:func:`raytrace.paraxial.conjugates.checked_wavelength`: nm, a string with a unit, a line
    letter; TraceError naming it), except a float in range (the optimizers' calls), which needs
    no more checking."""
    if wavelength is None or (
        isinstance(wavelength, float)
        and WAVELENGTH_RANGE_NM[0] <= wavelength <= WAVELENGTH_RANGE_NM[1]
    ):
        return wavelength
    from .conjugates import checked_wavelength

    return checked_wavelength(wavelength)


def element_power(
    lens: Lens, first: int, last: int, wavelength: float | str | None = None
) -> float:
    """Paraxial power of the surfaces ``first`` .. ``last`` (1-based, inclusive): an element, a
    cemented group or any run of surfaces, in the media around it.

    Parameters
    ----------
    lens : Lens
    first, last : int
        1-based surface numbers, ``first <= last`` (an element in air: its two surfaces).
    wavelength : float or str, optional
        nm (or ``"0.5876um"``, a line letter ``"d"``); default the lens's reference wavelength.

    Returns
    -------
    float
        Power φ in 1/mm: −n′u′ after surface ``last`` of a ray entering surface ``first`` at
        height 1 mm parallel to the axis (:func:`ynu_trace`); + converging. For a lens in air,
        φ = (n − 1)(c1 − c2) + (n − 1)² t c1 c2 / n (the thick-lens formula); 1/φ is its
        focal length.

    Raises
    ------
    LensError
        Surfaces out of range, or a lens that is not centred.
    TraceError
        A wavelength the unit check refuses (``"abc"``, a bare 0.5876, which looks like µm).
    """
    require_centred(lens)
    n = lens.n_surfaces
    if not 1 <= first <= last <= n:
        raise LensError(f"{lens.name}: surfaces {first}..{last}: need 1 <= first <= last <= {n}")
    wl = _checked_wavelength(wavelength)
    c, t, n_in, n_out = _system(lens, lens.wavelength if wl is None else wl)
    _, nu = ynu_trace(c, t, n_in, n_out, 1.0, 0.0, last, start=first - 1)
    return float(-nu)


def _gaussian_z(lens: Lens, od: float, z_last: float) -> float:
    """z of the Gaussian image of the axial object point ``od`` mm in front of the first vertex
    (``inf``) at the lens's reference wavelength: an axial ray (slope 1, or height 1 from
    infinity) through the system matrix, z_last − y'/u'; NaN when the image is at infinity."""
    c, t, n_in, n_out = _system(lens, lens.wavelength)
    (A, B), (C, D) = ynu_matrix(c, t, n_in, n_out, len(c))
    n0 = float(n_in[0])
    y, nu = (A, C) if math.isinf(od) else (A * od + B * n0, C * od + D * n0)
    return z_last - y * float(n_out[-1]) / nu if nu != 0.0 else math.nan


def paraxial(
    lens: Lens,
    object_distance: float | str | None = None,
    wavelength: float | str | None = None,
    *,
    object_s: float | str | None = None,
    object_scale: float | str | None = None,
) -> ParaxialResult:
    """First-order analysis of ``lens`` (see :class:`ParaxialResult` for every quantity).

    Parameters
    ----------
    lens : Lens
    object_distance, object_s, object_scale : optional
        The object plane, at most one (the same words as every trace, docs/design.md
        "Vocabulary"): positive mm from the object plane to the first vertex (or ``inf``, a
        length with its unit ``"1.5m"``, an image scale ``"12x"``); Pestrecov's signed s from H
        (mm, negative); the image scale N of "N×". Default: the lens's object.
    wavelength : float or str, optional
        nm (or ``"0.5876um"``, a line letter ``"d"``); default the lens's reference wavelength.

    Returns
    -------
    ParaxialResult

    Raises :class:`LensError` for an afocal lens, a stop the paraxial chief ray cannot locate
    (pupil at infinity is allowed and reported as ±inf), an object at a focal point, or a lens
    that is not centred (:func:`require_centred`; mirrors on the axis are fine); TraceError for
    a value the unit checks refuse.
    """
    require_lens(lens)
    wavelength = _checked_wavelength(wavelength)
    if isinstance(object_distance, str) or object_s is not None or object_scale is not None:
        from .conjugates import resolve_object_distance

        object_distance = resolve_object_distance(
            lens,
            object_distance=object_distance,
            object_s=object_s,
            object_scale=object_scale,
            wavelength=wavelength,
        )
    if object_distance is None:
        od = lens.object_distance
    else:  # a bool or a complex number is no distance (raytrace.units.real_number)
        od = real_number(object_distance, "object_distance", OBJECT_DISTANCE_FORMS, error=LensError)
    if not (od > 0.0):
        raise LensError(f"object distance must be a positive magnitude or inf, got {od}")
    require_centred(lens)
    wl = lens.wavelength if wavelength is None else float(wavelength)
    c, t, n_in, n_out = _system(lens, wl)
    ns = len(c)
    n0, nk = float(n_in[0]), float(n_out[-1])
    z_last = float(np.sum(t))
    (A, B), (C, D) = ynu_matrix(c, t, n_in, n_out, ns)
    power_scale = float(np.sum(np.abs((n_out - n_in) * c))) + 1e-300
    if abs(C) < 1e-9 * power_scale:
        raise LensError(f"{lens.name}: the lens is afocal (zero power); focal data undefined")
    phi = -C
    efl = 1.0 / phi
    f_obj, f_img = -n0 / phi, nk / phi
    bfl = -A * nk / C
    ffl = n0 * D / C
    z_Fp = z_last + bfl
    z_F = ffl
    z_H = z_F - f_obj
    z_Hp = z_Fp - f_img
    z_N = z_F + f_img
    z_Np = z_Fp + f_obj

    # Chief ray: the paraxial ray through the centre of the stop (y_stop = a y1 + b nu1 = 0).
    a, b, z_E0 = _entrance_pupil(c, t, n_in, n_out, lens.stop_index)
    if a == 0.0:
        yc1, nuc1 = 1.0, 0.0  # object-space telecentric: chief ray parallel to the axis
    else:
        yc1, nuc1 = -b * n0 / a, n0  # u1 = 1
    yck, nuck = ynu_trace(c, t, n_in, n_out, yc1, nuc1, ns)
    uck = nuck / nk
    z_E0p = math.inf if uck == 0.0 else z_last - yck / uck
    m_e = (nuc1 / n0) / uck if uck != 0.0 else math.inf

    # Object plane and marginal ray.
    infinite = math.isinf(od)
    z_obj = -math.inf if infinite else -od
    epd = entrance_pupil_diameter(lens, efl, n0, z_E0, z_obj, system=(c, t, n_in, n_out))
    ym1, num1 = _marginal_start(lens, epd, n0, z_E0, z_obj)
    stop_radius = abs(a * ym1 + b * num1)
    ymk, numk = ynu_trace(c, t, n_in, n_out, ym1, num1, ns)
    umk = numk / nk
    if math.isinf(z_E0p):
        xpd = math.inf
    else:
        xpd = 2.0 * abs(ymk + umk * (z_E0p - z_last))
    working_f = math.inf if umk == 0.0 else 1.0 / (2.0 * abs(nk) * abs(umk))

    if infinite:
        s = -math.inf
        z_gauss = z_Fp
        m0 = 0.0
        p0 = -math.inf
    else:
        s = z_obj - z_H
        if abs(umk) < 1e-300:
            raise LensError(
                f"{lens.name}: the object is at the front focal point: image at infinity"
            )
        z_gauss = z_last - ymk / umk
        m0 = (num1) / (numk) if numk != 0.0 else math.inf  # n u / n' u' of the marginal ray
        p0 = z_obj - z_E0
    # Lagrange invariant for the lens's full field: scale the chief ray to the field.
    fld = lens.field
    if fld.kind == "angle":
        k = math.tan(math.radians(fld.value))  # chief-ray slope in object space
    else:
        k = fld.value / (z_obj - z_E0) if not (infinite or math.isinf(z_E0)) else 0.0
    lagrange = n0 * (k * (nuc1 / n0) * ym1 - (num1 / n0) * k * yc1)
    if wl == lens.wavelength:
        z_gauss_ref = z_gauss
    else:  # an image solve is the reference wavelength's, whatever wavelength is traced
        z_gauss_ref = _gaussian_z(lens, od, z_last)
    return ParaxialResult(
        efl=efl,
        f_object=f_obj,
        f_image=f_img,
        bfl=bfl,
        ffl=ffl,
        z_F=z_F,
        z_Fp=z_Fp,
        z_H=z_H,
        z_Hp=z_Hp,
        z_N=z_N,
        z_Np=z_Np,
        z_E0=z_E0,
        z_E0p=z_E0p,
        epd=epd,
        xpd=xpd,
        pupil_magnification=xpd / epd,
        m_e=m_e,
        lagrange=lagrange,
        stop_radius=stop_radius,
        HE0=z_E0 - z_H,
        HpE0p=z_E0p - z_Hp,
        object_distance=od,
        z_object=z_obj,
        s=s,
        z_gauss=z_gauss,
        s_prime_gauss=z_gauss - z_Hp,
        gaussian_image_distance=z_gauss - z_last,
        m0=m0,
        p0=p0,
        working_fnumber=working_f,
        z_last=z_last,
        z_image_file=z_last + lens.surfaces[-1].thickness,
        n_object=n0,
        n_image=nk,
        wavelength=wl,
        chief_height_last=float(yck),
        chief_slope_image=float(uck),
        z_gauss_reference=float(z_gauss_ref),
    )
