"""Camera-model charts: the residual of a model fitted to a traced lens, the lens's distortion as
a picture at true scale (a grid warped by ``cv2.remap``), and a measured calibration against the
prescription's prediction — the radial curves side by side with the map of their difference.

Every single-panel function draws into ``ax`` (a new pyplot figure when ``ax`` is None) and
returns the Figure (:mod:`orthoscope.plots.common`); :func:`plot_calibration_comparison` makes
a two-panel figure of its own. Image coordinates are OpenCV pixels (u right, v down, pixel
centres at integers), drawn as the picture is seen: v grows downward.
"""

from __future__ import annotations

import math

import numpy as np

from distortion.camera import CameraComparison, CameraModel, DistortionPicture, TracedCamera
from distortion.errors import DataError

from .common import GRID, ZERO, figure_and_axes, fmt, legend, panel_figure, set_title

ARROWS = "tab:red"
MEASURED = "tab:blue"
PREDICTED = "tab:red"
FIGSIZE_IMAGE = (7.2, 5.2)
#: arrows per row of a map (a denser comparison grid is thinned for the arrows)
ARROWS_PER_ROW = 14


def _arrows(ax, pos: np.ndarray, vec: np.ndarray, width: int, unit: str = "px"):
    """Quiver of ``vec`` at ``pos`` (pixels) scaled so the longest arrow spans ~1.5 grid
    steps, with a key; returns the longest length."""
    from .grid import arrow_field

    return arrow_field(ax, pos, vec, ARROWS, lambda key: f"{fmt(key, 3)} {unit}", span=width)[1]


def _image_axes(ax, width: int, height: int) -> None:
    ax.set_xlim(-0.5, width - 0.5)
    ax.set_ylim(height - 0.5, -0.5)  # v grows downward, as the picture is seen
    ax.set_aspect("equal")
    ax.set_xlabel("u (px)")
    ax.set_ylabel("v (px)")


