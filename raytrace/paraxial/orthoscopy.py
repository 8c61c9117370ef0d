"""Pestrecov's paraxial constants of orthoscopy (Eqs. 1, 5, 7, 8) — the one implementation.

K. Pestrecov, *Radial Distortion: Its Calibration, Computation in Non-Gaussian Image Planes, and
Compensation*, Photogrammetric Engineering (1958), Sections II–III.

Signs follow Pestrecov's Fig. 1 (docs/design.md, "Conventions"): distances are measured from the
reference point, negative to the left (object side) and positive to the right. ``s`` (object
plane from the first nodal point H) is negative for a real object, ``s'`` (actual image plane from
the second nodal point H') is positive, ``HE0`` / ``H'E0'`` are the paraxial entrance / exit
pupil positions measured from H / H'. All lengths are in millimetres; magnifications are
dimensionless.

The functions of numbers check a paper's tables without a lens (Table III → Table IV);
:func:`pestrecov_constants`, :func:`orthoscopy_abscissa` and :func:`ideal_heights` apply the same
equations to the :class:`~raytrace.paraxial.firstorder.ParaxialResult` of a prescription — the
reference image size ``y0' = K0·x`` that characteristic distortion ``D0 = y' − y0'`` (Eq. 9) is
measured from, wherever it is computed (distortion module, optimizer operands).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from .firstorder import ParaxialResult


def gaussian_magnification(f: float, s: float) -> float:
    """Paraxial lateral magnification in the Gaussian image plane, Eq. (5): ``m0 = f / (f + s)``.

    ``f`` is the equivalent focal length, ``s`` the (negative) object distance from H.
    """
    if f + s == 0.0:
        raise ValueError("object in the front focal plane (f + s = 0): the image is at infinity")
    return f / (f + s)


def gaussian_image_distance(f: float, s: float) -> float:
    """Gaussian image distance from H', Eq. (1): ``1/s' − 1/s = 1/f`` → ``s' = f s / (f + s)``.

    ``s = -inf`` (object at infinity) gives ``s' = f``.
    """
    if math.isinf(s):
        return f
    return gaussian_magnification(f, s) * s


def object_distance_for_magnification(f: float, m0: float) -> float:
    """Inverse of Eq. (5): the object distance ``s = f / m0 − f`` for Gaussian magnification m0."""
    if m0 == 0.0:
        raise ValueError("magnification 0 means an object at infinity")
    return f / m0 - f


def pupil_distances(s: float, s_prime: float, HE0: float, HpE0p: float) -> tuple[float, float]:
    """Object and image distances from the paraxial pupils (Fig. 1):
    ``p0 = s − HE0`` and ``p0' = s' − H'E0'``.
    """
    return s - HE0, s_prime - HpE0p


def exit_pupil_to_gaussian_image(
    m_e: float, *, f: float | None = None, m0: float | None = None, p0: float | None = None
) -> float:
    """Distance of the Gaussian image plane from the paraxial exit pupil, Eq. (7).

    ``P0g' = m_e m0 p0`` for finite conjugates (give ``m0`` and ``p0``), ``P0g' = m_e f`` for an
    object at infinity (give ``f``).
    """
    if m0 is not None and p0 is not None:
        return m_e * m0 * p0
    if f is not None:
        return m_e * f
    raise ValueError("give m0 and p0 (finite conjugates) or f (object at infinity)")


def orthoscopy_constant_finite(
    p0p: float | np.ndarray, m_e: float, p0: float
) -> float | np.ndarray:
    """Constant of orthoscopy in ANY image plane, finite conjugates, Eq. (8):
    ``M0 = p0' / (m_e p0)``."""
    if p0 == 0.0 or m_e == 0.0:
        raise ValueError("p0 and m_e must be nonzero (object plane in the entrance pupil?)")
    return p0p / (m_e * p0)


