"""Prescription mode of the distortion-variation analysis (Fraser & Shortis 1992, issue 5).

From a lens prescription, a list of focus settings s and object planes s', this module traces the
three kinds of radial distortion profile the paper measures and feeds them to the data-mode
analysis :func:`distortion.variation.analyze_variation` (same tables, same plots):

* ``δr_s``   object at s, lens focused at s (image plane = Gaussian image plane of s);
* ``δr_s'``  object at s', lens focused at s' (its own Gaussian plane);
* ``δr_ss'`` object at s', lens focused at s: the image plane stays at the Gaussian image plane of
  s — Pestrecov's (1958) non-Gaussian plane.

Focusing model (unit focusing)
------------------------------
The whole lens moves; the image plane stays where it is for every object once the lens is
focused. In lens coordinates this means: for focus setting s the image plane is the Gaussian
image plane of an object at s, at a fixed distance from the lens, and an object at another
distance s' is imaged into that same plane.

Distances
---------
Object distances are Pestrecov's ``s``, measured from the first principal point H (= first nodal
point in air), negative to the left. A user types them as positive magnitudes:

* ``Conjugate.metres(D)`` — the object plane D metres in front of H: ``s = −1000·D`` mm;
  ``inf`` = infinity;
* ``Conjugate.scale(N)`` — image scale "N×": the object distance at which the lens focused on it
  has Gaussian magnification ``m0 = −1/N``. Pestrecov Eq. (5), ``m0 = f/(f + s)``, gives
  ``s = −f (1 + N)`` exactly for the thick lens in air (the distance is from H; Brown's thin-lens
  formula ``s = f(1 + N)`` of :mod:`distortion.variation` is the same relation measured from H).
  An object plane "8×(12×)" is therefore the plane at ``s = −f(1 + 8)`` while the image plane is
  the Gaussian plane of ``s = −f(1 + 12)``: its actual magnification is close to, but not exactly,
  −1/8.

Distortion definition
---------------------
All three profiles are Pestrecov's *characteristic* distortion (Eqs. 8–9) in the actual image
plane: ``D0 = y' − M0·y`` with ``M0 = p0'/(m_e p0)`` (``F0 = p0'/m_e`` for an object at infinity).
Because ``y0' = M0 y = (p0'/m_e)·tan α`` with ``tan α = y/p0`` the slope from the entrance pupil
E0, the reference scale ``F0 = p0'/m_e`` depends only on the image plane: for every object plane
s' with the lens focused at s it is the same constant — the principal distance of focus setting s
with the perspective centre at the entrance pupil. So ``δr_ss'`` is exactly the distortion a
photogrammetrist computes with the calibrated (Gaussian-form, no linear term) principal distance
of the focus setting, which is what the paper's plumbline profiles are (a plumbline calibration
cannot see a linear term). ``reference="real-chief-transport"`` or ``"distortion-focal-length"``
(:mod:`distortion.characteristic`) can be chosen instead; the output says which was used.

Radial profiles
---------------
``r = |y'|`` is the *actual* (measured, distorted) radial distance in the image (mm), and
``δr = D0·sign(y0')`` (µm) is positive outward (pincushion positive), whatever the sign of the
image height — the photogrammetric convention of :mod:`distortion.coefficients`.

The profiles are at different image scales, so they are compared at common radial distances: each
profile is traced at ``n_fields`` equally spaced nominal field angles (object heights
``y = p0 tan α``; angles α for an object at infinity), the traced (r, δr) pairs are interpolated
with a not-a-knot cubic spline of δr against r onto one common grid of ``n_r`` radii, from
``r_min`` (default ``r_hi/n_r``) to ``r_hi`` = the smallest largest radius reached by any profile
(or ``r_max``). All profiles handed to ``analyze_variation`` then share these radii exactly, so
its own PCHIP resampling is the identity. The spline error (dense trace, smooth profile) is below
1e-4 µm for the bundled lenses at the default density (checked in the tests against a trace at
the grid radii themselves).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicSpline

from raytrace.errors import TraceError
from raytrace.lens import Lens
from raytrace.paraxial.orthoscopy import object_distance_for_magnification

from ..errors import DataError, UnitWarning
from .analysis import (
    Profile,
    ProfileSet,
    VariationAnalysis,
    analyze_variation,
    check_analysis_options,
)
from .models import PLAIN_METRES_WARN, WEAK_THRESHOLD_UM, Conjugate

DEFAULT_N_FIELDS = 121
DEFAULT_N_R = 25

DEFINITION = (
    "characteristic distortion (Pestrecov 1958 Eqs. 8-9) in the actual image plane: "
    "D0 = y' - M0 y, M0 = p0'/(m_e p0), i.e. relative to the principal distance F0 = p0'/m_e "
    "of the focus setting with the perspective centre at the entrance pupil; r = |y'| "
    "(measured radius), dr = D0 sign(y0') positive outward"
)
FOCUSING = (
    "unit focusing: the whole lens moves; for focus s the image plane is the Gaussian image "
    "plane of s and stays there for every object plane s'. Distances: Pestrecov's s from the "
    "first principal point H; 'Nx' means s = -f(1 + N) (Gaussian magnification -1/N, Eq. 5)"
)
GRID = (
    "each profile traced at {n} nominal field angles and interpolated (cubic spline of dr "
    "against r) onto one common grid of {m} radii"
)


# --------------------------------------------------------------------------------------------
# Parsing and conjugates
# --------------------------------------------------------------------------------------------


def parse_conjugate(text: str) -> Conjugate:
    """A focus or object distance as a person types it.

    ``"12x"`` (also ``12X``, ``12×``): image scale N (Gaussian magnification −1/N);
    ``"1.5"`` or ``"1.5m"``: metres from the first principal point H (positive; Fraser &
    Shortis's unit); ``"1500mm"`` / ``"150cm"``: the same distance with its unit;
    ``"inf"``: infinity (metres). Raises DataError otherwise. A plain number of
    :data:`PLAIN_METRES_WARN` or more warns (:class:`~distortion.errors.UnitWarning`) that it
    looks like millimetres; a unit written out (``"1500m"``) says it is meant.
    """
    from raytrace.units import LENGTH_UNITS, UnitError, split_unit

    t = str(text).strip()
    if not t:
        raise DataError("empty distance (expected e.g. '12x' or '1.5' metres)")
    if t.lower() in ("infinity", "inf m", "infm"):
        t = "inf"
    try:
        v, u = split_unit(t)
    except UnitError:
        u = "?"
    if u not in ("", "x", *LENGTH_UNITS):
        raise DataError(
            f"distance {t!r}: expected an image scale like '12x' (magnification -1/12) or a "
            "distance from the lens like '1.5' (metres), '1.5m' or '1500mm'"
        )
    if not (v > 0 and (math.isfinite(v) or u != "x")):
        raise DataError(f"distance {t!r} must be positive (a magnitude) and finite")
    if u == "x":
        return Conjugate(v, "x", t)
    if u:  # a length unit written out (the one table: raytrace.units)
        return Conjugate(v * LENGTH_UNITS[u] / LENGTH_UNITS["m"], "m", t)
    if v >= PLAIN_METRES_WARN and math.isfinite(v):
        warnings.warn(
            UnitWarning(
                f"distance {t!r} is read as {v:g} m from the lens (a plain number is metres "
                f"here); it looks like millimetres: write {t}mm, or {t}m to keep metres"
            ),
            stacklevel=2,
        )
    return Conjugate(v, "m", t)


def as_conjugates(value, what: str) -> list[Conjugate]:
    """One or more focus / object distances as the API takes them: :class:`Conjugate` objects,
    strings as :func:`parse_conjugate` reads them (``"12x"``, ``"1.5m"``, ``"1500mm"``,
    ``"8x,16x"``) or plain numbers (metres, Fraser & Shortis's unit, as a plain typed number)."""
    items = [value] if isinstance(value, Conjugate | str | int | float) else value
    try:
        items = list(items)
    except TypeError:
        raise TypeError(
            f"{what}: give a distance ('12x', '1.5m', 1.5) or a list of them, not "
            f"{type(value).__name__}"
        ) from None
    out: list[Conjugate] = []
    for c in items:
        if isinstance(c, Conjugate):
            out.append(c)
        elif isinstance(c, str):
            out.extend(parse_conjugates(c))
        elif isinstance(c, int | float) and not isinstance(c, bool):
            out.append(parse_conjugate(repr(float(c))))
        else:
            raise TypeError(
                f"{what}: {c!r} is not a distance (give '12x', '1.5m', 1.5 or a Conjugate)"
            )
    return out


def parse_conjugates(text: str) -> list[Conjugate]:
    """Comma-separated :func:`parse_conjugate` values (``"8x,16x,20x"``)."""
    parts = [p for p in (q.strip() for q in str(text).split(",")) if p]
    if not parts:
        raise DataError("empty list of distances")
    return [parse_conjugate(p) for p in parts]


@dataclass(frozen=True)
class ConjugateGeometry:
    """Where a :class:`Conjugate` puts the object for a lens (mm).

    ``s``: Pestrecov's signed object distance from H (negative; −inf at infinity);
    ``object_distance``: positive magnitude from the object plane to the first vertex (inf);
    ``scale``: image scale N = −1/m0 of an object there in its own Gaussian plane (inf)."""

    conjugate: Conjugate
    s: float
    object_distance: float
    scale: float


def conjugate_geometry(lens: Lens, c: Conjugate, *, wavelength: float | None = None):
    """Object position of ``c`` for ``lens`` (module docstring: distances from H, N× → s =
    −f(1 + N)). Raises DataError when the object would lie inside the focal length (no real
    image) or behind the first vertex."""
    from raytrace.paraxial import paraxial

    par = paraxial(lens, math.inf, wavelength)
    f = par.efl
    if not f > 0:
        raise DataError(f"{lens.name}: focal length {f:g} mm is not positive")
    if c.unit == "x":
        s = object_distance_for_magnification(f, -1.0 / c.value)  # -f(1 + N), Eq. (5)
    else:
        s = -c.value * 1000.0
    if math.isinf(s):
        return ConjugateGeometry(c, -math.inf, math.inf, math.inf)
    if not -s > f:
        raise DataError(
            f"object distance {c.label} ({-s:g} mm from H) is not beyond the focal length "
            f"{f:g} mm of {lens.name}: no real image"
        )
    od = -(par.z_H + s)
    if not od > 0:
        raise DataError(
            f"object distance {c.label} puts the object plane behind the first vertex of "
            f"{lens.name} (H is {par.z_H:g} mm behind it)"
        )
    return ConjugateGeometry(c, s, od, -s / f - 1.0)


# --------------------------------------------------------------------------------------------
# Tracing one setting
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class TracedSetting:
    """One traced profile: object at ``obj`` with the lens focused at ``focus``.

    ``object_distance`` (mm, first vertex, positive), ``s`` (mm from H, signed);
    ``from_last_vertex`` (last vertex → image plane, mm), ``s_prime`` (from H', mm), ``defocus``
    (image plane − Gaussian image plane of this object, mm; 0 for a Gaussian profile);
    ``constant``: M0 (or F0, mm) of Eq. (8) in that plane; ``magnification``: Gaussian m0 of
    the object in its own plane. ``fields`` (deg, nominal angles), ``r_mm`` = |y'|,
    ``dr_um`` (positive outward) and ``status`` per traced field (NaN where not OK)."""

    focus: Conjugate
    obj: Conjugate
    gaussian: bool
    object_distance: float
    s: float
    from_last_vertex: float
    s_prime: float
    defocus: float
    constant: float
    magnification: float
    fields: np.ndarray
    r_mm: np.ndarray
    dr_um: np.ndarray
    status: np.ndarray

    @property
    def label(self) -> str:
        return Profile(self.focus, self.obj, np.zeros(2), np.zeros(2)).label

    def valid(self) -> tuple[np.ndarray, np.ndarray]:
        """(r, δr) of the leading run of successfully traced fields (a failure ends the profile)."""
        return leading_run(self.r_mm, self.dr_um)


def leading_run(r: np.ndarray, dr: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(r, δr) up to the first field where either is not finite (a failed ray ends a traced
    profile): the part of a profile that :func:`resample_spline` may interpolate."""
    ok = np.isfinite(r) & np.isfinite(dr)
    n = int(np.argmin(ok)) if not ok.all() else ok.size
    return r[:n], dr[:n]


def radial_profile(cd) -> tuple[np.ndarray, np.ndarray]:
    """(r, δr) of the first image plane of a characteristic distortion ``cd`` (module docstring,
    "Radial profiles"): r = |y'| (mm) and δr = D0·sign(y0') (µm, outward positive; 0 on the
    axis)."""
    yp, y0p, d0 = cd.yp[0], cd.y0p[0], cd.D0[0]
    return np.abs(yp), d0 * np.sign(y0p) * 1000.0


def _same(a: Conjugate, b: Conjugate) -> bool:
    return a.unit == b.unit and a.value == b.value


def trace_setting(
    lens: Lens,
    focus: Conjugate,
    obj: Conjugate,
    fields_deg: np.ndarray,
    *,
    reference: str = "characteristic",
    wavelength: float | None = None,
) -> TracedSetting:
    """Trace the profile of an object at ``obj`` with ``lens`` focused at ``focus`` (unit
    focusing). ``fields_deg``: nominal field angles (deg; object heights ``y = p0 tan α`` for a
    finite object). The image plane is the Gaussian plane of ``focus``, passed to
    :func:`distortion.characteristic.characteristic_distortion` as a distance from the last
    vertex — the same number for every object plane, so ``obj == focus`` reproduces the
    Gaussian profile bit for bit."""
    from raytrace.paraxial import paraxial

    from ..characteristic import characteristic_distortion

    gf = conjugate_geometry(lens, focus, wavelength=wavelength)
    go = conjugate_geometry(lens, obj, wavelength=wavelength)
    pf = paraxial(lens, gf.object_distance, wavelength)
    image_distance = pf.gaussian_image_distance
    if not (math.isfinite(image_distance) and image_distance > 0):
        raise DataError(
            f"{lens.name} focused at {focus.label}: the Gaussian image lies "
            f"{image_distance:g} mm from the last vertex (not a real image behind the lens)"
        )
    try:
        cd = characteristic_distortion(
            lens,
            np.asarray(fields_deg, dtype=float),
            object_distance=go.object_distance,
            from_last_vertex=image_distance,
            reference=reference,
            wavelength=wavelength,
        )
    except TraceError as e:
        raise DataError(f"{lens.name}, object {obj.label} focused at {focus.label}: {e}") from None
    r, dr = radial_profile(cd)
    m0 = cd.gaussian_constant
    return TracedSetting(
        focus=focus,
        obj=obj,
        gaussian=_same(focus, obj),
        object_distance=go.object_distance,
        s=go.s,
        from_last_vertex=float(cd.from_last_vertex[0]),
        s_prime=float(cd.s_prime[0]),
        defocus=float(cd.defocus[0]),
        constant=float(cd.constant[0]),
        magnification=float(m0),
        fields=cd.fields,
        r_mm=r,
        dr_um=dr,
        status=cd.status,
    )


# --------------------------------------------------------------------------------------------
# The whole study
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class TracedVariation:
    """Prescription-mode result.

    ``analysis``: the data-mode :class:`VariationAnalysis` of the traced profiles (γ, Brown's
    Eq. (1) prediction δr_s'/γ beside the traced δr_ss' in ``analysis.brown``, g per plane ± σ,
    mean g, RMS errors, Eq. (3)–(4) checks). ``profile_set``: the profiles on the common grid
    ``r_grid_mm``. ``settings``: the raw dense traces. ``efl_mm``: the lens EFL (f of Eq. 2, 4).
    ``reference``: distortion definition; ``notes``: what was assumed."""

    lens_name: str
    efl_mm: float
    reference: str
    r_grid_mm: np.ndarray
    settings: tuple[TracedSetting, ...]
    profile_set: ProfileSet
    analysis: VariationAnalysis
    notes: tuple[str, ...]

    def __repr__(self) -> str:
        return (
            f"TracedVariation({self.lens_name}, f = {self.efl_mm:.4f} mm, "
            f"{len(self.settings)} traced settings, analysis={self.analysis!r})"
        )


def field_limit(lens: Lens, max_field_deg: float | None) -> float:
    """The largest field angle (degrees) a prescription-mode study traces: ``max_field_deg``,
    checked to lie in (0, 90), or the lens's field; a field given as an object height h becomes
    the paraxial angle atan(|h/p0|)."""
    if max_field_deg is not None:
        if not 0 < max_field_deg < 90:
            raise DataError(f"maximum field angle must lie in (0, 90) degrees, got {max_field_deg}")
        return float(max_field_deg)
    if lens.field.kind == "angle":
        return float(lens.field.value)
    from raytrace.paraxial import paraxial

    par = paraxial(lens)
    return float(math.degrees(math.atan(abs(lens.field.value / par.p0))))


def resample_spline(r: np.ndarray, dr: np.ndarray, grid: np.ndarray, label: str) -> np.ndarray:
    """δr of a traced profile (module docstring, "Radial profiles") on the radii ``grid`` (mm): a
    not-a-knot cubic spline of δr against r. ``r`` must hold at least 4 radii, increasing;
    ``label`` names the profile in the DataError otherwise."""
    if r.size < 4:
        raise DataError(f"profile {label}: fewer than 4 traced fields before the first failure")
    if not np.all(np.diff(r) > 0):
        raise DataError(
            f"profile {label}: the image radius does not grow with the field angle, so δr is "
            "not a function of r"
        )
    return CubicSpline(r, dr)(grid)


def trace_variation(
    lens: Lens,
    focus: Conjugate | str | float | Sequence[Conjugate | str | float],
    objects: Conjugate | str | float | Sequence[Conjugate | str | float],
    *,
    r_min: float | None = None,
    r_max: float | None = None,
    n_r: int = DEFAULT_N_R,
    n_fields: int = DEFAULT_N_FIELDS,
    max_field_deg: float | None = None,
    threshold_um: float = WEAK_THRESHOLD_UM,
    method: str = "lsq",
    reference: str = "characteristic",
    wavelength: float | None = None,
) -> TracedVariation:
    """Trace δr_s, δr_s', δr_ss' for ``lens`` (module docstring) and analyse them (Fraser &
    Shortis 1992, Eqs. 1–6).

    Parameters
    ----------
    lens : Lens
        The prescription; unit focusing (the whole lens moves) is assumed (``FOCUSING``).
    focus, objects : distance or list of distances
        Focus settings and object planes: ``"12x"`` (image scale N, Gaussian magnification
        −1/N), ``"1.5m"`` / ``"1500mm"`` or a plain number (metres from the first principal
        point H, positive), ``"8x,16x"``, or :class:`Conjugate` objects (:func:`as_conjugates`).
        A plane equal to a focus setting adds nothing for that focus; every focus setting and
        every object plane also gets its Gaussian profile. A distance given twice is refused.
    r_min, r_max : float, optional
        The common radial grid in the image, mm (defaults ``r_hi/n_r`` and the largest radius
        all profiles reach).
    n_r, n_fields : int
        Radii of the common grid; traced nominal field angles from 0 to ``max_field_deg``
        (degrees; default the lens's field).
    threshold_um, method
        As :func:`distortion.variation.analyze_variation` (µm; ``"lsq"`` or ``"mean"``).
    reference : str
        The distortion definition (:mod:`distortion.characteristic`; default Pestrecov's
        characteristic D0). wavelength: nm (default the lens's).

    Returns
    -------
    TracedVariation
        ``analysis`` holds γ, g per plane and the mean g; δr positive outward (µm).

    Raises DataError for impossible requests.
    """
    from raytrace.paraxial import paraxial

    check_analysis_options(r_min, r_max, threshold_um, method)
    foci, objs = as_conjugates(focus, "focus"), as_conjugates(objects, "objects")
    if not foci:
        raise DataError("give at least one focus setting")
    for what, cs in (("focus setting", foci), ("object plane", objs)):
        for i, c in enumerate(cs):
            twin = next((d for d in cs[:i] if _same(c, d)), None)
            if twin is not None:
                raise DataError(
                    f"{what} {c.text or c.label} is given twice (as {twin.text or twin.label})"
                )
    if n_r < 2 or n_fields < 8:
        raise DataError("need n_r >= 2 common radii and n_fields >= 8 traced fields")
    efl = paraxial(lens, math.inf, wavelength).efl
    fmax = field_limit(lens, max_field_deg)
    fields = np.linspace(0.0, fmax, n_fields)

    gauss: list[Conjugate] = []
    for c in foci + objs:
        if not any(_same(c, g) for g in gauss):
            gauss.append(c)
    pairs = [(c, c) for c in gauss]
    for fc in foci:
        for o in objs:
            if not _same(o, fc) and not any(_same(fc, a) and _same(o, b) for a, b in pairs):
                pairs.append((fc, o))
    if len(pairs) < 2:
        raise DataError(
            "one profile only: give object planes different from the focus setting "
            "(e.g. --focus 12x --objects 8x,16x,20x)"
        )
    settings = [
        trace_setting(lens, a, b, fields, reference=reference, wavelength=wavelength)
        for a, b in pairs
    ]
    valid = [s.valid() for s in settings]
    r_hi = min(float(v[0][-1]) if v[0].size else 0.0 for v in valid)
    worst = settings[int(np.argmin([v[0][-1] if v[0].size else 0.0 for v in valid]))]
    if r_max is not None:
        if not r_max > 0:
            raise DataError(f"r_max must be positive, got {r_max}")
        if r_max > r_hi:
            raise DataError(
                f"r_max = {r_max:g} mm is beyond the largest radius {r_hi:.3f} mm that profile "
                f"{worst.label} reaches within {fmax:g} deg (raise the maximum field angle)"
            )
        r_hi = float(r_max)
    lo = r_hi / n_r if r_min is None else float(r_min)
    if not 0 < lo < r_hi:
        raise DataError(f"radial range {lo:g}–{r_hi:g} mm is empty or starts at r <= 0")
    grid = np.linspace(lo, r_hi, n_r)
    profiles = tuple(
        Profile(s.focus, s.obj, grid.copy(), resample_spline(r, d, grid, s.label))
        for s, (r, d) in zip(settings, valid, strict=True)
    )
    notes = (
        f"traced from the prescription {lens.name}, f = {efl:.4f} mm",
        FOCUSING,
        "distortion: "
        + (
            DEFINITION
            if reference == "characteristic"
            else f"reference '{reference}' (distortion.characteristic); r = |y'|"
        ),
        GRID.format(n=n_fields, m=n_r) + f" from {lo:.4g} to {r_hi:.4g} mm",
    )
    ps = ProfileSet(profiles, efl, f"{lens.name} (traced)", notes)
    an = analyze_variation(ps, threshold_um=threshold_um, method=method)
    return TracedVariation(lens.name, efl, reference, grid, tuple(settings), ps, an, notes)
