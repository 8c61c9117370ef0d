"""Lens layout drawing: elements, stop, image plane(s) and real rays per field (meridional section).

Centred lenses, mirrors on the axis included (a mirror is a heavy line hatched on its back); a
lens that is not centred (decenters, tilts, folds) has no paraxial data and is refused in one line
(``raytrace.paraxial.require_centred``).

:func:`layout_rays` computes everything the drawing shows (no matplotlib: usable in tests and
other drawings); :func:`plot_layout` draws it to scale (equal axes, mm, light from left to right).

* **Rays.** Per field the real chief ray (aimed at the centre of the real stop,
  :func:`raytrace.trace.aim`) and two meridional rim rays: the rays parallel to the chief ray
  (object at infinity) or from the same object point (finite object) that pass the rim of the real
  stop, found by bisection on their pupil offset. Where the file gives semi-diameters the rays are
  traced with them (a rim ray vignetted before the stop rim is the last ray that still passes). A
  ray is drawn as straight segments between its intersections with the surfaces: it starts at the
  object plane (a near object) or a little before the first surface (a far one or infinity) and
  ends on the farthest image plane.
* **Lens edges.** Each surface is drawn out to its semi-diameter from the file, or — where the file
  gives none — to the largest height of the drawn rays there plus a margin
  (:data:`SD_MARGIN`), so that no drawn ray passes outside a drawn surface. The surfaces of an
  element (of a cemented group) are joined by flats and an edge line at the group's largest
  semi-diameter; glass is shaded.
* **Marks.** The stop (bars from the stop radius outward), the image plane(s) and, when drawn, the
  object plane; a legend per field (colour) and per image plane.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from raytrace.errors import TraceError
from raytrace.lens import Lens
from raytrace.paraxial import ParaxialResult

from .common import figure_and_axes, fmt, set_title

#: Drawn semi-diameter where the file gives none: (1 + relative) × the largest ray height at the
#: surface + absolute × the largest ray height anywhere in the lens.
SD_MARGIN = (0.04, 0.02)
#: Default fields as fractions of the lens's field.
DEFAULT_FIELD_FRACTIONS = (0.0, 0.7, 1.0)
ROLE_CHIEF, ROLE_UPPER, ROLE_LOWER = 0, 1, -1
GLASS_FILL = "#dce8f4"


@dataclass(frozen=True, eq=False)
class LayoutRays:
    """The geometry :func:`plot_layout` draws (mm, absolute z from the first vertex).

    fields (f,): the fields drawn (degrees, or mm for object heights); field_kind: ``"angle"`` or
    ``"height"``; traced (f,): whether the chief ray of each field passed the lens.
    z, y (r, n_surfaces + 2): each ray's polyline — start point, its intersection with every
    surface, its point on the farthest image plane. field_index (r,): the field of each ray;
    role (r,): 0 chief ray, +1 / −1 upper / lower rim ray.
    semi_diameters (n_surfaces,): drawn semi-diameters; from_file (n_surfaces,): given by the file.
    stop_radius: the real stop's radius (paraxial, from the aperture). z_planes (p,): image planes.
    z_start: where the rays start (the object plane when ``object_drawn``). paraxial: the
    first-order data of this object distance and wavelength.
    """

    lens: Lens
    fields: np.ndarray
    field_kind: str
    traced: np.ndarray
    z: np.ndarray
    y: np.ndarray
    field_index: np.ndarray
    role: np.ndarray
    semi_diameters: np.ndarray
    from_file: np.ndarray
    stop_radius: float
    z_planes: np.ndarray
    z_start: float
    object_drawn: bool
    paraxial: ParaxialResult


def _pick(values: np.ndarray, n: int) -> np.ndarray:
    """Up to ``n`` of ``values`` spread over their range (first and last kept)."""
    if values.size <= n:
        return values
    return values[np.unique(np.linspace(0, values.size - 1, n).round().astype(int))]


def _rays_from(cr, par, p: np.ndarray, idx: np.ndarray):
    """Start points and unit directions (y, z, M, N) of meridional rays of fields ``idx`` with
    pupil offsets ``p`` (mm): parallel to the chief ray shifted by p (object at infinity), or
    from the object point toward the chief ray's entrance-pupil-plane height + p (finite)."""
    y0, z0 = cr.y_start[idx], cr.z_start[idx]
    M, N = cr.M_start[idx], cr.N_start[idx]
    if par.infinite:
        return y0 + p, z0, M, N
    dz = par.z_E0 - z0
    dy = dz * M / N + p
    n = np.hypot(dy, dz)
    return y0, z0, dy / n, dz / n