def plot_camera_residuals(tc: TracedCamera, *, ax=None, title: str | None = None):
    """Arrows of the fitted model's residual (model − traced image point) at every traced
    chief ray over the sensor, with the RMS in the title.

    Residual vectors in OpenCV pixels (u right, v down; :func:`distortion.camera.camera_residual`):
    the model's projection of each traced direction minus the traced chief ray's image point.
    The arrows are scaled so that the longest spans about 1.5 grid steps (key above the axes);
    grey dots mark the traced points. The title states the RMS and the largest residual (px).

    Parameters
    ----------
    tc : TracedCamera
        From ``osc.camera_model`` (a camera model fitted to a lens's traced chief rays).
    ax : matplotlib.axes.Axes, optional
        Draw here; default a new pyplot figure.
    title : str, optional
        Replaces the default title (which is wrapped to the axes width either way).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from distortion.camera import camera_residual

    fig, ax = figure_and_axes(ax, figsize=FIGSIZE_IMAGE)
    pts = tc.points
    res = camera_residual(tc.camera, pts).residual_px
    w, h = pts.sensor.image_size
    ax.plot(pts.image_px[:, 0], pts.image_px[:, 1], ".", color="0.6", ms=2.5, zorder=1)
    vmax = _arrows(ax, pts.image_px, res, w)
    _image_axes(ax, w, h)
    set_title(
        ax,
        title
        or (
            f"{pts.geometry.lens_name}: {tc.camera.model} fitted to {tc.fit.n_points} chief rays "
            f"- residual RMS {fmt(tc.rms_px, 3)} px, max {fmt(vmax, 3)} px"
        ),
        pad=16.0,
    )
    return fig


def plot_distortion_picture(
    picture: DistortionPicture | CameraModel,
    *,
    pattern: str = "grid",
    reference: bool = False,
    ax=None,
    title: str | None = None,
):
    """A grid (or checkerboard) of the ideal image as the camera records it, at true scale
    (:func:`distortion.camera.distortion_picture`; warped by ``cv2.remap``). Axes in full-size
    pixels. ``reference``: draw the grid's lines where a distortion-free camera would record
    them (thin red lines) — zoom in (``ax.set_xlim``) to see the recorded lines leave them.

    Parameters
    ----------
    picture : DistortionPicture or CameraModel
        A picture made by ``osc.distortion_picture`` (its own pattern, spacing and preview scale),
        or a camera model, whose picture is made here with the defaults (line spacing a tenth of
        the image height, preview at most 1200 px wide; needs OpenCV, the ``camera`` extra).
    pattern : {"grid", "checkerboard"}
        The pattern for a camera model; ignored for a ready :class:`DistortionPicture`.
    reference : bool
        Draw the lines of the ideal grid (pinhole part of the model, spacing in full-size px)
        in red; only for a grid pattern of a camera without skew (else ``DataError``).
    ax : matplotlib.axes.Axes, optional
        Draw here; default a new pyplot figure. Pixels are OpenCV's (u right, v down, pixel
        centres at integers), v growing downward as the picture is seen.
    title : str, optional
        Replaces the default title (which is wrapped to the axes width either way).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from distortion.camera import distortion_picture, pinhole_part

    pic = picture if isinstance(picture, DistortionPicture) else distortion_picture(
        picture, pattern
    )  # fmt: skip
    cam = pic.camera
    fig, ax = figure_and_axes(ax, figsize=FIGSIZE_IMAGE)
    ax.imshow(
        pic.image, cmap="gray", vmin=0, vmax=255, interpolation="antialiased",
        extent=(-0.5, cam.width - 0.5, cam.height - 0.5, -0.5),
    )  # fmt: skip
    if reference:
        u0, j = pinhole_part(cam)
        if pic.pattern != "grid" or abs(j[0, 1]) > 1e-9 * abs(j[0, 0]):
            raise DataError("reference lines are drawn for a grid pattern of a camera without skew")
        sp = pic.spacing_px
        for axis, n in ((0, cam.width), (1, cam.height)):
            c0 = float(u0[axis])
            line = ax.axvline if axis == 0 else ax.axhline
            for k in range(math.floor(-c0 / sp), math.ceil((n - c0) / sp) + 1):
                line(c0 + k * sp, color=ARROWS, lw=0.6, zorder=2)
    _image_axes(ax, cam.width, cam.height)
    set_title(
        ax,
        title
        or (
            f"{cam.model} {cam.width} x {cam.height} px: a straight {pic.pattern} of the ideal "
            f"image (spacing {fmt(pic.spacing_px, 4)} px) as the camera records it - true scale, "
            "no exaggeration"
        ),
    )
    return fig