def orthoscopy_constant_infinite(p0p: float | np.ndarray, m_e: float) -> float | np.ndarray:
    """Constant of orthoscopy in ANY image plane, object at infinity, Eq. (8):
    ``F0 = p0' / m_e``."""
    if m_e == 0.0:
        raise ValueError("m_e must be nonzero")
    return p0p / m_e


def object_distance_for_plane_magnification(
    M0: float, s_prime: float, m_e: float, HE0: float, HpE0p: float
) -> float:
    """Inverse of Eq. (8): the object distance ``s`` (from H) for which the constant of orthoscopy
    in the image plane at ``s'`` equals ``M0``: ``p0 = p0' / (m_e M0)``, ``s = p0 + HE0``.

    This is how Pestrecov's Section V sets the projector: the magnification −9.545455 (= −525/55)
    is required at the nominal projection distance s' = 525 mm.
    """
    if M0 == 0.0:
        raise ValueError("M0 must be nonzero")
    p0p = s_prime - HpE0p
    return p0p / (m_e * M0) + HE0


@dataclass(frozen=True)
class PlaneConstants:
    """Pestrecov's setting data for one image plane (one row of Table IV).

    s, s_prime: object plane from H (negative; ``-inf`` for an object at infinity) and actual image
        plane from H' (mm).
    p0, p0p: the same distances from the paraxial entrance / exit pupils E0, E0' (mm); ``p0`` is
        ``-inf`` for an object at infinity.
    constant: M0 (finite conjugates) or F0 (mm, object at infinity), Eq. (8).
    gaussian_s_prime: s' of the Gaussian image plane, Eq. (1).
    gaussian_constant: m0 (Eq. 5) or f, the value ``constant`` takes in the Gaussian plane.
    """

    s: float
    s_prime: float
    p0: float
    p0p: float
    constant: float
    gaussian_s_prime: float
    gaussian_constant: float

    @property
    def finite(self) -> bool:
        return not math.isinf(self.s)

    @property
    def symbol(self) -> str:
        return "M0" if self.finite else "F0"

    @property
    def defocus(self) -> float:
        """Actual plane minus Gaussian plane along the axis, ``s' − s'_g`` (mm)."""
        return self.s_prime - self.gaussian_s_prime


def plane_constants(
    f: float, m_e: float, HE0: float, HpE0p: float, s: float, s_prime: float | None = None
) -> PlaneConstants:
    """Setting data of one image plane from the basic paraxial parameters (Table III → Table IV).

    ``s_prime=None`` selects the Gaussian plane of the object (Eq. 1). ``s = -inf`` is an object at
    infinity (then the constant is F0 and ``p0 = -inf``).
    """
    gs = gaussian_image_distance(f, s)
    sp = gs if s_prime is None else s_prime
    if math.isinf(s):
        p0p = sp - HpE0p
        return PlaneConstants(s, sp, -math.inf, p0p, orthoscopy_constant_infinite(p0p, m_e), gs, f)
    p0, p0p = pupil_distances(s, sp, HE0, HpE0p)
    return PlaneConstants(
        s,
        sp,
        p0,
        p0p,
        orthoscopy_constant_finite(p0p, m_e, p0),
        gs,
        gaussian_magnification(f, s),
    )


# --------------------------------------------------------------------------------------------
# The same equations applied to a traced prescription
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class PestrecovConstants:
    """Pestrecov's constants of orthoscopy in one image plane (Eq. 8).

    s_prime: image plane from H' (mm); p0, p0p: object / image plane from the paraxial pupils
    E0, E0' (mm); scale: M0 (finite conjugates, dimensionless) or F0 (object at infinity, mm);
    infinite: which of the two ``scale`` is.
    """

    s_prime: float
    p0: float
    p0p: float
    scale: float
    infinite: bool


