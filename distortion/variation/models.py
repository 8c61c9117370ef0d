"""Brown's and Fraser & Shortis' models of the variation of radial distortion with object
distance (Fraser & Shortis 1992, Eqs. 1–6), and the distances / image scales they take.

* Brown (1971), Eqs. (1)–(2): ``δr_ss' = δr_s' / γ_ss'``, ``γ_ss' = (s'/s)·(s − f)/(s' − f)``.
* Brown (1971), Eqs. (3)–(4): ``δr_s = α_s δr_s1 + (1 − α_s) δr_s2``,
  ``α_s = (s2 − s)/(s2 − s1) · (s1 − f)/(s − f)``.
* Fraser & Shortis, Eqs. (5)–(6): ``δr_ss' = δr_s + g_ss' (δr_s' − δr_s)``.

Distances are POSITIVE magnitudes from the lens (Brown's thin-lens model), same unit as f, all
beyond f; an image scale "N×" is a Gaussian magnification −1/N, ``s = f(1 + N)``. See
:mod:`distortion.variation.analysis` for the notation of the profiles.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from raytrace.paraxial.orthoscopy import object_distance_for_magnification

from ..errors import DataError

WEAK_THRESHOLD_UM = 0.5
"""Default threshold (µm) on |δr_s' − δr_s| below which g_ss' is weakly determined (the paper's
Figs. 5–6 captions: "very small variation of distortion (<0.5 micrometres)")."""

#: a plain distance (metres) this large looks like millimetres (parse_conjugate and the profile
#: CSV reader warn)
PLAIN_METRES_WARN = 100.0

INTERPOLATION = (
    "PCHIP (Fritsch-Carlson monotone piecewise cubic) interpolation of the Gaussian profiles "
    "delta_r_s, delta_r_s' onto the radii of the measured delta_r_ss' profile, no extrapolation"
)

# --------------------------------------------------------------------------------------------
# Distances, image scales
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Conjugate:
    """A focused or object distance as typed by a user.

    ``unit`` is ``"m"`` (``value`` = distance from the lens in metres, positive; ``inf`` allowed)
    or ``"x"`` (``value`` = image scale number N, Gaussian magnification −1/N).
    """

    value: float
    unit: str
    text: str = field(default="", compare=False)

    def __post_init__(self) -> None:
        if self.unit not in ("m", "x"):
            raise DataError(f"unknown distance unit {self.unit!r} (expected 'm' or 'x')")
        if not self.value > 0:
            what = "image scale" if self.unit == "x" else "distance"
            raise DataError(f"{what} must be positive, got {self.text or self.value!r}")

    @classmethod
    def metres(cls, value: float) -> Conjugate:
        return cls(float(value), "m", f"{value:g} m")

    @classmethod
    def scale(cls, n: float) -> Conjugate:
        return cls(float(n), "x", f"{n:g}x")

    def image_scale(self, focal_length_mm: float | None) -> float:
        """Image scale number N (thin lens, unit focusing: N = s/f − 1). Needs f for metres."""
        if self.unit == "x":
            return self.value
        if focal_length_mm is None:
            raise DataError(
                f"distance {self.label} is in metres: the focal length is needed to convert it "
                "to an image scale (give focal_length_mm)"
            )
        return scale_from_distance(self.value * 1000.0, focal_length_mm)

    def distance_mm(self, focal_length_mm: float | None) -> float:
        """Object distance from the lens in mm (s = f(1 + N) for an image scale)."""
        if self.unit == "m":
            return self.value * 1000.0
        if focal_length_mm is None:
            raise DataError(f"image scale {self.label} needs the focal length to become a distance")
        return distance_from_scale(self.value, focal_length_mm)

    @property
    def label(self) -> str:
        """Short label: ``12×`` or ``1.5 m``."""
        if self.unit == "x":
            return f"{self.value:g}×"
        return "∞" if math.isinf(self.value) else f"{self.value:g} m"


def scale_from_distance(s: float, f: float) -> float:
    """Image scale N = s/f − 1 for an object at distance s (> f, same unit as f) from a thin lens
    focused on it (Gaussian magnification −1/N). s = inf gives N = inf."""
    _check_distance(s, f)
    return math.inf if math.isinf(s) else s / f - 1.0


def distance_from_scale(n: float, f: float) -> float:
    """Object distance s = f(1 + N) of image scale N (thin lens, unit focusing), unit of f: the
    magnitude of Pestrecov's Eq. (5) inverted for m0 = −1/N."""
    if not n > 0:
        raise DataError(f"image scale must be positive, got {n!r}")
    return -object_distance_for_magnification(f, -1.0 / n)


