"""2-D distortion charts: the grid-distortion picture (ideal against real grid, exaggerated), the
vector plot of the distortion field (or of one of its parts) and the radial curve per azimuth.

Every function draws into ``ax`` (a new pyplot figure when ``ax`` is None) and returns the Figure
(:mod:`orthoscope.plots.common` states the convention). Image coordinates in mm in the lens frame
(x right, y up, looking along −z; docs/design.md, "2-D distortion"), equal axes.
"""

from __future__ import annotations

import math

import numpy as np

from distortion.errors import DataError
from distortion.grid import DistortionGrid, GridDecomposition, RadialByAzimuth

from .common import GRID, figure_and_axes, figure_with_zero, fmt, legend, set_title

IDEAL = "0.65"
REAL = "tab:red"
FIGSIZE_SQUARE = (6.4, 6.0)
COMPONENTS = ("total", "radial", "decentering", "thin_prism", "offset", "scale", "residual")


def nice_factor(value: float) -> float:
    """The largest 1-2-5 number ≤ ``value`` (≥ 1): a readable exaggeration factor."""
    if not (value > 1.0) or not math.isfinite(value):
        return 1.0
    mag = 10.0 ** math.floor(math.log10(value))
    for m in (5.0, 2.0, 1.0):
        if m * mag <= value:
            return m * mag
    return mag  # pragma: no cover


def default_exaggeration(grid: DistortionGrid, plane: int = 0, fraction: float = 0.05) -> float:
    """A 1-2-5 factor k with which the largest |D| appears as about ``fraction`` of the grid's
    half-size (1 when the distortion is already that large)."""
    p = grid.plane_index(plane)
    ideal = grid.ideal[p]
    half = 0.5 * float(np.nanmax(ideal[..., 0]) - np.nanmin(ideal[..., 0]))
    half = max(half, 0.5 * float(np.nanmax(ideal[..., 1]) - np.nanmin(ideal[..., 1])))
    dmax = grid.max_distortion(p)
    if not (dmax > 0 and half > 0):
        return 1.0
    return nice_factor(fraction * half / dmax)


def _lines(ax, pts: np.ndarray, **kw):
    """Draw the rows and the columns of an (ny, nx, 2) point grid as polylines."""
    first = None
    for row in pts:
        (h,) = ax.plot(row[:, 0], row[:, 1], **kw)
        if first is None:
            first = h
    for col in np.swapaxes(pts, 0, 1):
        ax.plot(col[:, 0], col[:, 1], **kw)
    return first


def _frame(ax, grid: DistortionGrid, p: int) -> None:
    """The black cross at the reference point of plane ``p``, equal axes, x' and y' in mm."""
    ax.plot(*grid.reference_xy[p], marker="+", color="k", ms=9, ls="none", zorder=3)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x' (mm)")
    ax.set_ylabel("y' (mm)")


def plot_grid_distortion(
    grid: DistortionGrid,
    plane: int = 0,
    *,
    exaggeration: float | None = None,
    ax=None,
    title: str | None = None,
):
    """The ideal grid (grey) and the real grid with its distortion exaggerated k times (red):
    points ``P0' + k·D``. ``exaggeration`` k: default a 1-2-5 factor that makes the largest
    distortion about 5 % of the picture (:func:`default_exaggeration`); k is stated in the
    title.

    Ideal points ``P0' = R + K0·X`` (Pestrecov 1958, Eq. 8 in 2-D) and distortion vectors
    ``D = P' − P0'`` (mm) as :mod:`distortion.grid.field` defines them; image coordinates
    (x', y') in mm in the lens frame (x right, y up, looking along −z), equal axes. A black
    cross marks the reference point R. The title states max |D| in µm.

    Parameters
    ----------
    grid : DistortionGrid
        From ``osc.distortion_grid``; a 2-D grid of fields (rows × columns), else ``DataError``.
    plane : int
        Which image plane of ``grid`` (0-based).
    exaggeration : float, optional
        The factor k (dimensionless, > 0).
    ax : matplotlib.axes.Axes, optional
        Draw here; default a new pyplot figure.
    title : str, optional
        Replaces the default title (which is wrapped to the axes width either way).

    Returns
    -------
    matplotlib.figure.Figure
    """
    p = grid.plane_index(plane)
    if len(grid.shape) != 2:
        raise DataError("plot_grid_distortion needs a 2-D grid of fields (rows x columns)")
    k = default_exaggeration(grid, p) if exaggeration is None else float(exaggeration)
    if not (k > 0 and math.isfinite(k)):
        raise DataError(f"exaggeration must be a positive number, got {exaggeration!r}")
    fig, ax = figure_and_axes(ax, figsize=FIGSIZE_SQUARE)
    ideal = grid.ideal[p]
    shown = ideal + k * grid.D[p]
    hi = _lines(ax, ideal, color=IDEAL, lw=0.8, zorder=1)
    hr = _lines(ax, shown, color=REAL, lw=1.1, zorder=2)
    _frame(ax, grid, p)
    legend(ax, [hi, hr], ["ideal (Eq. 8, 2-D)", f"real, distortion x {fmt(k, 3)}"], loc="best")
    dmax = grid.max_distortion(p)
    set_title(
        ax,
        title
        or (
            f"{grid.name}: grid distortion, {grid.plane_label(p)}; distortion exaggerated "
            f"{fmt(k, 3)}x (max |D| = {fmt(dmax * 1000, 4)} um, reference {grid.reference_point})"
        ),
    )
    return fig