def _rim_offsets(lens, packed, cr, par, idx, sign, clip, stop_radius):
    """Pupil offsets of the rim rays (one per field in ``idx``, side ``sign``): going out from the
    chief ray (offset 0), the first offset whose ray no longer passes the lens (clipped when
    ``clip``) or meets the stop surface outside the stop radius. Scanned in steps of a sixth of the
    paraxial pupil radius out to four radii, then bisected to round-off."""
    from raytrace.trace import ray_paths

    st = lens.stop_index
    limit = stop_radius * (1.0 + 1e-12)

    def passes(p, ix):
        y, z, M, N = _rays_from(cr, par, p, ix)
        rp = ray_paths(packed, (0.0, y, z), (0.0, M, N), clip=clip)
        ys = rp.y[:, st]
        return (rp.status == 0) & np.isfinite(ys) & (np.abs(ys) <= limit)

    n_scan = 24
    step = sign * max(par.epd, 1e-9) / 12.0
    k = np.arange(1, n_scan + 1)
    grid_p = np.repeat(k[None, :] * step, idx.size, axis=0)  # (fields, steps)
    ok = passes(grid_p.ravel(), np.repeat(idx, n_scan)).reshape(idx.size, n_scan)
    first_fail = np.where(~ok.all(axis=1), np.argmin(ok, axis=1), n_scan)  # index of first fail
    lo = first_fail * step  # the last passing offset (0: the chief ray)
    hi = (first_fail + 1) * step
    done = first_fail == n_scan  # passes out to the end of the scan: keep that
    for _ in range(48):
        mid = 0.5 * (lo + hi)
        good = passes(mid, idx)
        lo = np.where(good, mid, lo)
        hi = np.where(good, hi, mid)
    return np.where(done, n_scan * step, lo)


def _sag_limit(s) -> float:
    """Largest radial height where the surface's quadric is defined (inf for a plane)."""
    if s.curvature == 0.0 or 1.0 + s.conic <= 0.0:
        return math.inf
    return 0.999 / (abs(s.curvature) * math.sqrt(1.0 + s.conic))


def _bundle(lens, show, kind, od, wavelength, par, clip, rim_rays):
    """Chief and rim rays of the fields ``show``: (traced per field, field index and role per ray,
    object-space start (y, z, M, N), surface intersections (y, z), final segment (y, z, M, N))."""
    from raytrace.packing import pack
    from raytrace.trace import aim, ray_paths, trace_rays

    packed = pack(lens, wavelength)
    cr = aim(lens, show, kind, od, wavelength, clip=clip)
    traced = cr.status == 0
    ok_idx = np.nonzero(traced)[0]
    fi = [ok_idx]
    role = [np.full(ok_idx.size, ROLE_CHIEF)]
    offs = [np.zeros(ok_idx.size)]
    if rim_rays and ok_idx.size:
        for sign, r in ((1.0, ROLE_UPPER), (-1.0, ROLE_LOWER)):
            fi.append(ok_idx)
            role.append(np.full(ok_idx.size, r))
            offs.append(
                _rim_offsets(lens, packed, cr, par, ok_idx, sign, clip, float(par.stop_radius))
            )
    fidx = np.concatenate(fi).astype(int)
    roles = np.concatenate(role).astype(int)
    y0, z0, M0, N0 = _rays_from(cr, par, np.concatenate(offs), fidx)
    paths = ray_paths(packed, (0.0, y0, z0), (0.0, M0, N0), clip=clip)
    final = trace_rays(packed, (0.0, y0, z0), (0.0, M0, N0), clip=clip)
    keep = (paths.status == 0) & (final.status == 0)
    return (
        traced,
        fidx[keep],
        roles[keep],
        (y0[keep], z0[keep], M0[keep], N0[keep]),
        (paths.y[keep], paths.z[keep]),
        (final.y[keep], final.z[keep], final.M[keep], final.N[keep]),
    )


def _ray_semi_diameters(lens, py, r_stop) -> np.ndarray:
    """Semi-diameters from the rays' heights at each surface plus the margin (capped where the
    quadric ends); the stop surface gets the stop radius."""
    ns = lens.n_surfaces
    hmax = np.max(np.abs(py), axis=0) if py.shape[0] else np.zeros(ns)
    rel, absm = SD_MARGIN
    top = float(hmax.max()) if hmax.size and hmax.max() > 0 else max(r_stop, 1.0)
    sd = np.empty(ns)
    for j, s in enumerate(lens.surfaces):
        h = (1.0 + rel) * hmax[j] + absm * top if hmax[j] > 0 else max(r_stop, absm * top)
        sd[j] = max(min(h, _sag_limit(s)), hmax[j])
    st = lens.stop_index
    sd[st] = max(r_stop, hmax[st])
    return sd


