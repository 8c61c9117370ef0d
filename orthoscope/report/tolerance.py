"""Text and JSON of tolerancing results (:mod:`distortion.tolerance`): the ranked sensitivity
table and the Monte Carlo summary (envelopes, spreads raw and calibrated, yield against limits).

JSON keys carry their units (``_um``, ``_mm``, ``_deg``); the Monte Carlo block is the run's own
:meth:`MonteCarloResult.summary` (bit-identical for a seed whatever the chunking or workers) with
the yields added."""

from __future__ import annotations

import math

import numpy as np

from .jsonout import jsonable
from .text import printed

#: the scalar spreads listed, in order: (key, label, unit shown, factor from the output's unit)
SPREADS = (
    ("efl", "EFL (paraxial)", "mm", 1.0),
    ("k0", "F0 in the refocused plane", "mm", 1.0),
    ("focus_shift", "focus shift (compensator)", "mm", 1.0),
    ("P1_raw", "P1 raw", "1e-6/mm", 1e6),
    ("P2_raw", "P2 raw", "1e-6/mm", 1e6),
    ("c", "Fc (calibrated)", "mm", 1.0),
    ("x0", "principal point x0", "µm", 1e3),
    ("y0", "principal point y0", "µm", 1e3),
    ("P1", "P1 calibrated", "1e-6/mm", 1e6),
    ("P2", "P2 calibrated", "1e-6/mm", 1e6),
    ("g", "variation factor g", "", 1.0),
)
#: the sensitivity columns: (output, at the largest field?, label, factor from the output's unit)
SENS_COLUMNS = (
    ("D_cal_um", True, "ΔD_c@{f}° µm", 1.0),
    ("D_um", True, "ΔD@{f}° µm", 1.0),
    ("c", False, "ΔFc µm", 1e3),
    ("x0", False, "Δx0 µm", 1e3),
    ("y0", False, "Δy0 µm", 1e3),
    ("P1", False, "ΔP1 e-6/mm", 1e6),
    ("P2", False, "ΔP2 e-6/mm", 1e6),
)
#: the column of g_ss' (when the run computed it)
G_COLUMN = ("g", False, "Δg", 1.0)
#: the outputs of the sensitivity JSON besides the curves at the largest field (and g when the
#: run computed it)
SENS_SCALARS = ("efl", "k0", "focus_shift", "c", "x0", "y0", "P1", "P2", "P1_raw", "P2_raw")
MAX_TEXT_FIELDS = 11


def _cell(v, dec: int = 3, width: int = 10) -> str:
    if v is None or not math.isfinite(float(v)):
        return f"{'-':>{width}}"
    if round(float(v), dec) == 0.0:
        return f"{0.0:>{width}.{dec}f}"
    return f"{float(v):>+{width}.{dec}f}"


def _num(v, dec: int = 3) -> str:
    """A signed change with ``dec`` decimals ("0.000" for what rounds to zero, "-" for NaN)."""
    if v is None or not math.isfinite(float(v)):
        return "-"
    if round(float(v), dec) == 0.0:
        return f"{0.0:.{dec}f}"
    return f"{float(v):+.{dec}f}"


def _pair(row: dict | None, fac: float) -> str:
    """The change at the item's min and at its max, ``"at min/at max"`` (both signs shown: a
    change that is odd in the item has opposite signs, an even one the same)."""
    if row is None:
        return "-/-"
    a, b = _num(row["delta_min"] * fac), _num(row["delta_max"] * fac)
    return "0" if a == b == _num(0.0) else f"{a}/{b}"


def rank_key(sens) -> tuple[str, float]:
    """What the sensitivity is ranked by: the calibrated distortion ``D_cal_um`` at the largest
    curve field (output name, field in degrees)."""
    return "D_cal_um", float(np.max(sens.fields_deg))


def _rss(sens, output: str, field) -> float:
    return float(np.asarray(sens.rss(output, field)).reshape(-1)[0])


def sensitivity_to_dict(sens) -> dict:
    """JSON of a SensitivityResult: for the distortion at the largest field (calibrated and raw)
    and each scalar output, the items ranked by their largest change and the RSS of the 1-σ
    changes (the predicted Monte Carlo standard deviation). Strict-JSON-ready: NaN is null,
    infinities "inf" / "-inf"."""
    fmax = float(np.max(sens.fields_deg))
    keys = [("D_cal_um", fmax), ("D_um", fmax)] + [(k, None) for k in SENS_SCALARS]
    if _has_g(sens):
        keys.append(("g", None))
    outputs = {}
    for name, field in keys:
        label = name if field is None else f"{name}@{fmax:g}deg"
        outputs[label] = {
            "output": name,
            "field_deg": field,
            "rss_1sigma": float(_rss(sens, name, field)),
            "items": [
                {
                    "name": r["name"],
                    "unit": r["unit"],
                    "min": float(r["min"]),
                    "max": float(r["max"]),
                    "delta_at_min": float(r["delta_min"]),
                    "delta_at_max": float(r["delta_max"]),
                    "share_of_rss": float(r["share"]),
                }
                for r in sens.table(name, field)
            ],
        }
    out = {
        "lens": sens.lens_name,
        "compensator": sens.compensator,
        "fields_deg": np.asarray(sens.fields_deg).tolist(),
        "ranked_by": f"D_cal_um@{fmax:g}deg",
        "outputs": outputs,
    }
    if _has_g(sens):
        out["g_object_distance_mm"] = float(sens.g_object_distance)
        out["nominal_g"] = float(np.asarray(sens.nominal.g).reshape(-1)[0])
    return jsonable(out)


