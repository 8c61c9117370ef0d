"""Analysis of measured (or traced) radial-distortion profiles at several focus settings and
object distances (Fraser & Shortis 1992): Brown's γ, g_ss' per object plane, mean g, RMS errors.

Models
------
* Brown (1971) Eq. (1)–(2) of Fraser & Shortis (1992):
  ``δr_ss' = δr_s' / γ_ss'``, ``γ_ss' = c_s'/c_s = (s'/s)·(s − f)/(s' − f)``.
* Brown (1971) Eq. (3)–(4): ``δr_s = α_s δr_s1 + (1 − α_s) δr_s2``,
  ``α_s = (s2 − s)/(s2 − s1) · (s1 − f)/(s − f)``.
* Fraser & Shortis Eq. (5)–(6): ``δr_ss' = δr_s + g_ss' (δr_s' − δr_s)``.

Notation (the paper's): ``δr_s`` is the distortion profile for an object at distance s with the
lens focused at s (a "Gaussian" profile: object plane = plane of sharpest focus); ``δr_s'`` the same
for s'; ``δr_ss'`` the profile for an object at s' while the lens is focused at s. All profiles are
functions of the radial distance r in the image (mm); δr in micrometres, positive outward
(``δr = r_actual − r_ideal``, pincushion positive).

Distances and image scales
--------------------------
In Eq. (2) and Eq. (4) s, s', s1, s2 are object distances measured from the lens (its front
principal point, Brown's thin-lens model) as POSITIVE magnitudes, in the same length unit as f;
they must exceed f (a real image). An image scale "N×" means a Gaussian magnification of −1/N;
for a lens focused by moving it as a whole (unit focusing) the thin-lens equation gives

    s = f (1 + N),    N = s/f − 1,    principal distance c_s = f (1 + 1/N).

In image scales both γ and α are independent of f:
``γ_ss' = N (1 + N') / (N' (1 + N))`` and ``α_s = (N2 − N)/(N2 − N1) · N1/N``; i.e. Eq. (4) is
linear interpolation in ``1/(s − f) = 1/(f N)`` (proportional to the magnification), so Eq. (3) is
exact for profiles of the form ``δr_s(r) = A(r) + B(r)/(s − f)``.
An infinite distance (``inf`` metres, N = ∞) is allowed for a focus setting. Check against the
paper's Table 1 text (Pentax, f = 45 mm): "focused at 8m (175×)", planes 1.5/2.1/2.6/3.4 m
"approximately 33×, 45×, 56×, and 75×"; N = s/f − 1 gives 176.8, 32.3, 45.7, 56.8, 74.6.

(The docs/design.md sign convention has s negative; the paper's formulas use positive distances,
and so do these functions. They never mix the two.)

Comparing profiles
------------------
Profiles at different focus settings are measured at different principal distances, hence at
different radii. They are compared at common radial distances: the two Gaussian profiles are
interpolated onto the radii of the measured ``δr_ss'`` profile (inside the radial range common to
all three; no extrapolation) with PCHIP, the Fritsch–Carlson monotone piecewise-cubic Hermite
interpolant (``scipy.interpolate.PchipInterpolator``). It passes through the data points, so
profiles given at identical radii are compared at those radii without change.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import PchipInterpolator

from ..errors import DataError
from .models import (
    INTERPOLATION,
    WEAK_THRESHOLD_UM,
    Conjugate,
    brown_alpha_scales,
    brown_gamma_scales,
    brown_interpolate,
    brown_predict,
    fs_predict,
)


@dataclass(frozen=True, eq=False)
class GEstimate:
    """g_ss' from one object plane (Eq. 6 rearranged: δr_ss' − δr_s = g (δr_s' − δr_s)).

    Arrays are over the radii ``r_mm`` of the radial range used. ``x_um = δr_s' − δr_s``,
    ``y_um = δr_ss' − δr_s``; ``weak`` marks radii with |x| < threshold (excluded from the fit);
    ``g_pointwise = y/x`` (NaN where x = 0; unreliable where ``weak``). ``status`` is ``"ok"`` or
    ``"undetermined"`` (then g and se are NaN and ``message`` says why). ``se`` is the standard
    error (one sigma) of g; ``rms_fit_um`` the RMS residual of Eq. (6) with this plane's own g.
    """

    g: float
    se: float
    n_used: int
    n_excluded: int
    method: str
    threshold_um: float
    r_mm: np.ndarray
    x_um: np.ndarray
    y_um: np.ndarray
    weak: np.ndarray
    g_pointwise: np.ndarray
    rms_fit_um: float
    status: str
    message: str

    @property
    def determined(self) -> bool:
        return self.status == "ok"

    @property
    def excluded_r_mm(self) -> np.ndarray:
        return self.r_mm[self.weak]


def estimate_g(
    r_mm: np.ndarray,
    dr_s: np.ndarray,
    dr_s_prime: np.ndarray,
    dr_ss_prime: np.ndarray,
    *,
    threshold_um: float = WEAK_THRESHOLD_UM,
    method: str = "lsq",
    min_points: int = 2,
) -> GEstimate:
    """Estimate g_ss' of Eq. (6) from three profiles given at the same radii (µm).

    method ``"lsq"``: least squares through the origin of y = δr_ss' − δr_s on
    x = δr_s' − δr_s, ``g = Σxy/Σx²``, ``se = sqrt(Σe²/(n−1) / Σx²)`` (e = y − g x);
    method ``"mean"``: mean of the pointwise ratios y/x over the radial range (the paper: "the mean
    over the radial distance range of 20 to 140 mm"), ``se`` = sample SD / √n.
    Radii with |x| < ``threshold_um`` are excluded (weak determination). If fewer than
    ``min_points`` radii remain — e.g. δr_s' = δr_s everywhere — g is reported undetermined
    (NaN, status ``"undetermined"``) instead of dividing by zero. ``rms_fit_um`` is over all radii.
    """
    if method not in ("lsq", "mean"):
        raise DataError(f"unknown g estimation method {method!r} (expected 'lsq' or 'mean')")
    if min_points < 2:
        raise DataError("min_points must be at least 2 (a standard error needs n - 1 > 0)")
    r = np.asarray(r_mm, dtype=float)
    s = np.asarray(dr_s, dtype=float)
    x = np.asarray(dr_s_prime, dtype=float) - s
    y = np.asarray(dr_ss_prime, dtype=float) - s
    if not (r.shape == s.shape == x.shape == y.shape) or r.ndim != 1:
        raise DataError("estimate_g needs four 1-D arrays of the same length")
    weak = np.abs(x) < threshold_um
    with np.errstate(divide="ignore", invalid="ignore"):
        g_pt = np.where(x != 0.0, y / np.where(x != 0.0, x, 1.0), np.nan)
    use = ~weak
    n = int(use.sum())
    common = dict(
        n_used=n,
        n_excluded=int(weak.sum()),
        method=method,
        threshold_um=float(threshold_um),
        r_mm=r,
        x_um=x,
        y_um=y,
        weak=weak,
        g_pointwise=g_pt,
    )
    if n < min_points:
        msg = (
            f"g_ss' undetermined: |δr_s' − δr_s| ≥ {threshold_um:g} µm at only {n} of {r.size} "
            f"radii (need {min_points}); the focus change does not alter the distortion enough "
            "to give Eq. (6) any leverage"
        )
        return GEstimate(
            g=math.nan,
            se=math.nan,
            rms_fit_um=math.nan,
            status="undetermined",
            message=msg,
            **common,
        )
    xu, yu = x[use], y[use]
    if method == "lsq":
        sxx = float(np.dot(xu, xu))
        g = float(np.dot(xu, yu)) / sxx
        e = yu - g * xu
        se = math.sqrt(float(np.dot(e, e)) / (n - 1) / sxx)
    else:
        ratios = yu / xu
        g = float(ratios.mean())
        se = float(ratios.std(ddof=1)) / math.sqrt(n)
    resid = y - g * x
    rms = float(np.sqrt(np.mean(resid**2)))
    msg = f"g_ss' = {g:.3f} ± {se:.3f} from {n} radii"
    if weak.any():
        msg += f"; {int(weak.sum())} weak radii excluded (|δr_s' − δr_s| < {threshold_um:g} µm)"
    return GEstimate(g=g, se=se, rms_fit_um=rms, status="ok", message=msg, **common)


@dataclass(frozen=True)
class GSummary:
    """Mean of g values and its spread. ``precision`` is the sample standard deviation (n − 1)
    — what Fraser & Shortis Tables 2–3 call "precision" of the overall mean (their text: "An
    overall mean value and standard deviation are additionally given"); ``sem`` = precision/√n."""

    mean: float
    precision: float
    sem: float
    n: int


def summarize_g(values: Sequence[float]) -> GSummary:
    """Unweighted mean, sample SD ("precision") and standard error of finite g values.

    Used both for the mean g over object planes of one lens (Tables 2–3 column "Mean") and for
    the overall mean over lenses (the captions' "overall mean ... with a precision of ...").
    NaN values (undetermined planes) are ignored; none left → NaN summary with n = 0."""
    v = np.asarray([x for x in values if np.isfinite(x)], dtype=float)
    n = int(v.size)
    if n == 0:
        return GSummary(math.nan, math.nan, math.nan, 0)
    mean = float(v.mean())
    sd = float(v.std(ddof=1)) if n > 1 else math.nan
    return GSummary(mean, sd, sd / math.sqrt(n) if n > 1 else math.nan, n)


def _misfit(predicted: np.ndarray, measured: np.ndarray) -> tuple[float, float]:
    """RMS and largest |predicted − measured| over the radii (units of the inputs)."""
    d = predicted - measured
    return float(np.sqrt(np.mean(d**2))), float(np.max(np.abs(d)))


def rms_error_eq6(dr_s: np.ndarray, dr_s_prime: np.ndarray, dr_ss_prime: np.ndarray, g: float):
    """RMS (µm) of δr_ss' − [δr_s + g(δr_s' − δr_s)] over the given radii (Tables 2–3 'e')."""
    d = fs_predict(dr_s, dr_s_prime, g) - np.asarray(dr_ss_prime, dtype=float)
    return float(np.sqrt(np.mean(d**2)))


# --------------------------------------------------------------------------------------------
# Profiles and resampling
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class Profile:
    """One radial distortion profile: object at ``obj`` with the lens focused at ``focus``.

    ``r_mm`` strictly increasing radial distances (mm); ``dr_um`` distortion (µm, positive
    outward). ``line`` is the first source line (for messages), if read from a file."""

    focus: Conjugate
    obj: Conjugate
    r_mm: np.ndarray
    dr_um: np.ndarray
    line: int | None = None

    @property
    def label(self) -> str:
        """The paper's notation: ``i×(j×)`` = object plane i× with the lens focused at j×;
        a profile in its plane of focus is labelled ``j×``."""
        if self.focus == self.obj:
            return self.focus.label
        sep = " " if self.obj.unit == "m" or self.focus.unit == "m" else ""
        return f"{self.obj.label}{sep}({self.focus.label})"


@dataclass(frozen=True)
class ProfileSet:
    """Profiles of one lens. ``focal_length_mm`` is needed for distances in metres."""

    profiles: tuple[Profile, ...]
    focal_length_mm: float | None = None
    source: str = ""
    notes: tuple[str, ...] = ()


def resample(profile: Profile, r_mm: np.ndarray) -> np.ndarray:
    """δr of ``profile`` at radii ``r_mm`` (inside its range) by PCHIP interpolation."""
    r = np.asarray(r_mm, dtype=float)
    lo, hi = profile.r_mm[0], profile.r_mm[-1]
    if r.size and (r.min() < lo - 1e-12 or r.max() > hi + 1e-12):
        raise DataError(f"profile {profile.label}: radii outside its range {lo:g}–{hi:g} mm")
    exact = np.isin(r, profile.r_mm)
    if exact.all():
        idx = np.searchsorted(profile.r_mm, r)
        return profile.dr_um[idx].astype(float)
    return PchipInterpolator(profile.r_mm, profile.dr_um, extrapolate=False)(r)


def common_radii(
    target: Profile, others: Sequence[Profile], r_min: float | None, r_max: float | None
) -> np.ndarray:
    """Radii of ``target`` inside the range common to all profiles and [r_min, r_max]."""
    lo = max([target.r_mm[0]] + [p.r_mm[0] for p in others])
    hi = min([target.r_mm[-1]] + [p.r_mm[-1] for p in others])
    if r_min is not None:
        lo = max(lo, r_min)
    if r_max is not None:
        hi = min(hi, r_max)
    r = target.r_mm
    return r[(r >= lo) & (r <= hi)]


# --------------------------------------------------------------------------------------------
# Analysis of a profile set (data mode; the prescription mode builds a ProfileSet and reuses it)
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class BrownGamma:
    """γ_ss' (Eq. 2) for object plane ``obj`` with the lens focused at ``focus``."""

    focus: Conjugate
    obj: Conjugate
    scale_focus: float
    scale_object: float
    gamma: float


@dataclass(frozen=True, eq=False)
class BrownComparison:
    """Brown's Eq. (1) prediction δr_s'/γ against the measured δr_ss' (µm) at radii ``r_mm``."""

    focus: Conjugate
    obj: Conjugate
    gamma: float
    r_mm: np.ndarray
    measured_um: np.ndarray
    predicted_um: np.ndarray
    rms_um: float
    max_abs_um: float


@dataclass(frozen=True)
class PlaneResult:
    """Eq. (6) for one object plane: g estimate and the error of applying the focus's mean g."""

    focus: Conjugate
    obj: Conjugate
    estimate: GEstimate
    rms_mean_g_um: float  # RMS error of Eq. (6) with the mean g of this focus setting


@dataclass(frozen=True)
class FocusSummary:
    """One row of Tables 2–3: planes at one focus setting, mean g and its precision."""

    focus: Conjugate
    planes: tuple[PlaneResult, ...]
    summary: GSummary


@dataclass(frozen=True, eq=False)
class FieldVariation:
    """Distortion of all object planes at one focus setting on common radii (µm); ``spread_um``
    = max − min over the planes at each radius: the variation within the photographic field."""

    focus: Conjugate
    objects: tuple[Conjugate, ...]
    r_mm: np.ndarray
    dr_um: np.ndarray  # (n_objects, n_r)
    spread_um: np.ndarray


@dataclass(frozen=True, eq=False)
class InterpolationCheck:
    """Brown Eq. (3)–(4): the Gaussian profile at s predicted from those at s1, s2."""

    s: Conjugate
    s1: Conjugate
    s2: Conjugate
    alpha: float
    r_mm: np.ndarray
    measured_um: np.ndarray
    predicted_um: np.ndarray
    rms_um: float
    max_abs_um: float


@dataclass(frozen=True)
class VariationAnalysis:
    """Everything the data allow: γ, Brown's prediction, g per plane, mean g, RMS errors,
    within-field variation, Eq. (3)–(4) checks; ``messages`` say what could not be estimated."""

    source: str
    focal_length_mm: float | None
    profiles: tuple[Profile, ...]
    gammas: tuple[BrownGamma, ...]
    brown: tuple[BrownComparison, ...]
    focus_summaries: tuple[FocusSummary, ...]
    field_variation: tuple[FieldVariation, ...]
    interpolation_checks: tuple[InterpolationCheck, ...]
    radial_range_mm: tuple[float | None, float | None]
    threshold_um: float
    method: str
    interpolation: str = INTERPOLATION
    messages: tuple[str, ...] = field(default_factory=tuple)

    def __repr__(self) -> str:
        gs = "; ".join(
            f"focus {fs.focus.label}: mean g {fs.summary.mean:.3f} ± {fs.summary.precision:.3f}"
            if fs.summary.n
            else f"focus {fs.focus.label}: no g"
            for fs in self.focus_summaries
        )
        return (
            f"VariationAnalysis({self.source or 'profiles'}: {len(self.profiles)} profiles"
            + (f", {gs}" if gs else "")
            + ")"
        )


def _keyer(ps: ProfileSet):
    """Key function identifying equal distances, across units when the focal length is known."""
    units = {p.focus.unit for p in ps.profiles} | {p.obj.unit for p in ps.profiles}
    if len(units) == 1:
        return lambda c: (c.unit, c.value)
    if ps.focal_length_mm is None:
        raise DataError(
            f"{ps.source or 'profiles'}: the focus and object columns use different units "
            "(metres and image scales): the focal length is needed to relate them "
            "(add '# focal_length_mm: F' to the file or pass it)"
        )
    return lambda c: ("x", round(c.image_scale(ps.focal_length_mm), 9))


def _scale_or_none(c: Conjugate, f: float | None) -> float | None:
    if c.unit == "x":
        return c.value
    return None if f is None else c.image_scale(f)


def check_analysis_options(
    r_min: float | None, r_max: float | None, threshold_um: float, method: str
) -> None:
    """Refuse analysis options that cannot mean anything (DataError naming the keyword): a
    negative or non-finite radius, r_min not below r_max, a negative or NaN threshold, an
    unknown g method."""
    for name, v in (("r_min", r_min), ("r_max", r_max)):
        if v is not None and not (v >= 0 and math.isfinite(v)):
            raise DataError(f"{name}= must be a non-negative radius in mm, got {v!r}")
    if r_min is not None and r_max is not None and not r_min < r_max:
        raise DataError(f"r_min={r_min:g} must be below r_max={r_max:g} (mm)")
    if not threshold_um >= 0 or not math.isfinite(threshold_um):
        raise DataError(f"threshold_um= must be >= 0 (micrometres), got {threshold_um!r}")
    if method not in ("lsq", "mean"):
        raise DataError(f"unknown g estimation method {method!r} (expected 'lsq' or 'mean')")


def analyze_variation(
    ps: ProfileSet | str | os.PathLike,
    *,
    r_min: float | None = None,
    r_max: float | None = None,
    threshold_um: float = WEAK_THRESHOLD_UM,
    method: str = "lsq",
) -> VariationAnalysis:
    """Analyse a set of radial distortion profiles of one lens (Fraser & Shortis 1992).

    For every non-Gaussian profile δr_ss' (object s' ≠ focus s): γ_ss' (Eq. 2; needs f when the
    distances are in metres); Brown's Eq. (1) prediction if the Gaussian profile δr_s' exists;
    g_ss' (Eq. 6) if both δr_s and δr_s' exist, over radii in [r_min, r_max] (mm; default all
    common radii), weak radii (|δr_s' − δr_s| < threshold_um) excluded. Per focus setting: mean g
    over planes and its precision (sample SD), and the RMS error of Eq. (6) with that mean g per
    plane. Per focus with ≥ 2 profiles: the within-field variation. For each Gaussian profile
    bracketed by two others: the Eq. (3)–(4) prediction. ``messages`` state what could not be
    estimated and why.

    Parameters
    ----------
    ps : ProfileSet, str or os.PathLike
        The profiles (δr in µm, positive outward, at radii r in mm), or the path of a profile CSV,
        read by :func:`distortion.variation.profiles.read_profiles_csv` with the file's own focal
        length. At least two profiles.
    r_min, r_max : float, optional
        Radial range in mm (non-negative, finite, ``r_min < r_max``) over which g_ss' is
        estimated and the profiles are compared; default all common radii.
    threshold_um : float
        Radii where |δr_s' − δr_s| < ``threshold_um`` (µm, ≥ 0, finite) are left out of the
        g_ss' estimate; default :data:`~distortion.variation.models.WEAK_THRESHOLD_UM` (0.5 µm).
    method : {"lsq", "mean"}
        How g_ss' is estimated from Eq. (6): ``"lsq"`` (default) least squares through the
        origin of δr_ss' − δr_s against δr_s' − δr_s; ``"mean"`` the mean of the pointwise
        ratios over the radial range, as in the paper.

    Returns
    -------
    VariationAnalysis
        γ_ss' of each non-Gaussian profile whose image scales are known, Brown's Eq. (1)
        comparisons, the per-focus g_ss' summaries, the within-field variation, the Eq. (3)–(4)
        checks, the options used and the ``messages``.

    Raises
    ------
    TypeError
        ``ps`` is neither a ProfileSet nor a path.
    DataError
        Fewer than two profiles; a negative or non-finite ``r_min``/``r_max``, ``r_min`` not
        below ``r_max``, a negative or non-finite ``threshold_um``, an unknown ``method``; or a
        CSV that :func:`~distortion.variation.profiles.read_profiles_csv` refuses.
    """
    check_analysis_options(r_min, r_max, threshold_um, method)
    if isinstance(ps, str | os.PathLike):
        from .profiles import read_profiles_csv

        ps = read_profiles_csv(ps)
    elif not isinstance(ps, ProfileSet):
        raise TypeError(
            f"analyze_variation takes a ProfileSet or the path of a profile CSV, not "
            f"{type(ps).__name__}"
        )
    if len(ps.profiles) < 2:
        raise DataError(
            f"{ps.source or 'profiles'}: a variation analysis needs at least two profiles, "
            f"got {len(ps.profiles)}"
        )
    f = ps.focal_length_mm
    key = _keyer(ps)
    msgs: list[str] = []
    gaussian = {key(p.focus): p for p in ps.profiles if key(p.focus) == key(p.obj)}
    focus_keys: dict = {}
    for p in ps.profiles:
        focus_keys.setdefault(key(p.focus), p.focus)

    def order(c: Conjugate) -> float:
        sc = _scale_or_none(c, f)
        return sc if sc is not None else c.value

    gammas: list[BrownGamma] = []
    brown: list[BrownComparison] = []
    summaries: list[FocusSummary] = []
    variations: list[FieldVariation] = []
    gamma_missing = False
    for fk, focus in sorted(focus_keys.items(), key=lambda kv: order(kv[1])):
        members = sorted([p for p in ps.profiles if key(p.focus) == fk], key=lambda p: order(p.obj))
        planes = [p for p in members if key(p.obj) != fk]
        g_s = gaussian.get(fk)
        estimates: list[tuple[Profile, Profile | None, GEstimate | None, np.ndarray]] = []
        for p in planes:
            sf, so = _scale_or_none(p.focus, f), _scale_or_none(p.obj, f)
            gamma = math.nan
            if sf is None or so is None:
                gamma_missing = True
            else:
                gamma = brown_gamma_scales(sf, so)
                gammas.append(BrownGamma(p.focus, p.obj, sf, so, gamma))
            g_sp = gaussian.get(key(p.obj))
            if g_sp is not None and np.isfinite(gamma):
                r = common_radii(p, [g_sp], r_min, r_max)
                if r.size:
                    meas = resample(p, r)
                    pred = brown_predict(resample(g_sp, r), gamma)
                    brown.append(
                        BrownComparison(p.focus, p.obj, gamma, r, meas, pred, *_misfit(pred, meas))
                    )
            missing = []
            if g_s is None:
                missing.append(f"δr_s (object at the focus {focus.label})")
            if g_sp is None:
                missing.append(f"δr_s' (lens focused on {p.obj.label})")
            if missing:
                msgs.append(
                    f"{p.label}: g_ss' (Eq. 6) cannot be estimated: no Gaussian profile "
                    + " nor ".join(missing)
                    + ("; Brown's Eq. (1) prediction needs δr_s' too" if g_sp is None else "")
                )
                continue
            r = common_radii(p, [g_s, g_sp], r_min, r_max)
            if r.size < 2:
                msgs.append(f"{p.label}: fewer than 2 common radii in the radial range; skipped")
                continue
            a, b, c = resample(g_s, r), resample(g_sp, r), resample(p, r)
            est = estimate_g(r, a, b, c, threshold_um=threshold_um, method=method)
            if not est.determined:
                msgs.append(f"{p.label}: {est.message}")
            estimates.append((p, g_sp, est, r))
        if estimates:
            summ = summarize_g([e.g for _, _, e, _ in estimates])
            results = []
            for p, g_sp, est, r in estimates:
                rms = (
                    rms_error_eq6(resample(g_s, r), resample(g_sp, r), resample(p, r), summ.mean)
                    if summ.n
                    else math.nan
                )
                results.append(PlaneResult(p.focus, p.obj, est, rms))
            summaries.append(FocusSummary(focus, tuple(results), summ))
            if summ.n == 1:
                msgs.append(
                    f"focus {focus.label}: only one determined object plane, so the mean g has "
                    "no precision (it needs at least two planes)"
                )
        if len(members) >= 2:
            ref = members[0]
            r = common_radii(ref, members[1:], r_min, r_max)
            if r.size:
                mat = np.array([resample(p, r) for p in members])
                variations.append(
                    FieldVariation(
                        focus,
                        tuple(p.obj for p in members),
                        r,
                        mat,
                        mat.max(axis=0) - mat.min(axis=0),
                    )
                )
    if gamma_missing:
        msgs.append(
            "γ_ss' (Eq. 2) needs the focal length for distances given in metres; "
            "it was not given, so γ and Brown's prediction are not computed"
        )

    checks = _interpolation_checks(list(gaussian.values()), f, r_min, r_max)
    n_focus = len(focus_keys)
    if len(gaussian) < 2:
        msgs.append(
            f"Brown's Eq. (3)–(4) needs Gaussian profiles at two focus settings; "
            f"{len(gaussian)} available"
        )
    elif len(gaussian) < 3 or not checks:
        msgs.append(
            "Brown's Eq. (3)–(4) can interpolate between the Gaussian profiles, but no third "
            "Gaussian profile lies between two others to check it against"
        )
    if n_focus == 1:
        fc = next(iter(focus_keys.values()))
        msgs.insert(
            0,
            f"one focus setting only ({fc.label}): only the variation of distortion with object "
            "distance at that focus (within the photographic field) is available; g_ss' needs "
            "profiles at two focus settings (δr_s at the focus and δr_s' at the object plane) "
            "besides the object-plane profile δr_ss'",
        )
        if key(fc) not in gaussian:
            msgs.insert(
                1,
                f"no profile with the object in the plane of focus {fc.label}: δr_s is unknown; "
                "γ_ss' (Eq. 2) can still be computed, and Brown's Eq. (1) then implies the "
                "Gaussian profiles δr_s' = γ_ss'·δr_ss' — a model statement, not a measurement",
            )
    if not any(s.summary.n for s in summaries):
        msgs.append("no g_ss' could be determined from these profiles")
    return VariationAnalysis(
        source=ps.source,
        focal_length_mm=f,
        profiles=ps.profiles,
        gammas=tuple(gammas),
        brown=tuple(brown),
        focus_summaries=tuple(summaries),
        field_variation=tuple(variations),
        interpolation_checks=tuple(checks),
        radial_range_mm=(r_min, r_max),
        threshold_um=threshold_um,
        method=method,
        messages=tuple(msgs),
    )


def _interpolation_checks(gaussians: list[Profile], f, r_min, r_max) -> list[InterpolationCheck]:
    scales = [(_scale_or_none(p.focus, f), p) for p in gaussians]
    scales = sorted([(s, p) for s, p in scales if s is not None], key=lambda t: t[0])
    out = []
    for i in range(1, len(scales) - 1):
        (n1, p1), (n, p), (n2, p2) = scales[i - 1], scales[i], scales[i + 1]
        r = common_radii(p, [p1, p2], r_min, r_max)
        if not r.size:
            continue
        alpha = brown_alpha_scales(n, n1, n2)
        meas = resample(p, r)
        pred = brown_interpolate(resample(p1, r), resample(p2, r), alpha)
        out.append(
            InterpolationCheck(
                p.focus, p1.focus, p2.focus, alpha, r, meas, pred, *_misfit(pred, meas)
            )
        )
    return out


def brown_implied_gaussian(analysis: VariationAnalysis) -> dict[str, np.ndarray]:
    """Brown's Eq. (1) inverted: δr_s' = γ_ss' · δr_ss' for each non-Gaussian profile with a γ.

    This is what Eq. (1)–(2) would require of the (unmeasured) Gaussian profiles; useful when no
    Gaussian profile was measured (the paper's Pentax case). Keys are the profile labels."""
    out = {}
    for gm in analysis.gammas:
        for p in analysis.profiles:
            if p.focus == gm.focus and p.obj == gm.obj:
                out[p.label] = gm.gamma * p.dr_um
    return out


# --------------------------------------------------------------------------------------------
# Text and JSON output
# --------------------------------------------------------------------------------------------