def pestrecov_constants(par: ParaxialResult, s_prime: float | str) -> PestrecovConstants:
    """Pestrecov Eq. (8) in the image plane at ``s_prime`` (mm from H') of a traced lens.

    ``p0 = s − HE0``, ``p0' = s' − H'E0'``; ``M0 = p0' / (m_e p0)`` (finite conjugates) or
    ``F0 = p0' / m_e`` (object at infinity). In the Gaussian plane M0 = m0 and F0 = f (Eq. 7).

    For an image-space telecentric lens (exit pupil at infinity, m_e = ∞) Eq. (8) is the limit
    ∞/∞; its value is the height of the paraxial chief ray in the plane per unit abscissa, which
    is the same in every plane: F0 = y_c (the chief ray of tan α = 1 at the last vertex), or
    M0 = y_c / p0.

    Parameters
    ----------
    par : ParaxialResult
        :func:`raytrace.paraxial.paraxial` of the lens and its object (m_e of Eq. 6, the pupils
        E0, E0', p0 in mm, negative for a finite object).
    s_prime : float or str
        The image plane, mm from the second principal point H' (positive toward the image), or a
        string with a length unit as the command line takes it (``"50.5mm"``;
        :class:`~raytrace.paraxial.ImagePlane`; TraceError naming ``s_prime``).

    Returns
    -------
    PestrecovConstants
        ``s_prime``, ``p0`` and ``p0p`` (mm, object and image plane from E0 and E0'),
        ``scale`` = M0 (finite conjugates, dimensionless, signed) or F0 (object at infinity, mm)
        and ``infinite``.
    """
    from .conjugates import ImagePlane  # (conjugates imports this module)

    sp = ImagePlane("s_prime", s_prime).value  # the one reading of an image-plane distance
    return PestrecovConstants(sp, par.p0, sp - par.HpE0p, float(_scale(par, sp)), par.infinite)


def _scale(par: ParaxialResult, s_prime):
    """K0 of Eq. (8) in the plane(s) ``s_prime`` (mm from H'; a float or an array, elementwise):
    the one implementation behind :func:`pestrecov_constants` and :func:`orthoscopy_constants`,
    with the image-telecentric limit of :func:`pestrecov_constants`."""
    p0p = s_prime - par.HpE0p
    if math.isinf(par.m_e) and math.isfinite(par.chief_height_last):
        z = s_prime + par.z_Hp
        h = par.chief_height_last + (z - par.z_last) * par.chief_slope_image
        return h if par.infinite else h / par.p0
    if par.infinite:
        return orthoscopy_constant_infinite(p0p, par.m_e)
    return orthoscopy_constant_finite(p0p, par.m_e, par.p0)


def orthoscopy_abscissa(par: ParaxialResult, fields, field_kind: str) -> np.ndarray:
    """The abscissa of orthoscopy ``x`` that the constant K0 multiplies (Eqs. 8–9).

    field_kind ``"angle"`` with an object at infinity: ``x = tan α`` (α in degrees);
    ``"height"``: the object height ``x = y`` (mm); ``"angle"`` with a finite object: Pestrecov's
    nominal angle, ``x = y = p0 tan α`` (mm, p0 < 0 for a real object: a positive nominal angle is
    a negative object height, which images to a positive height).
    """
    f = np.asarray(fields, dtype=float)
    if field_kind == "height":
        if par.infinite:
            raise ValueError("object heights need a finite object distance")
        return f.copy()
    if field_kind != "angle":
        raise ValueError(f"unknown field kind {field_kind!r}")
    return np.tan(np.radians(f)) if par.infinite else nominal_heights(par.p0, f)


def nominal_heights(p0: float, fields_deg) -> np.ndarray:
    """Pestrecov's nominal angles α (degrees) as object heights ``y = p0 tan α`` (mm; §3), with
    ``p0 = z_object − z_E0`` (mm, < 0 for a real object left of the paraxial entrance pupil E0):
    the one conversion (:func:`orthoscopy_abscissa`, the chief-ray aims of
    :mod:`raytrace.trace`)."""
    return p0 * np.tan(np.radians(fields_deg))


def orthoscopy_constants(par: ParaxialResult, s_prime) -> np.ndarray:
    """Pestrecov's constant of orthoscopy K0 (Eq. 8: F0 in mm for an object at infinity, M0 for
    a finite one; :attr:`PestrecovConstants.scale`) in each plane at ``s_prime`` (mm from H'):
    (planes,), the planes flattened."""
    sp = np.asarray(s_prime, dtype=float)
    return np.asarray(_scale(par, sp.ravel()), dtype=float)