def _has_g(sens) -> bool:
    """Whether a SensitivityResult computed g_ss' (``g_object_distance`` set)."""
    return getattr(sens, "g_object_distance", None) is not None


def format_sensitivity(sens) -> str:
    """The ranked sensitivity table: each item alone at its limits (compensator applied), the
    change of the distortion at the largest field (calibrated and raw), of Fc, x0, y0, P1, P2
    — each cell the signed change with the item at its min, then at its max — and each item's
    share of the RSS of the calibrated distortion there."""
    key, fmax = rank_key(sens)
    rows = sens.table(key, fmax)
    cols = [
        (name, fmax if at_field else None, lab.format(f=f"{fmax:g}"), fac)
        for name, at_field, lab, fac in SENS_COLUMNS + ((G_COLUMN,) if _has_g(sens) else ())
    ]
    by_name = {name: {r["name"]: r for r in sens.table(name, field)} for name, field, _, _ in cols}
    cells = [[_pair(by_name[name].get(r["name"]), fac) for name, _, _, fac in cols] for r in rows]
    widths = [max([len(lab)] + [len(c[i]) for c in cells]) for i, (_, _, lab, _) in enumerate(cols)]
    nw = max([len("item")] + [len(r["name"]) for r in rows])
    gnote = ""
    if _has_g(sens):
        od = float(sens.g_object_distance)
        gnote = (
            f"; Δg: Fraser & Shortis's g_ss' for the object plane at "
            f"{'infinity' if not math.isfinite(od) else f'{od:g} mm'} (nominal "
            f"{float(np.asarray(sens.nominal.g).reshape(-1)[0]):.4f})"
        )
    lines = [
        f"Sensitivity of {sens.lens_name}: each tolerance alone at its min and max, compensator "
        f"{sens.compensator}; ranked by the calibrated distortion D_c at {fmax:g}°{gnote}",
        "each cell: the change with the item at its min / at its max",
        f"{'item':<{nw}} {'min':>9} {'max':>9}  "
        + "  ".join(f"{lab:>{w}}" for (_, _, lab, _), w in zip(cols, widths, strict=True))
        + f"  {'share':>7}",
    ]
    lines.append("-" * len(lines[-1]))
    for r, row_cells in zip(rows, cells, strict=True):
        share = r["share"]
        share_s = f"{100 * share:6.1f}%" if math.isfinite(share) else "      -"
        lines.append(
            f"{r['name']:<{nw}} {r['min']:>9.3g} {r['max']:>9.3g}  "
            + "  ".join(f"{c:>{w}}" for c, w in zip(row_cells, widths, strict=True))
            + f"  {share_s:>7}"
        )
    rss = [f"{lab.lstrip('Δ')} {_rss(sens, n, f) * fac:.3g}" for n, f, lab, fac in cols]
    lines.append(
        "RSS of the 1-σ changes (the Monte Carlo standard deviation expected for small "
        "tolerances): " + ", ".join(rss)
    )
    return "\n".join(lines)


def yields(mc, limits) -> list[dict]:
    """Yield against each (limit µm, field deg): share of the lenses with |D| below the limit,
    raw and after calibration, with the sentence the text prints."""
    out = []
    for lim, deg in limits:
        raw = float(mc.yield_fraction(lim, deg))
        cal = float(mc.yield_fraction(lim, deg, calibrated=True))
        out.append(
            {
                "limit_um": lim,
                "field_deg": deg,
                "fraction": raw,
                "fraction_calibrated": cal,
                "text": (
                    f"{100 * raw:.1f} % of lenses have |D| < {lim:g} µm at {deg:g}° "
                    f"({100 * cal:.1f} % after calibration)"
                ),
            }
        )
    return out


def monte_carlo_to_dict(mc, limits=()) -> dict:
    """JSON of a MonteCarloResult: its summary plus the yields."""
    d = dict(mc.summary())
    d["yield"] = yields(mc, limits)
    return d


def _text_fields(f: np.ndarray) -> np.ndarray:
    if f.size <= MAX_TEXT_FIELDS:
        return np.arange(f.size)
    return np.unique(np.round(np.linspace(0, f.size - 1, MAX_TEXT_FIELDS)).astype(int))


