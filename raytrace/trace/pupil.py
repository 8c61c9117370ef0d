"""Pupil sampling and ray bundles aimed about the real chief ray.

A bundle for one field is made of rays that fill the paraxial entrance pupil (diameter EPD at the
paraxial entrance-pupil plane z = z_E0) *centred on the real chief ray*: for an object at
infinity the rays are parallel to the real chief ray and cross the plane z_E0 at the chief ray's
crossing point offset by (px, py)·EPD/2; for a finite object they leave the object point toward
those points. (px, py) are normalised pupil coordinates, px² + py² ≤ 1; +py is the +y (meridional)
direction, +px the +x (sagittal) one.

Patterns (:func:`pupil_points`):

``rings``      equal-area rings, ρ_k = √((k − ½)/n), ``per_ring`` rays each (alternate rings turned
               by half a step): every ray stands for the same pupil area, so RMS values and the
               least-RMS focus are those of a uniformly filled pupil.
``hexapolar``  the axis ray plus rings at ρ = k/n with 6k rays (the classic spot-diagram pattern).
``square``     a square grid clipped to the unit circle (n points across, n >= 3: with 1 or 2
               points across every grid point is a corner (±1, ±1), outside the pupil).
``fan_y``, ``fan_x``  n points from −1 to 1 along py (tangential) or px (sagittal).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import limits
from ..errors import TraceError
from ..lens import Lens
from ..paraxial.firstorder import ParaxialResult
from ..units import is_whole

PATTERNS = ("rings", "hexapolar", "square", "fan_y", "fan_x")
#: memory per ray of a fan or spot diagram (bytes, about: the trace and its output), for the
#: size a refused request would have taken
SAMPLE_BYTES = 200


def pupil_count(pattern: str, n: int, *, per_ring: int = 24) -> int:
    """How many rays :func:`pupil_points` gives for ``pattern`` and ``n``, counted without making
    them (``square`` beyond 100 000 points across: π/4·n², above every work limit)."""
    n = int(n)
    if pattern == "rings":
        return n * per_ring
    if pattern == "hexapolar":
        return 1 + 3 * n * (n + 1)
    if pattern == "square":
        if n > 100_000:
            return round(math.pi / 4 * n * n)
        g = np.linspace(-1.0, 1.0, n)
        half = np.sqrt(np.clip(1.0 + 1e-12 - g * g, 0.0, None))  # |x| allowed in each row
        return int(np.sum(np.searchsorted(g, half, side="right") - np.searchsorted(g, -half)))
    return n


def check_sampling(
    pattern: str,
    n,
    *,
    per_ring: int = 24,
    allow_large: bool = False,
    words: tuple[str, str, str] = ("n={n}", "pattern={pattern!r} with n={n}", "allow_large=True"),
) -> int:
    """The ray count of ``pattern`` and ``n`` (:func:`pupil_count`), or :class:`TraceError`:
    an unknown pattern, ``n`` not a whole number ≥ 1, a square grid with no point inside the
    pupil (n < 3), more than :data:`raytrace.limits.MAX_SAMPLES` rays without ``allow_large``
    (counted, not made). ``words``: how the caller says ``n`` and the pattern (format strings)
    and how the limit is lifted (the command line names its flags)."""
    say_n, say_pattern, lift = words
    name = say_n.split("{")[0].rstrip("= ")
    if pattern not in PATTERNS:
        raise TraceError(f"unknown pupil pattern {pattern!r}; use one of {', '.join(PATTERNS)}")
    if not (is_whole(n) and n >= 1):
        raise TraceError(f"pupil sampling {name} must be a whole number, at least 1, got {n!r}")
    if pattern == "square" and n < 3:
        raise TraceError(
            f"{say_pattern.format(pattern=pattern, n=n)}: a grid of {n} point(s) across has no "
            f"point inside the pupil (its points are corners (±1, ±1)); give "
            f"{say_n.format(n=3)} or more"
        )
    count = pupil_count(pattern, n, per_ring=per_ring)
    if count > limits.MAX_SAMPLES and not allow_large:
        fan = pattern in ("fan_y", "fan_x")
        given = say_n.format(n=n) if fan else say_pattern.format(pattern=pattern, n=n)
        raise TraceError(
            f"{given}: {count} rays, more than {limits.MAX_SAMPLES} "
            f"(about {count * SAMPLE_BYTES / 1e9:.3g} GB and a long run); give {lift} to run it "
            "anyway"
        )
    return count


def pupil_points(
    pattern: str, n: int, *, per_ring: int = 24, allow_large: bool = False
) -> tuple[np.ndarray, np.ndarray]:
    """Normalised pupil coordinates (px, py) of a sampling ``pattern`` (module docstring).

    ``n`` is a whole number (rings, or points across); more than
    :data:`raytrace.limits.MAX_SAMPLES` rays are refused, before any is made, unless
    ``allow_large=True``.
    """
    check_sampling(pattern, n, per_ring=per_ring, allow_large=allow_large)
    if pattern == "rings":
        k = np.arange(1, n + 1)
        rho = np.repeat(np.sqrt((k - 0.5) / n), per_ring)
        step = 2 * np.pi / per_ring
        th = np.tile(np.arange(per_ring) * step, n) + np.repeat((k % 2) * 0.5 * step, per_ring)
        return rho * np.cos(th), rho * np.sin(th)
    if pattern == "hexapolar":
        px, py = [0.0], [0.0]
        for k in range(1, n + 1):
            th = np.arange(6 * k) * (2 * np.pi / (6 * k))
            px += list(k / n * np.cos(th))
            py += list(k / n * np.sin(th))
        return np.array(px), np.array(py)
    if pattern == "square":
        g = np.linspace(-1.0, 1.0, n)
        X, Y = np.meshgrid(g, g)
        keep = X**2 + Y**2 <= 1.0 + 1e-12
        return X[keep], Y[keep]
    t = np.linspace(-1.0, 1.0, n) if n > 1 else np.zeros(1)
    z = np.zeros_like(t)
    return (z, t) if pattern == "fan_y" else (t, z)


@dataclass(frozen=True, eq=False)
class Bundle:
    """Rays of one field, ready for :func:`raytrace.trace.trace_rays`: start points and unit
    directions (mm, (n, 3) arrays each as three 1-D arrays), the pupil coordinates they stand
    for, and the chief ray (start, direction) they are centred on."""

    origins: tuple[np.ndarray, np.ndarray, np.ndarray]
    directions: tuple[np.ndarray, np.ndarray, np.ndarray]
    px: np.ndarray
    py: np.ndarray
    chief_origin: tuple[float, float, float]
    chief_direction: tuple[float, float, float]


def aimed_bundle(
    lens: Lens,
    par: ParaxialResult,
    chief_start: tuple[float, float, float, float],
    px: np.ndarray,
    py: np.ndarray,
) -> Bundle:
    """Rays through the paraxial entrance pupil centred on the real chief ray.

    ``chief_start`` = (y, z, M, N) of the object-space chief ray in the meridional plane
    (:class:`~raytrace.trace.chief.ChiefRays` ``y_start, z_start, M_start, N_start``);
    ``par`` the paraxial data of the same object and wavelength.
    """
    if not math.isfinite(par.z_E0):
        raise TraceError(f"{lens.name}: the entrance pupil is at infinity; cannot aim a bundle")
    y0, z0, M0, N0 = (float(v) for v in chief_start)
    if not all(math.isfinite(v) for v in (y0, z0, M0, N0)):
        raise TraceError("the chief ray of this field failed; no bundle can be aimed about it")
    a = par.epd / 2.0
    zE = par.z_E0
    y_c = y0 + (zE - z0) * M0 / N0  # chief ray crossing of the entrance-pupil plane
    ex, ey = a * np.asarray(px, float), y_c + a * np.asarray(py, float)
    if par.infinite:
        L = np.zeros_like(ex)
        M = np.full_like(ex, M0)
        N = np.full_like(ex, N0)
        x_at, y_at = ex, ey
    else:
        dx, dy, dz = ex, ey - y0, np.full_like(ex, zE - z0)
        nrm = np.sqrt(dx * dx + dy * dy + dz * dz)
        L, M, N = dx / nrm, dy / nrm, dz / nrm
        x_at, y_at = ex, ey
    # start left of every surface: back along each ray from the pupil plane
    z_start = min(0.0, zE, z0 if math.isfinite(z0) else 0.0) - (2.0 * a + abs(y_c) + 1.0)
    s = (z_start - zE) / N
    origins = (x_at + s * L, y_at + s * M, np.full_like(ex, z_start))
    cs = (z_start - zE) / N0
    return Bundle(
        origins,
        (L, M, N),
        np.asarray(px, float),
        np.asarray(py, float),
        (0.0, y_c + cs * M0, z_start),
        (0.0, M0, N0),
    )