def plot_radial_comparison(c: CameraComparison, *, ax=None, title: str | None = None):
    """Radial distortion (azimuthal mean, positive outward) of the measured and the predicted
    camera against the measured radius; the part beyond the sensor's short side (where the
    circles leave the sensor) is shaded.

    Radii in mm and δr in µm when the comparison has a pixel size, else both in pixels (along
    the pixels' x axis). A third, dotted curve is the difference predicted − measured.

    Parameters
    ----------
    c : CameraComparison
        From ``osc.compare_calibration`` or ``osc.compare_cameras`` (``profile_measured`` and
        ``profile_predicted`` at the same radii).
    ax : matplotlib.axes.Axes, optional
        Draw here; default a new pyplot figure.
    title : str, optional
        Replaces the default title (which is wrapped to the axes width either way).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = figure_and_axes(ax)
    pm, pp = c.profile_measured, c.profile_predicted
    mm = pm.radius_mm is not None
    r = pm.radius_mm if mm else pm.radius_px
    a = pm.dr_um if mm else pm.dr_px
    b = pp.dr_um if mm else pp.dr_px
    ax.axhline(0.0, **ZERO)
    ax.grid(True, **GRID)
    (h1,) = ax.plot(r, a, color=MEASURED, lw=1.5)
    (h2,) = ax.plot(r, b, color=PREDICTED, lw=1.5, ls="--")
    (h3,) = ax.plot(r, b - a, color="0.35", lw=1.0, ls=":")
    outside = ~pm.inside
    if np.any(outside):
        ax.axvspan(float(r[np.argmax(outside)]), float(r[-1]), color="0.93", zorder=0)
    ax.set_xlabel("radial distance r (mm)" if mm else "radial distance r (px)")
    ax.set_ylabel(r"radial distortion $\delta r$ (" + (r"$\mu$m" if mm else "px") + ")")
    legend(ax, [h1, h2, h3], [c.label_measured, c.label_predicted, "predicted - measured"],
           loc="best")  # fmt: skip
    set_title(ax, title or "Radial distortion, measured and predicted (shaded: beyond the "
              "sensor's short side)")  # fmt: skip
    return fig


def plot_difference_map(c: CameraComparison, *, ax=None, title: str | None = None):
    """The distortion difference predicted − measured over the sensor: its length in colour,
    the vectors as arrows (pixels).

    ``c.difference_px``: Δd = d_predicted − d_measured in OpenCV pixels (u right, v down), drawn
    at the predicted camera's image points; the colour bar is |Δd| (px), the arrows are thinned to
    about 14 per row and scaled so that the longest spans about 1.5 grid steps (key above the
    axes). The title states the RMS and the largest |Δd| (px).

    Parameters
    ----------
    c : CameraComparison
        From ``osc.compare_calibration`` or ``osc.compare_cameras``. ``DataError`` when no point
        of its map could be evaluated by both models.
    ax : matplotlib.axes.Axes, optional
        Draw here (the colour bar takes room from it); default a new pyplot figure.
    title : str, optional
        Replaces the default title (which is wrapped to the axes width either way).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = figure_and_axes(ax, figsize=FIGSIZE_IMAGE)
    img = c.image_px
    d = c.difference_px
    mag = np.hypot(d[..., 0], d[..., 1])
    if not np.isfinite(mag).any():
        raise DataError("the comparison has no point where both models could be evaluated")
    mesh = ax.pcolormesh(img[..., 0], img[..., 1], mag, shading="gouraud", cmap="viridis",
                         zorder=0)  # fmt: skip
    fig.colorbar(mesh, ax=ax, label="|predicted - measured| (px)", shrink=0.85)
    w, h = c.measured.width, c.measured.height
    step = max(1, round(img.shape[1] / ARROWS_PER_ROW))
    sub = (slice(None, None, step), slice(None, None, step))
    _arrows(ax, img[sub].reshape(-1, 2), d[sub].reshape(-1, 2), w)
    _image_axes(ax, w, h)
    set_title(
        ax,
        title
        or (
            f"Distortion difference over the sensor: RMS {fmt(c.rms_px, 3)} px, max "
            f"{fmt(c.max_px, 3)} px"
        ),
        pad=16.0,
    )
    return fig


def plot_calibration_comparison(c: CameraComparison):
    """Two panels side by side: the radial curves (:func:`plot_radial_comparison`) and the map
    of the difference (:func:`plot_difference_map`).

    Parameters
    ----------
    c : CameraComparison
        From ``osc.compare_calibration`` or ``osc.compare_cameras``.

    Returns
    -------
    matplotlib.figure.Figure
        A new figure of 14 × 5 inches (no ``ax=``: the figure is its own); default titles.
    """
    fig, axs = panel_figure(1, 2, figsize=(14.0, 5.0))
    plot_radial_comparison(c, ax=axs[0])
    plot_difference_map(c, ax=axs[1])
    return fig


__all__ = [
    "plot_calibration_comparison",
    "plot_camera_residuals",
    "plot_difference_map",
    "plot_distortion_picture",
    "plot_radial_comparison",
]