def plot_distortion_vectors(
    grid: DistortionGrid,
    plane: int = 0,
    *,
    decomposition: GridDecomposition | None = None,
    component: str = "total",
    ax=None,
    title: str | None = None,
):
    """Arrows of the distortion vectors D (or of one part of a ``decomposition``: "radial",
    "decentering", "thin_prism", "offset", "scale", "residual") at the ideal image points; the
    arrow key states the length it stands for.

    D = P' − P0' (mm; ideal points of Pestrecov 1958, Eq. 8 in 2-D) at the ideal points, in the
    lens frame (x', y' in mm; x right, y up, looking along −z), equal axes; the arrows are
    scaled so that the longest spans about 1.5 grid steps, the key and the title state lengths
    in µm. A black cross marks the reference point.

    Parameters
    ----------
    grid : DistortionGrid
        From ``osc.distortion_grid``.
    plane : int
        Which image plane of ``grid`` (0-based).
    decomposition : GridDecomposition, optional
        From ``osc.decompose_distortion`` of the same plane (needed for any ``component`` but
        "total"; ``DataError`` for another plane or an undetermined decomposition).
    component : {"total", "radial", "decentering", "thin_prism", "offset", "scale", "residual"}
        What to draw: D itself, or that part of the decomposition (mm; the parts sum to D).
    ax : matplotlib.axes.Axes, optional
        Draw here; default a new pyplot figure.
    title : str, optional
        Replaces the default title (which is wrapped to the axes width either way).

    Returns
    -------
    matplotlib.figure.Figure
    """
    p = grid.plane_index(plane)
    if component not in COMPONENTS:
        raise DataError(f"component={component!r}; use one of {', '.join(COMPONENTS)}")
    if component == "total":
        vec = grid.D[p]
        what = "distortion D"
    else:
        if decomposition is None:
            raise DataError(f"component={component!r} needs decomposition= (decompose_distortion)")
        if decomposition.plane != p:
            raise DataError(f"the decomposition is of plane {decomposition.plane}, not plane {p}")
        if not decomposition.determined:
            raise DataError(
                f"the decomposition is not determined ({decomposition.not_determined}): it has "
                "no parts to draw"
            )
        vec = decomposition.components[component]
        what = f"{component.replace('_', ' ')} part"
    fig, ax = figure_and_axes(ax, figsize=FIGSIZE_SQUARE)
    pos, vmax = arrow_field(
        ax,
        grid.ideal[p].reshape(-1, 2),
        np.asarray(vec, dtype=float).reshape(-1, 2),
        REAL,
        lambda key: f"{fmt(key * 1000, 3)} um",
    )
    ax.plot(pos[:, 0], pos[:, 1], ".", color=IDEAL, ms=2.5, zorder=1)
    _frame(ax, grid, p)
    set_title(
        ax,
        title
        or (
            f"{grid.name}: {what}, {grid.plane_label(p)} (max {fmt(vmax * 1000, 4)} um, "
            f"reference {grid.reference_point})"
        ),
        pad=16.0,
    )
    return fig


