"""Plain-text tables: one number formatter and one table layout for every command."""

from __future__ import annotations

import math
import sys

import numpy as np

from raytrace.trace.results import status_name


def fmt(v: float | None, width: int = 12, prec: int = 4) -> str:
    """A right-aligned number: ``-`` for None/NaN, ``inf``/``-inf`` for infinities."""
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return f"{'-':>{width}}"
    if isinstance(v, float) and math.isinf(v):
        return f"{('inf' if v > 0 else '-inf'):>{width}}"
    return f"{v:>{width}.{prec}f}"


def untraced(fields: np.ndarray, status: np.ndarray) -> list[str]:
    """``["fields not traced: 30: TIR, 45: missed"]`` for the fields whose status is not 0, or
    ``[]`` when every field traced (status words: :func:`raytrace.trace.results.status_name`)."""
    bad = [f"{v:g}: {status_name(c)}" for v, c in zip(fields, status, strict=True) if c != 0]
    return ["fields not traced: " + ", ".join(bad)] if bad else []


def printed(text: str, stream=None) -> str:
    """``text`` as ``stream`` (default: ``sys.stdout``) will write it, so that a table can be laid
    out in the characters that reach the reader.

    Unchanged where the stream's encoding holds every character; otherwise passed through the
    stream's error handler: under a locale that cannot encode the tables' symbols the command line
    writes them in ASCII (``α`` -> ``alpha``, ``°`` -> `` deg``; ``orthoscope.cli``), and a label
    measured before that substitution would no longer match its column. A stream whose handler
    refuses the text (``errors="strict"``) gets it unchanged, as before.

    >>> import io
    >>> printed("α (deg)", io.TextIOWrapper(io.BytesIO(), encoding="utf-8"))
    'α (deg)'
    >>> printed("α (deg)", io.TextIOWrapper(io.BytesIO(), encoding="ascii", errors="replace"))
    '? (deg)'
    """
    stream = sys.stdout if stream is None else stream
    enc = getattr(stream, "encoding", None) or "utf-8"
    try:
        text.encode(enc)
        return text
    except (UnicodeEncodeError, LookupError):
        pass
    try:
        return text.encode(enc, getattr(stream, "errors", None) or "strict").decode(enc)
    except (UnicodeError, LookupError):
        return text


def _cell(v: float, dec: int, signed: bool) -> str:
    if not math.isfinite(v):
        return "-"
    s = f"{v:+.{dec}f}" if signed else f"{v:.{dec}f}"
    if signed and float(s) == 0.0:
        s = f"{0.0:.{dec}f}"
    return s


def format_columns(
    title: list[str],
    field_label: str,
    fields: np.ndarray,
    quantities: list[tuple[str, np.ndarray, int, bool]],
    *,
    layout: str = "rows",
) -> str:
    """A table with one line per field (``layout="rows"``, the default of every command) or one
    column per field and one line per quantity (``layout="paper"``: Pestrecov's Tables I, II, V).

    ``quantities`` items are ``(label, values, decimals, signed)``. The labels are laid out as
    they will be printed (:func:`printed`: in ASCII under an ASCII-only locale, ``alpha (deg)``
    for ``α (deg)``), so that the rule and the columns are as wide as the header the reader sees.
    """
    if layout == "auto":  # the old spelling: rows are the one default orientation now
        layout = "rows"
    if layout not in ("paper", "rows"):
        raise ValueError(f"unknown table layout {layout!r}; expected rows or paper")
    fcells = [f"{v + 0.0:g}" for v in fields]  # + 0.0: no "-0" for a table's -0.0000 axis row
    qcells = [[_cell(float(v), dec, sg) for v in vals] for _, vals, dec, sg in quantities]
    labels = [printed(lab) for lab in [field_label] + [q[0] for q in quantities]]
    lw = max(len(s) for s in labels)
    out = list(title)
    if layout == "paper":
        cw = max([len(c) for c in fcells] + [len(c) for row in qcells for c in row]) + 2
        out.append(labels[0].ljust(lw) + "".join(c.rjust(cw) for c in fcells))
        out.append("-" * (lw + cw * len(fcells)))
        for lab, row in zip(labels[1:], qcells, strict=True):
            out.append(lab.ljust(lw) + "".join(c.rjust(cw) for c in row))
    else:
        widths = [max(len(labels[0]), *(len(c) for c in fcells))] + [
            max(len(labels[j + 1]), *(len(c) for c in qcells[j])) for j in range(len(qcells))
        ]
        out.append("  ".join(lab.rjust(w) for lab, w in zip(labels, widths, strict=True)))
        out.append("  ".join("-" * w for w in widths))
        for i, fc in enumerate(fcells):
            cells = [fc] + [qcells[j][i] for j in range(len(qcells))]
            out.append("  ".join(c.rjust(w) for c, w in zip(cells, widths, strict=True)))
    return "\n".join(out)


def csv_text(header: list[str], rows: list[list]) -> str:
    """CSV text: floats at full precision (``repr``), None/NaN as empty cells."""
    import csv
    import io

    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(header)
    for r in rows:
        w.writerow(
            [
                ""
                if v is None or (isinstance(v, float) and math.isnan(v))
                else (repr(float(v)) if isinstance(v, (float, np.floating)) else v)
                for v in r
            ]
        )
    return buf.getvalue().rstrip("\n")
