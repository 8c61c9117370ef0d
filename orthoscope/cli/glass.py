"""``orthoscope glass``: a catalog glass (formula, range, nd, vd, n at wavelengths), or the
catalog glasses nearest to an nd/vd pair (``--search nd=1.62,vd=60``). No numba: it starts
fast."""

from __future__ import annotations

import argparse
import math

from .colour import add_wavelengths_arg
from .common import CliError, add_output_args, add_strict_arg, print_result

SAMPLES = [
    ["glass", "N-BK7", "--wavelengths", "F,d,C"],
    ["glass", "--search", "nd=1.62,vd=60"],
]
OUTPUTS = []
#: glasses --search lists without --count
DEFAULT_COUNT = 10


def _price(text: str) -> float:
    """--max-price: a positive relative price."""
    try:
        v = float(text)
    except ValueError:
        v = math.nan
    if not v > 0:
        raise argparse.ArgumentTypeError(
            f"--max-price {text!r}: a positive relative price (N-BK7 = 1), e.g. 2"
        )
    return v


def _search_spec(text: str) -> tuple[float, float]:
    """``nd=1.62,vd=60`` (either order) or a glass code ``620603`` → (nd, vd)."""
    from raytrace.glass import parse_glass_code

    t = text.strip()
    got: dict[str, float] = {}
    if "=" in t:
        for part in t.split(","):
            key, _, val = part.partition("=")
            key = key.strip().lower()
            if key not in ("nd", "vd") or key in got:
                raise argparse.ArgumentTypeError(
                    f"--search {text!r}: expected nd=VALUE,vd=VALUE (e.g. nd=1.62,vd=60)"
                )
            try:
                got[key] = float(val)
            except ValueError:
                raise argparse.ArgumentTypeError(
                    f"--search: {key} must be a number, got {val.strip()!r}"
                ) from None
        if set(got) != {"nd", "vd"}:
            raise argparse.ArgumentTypeError("--search needs both nd= and vd=")
        return got["nd"], got["vd"]
    m = parse_glass_code(t)
    if m is None:
        raise argparse.ArgumentTypeError(
            f"--search {text!r}: expected nd=1.62,vd=60, a code such as 620603, or 1.62/60"
        )
    return m.nd, m.vd


def cmd_glass(args) -> int:
    import numpy as np

    from raytrace.glass import search_glass

    from ..report.glass import (
        default_wavelengths,
        format_glass,
        format_search,
        glass_to_dict,
        search_to_dict,
    )

    if (args.name is None) == (args.search is None):
        raise CliError("give a glass NAME or --search nd=...,vd=... (one of them)")
    cats = None
    if args.catalog:
        from raytrace.glass.catalog import require_catalog

        cats = [require_catalog(c.strip()) for c in args.catalog.split(",")]
    if args.search is not None:
        if args.wavelengths is not None:
            raise CliError("--wavelengths goes with a glass NAME, not with --search")
        nd, vd = args.search
        if not (1.0 <= nd < 5.0 and 10.0 <= vd <= 120.0):
            swapped = (
                f" (swapped? nd={vd:g},vd={nd:g})"
                if 10.0 <= nd <= 120.0 and 1.0 <= vd < 5.0
                else ""
            )
            raise CliError(
                f"--search: nd {nd:g} / vd {vd:g} are not glass values (optical glasses have "
                f"nd 1.4-2.1 and Abbe numbers vd 17-95){swapped}"
            )
        count = DEFAULT_COUNT if args.count is None else args.count
        if count < 1:
            raise CliError("--count must be at least 1")
        limit = math.inf if args.max_price is None else args.max_price
        matches = search_glass(
            nd, vd, count, catalogs=cats, include_retired=args.include_retired,
            max_price=limit,
        )  # fmt: skip
        print_result(
            args,
            json=lambda: search_to_dict(nd, vd, matches),
            text=lambda: format_search(nd, vd, matches, limit),
        )
        return 0
    search_only = [
        flag
        for flag, given in (
            ("--max-price", args.max_price is not None),
            ("--count", args.count is not None),
            ("--include-retired", args.include_retired),
        )
        if given
    ]
    if search_only:
        verb = "goes" if len(search_only) == 1 else "go"
        raise CliError(f"{', '.join(search_only)} {verb} with --search, not with a glass NAME")
    g = _named_glass(args.name, cats, args.catalog)
    wls = args.wavelengths
    if wls is None or wls == "lens":
        if wls == "lens":
            raise CliError("--wavelengths lens applies to lens commands; give nm or line letters")
        wls = default_wavelengths(g)
    wl = np.asarray(wls, dtype=float)
    n = _indices(g, wl)
    print_result(args, json=lambda: glass_to_dict(g, wl, n), text=lambda: format_glass(g, wl, n))
    return 0