def _check_distance(s: float, f: float) -> None:
    if not f > 0:
        raise DataError(f"focal length must be positive, got {f!r}")
    if not s > f:
        raise DataError(
            f"object distance {s:g} is not beyond the focal length {f:g}: no real image "
            "(distances are positive magnitudes from the lens, same unit as f)"
        )


# --------------------------------------------------------------------------------------------
# Brown Eq. (1)-(4)
# --------------------------------------------------------------------------------------------


def brown_gamma(s: float, s_prime: float, f: float) -> float:
    """Brown's γ_ss' = c_s'/c_s = (s'/s)·(s − f)/(s' − f), Fraser & Shortis Eq. (2).

    s: focused object distance, s_prime: object distance, f: focal length — positive, same unit,
    s, s' > f; ``inf`` allowed (limits taken analytically).
    """
    return brown_gamma_scales(scale_from_distance(s, f), scale_from_distance(s_prime, f))


def brown_gamma_scales(n: float, n_prime: float) -> float:
    """Eq. (2) in image scales (s = f(1 + N)): γ_ss' = N (1 + N') / (N' (1 + N)) = c_s'/c_s with
    c = f(1 + 1/N). N: focused scale, N': object-plane scale; ``inf`` allowed."""
    if not (n > 0 and n_prime > 0):
        raise DataError(f"image scales must be positive, got {n!r}, {n_prime!r}")
    c_s = 1.0 + (0.0 if math.isinf(n) else 1.0 / n)
    c_sp = 1.0 + (0.0 if math.isinf(n_prime) else 1.0 / n_prime)
    return c_sp / c_s


def brown_predict(dr_s_prime: np.ndarray, gamma: float) -> np.ndarray:
    """Brown's Eq. (1): δr_ss' = δr_s' / γ_ss' (same radii, same unit as the input)."""
    return np.asarray(dr_s_prime, dtype=float) / gamma


def brown_alpha(s: float, s1: float, s2: float, f: float) -> float:
    """Brown's α_s = (s2 − s)/(s2 − s1) · (s1 − f)/(s − f), Eq. (4).

    Positive distances (unit of f), all > f; s1 ≠ s2; ``inf`` allowed for any of them.
    α_s = 1 at s = s1 and 0 at s = s2.
    """
    return brown_alpha_scales(*(scale_from_distance(d, f) for d in (s, s1, s2)))


def brown_alpha_scales(n: float, n1: float, n2: float) -> float:
    """Eq. (4) in image scales: α = (t − t2)/(t1 − t2) with t = 1/N ∝ 1/(s − f)."""
    t, t1, t2 = (0.0 if math.isinf(v) else 1.0 / v for v in (n, n1, n2))
    if t1 == t2:
        raise DataError("Eq. (4) needs two different calibrated focus settings s1 ≠ s2")
    return (t - t2) / (t1 - t2)


def brown_interpolate(dr_s1: np.ndarray, dr_s2: np.ndarray, alpha: float) -> np.ndarray:
    """Brown's Eq. (3): δr_s = α_s δr_s1 + (1 − α_s) δr_s2 (same radii for both profiles)."""
    return alpha * np.asarray(dr_s1, dtype=float) + (1.0 - alpha) * np.asarray(dr_s2, dtype=float)


# --------------------------------------------------------------------------------------------
# Fraser-Shortis Eq. (5)-(6)
# --------------------------------------------------------------------------------------------


def fs_predict(dr_s: np.ndarray, dr_s_prime: np.ndarray, g: float) -> np.ndarray:
    """Fraser & Shortis Eq. (6): δr_ss' = δr_s + g_ss' (δr_s' − δr_s)."""
    dr_s = np.asarray(dr_s, dtype=float)
    return dr_s + g * (np.asarray(dr_s_prime, dtype=float) - dr_s)
