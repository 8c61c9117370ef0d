"""Numba primitives of the real-ray trace: surface intersection, vector refraction, one surface
step and a span of surfaces for a single ray (used by :mod:`.bulk`, :mod:`.aim`, :mod:`.paths`).

Everything here sees only contiguous float64 / int64 arrays and scalars (docs/design.md,
"Performance"); the Python layer in :mod:`raytrace.trace` owns objects, validation and errors.

Geometry (docs/design.md, "Conventions"): millimetres, light toward +z, first vertex at z = 0. A
ray is a point (x, y, z) and unit direction cosines (L, M, N). The lens arrays are those of
:class:`raytrace.packing.PackedLens`: ``kind, c, k, asph, geo, n_in, n_out, sd``, where ``geo`` is
the placement table (:mod:`.codes`, column ``G_ZV`` the vertex z).

Frames (:mod:`raytrace.frames`)
    A ray is carried in the *axis frame* of the surface it last met (the global frame before the
    first surface): the vertex of surface j is at (0, 0, zv_j) of its axis frame and its axis is
    the z axis, so the coaxial code below works in it unchanged. Before a surface flagged
    ``F_FRAME`` the ray is moved into that surface's axis frame (``p' = M p + t``, ``d' = M d``,
    :func:`reframe`); for a centred lens no surface is flagged and nothing is moved. Surfaces
    flagged ``F_SKIP`` (coordinate breaks, the image-frame pseudo-surface) are not traced. The
    final segment is therefore in the image frame, where image planes are z = const.

Mirrors (``F_MIRROR``): ``d' = d − 2 (d·n̂) n̂`` (either orientation of n̂), direction cosines in
the physical sense (after a mirror N < 0 on the axis, as the negative thicknesses of Zemax and
CODE V say). Surfaces flagged ``F_GENERAL`` accept rays travelling toward −z of their axis frame:
the vertex-plane transfer and the quadric root use the direction's sign
``σ = sign(N)`` (``s = σ C / (σ B + sqrt(B² − A C))``, the root continuous with the vertex for
either direction); N = 0 → MISSED. Without the flag (a centred refracting lens) a ray with
N <= 0 is MISSED, as before.

Intersection (cancellation-free curvature form)
    The ray is first transferred to the vertex tangent plane of the surface (local z = 0) at
    (x1, y1). The quadric ``c (x² + y² + (1 + k) z²) − 2 z = 0`` then gives, along the ray
    parameter s (mm), ``A s² − 2 B s + C = 0`` with ``A = c (1 + k N²)``,
    ``B = N − c (x1 L + y1 M)``, ``C = c (x1² + y1²)``; the root continuous with the vertex is
    ``s = C / (B + sqrt(B² − A C))`` — no subtraction of nearly equal numbers, exact for c → 0
    (plane). Negative discriminant → MISSED; a root on the far sheet of the quadric
    (``1 − c (1 + k) z <= 0``) → MISSED. Even aspheres and Q-type aspheres: Newton iteration on
    ``z − sag(x² + y²) = 0`` along the ray, started at the conic solution, stopped when the step
    is below 1e-14 mm × (1 + |x| + |y| + |z|); more than ``NEWTON_MAX`` steps → MISSED. A Q-type
    surface (kinds ``KIND_QBFS``, ``KIND_QCON``; :mod:`raytrace.qtype`) goes through
    :func:`qtype_newton`, a compiled function of its own, called, not inlined, so that the many
    kernels that inline this step grow by one call and one linked copy of it (numba compile
    time); the vectorised bulk passes (:mod:`.bulk`) do not hold it — packing flags Q-type
    surfaces ``F_SCALAR``, which sends them through this step there too.

Refraction (vector Snell)
    With the unit normal n̂ oriented along the ray (cos I = d·n̂ >= 0) and μ = n/n':
    ``sin² I' = μ² (1 − cos² I)``; > 1 → TIR; ``d' = μ d + (cos I' − μ cos I) n̂``. The scalar
    path (chief rays, ray paths) and the asphere surfaces renormalise d'; the vectorised bulk path
    for planes and quadrics does not (|d'| = 1 exactly in exact arithmetic; on a sphere the
    normal (−c x, −c y, 1 − c z) is unit without normalisation): the direction cosines stay unit
    length to <= 2e-15 over 11 surfaces.

Clear apertures (``F_APERTURE``, clipping on): circle / rectangle / ellipse of half-widths
(hx, hy) about (x0, y0) in the surface frame, besides the semi-diameter about the vertex.

Travelling backwards (``STATUS_BACKWARD``)
    The path length from the point where the ray met the previous surface to the point on this
    one is ``t = d·(p_new − p_old)`` (d the unit direction: exact for a point on the line; frame
    moves are rigid and keep it). A surface that *acts* on the ray (it refracts, n ≠ n', or
    reflects) must be reached from the last acting surface by a path ``T = Σ t`` (summed over the
    dummy surfaces between, where the ray goes straight on) with
    ``T ≥ −BACKWARD_TOL (1 mm + |z_vertex|)``; otherwise the ray would have to travel
    against its direction — the surfaces overlap (a negative air gap, a curved surface reaching
    past one set at zero distance) — and it fails with BACKWARD instead of passing with a silent
    number. The sign is taken along the current direction, so the reversed direction after a
    mirror and the moved frames of placed surfaces count correctly; T ≈ 0 within the tolerance
    (coincident surfaces, round-off) passes. Dummy surfaces (n = n', no mirror: reference planes,
    a stop drawn in air, CODE V / Zemax test files of decenters) may be reached virtually, as the
    source programs allow. Before the first acting surface nothing is checked: a ray is a line
    that may start anywhere before it (for an object at infinity a point on the vertex plane of
    surface 1, behind a concave first surface). Callers that carry T (:func:`trace_span`, the
    bulk trace) pass ``t_before`` and ``check``; a bare call (``check = -1``) measures T from the
    incoming point and checks once any surface before j is traced. Not detected: overlaps off
    the ray's path (semi-diameters are the lens's business: :func:`raytrace.lens.check_physical`).

Status codes: OK 0, MISSED 1, TIR 2, CLIPPED 3 (outside the semi-diameter or clear aperture, when
clipping is on), AIM_FAILED 4, BACKWARD 5. A failed ray carries the 1-based number of the surface
where it failed and NaN coordinates; every ray gets a status.
"""

