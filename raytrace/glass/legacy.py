"""Glass names as real lens files write them: preferred catalogs, successors, moulded glasses,
printed nd/vd, and the strict reading.

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
3. **A data set of a non-catalog material** — ``CAF2_DAIMON-20`` (a ``Misc`` material and a
   suffix that is no catalog, as optiland writes refractiveindex.info data sets): the shipped
   data of the material, with a warning.
4. **Any other catalog** — the name in the catalogs the file does not name; one match (or
   several with equal nd/vd) is used, with a warning when the file named catalogs; several
   different ones make the name ambiguous (refused, listing the candidates). A file that names
   no catalog gets no successor: ``BK7`` alone is refused, its message suggesting ``N-BK7``.
5. **A precision-moulded glass** — moulding versions of catalog glasses carry the parent's name
   with ``_MOLD`` (RPO's Zemax catalog: ``L-TIM28_MOLD``), ``_M`` or ``M`` (LightPath's:
   ``D-ZK3M``, ``D-ZLAF52LA_M``), catalogs orthoscope does not ship. Moulding lowers the index
   (:data:`MOULDING_DND`, :data:`MOULDING_DVD`, measured): the parent's data are used, with a
   warning stating that bias. Where the file prints nd/vd for the glass that a moulded parent
   can have (:data:`MOULDED_ND_WINDOW`, :data:`MOULDED_VD_WINDOW`) and that differ from the
   parent's beyond the tolerances of step 2, a model glass of the printed nd/vd is used (its nd
   is the moulded glass's). Printed numbers no moulded parent can have are not the glass's
   (OpticStudio traces a catalog glass from its catalog, not from these cached numbers;
   ``rayoptics/354710-C-Zemax(ZMX).zmx`` prints for ``D-ZK3M`` the Abbe number of LightPath's
   ECO-550) and are ignored, with a warning.
6. **The file's own nd/vd** — a name nothing above resolves, on a line that prints nd and vd
   (:func:`printed_nd_vd`): a model glass of those numbers, with a warning that its dispersion
   is the model's and how far the model is from real glasses of similar nd/vd
   (:func:`model_glass_error`).

A name none of these resolves is refused with the fix (a model glass, or the catalog to add).
Old Schott glasses that no later catalog lists are shipped from Schott's 1980 catalog as
Robb & Mercado fitted it (status ``legacy``; :data:`HISTORICAL_SOURCE`): such a glass is used
as named, with a warning naming the data and their accuracy; printed nd/vd beyond the
tolerances of step 2 make a model glass, as there.

**Strict reading** (``resolve_glass(..., strict=True)``, the :func:`strict_glasses` block, or
``raytrace.files.read_lens_file(path, strict=True)``): every step that puts another glass or a
model glass in place of the named one (2, 3, 4 when the file names catalogs, 5, 6, and a model
glass instead of the 1980 data) raises :class:`~raytrace.errors.PrescriptionError` instead;
the named glass's own data (step 1, step 4 without named catalogs, the 1980 fits) are used.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass
from dataclasses import replace as dataclass_replace

import numpy as np

from ..errors import PrescriptionError
from ..materials import LAMBDA_C, Material, model_glass
from .catalog import (
    CatalogGlass,
    canonical_catalog,
    find_glass,
    lookup_glass,
    normalize_name,
    search_glass,
    split_catalog_suffix,
)

#: vendor → prefix of its successor glasses (Schott's lead- and arsenic-free "N-" glasses)
SUCCESSOR_PREFIX: dict[str, str] = {"Schott": "N-"}

#: largest |nd(successor) − nd(printed)| and |vd(successor) − vd(printed)| for which the
#: successor is used; beyond either, the file's nd/vd model glass is used
ND_TOLERANCE = 5e-4
VD_TOLERANCE = 0.5

#: (nd, vd) that OpticStudio writes after a catalog glass name as placeholders, not data
PLACEHOLDER_ND_VD: tuple[tuple[float, float], ...] = ((1.5, 40.0), (0.0, 0.0))

#: name endings of precision-moulded glasses, tried in this order: RPO's ``_MOLD``
#: (``L-TIM28_MOLD``), LightPath's ``_M`` and ``M`` (``D-ZLAF52LA_M``, ``D-ZK3M``)
MOULDED_SUFFIXES: tuple[str, ...] = ("_MOLD", "-MOLD", "_M", "M")

#: nd(moulded) − nd(parent) and vd(moulded) − vd(parent), smallest and largest, measured on the
#: 32 moulded glasses whose parents orthoscope ships in the RPO Zemax catalog (rpo.agf,
#: "Updated 2/25/2009") and the LightPath one (lightpath.agf), as KrakenOS 1.0.0.24 and
#: ZemaxGlass 1.0 redistribute them (median Δnd −0.0046; e.g. L-TIM28_MOLD −0.00545 / −0.16,
#: D-ZK3M −0.00271 / −0.44). Those catalogs are not shipped (no licence to redistribute).
MOULDING_DND: tuple[float, float] = (-0.0102, -0.0019)
MOULDING_DVD: tuple[float, float] = (-0.64, -0.08)
MOULDING_DND_MEDIAN = -0.0046

#: printed nd/vd minus the parent's that a moulded glass can have: the measured ranges above,
#: widened by half again, up to the tolerances of an equal glass
MOULDED_ND_WINDOW: tuple[float, float] = (-0.015, ND_TOLERANCE)
MOULDED_VD_WINDOW: tuple[float, float] = (-1.5, VD_TOLERANCE)

#: source key (:func:`~raytrace.glass.catalog_sources`) of the Schott 1980 glasses: Robb &
#: Mercado's fits (Appl. Opt. 22, 1198, 1983, Table V)
HISTORICAL_SOURCE = "robb1983_data_final.txt"

#: wavelengths (nm) over which :func:`model_glass_error` compares the model with real glasses
VISIBLE_NM: tuple[float, float] = (400.0, 700.0)

_STRICT: ContextVar[bool] = ContextVar("raytrace_glass_strict", default=False)


@contextmanager
def strict_glasses(on: bool = True) -> Iterator[None]:
    """Within the block, :func:`resolve_glass` (``strict=None``, as the file readers call it)
    reads strictly: every substitute glass is refused (see the module docstring)."""
    token = _STRICT.set(bool(on))
    try:
        yield
    finally:
        _STRICT.reset(token)


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


def _split_suffix(name: str, catalogs: list[str]) -> tuple[str, list[str]]:
    base, suffix = split_catalog_suffix(name)
    return base, ([suffix] if suffix is not None else catalogs)


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


@dataclass(frozen=True)
class ModelGlassError:
    """How far the nd/vd model glass is from real glasses of similar nd/vd.

    glasses:
        the catalog glasses compared (``"Schott N-SK16"``, ...): the current ones nearest to
        the nd/vd asked for (:func:`~raytrace.glass.search_glass`).
    visible, g_to_c:
        the largest ``|n_model(nd_g, vd_g) − n_g|`` over those glasses, over
        :data:`VISIBLE_NM` and over the g to C lines (435.8–656.3 nm), each glass's model
        built from its own catalog nd and vd.
    """

    glasses: tuple[str, ...]
    visible: float
    g_to_c: float


def model_glass_error(nd: float, vd: float, n: int = 5) -> ModelGlassError:
    """The index error of the nd/vd model glass (:func:`~raytrace.materials.model_glass`, the
    law the file readers use for nd/vd glasses), measured on the ``n`` current catalog glasses
    nearest to (``nd``, ``vd``): each glass's vendor formula against the model of its own
    catalog nd and vd, on the part of the wavelength bands its data cover."""
    lam = np.linspace(*VISIBLE_NM, 61)
    g_line = 435.8343  # nm, the g line (Schott TIE-29)
    names, e_vis, e_gc = [], 0.0, 0.0
    for hit in search_glass(nd, vd, n):
        g = hit.glass
        lo, hi = g.wavelength_range_nm
        w = lam[(lam >= lo) & (lam <= hi)]
        if w.size == 0:
            continue
        diff = np.abs(model_glass(g.nd, g.vd).index(w) - g.material.index(w))
        names.append(f"{g.catalog} {g.name}")
        e_vis = max(e_vis, float(diff.max()))
        gc = (w >= g_line) & (w <= LAMBDA_C)
        if gc.any():
            e_gc = max(e_gc, float(diff[gc].max()))
    return ModelGlassError(tuple(names), e_vis, e_gc)


def _model_dispersion_note(nd: float, vd: float) -> str:
    err = model_glass_error(nd, vd)
    return (
        "its index equals the printed nd at the d line and its dispersion is orthoscope's nd/vd "
        "model (n = A + B/λ², exact nF − nC), not the vendor's formula: against the "
        f"{len(err.glasses)} current catalog glasses nearest to these nd/vd "
        f"({', '.join(err.glasses)}) the model is off by up to {err.visible:.1e} in n over "
        f"{VISIBLE_NM[0]:g}-{VISIBLE_NM[1]:g} nm ({err.g_to_c:.1e} from the g to the C line), "
        "more outside"
    )


def _substitute(r: GlassResolution, strict: bool) -> GlassResolution:
    """``r`` (a resolution that uses another glass or a model glass), or the strict refusal."""
    if strict:
        raise PrescriptionError(
            "a strict reading takes no substitute glass: write the glass the lens needs into the "
            "file (a shipped catalog glass, or a model glass with its nd and vd), or read "
            f"without strict, which warns: {r.warning}"
        )
    return r


def _historical(
    name: str, g: CatalogGlass, head: str, printed: tuple[float, float] | None
) -> GlassResolution:
    """A Schott 1980 glass (:data:`HISTORICAL_SOURCE`): its fit, or the file's nd/vd model
    glass (``glass`` None) where the file prints numbers beyond the tolerances."""
    m = re.search(r"max error ([0-9.eE+-]+) at ([0-9.]+) µm", g.note)
    err = f"largest error {m.group(1)} at {m.group(2)} µm, " if m else ""
    lo, hi = g.wavelength_range_nm
    data = (
        f"glass {name}: {g.name} is in no current catalog; its data are Schott's 1980 catalog as "
        f"Robb & Mercado fitted it (Appl. Opt. 22, 1198 (1983), Table V: Buchdahl quadratic, "
        f"{err}nd {g.nd:.6g}, vd {g.vd:.2f}), valid {lo:g}-{hi:g} nm and extrapolated outside"
    )
    text = "; ".join(x for x in (head, data) if x)
    if printed is not None:
        nd, vd = printed
        dnd, dvd = nd - g.nd, vd - g.vd
        if abs(dnd) > ND_TOLERANCE or abs(dvd) > VD_TOLERANCE:
            return GlassResolution(
                name,
                model_glass(nd, vd),
                None,
                f"{text}; the file prints nd {nd:.10g}, vd {vd:.10g} for it (Δnd {dnd:+.2e}, "
                f"Δvd {dvd:+.3f} from the 1980 data, more than {ND_TOLERANCE:g} / "
                f"{VD_TOLERANCE:g}): a model glass with the file's nd and vd is used "
                f"instead — {_model_dispersion_note(nd, vd)}",
            )
        text += f"; the file's nd {nd:.10g}, vd {vd:.10g} agree (Δnd {dnd:+.2e}, Δvd {dvd:+.3f})"
    return GlassResolution(name, g.material, g, text)


def _found(
    name: str,
    g: CatalogGlass,
    head: str,
    printed: tuple[float, float] | None,
    strict: bool,
) -> GlassResolution:
    """The resolution of a catalog glass found by its name; ``head``: the warning when it is
    not in the catalogs the file names (a substitute), else empty. A substitute (that, or a
    model glass in place of a 1980 glass) goes through :func:`_substitute`."""
    if g.source == HISTORICAL_SOURCE:
        r = _historical(name, g, head, printed)
    else:
        r = GlassResolution(name, g.material, g, head)
    return _substitute(r, strict) if head or r.glass is None else r


def _unshipped_note(unshipped: list[str]) -> str:
    """`` (the file names RPO, which orthoscope does not ship)`` or empty."""
    if not unshipped:
        return ""
    return f" (the file names {', '.join(unshipped)}, which orthoscope does not ship)"


def _parent(raw: str, named: tuple[str, ...]) -> tuple[str, CatalogGlass] | None:
    """(suffix, parent glass) when ``raw`` is a moulded glass's name (:data:`MOULDED_SUFFIXES`)
    whose parent one catalog glass is (the catalogs the file names first)."""
    key = raw.strip().upper()
    for suffix in MOULDED_SUFFIXES:
        if not key.endswith(suffix) or len(key) == len(suffix):
            continue
        base = raw.strip()[: -len(suffix)]
        for c in named:
            found = find_glass(base, [c])
            if found:
                return raw.strip()[-len(suffix) :], found[0]
        try:
            return raw.strip()[-len(suffix) :], lookup_glass(base)
        except PrescriptionError:
            continue
    return None


def _moulded(
    name: str,
    raw: str,
    named: tuple[str, ...],
    unshipped: list[str],
    printed: tuple[float, float] | None,
    strict: bool,
) -> GlassResolution | None:
    """Step 5 of the module docstring, or None when ``raw`` is no moulded glass's name."""
    hit = _parent(raw, named)
    if hit is None:
        return None
    suffix, g = hit
    where = _unshipped_note(unshipped)
    bias = (
        f"moulding lowers the index: by {-MOULDING_DND[1]:g} to {-MOULDING_DND[0]:g} in nd "
        f"(median {-MOULDING_DND_MEDIAN:g}) and {-MOULDING_DVD[1]:g} to {-MOULDING_DVD[0]:g} "
        "in vd for the moulded glasses of RPO's and LightPath's catalogs against their parents"
    )
    head = (
        f"glass {name}: {raw} is in none of the shipped catalogs{where}; the ending {suffix!r} "
        f"marks a precision-moulded {g.name}"
    )
    parent = GlassResolution(
        name,
        g.material,
        g,
        f"{head}, so the data of its parent {_describe(g)} are used; {bias}",
    )
    if printed is None:
        parent = dataclass_replace(
            parent,
            warning=parent.warning
            + f"; the file prints no nd/vd for {raw}: if the lens needs the moulded glass's own "
            "index, give it as a model glass with its nd and vd",
        )
        return _substitute(parent, strict)
    nd, vd = printed
    dnd, dvd = nd - g.nd, vd - g.vd
    diff = f"Δnd {dnd:+.2e}, Δvd {dvd:+.3f} from {g.name}"
    if abs(dnd) <= ND_TOLERANCE and abs(dvd) <= VD_TOLERANCE:
        return _substitute(
            dataclass_replace(
                parent,
                warning=parent.warning
                + f"; the file's nd {nd:.10g}, vd {vd:.10g} are the parent's ({diff})",
            ),
            strict,
        )
    lo_n, hi_n = MOULDED_ND_WINDOW
    lo_v, hi_v = MOULDED_VD_WINDOW
    if lo_n <= dnd <= hi_n and lo_v <= dvd <= hi_v:
        return _substitute(
            GlassResolution(
                name,
                model_glass(nd, vd),
                None,
                f"{head} ({_describe(g)}), and the file prints nd {nd:.10g}, vd {vd:.10g} for it "
                f"({diff}: a moulding drop), so a model glass with the file's nd and vd is used — "
                f"{_model_dispersion_note(nd, vd)}",
            ),
            strict,
        )
    return _substitute(
        dataclass_replace(
            parent,
            warning=parent.warning
            + f"; the file prints nd {nd:.10g}, vd {vd:.10g} for it ({diff}), which no "
            f"moulded {g.name} has: those numbers are not this glass's and are ignored "
            "(OpticStudio traces a catalog glass from its catalog, not from the numbers on the "
            "GLAS line)",
        ),
        strict,
    )


