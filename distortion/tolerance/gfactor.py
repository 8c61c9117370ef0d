"""Fraser & Shortis's variation factor g_ss' of every perturbed instance (issue: "the spread of
the variation factor g_ss' over a production batch").

Definition (Fraser & Shortis 1992, Eq. 6; estimated exactly as :mod:`distortion.variation`
estimates it from traced profiles)::

    δr_ss' = δr_s + g_ss' (δr_s' − δr_s)

* ``s`` is the run's object distance: each instance is focused on it by its compensator
  (:mod:`.compensators`), giving its image plane ``z_s``;
* ``s'`` is ``g_object_distance`` (mm from the object plane to the first vertex, or ``inf``);
* ``δr_s``: the object at s in the plane z_s; ``δr_ss'``: the object at s' in the same plane
  z_s — the lens focused at s, the sensor fixed (Pestrecov's non-Gaussian plane, the paper's
  "object distance s' for the lens focused at distance s"); ``δr_s'``: the object at s' with the
  lens focused at s', in the plane ``z_s'`` the same compensator chooses for an object at s':
  ``"paraxial-refocus"`` — the instance's paraxial image of s' (the Gaussian plane of s', the
  unit focusing of :mod:`distortion.variation.traced`); ``"best-focus"`` — the least-RMS plane
  of the axial bundle from s'; ``"fixed-sensor"`` — nothing of the instance is adjusted, the
  focusing mechanism racks the lens by the *nominal* lens's extension from s to s':
  ``z_s' = z_s + (z_G,nom(s') − z_G,nom(s))`` (its Gaussian planes).

Each profile is the radial distortion along +y at the run's curve fields α (nominal angles;
object heights ``p0 tan α`` for a finite object, as everywhere): ``r = y' − y'(α = 0)`` (mm,
measured from the image of the axial object point of that object distance, so that the boresight
shift of a decentered instance does not enter g) and ``δr = r − K0 tan α`` (µm; K0 of Pestrecov's
Eq. 8 for that object in that plane: the characteristic distortion of
:mod:`distortion.variation.traced`). For a centred lens ``y'(0) = 0`` and these are exactly the
profiles :func:`distortion.variation.trace_variation` traces. As there, the three profiles are
interpolated (not-a-knot cubic spline of δr against r) onto one grid of ``n_r`` radii from
``r_hi/n_r`` to ``r_hi``, the smallest largest radius of the three, and g is
:func:`distortion.variation.analysis.estimate_g` of them (least squares through the origin,
radii with ``|δr_s' − δr_s| < threshold_um`` excluded; NaN where fewer than two radii remain —
"undetermined"). g is dimensionless.

Cost: the three chief-ray curves at s' and s share one extra kernel launch (the aim at s'); the
spline and the fit run per instance in Python (about 0.3 ms each), so g is computed only when
asked for.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from raytrace.errors import OrthoscopeError
from raytrace.lens import Lens
from raytrace.paraxial import paraxial, resolve_object_distance
from raytrace.tolerance import (
    InstanceArrays,
    NominalAim,
    ToleranceSpec,
    ToleranceSpecError,
    aim_instances,
    nominal_aim,
    paraxial_batch,
)
from raytrace.units import UnitError, length_mm

from ..errors import DataError
from ..variation.analysis import estimate_g
from ..variation.models import WEAK_THRESHOLD_UM
from ..variation.traced import DEFAULT_N_R, leading_run, resample_spline
from .compensators import image_planes, pupil_bundle

#: what g is, in one line (summary JSON, reports)
DEFINITION = (
    "Fraser & Shortis 1992 Eq. 6, dr_ss' = dr_s + g (dr_s' - dr_s): s = the run's object "
    "distance (lens focused there by its compensator), s' = g_object_distance; dr_ss' = object "
    "at s' in the plane of s (sensor fixed); profiles along +y, r from the image of the axial "
    "object point, characteristic distortion (Pestrecov Eq. 8-9); g estimated as "
    "distortion.variation.analysis.estimate_g on a common grid of radii"
)


@dataclass(frozen=True, eq=False)
class GSetup:
    """What the g of every instance needs besides the run's own setup (picklable).

    object_distance : s', mm from the object plane to the first vertex (inf allowed).
    object_per_t : the nominal lens's p0 at s' (object height per unit tan α), None at infinity.
    aim : the nominal chief rays at s' of the curve fields (0, α).
    bundle : (6, R) axial rays from s' (best-focus compensator), else None.
    extension : z_G,nom(s') − z_G,nom(s), mm (the nominal lens's focusing travel; fixed sensor).
    n_r, threshold_um, method : the common grid and the estimation of
        :func:`distortion.variation.analysis.estimate_g`.
    """

    object_distance: float
    object_per_t: float | None
    aim: NominalAim
    bundle: np.ndarray | None
    extension: float
    n_r: int
    threshold_um: float
    method: str


def resolve_g_distance(lens: Lens, value, wavelength: float, where: str) -> float:
    """s' in mm from the first vertex from ``value``: a number (mm), ``"inf"``, a length with a
    unit (``"2m"``) or an image scale (``"10x"``: Gaussian magnification −1/10). Raises
    :class:`ToleranceSpecError` naming ``where``."""
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        raise ToleranceSpecError(
            f"{where}: {value!r} is not a distance; give mm from the object plane to the first "
            "vertex, a length such as '2m', 'inf' or an image scale such as '10x'"
        )
    try:
        if isinstance(value, str):
            t = value.strip().lower()
            if t.endswith(("x", "×")) or t in ("inf", "infinity"):
                return float(resolve_object_distance(lens, object_distance=t,
                                                     wavelength=wavelength))  # fmt: skip
            return length_mm(t, where, allow_inf=True, positive=True)
    except UnitError as e:
        raise ToleranceSpecError(str(e)) from None
    except OrthoscopeError as e:
        raise ToleranceSpecError(f"{where}: {e}") from None
    v = float(value)
    if not v > 0:
        raise ToleranceSpecError(f"{where}: {value!r} must be a positive distance (mm) or inf")
    return v


def prepare_g(
    lens: Lens,
    spec: ToleranceSpec,
    fields_deg: np.ndarray,
    object_distance: float,
    g_object_distance: float,
    wavelength: float,
    *,
    n_r: int = DEFAULT_N_R,
    threshold_um: float = WEAK_THRESHOLD_UM,
    method: str = "lsq",
) -> GSetup:
    """The :class:`GSetup` for the object plane ``g_object_distance`` (mm; module docstring).
    Raises DataError when g cannot be defined: the curve must start at α = 0 and have at least
    4 fields, s' must differ from s and both must have a real image."""
    od2 = float(g_object_distance)
    if not (od2 > 0):
        raise DataError(f"g_object_distance {od2!r}: give a positive distance (mm) or inf")
    if od2 == object_distance:
        where = "infinity" if math.isinf(od2) else f"{od2:g} mm"
        raise DataError(
            f"g_object_distance {where} is the run's object distance: g_ss' needs an object "
            "plane s' other than the focus s"
        )
    fd = np.asarray(fields_deg, dtype=float)
    if fd.size < 4 or fd[0] != 0.0 or not np.all(np.diff(fd) > 0):
        raise DataError(
            "g_ss' needs the curve fields to start at 0 deg and increase (at least 4 fields); "
            "give fields_deg such as linspace(0, max, 50)"
        )
    if n_r < 2:
        raise DataError(f"g needs at least 2 common radii, got n_r = {n_r}")
    nom = lens.nominal()
    par_s = paraxial(nom, object_distance, wavelength)
    par2 = paraxial(nom, od2, wavelength)
    for p, what in ((par_s, "s (the run's object)"), (par2, "s' (g_object_distance)")):
        if not (math.isfinite(p.z_gauss) and p.z_gauss > p.z_last):
            raise DataError(
                f"{lens.name}: the object distance {p.object_distance:g} mm of {what} has no "
                "real image behind the lens; choose an object farther than the focal length"
            )
    aim = nominal_aim(lens, spec, np.zeros_like(fd), fd, object_distance=od2,
                      wavelength=wavelength)  # fmt: skip
    bundle = None
    if spec.compensator.type == "best-focus":
        bundle = pupil_bundle(par2, od2, spec.compensator.rings)
    p0 = None if math.isinf(od2) else float(par2.p0)
    ext = float(par2.z_gauss - par_s.z_gauss)
    return GSetup(od2, p0, aim, bundle, ext, int(n_r), float(threshold_um), str(method))