from __future__ import annotations

import math

from .codes import (
    F_APERTURE,
    F_FRAME,
    F_GENERAL,
    F_MIRROR,
    F_SKIP,
    G_AP,
    G_FLAGS,
    G_LENS,
    G_REL,
    G_RELT,
    G_ZV,
    KIND_ASPHERE,
    KIND_PLANE,
    KIND_QCON,
    KIND_QUADRIC,
    L_COAXIAL,
    STATUS_BACKWARD,
    STATUS_CLIPPED,
    STATUS_MISSED,
    STATUS_OK,
    STATUS_TIR,
)
from .forbes import qbfs_sum
from .jit import kernel

NEWTON_MAX = 60
NEWTON_TOL = 1e-14
#: relative tolerance of the backward-travel test (module docstring): t < -BACKWARD_TOL * scale
BACKWARD_TOL = 1e-9


@kernel(error_model="numpy", inline="always")
def path_length(x0, y0, z0, x1, y1, z1, L, M, N):
    """Signed path length (mm) from (x0, y0, z0) to (x1, y1, z1) along the unit direction
    (L, M, N) of the line through both."""
    return L * (x1 - x0) + M * (y1 - y0) + N * (z1 - z0)


@kernel(error_model="numpy", inline="always")
def backward_limit(zvj):
    """The most negative path (mm) still taken as forward at a surface whose vertex is at z =
    zvj of its axis frame: −BACKWARD_TOL (1 mm + |zvj|) (module docstring)."""
    return -BACKWARD_TOL * (1.0 + abs(zvj))


@kernel(error_model="numpy", inline="always")
def traced_before(geo, j, coaxial):
    """True when some surface before j is traced (not ``F_SKIP``): the check of a bare
    :func:`surface_step` call (``check = -1``)."""
    if coaxial:
        return j > 0
    for i in range(j):
        if (int(geo[i, G_FLAGS]) & F_SKIP) == 0:
            return True
    return False


