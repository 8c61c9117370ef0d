"""The tolerance lines (``TOL``) of a Zemax OpticStudio ``.zmx`` file, read into a
:class:`~raytrace.tolerance.spec.ToleranceSpec` (the lens itself is read by
:mod:`raytrace.files.zemax`; this module reads only the tolerance data).

Line layout (as OpticStudio writes it; the corpus file ``pyzdde/Cooke_40_degree_field.zmx``
shows its default ``TOL TOFF   0   0              0              0   0 0 0``)::

    TOL CODE INT1 INT2 MIN MAX INT3 INT4 INT5

* operands read (their meanings: :mod:`raytrace.tolerance.spec`): ``TRAD TCUR TFRN TTHI TCON
  TSDX TSDY TSTX TSTY TIRX TIRY TIRR TIND TABB`` with INT1 the surface (TTHI: INT2 the adjust
  surface), ``TEDX TEDY TETX TETY`` with INT1..INT2 the element's surfaces, ``TPAR`` on an
  ``EVENASPH`` surface (INT2 = parameter n ≥ 2 → the r^(2n) coefficient, our ``TASP``);
* ``TWAV``: the test wavelength for fringes, MIN in µm;
* ``STAT``: the distribution of the operands after it: INT1 = 0 normal (INT2 = the limits in σ,
  default 2), 1 uniform; 2 (parabolic) and 3 (user) are not supported;
* ``COMP`` on the last thickness (INT2 = 0): the back focus is a compensator → ``best-focus``
  (OpticStudio's default criterion, RMS spot radius); other compensators are not supported;
* ``TOFF`` (an empty row) is ignored; every other code (``CPAR``, ``SAVE``, ``TEZI``, ...) is
  listed in :attr:`ZemaxTolerances.skipped` with its line, not guessed.

OpticStudio counts surfaces from 0 (the object); the surface numbers here are the file's, which
are the 1-based numbers of :mod:`raytrace.lens` (surface 1 = the first lens surface).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from ..files.text import read_capped
from .spec import (
    DEFAULT_SIGMA,
    DEFAULT_TEST_WAVELENGTH,
    Compensator,
    ToleranceSpec,
    ToleranceSpecError,
    make_item,
)

#: OpticStudio operand codes read as surface or element items
READ_CODES = ("TRAD", "TCUR", "TFRN", "TTHI", "TCON", "TSDX", "TSDY", "TSTX", "TSTY", "TIRX",
              "TIRY", "TIRR", "TIND", "TABB", "TEDX", "TEDY", "TETX", "TETY")  # fmt: skip


@dataclass(frozen=True)
class ZemaxTolerances:
    """What the TOL lines of a file hold: ``spec`` (None when there is no operand), the lines
    not read (``skipped``: (line, text, reason)) and the surface types seen (``surface_types``,
    for messages)."""

    spec: ToleranceSpec | None
    skipped: tuple[tuple[int, str, str], ...]
    path: str


def _text(path: Path) -> str:
    try:
        raw = read_capped(path)
    except FileNotFoundError:
        raise ToleranceSpecError(f"{path}: no such file; check the path") from None
    except OSError as e:
        raise ToleranceSpecError(f"{path}: cannot read it: {e.strerror or e}") from None
    if raw[:2] in (b"\xff\xfe", b"\xfe\xff"):
        return raw.decode("utf-16")
    for enc in ("utf-8-sig", "latin-1"):
        try:
            return raw.decode(enc)
        except UnicodeDecodeError:
            continue
    return raw.decode("latin-1", errors="replace")  # pragma: no cover - latin-1 always decodes


def parse_zmx_tolerances(text: str, path: str = "<zmx>") -> ZemaxTolerances:
    """The TOL lines of ``text`` (the contents of a .zmx file) — see the module docstring."""
    items = []
    skipped = []
    dist, sigma = "normal", DEFAULT_SIGMA
    test_wl = DEFAULT_TEST_WAVELENGTH
    comp = None
    surf_type: dict[int, str] = {}
    cur = None
    last_surface = 0
    for ln, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if line.startswith("SURF "):
            try:
                cur = int(line.split()[1])
                last_surface = max(last_surface, cur)
            except (IndexError, ValueError):
                cur = None
            continue
        if line.startswith("TYPE ") and cur is not None:
            surf_type[cur] = line.split()[1]
            continue
        if not line.startswith("TOL "):
            continue
        tok = line.split()
        where = f"{path}:{ln}"
        code = tok[1].upper() if len(tok) > 1 else ""
        try:
            i1, i2 = int(tok[2]), int(tok[3])
            lo, hi = float(tok[4]), float(tok[5])
        except (IndexError, ValueError):
            raise ToleranceSpecError(
                f"{where}: expected 'TOL CODE INT1 INT2 MIN MAX ...', got {line!r}"
            ) from None
        if code == "TOFF":
            continue
        if code == "TWAV":
            if not (math.isfinite(lo) and lo > 0.0):
                raise ToleranceSpecError(f"{where}: TWAV test wavelength must be positive µm")
            test_wl = round(lo * 1000.0, 9)  # µm → nm without 632.8000000000001
            continue
        if code == "STAT":
            if i1 == 0:
                dist, sigma = "normal", float(i2) if i2 > 0 else DEFAULT_SIGMA
            elif i1 == 1:
                dist = "uniform"
            else:
                raise ToleranceSpecError(
                    f"{where}: STAT {i1} (parabolic or user-defined statistics) is not "
                    "supported; use 0 (normal) or 1 (uniform)"
                )
            continue
        if code == "COMP":
            if i2 == 0 and i1 >= 1:
                comp = (ln, i1)
            else:
                skipped.append((ln, line, "compensators other than a thickness are not read"))
            continue
        if code == "TPAR":
            if surf_type.get(i1, "") == "EVENASPH" and i2 >= 2:
                items.append(make_item("TASP", where=where, surface=i1, lo=lo, hi=hi,
                                       distribution=dist, sigma=sigma, term=2 * i2))  # fmt: skip
            else:
                skipped.append((ln, line, "TPAR is read only for even-asphere terms r^4 and up"))
            continue
        if code not in READ_CODES:
            skipped.append((ln, line, f"{code} is not supported"))
            continue
        kw: dict = dict(where=where, lo=lo, hi=hi, distribution=dist, sigma=sigma)
        if code in ("TEDX", "TEDY", "TETX", "TETY"):
            kw["surfaces"] = (i1, i2)
        else:
            kw["surface"] = i1
            if code == "TTHI":
                kw["adjust"] = i2
        items.append(make_item(code, **kw))
    compensator = Compensator("fixed-sensor")
    if comp is not None:
        ln, s = comp
        if s == last_surface - 1 or s == last_surface:
            compensator = Compensator("best-focus")
        else:
            skipped.append((ln, f"COMP {s} 0", "only the back-focus thickness is a compensator"))
    spec = None
    if items:
        spec = ToleranceSpec(tuple(items), compensator, test_wl, name=Path(path).stem,
                             notes="read from the TOL lines of a .zmx file", path=path)  # fmt: skip
    return ZemaxTolerances(spec, tuple(skipped), path)


def read_zmx_tolerances(path: str | Path) -> ToleranceSpec:
    """The tolerance spec of a .zmx file's TOL lines (module docstring). Raises
    :class:`ToleranceSpecError` when the file has no tolerance operand; lines not read are in
    :func:`parse_zmx_tolerances`'s ``skipped``."""
    p = Path(path)
    z = parse_zmx_tolerances(_text(p), str(p))
    if z.spec is None:
        raise ToleranceSpecError(
            f"{p}: the file has no tolerance operands (TOL lines other than TOFF); write a "
            "TOML tolerance spec (docs/tolerance.md)"
        )
    return z.spec
