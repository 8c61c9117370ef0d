"""Build ``raytrace/glass/data/catalogs.zip`` from the vendor catalogs and refractiveindex.info.

Development-time only: it reads spreadsheets with pandas (xlrd for ``.xls``, openpyxl for
``.xlsx``) and YAML with PyYAML; the runtime reads the result with the standard library.

Sources
-------
* Vendor catalog spreadsheets as the ``opticalglass`` package ships them
  (``site-packages/opticalglass/data``): SCHOTT.xls, OHARA.xlsx, HOYA.xlsx, CDGM.xls,
  HIKARI.xlsx, SUMITA.xlsx, and the previous editions SCHOTT_prev.xls, OHARA_prev.xlsx,
  HOYA_prev.xlsx, HIKARI_prev.xls (a glass found only in a previous edition is kept with status
  ``"withdrawn"``).
* The refractiveindex.info database as the ``optiland`` wheel ships it
  (``site-packages/optiland/database/data-nk``): vendor shelves ``glass/<vendor>`` for legacy
  glasses no spreadsheet lists (the shelves were converted by refractiveindex.info from the
  vendors' Zemax AGF files), and a hand-picked list of non-catalog materials (``MISC`` below).
  The database is public domain (CC0 1.0; ``optiland/database/doc/permission.txt``).
* Schott's 1980 catalog as Robb & Mercado fitted it (P. N. Robb and R. I. Mercado,
  "Calculation of refractive indices using Buchdahl's chromatic coordinate", Appl. Opt. 22,
  1198-1215 (1983), Table V), as the ``opticalglass`` package transcribes it
  (``robb1983_data_final.txt``): old Schott glasses that no later catalog, no shelf and no
  ``N-`` successor covers, each only where the same name's row of another 1980 catalog of the
  table (Ohara, Hoya, Corning-France, Chance: the equivalent glass) confirms the transcription
  (:func:`robb_schott_1980`).
* Definitions of the Zemax ``MISC`` catalog that are no measured data (``DEFINITIONS``).

Every spreadsheet column is located by its header label and checked, so a changed file fails
loudly instead of shifting columns. Output: one zip archive of JSON members (``index.json``
with names, nd, vd and status of every material; one JSON-lines member per catalog,
``CATALOG.jsonl``, with the full records (formula, printed indices, dn/dT, transmission and,
where the vendor prints one, the relative price: Schott's "rel. Price", CDGM's price per
volume), one material a line in index order, so that a reader
parses only the glasses it needs; ``meta.json`` with file, package, version, sha256 and catalog
date of every source). The archive is deterministic: same inputs and ``--date`` give
byte-identical output.

Usage::

    python tools/make_glass_catalog.py [--date YYYY-MM-DD] [--out PATH]
"""

from __future__ import annotations

import argparse
import datetime as dt
import hashlib
import importlib.metadata
import importlib.util
import json
import math
import re
import sys
import warnings
import zipfile
from dataclasses import dataclass
from pathlib import Path

import pandas as pd
import yaml

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "raytrace" / "glass" / "data" / "catalogs.zip"
FORMAT = 2  # 1: one JSON array per catalog (CATALOG.json); 2: JSON lines (CATALOG.jsonl)

# Spectral lines (nm, in air) by the labels the vendors print. Schott TIE-29 / the
# Hikari and Hoya sheets give the same values; A' and He-Cd from the Ohara / Hikari sheets.
LINES_NM = {
    "t": 1013.98,
    "s": 852.11,
    "A'": 768.195,
    "r": 706.5188,
    "C": 656.2725,
    "C'": 643.8469,
    "HE-NE": 632.8,
    "D": 589.2938,
    "d": 587.5618,
    "e": 546.074,
    "F": 486.1327,
    "F'": 479.9914,
    "HE-CD": 441.5630,
    "g": 435.8343,
    "h": 404.6561,
    "i": 365.0146,
}


# Lines the vendors label by rounded wavelength (nm) → the line's wavelength (nm, in air).
# Mercury lines 2325.42, 1970.09, 1529.582, 1128.64, 334.1478, 312.5663, 296.7278 nm as Schott
# TIE-29 (table 1) lists them; helium 388.8648 nm; He-Ne 632.8 nm as Schott prints it.
PRECISE_NM = (2325.42, 1970.09, 1529.582, 1128.64, 334.1478, 312.5663, 296.7278, 388.8648)


def _precise(lam_nm: float) -> float:
    """The spectral line a rounded label such as 'n1530' or 'n334.1' stands for."""
    for p in PRECISE_NM:
        if abs(p - lam_nm) < 0.5:
            return p
    for p in LINES_NM.values():
        if abs(p - lam_nm) < 0.05:
            return p
    return lam_nm