def _profile(y: np.ndarray, k0: np.ndarray, tan_a: np.ndarray):
    """(r, δr) of curves y' (I, F) mm with constants K0 (I,): r = y' − y'(0) mm, δr µm."""
    r = y - y[:, :1]
    return r, (r - k0[:, None] * tan_a[None, :]) * 1e3


def g_of_profiles(profiles, n_r: int, threshold_um: float, method: str) -> float:
    """g of one instance from its three profiles ``[(r_s, δr_s), (r_s', δr_s'), (r_ss',
    δr_ss')]`` (module docstring); NaN when a profile has fewer than 4 traced fields, is not
    increasing in r, or g is undetermined."""
    prof = [leading_run(np.asarray(r), np.asarray(d)) for r, d in profiles]
    if any(r.size < 4 or not np.all(np.diff(r) > 0) for r, _ in prof):
        return math.nan
    r_hi = min(float(r[-1]) for r, _ in prof)
    if not r_hi > 0:
        return math.nan
    grid = np.linspace(r_hi / n_r, r_hi, n_r)
    a, b, c = (resample_spline(r, d, grid, "") for r, d in prof)  # checked above: no raise
    return float(estimate_g(grid, a, b, c, threshold_um=threshold_um, method=method).g)


def instance_g(
    gs: GSetup,
    kind: str,
    arrays: InstanceArrays,
    z_s: np.ndarray,
    y_s: np.ndarray,
    k0_s: np.ndarray,
    tan_a: np.ndarray,
    *,
    parallel: bool = True,
) -> np.ndarray:
    """g_ss' (I,) of the instances ``arrays`` (module docstring): ``kind`` the compensator,
    ``z_s`` (I,) their planes for s, ``y_s`` (I, F) the curve y' at s there (mm), ``k0_s`` (I,)
    its K0, ``tan_a`` (F,) the tangents of the curve fields. NaN where a ray fails or g is
    undetermined."""
    pb2 = paraxial_batch(arrays, gs.object_distance, gs.object_per_t)
    cr2 = aim_instances(arrays, gs.aim, parallel=parallel)
    if kind == "fixed-sensor":
        z2 = z_s + gs.extension
    else:
        z2 = image_planes(kind, arrays, pb2, gs.bundle, parallel=parallel)
    good = np.all(cr2.ok, axis=1) & np.isfinite(z2) & np.isfinite(z_s)
    r_s, d_s = _profile(y_s, k0_s, tan_a)
    r_sp, d_sp = _profile(cr2.points_at(z2)[:, :, 1], pb2.k0_at(z2), tan_a)
    r_ssp, d_ssp = _profile(cr2.points_at(z_s)[:, :, 1], pb2.k0_at(z_s), tan_a)
    out = np.full(z_s.shape[0], np.nan)
    for i in np.nonzero(good)[0]:
        out[i] = g_of_profiles(
            [(r_s[i], d_s[i]), (r_sp[i], d_sp[i]), (r_ssp[i], d_ssp[i])],
            gs.n_r,
            gs.threshold_um,
            gs.method,
        )
    return out