def _crossing_caps(lens: Lens, sd: np.ndarray, free: np.ndarray) -> np.ndarray:
    """Semi-diameters reduced (where ``free``) so that neighbouring surfaces do not cross: in an
    element the two surfaces, extended by their flats, keep a non-negative edge thickness; across
    an air space the two profiles do not cross. A plane stop in air is skipped over."""
    sd = sd.copy()
    zv = lens.vertex_z
    st = lens.stop_index
    keep = [
        j
        for j, s in enumerate(lens.surfaces)
        if not (j == st and s.curvature == 0.0 and s.material.is_air)
        or (j > 0 and not lens.surfaces[j - 1].material.is_air)
    ]
    for a, b in zip(keep[:-1], keep[1:], strict=True):
        glass = not lens.surfaces[a].material.is_air and b == a + 1
        top = max(sd[a], sd[b]) if glass else min(sd[a], sd[b])
        if not (top > 0 and math.isfinite(top)):
            continue
        h = np.linspace(0.0, top, 401)
        za = zv[a] + lens.surfaces[a].sag(np.minimum(h, sd[a]))
        zb = zv[b] + lens.surfaces[b].sag(np.minimum(h, sd[b]))
        bad = np.nonzero(~(zb - za >= 0.0))[0]
        if bad.size == 0 or bad[0] == 0:
            continue  # no crossing, or crossing on the axis (the file's business)
        cap = float(h[bad[0] - 1])
        for j in (a, b):
            if free[j] and sd[j] > cap:
                sd[j] = cap
    return sd


