"""Why distortion varies across image planes: the image-side chief-ray angle (telecentricity), the
exit pupil it implies, the exact slope ∂D0/∂s', and the entrance-pupil (viewpoint) shift with
field (docs/design.md, "Distortion definitions and pupils").

Per field, from one trace of the real chief rays (through the centre of the real stop):

- **Chief-ray angle** (CRA) ``α'`` of the final segment with the axis, degrees, signed like its
  direction cosine M (``atan2(M_last, N_last)``); an image-side telecentric lens has CRA = 0 at
  every field. The paraxial CRA scaled linearly to the field is ``atan(x·dK0/ds')``
  (``tan α / m_e`` at infinity).
- **Real exit pupil** implied by the final segment: where it crosses the axis,
  ``z_X = z_last − y_last·N_last/M_last`` (absolute z; ±inf when it is parallel to the axis),
  and its shift from the paraxial exit pupil E0'.
- **Slope** ``∂D0/∂s' = tan α' − x·dK0/ds'`` (mm of distortion per mm of plane shift;
  :func:`raytrace.paraxial.distortion_slope`, the one implementation): D0 is affine in s' for a
  fixed object, so ``D0(s'_2) = D0(s'_1) + (s'_2 − s'_1)·∂D0/∂s'`` exactly — the mechanism
  behind Pestrecov's Section V (Table V). It vanishes at every field only when the real chief
  rays leave parallel to their paraxial counterparts (no pupil aberration in image space).
- **Entrance pupil (viewpoint)**: where the object-space chief ray crosses the axis
  (``ChiefRays.entrance_pupil_z``), its shift from the paraxial E0, the height at which the
  chief ray crosses the plane of E0 (what paraxial ray aiming gets wrong), and the lateral
  viewpoint offset: the perpendicular distance from E0 to the object-space chief-ray line,
  ``(z_EP − z_E0)·sin θ`` (signed; θ the real object-space chief-ray angle) — zero at every
  field for a single-viewpoint (central) camera.

Units: mm, degrees; absolute z from the first vertex, light toward +z (docs/design.md,
"Conventions"). A field the lens cannot pass has a status code and NaN values.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from raytrace.lens import Lens
from raytrace.paraxial import ParaxialResult
from raytrace.trace.results import field_unit, object_words

from .curve import FieldKindMixin, fields_and_abscissa


@dataclass(frozen=True, eq=False)
class PupilAnalysis(FieldKindMixin):
    """Chief-ray angles, pupils and the distortion slope of one lens and object, per field.

    name: lens name; field_kind: ``"angle"``, ``"height"`` or ``"nominal-angle"``; fields (n,):
    as given (deg or mm); object_distance: mm from the first vertex (inf); wavelength: nm.
    x (n,): abscissa of orthoscopy (``tan α`` or the object height, mm).
    theta_object_deg (n,): real object-space chief-ray angle (deg).
    cra_deg (n,): image-side chief-ray angle α' (deg); cra_paraxial_deg (n,): the paraxial one,
    linear in x. exit_pupil_z (n,): real exit pupil (absolute z, mm; ±inf when telecentric);
    exit_pupil_shift (n,): it minus the paraxial E0' (mm; NaN when both are infinite).
    slope (n,): ∂D0/∂s' (mm/mm); constant_slope: dK0/ds' (``1/(m_e p0)`` in 1/mm for a finite
    object, ``1/m_e`` at infinity; :func:`raytrace.paraxial.orthoscopy_constant_slope`).
    entrance_pupil_z (n,): real entrance pupil (absolute z, mm); entrance_pupil_shift (n,): it
    minus the paraxial E0 (mm); height_at_E0 (n,): chief-ray height in the plane of E0 (mm);
    viewpoint_offset (n,): perpendicular distance from E0 to the object-space chief ray (mm,
    signed). status (n,): trace status. paraxial: the ParaxialResult used.
    """

    name: str
    field_kind: str
    fields: np.ndarray
    object_distance: float
    wavelength: float
    x: np.ndarray
    theta_object_deg: np.ndarray
    cra_deg: np.ndarray
    cra_paraxial_deg: np.ndarray
    exit_pupil_z: np.ndarray
    exit_pupil_shift: np.ndarray
    slope: np.ndarray
    constant_slope: float
    entrance_pupil_z: np.ndarray
    entrance_pupil_shift: np.ndarray
    height_at_E0: np.ndarray
    viewpoint_offset: np.ndarray
    status: np.ndarray
    paraxial: ParaxialResult

    @property
    def max_abs_cra_deg(self) -> float:
        """Largest |CRA| over the traced fields (deg): 0 for an image-side telecentric lens."""
        return _max_abs_finite(self.cra_deg)

    @property
    def max_abs_viewpoint_offset(self) -> float:
        """Largest |viewpoint offset| over the traced fields (mm)."""
        return _max_abs_finite(self.viewpoint_offset)

    def __repr__(self) -> str:
        unit, obj = field_unit(self.field_kind), object_words(self.object_distance)
        return (
            f"PupilAnalysis({self.name!r}, {self.fields.size} fields "
            f"{self.fields.min():g}..{self.fields.max():g} {unit}, object {obj}, "
            f"{self.wavelength:g} nm, max |CRA| = {self.max_abs_cra_deg:.6g} deg, "
            f"max |viewpoint offset| = {self.max_abs_viewpoint_offset:.6g} mm)"
        )


def _max_abs_finite(a: np.ndarray) -> float:
    """Largest |a| over the finite entries of ``a`` (NaN when there are none)."""
    v = a[np.isfinite(a)]
    return float(np.max(np.abs(v))) if v.size else math.nan


def pupil_analysis(
    lens: Lens,
    fields_deg: npt.ArrayLike | None = None,
    *,
    object_heights_mm: npt.ArrayLike | None = None,
    object_distance: float | str | None = None,
    object_s: float | None = None,
    object_scale: float | None = None,
    wavelength: float | str | None = None,
    clip: bool = True,
) -> PupilAnalysis:
    """Chief-ray angle, real exit and entrance pupils, viewpoint offset and ∂D0/∂s' per field
    (module docstring), from one trace of the real chief rays.

    Parameters
    ----------
    lens : Lens
    fields_deg, object_heights_mm
        Field angles α (deg; nominal angles ``y = p0 tan α`` with a finite object) or object
        heights (mm, finite object). Default: 11 fields from 0 to the lens's field.
    object_distance, object_s, object_scale
        The object plane (at most one), as in
        :func:`distortion.characteristic.characteristic_distortion`. Default: the lens file's.
    wavelength : float or str, optional
        nm; default the lens's reference wavelength (paraxial data at the same wavelength).
    clip : bool
        Apply the lens's semi-diameters to the chief rays.

    Returns
    -------
    PupilAnalysis
    """
    from raytrace.paraxial import (
        checked_wavelength,
        distortion_slope,
        orthoscopy_constant_slope,
        resolve_paraxial,
    )
    from raytrace.trace import aim

    wl = checked_wavelength(wavelength)
    par = resolve_paraxial(lens, object_distance, object_s, object_scale, wl)
    fk, f, kind, x = fields_and_abscissa(lens, par, fields_deg, object_heights_mm)
    cr = aim(lens, f, fk, par.object_distance, wl, clip)
    ok = cr.ok

    def only_ok(a: np.ndarray) -> np.ndarray:
        return np.where(ok, a, np.nan)

    ksl = orthoscopy_constant_slope(par.m_e, None if par.infinite else par.p0)
    with np.errstate(divide="ignore", invalid="ignore"):
        theta = np.degrees(np.arctan2(cr.M_start, cr.N_start))
        cra = cr.landing_angle_deg
        cra_par = np.degrees(np.arctan(ksl * x))
        z_x = np.where(
            cr.M_last != 0.0,
            cr.z_last - cr.y_last * cr.N_last / cr.M_last,
            np.copysign(np.inf, cr.y_last),
        )
        z_x = np.where(x == 0.0, par.z_E0p, z_x)  # axial ray: the paraxial limit
        x_shift = z_x - par.z_E0p
        zE = cr.entrance_pupil_z
        e_shift = zE - par.z_E0
        y_E0 = cr.y_start + (par.z_E0 - cr.z_start) * cr.M_start / cr.N_start
        offset = (zE - par.z_E0) * np.sin(np.radians(theta))
        offset = np.where(x == 0.0, 0.0, offset)
    return PupilAnalysis(
        name=lens.name,
        field_kind=kind,
        fields=f,
        object_distance=par.object_distance,
        wavelength=float(cr.wavelength),
        x=x,
        theta_object_deg=only_ok(theta),
        cra_deg=only_ok(cra),
        cra_paraxial_deg=cra_par,
        exit_pupil_z=only_ok(z_x),
        exit_pupil_shift=only_ok(x_shift),
        slope=only_ok(distortion_slope(par, x, cr.tan_out)),
        constant_slope=float(ksl),
        entrance_pupil_z=only_ok(zE),
        entrance_pupil_shift=only_ok(e_shift),
        height_at_E0=only_ok(y_E0),
        viewpoint_offset=only_ok(offset),
        status=cr.status.copy(),
        paraxial=par,
    )
