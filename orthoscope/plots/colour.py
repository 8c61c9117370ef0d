"""Colour charts: the focal-shift curve, lateral colour over the field and distortion per
wavelength.

Every function draws into ``ax`` (a new figure when ``ax`` is None) and returns the Figure
(:mod:`orthoscope.plots.common`); :func:`orthoscope.plots.save.save_figure` writes it. Lengths
in µm where they are small (shifts, lateral colour), mm for image heights; relative values in
per cent. Titles say which wavelengths are compared and which constant the distortion uses.
"""

from __future__ import annotations

import numpy as np

from distortion.characteristic import ChromaticDistortion
from distortion.colour import FocalShift, LateralColour
from distortion.curve import NOMINAL_ANGLE
from distortion.errors import DataError

from .common import figure_with_zero, label_axes, panel_figure, set_title


def wavelength_colour(nm: float) -> tuple[float, float, float]:
    """An RGB colour for a wavelength (nm): the visible spectrum 380–780 nm by the piecewise
    linear approximation of D. Bruton (1996, "Color Science" web note), dimmed toward the ends;
    grey outside it."""
    w = float(nm)
    if w < 380.0 or w > 780.0:
        return (0.45, 0.45, 0.45)
    if w < 440.0:
        r, g, b = -(w - 440.0) / 60.0, 0.0, 1.0
    elif w < 490.0:
        r, g, b = 0.0, (w - 440.0) / 50.0, 1.0
    elif w < 510.0:
        r, g, b = 0.0, 1.0, -(w - 510.0) / 20.0
    elif w < 580.0:
        r, g, b = (w - 510.0) / 70.0, 1.0, 0.0
    elif w < 645.0:
        r, g, b = 1.0, -(w - 645.0) / 65.0, 0.0
    else:
        r, g, b = 1.0, 0.0, 0.0
    f = 0.3 + 0.7 * (w - 380.0) / 40.0 if w < 420.0 else 1.0
    f = 0.3 + 0.7 * (780.0 - w) / 80.0 if w > 700.0 else f
    # darken a little so that yellow and cyan stay visible on white
    return (0.85 * r * f, 0.75 * g * f, 0.85 * b * f)


def plot_focal_shift(fs: FocalShift, ax=None):
    """The focal-shift curve: image-plane shift (µm) against wavelength (nm), the reference
    wavelength marked.

    The shift is each wavelength's image plane minus the reference wavelength's, + away from the
    lens (``fs.shift``, mm, drawn in µm); paraxial image or best focus as ``fs.kind`` says (the
    title states which). Up to 12 wavelengths get a marker in their spectral colour.

    Parameters
    ----------
    fs : FocalShift
        From ``osc.focal_shift`` (``DataError`` for anything else).
    ax : matplotlib.axes.Axes, optional
        Draw here; default a new pyplot figure.

    Returns
    -------
    matplotlib.figure.Figure
    """
    if not isinstance(fs, FocalShift):
        raise DataError(f"expected a FocalShift (distortion.colour.focal_shift), got {type(fs)}")
    fig, ax = figure_with_zero(ax)
    ax.plot(fs.wavelengths, 1000.0 * fs.shift, "-", color="k", lw=1.4)
    if fs.wavelengths.size <= 12:
        for w, v in zip(fs.wavelengths, fs.shift, strict=True):
            ax.plot([w], [1000.0 * v], "o", color=wavelength_colour(w), ms=6)
    ax.axvline(fs.reference_wavelength, color="0.6", lw=0.8, ls="--")
    label_axes(ax, "wavelength (nm)", f"focal shift from {fs.reference_wavelength:g} nm (µm)")
    what = "paraxial image" if fs.kind == "paraxial" else "best focus (least RMS spot)"
    set_title(ax, f"{fs.name}: longitudinal colour, {what}")
    return fig


