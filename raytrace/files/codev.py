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
  ``S r t [glass]``, ``STO r t [glass]`` (a surface that is the stop), ``SI r t`` (image: ``t``
  is CODE V's defocus, added to the last ``S`` thickness — or to the ``PIM`` solve —; not applied,
  with a warning, when the image surface is decentered; a curved image surface is read as flat,
  with a warning). After a surface line:
  ``STO`` (this surface is the stop), ``SLB 'label'``, ``CIR r`` (clear aperture: semi-diameter
  that clips rays; ``CIR EDG`` is mechanical and ignored), ``ASP``/``CON``/``SPH``, ``K`` (conic),
  ``A B C D E F G H J`` (the r⁴ … r²⁰ coefficients: CODE V's asphere is
  ``z = c r²/(1+√(1−(1+K)c²r²)) + A r⁴ + B r⁶ + C r⁸ + D r¹⁰ + …``), ``PIM`` (paraxial image
  solve on the last thickness → the Gaussian image plane, ``Lens.image_solve = "gaussian"``).
  ``CCY``, ``THC``, ``GLC`` and coefficient variable codes (``KC``, ``AC`` …) are optimization
  flags and are ignored.
* Glasses: catalog names (``NSK16_SCHOTT``, ``N-SK16``; a ``_VENDOR`` suffix picks the catalog),
  ``nd:vd`` model glasses (``1.620:60.3``) and six-digit codes (``620603`` or ``620.603``).

* Decenters and tilts (:mod:`raytrace.frames` states the conventions): ``XDE YDE ZDE`` (mm) and
  ``ADE BDE CDE`` (degrees; α, β left-handed, γ right-handed: stored as right-handed tilts
  (−α, −β, γ)), applied decenter first, then α, β, γ about the moving axes; the decenter type
  ``DEC`` (basic, the default: the following surfaces stay in the new frame), ``DAR`` (decenter
  and return), ``BEN`` (bend: the axis turns by the tilt once more, for fold mirrors) or ``REV``
  (reverse: the surface stays, the following surfaces move by the inverse). On ``SI`` they
  place the image surface. ``RET`` and ``GLB`` (coordinates of another surface) are refused.
* Mirrors: ``REFL`` on the surface line (``S r t REFL``) or as a command after it; the medium
  after a mirror is the one before it, and thicknesses after an odd number of mirrors are
  negative (as CODE V writes them).
* Clear apertures: ``CIR r`` (circular, about the vertex unless ``ADX``/``ADY`` move it),
  ``REX``/``REY`` (rectangle half-widths), ``ELX``/``ELY`` (ellipse semi-axes), with ``ADX``,
  ``ADY`` (aperture decenter); ``EDG`` (mechanical edge) is ignored, ``HOL``/``OBS`` (holes,
  obscurations) are ignored with a warning.
* Fields in image space: ``YIM``/``XIM`` (paraxial image height) and ``YRI``/``XRI`` (real image
  height) are turned into the object-space angle (or height) that gives them
  (``Field.given`` keeps the original).
* Pickups (``PIK item Sk ... item Sj ... [scale [offset]]`` for ``RDY``, ``CUY``, ``THI``): CODE V
  writes the picked-up values into the surface lines, so a pickup is only checked against them
  (within 1e-9 relative) and refused when they disagree.

Solves (``THI HMY 0``, ``CUY UMY -0.1``: CODE V wrote their results on the surface lines) keep
the stored values, with a warning. Anything that changes the optics and cannot be modelled
(diffractive, special or anamorphic surfaces, gradient index, other pickups, a surface changed
by a command such as ``THI S5 20`` or ``GLA S1 …``) raises
:class:`~raytrace.errors.PrescriptionError` with the file, line and what to do; other unknown
commands are listed in one :class:`~raytrace.zemax.InteropWarning`. Every problem with the
input raises PrescriptionError (never another exception type). A file cut short is refused,
never read as a shorter lens (``check_complete``: ``GO``, or without it ``SI``, aperture, field
and wavelengths; lenses/INTEROP.md, "Truncated files").
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path

from ..errors import LensError, PrescriptionError
from ..frames import Placement, codev_tilt
from ..glass import normalize_name, parse_glass_code, private_material, resolve_glass
from ..lens import Aperture, ClearAperture, Field, Lens, Surface
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

#: CODE V treats an object distance of 1e10 or more as infinite.
CODEV_INFINITY = 1.0e10