def layout_rays(
    lens: Lens,
    fields_deg=None,
    *,
    object_heights_mm=None,
    object_distance: float | str | None = None,
    object_s: float | None = None,
    object_scale: float | None = None,
    plane=None,
    s_prime=None,
    from_last_vertex=None,
    defocus=None,
    z_planes=None,
    wavelength: float | None = None,
    rim_rays: bool = True,
    n_fields: int = 3,
) -> LayoutRays:
    """The rays, semi-diameters and planes of a layout drawing (module docstring).

    Parameters
    ----------
    lens : Lens
    fields_deg, object_heights_mm : array_like, optional
        Field angles α (degrees) or object heights (mm, finite object); up to ``n_fields`` of
        them are drawn, spread over their range. Default: 0, 0.7 and 1 × the lens's field.
    object_distance, object_s, object_scale
        The object, as in :func:`distortion.characteristic.characteristic_distortion`; default
        the lens file's.
    plane, s_prime, from_last_vertex, defocus
        The image plane(s), as in ``characteristic_distortion`` (docs/design.md, "Vocabulary");
        default the Gaussian plane. ``z_planes``: planes as absolute z (mm) instead.
    wavelength : float, optional
        nm; default the lens's.
    rim_rays : bool
        Draw the two meridional rim rays of each field.
    n_fields : int
        How many of the given fields to draw.

    Returns
    -------
    LayoutRays

    Notes
    -----
    Semi-diameters the file does not give are the drawn rays' largest heights plus
    :data:`SD_MARGIN`, reduced where neighbouring surfaces would cross (a prescription traced
    beyond the diameters it can physically have); the rays are then traced again with those
    semi-diameters as apertures, so the drawn beam is the one that lens passes.
    """
    from dataclasses import replace

    from raytrace.paraxial import image_planes, plane_z, resolve_paraxial

    par = resolve_paraxial(lens, object_distance, object_s, object_scale, wavelength)
    od = par.object_distance
    if fields_deg is not None and object_heights_mm is not None:
        raise TraceError("give fields_deg or object_heights_mm, not both")
    if object_heights_mm is not None:
        kind, given = "height", object_heights_mm
    elif fields_deg is not None:
        kind, given = "angle", fields_deg
    else:
        kind = lens.field.kind if not (par.infinite and lens.field.kind == "height") else "angle"
        given = np.array(DEFAULT_FIELD_FRACTIONS) * lens.field.value
    f = np.atleast_1d(np.asarray(given, dtype=float)).ravel()
    if f.size == 0:
        raise TraceError("no fields given")
    show = _pick(np.unique(f) if f.size > n_fields else f, max(1, int(n_fields)))
    if z_planes is not None:
        zp = np.atleast_1d(np.asarray(z_planes, dtype=float)).ravel()
    else:
        zp = plane_z(
            par,
            image_planes(
                plane, s_prime=s_prime, from_last_vertex=from_last_vertex, defocus=defocus
            ),
        )
    # the farthest plane along the light (toward −z after an odd number of mirrors)
    z_img = float(zp.max() if lens.image_direction > 0 else zp.min())
    r_stop = float(par.stop_radius)
    from_file = np.array([math.isfinite(s.semi_diameter) for s in lens.surfaces])
    free = ~from_file

    # trace; size the free surfaces from the rays; where that makes surfaces cross, cap them and
    # trace again with the caps as apertures (the beam that lens passes)
    traced_lens = lens
    caps = np.full(lens.n_surfaces, np.inf)
    for _ in range(4):
        clip = any(math.isfinite(s.semi_diameter) for s in traced_lens.surfaces)
        traced, fidx, roles, start, (py, pz), fin = _bundle(
            traced_lens, show, kind, od, wavelength, par, clip, rim_rays
        )
        sd = np.where(from_file, [s.semi_diameter for s in lens.surfaces], np.inf)
        sd = np.where(free, np.minimum(_ray_semi_diameters(lens, py, r_stop), caps), sd)
        capped = _crossing_caps(lens, sd, free)
        hmax = np.max(np.abs(py), axis=0) if py.shape[0] else np.zeros(lens.n_surfaces)
        over = free & (capped < hmax * (1.0 - 1e-12))
        sd = capped
        if not over.any():
            break
        caps = np.where(over, capped, caps)
        surfaces = tuple(
            replace(s, semi_diameter=float(caps[j])) if math.isfinite(caps[j]) else s
            for j, s in enumerate(lens.surfaces)
        )
        traced_lens = replace(lens, surfaces=surfaces)
    y0, z0, M0, N0 = start
    yf, zf, Mf, Nf = fin

    # where the rays start: a near object plane, else a little before the first surface
    front = min(0.0, float(np.nanmin(lens.surfaces[0].sag(np.linspace(0.0, sd[0], 65)))))
    span = max(z_img, lens.length, 1e-3)
    object_drawn = not par.infinite and od <= 0.6 * span
    if object_drawn:
        z_start = -od
    else:
        z_start = front - 0.3 * max(lens.length, float(sd.max()), 1.0)
    ys = y0 + (z_start - z0) * M0 / N0
    yi = yf + (z_img - zf) * Mf / Nf
    Z = np.column_stack([np.full(ys.size, z_start), pz, np.full(ys.size, z_img)])
    Y = np.column_stack([ys, py, yi])
    return LayoutRays(
        lens=lens,
        fields=show,
        field_kind=kind,
        traced=traced,
        z=Z,
        y=Y,
        field_index=fidx,
        role=roles,
        semi_diameters=sd,
        from_file=from_file,
        stop_radius=r_stop,
        z_planes=zp,
        z_start=float(z_start),
        object_drawn=bool(object_drawn),
        paraxial=par,
    )


# ------------------------------------------------------------------ drawing


def _groups(lens: Lens) -> list[tuple[int, int]]:
    """(first, last) surface indices of each element or cemented group (glass between them)."""
    out = []
    j, n = 0, lens.n_surfaces
    while j < n - 1:
        if lens.surfaces[j].material.is_air:
            j += 1
            continue
        k = j + 1
        while k < n - 1 and not lens.surfaces[k].material.is_air:
            k += 1
        out.append((j, k))
        j = k
    return out


def _field_label(value: float, kind: str, finite: bool, traced: bool) -> str:
    if kind == "height":
        t = f"$y$ = {fmt(value, 4)} mm"
    else:
        t = ("nominal " if finite else "") + rf"$\alpha$ = {fmt(value, 4)}°"
    return t if traced else t + " (not traced)"