@kernel(error_model="numpy", inline="always")
def acts(geo, j, n_in, n_out):
    """True when surface j acts on a ray (refracts with n ≠ n', or reflects) and is traced."""
    fl = int(geo[j, G_FLAGS])
    if (fl & F_SKIP) != 0:
        return False
    return (fl & F_MIRROR) != 0 or n_in[j] != n_out[j]


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
def newton_step(x, y, zl, sag, gp, L, M, N):
    """One Newton step along the unit direction (L, M, N) toward the surface z = sag: the point
    (x, y, zl) (surface frame, zl from the vertex) moves by ``ds = −(zl − sag) / gp``, with gp
    the derivative of zl − sag along the ray. Returns (ok, x, y, zl, done): ok False (the
    caller's MISSED) where gp is 0 or not finite; done when |ds| <= NEWTON_TOL (1 + |x| + |y| +
    |zl|), the stopping rule of every Newton intersection (module docstring)."""
    if gp == 0.0 or not math.isfinite(gp):
        return False, x, y, zl, False
    ds = -(zl - sag) / gp
    x += ds * L
    y += ds * M
    zl += ds * N
    return True, x, y, zl, abs(ds) <= NEWTON_TOL * (1.0 + abs(x) + abs(y) + abs(zl))


@kernel(error_model="numpy", inline="always")
def newton_intersect(sag_gp, params, x, y, zl, L, M, N):
    """The intersection of the ray through (x, y, zl) (surface frame, zl from the vertex) along
    the unit direction (L, M, N) with the surface z = sag, by :func:`newton_step` from that
    point, at most ``NEWTON_MAX`` steps. ``sag_gp(params, x, y, L, M, N)`` gives (ok, sag, gp)
    at (x, y): the sag, the derivative of zl − sag along the ray, ok False outside the
    surface's domain. Returns (ok, x, y, zl); ok False when the iteration leaves the domain,
    stalls or does not converge (the caller's MISSED)."""
    for _ in range(NEWTON_MAX):
        ok, sag, gp = sag_gp(params, x, y, L, M, N)
        if not ok:
            return False, x, y, zl
        ok, x, y, zl, done = newton_step(x, y, zl, sag, gp, L, M, N)
        if not ok:
            return False, x, y, zl
        if done:
            return True, x, y, zl
    return False, x, y, zl


@kernel(error_model="numpy", inline="always")
def _asphere_sag_gp(params, x, y, L, M, N):
    """(ok, sag, gp) of the even asphere ``params`` = (c, k, asph, j) (:func:`asphere_sag`)
    for :func:`newton_intersect`."""
    c, k, asph, j = params
    sag, dsag, ok = asphere_sag(c, k, asph, j, x * x + y * y)
    return ok, sag, N - 2.0 * dsag * (x * L + y * M)


_qbfs_sum = kernel(error_model="numpy", inline="always")(qbfs_sum)


@kernel(error_model="numpy", inline="always")
def qtype_sag(con, c, k, coef, j, rho):
    """Q-type sag z and dz/dρ at ρ = x² + y² (mm²) (:mod:`raytrace.qtype`) on the base conic
    (c, k): Qbfs (``con`` False) or Qcon (True), with row j of ``coef`` = (1/ρ_max²,
    coefficients of the sum in the basis P_m, :meth:`raytrace.qtype.QType.packed_row`); ok False
    outside the conic's domain. Departure E(x) Φ(ρ) S(x) with, for Qbfs, E = x(1 − x) and
    Φ = √(1 + z_conic'²), for Qcon E = x² and Φ = 1 (blended, not branched: one code path)."""
    cc = c * c
    arg = 1.0 - (1.0 + k) * cc * rho
    if not (arg > 0.0):
        return 0.0, 0.0, False
    q = math.sqrt(arg)
    w = coef[j, 0]
    x = rho * w  # u²
    s, ds = _qbfs_sum(coef, j, x)
    f = 1.0 if con else 0.0
    g = 1.0 - f
    e = x * (f * x + g * (1.0 - x))
    de = f * 2.0 * x + g * (1.0 - 2.0 * x)
    phi = math.sqrt((1.0 - k * cc * rho) / arg)  # √(1 + z_conic'²): along the conic's normal
    ph = f + g * phi
    dph = g * 0.5 * cc / (phi * arg * arg)  # dφ/dρ = c² / (2 φ arg²)
    z = c * rho / (1.0 + q) + e * ph * s
    dz = 0.5 * c / q + w * ph * (de * s + e * ds) + e * s * dph
    return z, dz, True


