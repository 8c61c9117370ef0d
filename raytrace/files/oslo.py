"""OSLO ``.len`` lens files: read the common sequential subset into a :class:`Lens`.

Syntax: one command per line, ``//`` starts a comment, commands are case-insensitive; a file is
``LEN [NEW] "title" ...``, system commands, then the surfaces from the object (surface 0) on,
each ended by ``NXT``, and ``END``. Read:

* System: ``UNI u`` (mm per lens unit; lengths are converted to mm), ``EBR r`` (entrance beam
  radius: EPD = 2 r; OSLO Program Reference: the beam radius at surface 1, the entrance pupil
  for an object at infinity), ``FNO N`` (OSLO's image-space F-number, the paraxial working F/#
  1/(2 |n' u'|): ``Aperture("working_fnumber")``), ``NAO`` (object-space NA), ``ANG a`` (field
  angle, degrees) or ``OBH h`` (object height; with an object at infinity it gives the angle
  atan(h / object distance)), ``WV λ1 λ2 …`` / ``WV2 λ`` … (µm; the first is the primary),
  ``WW`` (weights), ``DES``/``SNO…`` (notes).
* Surfaces: ``RD r`` (radius; ``CV c`` curvature), ``TH t`` (thickness to the next vertex; on
  surface 0 the object distance, ≥ 1e10 = infinity), ``AIR`` / ``GLA NAME`` (the medium after
  the surface; catalog names are looked up with Schott first, OSLO's default catalog) / ``GLA
  MOD NAME n1 n2 …`` (indices at the WV wavelengths: a private glass through those points) /
  ``RFL`` (a mirror: the medium after it is the one before; thicknesses after an odd number of
  mirrors are negative, as OSLO writes them), ``CC k`` (conic), ``AD AE AF AG`` (r⁴ … r¹⁰
  coefficients), ``AST`` (aperture stop), ``AP r`` (aperture radius: a hard aperture only where
  the file checks it with ``APCK``), ``PY 0`` on the last surface (axial-ray height solve: the
  image plane at the paraxial image, ``Lens.image_solve = "gaussian"``).

Anything that changes the optics and is not read (decenters ``DCX DCY DCZ TLA TLB TLC``, other
solves and pickups, special surfaces, gradient index) raises
:class:`~raytrace.errors.PrescriptionError` with the file, line and what to do; display and
bookkeeping commands are listed in one InteropWarning. The file format is OSLO 5/6 as written by
OSLO and by optiland's OSLO writer (the corpus files of tests/data/corpus/optiland/). A file cut
short is refused (``check_complete``: the closing ``END`` and the surface counts of ``END n`` and
``LEN NEW "title" … n``; lenses/INTEROP.md, "Truncated files").
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import PrescriptionError
from ..glass import private_material, resolve_glass
from ..lens import Aperture, Field, Lens, Surface
from ..materials import AIR, LAMBDA_D, Material
from .text import (
    ImportResult,
    LineParser,
    emit_warnings,
    guarded_parse,
    number,
    read_bytes,
    solve_paraxial_image,
)

#: OSLO treats a thickness of 1e10 or more on the object surface as an object at infinity
OSLO_INFINITY = 1.0e10
_ASPH = {"AD": 0, "AE": 1, "AF": 2, "AG": 3, "AH": 4, "AI": 5, "AJ": 6, "AK": 7}
_IGNORED = set(
    """LEN DES SNO SNO1 SNO2 SNO3 SNO4 SNO5 SNO6 SNO7 SNO8 SNO9 SNO10 NAM TEM PRE DLM DLW DLS
    DLA DLC DLN DLP DLR DLF DLO DLV DLH DLT DLD DLI LBL SRF AP_ NOT CMT""".split()
)
_REFUSED = {
    "DCX": "decenter",
    "DCY": "decenter",
    "DCZ": "decenter",
    "TLA": "tilt",
    "TLB": "tilt",
    "TLC": "tilt",
    "DT": "decenter type",
    "GRT": "grating",
    "DFR": "diffractive surface",
    "GRN": "gradient-index medium",
    "SPS": "special surface",
    "XSD": "special surface",
    "TOR": "toroidal surface",
    "PK": "pickup",
    "PYC": "solve",
    "PUY": "solve",
    "PUC": "solve",
    "CVM": "solve",
}


@dataclass
class _OSurf:
    line: int
    curv: float = 0.0
    th: float = 0.0
    th_line: int = 0
    medium: tuple[str, list[str], int] | None = None  # ("AIR" | "GLA" | "RFL", args, line)
    cc: float = 0.0
    asph: dict[int, float] = field(default_factory=dict)
    stop: bool = False
    ap: float = math.inf
    apck: bool = False
    py: int | None = None


def _tokens(line: str) -> list[str]:
    """Tokens of one line (comments removed; quoted strings kept as one token)."""
    out, cur, quote = [], "", ""
    i = 0
    while i < len(line):
        ch = line[i]
        if quote:
            cur += ch
            if ch == quote:
                quote = ""
        elif ch in "'\"":
            quote = ch
            cur += ch
        elif line.startswith("//", i):
            break
        elif ch.isspace():
            if cur:
                out.append(cur)
                cur = ""
        else:
            cur += ch
        i += 1
    if cur:
        out.append(cur)
    return out


class _LenParser(LineParser):
    def parse(self) -> ImportResult:
        if not self.text.strip():
            raise self.err("the file is empty: expected an OSLO .len lens file", 1)
        h: dict[str, tuple] = {}
        surfs: list[_OSurf] = []
        cur: _OSurf | None = None
        wvs: dict[int, tuple[float, int]] = {}
        seen_len = False
        declared: tuple[int, int] | None = None  # surface count on the LEN line, its line
        end: tuple[int | None, int] | None = None  # surface count on the END line, its line
        nxt = 0
        for lineno, raw in enumerate(self.text.split("\n"), start=1):
            toks = _tokens(raw.strip().lstrip("\ufeff"))
            if not toks:
                continue
            cmd, args = toks[0].upper(), toks[1:]
            if cmd == "LEN":
                seen_len = True
                title = [a.strip("\"'") for a in args if a.upper() != "NEW"]
                if title and not _is_number(title[0]):
                    h["NAME"] = title[0]
                nums = [t for t in title if _is_number(t)]
                n_decl = _count(nums) if len(nums) >= 2 else None  # "title" value count
                declared = None if n_decl is None else (n_decl, lineno)
                continue
            if not seen_len:
                raise self.err(
                    f"{cmd}: an OSLO lens file starts with 'LEN [NEW] \"title\"'", lineno
                )
            if cmd == "END":
                end = (_count(args), lineno)
                break
            if cmd == "NXT":
                cur = None
                nxt += 1
                continue
            if cmd in ("UNI", "EBR", "FNO", "NAO", "ANG", "OBH"):
                h[cmd] = (self.num(args, 0, cmd, lineno), lineno)
                continue
            if cmd.startswith("WV"):
                k = 1 if cmd == "WV" else int(cmd[2:]) if cmd[2:].isdigit() else 0
                if k == 0:
                    raise self.err(f"{cmd}: expected WV or WVn", lineno)
                for j in range(len(args)):
                    wvs[k + j] = (self.num(args, j, cmd, lineno), lineno)
                continue
            if cmd == "WW":
                h["WW"] = ([self.num(args, j, cmd, lineno) for j in range(len(args))], lineno)
                continue
            if cmd in _REFUSED:
                raise self.err(
                    f"{cmd}: OSLO {_REFUSED[cmd]}s are not read; remove it in OSLO (or export "
                    "the lens as Zemax .zmx or CODE V .seq) and save again",
                    lineno,
                    len(surfs) - 1 if surfs else None,
                )
            surface_cmd = cmd in {"RD", "CV", "TH", "AIR", "GLA", "RFL", "CC", "AST", "AP",
                                  "APCK", "PY"} or cmd in _ASPH  # fmt: skip
            if surface_cmd:
                if cur is None:
                    cur = _OSurf(lineno)
                    surfs.append(cur)
                self.surface_command(cur, cmd, args, lineno, len(surfs) - 1)
                continue
            if cmd in _IGNORED or cmd.startswith("SNO"):
                continue
            self.unknown.setdefault(cmd[:20], lineno)
        if not seen_len:
            raise self.err("not an OSLO .len lens file: no LEN line", 1)
        self.check_complete(nxt, declared, end)
        return self.build(surfs, h, wvs)

    def check_complete(
        self, nxt: int, declared: tuple[int, int] | None, end: tuple[int | None, int] | None
    ) -> None:
        """Refuse a truncated file (a cut file must not read as a shorter lens). An OSLO lens
        ends with ``END n`` and its first line ``LEN NEW "title" ... n`` may carry the same n,
        the number of the image surface (= the number of ``NXT`` lines: surface 0 is the
        object); both are checked when present. Not detectable: a cut inside the ``END`` line
        itself (``END 12`` → ``END 1`` is caught by the count, ``END`` alone is not when the
        LEN line has no count)."""
        last_line = len(self.text.rstrip().split("\n"))
        if end is None:
            raise self.err(
                f"the file ends at line {last_line} without OSLO's closing END (after {nxt} "
                "surfaces): it looks truncated; use the complete file (OSLO writes END n last)",
                last_line,
            )
        for what, count, line in (
            ("END", end[0], end[1]),
            ("LEN", *(declared if declared else (None, 0))),
        ):
            if count is not None and count != nxt:
                raise self.err(
                    f"{what} declares {count} surfaces after the object, but the file has "
                    f"{nxt} (NXT lines): it is truncated or damaged; use the complete file",
                    line,
                )

    def surface_command(self, cur: _OSurf, cmd: str, args: list[str], line: int, no: int):
        if cmd == "RD":
            r = self.num(args, 0, cmd, line)
            cur.curv = 0.0 if r == 0.0 else 1.0 / r
        elif cmd == "CV":
            cur.curv = self.num(args, 0, cmd, line)
        elif cmd == "TH":
            cur.th = number(args[0], cmd, self.fail, line, allow_inf=True) if args else 0.0
            cur.th_line = line
        elif cmd in ("AIR", "GLA", "RFL"):
            cur.medium = (cmd, args, line)
        elif cmd == "CC":
            cur.cc = self.num(args, 0, cmd, line)
        elif cmd in _ASPH:
            cur.asph[_ASPH[cmd]] = self.num(args, 0, cmd, line)
        elif cmd == "AST":
            cur.stop = True
        elif cmd == "AP":
            cur.ap = self.num(args, 0, cmd, line)
        elif cmd == "APCK":
            cur.apck = not args or args[0].upper() in ("ON", "1", "Y", "YES")
        elif cmd == "PY":
            if self.num(args, 0, cmd, line) != 0.0:
                raise self.err(
                    "PY: only the axial-ray height solve PY 0 (the paraxial image) is read", line
                )
            cur.py = line

    def material(self, medium, wvs: list[float], before: Material, no: int) -> Material:
        if medium is None:
            return before if no > 0 else AIR
        cmd, args, line = medium
        if cmd == "AIR":
            return AIR
        if cmd == "RFL":
            return before
        if not args:
            raise self.err("GLA needs a glass name", line, no)
        if args[0].upper() == "MOD":
            vals = args[1:]
            name = vals[0].strip("\"'") if vals and not _is_number(vals[0]) else f"MOD{no}"
            idx = [float(v) for v in vals if _is_number(v)]
            if len(idx) < 2 or len(idx) > len(wvs):
                raise self.err(
                    f"GLA MOD {name}: needs one index per WV wavelength ({len(wvs)}), got "
                    f"{len(idx)}",
                    line,
                    no,
                )
            pairs = sorted(zip(wvs[: len(idx)], idx, strict=True))
            coef = tuple(p[0] / 1000.0 for p in pairs) + tuple(p[1] for p in pairs)
            try:
                return private_material(name, "spline", coef, (pairs[0][0], pairs[-1][0]))
            except ValueError as e:
                raise self.err(f"GLA MOD {name}: {e}", line, no) from None
        name = args[0].strip("\"'")
        try:
            r = resolve_glass(name, ["SCHOTT"])
        except PrescriptionError as e:
            raise self.err(f"GLA {name}: {e.reason}", line, no) from None
        if r.warning:
            self.warn(f"line {line}: {r.warning}")
        return r.material

    def build(self, surfs: list[_OSurf], h: dict, wvs: dict[int, tuple[float, int]]):
        last_line = len(self.text.split("\n"))
        if len(surfs) < 3:
            raise self.err(
                f"found {len(surfs)} surface(s): a lens needs the object surface, at least one "
                "lens surface and the image surface",
                last_line,
            )
        scale = h.get("UNI", (1.0, 0))[0]
        if not scale > 0.0:
            raise self.err("UNI must be positive (mm per lens unit)", h["UNI"][1])
        # wavelengths (µm → nm), the first is the primary
        if wvs:
            slots = sorted(wvs)
            wls = [wvs[k][0] * 1000.0 for k in slots]
        else:
            wls = [LAMBDA_D]
            self.warn("no WV: the d line 587.5618 nm is used")
        wts = list(h.get("WW", ([], 0))[0]) or [1.0] * len(wls)
        if len(wts) != len(wls):
            raise self.err(f"WW: one weight per wavelength ({len(wls)})", h["WW"][1])
        obj, img, body = surfs[0], surfs[-1], surfs[1:-1]
        od = obj.th
        od = math.inf if (math.isinf(od) or od >= OSLO_INFINITY) else od * scale
        if not od > 0.0:
            raise self.err(f"the object distance (TH of surface 0) must be positive, got {od}",
                           obj.th_line or obj.line)  # fmt: skip
        stops = [s for s in body if s.stop]
        if len(stops) > 1:
            raise self.err("more than one AST", stops[1].line)
        if not stops:
            self.warn("no AST: surface 1 is the stop")
        if img.curv != 0.0:
            self.warn(f"line {img.line}: the image surface is curved; a flat plane is used")
        object_material = self.material(obj.medium, wls, AIR, 0)
        out: list[Surface] = []
        for k, s in enumerate(body, start=1):
            before = object_material if not out else out[-1].material
            mirror = s.medium is not None and s.medium[0] == "RFL"
            mat = self.material(s.medium, wls, before, k)
            n = max(s.asph, default=-1) + 1
            asph = tuple(s.asph.get(j, 0.0) * scale ** (-3 - 2 * j) for j in range(n))
            out.append(
                Surface(
                    curvature=s.curv / scale,
                    thickness=s.th * scale,
                    material=mat,
                    semi_diameter=s.ap * scale if (s.apck and math.isfinite(s.ap)) else math.inf,
                    stop=s.stop or (not stops and k == 1),
                    conic=s.cc,
                    aspheric=asph,
                    line=s.line,
                    mirror=mirror,
                )
            )
        pys = [s for s in body if s.py is not None]
        if pys and pys[-1] is not body[-1]:
            raise self.err("PY 0 (the image solve) only on the last lens surface", pys[-1].py)
        # aperture
        if "EBR" in h:
            aperture = Aperture("epd", 2.0 * h["EBR"][0] * scale)
        elif "FNO" in h:
            aperture = Aperture("working_fnumber", abs(h["FNO"][0]))
        elif "NAO" in h:
            aperture = Aperture("na", h["NAO"][0])
        else:
            raise self.err("no aperture: the file needs EBR, FNO or NAO", last_line)
        if not aperture.value > 0.0:
            raise self.err(f"the aperture {aperture.describe()} must be positive", last_line)
        # field
        if "ANG" in h:
            a = abs(h["ANG"][0])  # with a finite object: a nominal angle (docs/design.md)
            fld = Field("angle", a, ((0.0, a),))
        elif "OBH" in h:
            y = abs(h["OBH"][0])
            if math.isinf(od):
                fld = Field("angle", math.degrees(math.atan(y / obj.th)))
            else:
                fld = Field("height", y * scale, ((0.0, y * scale),))
        else:
            fld = Field("angle", 0.0)
            self.warn("no field (ANG/OBH): the field is 0")
        self.warn_unknown()
        name = h.get("NAME") or (Path(self.path).stem if self.path else "OSLO lens")
        lines = [s.line for s in body]
        lens = self.file_lens(
            lines,
            obj.line,
            name=name,
            surfaces=tuple(out),
            aperture=aperture,
            field=fld,
            object_distance=od,
            wavelength=wls[0],
            wavelengths=tuple(wls),
            weights=tuple(wts),
            source=f"imported from the OSLO file {Path(self.path).name}" if self.path else "",
            units="mm",
            object_material=object_material,
            path=self.path,
        )
        if pys:
            lens = self.solve_image(lens, pys[-1].py, lines)
        return ImportResult(lens, tuple(self.warnings))

    def solve_image(self, lens: Lens, line: int, lines: list[int]) -> Lens:
        return solve_paraxial_image(
            lens,
            self.err,
            lines,
            line,
            lambda d: "PY 0: the paraxial image is virtual or at infinity",
        )


def _count(args: list[str]) -> int | None:
    """The last token as a whole number >= 0 (OSLO's surface count on LEN / END), else None."""
    if not args or not _is_number(args[-1]):
        return None
    v = float(args[-1])
    return int(v) if v == int(v) and 0 <= v < 1e6 else None


def _is_number(s: str) -> bool:
    try:
        float(s)
    except ValueError:
        return False
    return True


def parse_len(text: str | bytes, *, path: str | Path | None = None) -> ImportResult:
    """Parse OSLO ``.len`` content (text or bytes) into an :class:`ImportResult`."""
    return guarded_parse(_LenParser, text, path, "an OSLO .len lens file")


def loads_len(text: str | bytes, *, path: str | Path | None = None) -> Lens:
    """Parse ``.len`` content into a :class:`Lens`; skipped commands → one InteropWarning."""
    return emit_warnings(parse_len(text, path=path), None if path is None else str(path))


def read_len(path: str | Path) -> Lens:
    """Read an OSLO ``.len`` file into a :class:`Lens` (mm, nm). Raises PrescriptionError (file,
    line, what to do) for anything it cannot read."""
    return emit_warnings(parse_len(read_bytes(path), path=path), str(path))