def ideal_heights(par: ParaxialResult, x, s_prime) -> np.ndarray:
    """Ideal (orthoscopic) image sizes ``y0' = K0·x`` (mm), Eq. (8)–(9), in the plane(s) at
    ``s_prime`` (mm from H'): shape ``x.shape`` for a scalar plane, (planes, fields) otherwise."""
    xa = np.asarray(x, dtype=float)
    sp = np.asarray(s_prime, dtype=float)
    k = orthoscopy_constants(par, sp)
    if sp.ndim == 0:
        return k[0] * xa
    return k[:, None] * xa.reshape(1, -1)


def paraxial_chief_heights(
    par: ParaxialResult, fields, field_kind: str, z_image: float
) -> np.ndarray:
    """Paraxial chief-ray image heights (mm) at the absolute plane ``z_image``.

    For angle fields ``tan α`` is the object-space chief-ray slope; for height fields the chief
    ray leaves the object point toward E0. Heights follow the linearity y' = (z − z_E0')·tan α'
    with ``tan α' = tan α / m_e`` (Eqs. 4, 6).
    """
    f = np.asarray(fields, dtype=float)
    if field_kind == "angle":
        tan_a = np.tan(np.radians(f))
    elif field_kind == "height":
        tan_a = f / par.p0
    else:
        raise ValueError(f"unknown field kind {field_kind!r}")
    return (z_image - par.z_E0p) * tan_a / par.m_e


# --------------------------------------------------------------------------------------------
# How the distortion changes from plane to plane (Section V): the one implementation
# --------------------------------------------------------------------------------------------


def orthoscopy_constant_slope(m_e: float, p0: float | None = None) -> float:
    """Derivative of the constant of orthoscopy (Eq. 8) with respect to the image plane s':
    ``dM0/ds' = 1/(m_e p0)`` (finite conjugates, give ``p0``) or ``dF0/ds' = 1/m_e`` (object at
    infinity, ``p0=None`` or ``-inf``). Eq. (8) is affine in s' (``p0' = s' − H'E0'``), so this
    is exact. An image-side telecentric lens (``m_e = inf``) gives 0: its scale is the same in
    every plane. Units: 1/mm (finite) or dimensionless (infinity)."""
    if m_e == 0.0:
        raise ValueError("m_e must be nonzero")
    if p0 is None or math.isinf(p0):
        return 1.0 / m_e
    if p0 == 0.0:
        raise ValueError("p0 must be nonzero (object plane in the entrance pupil?)")
    return 1.0 / (m_e * p0)


def distortion_slope(par: ParaxialResult, x, tan_out) -> np.ndarray:
    """Exact rate of change of the characteristic distortion with the image plane,
    ``∂D0/∂s' = tan α'_real − x·dK0/ds'`` (mm per mm of s', dimensionless), per field.

    For a fixed object the real chief ray's final segment is straight, so ``y'(s')`` is affine
    with slope ``tan α'_real = M_last/N_last`` (``tan_out``); the ideal height ``y0' = K0(s')·x``
    is affine too, with ``dK0/ds'`` from :func:`orthoscopy_constant_slope`. Hence
    ``D0(s'_2) − D0(s'_1) = (s'_2 − s'_1)·∂D0/∂s'`` exactly, for any two planes (Pestrecov
    Section V, Table V). ``x`` is the abscissa of orthoscopy (:func:`orthoscopy_abscissa`).
    ``x·dK0/ds'`` is the image-side slope of the paraxial chief ray scaled linearly to the field
    (``tan α/m_e``), so the slope is the real minus the paraxial image-side chief-ray slope.
    """
    k = orthoscopy_constant_slope(par.m_e, None if par.infinite else par.p0)
    return np.asarray(tan_out, dtype=float) - k * np.asarray(x, dtype=float)
