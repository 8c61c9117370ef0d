"""Text and JSON of glass look-ups (``orthoscope glass``): one catalog glass with its formula,
range and indices, or the catalog glasses nearest to an nd/vd pair."""

from __future__ import annotations

import math

import numpy as np

from raytrace.glass import CatalogGlass, GlassMatch
from raytrace.glass.formulas import formula as formula_of
from raytrace.units import SPECTRAL_LINES


def line_name(nm: float) -> str:
    """The spectral-line letter of a wavelength (nm), or ``""``."""
    for k, v in SPECTRAL_LINES.items():
        if abs(v - nm) < 1e-6:
            return k
    return ""


def default_wavelengths(g: CatalogGlass) -> tuple[float, ...]:
    """The spectral lines inside the glass's data range, short to long (nm)."""
    lo, hi = g.wavelength_range_nm
    return tuple(sorted(v for v in SPECTRAL_LINES.values() if lo <= v <= hi))


def _fmt(v: float, digits: int = 6) -> str:
    return "-" if v is None or not math.isfinite(v) else f"{v:.{digits}f}"


def format_glass(g: CatalogGlass, wavelengths, indices) -> str:
    """The glass as text: catalog data, formula, range and n at ``wavelengths`` (nm)."""
    f = formula_of(g.formula)
    lo, hi = g.wavelength_range_nm
    out = [
        f"{g.name} ({g.catalog})" + (f" — {g.status}" if g.status else ""),
        f"  nd {_fmt(g.nd)}   vd {_fmt(g.vd, 3)}"
        + (f"   ne {_fmt(g.ne)}   ve {_fmt(g.ve, 3)}" if math.isfinite(g.ne) else ""),
        f"  formula {g.formula} ({f.name}): {f.equation}   [λ in µm]",
        "  coefficients " + ", ".join(f"{c:.10g}" for c in g.formula_coefficients),
        f"  valid {lo:g}–{hi:g} nm; index {g.basis} "
        + ("to air" if g.basis == "relative" else "(vacuum)")
        + f" at {g.temperature_c:g} °C, {g.pressure_atm:g} atm",
    ]
    if g.dndt:
        out.append(
            "  dn/dT (Schott) D0, D1, D2, E0, E1, λTK: " + ", ".join(f"{c:.4g}" for c in g.dndt)
        )
    if math.isfinite(g.price):
        ref = "N-BK7" if g.catalog == "Schott" else "H-K9L"
        out.append(f"  relative price {g.price:.3g} ({g.catalog}'s catalog, {ref} = 1)")
    for alias, p in g.alias_prices:
        out.append(
            f"  {alias}: the same optical data, relative price "
            + (f"{p:.3g}" if math.isfinite(p) else "not printed")
        )
    if g.source:
        out.append(f"  source: {g.source}" + (f" — {g.note}" if g.note else ""))
    printed = {round(w, 4): (lab, n, d) for lab, w, n, d in g.printed_indices}
    out.append("")
    out.append(f"  {'λ (nm)':>10}  {'line':>4}  {'n':>10}  {'catalog prints':>14}")
    for w, n in zip(wavelengths, indices, strict=True):
        p = printed.get(round(float(w), 4))
        pr = f"{p[1]:.{p[2]}f}" if p else ""
        flag = "" if lo <= w <= hi else "  (outside the data range: extrapolated)"
        out.append(f"  {w:>10.4f}  {line_name(w):>4}  {n:>10.6f}  {pr:>14}{flag}")
    return "\n".join(out)


def glass_to_dict(g: CatalogGlass, wavelengths, indices) -> dict:
    f = formula_of(g.formula)
    return {
        "name": g.name,
        "catalog": g.catalog,
        "status": g.status,
        "nd": g.nd,
        "vd": g.vd,
        "ne": g.ne,
        "ve": g.ve,
        "formula": g.formula,
        "formula_name": f.name,
        "equation": f.equation,
        "coefficients": list(g.formula_coefficients),
        "wavelength_range_nm": list(g.wavelength_range_nm),
        "basis": g.basis,
        "temperature_c": g.temperature_c,
        "pressure_atm": g.pressure_atm,
        "dndt": list(g.dndt),
        "source": g.source,
        "note": g.note,
        "relative_price": g.price,  # NaN (none printed) -> null by report.jsonout
        "alias_prices": dict(g.alias_prices),
        "printed_indices": [
            {"line": lab, "wavelength_nm": w, "n": n, "decimals": d}
            for lab, w, n, d in g.printed_indices
        ],
        "indices": [
            {
                "wavelength_nm": float(w),
                "line": line_name(float(w)),
                "n": float(n),
                "extrapolated": not g.material.in_range(float(w)),
            }
            for w, n in zip(wavelengths, np.atleast_1d(indices), strict=True)
        ],
    }


def format_search(
    nd: float, vd: float, matches: list[GlassMatch], max_price: float = math.inf
) -> str:
    """The nearest catalog glasses to (nd, vd), nearest first (``max_price``: the search's
    price limit, named in the heading)."""
    limit = f" with a relative price <= {max_price:g}" if math.isfinite(max_price) else ""
    out = [
        f"catalog glasses{limit} nearest to nd {nd:g}, vd {vd:g} (distance in glass-code "
        "units: 0.001 in nd or 0.1 in vd)",
        f"  {'#':>2}  {'glass':<16} {'catalog':<8} {'nd':>9} {'vd':>7} {'code':>7} "
        f"{'distance':>8} {'price':>6}  status",
    ]
    for i, m in enumerate(matches, start=1):
        g = m.glass
        code = f"{round(1000 * (g.nd - 1)):03d}{round(10 * g.vd):03d}"
        price = f"{g.price:>6.3g}" if g.price == g.price else f"{'':>6}"
        out.append(
            f"  {i:>2}  {g.name:<16} {g.catalog:<8} {g.nd:>9.5f} {g.vd:>7.2f} {code:>7} "
            f"{m.distance:>8.2f} {price}  {g.status}"
        )
    if any(m.glass.price == m.glass.price for m in matches):
        out.append(
            "  price: the vendor's relative price (Schott N-BK7 = 1, CDGM H-K9L = 1; not "
            "comparable across vendors; the others print none)"
        )
    if not matches:
        out.append("  (none)")
    return "\n".join(out)


def search_to_dict(nd: float, vd: float, matches: list[GlassMatch]) -> dict:
    return {
        "nd": nd,
        "vd": vd,
        "metric": "sqrt((1000 dnd)^2 + (10 dvd)^2)",
        "matches": [
            {
                "name": m.glass.name,
                "catalog": m.glass.catalog,
                "nd": m.glass.nd,
                "vd": m.glass.vd,
                "distance": m.distance,
                "relative_price": m.glass.price,
                "status": m.glass.status,
            }
            for m in matches
        ],
    }