def format_monte_carlo(mc, limits=(), lens_name: str = "") -> str:
    """The Monte Carlo summary as text: the run, the envelope of D along +y (raw and
    calibrated), the spreads of the per-lens outputs and the yields."""
    lines = [
        f"Monte Carlo of {lens_name or 'the lens'}: {mc.n} lenses "
        f"({mc.n_ok} traced in full), seed {mc.seed}, compensator {mc.compensator}, "
        f"chunks of {mc.chunk_size}" + (f" ({mc.resumed_chunks} resumed)" if mc.resumed_chunks
                                         else "") + f", {mc.elapsed_s:.2f} s",
        f"generator: {mc.generator}",
        _summary_note(mc),
        "",
    ]  # fmt: skip
    f = np.asarray(mc.fields_deg, dtype=float)
    lev = np.asarray(mc.percentiles, dtype=float)
    want = [p for p in (2.5, 50.0, 97.5) if np.any(np.isclose(lev, p))]
    idx = [int(np.nonzero(np.isclose(lev, p))[0][0]) for p in want]
    env, envc = np.asarray(mc.envelope_um), np.asarray(mc.envelope_cal_um)
    nom = np.asarray(mc.nominal.D_um).reshape(-1)
    nomc = np.asarray(mc.nominal.D_cal_um).reshape(-1)
    head = "  ".join(f"{'p' + format(p, 'g'):>8}" for p in want)
    lines.append("distortion along +y (µm): nominal lens and percentiles over the lenses")
    fl = printed("α deg")  # 'alpha deg' under an ASCII-only locale: the column widens to it
    fw = max(7, len(fl))
    lines.append(f"{fl:>{fw}} {'nominal':>9}  {head}   |  {'cal nom':>9}  {head}".rstrip())
    for j in _text_fields(f):
        a = "  ".join(_cell(env[i, j], 2, 8) for i in idx)
        b = "  ".join(_cell(envc[i, j], 2, 8) for i in idx)
        lines.append(f"{f[j]:>{fw}.2f} {_cell(nom[j], 2, 9)}  {a}   |  {_cell(nomc[j], 2, 9)}  {b}")
    lines += ["", "per-lens outputs: nominal, mean, standard deviation, 2.5 and 97.5 percentiles"]
    lines.append(
        f"{'':28} {'unit':>8} {'nominal':>12} {'mean':>12} {'std':>11} {'p2.5':>12} {'p97.5':>12}"
    )
    for key, lab, unit, fac in SPREADS:
        st = mc.stats.get(key)
        if st is None:
            continue
        nv = getattr(mc.nominal, key, None)
        nv = float(np.asarray(nv).reshape(-1)[0]) * fac if nv is not None else float("nan")
        vals = [st.get(k, float("nan")) for k in ("mean", "std", "p2.5", "p97.5")]
        vals = [float("nan") if v is None else float(v) * fac for v in vals]
        lines.append(
            f"{lab:28} {unit:>8} {nv:>12.6g} {vals[0]:>12.6g} {vals[1]:>11.4g} {vals[2]:>12.6g} "
            f"{vals[3]:>12.6g}"
        )
    if "g" not in mc.stats:
        lines.append(
            "variation factor g: not computed by this run (--g-object-distance, or [outputs] "
            "g_object_distance in the spec)"
        )
    else:
        lines += _g_lines(mc)
    if limits:
        lines.append("")
        lines += [y["text"] for y in yields(mc, limits)]
    return "\n".join(lines)


def _g_lines(mc) -> list[str]:
    """g_ss': its object plane, how many lenses determine it, and percentiles over them."""
    od = float(mc.g_object_distance)
    where = "infinity" if not math.isfinite(od) else f"{od:g} mm from the first vertex"
    st = mc.stats["g"]
    n = int(st.get("n", 0))
    out = [
        "",
        f"variation factor g_ss' (Fraser & Shortis Eq. 6): lens focused at its object distance "
        f"by the compensator, object plane s' at {where}; determined for {n} of {mc.n_ok} lenses",
    ]
    if n:
        lev = (0.5, 2.5, 16.0, 50.0, 84.0, 97.5, 99.5)
        q = mc.percentile_values("g", lev)
        out.append("  " + "  ".join(f"p{p:g} {v:.4f}" for p, v in zip(lev, q, strict=True)))
        counts, edges = mc.histogram("g", 12)
        out.append(
            f"  histogram {edges[0]:.4f}..{edges[-1]:.4f} in {counts.size} bins: "
            + " ".join(str(int(c)) for c in counts)
        )
    return out


def _summary_note(mc) -> str:
    """How the statistics were taken (exact, or streamed with histogram percentiles)."""
    if getattr(mc, "summary_method", "exact") != "streaming":
        return "statistics: exact, over all lenses gathered in memory"
    ss = mc.streamed
    return (
        f"statistics: streamed chunk by chunk (blocks of {ss.block} lenses merged in order; "
        f"percentiles from {ss.bins}-bin histograms, within one bin width)"
    )


__all__ = [
    "format_monte_carlo",
    "format_sensitivity",
    "monte_carlo_to_dict",
    "rank_key",
    "sensitivity_to_dict",
    "yields",
]
