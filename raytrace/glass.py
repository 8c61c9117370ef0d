"""Glass names → nd / vd, through the vendor catalogs of the optional ``opticalglass`` package.

Lens files from Zemax and CODE V name their glasses (``N-SK16``, ``NSK16_SCHOTT``, ``S-BSL7``)
instead of giving numbers. This module resolves such a name to the catalog's published ``nd``
(helium d line, 587.5618 nm) and Abbe number ``vd``, and returns them with the catalog's
dispersion-formula coefficients for information (orthoscope itself models a catalog glass as an
nd/vd model glass, see :mod:`raytrace.materials`).

The catalogs (CDGM, Hikari, Hoya, Ohara, Schott, Sumita spreadsheets) ship inside the
``opticalglass`` package (``pip install 'orthoscope[glass]'``); nothing is downloaded. Without the
package every name lookup raises :class:`~raytrace.errors.PrescriptionError` telling the user to
install it or to replace the name by a model glass.

Name matching ignores case, blanks, hyphens and underscores (``N-SK16`` = ``NSK16`` = ``n sk16``),
so CODE V's hyphen-free spellings match. A name found in several catalogs with different nd/vd is
ambiguous: the error lists the candidates and how to pick one (a catalog suffix ``_SCHOTT``, a
Zemax ``GCAT`` line, or a model glass). Six-digit glass codes (``620603`` → nd 1.620, vd 60.3) and
``nd:vd`` strings are parsed by :func:`parse_glass_code` without any catalog.
"""

from __future__ import annotations

import difflib
import math
import re
import warnings
from dataclasses import dataclass
from functools import cache

from .errors import PrescriptionError
from .materials import Material, model_glass

#: Catalogs of ``opticalglass`` in the order they are searched (names as users write them).
CATALOGS: tuple[str, ...] = ("Schott", "Ohara", "Hoya", "CDGM", "Hikari", "Sumita")

INSTALL_HINT = "install the glass catalogs with: pip install 'orthoscope[glass]'"


@dataclass(frozen=True)
class CatalogGlass:
    """A catalog glass: ``name`` as the vendor spells it, ``catalog`` (e.g. ``"Schott"``),
    ``nd`` and ``vd`` as published, ``formula_coefficients`` the catalog's dispersion-formula
    coefficients (Sellmeier for Schott; vendor formulas otherwise; may be empty)."""

    name: str
    catalog: str
    nd: float
    vd: float
    formula_coefficients: tuple[float, ...] = ()

    @property
    def material(self) -> Material:
        """The nd/vd model glass orthoscope traces with."""
        return model_glass(self.nd, self.vd)


def normalize_name(name: str) -> str:
    """Key used to compare glass names: upper case, only letters, digits and dots."""
    return re.sub(r"[^A-Z0-9.]", "", name.upper())


def catalog_available() -> bool:
    """True when the ``opticalglass`` package (and so the catalogs) can be imported."""
    try:
        import opticalglass.glassfactory  # noqa: F401
    except Exception:
        return False
    return True


def _canonical_catalog(name: str) -> str | None:
    key = normalize_name(name)
    for c in CATALOGS:
        if normalize_name(c) == key or key.startswith(normalize_name(c)):
            # "SUMITA_AUG2011", "SCHOTT" ... (Zemax catalog file names carry dates)
            return c
    return None


@cache
def _catalog_index(catalog: str) -> dict[str, tuple[CatalogGlass, ...]]:
    """normalized name -> glasses of one catalog (loaded once per process)."""
    try:
        import opticalglass.glassfactory as gf
    except Exception as e:  # ImportError, or a broken install
        raise PrescriptionError(
            f"glass names need the optional glass catalogs ({type(e).__name__}: {e}); "
            + INSTALL_HINT
        ) from None
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            cat = gf.get_glass_catalog(catalog)
            df = cat.df
            index: dict[str, list[CatalogGlass]] = {}
            for gname in cat.get_glass_names():
                row = df.loc[gname]
                nd = float(row["refractive indices"]["d"])
                vd = float(row["abbe number"]["vd"])
                if not (math.isfinite(nd) and math.isfinite(vd) and nd > 1.0 and vd > 0.0):
                    continue
                try:
                    coefs = tuple(float(x) for x in cat.glass_coefs(gname))
                except Exception:
                    coefs = ()
                g = CatalogGlass(str(gname).strip(), catalog, nd, vd, coefs)
                index.setdefault(normalize_name(str(gname)), []).append(g)
    except PrescriptionError:
        raise
    except Exception as e:
        raise PrescriptionError(
            f"the {catalog} glass catalog could not be loaded ({type(e).__name__}: {e}); "
            "reinstall it with: pip install --force-reinstall opticalglass"
        ) from None
    return {k: tuple(v) for k, v in index.items()}