@kernel(error_model="numpy")
def qtype_newton(con, c, k, coef, j, x, y, zl, L, M, N):
    """The intersection with a Q-type surface (:func:`qtype_sag`) by the Newton iteration of the
    even-asphere branch of :func:`surface_step` (same step, stopping rule and ``NEWTON_MAX``),
    from the point (x, y, zl) on the ray (surface frame, zl from the vertex). Returns (ok, x, y,
    zl, dz/dρ at the point); ok False when it leaves the conic's domain, stalls or does not
    converge. A compiled function of its own, called, not inlined, with one sag evaluation in
    its loop (the one after the last step gives the normal): numba links a copy of it into
    every kernel that calls :func:`surface_step`, so its size is compile time (module
    docstring)."""
    done = False
    for it in range(NEWTON_MAX + 1):
        sag, dsag, ok = qtype_sag(con, c, k, coef, j, x * x + y * y)
        if not ok:
            return False, x, y, zl, 0.0
        if done:
            return True, x, y, zl, dsag
        if it == NEWTON_MAX:
            break
        gp = N - 2.0 * dsag * (x * L + y * M)
        ok, x, y, zl, done = newton_step(x, y, zl, sag, gp, L, M, N)
        if not ok:
            return False, x, y, zl, 0.0
    return False, x, y, zl, 0.0


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
def unit(x, y, z):
    """The vector (x, y, z) divided by its length."""
    inv = 1.0 / math.sqrt(x * x + y * y + z * z)
    return x * inv, y * inv, z * inv


@kernel(error_model="numpy", inline="always")
def refract(L, M, N, nx, ny, nz, mu):
    """:func:`snell` at the normal (nx, ny, nz) of any length, the refracted direction
    renormalised (the scalar path; module docstring, "Refraction"). Returns (tir, L', M', N');
    on total internal reflection (tir True) the direction is returned unchanged."""
    nx, ny, nz = unit(nx, ny, nz)
    L2, M2, N2, sin2t = snell(L, M, N, nx, ny, nz, mu, mu * mu)
    if sin2t > 1.0:
        return True, L, M, N
    L2, M2, N2 = unit(L2, M2, N2)
    return False, L2, M2, N2


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
def vertex_plane_root(c, k, zvj, x, y, z, L, M, N):
    """The ray (x, y, z) + t (L, M, N) (axis frame, travelling toward +z) carried to the vertex
    tangent plane z = zvj of a surface, and its quadric root from there: (t0, x1, y1, s, hit)
    with t0 the path (mm) to the plane, (x1, y1) the point on it and s, hit as
    :func:`quadric_root`."""
    t0 = (zvj - z) / N
    x1 = x + t0 * L
    y1 = y + t0 * M
    s, hit = quadric_root(c, k, x1, y1, L, M, N)
    return t0, x1, y1, s, hit


@kernel(error_model="numpy", inline="always")
def reframe(geo, j, x, y, z, L, M, N):
    """The ray (x, y, z, L, M, N) moved into surface j's axis frame: p' = M p + t, d' = M d with
    M = geo[j, G_REL:G_REL + 9] (row-major) and t = geo[j, G_RELT:G_RELT + 3]."""
    m0 = geo[j, G_REL]
    m1 = geo[j, G_REL + 1]
    m2 = geo[j, G_REL + 2]
    m3 = geo[j, G_REL + 3]
    m4 = geo[j, G_REL + 4]
    m5 = geo[j, G_REL + 5]
    m6 = geo[j, G_REL + 6]
    m7 = geo[j, G_REL + 7]
    m8 = geo[j, G_REL + 8]
    xn = m0 * x + m1 * y + m2 * z + geo[j, G_RELT]
    yn = m3 * x + m4 * y + m5 * z + geo[j, G_RELT + 1]
    zn = m6 * x + m7 * y + m8 * z + geo[j, G_RELT + 2]
    Ln = m0 * L + m1 * M + m2 * N
    Mn = m3 * L + m4 * M + m5 * N
    Nn = m6 * L + m7 * M + m8 * N
    return xn, yn, zn, Ln, Mn, Nn


