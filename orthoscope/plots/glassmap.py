"""The glass map (Abbe diagram): catalog glasses as nd over vd, with vd decreasing to the right
as the vendors draw it, coloured by availability class, and the glasses a design chose marked
and labelled."""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence

from matplotlib.figure import Figure

#: marker colour per availability class (raytrace.optimize.glasses.availability)
CLASS_COLOURS = {"current": "tab:blue", "withdrawn": "tab:orange", "legacy": "0.7"}


def plot_glass_map(
    glasses: Iterable,
    chosen: Sequence = (),
    *,
    title: str | None = None,
    annotate: bool = True,
) -> Figure:
    """Draw catalog glasses on the nd–vd map and mark the ``chosen`` ones.

    Parameters
    ----------
    glasses : iterable of CatalogGlass
        The glasses to show (e.g. ``raytrace.optimize.glass_pool(settings).glasses``); each has
        ``nd``, ``vd``, ``name``, ``catalog`` and ``status``.
    chosen : sequence
        Glasses to mark: objects with ``nd``, ``vd``, ``name`` and, optionally, ``surface`` and
        ``catalog`` (``raytrace.optimize.GlassChoice``, ``CatalogGlass``).
    title : str, optional
        Figure title (default: "Glass map").
    annotate : bool
        Label the chosen glasses with surface, name, catalog and, where the vendor prints one,
        the relative price (``price``: Schott N-BK7 = 1, CDGM H-K9L = 1).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from raytrace.optimize.glasses import availability

    fig = Figure(figsize=(7.5, 5.5))
    ax = fig.add_subplot(1, 1, 1)
    by_class: dict[str, list] = {}
    n = 0
    for g in glasses:
        by_class.setdefault(availability(g), []).append(g)
        n += 1
    for cls in ("legacy", "withdrawn", "current"):
        gs = by_class.get(cls, [])
        if gs:
            ax.scatter(
                [g.vd for g in gs],
                [g.nd for g in gs],
                s=9,
                color=CLASS_COLOURS[cls],
                label=f"{cls} ({len(gs)})",
                zorder=2 if cls == "current" else 1,
            )
    for c in chosen:
        ax.scatter([c.vd], [c.nd], s=90, facecolors="none", edgecolors="tab:red", lw=1.8, zorder=3)
        if annotate:
            surf = getattr(c, "surface", None)
            cat = getattr(c, "catalog", "")
            price = getattr(c, "price", math.nan)
            extra = ", ".join(x for x in (cat, f"price {price:g}" if price == price else "") if x)
            text = (
                (f"S{surf}: " if surf is not None else "")
                + c.name
                + (f" ({extra})" if extra else "")
            )
            ax.annotate(
                text,
                (c.vd, c.nd),
                xytext=(6, 6),
                textcoords="offset points",
                fontsize=8,
                color="tab:red",
                bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": "none", "alpha": 0.8},
                zorder=4,
            )
    if chosen:
        ax.scatter([], [], s=90, facecolors="none", edgecolors="tab:red", label="chosen")
    ax.invert_xaxis()  # the Abbe diagram: vd decreases to the right
    ax.set_xlabel("Abbe number $v_d$")
    ax.set_ylabel("refractive index $n_d$")
    ax.set_title(title or f"Glass map ({n} glasses)")
    ax.grid(True, lw=0.3, alpha=0.5)
    if n or chosen:
        ax.legend(loc="upper left", fontsize=8)
    return fig