def _named_glass(name: str, cats: list[str] | None, catalog_flag: str | None):
    """The catalog glass NAME means (in the --catalog catalogs, the first that has it, when
    given), or a CliError that says what to type: --catalog for an ambiguous name or one of
    another catalog, --search for an nd/vd pair or glass code."""
    from raytrace.glass import find_glass, parse_glass_code, split_catalog_suffix
    from raytrace.glass.catalog import CATALOGS, RETIRED, canonical_catalog, similar_names

    raw, suffix = split_catalog_suffix(name)
    if suffix is not None:  # NSK16_SCHOTT: the catalog is in the name
        named = canonical_catalog(suffix)
        if cats and named not in cats:
            raise CliError(
                f"glass {name} names the {named} catalog but --catalog says {catalog_flag}: "
                "drop one of them"
            )
        cats = [named]
    cand = []
    for c in cats or ():
        cand = find_glass(raw, [c])
        if cand:
            break
    if not cats:
        cand = find_glass(raw)
    if not cand:
        elsewhere = find_glass(raw) if cats else []
        if elsewhere:
            where = list(dict.fromkeys(g.catalog for g in elsewhere))
            raise CliError(
                f"glass {raw} is not in the {', '.join(cats)} catalog"
                f"{'s' if len(cats) > 1 else ''}; it is in {', '.join(where)}: give --catalog "
                f"{where[0]}"
            )
        model = parse_glass_code(raw)
        if model is not None:
            raise CliError(
                f"{name!r} is an nd/vd pair (nd {model.nd:g}, vd {model.vd:g}), not a glass name: "
                "NAME looks up catalog glasses; for the catalog glasses nearest to it give "
                f"--search nd={model.nd:g},vd={model.vd:g}"
            )
        similar = similar_names(raw)
        hint = f"; similar names: {', '.join(similar)}" if similar else ""
        raise CliError(
            f"unknown glass {name!r}: it is in none of the catalogs "
            f"({', '.join(cats or CATALOGS)}){hint}; check the spelling, or find glasses by their "
            "numbers with --search nd=N,vd=V"
        )
    if len({(g.nd, g.vd) for g in cand}) > 1:
        listing = "; ".join(
            f"{g.catalog} {g.name} (nd {g.nd:g}, vd {g.vd:g}"
            + (f", {g.status}" if g.status in RETIRED else "")
            + ")"
            for g in cand
        )
        options = list(dict.fromkeys(g.catalog for g in cand))
        raise CliError(
            f"ambiguous glass {name!r}: {listing}. Choose one with --catalog {options[0]}"
            + (f" (or {', '.join(options[1:])})" if len(options) > 1 else "")
        )
    return cand[0]


def _indices(g, wl):
    """The index of glass ``g`` at the wavelengths ``wl`` (nm): the material's one warning names
    every wavelength outside its data range (with --strict, :func:`orthoscope.cli.main` makes
    it an error); beyond a pole of the formula it refuses (OutOfRangeError)."""
    import numpy as np

    return np.atleast_1d(g.material.index(wl))  # --strict: the warning is an error (main)


def register(sub: argparse._SubParsersAction) -> None:
    q = sub.add_parser(
        "glass",
        help="A catalog glass (formula, range, nd, vd, indices) or the nearest to nd/vd.",
        description=(
            "Look a glass up in the shipped catalogs (Schott, Ohara, Hoya, CDGM, Hikari, "
            "Sumita, Misc) and print its vendor dispersion formula, coefficients, valid range, "
            "nd, vd and its index at the requested wavelengths next to the indices the catalog "
            "prints; or list the catalog glasses nearest to an nd/vd pair (what a patent that "
            "gives only nd and vd leaves to choose)."
        ),
        epilog=(
            "Examples:\n"
            "  orthoscope glass N-BK7 --wavelengths 486.1327,587.5618,656.2725\n"
            "  orthoscope glass S-BSL7 --catalog Ohara --json\n"
            "  orthoscope glass --search nd=1.62,vd=60 --count 5"
        ),
    )
    q.add_argument("name", metavar="NAME", nargs="?", help="Glass name (N-BK7, NSK16_SCHOTT).")
    q.add_argument(
        "--search",
        type=_search_spec,
        metavar="nd=N,vd=V",
        help="List the catalog glasses nearest to this nd and vd (or a code such as 620603).",
    )
    q.add_argument(
        "--catalog",
        metavar="NAME[,NAME]",
        help="Catalog(s) to look in: Schott, Ohara, Hoya, CDGM, Hikari, Sumita, Misc.",
    )
    add_wavelengths_arg(
        q,
        help="Wavelengths for the index listing: nm, a number with a unit (0.5876um) or a line "
        "letter (F, d, C, e, g, ...). Default: the spectral lines inside the data range.",
    )
    add_strict_arg(
        q, help="Refuse wavelengths outside the glass's data range (default: a warning)."
    )
    q.add_argument(
        "--count", type=int, metavar="N", help=f"--search: how many (default {DEFAULT_COUNT})."
    )
    q.add_argument(
        "--max-price",
        type=_price,
        metavar="P",
        help="--search: only glasses whose vendor prints a relative price <= P (Schott: "
        "N-BK7 = 1; CDGM: H-K9L = 1; the other vendors print none).",
    )
    q.add_argument(
        "--include-retired",
        action="store_true",
        help="--search: also withdrawn / legacy glasses.",
    )
    add_output_args(q, csv=False, json_help="Print JSON.")
    q.set_defaults(func=cmd_glass)