_DIM = {"M": 1.0, "MM": 1.0, "C": 10.0, "CM": 10.0, "I": 25.4, "IN": 25.4}
_ASPH_LETTERS = "ABCDEFGHJ"  # r^4 ... r^20
_IGNORED = set(
    """LEN WTF VUY VLY VUX VLX INI DER CCY THC GLC CUF KC AC BC CC DC EC FC GC HC
    JC POL CLS TOL TOLE AUT SAV DES""".split()
)
_DECENTER = {"ADE", "BDE", "CDE", "XDE", "YDE", "ZDE"}
_DECENTER_TYPES = {"DEC": "basic", "DAR": "dar", "BEN": "bend", "REV": "rev"}
_APERTURES = {"CIR", "REX", "REY", "ELX", "ELY", "ADX", "ADY"}
#: commands refused (at their line, naming the surface before them), and why
_RELATIVE = (
    "coordinates relative to another surface are not supported; in CODE V convert the decenters "
    "to DEC/DAR/BEN/REV form (local to each surface) and save the .seq again"
)
_SPECIAL = (
    "diffractive, gradient-index and special surfaces are not supported; orthoscope reads "
    "spheres, conics and even aspheres (ASP with K, A, B, C, D ...)"
)
_ANAMORPHIC = (
    "anamorphic surfaces (an x curvature, cylinders, toroids) are not supported; orthoscope "
    "reads rotationally symmetric surfaces"
)
_REFUSED = (
    dict.fromkeys(("RET", "GLB", "TILT"), _RELATIVE)
    | dict.fromkeys(
        ("DIF", "HOE", "HCO", "HWL", "HOR", "GRT", "SPS", "UDS", "GRIN", "GRD", "ZRN"), _SPECIAL
    )
    | dict.fromkeys(("RDX", "CUX", "CYL", "XTO", "YTO"), _ANAMORPHIC)
)
#: commands that set a surface value; with a solve type (``THI HMY 0``, ``CUY UMY -0.1``) they
#: are solves whose result CODE V wrote on the surface line (kept, with a note); with a surface
#: (``THI S5 20``) or a value they change the lens after its surface lines (refused)
_SURFACE_SETTERS = {"THI", "RDY", "CUY", "GLA", "INS", "DEL"}


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
    dec: dict[str, tuple[float, int]] = field(default_factory=dict)  # XDE ... CDE -> (value, line)
    dtype: str = "basic"
    refl: bool = False
    ap: dict[str, float] = field(default_factory=dict)  # REX REY ELX ELY ADX ADY


def _ends_continued(text: str) -> bool:
    """True when the last line that holds a command (comments removed) ends with ``&``."""
    for raw in reversed(text.split("\n")):
        body = raw.split("!", 1)[0].strip()
        if body:
            return body.endswith("&")
    return False


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


