"""Numba primitives of the real-ray trace: surface intersection, vector refraction, one surface
step and a span of surfaces for a single ray (used by :mod:`.bulk`, :mod:`.aim`, :mod:`.paths`).

Everything here sees only contiguous float64 / int64 arrays and scalars (docs/design.md, "Performance"); the Python
layer in :mod:`raytrace.trace` owns objects, validation and errors.

Geometry (docs/design.md, "Conventions"): millimetres, light toward +z, first vertex at z = 0. A ray is a point
(x, y, z) and unit direction cosines (L, M, N). The lens arrays are those of
:class:`raytrace.lens.PackedLens`: ``kind, c, k, asph, zv, n_in, n_out, sd``.

Intersection (cancellation-free curvature form)
    The ray is first transferred to the vertex tangent plane of the surface (local z = 0) at
    (x1, y1). The quadric ``c (x² + y² + (1 + k) z²) − 2 z = 0`` then gives, along the ray
    parameter s (mm), ``A s² − 2 B s + C = 0`` with ``A = c (1 + k N²)``,
    ``B = N − c (x1 L + y1 M)``, ``C = c (x1² + y1²)``; the root continuous with the vertex is
    ``s = C / (B + sqrt(B² − A C))`` — no subtraction of nearly equal numbers, exact for c → 0
    (plane). Negative discriminant → MISSED; a root on the far sheet of the quadric
    (``1 − c (1 + k) z <= 0``) → MISSED. Even aspheres: Newton iteration on
    ``z − sag(x² + y²) = 0`` along the ray, started at the conic solution, stopped when the step
    is below 1e-14 mm × (1 + |x| + |y| + |z|); more than ``NEWTON_MAX`` steps → MISSED.

Refraction (vector Snell)
    With the unit normal n̂ oriented along the ray (cos I = d·n̂ >= 0) and μ = n/n':
    ``sin² I' = μ² (1 − cos² I)``; > 1 → TIR; ``d' = μ d + (cos I' − μ cos I) n̂``. The scalar
    path (chief rays, ray paths) and the asphere surfaces renormalise d'; the vectorised bulk path
    for planes and quadrics does not (|d'| = 1 exactly in exact arithmetic; on a sphere the
    normal (−c x, −c y, 1 − c z) is unit without normalisation): the direction cosines stay unit
    length to <= 2e-15 over 11 surfaces.

Status codes: OK 0, MISSED 1, TIR 2, CLIPPED 3 (outside the semi-diameter, when clipping is on),
AIM_FAILED 4. A failed ray carries the 1-based number of the surface where it failed and NaN
coordinates; every ray gets a status.
"""


from __future__ import annotations

import math

from .codes import (
    KIND_PLANE,
    KIND_QUADRIC,
    STATUS_CLIPPED,
    STATUS_MISSED,
    STATUS_OK,
    STATUS_TIR,
)
from .jit import kernel

NEWTON_MAX = 60
NEWTON_TOL = 1e-14


@kernel(error_model="numpy", inline="always")
def asphere_sag(c, k, asph, j, rho):
    """Even-asphere sag z(ρ) and dz/dρ at ρ = x² + y²; ok False outside the conic's domain."""
    arg = 1.0 - (1.0 + k) * c * c * rho
    if not (arg > 0.0):
        return 0.0, 0.0, False
    q = math.sqrt(arg)
    z = c * rho / (1.0 + q)
    dz = 0.5 * c / q
    pw = rho  # ρ^(j+1)
    for m in range(asph.shape[1]):
        a = asph[j, m]
        z += a * pw * rho
        dz += (m + 2) * a * pw
        pw *= rho
    return z, dz, True


@kernel(error_model="numpy", inline="always")
def snell(LL, MM, NN, nx, ny, nz, mu, mu2):
    """Vector Snell refraction of the unit direction (LL, MM, NN) at the unit normal (nx, ny,
    nz), either orientation, with mu = n/n' and mu2 = mu². Returns (L', M', N', sin²θ'); the
    caller flags TIR where sin²θ' > 1 (the direction is then meaningless)."""
    cosi = LL * nx + MM * ny + NN * nz
    sgn = 1.0 if cosi >= 0.0 else -1.0
    cosi *= sgn
    sin2t = mu2 * (1.0 - cosi * cosi)
    g = (math.sqrt(max(1.0 - sin2t, 0.0)) - mu * cosi) * sgn
    return mu * LL + g * nx, mu * MM + g * ny, mu * NN + g * nz, sin2t


