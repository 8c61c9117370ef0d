"""Lens layout drawing: elements, stop and real chief (and rim) rays to the chosen image plane(s).

The meridional section is drawn to scale (equal axes, mm), light from left to right. Surface
profiles are the exact sags (``Surface.sag``) out to the semi-diameter, or — where the file gives
none — to the largest height the drawn rays reach there plus a margin. Chief rays are the aimed real
chief rays (``raytrace.trace.chief_rays``); the rim rays pass the paraxial entrance-pupil rim in the
meridional plane and are traced without clipping.
"""

from __future__ import annotations

import math

import numpy as np
from matplotlib.figure import Figure

from raytrace.lens import Lens
from raytrace.packing import pack
from raytrace.paraxial import paraxial
from raytrace.trace import aim, ray_paths, trace_rays


def _rim_rays(par, cr, i, sign: float):
    """Start of a meridional rim ray of field i through the pupil rim (sign ±1)."""
    a = sign * par.epd / 2.0
    if par.infinite:
        M, N = cr.M_start[i], cr.N_start[i]
        # parallel to the chief ray, offset so that it crosses the EP plane at height a
        z0 = cr.z_start[i]
        y_ep = cr.y_start[i] + (par.z_E0 - z0) * M / N + a
        return y_ep - (par.z_E0 - z0) * M / N, z0, M, N
    y0, z0 = cr.y_start[i], cr.z_start[i]
    dy, dz = a - y0, par.z_E0 - z0
    n = math.hypot(dy, dz)
    return y0, z0, dy / n, dz / n


def plot_layout(
    lens: Lens,
    fields,
    *,
    field_kind: str | None = None,
    object_distance: float | None = None,
    z_planes=None,
    wavelength: float | None = None,
    rim_rays: bool = True,
    n_fields: int = 3,
):
    """Draw ``lens`` with real chief rays at (up to ``n_fields`` of) ``fields`` to ``z_planes``
    (absolute z, default: the lens file's image plane). Returns the Figure."""
    od = lens.object_distance if object_distance is None else float(object_distance)
    kind = field_kind or lens.field.kind
    par = paraxial(lens, od, wavelength)
    fields = np.asarray(fields, dtype=float)
    pick = np.unique(
        np.linspace(0, fields.size - 1, min(n_fields, fields.size)).round().astype(int)
    )
    show = fields[pick]
    cr = aim(lens, show, kind, od, wavelength, clip=False)
    zp = np.atleast_1d(par.z_image_file if z_planes is None else np.asarray(z_planes, float))
    packed = pack(lens, wavelength)

    # collect rays: (start y, z, M, N, colour, width)
    starts = []
    for i in range(show.size):
        if cr.status[i] != 0:
            continue
        starts.append((cr.y_start[i], cr.z_start[i], cr.M_start[i], cr.N_start[i], i, 1.3))
        if rim_rays:
            for sgn in (1.0, -1.0):
                starts.append((*_rim_rays(par, cr, i, sgn), i, 0.6))
    ys = np.array([s[0] for s in starts])
    zs = np.array([s[1] for s in starts])
    Ms = np.array([s[2] for s in starts])
    Ns = np.array([s[3] for s in starts])
    paths = ray_paths(packed, (0.0, ys, zs), (0.0, Ms, Ns), clip=False)
    final = trace_rays(packed, (0.0, ys, zs), (0.0, Ms, Ns), clip=False)

    fig = Figure(figsize=(9.0, 4.2))
    ax = fig.subplots()
    zv = lens.vertex_z
    length = max(lens.length, 1e-3)
    z_left = -0.35 * length - 5.0
    if not par.infinite and par.z_object > -3.0 * (length + zp.max() - zv[-1]):
        z_left = par.z_object
    # ray segments
    for r, s in enumerate(starts):
        colour, lw = f"C{s[4]}", s[5]
        pz, py = paths.z[r], paths.y[r]
        okj = np.isfinite(pz)
        y0, z0, M, N = s[0], s[1], s[2], s[3]
        t = (z_left - z0) / N
        zz = [z_left] + list(pz[okj])
        yy = [y0 + t * M] + list(py[okj])
        if paths.status[r] == 0:
            # final segment, moved analytically to the farthest image plane
            zz.append(zp.max())
            yy.append(float(final.y[r] + (zp.max() - final.z[r]) * final.M[r] / final.N[r]))
        ax.plot(zz, yy, color=colour, lw=lw)

    # surfaces
    # clear apertures from the chief rays and the axial rim rays (off-axis rim rays of wide-angle
    # lenses are vignetted in the real lens and would inflate the drawing)
    size_rays = [r for r, s in enumerate(starts) if s[5] > 1.0 or show[s[4]] == 0.0]
    ysz = np.abs(paths.y[size_rays]) if size_rays else np.zeros((1, lens.n_surfaces))
    hmax_ray = np.nan_to_num(np.nanmax(ysz, axis=0))
    heights = []
    for j, s in enumerate(lens.surfaces):
        h = s.semi_diameter if math.isfinite(s.semi_diameter) else 1.08 * hmax_ray[j] + 0.3
        if s.curvature != 0.0:
            lim = 1.0 / math.sqrt(max(1.0 + s.conic, 1e-12)) / abs(s.curvature)
            h = min(h, 0.95 * lim)
        heights.append(h)
    for j, s in enumerate(lens.surfaces):
        if s.stop:
            continue
        r = np.linspace(-heights[j], heights[j], 121)
        ax.plot(zv[j] + s.sag(r), r, color="k", lw=1.0)
    for j in range(lens.n_surfaces - 1):
        if lens.surfaces[j].material.is_air:
            continue
        h = max(heights[j], heights[j + 1])
        for sgn in (1.0, -1.0):
            za = zv[j] + float(lens.surfaces[j].sag(heights[j]))
            zb = zv[j + 1] + float(lens.surfaces[j + 1].sag(heights[j + 1]))
            ax.plot(
                [za, za, zb, zb],
                [sgn * heights[j], sgn * h, sgn * h, sgn * heights[j + 1]],
                color="k",
                lw=1.0,
            )
    st = lens.stop_index
    rs = par.stop_radius
    top = max(heights) * 1.15
    for sgn in (1.0, -1.0):
        ax.plot([zv[st], zv[st]], [sgn * rs, sgn * max(top, rs * 1.4)], color="k", lw=2.5)
    for z in zp:
        ax.axvline(z, color="0.35", lw=1.0, ls="--")
    ax.axhline(0.0, color="0.5", lw=0.6, ls="-.")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("z (mm, from the first vertex)")
    ax.set_ylabel("y (mm)")
    kind_txt = "deg" if kind == "angle" else "mm"
    ftxt = ", ".join(f"{f:g}" for f in show)
    planes = ", ".join(f"s' = {z - par.z_Hp:.2f}" for z in zp)
    ax.set_title(f"{lens.name}: chief rays at {ftxt} {kind_txt} to {planes} mm", fontsize=10)
    fig.tight_layout()
    return fig
