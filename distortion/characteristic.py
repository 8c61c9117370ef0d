"""Characteristic distortion of a traced lens in any image plane (Pestrecov 1958, Eqs. 8–9).

One trace of the real chief rays (``raytrace.trace.chief_rays``) serves any number of image
planes: the final segment is moved analytically to each plane. Image planes may be given as

- ``s_prime``: distance s' from the second principal point H' (Pestrecov's convention),
- ``from_last_vertex``: distance from the last vertex,
- ``defocus``: distance from the Gaussian image plane of the object (+ = away from the lens),
- or ``plane=`` :class:`~raytrace.paraxial.ImagePlane` objects (docs/design.md, "Vocabulary");

none of them = the Gaussian plane. Distances in mm; planes before the last vertex are refused.

Fields: angles α in degrees (object at infinity), object heights y in mm (finite conjugates) or,
for a finite object, nominal angles α standing for ``y = p0·tan α`` (``field_kind="angle"`` with a
finite object distance). For an object at infinity ``x = tan α``; for finite conjugates ``x = y``.

Reference definitions (``REFERENCES``), never mixed silently:

``characteristic`` (default; Pestrecov Eqs. 8–9)
    ``y0' = K0·x`` with the paraxial constants of orthoscopy IN THE ACTUAL PLANE:
    ``M0 = p0'/(m_e p0)``, ``F0 = p0'/m_e``. ``D0 = y' − y0'``, ``Dr = D0/y0'``.

``distortion-focal-length``
    ``y0' = K_dfl·x`` with the scale ``K_dfl = y'(ε)/x(ε)`` of a near-axis real chief ray at the
    evaluation plane (what several commercial and open tools report). It is evaluated at
    ε and 2ε (ε = ``1e-3 ×`` the largest |field|) and Richardson-extrapolated to ε → 0
    (``K = (4K(ε) − K(2ε))/3``; the ε² distortion term cancels). Because Pestrecov derives
    Eq. (8) as exactly this limit, ``K_dfl`` equals M0/F0 in every plane up to the O(ε⁴) and
    round-off residue: the two definitions differ only by that residue (a cross-check of the
    paraxial constants against the real tracer, Gaussian plane or not).

``real-chief-transport``
    The Gaussian-plane ideal point carried along the real chief ray to the actual plane:
    reference height ``y_ref = y'_par,G + Δz·tan u'_real`` with ``y'_par,G = m0·y`` (or ``f tan α``)
    and ``Δz`` the defocus, so the linear distortion ``y' − y_ref = y'_real,G − y'_par,G`` is that
    of the Gaussian plane in every plane, and
    ``Dr = (y'_real,G − y'_par,G)/(y'_par,G + Δz·tan u'_real)``.
    It agrees with ``characteristic`` only in the Gaussian plane.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from raytrace.errors import TraceError
from raytrace.lens import Lens
from raytrace.paraxial import (
    ImagePlane,
    ParaxialResult,
    orthoscopy_abscissa,
    pestrecov_constants,
)

from .curve import ANGLE, HEIGHT, NOMINAL_ANGLE, DistortionCurve

REFERENCES = ("characteristic", "distortion-focal-length", "real-chief-transport")
DFL_EPSILON = 1e-3  # near-axis reference field as a fraction of the largest |field|


@dataclass(frozen=True, eq=False)
class CharacteristicDistortion:
    """Distortion of one lens and object distance in several image planes (arrays: planes × fields).

    name: lens name; reference: one of ``REFERENCES``; field_kind: ``"angle"``, ``"height"`` or
    ``"nominal-angle"``; fields (n,): as given (deg or mm); object_distance: positive magnitude
    from the object plane to the first vertex (``inf`` for infinity).
    x (n,): ``tan α`` or the object height y (mm); y (n,): object heights (mm; NaN at infinity).
    z_planes, s_prime, from_last_vertex, defocus (p,): the planes as absolute z, from H', from the
    last vertex and from the Gaussian plane (mm). constant (p,): K0 of Eq. (8) in each plane
    (F0 in mm or M0); scale (p,): the reference's linear scale (= K0 for ``characteristic``).
    gaussian_constant: f or m0.  y0p, yp, D0 (p, n) in mm; Dr (p, n) a fraction (0 on the axis).
    status (n,): trace status per field (``raytrace.trace.STATUS_*``); NaN values where not OK.
    paraxial: the ``ParaxialResult`` used.
    """

    name: str
    reference: str
    field_kind: str
    fields: np.ndarray
    object_distance: float
    x: np.ndarray
    y: np.ndarray
    z_planes: np.ndarray
    s_prime: np.ndarray
    from_last_vertex: np.ndarray
    defocus: np.ndarray
    constant: np.ndarray
    scale: np.ndarray
    gaussian_constant: float
    y0p: np.ndarray
    yp: np.ndarray
    D0: np.ndarray
    Dr: np.ndarray
    status: np.ndarray
    paraxial: ParaxialResult

    @property
    def finite(self) -> bool:
        return self.field_kind != ANGLE

    @property
    def symbol(self) -> str:
        return "M" if self.finite else "F"

    @property
    def n_planes(self) -> int:
        return int(self.z_planes.size)

    def plane_label(self, i: int) -> str:
        d = self.defocus[i]
        g = (
            "Gaussian plane"
            if abs(d) <= 1e-9 * max(1.0, abs(self.s_prime[i]))
            else f"defocus {d:+.4f} mm"
        )
        return f"s' = {self.s_prime[i]:.4f} mm ({g})"

    def __repr__(self) -> str:
        unit = "mm" if self.field_kind == HEIGHT else "deg"
        obj = "inf" if math.isinf(self.object_distance) else f"{self.object_distance:g} mm"
        planes = ", ".join(f"{v:.4g}" for v in self.s_prime[:4]) + (
            ", ..." if self.n_planes > 4 else ""
        )
        with np.errstate(invalid="ignore"):
            worst = float(np.nanmax(np.abs(self.D0))) if np.isfinite(self.D0).any() else math.nan
        bad = int(np.count_nonzero(self.status != 0))
        return (
            f"CharacteristicDistortion({self.name!r}, {self.fields.size} fields "
            f"{self.fields.min():g}..{self.fields.max():g} {unit}, object {obj}, "
            f"s' = [{planes}] mm, max |D0| = {worst:.6g} mm, reference {self.reference}"
            + (f", {bad} fields failed" if bad else "")
            + ")"
        )

    def curve(self, i: int = 0) -> DistortionCurve:
        """Plane ``i`` as a :class:`DistortionCurve` (fields with status != OK dropped) for
        calibration, tables and plots. Its constant is K0 of Eq. (8) in that plane."""
        ok = np.isfinite(self.yp[i])
        return DistortionCurve(
            fields=self.fields[ok],
            field_kind=self.field_kind,
            x=self.x[ok],
            y0p=self.y0p[i][ok],
            D0=self.D0[i][ok],
            constant=float(self.constant[i]),
            name=self.name,
            plane=self.plane_label(i),
            source=f"traced; reference {self.reference}",
            decimals=4,
        )


def characteristic_distortion(
    lens: Lens,
    fields_deg: npt.ArrayLike | None = None,
    *,
    object_heights_mm: npt.ArrayLike | None = None,
    plane: ImagePlane | Sequence[ImagePlane] | str | None = None,
    s_prime: npt.ArrayLike | None = None,
    from_last_vertex: npt.ArrayLike | None = None,
    defocus: npt.ArrayLike | None = None,
    object_distance: float | str | None = None,
    object_s: float | None = None,
    object_scale: float | None = None,
    reference: str = "characteristic",
    wavelength: float | None = None,
    clip: bool = True,
) -> CharacteristicDistortion:
    """Distortion of ``lens`` at the given fields in one or more image planes (Pestrecov 1958,
    Eqs. 8–9; the module docstring defines the three references).

    Parameters
    ----------
    lens : Lens
    fields_deg : array_like, optional
        Field angles α in degrees (object-space chief-ray slope angle). With a finite object they
        are Pestrecov's nominal angles: object heights ``y = p0 tan α``. Default: 11 fields from
        0 to the lens's field.
    object_heights_mm : array_like, optional
        Object heights in mm instead of angles (finite objects only).
    plane : ImagePlane, list of ImagePlane, "gaussian" or "file", optional
        The image plane(s); or give ONE of ``s_prime`` (mm from H'), ``from_last_vertex`` (mm
        from the last vertex), ``defocus`` (mm from the Gaussian plane, + away from the lens),
        each a number or a sequence. Default: the Gaussian image plane of the object. All
        planes come from one trace.
    object_distance, object_s, object_scale
        The object plane (at most one): mm from the first vertex (or ``inf`` / ``"12x"``),
        Pestrecov's signed s from H (mm, negative), or an image scale N ("N×", magnification
        −1/N). Default: the lens file's object.
    reference : {"characteristic", "distortion-focal-length", "real-chief-transport"}
        The reference the ideal image is measured from (module docstring).
    wavelength : float, optional
        nm; default the lens's.
    clip : bool
        Apply the lens's semi-diameters to the chief rays.

    Returns
    -------
    CharacteristicDistortion
        Arrays (planes × fields) of y0', y', D0 (mm) and Dr (fraction); a field the lens cannot
        pass has a status code and NaN values.

    Raises
    ------
    TraceError, LensError
        For impossible requests (a plane before the last vertex, heights with an object at
        infinity, an unknown reference, ...).
    """
    from raytrace.paraxial import ideal_heights, image_planes, paraxial, plane_z
    from raytrace.paraxial import resolve_object_distance
    from raytrace.trace import STATUS_OK, aim

    if reference not in REFERENCES:
        raise TraceError(
            f"unknown distortion reference {reference!r}; expected one of {', '.join(REFERENCES)}"
        )
    od = resolve_object_distance(
        lens,
        object_distance=object_distance,
        object_s=object_s,
        object_scale=object_scale,
        wavelength=wavelength,
    )
    par = paraxial(lens, object_distance=od, wavelength=wavelength)
    if fields_deg is not None and object_heights_mm is not None:
        raise TraceError("give fields_deg or object_heights_mm, not both")
    if object_heights_mm is not None:
        fk = "height"
        f = np.atleast_1d(np.asarray(object_heights_mm, dtype=float)).ravel()
    elif fields_deg is not None:
        fk = "angle"
        f = np.atleast_1d(np.asarray(fields_deg, dtype=float)).ravel()
    else:
        fk = lens.field.kind if not (par.infinite and lens.field.kind == "height") else "angle"
        f = np.linspace(0.0, lens.field.value, 11)
    if f.size == 0:
        raise TraceError("no fields given")
    infinite = par.infinite
    if fk == "height" and infinite:
        raise TraceError("object heights need a finite object distance")
    kind = ANGLE if infinite else (HEIGHT if fk == "height" else NOMINAL_ANGLE)
    x = orthoscopy_abscissa(par, f, fk)
    yobj = np.full(f.shape, np.nan) if kind == ANGLE else x
    planes = image_planes(plane, s_prime=s_prime, from_last_vertex=from_last_vertex, defocus=defocus)
    z = plane_z(par, planes)
    sp = np.asarray(par.s_prime_of(z), dtype=float)
    K0 = np.array([pestrecov_constants(par, float(v)).scale for v in sp])
    KG = par.efl if infinite else par.m0

    extra = np.empty(0)
    if reference == "distortion-focal-length":
        fmax = float(np.max(np.abs(f)))
        eps = DFL_EPSILON * (fmax if fmax > 0 else 1.0)
        extra = np.array([eps, 2.0 * eps])
    cr = aim(lens, np.concatenate([f, extra]), fk, par.object_distance, wavelength, clip)
    n = f.size
    status = cr.status[:n].copy()
    ok = status == STATUS_OK
    H = np.atleast_2d(cr.heights_at(z))  # (p, n + extra)
    yp = np.where(ok[None, :], H[:, :n], np.nan)

    if reference == "characteristic":
        scale = K0.copy()
        y0p = ideal_heights(par, x, sp)
    elif reference == "distortion-focal-length":
        if not np.all(cr.status[n:] == STATUS_OK):
            raise TraceError(
                "the near-axis reference chief ray for the distortion focal length failed"
            )
        xe = orthoscopy_abscissa(par, extra, fk)
        k1 = H[:, n] / xe[0]
        k2 = H[:, n + 1] / xe[1]
        scale = (4.0 * k1 - k2) / 3.0
        y0p = scale[:, None] * x[None, :]
    else:  # real-chief-transport
        dz = z - par.z_gauss
        tan_u = cr.tan_out[:n]
        y0p = KG * x[None, :] + dz[:, None] * tan_u[None, :]
        scale = KG + dz / par.m_e if infinite else KG + dz / (par.m_e * par.p0)
    D0 = yp - y0p
    with np.errstate(divide="ignore", invalid="ignore"):
        Dr = np.where(x[None, :] != 0.0, D0 / np.where(y0p != 0.0, y0p, 1.0), 0.0)
    Dr = np.where(np.isfinite(yp), Dr, np.nan)
    return CharacteristicDistortion(
        name=lens.name,
        reference=reference,
        field_kind=kind,
        fields=f,
        object_distance=par.object_distance,
        x=x,
        y=yobj,
        z_planes=z,
        s_prime=sp,
        from_last_vertex=z - par.z_last,
        defocus=z - par.z_gauss,
        constant=K0,
        scale=np.asarray(scale, dtype=float),
        gaussian_constant=float(KG),
        y0p=y0p,
        yp=yp,
        D0=D0,
        Dr=Dr,
        status=status,
        paraxial=par,
    )