@kernel(error_model="numpy", inline="always")
def enter(geo, j, x, y, z, L, M, N):
    """The ray moved into surface j's axis frame where j is flagged ``F_FRAME`` (:func:`reframe`),
    and whether j is not traced (``F_SKIP``): (skip, x, y, z, L, M, N)."""
    fl = int(geo[j, G_FLAGS])
    if (fl & F_FRAME) != 0:
        x, y, z, L, M, N = reframe(geo, j, x, y, z, L, M, N)
    return (fl & F_SKIP) != 0, x, y, z, L, M, N


@kernel(error_model="numpy", inline="always")
def outside_aperture(geo, j, x, y):
    """True when (x, y) (surface frame) lies outside surface j's clear aperture."""
    shape = geo[j, G_AP]
    u = (x - geo[j, G_AP + 3]) / geo[j, G_AP + 1]
    v = (y - geo[j, G_AP + 4]) / geo[j, G_AP + 2]
    if shape == 2.0:
        return abs(u) > 1.0 or abs(v) > 1.0
    return u * u + v * v > 1.0


@kernel(error_model="numpy", inline="always")
def surface_step(
    kind,
    c,
    k,
    asph,
    geo,
    j,
    mu,
    sdj,
    clip,
    x,
    y,
    z,
    L,
    M,
    N,
    coaxial=False,
    t_before=0.0,
    check=-1,
    qtype=True,
):
    """Intersect surface j and refract (or reflect). The ray is in surface j's axis frame
    (module docstring). Returns (status, x, y, z, L, M, N) with the point on the surface (axis
    frame) and the direction after it; status != 0 leaves the values meaningless.

    ``t_before``: path (mm) from the last acting surface to the incoming point; ``check``: 1 / 0
    apply / skip the backward-travel test, -1 decide by :func:`traced_before` (module
    docstring, "Travelling backwards").

    ``coaxial=True`` (a literal at the call site, for a lens without any flag: lens flag
    ``L_COAXIAL``) skips reading the surface's flags; after inlining the branches it leaves are
    compiled away, so the coaxial path costs what it did before placements existed.
    ``qtype=False`` (a literal, for kernels that never see a Q-type surface: the tolerancing
    instance kernels, whose lenses :func:`raytrace.tolerance.check_against_lens` refuses) leaves
    :func:`qtype_newton` out of the compiled kernel; a Q-type surface is then MISSED."""
    fl = 0 if coaxial else int(geo[j, G_FLAGS])
    zvj = geo[j, G_ZV]
    if (fl & F_GENERAL) != 0:
        if N == 0.0 or not math.isfinite(N):
            return STATUS_MISSED, x, y, z, L, M, N
    elif not (N > 0.0):
        return STATUS_MISSED, x, y, z, L, M, N
    sg = 1.0 if (coaxial or N > 0.0) else -1.0
    x0 = x
    y0 = y
    z0 = z
    t0 = (zvj - z) / N
    x = x + t0 * L
    y = y + t0 * M
    zl = 0.0
    nx = 0.0
    ny = 0.0
    nz = 1.0
    if kind != KIND_PLANE:
        s, have = quadric_root(c, k, x, y, sg * L, sg * M, sg * N)
        s *= sg
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
            if kind == KIND_ASPHERE:
                ok, x, y, zl = newton_intersect(_asphere_sag_gp, (c, k, asph, j), x, y, zl, L, M, N)
                if not ok:
                    return STATUS_MISSED, x, y, z, L, M, N
                sag, dsag, ok = asphere_sag(c, k, asph, j, x * x + y * y)
                if not ok:
                    return STATUS_MISSED, x, y, z, L, M, N
            elif qtype:
                ok, x, y, zl, dsag = qtype_newton(
                    kind == KIND_QCON, c, k, asph, j, x, y, zl, L, M, N
                )
                if not ok:
                    return STATUS_MISSED, x, y, z, L, M, N
            else:
                return STATUS_MISSED, x, y, z, L, M, N
            nx = -2.0 * x * dsag
            ny = -2.0 * y * dsag
            nz = 1.0
    z = zvj + zl
    if check != 0 and ((fl & F_MIRROR) != 0 or mu != 1.0):
        t = t_before + path_length(x0, y0, z0, x, y, z, L, M, N)
        if t < backward_limit(zvj):
            if check == 1 or traced_before(geo, j, coaxial):
                return STATUS_BACKWARD, x, y, z, L, M, N
    if clip:
        if x * x + y * y > sdj * sdj:
            return STATUS_CLIPPED, x, y, z, L, M, N
        if (fl & F_APERTURE) != 0 and outside_aperture(geo, j, x, y):
            return STATUS_CLIPPED, x, y, z, L, M, N
    if (fl & F_MIRROR) != 0:
        nx, ny, nz = unit(nx, ny, nz)
        g = 2.0 * (L * nx + M * ny + N * nz)
        L, M, N = unit(L - g * nx, M - g * ny, N - g * nz)
    elif mu != 1.0:
        tir, L, M, N = refract(L, M, N, nx, ny, nz, mu)
        if tir:
            return STATUS_TIR, x, y, z, L, M, N
    return STATUS_OK, x, y, z, L, M, N