def arrow_field(ax, pos, vec, color, key_label, span: float | None = None):
    """Arrows ``vec`` at the points ``pos`` (both (N, 2), in the axes' data units; rows with a
    NaN are dropped), scaled so that the longest spans about 1.5 steps of a square grid of
    width ``span`` (default: the x extent of ``pos``), with a 1-2-5 key (:func:`key_length`)
    labelled ``key_label(key)``. The arrow tips count in the axes' data limits, so that no
    arrow leaves the axes (limits set afterwards take over); the key sits above the axes at
    their left, its tail at 0.16 of the axes' width (label to its left), pointing right.

    Returns
    -------
    pos : ndarray
        (M, 2) the points drawn.
    vmax : float
        The longest vector (data units; 0 when there is none).
    """
    ok = np.all(np.isfinite(pos), axis=1) & np.all(np.isfinite(vec), axis=1)
    pos, vec = pos[ok], vec[ok]
    lengths = np.hypot(vec[:, 0], vec[:, 1])
    vmax = float(lengths.max()) if lengths.size else 0.0
    if span is None:
        span = max(float(np.ptp(pos[:, 0])) if pos.size else 1.0, 1e-300)
    if vmax > 0:
        n_side = max(2.0, math.sqrt(max(pos.shape[0], 1)))
        scale = vmax / (1.5 * span / n_side)
        q = ax.quiver(
            pos[:, 0], pos[:, 1], vec[:, 0], vec[:, 1], angles="xy", scale_units="xy",
            scale=scale, color=color, width=0.004, zorder=2,
        )  # fmt: skip
        # quiver does not count its arrows in the data limits: add the tips (and a margin of
        # a quarter of the longest arrow for the heads), then let autoscaling apply
        tips = pos + vec / scale
        pad = 0.25 * vmax / scale
        lo = np.minimum(pos, tips).min(axis=0) - pad
        hi = np.maximum(pos, tips).max(axis=0) + pad
        ax.update_datalim(np.vstack([lo, hi]))
        ax.autoscale_view()
        key = key_length(vmax)
        # labelpos "W": the arrow's tail at X, pointing right (at most ~0.6 of the axes: the
        # key is <= 0.75 of the longest arrow, itself <= 0.75 of the width), its label left
        ax.quiverkey(q, 0.16, 1.02, key, key_label(key), labelpos="W", coordinates="axes")
    return pos, vmax


def key_length(vmax: float) -> float:
    """A 1-2-5 length near half the longest vector ``vmax`` for an arrow key (same unit)."""
    mag = 10.0 ** math.floor(math.log10(vmax))
    for m in (5.0, 2.0, 1.0):
        if m * mag <= 0.75 * vmax:
            return m * mag
    return mag / 2.0


def plot_radial_by_azimuth(
    curves: RadialByAzimuth,
    plane: int = 0,
    *,
    tangential: bool = True,
    ax=None,
    title: str | None = None,
):
    """Radial distortion (solid, outward positive) and, with ``tangential``, the tangential
    part (dashed) against the field, one colour per azimuth: Pestrecov's characteristic curve
    per azimuth (identical curves for a centred lens).

    D·ê_r and D·ê_t in µm (radial + outward = pincushion, tangential + counter-clockwise;
    azimuths in degrees from +x toward +y), against the total field angle θ in degrees (nominal
    for a finite object) or the object radius in mm. Along any azimuth of a centred lens the
    radial part is Pestrecov's D0 (1958, Eq. 9).

    Parameters
    ----------
    curves : RadialByAzimuth
        From ``osc.radial_by_azimuth``.
    plane : int
        Which image plane (0-based).
    tangential : bool
        Also draw the tangential part (dashed).
    ax : matplotlib.axes.Axes, optional
        Draw here; default a new pyplot figure.
    title : str, optional
        Replaces the default title (which is wrapped to the axes width either way).

    Returns
    -------
    matplotlib.figure.Figure
    """
    g = curves.grid
    p = g.plane_index(plane)
    fig, ax = figure_with_zero(ax)
    ax.grid(True, **GRID)
    handles, labels = [], []
    colors = _colors(curves.azimuths_deg.size)
    for i, a in enumerate(curves.azimuths_deg):
        (h,) = ax.plot(curves.fields, curves.radial[p, i] * 1000, color=colors[i], lw=1.3)
        if tangential:
            ax.plot(curves.fields, curves.tangential[p, i] * 1000, color=colors[i], lw=1.0,
                    ls="--")  # fmt: skip
        handles.append(h)
        labels.append(f"{fmt(a, 4)} deg")
    if curves.field_kind == "angle":
        ax.set_xlabel("field angle theta (deg)")
    elif curves.field_kind == "nominal-angle":
        ax.set_xlabel("nominal field angle theta (deg)")
    else:
        ax.set_xlabel("object radius (mm)")
    ax.set_ylabel("distortion (um)")
    legend(ax, handles, labels, title="azimuth" + (" (dashed: tangential)" if tangential else ""),
           loc="best")  # fmt: skip
    set_title(
        ax,
        title
        or (
            f"{g.name}: radial distortion per azimuth, {g.plane_label(p)} "
            f"(reference {g.reference_point})"
        ),
    )
    return fig


def _colors(n: int):
    from matplotlib import colormaps

    cmap = colormaps["viridis"] if n > 10 else colormaps["tab10"]
    if n > 10:
        return [cmap(i / max(n - 1, 1)) for i in range(n)]
    return [cmap(i) for i in range(n)]