def parse_glass_code(text: str) -> Material | None:
    """A model glass from a glass code, or ``None`` when ``text`` is not one.

    Accepted: six-digit codes ``620603`` (nd = 1 + 620/1000, vd = 603/10, the catalog
    convention), dotted codes ``620.603`` and CODE V's long form ``517000.520000`` (the digits
    before the dot are nd − 1, the ones after it vd with two integer digits: nd 1.517,
    vd 52.0), and ``nd:vd`` / ``nd/vd`` strings such as ``1.620:60.3``.
    """
    t = text.strip().strip("'\"")
    m = re.fullmatch(r"(\d{3})(\d{3})|(\d{3,9})\.(\d{3,9})", t)
    if m:
        a, b = (m.group(1), m.group(2)) if m.group(1) else (m.group(3), m.group(4))
        nd = 1.0 + int(a) / 10.0 ** len(a)
        vd = int(b) / 10.0 ** (len(b) - 2)
        return model_glass(nd, vd) if vd > 0 else None
    m = re.fullmatch(r"(\d+(?:\.\d*)?)\s*[:/]\s*(\d+(?:\.\d*)?)", t)
    if m:
        nd, vd = float(m.group(1)), float(m.group(2))
        if 1.0 <= nd < 5.0 and 0.0 < vd < 1000.0:
            return model_glass(nd, vd)
    return None


def find_glass(
    name: str, catalogs: tuple[str, ...] | list[str] | None = None
) -> list[CatalogGlass]:
    """Every catalog glass whose normalized name equals ``name``'s (possibly empty).

    ``catalogs`` limits the search (vendor names, case-insensitive, unknown ones ignored);
    default: all of :data:`CATALOGS`.
    """
    key = normalize_name(name)
    cats = CATALOGS
    if catalogs:
        wanted = [c for c in (_canonical_catalog(x) for x in catalogs) if c is not None]
        cats = tuple(dict.fromkeys(wanted))
    found: list[CatalogGlass] = []
    for c in cats:
        found.extend(_catalog_index(c).get(key, ()))
    return found


def _similar(name: str, limit: int = 5) -> list[str]:
    """Catalog glasses whose name ends with ``name`` (``BK7`` → ``N-BK7``) or is close to it."""
    key = normalize_name(name)
    if not key:
        return []
    everything: dict[str, list[CatalogGlass]] = {}
    for c in CATALOGS:
        for k, gs in _catalog_index(c).items():
            everything.setdefault(k, []).extend(gs)
    keys = [k for k in everything if k.endswith(key) and len(k) - len(key) <= 2]
    keys += [k for k in difflib.get_close_matches(key, list(everything), n=3, cutoff=0.8)]
    out = []
    for k in dict.fromkeys(keys):
        out += [f"{g.name} ({g.catalog})" for g in everything[k]]
    return out[:limit]


def lookup_glass(
    name: str,
    catalogs: tuple[str, ...] | list[str] | None = None,
    *,
    first_catalog_wins: bool = False,
) -> CatalogGlass:
    """Resolve a glass name to one :class:`CatalogGlass`.

    name:      the glass name; a catalog suffix ``NAME_SCHOTT`` (CODE V style) limits the search
               to that catalog.
    catalogs:  preferred catalogs in order (e.g. a Zemax ``GCAT`` line). With
               ``first_catalog_wins`` (Zemax's own rule) the first of them that has the name
               decides; otherwise, and when none of them has it, all catalogs are searched.

    Raises :class:`PrescriptionError` when the catalogs are not installed, the name is unknown,
    or it is ambiguous (several catalogs, different nd/vd); each message says what to do.
    """
    raw = name.strip()
    cats = list(catalogs) if catalogs else []
    if "_" in raw:
        base, _, suffix = raw.rpartition("_")
        if base and _canonical_catalog(suffix) is not None:
            raw, cats, first_catalog_wins = base, [suffix], True
    cand: list[CatalogGlass] = []
    if cats:
        if first_catalog_wins:
            for c in cats:
                cand = find_glass(raw, [c])
                if cand:
                    break
        else:
            cand = find_glass(raw, cats)
    if not cand:
        cand = find_glass(raw)
    if not cand:
        similar = _similar(raw)
        hint = f"; similar catalog names: {', '.join(similar)}" if similar else ""
        raise PrescriptionError(
            f"unknown glass {name!r}: it is in none of the catalogs "
            f"({', '.join(CATALOGS)}){hint}; check the spelling, or replace it by a model glass "
            "with its nd and vd (Zemax: GLAS ___BLANK 1 0 nd vd 0 0 0 0 0 0; CODE V: "
            'nd:vd such as 1.620:60.3; native: glass = "nd/vd")'
        )
    distinct = {(g.nd, g.vd) for g in cand}
    if len(distinct) > 1:
        listing = "; ".join(f"{g.catalog} {g.name} (nd {g.nd:g}, vd {g.vd:g})" for g in cand)
        raise PrescriptionError(
            f"ambiguous glass {name!r}: candidates {listing}. Say which one: add the catalog "
            f"(CODE V: {normalize_name(raw)}_{cand[0].catalog.upper()}; Zemax: a GCAT line "
            f"naming the vendor, e.g. GCAT {cand[0].catalog.upper()}), or give a model glass "
            "with its nd and vd"
        )
    return cand[0]