@kernel(error_model="numpy", inline="always")
def trace_span(kind, c, k, asph, geo, n_in, n_out, sd, j0, j1, clip, x, y, z, L, M, N):
    """Trace surfaces j0 .. j1-1 (0-based) of the packed lens; the ray comes in the axis frame of
    the last traced surface before j0 (global for j0 = 0) and leaves in that of the last one
    traced (for j1 = n: the image frame). Returns (status, surface_1based, x, y, z, L, M, N)."""
    # the ray starts on the last surface traced before j0: when that surface acts, the path
    # since the last acting surface is 0 and the backward-travel test applies at once; when it is
    # a dummy (a stop in air) the path from the acting surface before it is not known here, and
    # the test starts at the next acting surface (the full trace of the bulk kernels checks it)
    acted = False
    for jb in range(j0 - 1, -1, -1):
        if (int(geo[jb, G_FLAGS]) & F_SKIP) == 0:
            acted = acts(geo, jb, n_in, n_out)
            break
    tacc = 0.0  # path since the last acting surface
    if (int(geo[0, G_LENS]) & L_COAXIAL) != 0:  # a centred refracting lens: no flags to read
        for j in range(j0, j1):
            x0, y0, z0, L0, M0, N0 = x, y, z, L, M, N
            st, x, y, z, L, M, N = surface_step(
                kind[j], c[j], k[j], asph, geo, j, n_in[j] / n_out[j], sd[j], clip,
                x, y, z, L, M, N, True, tacc, 1 if acted else 0,
            )  # fmt: skip
            if st != STATUS_OK:
                return st, j + 1, x, y, z, L, M, N
            if n_in[j] != n_out[j]:
                acted = True
                tacc = 0.0
            else:
                tacc += path_length(x0, y0, z0, x, y, z, L0, M0, N0)
        return STATUS_OK, 0, x, y, z, L, M, N
    for j in range(j0, j1):
        skip, x, y, z, L, M, N = enter(geo, j, x, y, z, L, M, N)
        if skip:
            continue
        x0, y0, z0, L0, M0, N0 = x, y, z, L, M, N
        st, x, y, z, L, M, N = surface_step(
            kind[j], c[j], k[j], asph, geo, j, n_in[j] / n_out[j], sd[j], clip, x, y, z, L, M, N,
            False, tacc, 1 if acted else 0,
        )  # fmt: skip
        if st != STATUS_OK:
            return st, j + 1, x, y, z, L, M, N
        if acts(geo, j, n_in, n_out):
            acted = True
            tacc = 0.0
        else:
            tacc += path_length(x0, y0, z0, x, y, z, L0, M0, N0)
    return STATUS_OK, 0, x, y, z, L, M, N
