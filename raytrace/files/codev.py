"""CODE V sequence files (``.seq``): read the common subset into a :class:`Lens`.

Syntax: one command per line or several separated by ``;``; ``&`` at the end of a line continues
it; ``!`` starts a comment; commands are case-insensitive; strings are quoted with ``'`` or ``"``.

Supported commands:

* ``LEN`` (start), ``TIT``/``TITLE 'name'``, ``RDM [Y|N]`` (Y, the default: surface values are
  radii; N: curvatures — a file without ``RDM`` is read as radii and a warning says so),
  ``DIM M|C|I`` (mm, cm, inch → mm), ``GO`` (end).
* Aperture: ``EPD d`` (entrance-pupil diameter), ``FNO N`` (f-number, EFL/EPD), ``NA``/``NAO``
  (object-space NA). Field: ``YAN``/``XAN`` (angles, degrees) or ``YOB``/``XOB`` (object heights);
  the lens's field is the largest radial value √(x² + y²). Image-space fields (``YIM``, ``YRI``)
  are refused. Wavelengths: ``WL λ1 λ2 …`` (nm) and ``REF i`` (1-based reference wavelength;
  without ``REF`` the middle one of the list is used and a warning says so).
* Surfaces: ``SO r t [glass]`` (object: ``t`` is the object distance, ≥ 1e10 = infinity),
  ``S r t [glass]``, ``STO r t [glass]`` (a surface that is the stop), ``SI r t`` (image: its
  values are ignored, the last ``S`` thickness is the image distance). After a surface line:
  ``STO`` (this surface is the stop), ``SLB 'label'``, ``CIR r`` (clear aperture: semi-diameter
  that clips rays; ``CIR EDG`` is mechanical and ignored), ``ASP``/``CON``/``SPH``, ``K`` (conic),
  ``A B C D E F G H J`` (the r⁴ … r²⁰ coefficients: CODE V's asphere is
  ``z = c r²/(1+√(1−(1+K)c²r²)) + A r⁴ + B r⁶ + C r⁸ + D r¹⁰ + …``), ``PIM`` (paraxial image
  solve on the last thickness → the Gaussian image plane, ``Lens.image_solve = "gaussian"``).
  ``CCY``, ``THC``, ``GLC`` and coefficient variable codes (``KC``, ``AC`` …) are optimization
  flags and are ignored.
* Glasses: catalog names (``NSK16_SCHOTT``, ``N-SK16``; a ``_VENDOR`` suffix picks the catalog),
  ``nd:vd`` model glasses (``1.620:60.3``) and six-digit codes (``620603`` or ``620.603``).

Anything that changes the optics and cannot be modelled (decenters and tilts ``ADE BDE CDE XDE
YDE ZDE DAR BEN REV``, mirrors ``REFL``, diffractive or special surfaces, gradient index, pickups)
raises :class:`~raytrace.errors.PrescriptionError` with the file, line and what to do; other
unknown commands are listed in one :class:`~raytrace.zemax.InteropWarning`. Every problem with the
input raises PrescriptionError (never another exception type).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path

from ..errors import LensError, PrescriptionError
from ..glass import lookup_glass, normalize_name, parse_glass_code, private_material
from ..lens import Aperture, Field, Lens, Surface, check_file_lens
from ..materials import AIR, LAMBDA_D, Material
from .text import ImportResult, emit_warnings, guarded_parse, lens_error, number, read_bytes

#: CODE V treats an object distance of 1e10 or more as infinite.
CODEV_INFINITY = 1.0e10

_DIM = {"M": 1.0, "MM": 1.0, "C": 10.0, "CM": 10.0, "I": 25.4, "IN": 25.4}
_ASPH_LETTERS = "ABCDEFGHJ"  # r^4 ... r^20
_IGNORED = set(
    """LEN WTF VUY VLY VUX VLX INI DER CCY THC GLC CUF KC AC BC CC DC EC FC GC HC
    JC POL CLS TOL TOLE AUT SAV DES""".split()
)
_DECENTER = {"ADE", "BDE", "CDE", "XDE", "YDE", "ZDE", "DAR", "BEN", "REV", "RET", "DEC", "TILT"}
_SPECIAL = {"DIF", "HOE", "HCO", "HWL", "HOR", "GRT", "SPS", "UDS", "GRIN", "GRD", "ZRN"}
_MAX_WARNINGS = 50


@dataclass
class _CSurf:
    kind: str  # "SO" | "S" | "SI"
    line: int
    r: float = 0.0
    t: float = 0.0
    glass: tuple[str, int] | None = None
    stop: bool = False
    label: str = ""
    cir: float = math.inf
    conic: float = 0.0
    asph: dict[int, float] = field(default_factory=dict)
    pim: int | None = None


def _logical_lines(text: str) -> list[tuple[int, list[str]]]:
    """(line number, tokens) of each command: comments removed, ``&`` continuations joined,
    ``;`` separated; quoted strings kept as one token (with their quotes)."""
    out: list[tuple[int, list[str]]] = []
    pending: list[str] = []
    start = 0
    for lineno, raw in enumerate(text.split("\n"), start=1):
        toks: list[str] = []
        cur = ""
        quote = ""
        cont = False
        for ch in raw.rstrip("\r"):
            if quote:
                cur += ch
                if ch == quote:
                    quote = ""
                continue
            if ch in "'\"":
                quote = ch
                cur += ch
            elif ch == "!":
                break
            elif ch == ";":
                if cur:
                    toks.append(cur)
                    cur = ""
                toks.append(";")
            elif ch.isspace():
                if cur:
                    toks.append(cur)
                    cur = ""
            else:
                cur += ch
        if cur:
            toks.append(cur)
        if toks and toks[-1].endswith("&"):
            toks[-1] = toks[-1][:-1]
            if not toks[-1]:
                toks.pop()
            cont = True
        if not pending:
            start = lineno
        pending.extend(toks)
        if cont:
            continue
        cmd: list[str] = []
        for t in pending:
            if t == ";":
                if cmd:
                    out.append((start, cmd))
                cmd = []
            else:
                cmd.append(t)
        if cmd:
            out.append((start, cmd))
        pending = []
    if pending:
        cmd = [t for t in pending if t != ";"]
        if cmd:
            out.append((start, cmd))
    return out


def _unquote(s: str) -> str:
    if len(s) >= 2 and s[0] in "'\"" and s[-1] == s[0]:
        return s[1:-1]
    return s.strip("'\"")


class _SeqParser:
    def __init__(self, text: str, path: str | None) -> None:
        self.text = text
        self.path = path
        self.warnings: list[str] = []
        self.unknown: dict[str, int] = {}

    def err(self, message: str, line: int | None, surface: int | None = None):
        return PrescriptionError(message, path=self.path, line=line or 1, surface=surface)

    def fail(self, message: str, line: int | None):
        return self.err(message, line)

    def warn(self, message: str) -> None:
        if len(self.warnings) < _MAX_WARNINGS:
            self.warnings.append(message)

    def num(self, args: list[str], i: int, cmd: str, line: int) -> float:
        if i >= len(args):
            raise self.err(f"{cmd} needs a number (value {i + 1} is missing)", line)
        return number(args[i], cmd, self.fail, line)

    def nums(self, args: list[str], cmd: str, line: int) -> list[float]:
        if not args:
            raise self.err(f"{cmd} needs at least one number", line)
        return [self.num(args, i, cmd, line) for i in range(len(args))]

    def parse(self) -> ImportResult:
        if not self.text.strip():
            raise self.err("the file is empty: expected a CODE V .seq lens file", 1)
        surfs: list[_CSurf] = []
        cur: _CSurf | None = None
        h: dict[str, tuple] = {}
        xan = yan = xob = yob = None
        in_prv = False
        prv_wl: tuple[list[float], int] | None = None
        self.private: dict[str, Material] = {}
        rdm_seen = False
        for line, toks in _logical_lines(self.text):
            cmd, args = toks[0].upper(), toks[1:]
            if in_prv:
                if cmd == "END":
                    in_prv = False
                elif cmd == "PWL":
                    prv_wl = (self.nums(args, "PWL", line), line)
                else:
                    self.private_glass(toks, prv_wl, line)
                continue
            if cmd == "GO":
                break
            if cmd == "PRV":
                in_prv = True
                continue
            if cmd == "RDM":
                v = args[0].upper() if args else "Y"
                if v not in ("Y", "N", "YES", "NO"):
                    raise self.err(f"RDM {args[0][:20]}: expected RDM Y or RDM N", line)
                h["RDM"] = v.startswith("Y")
                rdm_seen = True
            elif cmd in ("TIT", "TITLE"):
                h["TITLE"] = " ".join(_unquote(a) for a in args)
            elif cmd == "DIM":
                d = args[0].upper() if args else ""
                if d not in _DIM:
                    raise self.err(f"DIM {d or '(none)'}: expected DIM M, C or I", line)
                h["DIM"] = _DIM[d]
            elif cmd in ("EPD", "FNO", "NA", "NAO"):
                h["APER"] = (cmd, self.num(args, 0, cmd, line), line)
            elif cmd in ("NAI", "NAM"):
                raise self.err(
                    f"{cmd}: an image-space NA aperture is not supported; use EPD, FNO or NAO",
                    line,
                )
            elif cmd == "WL":
                h["WL"] = (self.nums(args, "WL", line), line)
            elif cmd == "REF":
                h["REF"] = (int(self.num(args, 0, "REF", line)), line)
            elif cmd == "WTW":
                h["WTW"] = (self.nums(args, "WTW", line), line)
            elif cmd == "TEM":
                h["TEM"] = (self.num(args, 0, "TEM", line), line)
            elif cmd == "PRE":
                v = self.num(args, 0, "PRE", line)
                if v not in (1.0, 760.0):
                    raise self.err(
                        f"PRE {args[0][:20]}: a system pressure other than 1 atm is not "
                        "supported; remove PRE (or set it to 1 atm) and save again",
                        line,
                    )
            elif cmd in ("YAN", "XAN", "YOB", "XOB"):
                vals = (self.nums(args, cmd, line), line)
                if cmd == "YAN":
                    yan = vals
                elif cmd == "XAN":
                    xan = vals
                elif cmd == "YOB":
                    yob = vals
                else:
                    xob = vals
            elif cmd in ("YIM", "XIM", "YRI", "XRI"):
                raise self.err(
                    f"{cmd}: image-height fields are not supported; give the field as angles "
                    "(YAN) or object heights (YOB)",
                    line,
                )
            elif cmd in ("SO", "S", "SI") or (cmd in ("STO", "STOP") and len(args) >= 2):
                kind = "S" if cmd in ("STO", "STOP") else cmd
                if kind == "SO" and surfs:
                    raise self.err("SO (object surface) must come before every S line", line)
                if kind != "SO" and not surfs:
                    surfs.append(_CSurf("SO", line, t=math.inf))
                    self.warn("no SO line: the object is at infinity")
                if surfs and surfs[-1].kind == "SI":
                    raise self.err(f"{cmd} after SI: the image surface must be the last", line)
                if len(surfs) > 10000:
                    raise self.err("more than 10000 surfaces", line)
                cur = _CSurf(kind, line)
                if args:
                    cur.r = self.num(args, 0, cmd, line)
                if len(args) >= 2:
                    cur.t = self.num(args, 1, cmd, line)
                    if kind == "SO" and cur.t >= CODEV_INFINITY:
                        cur.t = math.inf
                rest = args[2:]
                for tok in rest:
                    if tok.upper() in ("REFL", "REFLECT"):
                        raise self.err(
                            "REFL: mirrors are not supported; orthoscope traces refracting "
                            "lenses only",
                            line,
                            len(surfs),
                        )
                if rest:
                    cur.glass = (_unquote(rest[0]), line)
                if len(rest) > 1:
                    self.warn(f"line {line}: extra values after the glass ignored: {rest[1:]}")
                cur.stop = cmd in ("STO", "STOP")
                surfs.append(cur)
            elif cmd in ("STO", "STOP"):
                if cur is None or cur.kind != "S":
                    raise self.err("STO must follow a surface line (S r t glass)", line)
                cur.stop = True
            elif cmd in ("SLB", "CIR", "ASP", "CON", "SPH", "K", "PIM") or (
                cmd in _ASPH_LETTERS and len(cmd) == 1
            ):
                if cur is None:
                    raise self.err(f"{cmd} before the first surface line", line)
                self.surface_command(cur, cmd, args, line, len(surfs) - 1)
            elif cmd in _DECENTER:
                raise self.err(
                    f"{cmd}: decenters and tilts are not supported; orthoscope models centred "
                    "lenses only — remove the decenter in CODE V and save the .seq again",
                    line,
                    max(len(surfs) - 1, 0) or None,
                )
            elif cmd in _SPECIAL:
                raise self.err(
                    f"{cmd}: diffractive, gradient-index and special surfaces are not "
                    "supported; orthoscope reads spheres, conics and even aspheres (ASP with "
                    "K, A, B, C, D ...)",
                    line,
                    max(len(surfs) - 1, 0) or None,
                )
            elif cmd in ("REFL", "REFLECT"):
                raise self.err(
                    "REFL: mirrors are not supported; orthoscope traces refracting lenses only",
                    line,
                )
            elif cmd == "PIK":
                raise self.err(
                    "PIK: pickups are not supported; in CODE V freeze the pickups (replace "
                    "them by their values) and save the .seq again",
                    line,
                )
            elif cmd in _IGNORED:
                pass
            else:
                self.unknown.setdefault(cmd[:20], line)
        if not rdm_seen:
            self.warn("no RDM line: surface values are read as radii (RDM Y, CODE V's default)")
        return self.build(surfs, h, xan, yan, xob, yob)

    def surface_command(self, cur: _CSurf, cmd: str, args: list[str], line: int, no: int):
        if cmd == "SLB":
            cur.label = " ".join(_unquote(a) for a in args)
        elif cmd == "CIR":
            if args and args[0].upper() in ("EDG", "HOL", "OBS"):
                if args[0].upper() != "EDG":
                    self.warn(f"line {line}: CIR {args[0]} (hole/obscuration) ignored")
                return
            r = self.num(args, 0, "CIR", line)
            if not r > 0.0:
                raise self.err(f"CIR: the aperture radius must be positive, got {r}", line, no)
            cur.cir = r
        elif cmd == "K":
            cur.conic = self.num(args, 0, "K", line)
        elif cmd in ("ASP", "CON", "SPH"):
            if cmd == "SPH":
                cur.conic = 0.0
                cur.asph.clear()
        elif cmd == "PIM":
            cur.pim = line
        else:
            cur.asph[_ASPH_LETTERS.index(cmd)] = self.num(args, 0, cmd, line)

    def private_glass(self, toks: list[str], prv_wl, line: int) -> None:
        """One private glass of a PRV block: ``'NAME' n1 n2 ...`` (indices at the PWL
        wavelengths, nm) or ``'NAME' LAU A0 A1 A2 A3 A4 A5`` (Laurent:
        n² = A0 + A1 λ² + A2 λ⁻² + A3 λ⁻⁴ + A4 λ⁻⁶ + A5 λ⁻⁸, λ in µm — AGF formula 1)."""
        name = _unquote(toks[0])
        args = toks[1:]
        if not args:
            raise self.err(f"PRV glass {name}: no data after the name", line)
        key = args[0].upper()
        if key == "LAU":
            coef = tuple(self.nums(args[1:], f"PRV {name} LAU", line))
            formula, rng = 1, (0.0, math.inf)
        elif key[:1].isalpha():
            raise self.err(
                f"PRV glass {name}: the dispersion form {args[0]} is not supported (orthoscope "
                "reads indices at the PWL wavelengths and LAU); give the glass as nd:vd or a "
                "catalog name instead",
                line,
            )
        else:
            vals = self.nums(args, f"PRV {name}", line)
            if prv_wl is None or len(prv_wl[0]) != len(vals):
                raise self.err(
                    f"PRV glass {name}: {len(vals)} indices need a PWL line with as many "
                    f"wavelengths (got {0 if prv_wl is None else len(prv_wl[0])})",
                    line,
                )
            pairs = sorted(zip(prv_wl[0], vals, strict=True))
            lam = [p[0] / 1000.0 for p in pairs]
            if len(set(lam)) != len(lam) or not all(v > 0.0 for v in vals):
                raise self.err(f"PRV glass {name}: repeated wavelengths or indices <= 0", line)
            coef = tuple(lam) + tuple(p[1] for p in pairs)
            formula, rng = "spline", (pairs[0][0], pairs[-1][0])
        try:
            self.private[normalize_name(name)] = private_material(name, formula, coef, rng)
        except ValueError as e:
            raise self.err(f"PRV {e}", line) from None

    def material(self, g: tuple[str, int] | None, no: int) -> Material:
        if g is None:
            return AIR
        name, line = g
        if name.upper() == "AIR":
            return AIR
        if normalize_name(name) in self.private:
            return self.private[normalize_name(name)]
        code = parse_glass_code(name)
        if code is not None:
            return code
        try:
            cg = lookup_glass(name)
        except PrescriptionError as e:
            raise self.err(f"glass {name}: {e.reason}", line, no) from None
        return cg.material

    def build(self, surfs, h, xan, yan, xob, yob) -> ImportResult:
        last_line = len(self.text.split("\n"))
        scale = h.get("DIM", 1.0)
        radius_mode = h.get("RDM", True)
        body = [s for s in surfs if s.kind == "S"]
        if not body:
            raise self.err("no surfaces: a lens needs S lines between SO and SI", last_line)
        obj = surfs[0]
        img = surfs[-1] if surfs[-1].kind == "SI" else None
        if img is not None and img.r != 0.0:
            self.warn(f"line {img.line}: the image surface is curved; a flat image plane is used")
        if obj.r != 0.0:
            self.warn(f"line {obj.line}: the object surface is curved; a flat object plane is used")
        stops = [s for s in body if s.stop]
        if len(stops) > 1:
            raise self.err("more than one STO surface", stops[1].line)
        if not stops:
            self.warn("no STO: surface 1 is the stop")
        od = obj.t if math.isinf(obj.t) else obj.t * scale
        if not od > 0.0:
            raise self.err(
                f"SO: the object distance must be positive (or >= 1e10 for infinity), got "
                f"{obj.t!r}",
                obj.line,
            )
        out: list[Surface] = []
        for k, s in enumerate(body, start=1):
            if s.r == 0.0:
                c = 0.0
            elif radius_mode:
                c = 1.0 / (s.r * scale)
            else:
                c = s.r / scale
            n = max(s.asph, default=-1) + 1
            asph = tuple(s.asph.get(j, 0.0) * scale ** (-3 - 2 * j) for j in range(n))
            while asph and asph[-1] == 0.0:
                asph = asph[:-1]
            out.append(
                Surface(
                    curvature=c,
                    thickness=s.t * scale,
                    material=self.material(s.glass, k),
                    semi_diameter=s.cir * scale,
                    stop=s.stop or (not stops and k == 1),
                    conic=s.conic,
                    aspheric=asph,
                    label=s.label,
                    line=s.line,
                )
            )
        pims = [s for s in body if s.pim is not None]
        if pims and pims[-1] is not body[-1]:
            raise self.err("PIM (paraxial image solve) only on the last surface", pims[-1].pim)
        # wavelengths (nm), weights, reference
        if "WL" in h:
            wls, wl_line = h["WL"]
            if "REF" in h:
                ref, ref_line = h["REF"]
                if not 1 <= ref <= len(wls):
                    raise self.err(f"REF {ref}: WL lists {len(wls)} wavelength(s)", ref_line)
            else:
                ref = (len(wls) + 1) // 2
                if len(wls) > 1:
                    self.warn(f"no REF: the middle wavelength {wls[ref - 1]:g} nm is used")
            wts = [1.0] * len(wls)
            if "WTW" in h:
                given, wt_line = h["WTW"]
                if len(given) != len(wls) or not all(w >= 0.0 for w in given):
                    raise self.err(
                        f"WTW: give one weight >= 0 per WL wavelength ({len(wls)})", wt_line
                    )
                wts = list(given)
        else:
            wls, wl_line, ref, wts = [LAMBDA_D], last_line, 1, [1.0]
            self.warn("no WL: the d line 587.5618 nm is used")
        from ..units import UnitError, wavelength_nm

        for w in wls:
            try:
                wavelength_nm(w)
            except UnitError as e:
                raise self.err(f"WL {w:g}: {e} (CODE V wavelengths are in nm)", wl_line) from None
        wl = wls[ref - 1]
        temperature = None
        if "TEM" in h:
            t, t_line = h["TEM"]
            if not -273.15 < t < 1000.0:
                raise self.err(f"TEM {t!r}: temperature out of range (°C)", t_line)
            temperature = t if t != 20.0 else None
        # aperture
        if "APER" not in h:
            raise self.err("no aperture: the file needs EPD, FNO or NAO", last_line)
        acmd, aval, aline = h["APER"]
        if not aval > 0.0:
            raise self.err(f"{acmd} must be positive, got {aval!r}", aline)
        if acmd == "EPD":
            aperture = Aperture("epd", aval * scale)
        elif acmd == "FNO":
            aperture = Aperture("fnumber", aval)
        else:
            if math.isinf(od) or aval >= 1.0:
                raise self.err(f"{acmd}: an object NA needs a finite object and NA < 1", aline)
            aperture = Aperture("na", aval)
        # field
        if yob or xob:
            kind, xs, ys = "height", xob, yob
        else:
            kind, xs, ys = "angle", xan, yan
        fline = (ys or xs or (None, last_line))[1]
        xv = xs[0] if xs else []
        yv = ys[0] if ys else []
        radial = [
            math.hypot(xv[i] if i < len(xv) else 0.0, yv[i] if i < len(yv) else 0.0)
            for i in range(max(len(xv), len(yv)))
        ]
        fmax = max(radial, default=0.0)
        if not radial:
            self.warn("no field (YAN/YOB): the field is 0")
        if kind == "angle":
            if fmax >= 90.0:
                raise self.err(f"field angle {fmax:g} deg: must be below 90", fline)
            fld = Field("angle", fmax)
        else:
            if math.isinf(od):
                raise self.err("YOB: object heights need a finite object distance (SO)", fline)
            fld = Field("height", fmax * scale)
        if self.unknown:
            listing = ", ".join(f"{c} (line {ln})" for c, ln in list(self.unknown.items())[:30])
            self.warn(f"unknown commands skipped: {listing}")
        name = h.get("TITLE") or (Path(self.path).stem if self.path else "CODE V lens")
        kw = dict(
            name=name,
            surfaces=tuple(out),
            aperture=aperture,
            field=fld,
            object_distance=od,
            wavelength=wl,
            wavelengths=tuple(wls),
            weights=tuple(wts),
            temperature_c=temperature,
            source=f"imported from the CODE V file {Path(self.path).name}" if self.path else "",
            notes="",
            units="mm",
            object_material=self.material(obj.glass, 0) if obj.glass else AIR,
            path=self.path,
        )
        lines = [s.line for s in body]
        try:
            lens = Lens(**kw)
            check_file_lens(lens)
        except (LensError, ValueError) as e:
            raise lens_error(self.err, e, lines, obj.line) from None
        if pims:
            lens = self.solve_image(lens, pims[-1].pim, lines)
        return ImportResult(lens, tuple(self.warnings))

    def solve_image(self, lens: Lens, line: int, lines: list[int]) -> Lens:
        from ..paraxial import paraxial

        try:
            d = float(paraxial(lens.with_image_distance(0.0)).gaussian_image_distance)
        except (LensError, ValueError, ArithmeticError) as e:
            raise lens_error(self.err, e, lines, line) from None
        if not (math.isfinite(d) and d >= 0.0):
            raise self.err(
                f"PIM: the paraxial image is {'at infinity' if not math.isfinite(d) else 'virtual'}"
                "; give the image distance as the last thickness instead",
                line,
            )
        s = list(lens.surfaces)
        s[-1] = replace(s[-1], thickness=d)
        return replace(lens, surfaces=tuple(s), image_solve="gaussian")


def parse_seq(text: str | bytes, *, path: str | Path | None = None) -> ImportResult:
    """Parse CODE V ``.seq`` content (text or bytes) into an :class:`ImportResult`."""
    return guarded_parse(_SeqParser, text, path, "a CODE V .seq lens file")


def loads_seq(text: str | bytes, *, path: str | Path | None = None) -> Lens:
    """Parse ``.seq`` content into a :class:`Lens`; skipped commands → one InteropWarning."""
    return emit_warnings(parse_seq(text, path=path), None if path is None else str(path))


def read_seq(path: str | Path) -> Lens:
    """Read a CODE V ``.seq`` file into a :class:`Lens` (mm, nm). Raises PrescriptionError
    (file, line, what to do) for anything it cannot read."""
    return emit_warnings(parse_seq(read_bytes(path), path=path), str(path))