def _pkg_dir(name: str) -> Path:
    spec = importlib.util.find_spec(name)
    if spec is None or not spec.submodule_search_locations:
        sys.exit(f"make_glass_catalog: the package {name!r} is needed at generation time")
    return Path(next(iter(spec.submodule_search_locations)))


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _num(x) -> float | None:
    """A finite float from a spreadsheet cell, or None (blank, '-', text)."""
    if x is None:
        return None
    if isinstance(x, str):
        x = x.strip()
        if not re.fullmatch(r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?", x):
            return None
    try:
        v = float(x)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def _decimals(values: list[float]) -> int:
    """Digits after the point of the column's print format: the most common count of decimals
    (a value ending in 0 shows fewer, a stray over-long entry more)."""
    counts: dict[int, int] = {}
    for v in values:
        s = repr(float(v))
        if "e" in s or "E" in s:
            continue
        frac = s.split(".")[1].rstrip("0") if "." in s else ""
        counts[len(frac)] = counts.get(len(frac), 0) + 1
    return max(counts, key=lambda k: (counts[k], k)) if counts else 0


def _clean(s) -> str:
    return re.sub(r"\s+", " ", str(s)).strip()


def _col(letter: str) -> int:
    n = 0
    for ch in letter:
        n = n * 26 + (ord(ch) - 64)
    return n - 1


class Sheet:
    """A worksheet read with header=None; row/column indices are 0-based."""

    def __init__(self, path: Path, sheet=0):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            self.df = pd.read_excel(path, sheet_name=sheet, header=None)
        self.path = path

    def cell(self, r: int, c: int):
        return self.df.iat[r, c]

    def find(self, row: int, pattern: str, start: int = 0, stop: int | None = None) -> int:
        """Column of the first header cell in ``row`` matching the regex ``pattern``."""
        stop = self.df.shape[1] if stop is None else stop
        rx = re.compile(pattern)
        for c in range(start, stop):
            v = self.df.iat[row, c]
            if isinstance(v, str) and rx.fullmatch(_clean(v)):
                return c
        raise SystemExit(f"{self.path.name}: no header {pattern!r} in row {row + 1}")

    def find_run(self, row: int, patterns: tuple[str, ...], start: int = 0) -> int:
        """Column of the first of the consecutive header cells in ``row`` that match
        ``patterns`` in turn (found from column ``start``)."""
        c = self.find(row, patterns[0], start)
        for k, pattern in enumerate(patterns[1:], start=1):
            self.expect(row, c + k, pattern)
        return c

    def expect(self, row: int, col: int, pattern: str) -> None:
        v = _clean(self.df.iat[row, col])
        if not re.fullmatch(pattern, v):
            raise SystemExit(
                f"{self.path.name}: cell row {row + 1} col {col + 1} is {v!r}, expected {pattern!r}"
            )


def _line_label(text: str) -> tuple[str, float] | None:
    """(label, λ nm) from an index-column header such as 'nd', "nC'", 'n1529.6', 'nHe-Ne'."""
    t = _clean(text).replace("ｔ", "t")
    t = t.split(" ")[0] if " " in t else t
    m = re.fullmatch(r"n?\s*(\d{3,4}(?:\.\d+)?)", t)
    if m:
        return f"n{m.group(1)}", _precise(float(m.group(1)))
    m = re.fullmatch(r"n?\s*(He-Ne|He-Cd|[tsrCDdeFghi]'?|A')", t, flags=re.IGNORECASE)
    if m:
        key = m.group(1)
        up = key.upper()
        if up in ("HE-NE", "HE-CD"):
            return f"n{key}", LINES_NM[up]
        if key not in LINES_NM:  # CDGM writes nc / nc'
            key = key[0].upper() + key[1:] if key[0] in "cf" else key
        return f"n{key}", LINES_NM[key]
    return None


def _record(
    name: str,
    formula,
    coefficients: list[float],
    indices: list[tuple[str, float, float, int]],
    *,
    nd: float | None,
    vd: float | None,
    ne: float | None = None,
    ve: float | None = None,
    dndt: list[float] | None = None,
    transmission: tuple[float, list[tuple[float, float]]] | None = None,
    status: str = "",
    source: str,
    range_um: tuple[float, float] | None = None,
    basis: str = "relative",
    temperature_c: float = 20.0,
    pressure_atm: float = 1.0,
    aliases: list[str] | None = None,
    note: str = "",
) -> dict:
    if range_um is None:
        lams = [lam for _, lam, _, _ in indices]
        range_um = (min(lams) / 1000.0, max(lams) / 1000.0)
    rec = {
        "name": name,
        "formula": formula,
        "coefficients": [float(c) for c in coefficients],
        "range_um": [round(range_um[0], 7), round(range_um[1], 7)],
        "nd": nd,
        "vd": vd,
        "basis": basis,
        "temperature_c": temperature_c,
        "pressure_atm": pressure_atm,
        "status": status,
        "source": source,
    }
    if ne is not None:
        rec["ne"] = ne
    if ve is not None:
        rec["ve"] = ve
    if dndt and any(v != 0.0 for v in dndt):
        rec["dndt"] = [float(v) for v in dndt]
    if indices:
        rec["indices"] = [[lab, lam, val, dec] for lab, lam, val, dec in indices]
    if transmission:
        thick, pts = transmission
        if pts:
            rec["transmission"] = {"thickness_mm": thick, "data": [[a, b] for a, b in pts]}
    if aliases:
        rec["aliases"] = aliases
    if note:
        rec["note"] = note
    return rec


# --------------------------------------------------------------------------- vendor sheets


def _index_columns(sh: Sheet, label_row: int, c0: int, c1: int, lam_row: int | None = None):
    """[(col, label, λ nm)] for the refractive-index block between columns c0..c1."""
    out = []
    for c in range(c0, c1 + 1):
        head = sh.cell(label_row, c)
        lab = _line_label(str(head)) if isinstance(head, str) else None
        if lab is None and lam_row is not None:
            lam = _num(sh.cell(lam_row, c))
            if lam is not None:
                lam_nm = lam * 1000.0 if lam < 10 else lam
                lab = (f"n{lam_nm:g}", _precise(lam_nm))
        if lab is None:
            raise SystemExit(f"{sh.path.name}: cannot read index header {head!r} (col {c + 1})")
        out.append((c, *lab))
    return out


def _printed(sh: Sheet, rows: list[int], cols) -> dict[int, int]:
    """Printed decimals per index column."""
    dec = {}
    for c, _, _ in cols:
        vals = [v for v in (_num(sh.cell(r, c)) for r in rows) if v is not None]
        dec[c] = _decimals(vals)
    return dec


def _indices(sh: Sheet, r: int, cols, dec) -> list[tuple[str, float, float, int]]:
    out = []
    for c, lab, lam in cols:
        v = _num(sh.cell(r, c))
        if v is not None and v > 1.0:
            out.append((lab, lam, v, dec[c]))
    return out


def _rows(sh: Sheet, first: int, name_col: int) -> list[int]:
    rows = []
    for r in range(first, sh.df.shape[0]):
        v = sh.cell(r, name_col)
        if not isinstance(v, str) or not v.strip() or v.strip().lower().startswith("over"):
            continue
        rows.append(r)
    return rows


def _transmission(sh: Sheet, r: int, cols: list[tuple[int, float]]) -> list[tuple[float, float]]:
    pts = []
    for c, lam in cols:
        v = _num(sh.cell(r, c))
        if v is not None:
            pts.append((lam, v))
    return sorted(pts)


def _header_run(sh: Sheet, row: int, start: int, value) -> list[tuple[int, float]]:
    """[(col, value(header))] over the consecutive header cells of ``row`` from column ``start``
    that ``value`` reads (a cell it gives None for ends the run): a transmission block and its
    wavelengths (nm)."""
    out = []
    for c in range(start, sh.df.shape[1]):
        v = value(sh.cell(row, c))
        if v is None:
            break
        out.append((c, v))
    return out


def _labelled(pattern: str):
    """A header reader for :func:`_header_run`: the number in group 1 of ``pattern`` (e.g.
    ``TAUI10/(.+)``, ``(\\d+)nm``), None for a header that does not match."""

    def value(head) -> float | None:
        m = re.fullmatch(pattern, _clean(head))
        return float(m.group(1)) if m else None

    return value


def _all_numbers(sh: Sheet, r: int, cols) -> list[float] | None:
    """The numbers of row ``r`` in ``cols``, or None when any of them is blank."""
    vals = [_num(sh.cell(r, c)) for c in cols]
    return None if any(v is None for v in vals) else vals


@dataclass(frozen=True, eq=False)
class Columns:
    """Where a vendor sheet keeps the fields of a glass row (0-based columns)."""

    name: int
    vd: int
    ve: int
    index: list[tuple[int, str, float]]  # (col, label, λ nm) of the refractive-index block
    decimals: dict[int, int]  # printed decimals per index column
    transmission: list[tuple[int, float]]  # (col, λ nm) of the internal transmittance
    dndt: list[int] | None = None  # D0 D1 D2 E0 E1 λTK; None: the sheet gives none
    nd: int | None = None  # None: nd and ne are read among the index columns
    ne: int | None = None


def _row_record(
    sh: Sheet,
    r: int,
    at: Columns,
    formula: int,
    coefs: list[float],
    *,
    source: str,
    thickness: float = 10.0,
    status: str = "",
) -> dict:
    """The record of the glass in row ``r`` of ``sh``: name, indices, Abbe numbers, dn/dT and
    transmission (``thickness`` mm) from the columns ``at``; the dispersion formula from the
    caller."""
    ind = _indices(sh, r, at.index, at.decimals)
    if at.nd is None:
        nd = next(v for lab, _, v, _ in ind if lab == "nd")
        ne = next((v for lab, _, v, _ in ind if lab == "ne"), None)
    else:
        nd, ne = _num(sh.cell(r, at.nd)), _num(sh.cell(r, at.ne))
    return _record(
        _clean(sh.cell(r, at.name)),
        formula,
        coefs,
        ind,
        nd=nd,
        vd=_num(sh.cell(r, at.vd)),
        ne=ne,
        ve=_num(sh.cell(r, at.ve)),
        dndt=None if at.dndt is None else _all_numbers(sh, r, at.dndt),
        transmission=(thickness, _transmission(sh, r, at.transmission)),
        status=status,
        source=source,
    )


def _sellmeier_records(sh: Sheet, rows: list[int], at: Columns, c0: int, source: str) -> list[dict]:
    """The records of a Sellmeier sheet: the rows whose constants B1 B2 B3 C1 C2 C3 (columns
    ``c0`` on) are all given, as AGF formula 2 (Sellmeier 1: K1 L1 K2 L2 K3 L3)."""
    out = []
    for r in rows:
        b = _all_numbers(sh, r, range(c0, c0 + 6))
        if b is not None:
            coefs = [b[0], b[3], b[1], b[4], b[2], b[5]]
            out.append(_row_record(sh, r, at, 2, coefs, source=source))
    return out


def _with_prices(
    records: list[dict], sh: Sheet, rows: list[int], price_col: int, reference: str
) -> list[dict]:
    """``rec["price"]``: the catalog's relative price divided by its ``reference`` glass's, where
    the sheet gives one (Schott's "rel. Price" column, N-BK7 = 1 in the sheet; CDGM's price
    per volume, H-K9L = 10 in the sheet). The reference's row must carry a price."""
    by_name = {}
    for r in rows:
        v = _num(sh.cell(r, price_col))
        if v is not None and v > 0:
            by_name[_clean(sh.cell(r, 0))] = v
    if reference not in by_name:
        raise SystemExit(
            f"{sh.path.name}: no relative price of {reference} in column {price_col + 1}"
        )
    ref = by_name[reference]
    for rec in records:
        if rec["name"] in by_name:
            rec["price"] = by_name[rec["name"]] / ref
    return records


def read_schott(path: Path, source: str) -> list[dict]:
    sh = Sheet(path, "Datatable")
    H = 3
    sh.expect(H, 0, "Glass")
    nd_c, ne_c, vd_c, ve_c = (sh.find(H, x) for x in ("nd", "ne", "vd", "ve"))
    b1 = sh.find_run(H, ("B1", "B2", "B3", "C1", "C2", "C3"))
    d0 = sh.find_run(H, ("D0", "D1", "D2", "E0", "E1", "lambda"))
    cols = _index_columns(sh, H, sh.find(H, r"n2325\.4"), sh.find(H, r"n248\.3"))
    tcols = _header_run(sh, H, sh.find(H, r"TAUI10/2500"), _labelled(r"TAUI10/(.+)"))
    rows = _rows(sh, H + 1, 0)
    at = Columns(
        name=0,
        nd=nd_c,
        ne=ne_c,
        vd=vd_c,
        ve=ve_c,
        index=cols,
        decimals=_printed(sh, rows, cols),
        transmission=tcols,
        dndt=list(range(d0, d0 + 6)),
    )
    records = _sellmeier_records(sh, rows, at, b1, source)
    if not path.stem.endswith("_prev"):  # the current catalog prints "rel. Price" (N-BK7 = 1)
        records = _with_prices(records, sh, rows, sh.find(H, r"rel\. Price"), "N-BK7")
    return records


def _ohara_sheet(sh: Sheet, source: str) -> list[dict]:
    H = 1
    sh.expect(H, 1, "Glass")
    cols = _index_columns(sh, H, sh.find(H, "n2325"), sh.find(H, "ni"))
    # two Abbe columns each: the first rounded to 0.1, the second to 0.01 (use the latter)
    vds = [c for c in range(sh.df.shape[1]) if _clean(sh.cell(H, c)) == "νd"]
    ves = [c for c in range(sh.df.shape[1]) if _clean(sh.cell(H, c)) == "νe"]
    sellmeier = sh.find(0, r"CONSTANTS OF DISPERSION FORMULA \(Sellmeier\)")
    a1 = sh.find_run(H, ("A1", "A2", "A3", "B1", "B2", "B3"), start=sellmeier)
    d0 = sh.find_run(H, ("D0", "D1", "D2", "E0", "E1", "λTK"))
    t0 = sh.find(0, r"INTERNAL TRANSMISSION \(τ／10mm Thick\)")
    rows = _rows(sh, H + 1, 1)
    at = Columns(
        name=1,
        vd=vds[-1],
        ve=ves[-1],
        index=cols,
        decimals=_printed(sh, rows, cols),
        transmission=_header_run(sh, H, t0, _num),
        dndt=list(range(d0, d0 + 6)),
    )
    return _sellmeier_records(sh, rows, at, a1, source)


def read_ohara(path: Path, source: str) -> list[dict]:
    xl = pd.ExcelFile(path)
    out = []
    for name in xl.sheet_names:
        out += _ohara_sheet(Sheet(path, name), source)
    return out


def read_hoya(path: Path, source: str) -> list[dict]:
    sh = Sheet(path, 0)
    sh.expect(0, 2, "Glass Type")
    nd_c, vd_c = _col("E"), _col("F")
    sh.expect(1, nd_c, "nd")
    sh.expect(1, vd_c, "νd")
    i0 = sh.find(1, r"n1529\.6")
    cols = _index_columns(sh, 1, i0, sh.find(1, "ni", start=i0), lam_row=3)
    a0 = sh.find_run(1, ("A0", "A0pow", "A1", "A1pow", "A2", "A2pow", "A3", "A3pow"))
    d0 = sh.find_run(2, ("D0", "D1", "D2", "E0", "E１", "λTk"))
    t0 = sh.find(1, r"Internal Transmittance \(10mmt\)")
    rows = [r for r in _rows(sh, 4, 2) if _num(sh.cell(r, nd_c)) is not None]
    at = Columns(
        name=2,
        nd=nd_c,
        ne=sh.find(1, "ne"),
        vd=vd_c,
        ve=sh.find(1, "νe"),
        index=cols,
        decimals=_printed(sh, rows, cols),
        transmission=_header_run(sh, 3, t0, _num),
        dndt=list(range(d0, d0 + 6)),
    )
    out = []
    for r in rows:
        pairs = [(_num(sh.cell(r, a0 + 2 * k)), _num(sh.cell(r, a0 + 2 * k + 1))) for k in range(6)]
        if any(m is None or p is None for m, p in pairs):
            continue
        # mantissa × 10**pow, printed so; float(f"{m}e{p}") keeps the decimal value exact
        coefs = [float(f"{m!r}e{int(p)}") for m, p in pairs]
        cls = sh.cell(r, 0)
        status = f"HOYA classification {_clean(cls)}" if isinstance(cls, str) else ""
        out.append(_row_record(sh, r, at, 1, coefs, status=status, source=source))
    return out


def read_cdgm(path: Path, source: str) -> list[dict]:
    sh = Sheet(path, 0)
    sh.expect(0, 0, "Glass")
    cols = _index_columns(sh, 0, sh.find(0, "nt"), sh.find(0, "ni"))
    a0 = sh.find_run(0, tuple(f"A{k}" for k in range(6)))
    d0 = sh.find_run(0, ("D0", "D1", "D2", "E0", "E1", "λTK"))
    rows = [r for r in _rows(sh, 2, 0) if _num(sh.cell(r, a0)) is not None]
    at = Columns(
        name=0,
        vd=sh.find(0, "υd"),
        ve=sh.find(0, "υe"),
        index=cols,
        decimals=_printed(sh, rows, cols),
        transmission=_header_run(sh, 1, sh.find(0, "τ10mm"), _num),
        dndt=list(range(d0, d0 + 6)),
    )
    records = [
        _row_record(sh, r, at, 1, [_num(sh.cell(r, a0 + k)) for k in range(6)], source=source)
        for r in rows
    ]
    # "Relative price" per mass and per volume (two columns; H-K9L = 10): per volume
    price = sh.find(0, "Relative price")
    sh.expect(1, price, "Mass")
    sh.expect(1, price + 1, "Volume")
    return _with_prices(records, sh, rows, price + 1, "H-K9L")


def read_hikari(path: Path, source: str) -> list[dict]:
    sh = Sheet(path, "Data")
    sh.expect(1, 0, r"(硝種 )?Glass type")
    i0 = sh.find(1, r"(屈折率.*)?Refractive index calculated.*")
    i1 = sh.find(2, r"i\s*0\.365015")
    cols = []
    for c in range(i0, i1 + 1):
        head = sh.cell(2, c)
        if isinstance(head, str):
            lab_txt, lam_txt = head.split("\n")
            lam = float(lam_txt) * 1000.0
            key = lab_txt.strip().replace("ｔ", "t").replace("ｓ", "s")
            lab = (f"n{key}", lam)  # the sheet's own wavelength: Hikari computes its table
        else:  # at these (rounded) values
            lam = float(head) * 1000.0
            lab = (f"n{lam:g}", lam)
        cols.append((c, *lab))
    a0 = sh.find(2, "A0")
    sh.expect(2, a0 + 8, r"A8/λ\^12")
    rows = [r for r in _rows(sh, 3, 0) if _num(sh.cell(r, a0)) is not None]
    at = Columns(
        name=0,
        vd=sh.find(2, "νd"),
        ve=sh.find(2, "νe"),
        index=cols,
        decimals=_printed(sh, rows, cols),
        transmission=_header_run(sh, 2, sh.find(2, "280nm"), _labelled(r"(\d+)nm")),
    )
    out = []
    for r in rows:
        # '-' marks a term the fit does not use (J-PSKH8 A2, J-KZFH9 A8): zero
        coefs = [_num(sh.cell(r, a0))] + [
            0.0 if _clean(sh.cell(r, a0 + k)) == "-" else _num(sh.cell(r, a0 + k))
            for k in range(1, 9)
        ]
        if any(v is None for v in coefs):
            continue
        out.append(_row_record(sh, r, at, 13, coefs, source=source))
    return out


def read_sumita(path: Path, source: str) -> list[dict]:
    sh = Sheet(path, 0)
    H = 1
    sh.expect(H, 2, "GNAME")
    cols = _index_columns(sh, H, sh.find(H, "n1548"), sh.find(H, "ni"))
    a0 = sh.find_run(H, tuple(f"A{k}" for k in range(6)))
    d0 = sh.find_run(H, ("D0", "D1"))
    dcols = [d0, d0 + 1] + [sh.find(H, x) for x in ("D2", "E0", "E1", "lambdaTK")]
    thick_c = sh.find(H, "T2_thick")
    rows = [r for r in _rows(sh, H + 1, 2) if _num(sh.cell(r, a0)) is not None]
    at = Columns(
        name=2,
        vd=sh.find(H, "vd"),
        ve=sh.find(H, "ve"),
        index=cols,
        decimals=_printed(sh, rows, cols),
        transmission=_header_run(sh, H, thick_c + 1, _labelled(r"T2_(\d+)")),
        dndt=dcols,
    )
    out = []
    for r in rows:
        coefs = [_num(sh.cell(r, a0 + k)) for k in range(6)]
        thick = _num(sh.cell(r, thick_c)) or 10.0
        out.append(_row_record(sh, r, at, 1, coefs, thickness=thick, source=source))
    return out


def _catalog_date(path: Path) -> str:
    """The edition date the file states about itself (empty when it states none)."""
    name = path.name
    try:
        if name.startswith("SCHOTT"):
            v = Sheet(path, "Datatable").cell(0, _col("G"))
            return v.date().isoformat()
        if name.startswith("SUMITA"):
            return Sheet(path, 0).cell(0, 2).date().isoformat()
        if name.startswith(("HOYA", "CDGM")):
            sheet = pd.ExcelFile(path).sheet_names[0]
            m = re.match(r"(\d{4})(\d{2})(\d{2})?", sheet)
            if m:
                return "-".join(g for g in m.groups() if g)
        if name.startswith("HIKARI"):
            first = str(Sheet(path, "Data").cell(0, 0)).split(",")[0].strip()
            y, mth, d = (int(x) for x in first.split("-"))
            return dt.date(y, mth, d).isoformat()
    except Exception:  # noqa: BLE001 - a date is informative only
        return ""
    return ""


VENDORS = [
    # catalog, reader, current file, previous edition
    ("Schott", read_schott, "SCHOTT.xls", "SCHOTT_prev.xls"),
    ("Ohara", read_ohara, "OHARA.xlsx", "OHARA_prev.xlsx"),
    ("Hoya", read_hoya, "HOYA.xlsx", "HOYA_prev.xlsx"),
    ("CDGM", read_cdgm, "CDGM.xls", None),
    ("Hikari", read_hikari, "HIKARI.xlsx", "HIKARI_prev.xls"),
    ("Sumita", read_sumita, "SUMITA.xlsx", None),
]

# --------------------------------------------------------------------------- refractiveindex.info

RII_SHELF = {
    "Schott": "glass/schott",
    "Ohara": "glass/ohara",
    "Hoya": "glass/hoya",
    "CDGM": "glass/cdgm",
    "Hikari": "glass/hikari",
    "Sumita": "glass/sumita",
}

# Non-catalog materials (catalog "Misc"): name, aliases, refractiveindex.info page, note.
MISC = [
    ("F_SILICA", ["FUSED_SILICA", "SILICA", "SIO2"], "main/SiO2/Malitson.yml", "fused silica"),
    ("CAF2", ["CALCIUM_FLUORIDE"], "main/CaF2/Malitson.yml", "calcium fluoride crystal"),
    ("BAF2", ["BARIUM_FLUORIDE"], "main/BaF2/Malitson.yml", "barium fluoride crystal"),
    ("MGF2", ["MAGNESIUM_FLUORIDE"], "main/MgF2/Dodge-o.yml", "MgF2 crystal, ordinary ray"),
    ("SAPPHIRE", ["AL2O3"], "main/Al2O3/Malitson-o.yml", "sapphire, ordinary ray"),
    ("ZNSE", ["ZINC_SELENIDE"], "main/ZnSe/Connolly.yml", "CVD zinc selenide"),
    ("GERMANIUM", ["GE"], "main/Ge/Burnett.yml", "germanium crystal"),
    ("SILICON", ["SI"], "main/Si/Edwards.yml", "silicon crystal"),
    ("B270", ["B-270", "B270_SCHOTT"], "glass/schott/misc/B270.yml", "Schott B 270 crown"),
    ("BOROFLOAT33", ["BOROFLOAT"], "glass/schott/misc/BOROFLOAT33.yml", "Schott Borofloat 33"),
    ("D263TECO", ["D263", "D263T"], "glass/schott/misc/D263TECO.yml", "Schott D 263 T eco"),
    ("ZERODUR", [], "glass/schott/misc/ZERODUR.yml", "Schott Zerodur"),
    ("EAGLEXG", ["EAGLE_XG"], "glass/corning/EagleXG.yml", "Corning Eagle XG"),
    ("SODA_LIME", ["SODALIME"], "glass/misc/soda-lime/Rubin-clear.yml", "clear soda-lime glass"),
    (
        "PMMA",
        ["ACRYLIC", "PLEXIGLAS"],
        "organic/(C5H8O2)n - poly(methyl methacrylate)/Sultanova.yml",
        "PMMA",
    ),
    (
        "PMMA_ZHANG",
        [],
        "organic/(C5H8O2)n - poly(methyl methacrylate)/Zhang-Mitsubishi.yml",
        "PMMA (Mitsubishi), absolute index, tabulated",
    ),
    (
        "POLYCARB",
        ["POLYCARBONATE", "PC"],
        "organic/(C16H14O3)n - polycarbonate/Sultanova.yml",
        "polycarbonate",
    ),
    (
        "POLYSTYR",
        ["POLYSTYRENE", "PS"],
        "organic/(C8H8)n - polystyren/Sultanova.yml",
        "polystyrene",
    ),
    (
        "ZEONEX_E48R",
        ["E48R", "ZEONEX"],
        "other/commercial plastics/ZeonexE48R/Sultanova.yml",
        "cyclo-olefin polymer Zeonex E48R",
    ),
    (
        "OPTOREZ1330",
        ["OZ1330"],
        "other/commercial plastics/Optorez1330/Sultanova.yml",
        "Optorez 1330",
    ),
    (
        "NAS-21",
        ["NAS21"],
        "other/commercial plastics/NAS-21/Sultanova.yml",
        "styrene-acrylic copolymer NAS-21",
    ),
    ("BD-2", ["BD2"], "glass/lightpath/BD-2.yml", "LightPath BD-2 chalcogenide moulding glass"),
]


# Materials the Zemax MISC catalog defines by a constant rather than by measured data: name,
# formula (AGF number), coefficients, range (µm), nd, note. Source: MISC.AGF as Zemax ships it
# ("Reproduced here by permission of RadiantZemax"), redistributed in KrakenOS 1.0.0.24
# (KrakenOS/Cat/misc.agf) and ZemaxGlass 1.0 (AGF_files/misc.agf), identical files (sha256
# below): "NM N15 5 1 1.500000 0.000000", "GC simulated glass with index of 1.5 at all
# wavelengths between min wave and max wave", "CD 1.5 0 0 ...", "LD 0.365 1.014". Only the
# definition is copied; no measured data of that file are shipped.
DEFINITIONS_SOURCE = {
    "file": "misc.agf (Zemax MISC catalog): KrakenOS/Cat/misc.agf, ZemaxGlass AGF_files/misc.agf",
    "package": "KrakenOS 1.0.0.24 / ZemaxGlass 1.0 (redistributions of the Zemax catalog)",
    "version": "",
    "sha256": "3edff292e367144f4525e0a9fe8278d469f5bff1ebebddfc9c8d08c4312a7f53",
    "catalog_date": "",
    "role": "Misc: Zemax definitions that are constants, not measured data",
}
DEFINITIONS = [
    (
        "N15",
        5,
        [1.5, 0.0, 0.0],
        (0.365, 1.014),
        1.5,
        "Zemax MISC N15: simulated glass of index 1.5 at all wavelengths of its range "
        "(Conrady formula n0 = 1.5, A = B = 0)",
    ),
]

# --------------------------------------------------------------------------- Robb & Mercado 1983

ROBB_FILE = "robb1983_data_final.txt"
#: base wavelength (µm) and α of the fits: ω = Δλ/(1 + 2.5 Δλ), Δλ = λ − 0.574 µm. The base
#: index is n(0.574 µm), not nd: checked in robb_schott_1980 on the glasses the 2018 Schott
#: sheet still lists (their formulas agree with the rows only for λ0 = 0.574 µm)
ROBB_LAMBDA0_UM = 0.574
ROBB_ALPHA = 2.5
#: the visible region of the fits: the wavelengths of largest error the table lists span it
ROBB_RANGE_UM = (0.400, 0.700)
#: largest |n(Schott row) − n(other catalog's row of the same name)| over ROBB_RANGE_UM for a
#: row to count as confirmed; equivalent glasses of two 1980 catalogs differ by ≤ 3.4e-4 in the
#: table; the rows that disagree (SF18, LASF13, LASF15) do so by ≥ 5e-2 — a transcription error
#: (the Schott SF18 row gives nd 1.654, Schott's SF18 is 1.7215) or another glass of that name
ROBB_CONFIRM = 1e-3
ROBB_NAMES = {
    "OHARA": "Ohara",
    "HOYA": "Hoya",
    "CORNING-FRANCE": "Corning-France",
    "CHANCE": "Chance",
}


def read_robb(path: Path) -> dict[str, dict[str, tuple[float, ...]]]:
    """catalog → glass → (n0, ν1, ν2, std dev, max error, λ of max error µm) of the table."""
    tables: dict[str, dict[str, tuple[float, ...]]] = {}
    cat = None
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.startswith("#"):
            m = re.match(r"#\s*(\S+) GLASS CATALOGUE", line)
            if m:
                cat = m.group(1)
                tables[cat] = {}
            continue
        t = line.split()
        if not t:
            continue
        if cat is None or len(t) != 7 or t[0] in tables[cat]:
            raise SystemExit(f"{path.name}: unexpected line {line!r}")
        tables[cat][t[0]] = tuple(float(x) for x in t[1:])
    return tables


def _robb_n(row: tuple[float, ...], lam_um):
    import numpy as np

    d = np.asarray(lam_um, dtype=float) - ROBB_LAMBDA0_UM
    w = d / (1.0 + ROBB_ALPHA * d)
    return row[0] + row[1] * w + row[2] * w * w


def robb_schott_1980(
    path: Path, source: str, catalogs: dict[str, list[dict]]
) -> tuple[list[dict], dict]:
    """Records for the Schott 1980 glasses of the Robb & Mercado table that nothing shipped
    covers, and a summary of the selection (counts, rejected rows)."""
    import numpy as np

    tables = read_robb(path)
    schott = tables["SCHOTT"]
    lam = np.linspace(*ROBB_RANGE_UM, 61)

    def key(name: str) -> str:
        return re.sub(r"[^A-Z0-9.]", "", name.upper())

    shipped = {
        key(n)
        for recs in catalogs.values()
        for r in recs
        for n in (r["name"], *r.get("aliases", []))
    }
    current = {key(r["name"]): r for r in catalogs["Schott"] if not r["status"]}
    evaluate = _runtime_formulas().evaluate
    check = []
    for name, row in schott.items():
        r = current.get(key(name))
        if r is not None:
            n = evaluate(r["formula"], tuple(r["coefficients"]), lam)
            check.append(float(np.max(np.abs(_robb_n(row, lam) - n))))
    if len(check) < 10 or float(np.median(check)) > 1e-4:
        raise SystemExit(
            f"{path.name}: the Schott rows do not reproduce the 2018 Schott formulas "
            f"(median max |Δn| {np.median(check):.1e} over {len(check)} glasses): λ0, α?"
        )
    out, rejected, unconfirmed = [], [], []
    for name, row in schott.items():
        if key(name) in shipped or key("N-" + name) in shipped:
            continue
        others = {c: t[name] for c, t in tables.items() if c != "SCHOTT" and name in t}
        diffs = {
            c: float(np.max(np.abs(_robb_n(row, lam) - _robb_n(o, lam)))) for c, o in others.items()
        }
        if not diffs:
            unconfirmed.append(name)
            continue
        if min(diffs.values()) > ROBB_CONFIRM:
            rejected.append(name)
            continue
        n0, nu1, nu2, sd, emax, lam_emax = row
        coef = [ROBB_LAMBDA0_UM, ROBB_ALPHA, n0, nu1, nu2]
        nd, nf, nc = (
            float(x) for x in evaluate("buchdahl", tuple(coef), [0.5875618, 0.4861327, 0.6562725])
        )
        by = "; ".join(
            f"{ROBB_NAMES[c]} {d:.1e}" for c, d in sorted(diffs.items()) if d <= ROBB_CONFIRM
        )
        out.append(
            _record(
                name,
                "buchdahl",
                coef,
                [],
                nd=round(nd, 6),
                vd=round((nd - 1.0) / (nf - nc), 4),
                status="legacy",
                source=source,
                range_um=ROBB_RANGE_UM,
                note=(
                    "Schott 1980 catalog as fitted by Robb & Mercado 1983 (Appl. Opt. 22, 1198, "
                    f"Table V; quadratic Buchdahl model, std dev {sd:g}, max error {emax:g} at "
                    f"{lam_emax:g} µm over the visible); nd and vd computed from the fit; the "
                    "row is confirmed by the same name's row of another 1980 catalog of the "
                    f"table (max |Δn| over 400-700 nm: {by})"
                ),
            )
        )
    summary = {
        "shipped": len(out),
        "rejected": rejected,
        "unconfirmed": len(unconfirmed),
        "median_max_dn_vs_2018_formulas": round(float(np.median(check)), 7),
        "glasses_compared_with_2018": len(check),
    }
    return out, summary


def _rii_temperature(d: dict) -> float | None:
    specs = d.get("SPECS") or {}
    t = specs.get("temperature")
    for text in (str(t) if t is not None else "", str(d.get("COMMENTS") or "")):
        m = re.search(r"(-?\d+(?:\.\d+)?)\s*(°C|K\b)", text)
        if m:
            v = float(m.group(1))
            return v - 273.15 if m.group(2) == "K" else v
    return None


def read_rii(path: Path, rel: str) -> dict | None:
    """A record from one refractiveindex.info page (None when it has no index data)."""
    d = yaml.safe_load(path.read_text(encoding="utf-8"))
    specs = d.get("SPECS") or {}
    formula = None
    for entry in d.get("DATA", []):
        typ = entry["type"].strip()
        if typ.startswith("formula"):
            n = int(typ.split()[1])
            coefs = [float(x) for x in str(entry["coefficients"]).split()]
            lo, hi = (float(x) for x in str(entry["wavelength_range"]).split())
            formula = (f"rii{n}" if n != 5 else "cauchy", coefs, (lo, hi))
            break
        if typ in ("tabulated n", "tabulated nk"):
            rows = [ln.split() for ln in str(entry["data"]).strip().splitlines()]
            lam = [float(r[0]) for r in rows]
            n = [float(r[1]) for r in rows]
            if len(lam) < 2:
                return None
            # the table's wavelengths are printed to 0.01 nm: its ends are known to ±0.005 nm
            formula = ("tabulated", lam + n, (min(lam) - 5e-6, max(lam) + 5e-6))
            break
    if formula is None:
        return None
    fid, coefs, rng = formula
    if fid == "rii7":  # refractiveindex.info formula 7 is the Herzberger formula, AGF 3
        fid = 3
        coefs = (coefs + [0.0] * 6)[:6]
    absolute = specs.get("n_is_absolute")
    temp = _rii_temperature(d)
    notes = []
    if absolute is None:
        notes.append("index basis not stated by the source; taken as relative to air")
    if temp is None:
        notes.append("temperature not stated by the source; taken as 20 °C")
    if specs.get("wavelength_is_vacuum"):
        notes.append("source wavelengths are vacuum wavelengths")
    dndt = None
    for td in specs.get("thermal_dispersion") or []:
        if str(td.get("type", "")).startswith("Schott"):
            dndt = [float(x) for x in str(td["coefficients"]).split()]
    return {
        "formula": fid,
        "coefficients": coefs,
        "range_um": rng,
        "basis": "absolute" if absolute else "relative",
        "temperature_c": 20.0 if temp is None else temp,
        "nd": specs.get("nd"),
        "vd": specs.get("Vd"),
        "status": str(specs.get("glass_status") or ""),
        "dndt": dndt,
        "note": "; ".join(notes),
        "path": rel,
    }


def _runtime_formulas():
    """raytrace/glass/formulas.py loaded on its own (numpy only; no package import)."""
    path = ROOT / "raytrace" / "glass" / "formulas.py"
    spec = importlib.util.spec_from_file_location("_glass_formulas", path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod  # dataclasses need the module registered
    spec.loader.exec_module(mod)
    return mod


def _nd_vd_from(formula_rec: dict) -> tuple[float | None, float | None]:
    """nd and vd computed from a refractiveindex.info formula (for materials without them)."""
    evaluate = _runtime_formulas().evaluate

    lo, hi = formula_rec["range_um"]
    if not (lo <= 0.4861327 and hi >= 0.6562725):
        return None, None
    n = evaluate(
        formula_rec["formula"],
        tuple(formula_rec["coefficients"]),
        [0.5875618, 0.4861327, 0.6562725],
    )
    nd, nf, nc = (float(x) for x in n)
    return round(nd, 6), round((nd - 1.0) / (nf - nc), 4)


# --------------------------------------------------------------------------- main


def build(date: str) -> dict[str, bytes]:
    og = _pkg_dir("opticalglass") / "data"
    rii = _pkg_dir("optiland") / "database" / "data-nk"
    og_v = importlib.metadata.version("opticalglass")
    ol_v = importlib.metadata.version("optiland")
    sources: dict[str, dict] = {}
    catalogs: dict[str, list[dict]] = {}

    def add_source(key: str, path: Path, package: str, version: str, role: str) -> str:
        sources[key] = {
            "file": str(
                path.relative_to(path.parents[2] if package == "optiland" else path.parents[1])
            )
            if package == "optiland"
            else f"opticalglass/data/{path.name}",
            "package": package,
            "version": version,
            "sha256": _sha256(path),
            "catalog_date": _catalog_date(path) if package == "opticalglass" else "",
            "role": role,
        }
        return key

    def add_rii_source(rel: str, path: Path, role: str) -> str:
        """Register the refractiveindex.info page ``rel`` (the file ``path``) as a source."""
        key = f"refractiveindex.info:{rel}"
        sources[key] = {
            "file": f"optiland/database/data-nk/{rel}",
            "package": "optiland",
            "version": ol_v,
            "sha256": _sha256(path),
            "catalog_date": "",
            "role": role,
        }
        return key

    for cat, reader, cur, prev in VENDORS:
        src = add_source(cur, og / cur, "opticalglass", og_v, f"{cat} catalog, current edition")
        recs, seen = [], {}
        for r in reader(og / cur, src):
            key = re.sub(r"[^A-Z0-9.]", "", r["name"].upper())
            if key in seen:  # CDGM lists "H-K9L" and "H-K9L*" with the same data
                first = recs[seen[key]]
                if first["coefficients"] != r["coefficients"]:
                    raise SystemExit(f"{cur}: {r['name']} and {first['name']} differ")
                first.setdefault("aliases", []).append(r["name"])
                if r.get("price") != first.get("price"):  # CDGM prices H-K9L* apart (5 vs 10)
                    first.setdefault("alias_prices", {})[r["name"]] = r.get("price")
                continue
            seen[key] = len(recs)
            recs.append(r)
        if prev:
            psrc = add_source(
                prev, og / prev, "opticalglass", og_v, f"{cat} catalog, previous edition"
            )
            for r in reader(og / prev, psrc):
                key = re.sub(r"[^A-Z0-9.]", "", r["name"].upper())
                if key not in seen:
                    r["status"] = "withdrawn"
                    seen[key] = len(recs)
                    recs.append(r)
        # legacy glasses from the refractiveindex.info vendor shelf (vendor AGF data)
        shelf = rii / RII_SHELF[cat]
        for p in sorted(shelf.rglob("*.yml")):
            if p.parent.name == "BK7":  # glass/schott/BK7/Lane.yml: infrared n,k of old BK7
                continue
            name = p.stem
            key = re.sub(r"[^A-Z0-9.]", "", name.upper())
            if key in seen:
                continue
            rec = read_rii(p, str(p.relative_to(rii)))
            if rec is None or rec["formula"] == "tabulated":
                continue
            computed = rec["nd"] is None or rec["vd"] is None
            if computed:
                rec["nd"], rec["vd"] = _nd_vd_from(rec)
                if rec["nd"] is None:
                    continue
                rec["note"] = "; ".join(
                    x for x in (rec["note"], "nd and vd computed from the formula") if x
                )
            rsrc = add_rii_source(
                rec["path"], p, f"{cat} legacy glass (refractiveindex.info, from the vendor AGF)"
            )
            recs.append(
                _record(
                    name,
                    rec["formula"],
                    rec["coefficients"],
                    [],
                    nd=float(rec["nd"]),
                    vd=float(rec["vd"]),
                    dndt=rec["dndt"],
                    status="legacy",
                    source=rsrc,
                    range_um=rec["range_um"],
                    basis=rec["basis"],
                    temperature_c=rec["temperature_c"],
                    note="; ".join(
                        x
                        for x in (
                            "in no catalog spreadsheet; data from refractiveindex.info"
                            + (f" (status there: {rec['status']})" if rec["status"] else ""),
                            rec["note"],
                        )
                        if x
                    ),
                )
            )
            seen[key] = len(recs) - 1
        catalogs[cat] = recs

    misc = []
    for name, aliases, rel, what in MISC:
        p = rii / rel
        rec = read_rii(p, rel)
        if rec is None:
            raise SystemExit(f"{rel}: no index data")
        nd, vd = rec["nd"], rec["vd"]
        if nd is None or vd is None:
            nd, vd = _nd_vd_from(rec)
            if nd is not None:
                rec["note"] = "; ".join(
                    x for x in (rec["note"], "nd and vd computed from the data") if x
                )
        rsrc = add_rii_source(rel, p, f"Misc: {what}")
        misc.append(
            _record(
                name,
                rec["formula"],
                rec["coefficients"],
                [],
                nd=None if nd is None else float(nd),
                vd=None if vd is None else float(vd),
                dndt=rec["dndt"],
                status=rec["status"],
                source=rsrc,
                range_um=rec["range_um"],
                basis=rec["basis"],
                temperature_c=rec["temperature_c"],
                aliases=aliases,
                note="; ".join(x for x in (what, rec["note"]) if x),
            )
        )
    sources["Zemax MISC definitions"] = DEFINITIONS_SOURCE
    for name, fid, coef, rng, nd, note in DEFINITIONS:
        misc.append(
            _record(
                name,
                fid,
                coef,
                [],
                nd=nd,
                vd=None,
                source="Zemax MISC definitions",
                range_um=rng,
                note=note,
            )
        )
    catalogs["Misc"] = misc

    rsrc = add_source(
        ROBB_FILE,
        og / ROBB_FILE,
        "opticalglass",
        og_v,
        "Schott 1980 catalog (Robb & Mercado 1983, Table V): old glasses nothing else covers",
    )
    old_schott, summary = robb_schott_1980(og / ROBB_FILE, rsrc, catalogs)
    catalogs["Schott"].extend(old_schott)
    sources[rsrc]["selection"] = summary

    meta = {
        "format": FORMAT,
        "generated": date,
        "generator": "tools/make_glass_catalog.py",
        "python": ".".join(map(str, sys.version_info[:3])),
        "readers": {
            "pandas": importlib.metadata.version("pandas"),
            "xlrd": importlib.metadata.version("xlrd"),
            "openpyxl": importlib.metadata.version("openpyxl"),
            "PyYAML": importlib.metadata.version("PyYAML"),
        },
        "catalogs": list(catalogs),
        "sources": sources,
    }
    index = {
        cat: [[r["name"], r["nd"], r["vd"], r["status"], r.get("aliases", [])] for r in recs]
        for cat, recs in catalogs.items()
    }

    def dump(obj) -> bytes:
        return json.dumps(obj, sort_keys=True, separators=(",", ":"), ensure_ascii=False).encode()

    members = {"meta.json": dump(meta), "index.json": dump(index)}
    for cat, recs in catalogs.items():
        members[f"{cat}.jsonl"] = b"".join(dump(r) + b"\n" for r in recs)
    return members


# --------------------------------------------------------------------------- test extracts

# refractiveindex.info pages copied into tests/data/glass/rii_pages.json (independent data for
# tests/test_glass_formulas.py): a sample of each vendor shelf, and the Misc pages.
RII_TEST_PAGES = [
    "glass/schott/N-BK7.yml",
    "glass/schott/F2.yml",
    "glass/schott/N-SF66.yml",
    "glass/schott/N-FK51A.yml",
    "glass/ohara/S-BSL7.yml",
    "glass/ohara/S-LAH79.yml",
    "glass/ohara/S-FPL53.yml",
    "glass/hoya/FCD1.yml",
    "glass/hoya/E-FD10.yml",
    "glass/hoya/TAFD25.yml",
    "glass/hikari/J-BK7A.yml",
    "glass/hikari/J-LASF016.yml",
    "glass/hikari/J-FK01A.yml",
    "glass/sumita/K-BK7.yml",
    "glass/sumita/K-LaSFn9.yml",
    "glass/cdgm/H-K9L.yml",
    "glass/cdgm/H-ZF88.yml",
    "organic/(C5H8O2)n - poly(methyl methacrylate)/Beadie.yml",
] + [rel for _, _, rel, _ in MISC]


def write_test_extracts(folder: Path) -> None:
    """Small reference extracts for the tests (sources named inside each file)."""
    rii = _pkg_dir("optiland") / "database" / "data-nk"
    pages = {}
    for rel in RII_TEST_PAGES:
        p = rii / rel
        d = yaml.safe_load(p.read_text(encoding="utf-8"))
        entry = next(e for e in d["DATA"] if not e["type"].strip().endswith(" k"))
        specs = d.get("SPECS") or {}
        pages[rel] = {
            "type": entry["type"].strip(),
            "wavelength_range": entry.get("wavelength_range"),
            "coefficients": entry.get("coefficients"),
            "data": entry.get("data"),
            "n_is_absolute": specs.get("n_is_absolute"),
            "temperature": str(specs.get("temperature") or ""),
            "comments": str(d.get("COMMENTS") or "")[:120],
            "sha256": _sha256(p),
        }
    out = {
        "source": "refractiveindex.info database pages as shipped in the optiland wheel "
        f"(optiland {importlib.metadata.version('optiland')}, optiland/database/data-nk); "
        "copied verbatim (first n or formula entry) by tools/make_glass_catalog.py",
        "pages": pages,
    }
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "rii_pages.json").write_text(json.dumps(out, indent=1, ensure_ascii=False) + "\n")

    og = _pkg_dir("opticalglass") / "data"
    sh = Sheet(og / "SCHOTT.xls", "Datatable")
    H = 3
    d0 = sh.find(H, "D0")
    blocks = {}
    for c in range(sh.df.shape[1]):
        top = sh.cell(2, c)
        if isinstance(top, str) and "temperature coefficients" in top:
            kind = "relative" if top.strip().startswith("Relative") else "absolute"
            rng = re.search(r"\[([-+]?\d+)/([-+]?\d+)", top)
            for k, line in enumerate(("1060nm", "e-line", "g-line")):
                blocks[(kind, int(rng.group(1)), int(rng.group(2)), line)] = c + k
    rows = {}
    for r in _rows(sh, H + 1, 0):
        name = _clean(sh.cell(r, 0))
        if name not in ("N-BK7", "F2", "N-SF6", "N-FK51A", "N-LASF44", "P-SK57", "SF6", "N-KZFS4"):
            continue
        rows[name] = {
            "dndt_constants": [_num(sh.cell(r, d0 + k)) for k in range(6)],
            "coefficients_10^-6/K": [
                [kind, t1, t2, line, _num(sh.cell(r, c))]
                for (kind, t1, t2, line), c in sorted(blocks.items())
            ],
        }
    out = {
        "source": "SCHOTT.xls (Schott optical glass data sheet, edition "
        f"{_catalog_date(og / 'SCHOTT.xls')}, as shipped in opticalglass "
        f"{importlib.metadata.version('opticalglass')}), columns 'Constants for dn/dT' and "
        "'Relative/Absolute temperature coefficients of refractive index [T1/T2 deg.C]' "
        "(10^-6/K; 1060 nm, e-line 546.074 nm, g-line 435.8343 nm); extracted by "
        "tools/make_glass_catalog.py",
        "sha256": _sha256(og / "SCHOTT.xls"),
        "glasses": rows,
    }
    (folder / "schott_dndt.json").write_text(json.dumps(out, indent=1) + "\n")


def write_zip(members: dict[str, bytes], out: Path) -> None:
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_suffix(".tmp")
    with zipfile.ZipFile(tmp, "w") as zf:
        for name in sorted(members):
            info = zipfile.ZipInfo(name, date_time=(1980, 1, 1, 0, 0, 0))
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = 0o644 << 16
            zf.writestr(info, members[name], compresslevel=9)
    tmp.replace(out)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--date", default=dt.date.today().isoformat(), help="generation date recorded")
    ap.add_argument("--out", type=Path, default=OUT)
    ap.add_argument(
        "--test-extracts", type=Path, metavar="DIR", help="also write the tests' reference extracts"
    )
    args = ap.parse_args(argv)
    if args.test_extracts:
        write_test_extracts(args.test_extracts)
    members = build(args.date)
    write_zip(members, args.out)
    index = json.loads(members["index.json"])
    for cat, rows in index.items():
        print(f"{cat:8s} {len(rows):5d} materials")
    print(f"{args.out}: {args.out.stat().st_size} bytes")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