def _draw_lens(ax, L: LayoutRays) -> None:
    lens, sd = L.lens, L.semi_diameters
    zv = lens.vertex_z
    st = lens.stop_index

    def edge_z(j):
        return float(zv[j] + lens.surfaces[j].sag(sd[j]))

    def profile(j, flip=False):
        r = np.linspace(-sd[j], sd[j], 161)
        r = r[::-1] if flip else r
        return zv[j] + lens.surfaces[j].sag(r), r

    glassy = set()
    for j, k in _groups(lens):
        H = float(sd[j : k + 1].max())
        for i in range(j, k):
            glassy.update((i, i + 1))
            za, ra = profile(i)
            zb, rb = profile(i + 1, flip=True)
            ea, eb = edge_z(i), edge_z(i + 1)
            poly_z = np.concatenate([za, [ea, eb], zb, [eb, ea]])
            poly_y = np.concatenate([ra, [H, H], rb, [-H, -H]])
            ax.fill(poly_z, poly_y, color=GLASS_FILL, lw=0, zorder=0.5)
            for sgn in (1.0, -1.0):
                ax.plot(
                    [ea, ea, eb, eb],
                    [sgn * sd[i], sgn * H, sgn * H, sgn * sd[i + 1]],
                    color="k",
                    lw=1.0,
                    zorder=3,
                    gid="edge",
                )
    arriving = 1.0  # direction of the light along z before each surface (mirrors flip it)
    for j, s in enumerate(lens.surfaces):
        if s.mirror:
            _draw_mirror(ax, *profile(j), arriving)
            arriving = -arriving
            continue
        if j == st and s.curvature == 0.0 and j not in glassy:
            continue  # a plane stop in air is drawn as the stop only
        z, r = profile(j)
        ax.plot(
            z,
            r,
            color="k" if j in glassy else "0.5",
            lw=1.0 if j in glassy else 0.7,
            ls="-" if j in glassy else ":",
            zorder=3,
            gid=f"surface {j + 1}",
        )
    # the stop: bars from the stop radius outward
    rs = L.stop_radius
    zs = float(zv[st] + lens.surfaces[st].sag(rs)) if math.isfinite(rs) else float(zv[st])
    outer = _stop_outer(L)
    for sgn in (1.0, -1.0):
        ax.plot([zs, zs], [sgn * rs, sgn * outer], color="k", lw=2.4, zorder=3, gid="stop")