class _SeqParser(LineParser):
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
        self.pickups: list[tuple[list[str], int]] = []
        self.si_thickness: tuple[float, int] | None = None  # THI SI v (a defocus)
        rdm_seen = False
        self.go_line = 0
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
                self.go_line = line
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
                v = self.num(args, 0, "REF", line)
                if v != int(v):
                    raise self.err(
                        f"REF {args[0][:20]}: expected the whole number of a WL wavelength "
                        "(REF 1 is the first)",
                        line,
                    )
                h["REF"] = (int(v), line)
            elif cmd in ("ZOO", "ZOOM"):
                if "ZOO" not in h:
                    h["ZOO"] = line
                    self.warn(
                        f"line {line}: ZOO: zoom data; the base lens is read, its thickness "
                        "positions by raytrace.files.configurations.read_configured"
                    )
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
                h.setdefault("IMF", {})[cmd] = (self.nums(args, cmd, line), line)
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
                    if kind == "SO":  # CODE V writes 1e10 or more; "inf" is accepted too
                        cur.t = number(args[1], cmd, self.fail, line, allow_inf=True)
                    else:
                        cur.t = self.num(args, 1, cmd, line)
                    if kind == "SO" and cur.t >= CODEV_INFINITY:
                        cur.t = math.inf
                rest = [a for a in args[2:] if a.upper() not in ("REFL", "REFLECT")]
                cur.refl = len(rest) < len(args[2:])
                if cur.refl and kind != "S":
                    raise self.err(f"REFL on {cmd}: only a lens surface (S) can be a mirror", line)
                if cur.refl and rest:
                    raise self.err(
                        f"REFL with a glass ({rest[0]}): a mirror returns the light into the "
                        "medium "
                        "before it; write the glass on the surfaces around the mirror",
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
            elif (
                cmd in ("SLB", "ASP", "CON", "SPH", "K", "PIM")
                or cmd in _APERTURES
                or (cmd in _ASPH_LETTERS and len(cmd) == 1)
            ):
                if cur is None:
                    raise self.err(f"{cmd} before the first surface line", line)
                self.surface_command(cur, cmd, args, line, len(surfs) - 1)
            elif cmd in _DECENTER or cmd in _DECENTER_TYPES:
                if cur is None or cur.kind == "SO":
                    raise self.err(
                        f"{cmd}: a decenter or tilt of the object surface is not supported; "
                        "decenter the first lens surface instead",
                        line,
                    )
                if cmd in _DECENTER:
                    cur.dec[cmd] = (self.num(args, 0, cmd, line), line)
                else:
                    if cur.kind == "SI" and cmd != "DEC":
                        raise self.err(f"{cmd} on the image surface (SI) has no meaning", line)
                    cur.dtype = _DECENTER_TYPES[cmd]
            elif cmd in _REFUSED:
                raise self.err(f"{cmd}: {_REFUSED[cmd]}", line, max(len(surfs) - 1, 0) or None)
            elif cmd in _SURFACE_SETTERS:
                self.surface_setter(cmd, args, line, len(surfs) - 1)
            elif cmd in ("REFL", "REFLECT"):
                if cur is None or cur.kind != "S":
                    raise self.err("REFL must follow a lens surface line (S r t)", line)
                if cur.glass is not None:
                    raise self.err(
                        "REFL on a surface with a glass: a mirror returns the light into the "
                        "medium before it",
                        line,
                    )
                cur.refl = True
            elif cmd == "PIK":
                self.pickups.append((toks, line))
            elif cmd in _IGNORED:
                pass
            else:
                self.unknown.setdefault(cmd[:20], line)
        self.check_complete(surfs, h, xan, yan, xob, yob, in_prv)
        if not rdm_seen:
            self.check_radius_mode([s for s in surfs if s.kind == "S"])
            self.warn("no RDM line: surface values are read as radii (RDM Y, CODE V's default)")
        return self.build(surfs, h, xan, yan, xob, yob)

    def check_radius_mode(self, body: list[_CSurf]) -> None:
        """Without an RDM line the values are radii (CODE V's default); refuse a file whose
        values, read so, give a radius a fifth or less of the glass or air beside it while read
        as curvatures they give none (rayoptics writes curvatures without RDM N)."""

        def tiny(radius_of) -> tuple[_CSurf, float, float] | None:
            for k, srf in enumerate(body):
                r = radius_of(srf)
                beside = [abs(t) for t in ([body[k - 1].t] if k else []) + [srf.t]]
                t = max([x for x in beside if math.isfinite(x)], default=0.0)
                if r != 0.0 and abs(r) <= t / 5.0:
                    return srf, r, t
            return None

        found = tiny(lambda srf: srf.r)
        if found and not tiny(lambda srf: 1.0 / srf.r if srf.r else 0.0):
            srf, r, t = found
            raise self.err(
                f"no RDM line, so the value {r:g} is a radius (CODE V's default), beside a "
                f"thickness of {t:g}: the values look like curvatures; add 'RDM N' to the file "
                "if they are curvatures (or 'RDM Y' if they really are radii)",
                srf.line,
            )

    def surface_setter(self, cmd: str, args: list[str], line: int, surface: int) -> None:
        """THI / RDY / CUY / GLA / INS / DEL: a solve (its stored result is used, said in a
        warning) or a change of the lens by command (refused)."""
        first = args[0].upper() if args else ""
        if cmd == "THI" and first == "SI" and len(args) == 2:  # CODE V's usual way to defocus
            self.si_thickness = (self.num(args, 1, cmd, line), line)
            return
        if first and first.isalpha() and cmd in ("THI", "RDY", "CUY") and first not in ("SO", "SI"):
            self.warn(
                f"line {line}: {cmd} {first} (a solve) not re-solved: the value on the surface "
                "line (CODE V's result when it saved the file) is used"
            )
            return
        raise self.err(
            f"{cmd} {' '.join(args)}: a surface changed by a command is not supported; write "
            "the value on the surface line (S r t glass) and save the file again",
            line,
            max(surface, 0) or None,
        )

    def check_complete(self, surfs, h, xan, yan, xob, yob, in_prv: bool) -> None:
        """Refuse a truncated file (a cut file must not read as a shorter lens).

        CODE V ends a sequence with ``GO`` (every file CODE V writes; in tests/data/corpus the
        files of CODE V and opticspy): with ``GO`` read, the lens is complete. Without it (files
        written by hand or by other programs), the file must hold its image surface ``SI``, an
        aperture, a field and a wavelength, a ``PRV`` block must be closed by ``END``, and the
        last line must not be continued with ``&``. Not detectable without ``GO``: a cut after
        ``SI`` that leaves the aperture, field and wavelength lines but drops later optional
        ones (``REF``, ``WTW``, an ``XAN`` line after ``YAN``), and a cut inside the
        last line that leaves a valid shorter number or list (``WL 650 550 450`` → ``WL 650
        55``)."""
        if self.go_line:
            return
        last_line = len(self.text.rstrip().split("\n"))
        missing = []
        if in_prv:
            missing.append("the END of its PRV block")
        if _ends_continued(self.text):
            missing.append("the rest of its last line (it ends with '&')")
        if not surfs or surfs[-1].kind != "SI":
            missing.append("the image surface SI")
        if "APER" not in h:
            missing.append("an aperture (EPD, FNO or NAO)")
        if not (xan or yan or xob or yob or h.get("IMF")):
            missing.append("a field (YAN, YOB, YIM ...)")
        elif (xan and not yan) or (xob and not yob):
            missing.append("the y field (YAN / YOB) that goes with its XAN / XOB")
        if "WL" not in h:
            missing.append("a wavelength (WL)")
        if missing:
            raise self.err(
                f"the file ends at line {last_line} without GO and without "
                f"{'; '.join(missing)}: it looks truncated (or is not a CODE V sequence file); "
                "use the complete file (CODE V writes GO at the end of a sequence)",
                last_line,
            )

    def surface_command(self, cur: _CSurf, cmd: str, args: list[str], line: int, no: int):
        if cmd == "SLB":
            cur.label = " ".join(_unquote(a) for a in args)
        elif cmd in _APERTURES:
            if args and args[0].upper() in ("EDG", "HOL", "OBS"):
                if args[0].upper() != "EDG":
                    self.warn(f"line {line}: {cmd} {args[0]} (hole/obscuration) ignored")
                return
            vals = [a for a in args if not (a[:1] in "'\"" or a.upper().startswith("L'"))]
            r = self.num(vals, 0, cmd, line)
            if cmd == "CIR":
                if not r > 0.0:
                    raise self.err(f"CIR: the aperture radius must be positive, got {r}", line, no)
                cur.cir = r
            elif cmd in ("ADX", "ADY"):
                cur.ap[cmd] = r
            else:
                if not r > 0.0:
                    raise self.err(f"{cmd}: the aperture half-width must be positive, got {r}",
                                   line, no)  # fmt: skip
                cur.ap[cmd] = r
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
        try:  # a code outside raytrace.materials.INDEX_RANGE / ABBE_RANGE: ValueError
            code = parse_glass_code(name)
            if code is not None:
                return code
            r = resolve_glass(name)
        except PrescriptionError as e:
            raise self.err(f"glass {name}: {e.reason}", line, no) from None
        except ValueError as e:
            raise self.err(f"glass {name}: {e}", line, no) from None
        if r.warning:
            self.warn(f"line {line}: {r.warning}")
        return r.material

    def object_material(self, obj: _CSurf) -> Material:
        return self.material(obj.glass, 0) if obj.glass else AIR

    def placement(self, s: _CSurf, scale: float) -> tuple[Placement | None, Placement | str]:
        """(placement, after) of a surface's XDE ... CDE and decenter type
        (:mod:`raytrace.frames`: CODE V α, β are left-handed, γ right-handed)."""
        if not s.dec:
            return None, "stay"

        def v(key):
            return s.dec.get(key, (0.0, 0))[0]

        p = Placement(
            (v("XDE") * scale, v("YDE") * scale, v("ZDE") * scale),
            codev_tilt(v("ADE"), v("BDE"), v("CDE")),
            "decenter-tilt",
        )
        if s.dtype == "dar":
            return p, "return"
        if s.dtype == "bend":
            return p, "bend"
        if s.dtype == "rev":
            return None, p.inverse()
        return p, "stay"

    def aperture(self, s: _CSurf, scale: float, no: int) -> tuple[float, ClearAperture | None]:
        """(semi-diameter, clear aperture) of CIR / REX REY / ELX ELY with ADX ADY."""
        a = s.ap
        x0 = a.get("ADX", 0.0) * scale
        y0 = a.get("ADY", 0.0) * scale
        rect = "REX" in a or "REY" in a
        ell = "ELX" in a or "ELY" in a
        if rect and ell:
            raise self.err(
                "REX/REY and ELX/ELY on one surface: give one aperture shape", s.line, no
            )
        if rect or ell:
            kx, ky = ("REX", "REY") if rect else ("ELX", "ELY")
            hx = a.get(kx, a.get(ky))
            hy = a.get(ky, a.get(kx))
            shape = "rectangle" if rect else "ellipse"
            return s.cir * scale, ClearAperture(shape, hx * scale, hy * scale, x0, y0)
        if (x0 or y0) and math.isfinite(s.cir):
            r = s.cir * scale
            return math.inf, ClearAperture("circle", r, r, x0, y0)
        return s.cir * scale, None

    def check_pickups(self, surfs: list[_CSurf], scale: float, radius_mode: bool) -> None:
        """CODE V stores picked-up values in the surface lines: check each ``PIK`` against them
        (module docstring) and refuse one that disagrees."""

        def value(item: str, k: int, line: int) -> float:
            if not 0 <= k < len(surfs):
                raise self.err(f"PIK: there is no surface S{k}", line)
            srf = surfs[k]
            if item == "THI":
                return srf.t * scale if math.isfinite(srf.t) else srf.t
            c = 0.0 if srf.r == 0.0 else (1.0 / (srf.r * scale) if radius_mode else srf.r / scale)
            if item == "CUY":
                return c
            return math.inf if c == 0.0 else 1.0 / c

        for toks, line in self.pickups:
            t = [x.upper() for x in toks[1:] if not (x[:1] in "Zz" and x[1:].isdigit())]
            try:
                item, tgt, item2, src = t[0], t[1], t[2], t[3]
                nums = [float(x) for x in t[4:]]
                kt, ks = int(tgt.lstrip("S") or 0), int(src.lstrip("S") or 0)
            except (IndexError, ValueError):
                raise self.err(
                    f"PIK {' '.join(toks[1:])[:40]}: expected 'PIK item Sk item Sj [scale "
                    "[offset]]'",
                    line,
                ) from None
            if item not in ("RDY", "CUY", "THI") or item2 != item:
                raise self.err(
                    f"PIK {item}: pickups are not supported (only RDY, CUY, THI pickups are "
                    "checked); in CODE V freeze the pickups and save the .seq again",
                    line,
                )
            scale_k = nums[0] if nums else 1.0
            offset = nums[1] if len(nums) > 1 else 0.0
            want = scale_k * value(item, ks, line) + offset * (scale if item == "THI" else 1.0)
            have = value(item, kt, line)
            if not (want == have or abs(want - have) <= 1e-9 * max(1.0, abs(want))):
                raise self.err(
                    f"PIK {item} S{kt}: the picked-up value {want:.10g} differs from the stored "
                    f"{have:.10g}; in CODE V freeze the pickups and save the .seq again",
                    line,
                )

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
            before = self.object_material(obj) if not out else out[-1].material
            mat = before if s.refl else self.material(s.glass, k)
            placement, after = self.placement(s, scale)
            sd, aperture = self.aperture(s, scale, k)
            out.append(
                Surface(
                    curvature=c,
                    thickness=s.t * scale,
                    material=mat,
                    semi_diameter=sd,
                    stop=s.stop or (not stops and k == 1),
                    conic=s.conic,
                    aspheric=asph,
                    label=s.label,
                    line=s.line,
                    placement=placement,
                    after=after,
                    mirror=s.refl,
                    aperture=aperture,
                )
            )
        image_placement = None
        if img is not None and img.dec:
            image_placement, _ = self.placement(img, scale)
        if img is not None and img.pim is not None:
            self.warn(f"line {img.pim}: PIM on the image surface (SI) ignored")
        self.check_pickups(surfs, scale, radius_mode)
        pims = [s for s in body if s.pim is not None]
        early = [s for s in pims if s is not body[-1]]
        if early:
            raise self.err("PIM (paraxial image solve) only on the last surface", early[0].pim)
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
        pts = tuple(
            (xv[i] if i < len(xv) else 0.0, yv[i] if i < len(yv) else 0.0)
            for i in range(max(len(xv), len(yv)))
        )
        imf = h.get("IMF")
        image_field = None
        if imf and not (xob or yob or xan or yan):
            image_field = self.image_field(imf, scale)
        elif imf:
            self.warn("image-height fields (YIM/YRI) ignored: the object-space field is used")
        if not radial and image_field is None:
            self.warn("no field (YAN/YOB): the field is 0")
        if image_field is not None:
            fld = Field("height" if math.isfinite(od) else "angle", 0.0)
        elif kind == "angle":
            if fmax >= 90.0:
                raise self.err(f"field angle {fmax:g} deg: must be below 90", fline)
            fld = Field("angle", fmax, pts)
        else:
            if math.isinf(od):
                raise self.err("YOB: object heights need a finite object distance (SO)", fline)
            fld = Field("height", fmax * scale, tuple((a * scale, b * scale) for a, b in pts))
        self.warn_unknown()
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
            object_material=self.object_material(obj),
            image_placement=image_placement,
            path=self.path,
        )
        lines = [s.line for s in body]
        lens = self.file_lens(lines, obj.line, **kw)
        if pims:
            if lens.is_centred:
                lens = self.solve_image(lens, pims[-1].pim, lines)
            else:
                self.warn(
                    f"line {pims[-1].pim}: PIM on a decentered or tilted lens: the stored image "
                    "distance is used (paraxial solves need a centred lens)"
                )
        if img is not None and self.si_thickness is not None:
            img.t = self.si_thickness[0]  # THI SI v: the same as the value on the SI line
        if img is not None and img.t != 0.0:  # CODE V: the image surface's thickness defocuses
            if img.dec:
                self.warn(
                    f"line {img.line}: SI thickness {img.t:g} (CODE V's defocus) on a decentered "
                    "image surface is not applied: the image surface is where the last "
                    "thickness and the decenter put it"
                )
            else:
                lens = lens.with_image_distance(lens.surfaces[-1].thickness + img.t * scale)
        if image_field is not None:
            lens = self.convert_image_field(lens, image_field, lines)
        return ImportResult(lens, tuple(self.warnings))

    def image_field(self, imf: dict, scale: float) -> tuple[str, float, int]:
        """(kind, largest radial image height mm, line) of YIM/XIM or YRI/XRI."""
        paraxial_f = "YIM" in imf or "XIM" in imf
        real_f = "YRI" in imf or "XRI" in imf
        if paraxial_f and real_f:
            line = max(v[1] for v in imf.values())
            raise self.err("both paraxial (YIM) and real (YRI) image heights: give one", line)
        kx, ky = ("XIM", "YIM") if paraxial_f else ("XRI", "YRI")
        xv, line_x = imf.get(kx, ([], 0))
        yv, line_y = imf.get(ky, ([], 0))
        hmax = max(
            (math.hypot(xv[i] if i < len(xv) else 0.0, yv[i] if i < len(yv) else 0.0)
             for i in range(max(len(xv), len(yv)))),
            default=0.0,
        )  # fmt: skip
        kind = "paraxial_image_height" if paraxial_f else "real_image_height"
        return kind, hmax * scale, max(line_x, line_y)

    def convert_image_field(self, lens: Lens, image_field, lines: list[int]) -> Lens:
        from ..trace.image_field import field_for_image_height

        kind, height, line = image_field
        try:
            fld = field_for_image_height(lens, height, kind)
        except (LensError, ValueError) as e:
            cmd = "YIM" if kind.startswith("paraxial") else "YRI"
            raise self.err(f"{cmd} {height:g}: {e}", line) from None
        return replace(lens, field=fld)

    def solve_image(self, lens: Lens, line: int, lines: list[int]) -> Lens:
        return solve_paraxial_image(
            lens,
            self.err,
            lines,
            line,
            lambda d: (
                f"PIM: the paraxial image is {'at infinity' if not math.isfinite(d) else 'virtual'}"
                "; give the image distance as the last thickness instead"
            ),
        )


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