@kernel(error_model="numpy", inline="always")
def quadric_root(c, k, x, y, L, M, N):
    """Distance s along the unit direction (L, M, N) from the point (x, y) on a surface's vertex
    tangent plane to the quadric of curvature c and conic k, in the cancellation-free form
    s = C / (B + sqrt(B² − A C)) (exact as c → 0). Returns (s, hit); hit is False where the ray
    misses the quadric or meets only its far branch, and s is then meaningless."""
    A = c * (1.0 + k * N * N)
    B = N - c * (x * L + y * M)
    C = c * (x * x + y * y)
    D = B * B - A * C
    den = B + math.sqrt(max(D, 0.0))
    return C / den, D >= 0.0 and den > 0.0


@kernel(error_model="numpy", inline="always")
def surface_step(kind, c, k, asph, j, zvj, mu, sdj, clip, x, y, z, L, M, N):
    """Intersect one surface and refract. Returns (status, x, y, z, L, M, N) with the point on the
    surface (global z) and the direction after it; status != 0 leaves the values meaningless."""
    if not (N > 0.0):
        return STATUS_MISSED, x, y, z, L, M, N
    t0 = (zvj - z) / N
    x = x + t0 * L
    y = y + t0 * M
    zl = 0.0
    nx = 0.0
    ny = 0.0
    nz = 1.0
    if kind != KIND_PLANE:
        s, have = quadric_root(c, k, x, y, L, M, N)
        if not have:
            s = 0.0
        if kind == KIND_QUADRIC:
            if not have:
                return STATUS_MISSED, x, y, z, L, M, N
            x = x + s * L
            y = y + s * M
            zl = s * N
            w = 1.0 - c * (1.0 + k) * zl
            if not (w > 0.0):
                return STATUS_MISSED, x, y, z, L, M, N
            nx = -c * x
            ny = -c * y
            nz = w
        else:
            x = x + s * L
            y = y + s * M
            zl = s * N
            converged = False
            for _ in range(NEWTON_MAX):
                sag, dsag, ok = asphere_sag(c, k, asph, j, x * x + y * y)
                if not ok:
                    return STATUS_MISSED, x, y, z, L, M, N
                gp = N - 2.0 * dsag * (x * L + y * M)
                if gp == 0.0 or not math.isfinite(gp):
                    return STATUS_MISSED, x, y, z, L, M, N
                ds = -(zl - sag) / gp
                x += ds * L
                y += ds * M
                zl += ds * N
                if abs(ds) <= NEWTON_TOL * (1.0 + abs(x) + abs(y) + abs(zl)):
                    converged = True
                    break
            if not converged:
                return STATUS_MISSED, x, y, z, L, M, N
            sag, dsag, ok = asphere_sag(c, k, asph, j, x * x + y * y)
            if not ok:
                return STATUS_MISSED, x, y, z, L, M, N
            nx = -2.0 * x * dsag
            ny = -2.0 * y * dsag
            nz = 1.0
    z = zvj + zl
    if clip and x * x + y * y > sdj * sdj:
        return STATUS_CLIPPED, x, y, z, L, M, N
    if mu != 1.0:
        inv = 1.0 / math.sqrt(nx * nx + ny * ny + nz * nz)
        nx *= inv
        ny *= inv
        nz *= inv
        L2, M2, N2, sin2t = snell(L, M, N, nx, ny, nz, mu, mu * mu)
        if sin2t > 1.0:
            return STATUS_TIR, x, y, z, L, M, N
        L, M, N = L2, M2, N2
        inv = 1.0 / math.sqrt(L * L + M * M + N * N)
        L *= inv
        M *= inv
        N *= inv
    return STATUS_OK, x, y, z, L, M, N


@kernel(error_model="numpy", inline="always")
def trace_span(kind, c, k, asph, zv, n_in, n_out, sd, j0, j1, clip, x, y, z, L, M, N):
    """Trace surfaces j0 .. j1-1 (0-based). Returns (status, surface_1based, x, y, z, L, M, N)."""
    for j in range(j0, j1):
        st, x, y, z, L, M, N = surface_step(
            kind[j], c[j], k[j], asph, j, zv[j], n_in[j] / n_out[j], sd[j], clip, x, y, z, L, M, N
        )
        if st != STATUS_OK:
            return st, j + 1, x, y, z, L, M, N
    return STATUS_OK, 0, x, y, z, L, M, N

