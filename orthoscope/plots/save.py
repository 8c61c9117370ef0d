"""Saving figures: the format from the file suffix, written atomically through
:func:`raytrace.files.output.write_atomic` (never onto an input, never over an existing file
unless asked)."""

from __future__ import annotations

import io
import os
from collections.abc import Iterable
from pathlib import Path

from raytrace.errors import OutputError

FORMATS = (".png", ".svg", ".pdf")


def save_figure(
    fig,
    path: str | os.PathLike,
    *,
    overwrite: bool = False,
    inputs: Iterable[str | os.PathLike] = (),
    dpi: int = 150,
    flag: str = "overwrite=True",
) -> Path:
    """Render ``fig`` in the format of ``path``'s suffix (.png, .svg, .pdf) and write it.

    The drawing is cropped to what is drawn (a tight bounding box), except for a fixed page (a
    figure with ``orthoscope_page = True``, e.g. the A4 certificate), which keeps its size.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        E.g. what a ``plot_*`` function returns.
    path : str or os.PathLike
        The file to write; its suffix (any case) picks the format: ``.png``, ``.svg`` or
        ``.pdf`` (else ``OutputError``). Written atomically
        (:func:`raytrace.files.output.write_atomic`).
    overwrite : bool
        Replace an existing file (else ``OutputError``).
    inputs : iterable of str or os.PathLike
        Files the output must never be (e.g. the lens file it was made from): ``OutputError``
        when ``path`` is one of them, ``overwrite`` or not.
    dpi : int
        Dots per inch of a .png (and of any raster part of a .svg or .pdf).
    flag : str
        How the refusal to overwrite names the way to allow it (default the API's
        ``"overwrite=True"``; the command line passes ``"--force"``).

    Returns
    -------
    pathlib.Path
        The path written.
    """
    from raytrace.files.output import check_output, write_atomic

    p = Path(path)
    fmt = p.suffix.lower()
    if fmt not in FORMATS:
        raise OutputError(f"{p}: unsupported plot format {p.suffix!r}; use {', '.join(FORMATS)}")
    check_output(path, inputs=inputs, overwrite=overwrite, flag=flag)  # as given: 'a.png/'
    buf = io.BytesIO()
    bbox = None if getattr(fig, "orthoscope_page", False) else "tight"
    fig.savefig(buf, format=fmt[1:], dpi=dpi, bbox_inches=bbox)
    return write_atomic(p, buf.getvalue(), inputs=inputs, overwrite=overwrite, flag=flag)
