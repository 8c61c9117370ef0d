"""Glass names as real lens files write them: preferred catalogs, successors, printed nd/vd.

:func:`resolve_glass` is what the file readers call. It resolves a name in this order:

1. **The catalogs the file names** — a Zemax ``GCAT`` line (in its order) or a CODE V
   ``NAME_VENDOR`` suffix (``BK7_SCHOTT`` → Schott): the first of them that has the name wins,
   silently (OpticStudio's rule).
2. **A successor in a named catalog** — Schott renamed its lead- and arsenic-free glasses with
   an ``N-`` prefix (``BK7`` → ``N-BK7``, ``LAF2`` → ``N-LAF2``); a name that a named catalog
   lacks while that catalog has the prefixed name (:data:`SUCCESSOR_PREFIX`) resolves to the
   successor, with a warning naming both glasses. The old glass's data are not shipped, so the
   difference is stated only where the file prints the old glass's nd and vd (Zemax ``GLAS NAME
   0 0 nd vd``); if it exceeds :data:`ND_TOLERANCE` or :data:`VD_TOLERANCE`, the file's nd/vd
   model glass is used instead, and the warning says so.
3. **Any other catalog** — the name in the catalogs the file does not name; one match (or
   several with equal nd/vd) is used, with a warning when the file named catalogs; several
   different ones make the name ambiguous (refused, listing the candidates). A file that names
   no catalog gets no successor: ``BK7`` alone is refused, its message suggesting ``N-BK7``.
4. **A data set of a non-catalog material** — ``CAF2_DAIMON-20`` (a ``Misc`` material and a
   suffix that is no catalog, as optiland writes refractiveindex.info data sets): the shipped
   data of the material, with a warning.

Nothing is invented: the successor rule and the file's own numbers are the only evidence used.
A name that none of these resolves is refused with the fix (a model glass, or the catalog to
add), and with the nd/vd the file prints, if any.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import PrescriptionError
from ..materials import Material, model_glass
from .catalog import (
    CatalogGlass,
    canonical_catalog,
    find_glass,
    lookup_glass,
    normalize_name,
)

#: vendor → prefix of its successor glasses (Schott's lead- and arsenic-free "N-" glasses)
SUCCESSOR_PREFIX: dict[str, str] = {"Schott": "N-"}

#: largest |nd(successor) − nd(printed)| and |vd(successor) − vd(printed)| for which the
#: successor is used; beyond either, the file's nd/vd model glass is used
ND_TOLERANCE = 5e-4
VD_TOLERANCE = 0.5

#: (nd, vd) that OpticStudio writes after a catalog glass name as placeholders, not data
PLACEHOLDER_ND_VD: tuple[tuple[float, float], ...] = ((1.5, 40.0), (0.0, 0.0))


@dataclass(frozen=True)
class GlassResolution:
    """What a glass name in a lens file resolved to.

    name:
        the name as the file writes it.
    material:
        the material to use (the catalog glass's, or a model glass of the file's nd/vd).
    glass:
        the catalog glass used, or ``None`` when ``material`` is a model glass.
    warning:
        one line for the user when something other than the named glass is used (a successor,
        another vendor's glass, a model glass); empty when the name resolved as written.
    """

    name: str
    material: Material
    glass: CatalogGlass | None
    warning: str = ""


def printed_nd_vd(fields: list[str] | tuple[str, ...]) -> tuple[float, float] | None:
    """The nd and vd a Zemax ``GLAS`` line prints for a catalog glass, or ``None``.

    ``fields`` are the tokens after ``GLAS`` (name first). OpticStudio writes ``NAME solve pickup
    nd vd dPgF ...``; the numbers are taken as the glass's only for a fixed glass (solve 0) and
    when they are not the placeholders of :data:`PLACEHOLDER_ND_VD` (files also carry left-over
    model values under a substitute solve, 3, which are not the glass's).
    """
    if len(fields) < 5 or fields[1] != "0":
        return None
    try:
        nd, vd = float(fields[3]), float(fields[4])
    except ValueError:
        return None
    if not (math.isfinite(nd) and math.isfinite(vd)) or nd <= 1.0 or vd <= 0.0:
        return None
    if any(nd == a and vd == b for a, b in PLACEHOLDER_ND_VD):
        return None
    return nd, vd


def _describe(g: CatalogGlass) -> str:
    extra = f", {g.status}" if g.status else ""
    return f"{g.catalog} {g.name} (nd {g.nd:.6g}, vd {g.vd:.2f}{extra})"


def _model_line(nd: float, vd: float) -> str:
    return f"GLAS ___BLANK 1 0 {nd:.10g} {vd:.10g}; CODE V: {nd:.10g}:{vd:.10g}"


def _split_suffix(name: str, catalogs: list[str]) -> tuple[str, list[str]]:
    raw = name.strip()
    if "_" in raw:
        base, _, suffix = raw.rpartition("_")
        if base and canonical_catalog(suffix) is not None and not find_glass(raw):
            return base, [suffix]
    return raw, catalogs


def _successor(raw: str, cats: tuple[str, ...]) -> CatalogGlass | None:
    key = normalize_name(raw)
    for c in cats:
        prefix = SUCCESSOR_PREFIX.get(c)
        if prefix is None or key.startswith(normalize_name(prefix)):
            continue
        found = find_glass(prefix + raw, [c])
        if found:
            return found[0]
    return None


def _successor_resolution(
    name: str, raw: str, g: CatalogGlass, printed: tuple[float, float] | None
) -> GlassResolution:
    head = (
        f"glass {name}: {raw} is not in the shipped {g.catalog} catalog (an older name); its "
        f"successor {_describe(g)} is used"
    )
    others = [x for x in find_glass(raw) if x.catalog != g.catalog]
    also = f"; other catalogs' {raw}: {', '.join(map(_describe, others))}" if others else ""
    if printed is None:
        return GlassResolution(
            name,
            g.material,
            g,
            f"{head}. The file does not print {raw}'s nd/vd, so the difference between the two "
            f"glasses is not known here{also}; if the lens needs the old glass, give it as a "
            "model glass with its nd and vd",
        )
    nd, vd = printed
    dnd, dvd = g.nd - nd, g.vd - vd
    diff = (
        f"{g.name} differs from the file's nd {nd:g}, vd {vd:g} by Δnd {dnd:+.2e}, Δvd {dvd:+.3f}"
    )
    if abs(dnd) <= ND_TOLERANCE and abs(dvd) <= VD_TOLERANCE:
        return GlassResolution(name, g.material, g, f"{head}; {diff}")
    return GlassResolution(
        name,
        model_glass(nd, vd),
        None,
        f"glass {name}: {raw} is not in the shipped {g.catalog} catalog and its successor "
        f"{_describe(g)} differs from the file's nd {nd:g}, vd {vd:g} by Δnd {dnd:+.2e}, "
        f"Δvd {dvd:+.3f} (more than {ND_TOLERANCE:g} / {VD_TOLERANCE:g}): a model glass with the "
        "file's nd and vd is used instead",
    )


def _misc_data_set(name: str, raw: str) -> GlassResolution | None:
    """``MATERIAL_DATASET`` (``CAF2_DAIMON-20``): a non-catalog material (catalog ``Misc``)
    with a suffix naming one of its measured data sets — optiland reads such a name as a
    refractiveindex.info page (``main/CaF2/Daimon-20.yml``). The shipped data set of the
    material is used, with a warning naming both; None when ``raw`` is not of that form."""
    if "_" not in raw or find_glass(raw):
        return None
    base, _, suffix = raw.rpartition("_")
    if not base or canonical_catalog(suffix) is not None:
        return None
    found = find_glass(base, ["Misc"])
    if len(found) != 1 or find_glass(base) != found:
        return None
    g = found[0]
    return GlassResolution(
        name,
        g.material,
        g,
        f"glass {name}: {suffix!r} is not a catalog orthoscope ships; it names a data set of "
        f"{base} that is not shipped either, so the shipped {_describe(g)} from {g.source} is "
        f"used; if the named data set matters, give {base} as a model glass with its nd and vd",
    )


def resolve_glass(
    name: str,
    catalogs: tuple[str, ...] | list[str] | None = None,
    *,
    printed: tuple[float, float] | None = None,
) -> GlassResolution:
    """Resolve a glass name from a lens file (see the module docstring for the order).

    name:
        the name as written (a CODE V ``NAME_VENDOR`` suffix names the catalog).
    catalogs:
        the catalogs the file names, in order (Zemax ``GCAT``; vendor names, case-insensitive;
        ones orthoscope does not ship, such as ``INFRARED`` or ``LIGHTPATH``, are not searched
        and are named in a refusal).
    printed:
        (nd, vd) the file prints for this glass (:func:`printed_nd_vd`), or ``None``.

    Raises :class:`~raytrace.errors.PrescriptionError` for a name found nowhere (naming the
    printed nd/vd and the model-glass line to use) or ambiguous across catalogs the file does
    not name.
    """
    raw, cats = _split_suffix(name, list(catalogs) if catalogs else [])
    named = tuple(dict.fromkeys(c for c in map(canonical_catalog, cats) if c is not None))
    for c in named:
        found = find_glass(raw, [c])
        if found:
            return GlassResolution(name, found[0].material, found[0])
    succ = _successor(raw, named)
    if succ is not None:
        return _successor_resolution(name, raw, succ, printed)
    data_set = _misc_data_set(name, raw)
    if data_set is not None:
        return data_set
    try:
        g = lookup_glass(raw)
    except PrescriptionError as e:
        where = (
            f"; the catalogs the file names ({', '.join(named)}) have neither {raw} nor a "
            "successor of it"
            if named
            else ""
        )
        prints = (
            f"; the file prints nd {printed[0]:.10g}, vd {printed[1]:.10g} for it — to use those, "
            f"replace the glass by a model glass ({_model_line(*printed)})"
            if printed is not None
            else ""
        )
        unshipped = [c for c in cats if canonical_catalog(c) is None]
        missing = (
            f"; the file also names catalogs orthoscope does not ship ({', '.join(unshipped)}): "
            "the glass may be theirs"
            if unshipped
            else ""
        )
        raise PrescriptionError(f"{e.reason}{where}{missing}{prints}") from None
    if not named:
        return GlassResolution(name, g.material, g)
    return GlassResolution(
        name,
        g.material,
        g,
        f"glass {name}: {raw} is in none of the catalogs the file names ({', '.join(named)}) "
        f"and none of them has a successor of it; {_describe(g)}, the only catalog glass of "
        "that name, is used — if the file means another vendor's glass, give it as a model "
        "glass with its nd and vd",
    )
