"""The glass-substitution pool: which real catalog glasses a ``glass`` variable may take.

A pool is built from the shipped catalogs (:mod:`raytrace.glass`) with a spec's
:class:`~raytrace.optimize.spec.GlassSettings`: the catalogs searched, the availability classes
allowed, nd / vd windows, or an explicit list of names. Glasses with identical catalog nd and vd
(a vendor's HT / HTi variants of one glass, a name in two catalogs) enter once, the first in
catalog order. Distances on the glass map are in units of the six-digit glass code, as
:func:`raytrace.glass.search_glass` measures them: ``sqrt((1000 Δnd)² + (10 Δvd)²)``.

Availability classes come from the catalog's status field (the only availability data the
shipped catalogs carry): ``current`` (listed in the vendor's current catalog edition),
``withdrawn`` (only in the previous edition), ``legacy`` (only in the refractiveindex.info
shelf of older vendor glasses). The catalogs carry no price and no preferred / inquiry flag.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from ..errors import PrescriptionError
from ..glass import CatalogGlass, catalog_glasses, lookup_glass
from ..glass.catalog import RETIRED
from ..materials import Material
from .spec import GlassSettings, SpecError


def availability(g: CatalogGlass) -> str:
    """Availability class of a catalog glass: ``current``, ``withdrawn`` or ``legacy``."""
    if g.status == "withdrawn":
        return "withdrawn"
    if g.status in RETIRED:
        return "legacy"
    return "current"


def glass_code_distance(nd1, vd1, nd2, vd2):
    """Distance on the glass map in glass-code units (0.001 in nd or 0.1 in vd is one unit)."""
    return np.hypot(1000.0 * (np.asarray(nd1) - nd2), 10.0 * (np.asarray(vd1) - vd2))


@dataclass(frozen=True, eq=False)
class GlassPool:
    """The candidate glasses of a glass variable, in catalog order.

    glasses: the candidates; nd, vd: their catalog d-line index and Abbe number (arrays);
    settings: what built the pool.
    """

    glasses: tuple[CatalogGlass, ...]
    nd: np.ndarray
    vd: np.ndarray
    settings: GlassSettings

    def __len__(self) -> int:
        return len(self.glasses)

    def material(self, i: int) -> Material:
        """The vendor-formula material of candidate ``i``."""
        return self.glasses[int(i)].material

    def nearest(self, nd: float, vd: float, n: int = 1) -> np.ndarray:
        """Indices of the ``n`` candidates nearest to (nd, vd), nearest first (ties: pool
        order)."""
        d = glass_code_distance(self.nd, self.vd, nd, vd)
        return np.argsort(d, kind="stable")[: max(1, n)]

    def neighbours(self, i: int, n: int) -> np.ndarray:
        """Indices of the ``n`` candidates nearest to candidate ``i``, ``i`` itself excluded."""
        near = self.nearest(self.nd[i], self.vd[i], n + 1)
        return near[near != i][:n]

    def index_of(self, m: Material) -> int | None:
        """The candidate that is material ``m`` (same name and catalog), or None."""
        if m.kind != "catalog":
            return None
        for i, g in enumerate(self.glasses):
            if g.name == m.name and g.catalog == m.catalog:
                return i
        return None

    def window(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """(nd_min, nd_max), (vd_min, vd_max) of the candidates."""
        return (float(self.nd.min()), float(self.nd.max())), (
            float(self.vd.min()),
            float(self.vd.max()),
        )

    def __repr__(self) -> str:
        (a, b), (c, d) = self.window()
        return f"GlassPool({len(self)} glasses, nd {a:.4f}-{b:.4f}, vd {c:.2f}-{d:.2f})"


@functools.cache
def glass_pool(settings: GlassSettings) -> GlassPool:
    """The substitution pool of ``settings`` (cached per process).

    Raises :class:`SpecError` for an unknown glass name or an empty pool.
    """
    if settings.glasses:
        cand = []
        for name in settings.glasses:
            try:
                cand.append(lookup_glass(name, settings.catalogs))
            except PrescriptionError as e:
                raise SpecError(f"glass pool: {e}") from None
    else:
        cand = [g for c in settings.catalogs for g in catalog_glasses(c)]
    lo_n, hi_n = settings.nd
    lo_v, hi_v = settings.vd
    seen: set[tuple[float, float]] = set()
    keep: list[CatalogGlass] = []
    for g in cand:
        if not (math.isfinite(g.nd) and math.isfinite(g.vd)):
            continue
        if availability(g) not in settings.availability:
            continue
        if not (lo_n <= g.nd <= hi_n and lo_v <= g.vd <= hi_v):
            continue
        if math.isfinite(settings.max_price) and not g.price <= settings.max_price:
            continue  # no printed price (nan) or above the cost class
        if (g.nd, g.vd) in seen:
            continue
        seen.add((g.nd, g.vd))
        keep.append(g)
    if not keep:
        raise SpecError(
            f"glass pool: no glass of {', '.join(settings.catalogs)} with availability "
            f"{', '.join(settings.availability)} lies in nd {settings.nd[0]}..{settings.nd[1]}, "
            f"vd {settings.vd[0]}..{settings.vd[1]}"
            + (
                f", relative price <= {settings.max_price:g} (Schott / CDGM prices only)"
                if math.isfinite(settings.max_price)
                else ""
            )
            + (f" among {', '.join(settings.glasses)}" if settings.glasses else "")
            + "; widen the windows or allow more catalogs / classes"
            + (" or raise max_price" if math.isfinite(settings.max_price) else "")
        )
    return GlassPool(
        tuple(keep),
        np.array([g.nd for g in keep]),
        np.array([g.vd for g in keep]),
        settings,
    )