def _draw_mirror(ax, z: np.ndarray, r: np.ndarray, arriving: float) -> None:
    """A mirror: its profile as a heavy line, hatched on the side the light does not reach
    (behind it along the arriving direction)."""
    ax.plot(z, r, color="k", lw=2.0, zorder=3, gid="mirror")
    span = float(np.ptp(r)) if r.size else 0.0
    h = 0.04 * span
    for k in range(0, r.size, max(1, r.size // 12)):
        ax.plot([z[k], z[k] + arriving * h], [r[k], r[k] + h], color="k", lw=0.6, zorder=3,
                gid="mirror back")  # fmt: skip


def _stop_outer(L: LayoutRays) -> float:
    return max(1.3 * L.stop_radius, L.stop_radius + 0.12 * float(L.semi_diameters.max()))


def _heights_at(L: LayoutRays, z: float) -> np.ndarray:
    """Heights of the drawn rays on the plane z behind the last surface (their last segment)."""
    z_last, y_last = L.z[:, -2], L.y[:, -2]
    t = (z - z_last) / (L.z[:, -1] - z_last)
    return y_last + t * (L.y[:, -1] - y_last)


def _segment(y: np.ndarray, floor: float) -> tuple[float, float]:
    """A plane mark spanning the heights y (and the axis), a little beyond them."""
    lo = min(float(np.min(y)) if y.size else 0.0, 0.0)
    hi = max(float(np.max(y)) if y.size else 0.0, 0.0)
    ext = max(0.06 * (hi - lo), floor)
    return lo - ext, hi + ext


def plot_layout(
    lens: Lens,
    fields_deg=None,
    *,
    ax=None,
    title: str | None = None,
    **options,
):
    """Draw ``lens`` to scale with real rays per field to the image plane(s).

    ``osc.plot_layout(lens)`` draws the lens's own object at the fields 0, 0.7 and 1 × its field,
    rays to the Gaussian image plane. The module docstring says what is drawn and how.

    Parameters
    ----------
    lens : Lens
    fields_deg : array_like, optional
        Field angles α (degrees); or ``object_heights_mm=`` (mm) for a finite object.
    ax : matplotlib.axes.Axes, optional
        Draw here (equal aspect; the axes box is fitted to the drawing); default a new pyplot
        figure sized to the drawing.
    title : str, optional
        Replaces the default title, the lens name (wrapped to the axes width either way).
    **options
        ``object_heights_mm``, ``object_distance`` / ``object_s`` / ``object_scale``, ``plane`` /
        ``s_prime`` / ``from_last_vertex`` / ``defocus`` / ``z_planes``, ``wavelength``,
        ``rim_rays``, ``n_fields``: as :func:`layout_rays`.

    Returns
    -------
    matplotlib.figure.Figure
    """
    L = layout_rays(lens, fields_deg, **options)
    par = L.paraxial
    sdmax = float(L.semi_diameters.max())
    planes = [(z, _segment(_heights_at(L, z), 0.05 * sdmax)) for z in sorted(L.z_planes)]
    obj = _segment(L.y[:, 0], 0.05 * sdmax) if L.object_drawn else None
    zlo = min(L.z_start, _front(L), float(L.z_planes.min()))
    zhi = max(float(L.z_planes.max()), _back(L))
    outer = _stop_outer(L)
    ylo = min(-sdmax, -outer, *(seg[0] for _, seg in planes), obj[0] if obj else 0.0)
    yhi = max(sdmax, outer, *(seg[1] for _, seg in planes), obj[1] if obj else 0.0)
    if L.y.size:
        ylo, yhi = min(ylo, float(L.y.min())), max(yhi, float(L.y.max()))
    pad = 0.035 * max(zhi - zlo, yhi - ylo)
    x0, x1, y0, y1 = zlo - pad, zhi + pad, ylo - pad, yhi + pad
    if ax is None:
        aspect = (y1 - y0) / (x1 - x0)
        w = 8.5
        h = w * aspect
        if h > 6.0:
            h, w = 6.0, 6.0 / aspect
        fig, ax = figure_and_axes(None, figsize=(max(w, 4.0) + 1.0, max(h, 1.6) + 1.3))
    else:
        fig, ax = figure_and_axes(ax)
    _draw_lens(ax, L)
    ax.plot([x0, x1], [0.0, 0.0], color="0.55", lw=0.6, ls="-.", zorder=1, gid="axis")

    handles, labels = [], []
    for i, fv in enumerate(L.fields):
        colour = f"C{i}"
        h = None
        for r in np.nonzero(L.field_index == i)[0]:
            chief = L.role[r] == 0
            (ln,) = ax.plot(
                L.z[r],
                L.y[r],
                color=colour,
                lw=1.2 if chief else 0.7,
                zorder=2,
                gid="chief ray" if chief else "rim ray",
            )
            if chief:
                h = ln
        if h is None:
            (h,) = ax.plot([], [], color=colour, lw=1.2)
        handles.append(h)
        labels.append(_field_label(fv, L.field_kind, not par.infinite, bool(L.traced[i])))
    (ln,) = ax.plot([], [], color="k", lw=2.4)
    handles.append(ln)
    labels.append(f"aperture stop, radius {fmt(L.stop_radius, 4)} mm")
    for k, (z, (lo, hi)) in enumerate(planes):
        ls = ["--", ":", "-.", (0, (5, 1, 1, 1))][k % 4]
        (ln,) = ax.plot(
            [z, z], [lo, hi], color="0.25", lw=1.1, ls=ls, zorder=2.5, gid="image plane"
        )
        handles.append(ln)
        labels.append(f"image plane $s'$ = {fmt(par.s_prime_of(z), 6)} mm")
    if obj is not None:
        (ln,) = ax.plot(
            [L.z_start] * 2, list(obj), color="0.25", lw=1.1, zorder=2.5, gid="object plane"
        )
        handles.append(ln)
        labels.append(f"object plane, {fmt(-L.z_start, 6)} mm before the first vertex")

    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel("z (mm from the first vertex)")
    ax.set_ylabel("y (mm)")
    ax.legend(
        handles, labels, fontsize=8, frameon=True, framealpha=0.9, edgecolor="0.8", loc="best"
    )
    set_title(ax, title or lens.name)
    return fig


def _back(L: LayoutRays) -> float:
    """Largest z of the drawn lens (a mirror system may lie right of its image planes)."""
    zv = L.lens.vertex_z
    return max(
        float(np.nanmax(zv[j] + s.sag(np.linspace(0.0, L.semi_diameters[j], 33))))
        for j, s in enumerate(L.lens.surfaces)
    )


def _front(L: LayoutRays) -> float:
    """Smallest z of the drawn lens (a surface may bulge left of its vertex)."""
    zv = L.lens.vertex_z
    return min(
        float(np.nanmin(zv[j] + s.sag(np.linspace(0.0, L.semi_diameters[j], 33))))
        for j, s in enumerate(L.lens.surfaces)
    )