def plot_lateral_colour(lc: LateralColour, ax=None, *, plane: int = 0, relative: bool = False):
    """Lateral colour ``y'(λ1) − y'(λ2)`` against the field (µm, or per cent of the reference
    wavelength's image height with ``relative``) in image plane ``plane``.

    λ1, λ2 are ``lc.wavelengths`` (nm), in that order; y' the signed chief-ray image heights
    (mm) in the plane, so positive = y'(λ1) > y'(λ2). Field axis in degrees (field angles;
    nominal angles for a finite object) or mm (object heights).

    Parameters
    ----------
    lc : LateralColour
        From ``osc.lateral_colour`` (``DataError`` for anything else).
    ax : matplotlib.axes.Axes, optional
        Draw here; default a new pyplot figure.
    plane : int
        Which image plane of ``lc`` (0-based; ``DataError`` outside the range).
    relative : bool
        Plot ``lc.relative`` = Δy'/y'(λ_ref) in per cent instead of ``lc.linear`` in µm.

    Returns
    -------
    matplotlib.figure.Figure
    """
    if not isinstance(lc, LateralColour):
        raise DataError(f"expected a LateralColour (distortion.colour), got {type(lc)}")
    if not 0 <= plane < lc.n_planes:
        raise DataError(f"plane={plane}: the result has {lc.n_planes} image plane(s) (0-based)")
    fig, ax = figure_with_zero(ax)
    y = 100.0 * lc.relative[plane] if relative else 1000.0 * lc.linear[plane]
    ax.plot(lc.fields, y, "o-", color="tab:purple", ms=4)
    w1, w2 = lc.wavelengths
    label_axes(
        ax,
        _field_label(lc.field_kind),
        f"(y'({w1:g}) − y'({w2:g})) / y'({lc.reference_wavelength:g}) (%)"
        if relative
        else f"y'({w1:g} nm) − y'({w2:g} nm) (µm)",
    )
    set_title(ax, f"{lc.name}: lateral colour, {lc.plane_label(plane)}")
    return fig


def plot_distortion_by_wavelength(
    cd: ChromaticDistortion, ax=None, *, plane: int = 0, relative: bool = False
):
    """Characteristic distortion D0 (mm; Dr in per cent with ``relative``) at each wavelength,
    one curve per wavelength in its colour; the title states the scale (the reference
    wavelength's F0/M0 for all, or each its own).

    D0 = y' − y0' of Pestrecov (1958) Eq. (9) and Dr = D0/y0', with y0' = K0·x of Eq. (8)
    (y' the real chief ray's signed image height, mm), against the field: degrees (field
    angles; nominal angles for a finite object) or mm (object heights). Fields a wavelength
    cannot trace are left out of its curve.

    Parameters
    ----------
    cd : ChromaticDistortion
        From ``osc.characteristic_distortion(..., wavelengths=...)`` (``DataError`` for anything
        else; its ``scale`` decides the constant each wavelength is measured against).
    ax : matplotlib.axes.Axes, optional
        Draw here; default a new pyplot figure.
    plane : int
        Which image plane of ``cd`` (0-based; ``DataError`` outside the range).
    relative : bool
        Plot Dr in per cent instead of D0 in mm.

    Returns
    -------
    matplotlib.figure.Figure
    """
    if not isinstance(cd, ChromaticDistortion):
        raise DataError(
            "expected a ChromaticDistortion (characteristic_distortion(..., wavelengths=...)), "
            f"got {type(cd).__name__}"
        )
    if not 0 <= plane < cd[0].n_planes:
        raise DataError(f"plane={plane}: the result has {cd[0].n_planes} image plane(s)")
    fig, ax = figure_with_zero(ax)
    for k, w in enumerate(cd.wavelengths):
        v = 100.0 * cd.Dr[k, plane] if relative else cd.D0[k, plane]
        ok = np.isfinite(v)
        ax.plot(cd.fields[ok], v[ok], "o-", ms=3, color=wavelength_colour(w), label=f"{w:g} nm")
    label_axes(ax, _field_label(cd[0].field_kind), "Dr (%)" if relative else "D0 (mm)")
    ax.legend(fontsize=8, frameon=False)
    set_title(ax, f"{cd.name}: distortion per wavelength, {cd.scale_description}")
    return fig


def plot_colour_summary(fs: FocalShift, lc: LateralColour, cd: ChromaticDistortion):
    """One figure of three panels: the focal-shift curve, lateral colour and distortion per
    wavelength (first image plane)."""
    fig, axs = panel_figure(1, 3, figsize=(15.0, 4.6))
    plot_focal_shift(fs, ax=axs[0])
    plot_lateral_colour(lc, ax=axs[1])
    plot_distortion_by_wavelength(cd, ax=axs[2])
    return fig


def _field_label(kind: str) -> str:
    """The field axis: object heights, a finite object's nominal angles, or field angles."""
    return {"height": "object height (mm)", NOMINAL_ANGLE: "nominal field angle (deg)"}.get(
        kind, "field angle (deg)"
    )