def resolve_glass(
    name: str,
    catalogs: tuple[str, ...] | list[str] | None = None,
    *,
    printed: tuple[float, float] | None = None,
    strict: bool | None = None,
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
    strict:
        refuse every substitute glass (module docstring, "Strict reading"); ``None``: as the
        enclosing :func:`strict_glasses` block says (default: not strict).

    Raises :class:`~raytrace.errors.PrescriptionError` for a name found nowhere (naming the
    printed nd/vd and the model-glass line to use), ambiguous across catalogs the file does
    not name, or, reading strictly, resolved only by a substitute.
    """
    strict = _STRICT.get() if strict is None else bool(strict)
    raw, cats = _split_suffix(name, list(catalogs) if catalogs else [])
    named = tuple(dict.fromkeys(c for c in map(canonical_catalog, cats) if c is not None))
    for c in named:
        found = find_glass(raw, [c])
        if found:
            return _found(name, found[0], "", printed, strict)
    succ = _successor(raw, named)
    if succ is not None:
        return _substitute(_successor_resolution(name, raw, succ, printed), strict)
    data_set = _misc_data_set(name, raw)
    if data_set is not None:
        return _substitute(data_set, strict)
    unshipped = [c for c in cats if canonical_catalog(c) is None]
    try:
        g = lookup_glass(raw)
    except PrescriptionError as e:
        if "unknown glass" in e.reason:
            moulded = _moulded(name, raw, named, unshipped, printed, strict)
            if moulded is not None:
                return moulded
            if printed is not None:
                nd, vd = printed
                where = _unshipped_note(unshipped)
                return _substitute(
                    GlassResolution(
                        name,
                        model_glass(nd, vd),
                        None,
                        f"glass {name}: {raw} is in none of the shipped catalogs{where}; the file "
                        f"prints nd {nd:.10g}, vd {vd:.10g} for it (the catalog values "
                        "OpticStudio shows), and a model glass with them is used — "
                        f"{_model_dispersion_note(nd, vd)}",
                    ),
                    strict,
                )
        where = (
            f"; the catalogs the file names ({', '.join(named)}) have neither {raw} nor a "
            "successor of it"
            if named
            else ""
        )
        missing = (
            f"; the file also names catalogs orthoscope does not ship ({', '.join(unshipped)}): "
            "the glass may be theirs"
            if unshipped
            else ""
        )
        raise PrescriptionError(f"{e.reason}{where}{missing}") from None
    if not named:
        return _found(name, g, "", printed, strict)
    return _found(
        name,
        g,
        f"glass {name}: {raw} is in none of the catalogs the file names ({', '.join(named)}) "
        f"and none of them has a successor of it; {_describe(g)}, the only catalog glass of "
        "that name, is used — if the file means another vendor's glass, give it as a model "
        "glass with its nd and vd",
        printed,
        strict,
    )
