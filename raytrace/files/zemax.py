"""Zemax OpticStudio ``.zmx`` files: read (ASCII, UTF-8 or UTF-16) and write.

Reading (:func:`read_zmx`, :func:`loads_zmx`, :func:`parse_zmx`) supports a sequential lens made
of ``STANDARD``, ``EVENASPH`` and ``QED_TYPE`` (Q-type asphere) surfaces, coordinate breaks and
mirrors:

* ``SURF n`` blocks in order; surface 0 is the object, the last one the image, the ones between
  are the lens. ``CURV`` (curvature, 1/lens unit), ``DISZ`` (thickness to the next vertex;
  ``INFINITY`` or ≥ 1e10 on surface 0 = object at infinity), ``CONI``, ``STOP``, ``COMM``
  (label), ``GLAS``, ``DIAM`` (semi-diameter, despite the name: a *fixed* one — solve flag 1 —
  clips rays; an automatic one — flag 0 — only reports what the rays need and does not clip),
  ``CLAP 0 r`` (circular aperture, clips at r).
* ``EVENASPH``: Zemax's sag is ``c r²/(1+√(1−(1+k)c²r²)) + α1 r² + α2 r⁴ + … + α8 r¹⁶`` in lens
  units (not normalized), with ``PARM i`` = αi. So ``PARM 2`` = A4, ``PARM 3`` = A6, …,
  ``PARM 8`` = A16. ``PARM 1`` (the r² term) must be 0: orthoscope models r⁴ and higher only.
* ``QED_TYPE`` (OpticStudio's Q-type asphere, :mod:`raytrace.qtype`): the Qbfs form on the
  base conic (``CURV``, ``CONI``), its parameters in the extra data: ``XDAT 1`` = 0 (the only
  value read: every Q-type file we have holds 0, and its Qbfs reading is confirmed by the
  Thorlabs ASL5040-UV file, tests/test_qtype.py; another value is refused), ``XDAT 2`` = the
  number of terms n, ``XDAT 3`` = the normalization radius ρ_max, ``XDAT 4 .. 3+n`` = a_0 ..
  a_(n−1) (lens units). A ``PARM`` on it is refused (no file here shows one).
* The image surface's ``DISZ`` is irrelevant: the last lens surface's ``DISZ`` is the image
  distance. A curved image surface is reported and read as flat.
* ``GLAS``: ``GLAS ___BLANK 1 0 nd vd dPgF …`` (a model glass; fields 4 and 5 after the command
  are nd and vd; vd = 0 means a non-dispersive index, as in OpticStudio) or a catalog name
  (``GLAS N-BK7 0 0 1.5 40 …`` — OpticStudio stores placeholder numbers for catalog glasses, so
  they are NOT used): the name is resolved through :mod:`raytrace.glass`, the ``GCAT`` catalogs
  first (first one that has it wins, as in OpticStudio).
* Geometry (:mod:`raytrace.frames` states the conventions): ``TYPE COORDBRK`` (``PARM 1..6`` =
  decenter x, y, tilt about x, y, z in degrees, order flag; its ``DISZ`` runs in the new frame)
  becomes a coordinate-break surface; the surface Tilt/Decenter tab ``SCBD 1 order 0 dx dy tx ty
  tz`` (before the surface) and ``SCBD 2 order 0 dx dy tx ty tz`` (after it, explicit values)
  becomes the surface's placement and ``after``; on the image surface it places the image plane.
  ``GLAS MIRROR`` makes the surface a mirror (the medium after it is the one before; thicknesses
  after an odd number of mirrors are negative, as OpticStudio writes them).
* Clear apertures: ``CLAP rmin r`` (circular; an annular minimum radius is ignored with a
  warning), ``SQAP hx hy`` (rectangular), ``ELAP a b`` (elliptical), moved by ``OBDC x y``
  (aperture decenter; then the surface's semi-diameter does not clip: the aperture is the
  off-axis section). ``OBSC`` (obscuration) and other vignetting apertures are ignored with a
  warning.
* Aperture: ``ENPD`` (entrance-pupil diameter), ``FNUM x 0`` (image-space F/#, EFL/EPD for an
  infinite conjugate = orthoscope's f-number), ``FNUM x 1`` (paraxial working F/#), ``OBNA x 0``
  (object-space NA), ``OBNA x 1`` (object cone angle, degrees), ``FLOA`` (float by stop size:
  the stop's semi-diameter ``DIAM`` sets the pupil). Field: ``FTYP t`` with t = 0 (angle,
  degrees), 1 (object height), 2 (paraxial image height) or 3 (real image height; both turned
  into the object-space field that gives them, ``Field.given`` keeps the original); the field
  values are ``XFLN``/``YFLN`` (or the older ``XFLD``/``YFLD``), of which the first
  ``FTYP``-count are used (``Field.points``); the lens's field is the largest radial value
  √(x² + y²). Wavelength: ``WAVM i λ w`` (or ``WAVL λ1 λ2 …``) in µm and ``PWAV i`` (the
  primary) → nm.
* ``UNIT MM|CM|IN|M``: lengths are converted to mm.

Solves (``PZUP``, solve fields on ``CURV``/``DISZ``) are ignored: OpticStudio stores the solved
values, which are read. Display, tolerance, coating and merit-function commands are skipped.
Other unknown commands are reported in one :class:`InteropWarning`. Anything that would change
the optics and cannot be modelled (non-sequential mode, other surface types such as gratings,
toroids and freeforms, gradient index, the r² term, a tilt/decenter mode other than explicit
where the order matters) raises :class:`~raytrace.errors.PrescriptionError` with the file, line
and what to do.
Every problem with the input raises PrescriptionError (never another exception type). A file cut
short is refused, never read as a shorter lens (:meth:`_ZmxParser.check_complete` says what is
checked and what cannot be detected; lenses/INTEROP.md, "Truncated files").

Writing (:func:`dumps_zmx`, :func:`write_zmx`) produces a sequential file OpticStudio reads, with
every number at full float64 precision (``repr``), model glasses, fixed semi-diameters, and the
orthoscope fields Zemax has no place for (source, notes, the Gaussian image solve) in
``NOTE 0 orthoscope.<key>: <json>`` lines, so that native → .zmx → native is exact. Catalog
glasses are written by name with a ``GCAT`` line whose catalog order makes every name resolve to
its own catalog under the first-catalog-wins rule above (:func:`_gcat`; refused when no order
does).
"""

from __future__ import annotations

import codecs
import json
import math
from dataclasses import dataclass, field, replace
from pathlib import Path

from ..errors import LensError, PrescriptionError
from ..frames import ORDERS, Placement
from ..glass import parse_glass_code, printed_nd_vd, resolve_glass
from ..lens import Aperture, ClearAperture, Field, Lens, Surface
from ..materials import AIR, LAMBDA_D, Material, fixed_index, model_glass
from ..qtype import QType
from .output import check_reads_back, write_atomic
from .text import (
    ImportResult,
    LineParser,
    emit_warnings,
    guarded_parse,
    micron_to_nm,
    nm_to_micron_text,
    number,
    read_bytes,
)

#: Zemax stores an object at infinity as ``DISZ INFINITY`` and treats ≥ 1e10 as infinite.
ZEMAX_INFINITY = 1.0e10

_UNITS = {"MM": 1.0, "CM": 10.0, "IN": 25.4, "M": 1000.0, "METER": 1000.0, "METR": 1000.0}


# --------------------------------------------------------------------------------------------
# Reader
# --------------------------------------------------------------------------------------------

# Commands skipped silently: display, reporting, tolerancing, coating, merit function, solves
# (the solved value is stored), configuration bookkeeping, non-optical metadata.
_IGNORED_GLOBAL = set(
    """VERS PFIL LANG GFAC RAIM PUSH SDMA ROPD PICB FWGN FWGT VDXN VDYN VCXN VCYN VANN
    POLS GLRS GSTD NSCD COFN TOL TOLE MOFF BLNK TRAC OPDX HYPR EFLY DMFS OMMA OEMA RCMF AUTH
    DBDT WAVN XFIE PUCN TCMM TOTR FLAN WFAN SSOB SGLI ZVDX ZVDY ZVCX ZVCY ZVAN PMAG
    MAZH TCED WFNO THIC""".split()
)
# THIC: a multi-configuration thickness row (raytrace.files.configurations reads those)
# WFNO is a merit-function / default-merit setting line (``WFNO 0 0 0 ...``), not an aperture:
# the aperture is ENPD, FNUM (flag 0 image-space F/#, 1 paraxial working F/#), OBNA (flag 0 NA,
# 1 object cone angle) or FLOA (float by stop size).
_IGNORED_SURFACE = set(
    """HIDE MIRR SLAB POPS VDSZ FLAP MEMA FIMP COAT PZUP PPAR VPAR VCON EDGE UDAD USAP BLNK
    TCED CDCS DCPM THMP""".split()
)
_VIGNETTING = {"OBSC", "UDAP", "RBAP", "SPID"}
_APERTURE_CMDS = {"SQAP", "ELAP", "OBDC"}
_TILTS = {"DECX", "DECY", "TILX", "TILY", "TILZ", "TILT", "SCBD"}
_SURF_CMDS = (
    {"TYPE", "CURV", "DISZ", "DIAM", "CONI", "PARM", "GLAS", "STOP", "COMM", "CLAP", "XDAT"}
    | _IGNORED_SURFACE
    | _VIGNETTING
    | _APERTURE_CMDS
    | _TILTS
)


@dataclass
class _ZSurf:
    number: int
    line: int
    type: str = "STANDARD"
    type_line: int = 0
    curv: float = 0.0
    curv_line: int = 0
    disz: float = 0.0
    disz_line: int = 0
    diam: float = 0.0
    diam_fixed: bool = False
    diam_line: int = 0
    clap: float = math.inf
    coni: float = 0.0
    parm: dict[int, tuple[float, int]] = field(default_factory=dict)
    xdat: dict[int, tuple[float, int]] = field(default_factory=dict)
    glas: tuple[list[str], int] | None = None
    stop: bool = False
    comm: str = ""
    mirror: bool = False
    scbd: dict[int, tuple[list[float], int]] = field(default_factory=dict)
    sqap: tuple[float, float] | None = None
    elap: tuple[float, float] | None = None
    obdc: tuple[float, float] = (0.0, 0.0)
    ap_line: int = 0
    cmds: list[str] = field(default_factory=list)  # the block's commands in order


class _ZmxParser(LineParser):
    ITEM = "field"

    def integer(self, args: list[str], i: int, cmd: str, line: int) -> int:
        v = self.num(args, i, cmd, line)
        if v != int(v) or abs(v) > 1e6:
            raise self.err(f"{cmd}: expected a whole number, got {args[i][:40]!r}", line)
        return int(v)

    # ------------------------------------------------------------------------------------
    def parse(self) -> ImportResult:
        lines = self.text.split("\n")
        if not self.text.strip():
            raise self.err("the file is empty: expected a Zemax .zmx lens file", 1)
        surfaces: list[_ZSurf] = []
        cur: _ZSurf | None = None
        h: dict[str, tuple] = {}
        notes_meta: dict[str, str] = {}
        plain_notes: list[str] = []
        xfln: tuple[list[float], int] | None = None
        yfln: tuple[list[float], int] | None = None
        wavm: dict[int, tuple[float, int]] = {}
        wavl: tuple[list[float], int] | None = None
        gcat: list[str] = []
        self.after_surfaces = 0  # first top-level line after the last SURF block (0: none)
        for lineno, raw in enumerate(lines, start=1):
            s = raw.strip().lstrip("\ufeff")
            if not s:
                continue
            parts = s.split()
            cmd = parts[0].upper()
            args = parts[1:]
            rest = s[len(parts[0]) :].strip()
            if surfaces and not self.after_surfaces and cmd != "SURF":
                if cmd in _SURF_CMDS or raw[:1].isspace():
                    surfaces[-1].cmds.append(cmd)
                else:  # surface data is indented, the sections after the surfaces are not
                    self.after_surfaces = lineno
            if cmd == "SURF":
                self.after_surfaces = 0
                n = self.integer(args, 0, "SURF", lineno)
                expected = len(surfaces)
                if n != expected:
                    raise self.err(
                        f"SURF {n} out of order: expected SURF {expected} (surfaces must be "
                        "numbered 0, 1, 2, ... in order)",
                        lineno,
                    )
                if n > 10000:
                    raise self.err("more than 10000 surfaces", lineno)
                cur = _ZSurf(number=n, line=lineno, type_line=lineno)
                surfaces.append(cur)
                continue
            if cmd in _SURF_CMDS:
                if cur is None:
                    raise self.err(
                        f"{cmd} before the first SURF line: surface data must follow a "
                        "'SURF n' line",
                        lineno,
                    )
                self.surface_command(cur, cmd, args, rest, lineno)
                continue
            # ---- global commands
            if cmd == "MODE":
                mode = args[0].upper() if args else ""
                if mode != "SEQ":
                    raise self.err(
                        f"MODE {mode or '(none)'}: only sequential lenses (MODE SEQ) can be "
                        "read; non-sequential files are not supported — export the sequential "
                        "part of the system from OpticStudio",
                        lineno,
                    )
            elif cmd == "NAME":
                h["NAME"] = (rest, lineno)
            elif cmd == "NOTE":
                text = rest.split(None, 1)[1] if len(rest.split(None, 1)) > 1 else ""
                if text.startswith("orthoscope.") and ":" in text:
                    key, _, val = text.partition(":")
                    notes_meta[key[len("orthoscope.") :].strip()] = val.strip()
                elif text.strip():
                    plain_notes.append(text.rstrip())
            elif cmd == "UNIT":
                u = args[0].upper() if args else ""
                if u not in _UNITS:
                    raise self.err(
                        f"UNIT {u or '(none)'}: unknown lens unit (MM, CM, IN or M expected)",
                        lineno,
                    )
                h["UNIT"] = (_UNITS[u], lineno)
            elif cmd in ("FNUM", "OBNA") and len(args) > 1 and args[1] not in ("0", "0.0"):
                flag = self.integer(args, 1, cmd, lineno)
                if flag != 1:
                    raise self.err(f"{cmd} {' '.join(args[:2])}: unknown aperture flag", lineno)
                key = "WFNO" if cmd == "FNUM" else "OBCA"  # working F/#, object cone angle
                h["APER"] = (key, self.num(args, 0, cmd, lineno), lineno)
            elif cmd in ("ENPD", "FNUM", "OBNA"):
                h["APER"] = (cmd, self.num(args, 0, cmd, lineno), lineno)
            elif cmd == "FLOA":
                h["APER"] = ("FLOA", math.nan, lineno)
            elif cmd in ("OBCA", "PWFN"):
                meaning = {
                    "OBCA": "object cone angle",
                    "PWFN": "paraxial working F/#",
                }[cmd]
                raise self.err(
                    f"{cmd}: aperture type '{meaning}' is not supported; in OpticStudio set the "
                    "system aperture to Entrance Pupil Diameter (ENPD), Image Space F/# (FNUM) "
                    "or Object Space NA (OBNA) and save again",
                    lineno,
                )
            elif cmd == "FTYP":
                ft = self.integer(args, 0, "FTYP", lineno)
                nf = self.integer(args, 2, "FTYP", lineno) if len(args) > 2 else None
                nw = self.integer(args, 3, "FTYP", lineno) if len(args) > 3 else None
                h["FTYP"] = (ft, nf, nw, lineno)
            elif cmd in ("XFLN", "XFLD"):
                xfln = ([self.num(args, i, cmd, lineno) for i in range(len(args))], lineno)
            elif cmd in ("YFLN", "YFLD"):
                yfln = ([self.num(args, i, cmd, lineno) for i in range(len(args))], lineno)
            elif cmd == "WAVM":
                i = self.integer(args, 0, "WAVM", lineno)
                if len(args) < 2:
                    raise self.err("WAVM needs 'WAVM index wavelength_um weight'", lineno)
                w = self.num(args, 2, "WAVM weight", lineno) if len(args) > 2 else 1.0
                wavm[i] = (micron_to_nm(args[1], self.fail, lineno, "WAVM"), w, lineno)
            elif cmd == "WAVL":
                wavl = (
                    [micron_to_nm(a, self.fail, lineno, "WAVL") for a in args],
                    lineno,
                )
            elif cmd == "WWGT":
                h["WWGT"] = ([self.num(args, i, "WWGT", lineno) for i in range(len(args))], lineno)
            elif cmd == "ENVD":
                t = self.num(args, 0, "ENVD temperature", lineno)
                pr = self.num(args, 1, "ENVD pressure", lineno) if len(args) > 1 else 1.0
                h["ENVD"] = (t, pr, lineno)
            elif cmd == "PWAV":
                h["PWAV"] = (self.integer(args, 0, "PWAV", lineno), lineno)
            elif cmd == "GCAT":
                gcat = list(args)
            elif cmd == "MNUM":
                n = self.integer(args, 0, "MNUM", lineno)
                if n > 1:
                    self.warn(
                        f"line {lineno}: MNUM {n}: a multi-configuration file; the surface "
                        "data are read as the base lens, its thickness configurations by "
                        "raytrace.files.configurations.read_configured"
                    )
            elif cmd == "CONF":
                self.warn(f"line {lineno}: CONF: multi-configuration data ignored")
            elif cmd.startswith("NSO"):
                raise self.err(
                    f"{cmd}: non-sequential objects are not supported; orthoscope reads "
                    "sequential lenses only",
                    lineno,
                )
            elif cmd in _IGNORED_GLOBAL:
                pass
            else:
                self.unknown.setdefault(cmd[:20], lineno)
        return self.build(surfaces, h, notes_meta, plain_notes, xfln, yfln, wavm, wavl, gcat)

    # ------------------------------------------------------------------------------------
    def surface_command(self, cur: _ZSurf, cmd: str, args: list[str], rest: str, line: int):
        no = cur.number
        if cmd == "TYPE":
            t = args[0].upper() if args else ""
            if t in ("STANDARD", "EVENASPH", "COORDBRK", "QED_TYPE"):
                cur.type, cur.type_line = t, line
                return
            hint = ""
            if "GRIN" in t or "GRAD" in t:
                hint = " (gradient-index media are not supported)"
            raise self.err(
                f"TYPE {t or '(none)'}: unsupported surface type{hint}; orthoscope reads "
                "STANDARD, EVENASPH and QED_TYPE (Q-type) surfaces only — convert the surface in "
                "OpticStudio (e.g. an even asphere without the r² term) or replace it by a "
                "standard surface",
                line,
                no,
            )
        if cmd == "CURV":
            cur.curv, cur.curv_line = self.num(args, 0, "CURV", line), line
        elif cmd == "DISZ":
            cur.disz = self.num(args, 0, "DISZ", line, allow_inf=True)
            cur.disz_line = line
            if math.isinf(cur.disz) and cur.number > 0:
                raise self.err("DISZ INFINITY is only allowed on the object surface", line, no)
        elif cmd == "DIAM":
            cur.diam = self.num(args, 0, "DIAM", line)
            flag = self.integer(args, 1, "DIAM", line) if len(args) > 1 else 0
            cur.diam_fixed = flag != 0
            cur.diam_line = line
        elif cmd == "CLAP":
            r = self.num(args, 1, "CLAP", line)
            rmin = self.num(args, 0, "CLAP", line)
            if rmin != 0.0:
                self.warn(f"line {line}: CLAP minimum radius {rmin} (annular aperture) ignored")
            if not r > 0.0:
                raise self.err(f"CLAP: the aperture radius must be positive, got {r}", line, no)
            cur.clap = min(cur.clap, r)
        elif cmd == "CONI":
            cur.coni = self.num(args, 0, "CONI", line)
        elif cmd == "PARM":
            i = self.integer(args, 0, "PARM", line)
            cur.parm[i] = (self.num(args, 1, "PARM", line), line)
        elif cmd == "XDAT":
            i = self.integer(args, 0, "XDAT", line)
            cur.xdat[i] = (self.num(args, 1, "XDAT", line), line)
        elif cmd == "GLAS":
            if not args:
                raise self.err("GLAS needs a glass name", line, no)
            if args[0].upper() == "MIRROR":
                cur.mirror = True
                return
            cur.glas = (list(args), line)
        elif cmd == "STOP":
            cur.stop = True
        elif cmd == "COMM":
            cur.comm = rest
        elif cmd in _VIGNETTING:
            self.warn(
                f"line {line}: {cmd} (an obscuration or user aperture on surface {no}) "
                "ignored: it can vignette rays but orthoscope does not clip with it"
            )
        elif cmd in ("SQAP", "ELAP"):
            a, b = self.num(args, 0, cmd, line), self.num(args, 1, cmd, line)
            if not (a > 0.0 and b > 0.0):
                raise self.err(f"{cmd}: the aperture half-widths must be positive", line, no)
            if cmd == "SQAP":
                cur.sqap = (a, b)
            else:
                cur.elap = (a, b)
            cur.ap_line = line
        elif cmd == "OBDC":
            cur.obdc = (self.num(args, 0, cmd, line), self.num(args, 1, cmd, line))
        elif cmd == "SCBD":
            vals = [self.num(args, i, cmd, line) for i in range(len(args))]
            if len(vals) < 8 or vals[0] not in (1.0, 2.0):
                raise self.err(
                    "SCBD: expected 'SCBD 1|2 order mode dx dy tilt_x tilt_y tilt_z' (surface "
                    "tilt/decenter before (1) or after (2) the surface)",
                    line,
                    no,
                )
            cur.scbd[int(vals[0])] = (vals[1:8], line)
        elif cmd in _TILTS:
            vals = []
            for a in args:
                try:
                    vals.append(float(a))
                except ValueError:
                    pass
            if any(v != 0.0 for v in vals[1:] if math.isfinite(v)) or (
                cmd != "SCBD" and any(v != 0.0 for v in vals)
            ):
                raise self.err(
                    f"{cmd}: this form of surface tilt/decenter is not supported; in OpticStudio "
                    "give it in the surface's Tilt/Decenter tab or as coordinate breaks and save "
                    "again",
                    line,
                    no,
                )
        # _IGNORED_SURFACE: nothing

    # ------------------------------------------------------------------------------------
    def material(self, glas: tuple[list[str], int] | None, gcat: list[str], no: int) -> Material:
        if glas is None:
            return AIR
        args, line = glas
        name = args[0]
        if name.upper() in ("___BLANK", "MODEL"):
            if len(args) < 5:
                raise self.err(
                    f"GLAS {name}: a model glass needs 'GLAS {name} 1 0 nd vd ...' (nd and vd "
                    "are the 4th and 5th fields)",
                    line,
                    no,
                )
            nd = number(args[3], "GLAS nd", self.fail, line)
            vd = number(args[4], "GLAS vd", self.fail, line)
            if not (nd > 0.0) or vd < 0.0:
                raise self.err(f"GLAS {name}: nd must be > 0 and vd >= 0, got {nd}, {vd}", line)
            try:  # within raytrace.materials.INDEX_RANGE (and ABBE_RANGE)
                return fixed_index(nd) if vd == 0.0 else model_glass(nd, vd)
            except ValueError as e:
                raise self.err(f"GLAS {name}: {e}", line) from None
        if name.upper() == "AIR":
            return AIR
        try:  # a code or printed nd/vd outside raytrace.materials.INDEX_RANGE: ValueError
            code = parse_glass_code(name)
            if code is not None:
                return code
            r = resolve_glass(name, gcat, printed=printed_nd_vd(args))
        except PrescriptionError as e:
            raise self.err(f"GLAS {name}: {e.reason}", line, no) from None
        except ValueError as e:
            raise self.err(f"GLAS {name}: {e}", line, no) from None
        if r.warning:
            self.warn(f"line {line}: {r.warning}")
        return r.material

    def extra_data(self, z: _ZSurf, scale: float) -> QType | None:
        """The Q-type terms of a ``QED_TYPE`` surface (module docstring); on other surfaces the
        extra data are ignored with a warning."""
        if z.type != "QED_TYPE":
            for i, (v, line) in sorted(z.xdat.items()):
                if v != 0.0:
                    self.warn(
                        f"line {line}: XDAT {i} {v} (extra data) ignored on a {z.type} surface"
                    )
            return None
        for i, (v, line) in sorted(z.parm.items()):
            if v != 0.0:
                raise self.err(
                    f"QED_TYPE PARM {i} = {v!r}: a parameter on a Q-type surface is not read "
                    "(orthoscope reads its extra data XDAT 1..3+n only); set it to 0 in "
                    "OpticStudio or convert the surface to an even asphere",
                    line,
                    z.number,
                )

        def xd(i: int) -> tuple[float, int]:
            return z.xdat.get(i, (0.0, z.type_line))

        mode, line = xd(1)
        if mode != 0.0:
            raise self.err(
                f"QED_TYPE extra data 1 = {mode!r}: only 0 is read (the Qbfs form, which every "
                "Q-type file checked holds; lenses/INTEROP.md); convert the surface to an even "
                "asphere or write the lens as TOML with qtype = { form = ... }",
                line,
                z.number,
            )
        nt, line = xd(2)
        if nt != int(nt) or not 0 <= nt <= 1000:
            raise self.err(
                f"QED_TYPE extra data 2 (the number of terms) = {nt!r}: expected a whole number "
                "from 0 to 1000",
                line,
                z.number,
            )
        n = int(nt)
        for i, (v, line) in sorted(z.xdat.items()):
            if (i < 1 or i > 3 + n) and v != 0.0:
                self.warn(
                    f"line {line}: XDAT {i} {v} ignored: the QED_TYPE surface has {n} terms "
                    "(extra data 2), in XDAT 4 to 3+n"
                )
        rn, line = xd(3)
        if n == 0 and not rn > 0.0:
            return None  # no terms: the base conic
        if not (math.isfinite(rn) and rn > 0.0):
            raise self.err(
                f"QED_TYPE extra data 3 (the normalization radius) = {rn!r}: must be positive",
                line,
                z.number,
            )
        return QType("qbfs", rn * scale, tuple(xd(4 + m)[0] * scale for m in range(n)))

    def aspheric(self, z: _ZSurf, scale: float) -> tuple[float, ...]:
        if z.type != "EVENASPH":
            if z.type == "QED_TYPE":
                return ()  # its PARMs are checked by extra_data
            for i, (v, line) in sorted(z.parm.items()):
                if v != 0.0:
                    self.warn(f"line {line}: PARM {i} = {v} ignored on a STANDARD surface")
            return ()
        coef: dict[int, float] = {}
        for i, (v, line) in z.parm.items():
            if i == 1:
                if v != 0.0:
                    raise self.err(
                        f"EVENASPH PARM 1 (the r² coefficient) = {v!r} is not supported: "
                        "orthoscope models r⁴ and higher terms only; in OpticStudio absorb the r² "
                        "term into the radius (re-optimize with PARM 1 = 0) and save again",
                        line,
                        z.number,
                    )
            elif 2 <= i <= 8:
                coef[i] = v
            else:
                raise self.err(
                    f"EVENASPH PARM {i}: an even asphere has parameters 1 to 8 (r² to r¹⁶)",
                    line,
                    z.number,
                )
        n = max([i for i, v in coef.items() if v != 0.0], default=1)
        return tuple(coef.get(i, 0.0) * scale ** (1 - 2 * i) for i in range(2, n + 1))

    # ------------------------------------------------------------------------------------
    def wavelengths(self, h, wavm, wavl):
        """(wavelengths nm, weights, line, primary nm): the WAVM slots 1..n with n the FTYP
        wavelength count (all slots when FTYP gives none), or the WAVL list with WWGT weights;
        the primary is slot PWAV. Each wavelength goes through raytrace.units.wavelength_nm."""
        from ..units import UnitError, wavelength_nm

        nw = h.get("FTYP", (0, None, None, None))[2]
        pw, pw_line = h.get("PWAV", (1, None))
        if wavm:
            slots = sorted(i for i in wavm if i >= 1 and (nw is None or nw <= 0 or i <= nw))
            if not slots:
                raise self.err(
                    f"FTYP asks for {nw} wavelength(s) but there are no WAVM 1..{nw} lines",
                    min(v[2] for v in wavm.values()),
                )
            if pw not in slots:
                raise self.err(
                    f"PWAV {pw}: there is no active WAVM {pw} line (wavelengths: "
                    f"{', '.join(str(i) for i in slots)})",
                    pw_line or min(v[2] for v in wavm.values()),
                )
            entries = [(wavm[i][0], wavm[i][1], wavm[i][2]) for i in slots]
            primary_pos = slots.index(pw)
        elif wavl is not None:
            vals, line = wavl
            wts = h.get("WWGT", ([], None))[0]
            if not 1 <= pw <= len(vals):
                raise self.err(f"PWAV {pw}: WAVL lists {len(vals)} wavelength(s)", line)
            entries = [(v, wts[i] if i < len(wts) else 1.0, line) for i, v in enumerate(vals)]
            primary_pos = pw - 1
        else:
            self.warn("no wavelength (WAVM/WAVL): the d line 587.5618 nm is used")
            return (LAMBDA_D,), (1.0,), 1, LAMBDA_D
        for v, w, line in entries:
            try:
                wavelength_nm(v)
            except UnitError:
                raise self.err(
                    f"the wavelength {v / 1000:g} µm is outside {100 / 1000:g}-{30000 / 1000:g} "
                    "µm (WAVM/WAVL are in µm)",
                    line,
                ) from None
            if not (math.isfinite(w) and w >= 0.0):
                raise self.err(f"wavelength weight {w!r} must be a number >= 0", line)
        wls = tuple(e[0] for e in entries)
        return wls, tuple(e[1] for e in entries), entries[primary_pos][2], wls[primary_pos]

    def check_complete(self, surfaces: list[_ZSurf], last_line: int) -> None:
        """Refuse a truncated file (a cut file must not read as a shorter lens).

        A complete .zmx either goes on after its surfaces (OpticStudio writes top-level
        sections there: ``BLNK``, ``TOL``, ``MNUM``, ``MOFF``, ...; surface data is indented,
        those are not) or ends with a complete image surface: its ``DISZ`` is written and is 0,
        it is no stop, mirror, glass or coordinate break, and it holds every command that
        follows ``DISZ`` in all the other blocks (``DIAM``, ``MEMA``, ``POPS`` in OpticStudio's
        files) — true of every real file in tests/data/corpus. Not detectable: a cut right
        after the whole block of a plain lens surface of thickness 0 (it looks like an image
        surface), a cut after ``DISZ 0`` of such a surface in a file whose blocks have nothing
        after ``DISZ``, and a cut inside the last line that leaves a valid shorter number
        (``DISZ 12.5`` → ``DISZ 1``) in a file without sections after the surfaces."""
        if self.after_surfaces:
            return
        img = surfaces[-1]

        def tail(z: _ZSurf) -> set[str] | None:
            return set(z.cmds[z.cmds.index("DISZ") + 1 :]) if "DISZ" in z.cmds else None

        tails = [t for t in (tail(z) for z in surfaces[:-1]) if t is not None]
        missing = sorted(set.intersection(*tails) - (tail(img) or set())) if tails else []
        what = ""
        if not img.disz_line:
            what = "has no DISZ line"
        elif img.disz != 0.0:
            what = f"has thickness DISZ {img.disz!r} (an image surface has 0)"
        elif img.stop or img.mirror or img.glas is not None or img.type == "COORDBRK":
            what = "is not an image surface (STOP, GLAS, a mirror or a coordinate break)"
        elif missing:
            what = f"lacks {', '.join(missing)}, which every other block has after DISZ"
        if what:
            raise self.err(
                f"the file ends at line {last_line} inside the surface list, and its last block "
                f"SURF {img.number} {what}: the file looks truncated (nothing follows the "
                "surfaces); use the complete file (save or export it again from OpticStudio)",
                img.line,
                img.number,
            )

    def coordinate_break(self, z: _ZSurf, scale: float, medium: Material) -> Surface:
        """A ``COORDBRK`` surface: PARM 1..6 = decenter x, y, tilt x, y, z (deg), order flag."""

        def parm(i: int) -> float:
            return z.parm.get(i, (0.0, 0))[0]

        order = ORDERS[0] if parm(6) == 0.0 else ORDERS[1]
        for i, (_v, line) in z.parm.items():
            if not 1 <= i <= 6:
                raise self.err(f"COORDBRK PARM {i}: a coordinate break has PARM 1 to 6", line)
        if z.stop:
            raise self.err("STOP on a coordinate break: the stop must be a lens surface", z.line)
        if z.mirror or z.glas is not None:
            self.warn(f"line {z.line}: GLAS on a coordinate break (surface {z.number}) ignored")
        p = Placement((parm(1) * scale, parm(2) * scale, 0.0), (parm(3), parm(4), parm(5)), order)
        return Surface(
            curvature=0.0,
            thickness=z.disz * scale,
            material=medium,
            label=z.comm,
            line=z.line,
            placement=p,
            coordinate_break=True,
        )

    def tilt_decenter(self, z: _ZSurf, scale: float) -> tuple[Placement | None, Placement | str]:
        """(placement, after) of the surface Tilt/Decenter tab (``SCBD 1`` before, ``SCBD 2``
        after the surface): values ``order mode dx dy tx ty tz``."""
        out: list[Placement | None] = [None, None]
        for which in (1, 2):
            if which not in z.scbd:
                continue
            (order, mode, dx, dy, tx, ty, tz), line = z.scbd[which]
            p = Placement((dx * scale, dy * scale, 0.0), (tx, ty, tz))
            moves = sum(v != 0.0 for v in (tx, ty, tz)) + (dx != 0.0 or dy != 0.0)
            if moves > 1 and (order != 0.0 or mode != 0.0):
                raise self.err(
                    f"SCBD {which}: a tilt/decenter with order flag {order:g} / mode {mode:g} "
                    "is not supported where the order matters; in OpticStudio use explicit "
                    "values with the order 'decenter then tilt' (or coordinate breaks) and "
                    "save again",
                    line,
                    z.number,
                )
            out[which - 1] = None if p.is_identity else p
        before, after = out
        return before, (after if after is not None else "stay")

    def clear_aperture(self, z: _ZSurf, sd: float, scale: float):
        """(semi-diameter, ClearAperture or None) from CLAP / SQAP / ELAP and OBDC."""
        x0, y0 = z.obdc[0] * scale, z.obdc[1] * scale
        shapes = [s for s, v in (("rectangle", z.sqap), ("ellipse", z.elap)) if v is not None]
        if len(shapes) > 1 or (shapes and math.isfinite(z.clap)):
            raise self.err(
                "more than one clear aperture (CLAP / SQAP / ELAP) on one surface",
                z.ap_line or z.line,
                z.number,
            )
        if shapes:
            hx, hy = z.sqap if z.sqap is not None else z.elap
            ap = ClearAperture(shapes[0], hx * scale, hy * scale, x0, y0)
            return (math.inf if (x0 or y0) else sd), ap
        if math.isfinite(z.clap):
            r = z.clap * scale
            if x0 or y0:
                return math.inf, ClearAperture("circle", r, r, x0, y0)
            return min(sd, r), None
        if x0 or y0:
            self.warn(f"OBDC on surface {z.number} without a clear aperture ignored")
        return sd, None

    def build(self, surfaces, h, notes_meta, plain_notes, xfln, yfln, wavm, wavl, gcat):
        last_line = len(self.text.split("\n"))
        if len(surfaces) < 3:
            raise self.err(
                f"found {len(surfaces)} SURF block(s): a lens needs the object surface (SURF 0), "
                "at least one lens surface and the image surface"
                + ("" if self.after_surfaces else " (the file ends there: is it truncated?)"),
                surfaces[-1].line if surfaces else last_line,
            )
        self.check_complete(surfaces, last_line)
        scale = h.get("UNIT", (1.0, 0))[0]
        obj, img, body = surfaces[0], surfaces[-1], surfaces[1:-1]
        if obj.stop or img.stop:
            which = obj if obj.stop else img
            raise self.err(
                "STOP on the object or image surface: the stop must be a lens surface",
                which.line,
                which.number,
            )
        stops = [z for z in body if z.stop]
        if len(stops) > 1:
            raise self.err(
                f"more than one STOP (surfaces {', '.join(str(z.number) for z in stops)})",
                stops[1].line,
                stops[1].number,
            )
        if not stops:
            self.warn("no STOP line: surface 1 is the stop (OpticStudio's default)")
        # object
        od = obj.disz
        if math.isinf(od) or od >= ZEMAX_INFINITY:
            od = math.inf
        else:
            od *= scale
            if not od > 0.0:
                raise self.err(
                    f"the object distance (DISZ of surface 0) must be positive or INFINITY, "
                    f"got {obj.disz!r}",
                    obj.disz_line or obj.line,
                    0,
                )
        object_material = self.material(obj.glas, gcat, 0)
        if img.curv != 0.0:
            self.warn(
                f"line {img.curv_line}: the image surface is curved (CURV {img.curv!r}); "
                "orthoscope uses a flat image plane at the same vertex"
            )
        out: list[Surface] = []
        mirrors = 0
        for z in (obj, img):
            if z.type == "QED_TYPE":
                z.type = "STANDARD"  # the object and image surfaces are read as planes
            self.extra_data(z, scale)
        for k, z in enumerate(body):
            before = object_material if not out else out[-1].material
            if z.type == "COORDBRK":
                self.extra_data(z, scale)
                out.append(self.coordinate_break(z, scale, before))
                continue
            if z.mirror and z.glas is not None:
                raise self.err("GLAS MIRROR and another GLAS on one surface", z.line, z.number)
            mat = before if z.mirror else self.material(z.glas, gcat, z.number)
            mirrors += z.mirror
            sd = math.inf
            if z.diam_fixed:
                if z.diam == 0.0:
                    # a dummy surface with a fixed semi-diameter of 0: nothing to clip with
                    self.warn(
                        f"line {z.diam_line}: DIAM 0 (fixed) on surface {z.number}: no "
                        "semi-diameter, the surface does not clip"
                    )
                elif not z.diam > 0.0:
                    raise self.err(
                        f"DIAM: a fixed semi-diameter must be positive, got {z.diam!r}",
                        z.diam_line,
                        z.number,
                    )
                else:
                    sd = z.diam * scale
            sd, aperture = self.clear_aperture(z, sd, scale)
            th = z.disz * scale
            direction = -1.0 if mirrors % 2 else 1.0
            if th * direction < 0.0 and not mat.is_air:
                raise self.err(
                    f"DISZ {z.disz!r}: a glass thickness must not be "
                    f"{'negative' if direction > 0 else 'positive after an odd number of mirrors'}",
                    z.disz_line or z.line,
                    z.number,
                )
            placement, after = self.tilt_decenter(z, scale)
            out.append(
                Surface(
                    curvature=z.curv / scale,
                    thickness=th,
                    material=mat,
                    semi_diameter=sd,
                    stop=z.stop or (not stops and k == 0),
                    conic=z.coni,
                    aspheric=self.aspheric(z, scale),
                    qtype=self.extra_data(z, scale),
                    label=z.comm,
                    line=z.line,
                    placement=placement,
                    after=after,
                    mirror=z.mirror,
                    aperture=aperture,
                )
            )
        if img.scbd.get(2):
            self.warn(f"line {img.scbd[2][1]}: a tilt/decenter after the image surface ignored")
        image_placement, _ = self.tilt_decenter(img, scale)
        # wavelengths (nm): the first FTYP-count WAVM slots (or WAVL), PWAV the primary
        wls, wts, _wl_line, primary = self.wavelengths(h, wavm, wavl)
        # aperture
        if "APER" not in h:
            raise self.err(
                "no system aperture: the file needs ENPD (entrance-pupil diameter), FNUM "
                "(image-space F/#) or OBNA (object-space NA)",
                last_line,
            )
        acmd, aval, aline = h["APER"]
        if acmd == "FLOA":
            st = [z for z in out if z.stop][0]
            if not math.isfinite(st.semi_diameter):
                raise self.err(
                    "FLOA (float by stop size): the stop surface needs a semi-diameter (DIAM); "
                    "give it in OpticStudio and save again",
                    aline,
                )
            aval = st.semi_diameter / scale
        if not aval > 0.0:
            raise self.err(f"{acmd} must be positive, got {aval!r}", aline)
        if acmd == "ENPD":
            aperture = Aperture("epd", aval * scale)
        elif acmd == "FNUM":
            aperture = Aperture("fnumber", aval)
        elif acmd == "FLOA":
            aperture = Aperture("float", aval * scale)
        elif acmd == "WFNO":
            aperture = Aperture("working_fnumber", aval)
        elif acmd == "OBCA":
            if math.isinf(od) or not aval < 90.0:
                raise self.err(
                    "OBNA x 1 (object cone angle): needs a finite object distance and an angle "
                    "below 90 degrees",
                    aline,
                )
            aperture = Aperture("cone_angle", aval)
        else:
            if aval >= 1.0 * object_material.nd or math.isinf(od):
                raise self.err(
                    "OBNA: an object-space NA needs a finite object distance and NA < n",
                    aline,
                )
            aperture = Aperture("na", aval)
        # field
        ft, nf, _nw, fline = h.get("FTYP", (0, None, None, None))
        temperature = pressure = None
        if "ENVD" in h:
            t, pr, eline = h["ENVD"]
            if not (-273.15 < t < 1000.0 and 0.0 <= pr < 100.0):
                raise self.err(
                    f"ENVD {t!r} {pr!r}: temperature (°C) and pressure (atm) out of range", eline
                )
            if (t, pr) != (20.0, 1.0):
                temperature, pressure = t, pr
        if ft not in (0, 1, 2, 3):
            raise self.err(
                f"FTYP {ft}: field type {ft} is not supported; set the field type to Angle (0), "
                "Object Height (1), Paraxial Image Height (2) or Real Image Height (3) in "
                "OpticStudio and save again",
                fline,
            )
        xs = xfln[0] if xfln else []
        ys = yfln[0] if yfln else []
        n = max(len(xs), len(ys)) if nf is None else nf
        if n < 0:
            raise self.err(f"FTYP: negative number of fields {n}", fline)
        npts = min(n, max(len(xs), len(ys)))
        pts = tuple(
            (xs[i] if i < len(xs) else 0.0, ys[i] if i < len(ys) else 0.0) for i in range(npts)
        )
        radial = [math.hypot(a, b) for a, b in pts]
        fmax = max(radial, default=0.0)
        if not radial:
            self.warn("no field values (YFLN/XFLN): the field is 0")
        fline = (yfln or xfln or (None, fline))[1] or fline or 1
        image_field = None
        if ft in (2, 3):
            kind = "paraxial_image_height" if ft == 2 else "real_image_height"
            image_field = (kind, fmax * scale, fline)
            fld = Field("height" if math.isfinite(od) else "angle", 0.0)
        elif ft == 0:
            if fmax >= 90.0:
                raise self.err(f"field angle {fmax} deg: must be below 90 deg", fline)
            fld = Field("angle", fmax, pts)
        else:
            if math.isinf(od):
                raise self.err(
                    "FTYP 1 (object height) needs a finite object distance (DISZ of surface 0)",
                    fline,
                )
            fld = Field("height", fmax * scale, tuple((a * scale, b * scale) for a, b in pts))
        # names and notes
        name_text = h.get("NAME", ("", None))[0]
        meta = {}
        for key, val in notes_meta.items():
            try:
                meta[key] = json.loads(val)
            except ValueError:
                plain_notes.append(f"orthoscope.{key}: {val}")
        name = meta.get("name") if isinstance(meta.get("name"), str) else None
        if name is None:
            name = name_text or (Path(self.path).stem if self.path else "zemax lens")
        source = meta.get("source")
        if not isinstance(source, str):
            source = f"imported from the Zemax file {Path(self.path).name}" if self.path else ""
        notes = meta.get("notes")
        if not isinstance(notes, str):
            notes = "\n".join(plain_notes)
        solve = meta.get("image_solve")
        solve = solve if solve == "gaussian" else None
        if meta.get("field_points") == [] and image_field is None:
            fld = replace(fld, points=())
        self.warn_unknown()
        lens = self.file_lens(
            [z.line for z in body],
            surfaces[0].line,
            name=name,
            surfaces=tuple(out),
            aperture=aperture,
            field=fld,
            object_distance=od,
            wavelength=primary,
            wavelengths=wls,
            weights=wts,
            temperature_c=temperature,
            pressure_atm=pressure,
            source=source,
            notes=notes,
            units="mm",
            object_material=object_material,
            image_solve=solve,
            path=self.path,
            image_placement=image_placement,
        )
        if image_field is not None:
            from ..errors import TraceError
            from ..trace.image_field import field_for_image_height

            kind, height, line = image_field
            try:
                lens = replace(lens, field=field_for_image_height(lens, height, kind))
            except (LensError, TraceError, ValueError) as e:
                raise self.err(
                    f"FTYP {ft} ({kind.replace('_', ' ')} {height:g} mm): {e}", line
                ) from None
        return ImportResult(lens, tuple(self.warnings))


def parse_zmx(text: str | bytes, *, path: str | Path | None = None) -> ImportResult:
    """Parse ``.zmx`` content (text, or raw bytes in any of the supported encodings) into an
    :class:`ImportResult` (lens + skipped-command list). Raises only PrescriptionError."""
    return guarded_parse(_ZmxParser, text, path, "a Zemax .zmx lens file")


def loads_zmx(text: str | bytes, *, path: str | Path | None = None) -> Lens:
    """Parse ``.zmx`` content into a :class:`Lens`; skipped commands → one InteropWarning."""
    return emit_warnings(parse_zmx(text, path=path), None if path is None else str(path))


def read_zmx(path: str | Path) -> Lens:
    """Read a Zemax ``.zmx`` file (ASCII/UTF-8/UTF-16) into a :class:`Lens` (mm, nm).

    Raises :class:`~raytrace.errors.PrescriptionError` (file, line, what to do) for anything it
    cannot read; skipped non-optical or unknown commands → one :class:`InteropWarning`."""
    return emit_warnings(parse_zmx(read_bytes(path), path=path), str(path))


# --------------------------------------------------------------------------------------------
# Writer
# --------------------------------------------------------------------------------------------


def _r(x: float) -> str:
    return repr(float(x))


def _agf_name(name: str) -> str:
    """A catalog glass's name as a .zmx file writes it: OpticStudio's catalogs spell names
    without spaces (Ohara's S-LAL 8 is S-LAL8 in OHARA.AGF), and a space would end the name."""
    return name.replace(" ", "")


def _glas(m: Material) -> str | None:
    if m.is_air:
        return None
    if m.kind == "catalog":
        # OpticStudio stores the catalog's nd/vd after a catalog name; readers ignore them
        return f"GLAS {_agf_name(m.name)} 0 0 {_r(m.nd)} {_r(m.vd)} 0 0 0 0 0 0"
    vd = 0.0 if m.kind == "index" else m.vd
    return f"GLAS ___BLANK 1 0 {_r(m.nd)} {_r(vd)} 0 0 0 0 0 0"


def _gcat(lens: Lens) -> list[str]:
    """The GCAT line: the catalogs of the lens's catalog glasses in an order in which every
    glass name resolves to that glass, as OpticStudio and the reader here resolve it
    (:func:`raytrace.glass.resolve_glass`: the first catalog on the line that has the name).

    A glass of catalog C whose name another written catalog D also has needs C before D; the
    order is the one that meets all these constraints and otherwise keeps the order of first use
    (a topological order, smallest by first use: the order of first use itself whenever it
    works). The Lens does not keep the GCAT line of a file it was read from, so that order is not
    preferred. Raises PrescriptionError when no order works (two glasses need opposite orders,
    e.g. Schott's SF11 and Hikari's SF11 in one lens) or a glass's name, as written, reads as
    another glass of its own catalog."""
    from ..glass import CATALOGS, find_glass

    mats = [lens.object_material, *(s.material for s in lens.surfaces)]
    for m in mats:
        if m.kind == "catalog" and m.catalog not in CATALOGS:
            raise PrescriptionError(
                f"glass {m.name} is a {m.catalog} glass defined in the lens file, which a .zmx "
                "file cannot hold (OpticStudio needs it in a glass catalog); write the lens as "
                ".toml instead"
            )
    glasses = list(dict.fromkeys((m.name, m.catalog) for m in mats if m.kind == "catalog"))
    cats = list(dict.fromkeys(c for _, c in glasses))
    # after[c][d]: the glass of catalog c whose name d also has, so c must come before d
    after: dict[str, dict[str, str]] = {c: {} for c in cats}
    for name, cat in glasses:
        written = _agf_name(name)
        own = find_glass(written, [cat])
        if not own or (own[0].catalog, own[0].name) != (cat, name):
            other = f"as {own[0].name}" if own else "as no glass of it"
            raise PrescriptionError(
                f"glass {name} of the {cat} catalog cannot be written to .zmx: its name, "
                f"written {written}, reads back in the {cat} catalog {other}; write the lens as "
                ".toml instead"
            )
        for d in cats:
            if d != cat and find_glass(written, [d]):
                after[cat].setdefault(d, name)
    rank = {c: i for i, c in enumerate(cats)}
    needs = {c: sum(c in after[b] for b in cats) for c in cats}  # catalogs that must precede c
    ready = [c for c in cats if not needs[c]]
    order: list[str] = []
    while ready:
        c = min(ready, key=rank.__getitem__)
        ready.remove(c)
        order.append(c)
        for d in after[c]:
            needs[d] -= 1
            if not needs[d]:
                ready.append(d)
    if len(order) < len(cats):
        left = [c for c in cats if c not in order]
        clashes = "; ".join(
            f"glass {name} of the {c} catalog needs {c.upper()} before {d.upper()}, which also "
            f"has a {name}"
            for c in left
            for d, name in after[c].items()
            if d in left
        )
        raise PrescriptionError(
            "the glasses of this lens cannot all be written to .zmx: OpticStudio takes the first "
            "catalog on the GCAT line that has a glass's name, and no order of the catalogs "
            f"gives every glass its own ({clashes}); write the lens as .toml instead, or give "
            "one of these glasses as a model glass"
        )
    return [c.upper() for c in order]


def _one_line(s: str) -> str:
    return " ".join(s.split())


def dumps_zmx(lens: Lens) -> str:
    """The lens as ``.zmx`` text (sequential, mm, full float64 precision; catalog glasses by name
    with a GCAT line, model glasses as ``___BLANK``).

    Limits: an even asphere holds A4 … A16 (7 coefficients); more raise PrescriptionError.
    A ``"index"`` material is written as a model glass with vd = 0 (OpticStudio's non-dispersive
    convention). Trailing zero aspheric coefficients are not kept (same surface)."""
    out: list[str] = ["MODE SEQ", f"NAME {_one_line(lens.name)}"]
    meta: dict[str, str] = {}
    if _one_line(lens.name) != lens.name or not lens.name.isascii():
        meta["name"] = lens.name
    meta["source"] = lens.source
    meta["notes"] = lens.notes
    if lens.image_solve:
        meta["image_solve"] = lens.image_solve
    if not lens.field.points and lens.field.given is None:
        meta["field_points"] = []  # the fields written below are a default fan, not the lens's
    for k, v in meta.items():
        out.append(f"NOTE 0 orthoscope.{k}: {json.dumps(v, ensure_ascii=True)}")
    out.append("UNIT MM X W X CM MR CPMM")
    env = lens.environment
    if env is not None:
        out.append(f"ENVD {_r(env[0])} {_r(env[1])} 0")
    gcat = _gcat(lens)
    if gcat:
        out.append("GCAT " + " ".join(gcat))
    ap = lens.aperture
    out.append(
        {
            "epd": f"ENPD {_r(ap.value)}",
            "fnumber": f"FNUM {_r(ap.value)} 0",
            "na": f"OBNA {_r(ap.value)} 0",
            "float": "FLOA",
            "working_fnumber": f"FNUM {_r(ap.value)} 1",
            "cone_angle": f"OBNA {_r(ap.value)} 1",
        }[ap.kind]
    )
    fld = lens.field
    fv = float(fld.value)
    if fld.given is not None:
        ftyp = 2 if fld.given[0] == "paraxial_image_height" else 3
        gv = fld.given[1]
        points = [(0.0, 0.0)] if gv == 0.0 else [(0.0, 0.0), (0.0, 0.7 * gv), (0.0, gv)]
    else:
        ftyp = 0 if fld.kind == "angle" else 1
        if fld.points and len(fld.points) <= 12:
            points = list(fld.points)
        else:
            points = [(0.0, 0.0)] if fv == 0.0 else [(0.0, 0.0), (0.0, 0.7 * fv), (0.0, fv)]
    nw = len(lens.wavelengths)
    out.append(f"FTYP {ftyp} 0 {len(points)} {nw} 0 0 0")
    pad = points + [(0.0, 0.0)] * (12 - len(points))
    out.append("XFLN " + " ".join(_r(x) if x else "0" for x, _ in pad))
    out.append("YFLN " + " ".join(_r(y) if y else "0" for _, y in pad))
    out.append("FWGN " + " ".join("1" for _ in pad))
    for i, (w, wt) in enumerate(zip(lens.wavelengths, lens.weights, strict=True), start=1):
        out.append(f"WAVM {i} {nm_to_micron_text(w)} {_r(wt)}")
    out.append(f"PWAV {lens.wavelengths.index(lens.wavelength) + 1}")
    # object surface
    out += ["SURF 0", "  TYPE STANDARD", '  CURV 0.0 0 0 0 0 ""']
    od = lens.object_distance
    out.append("  DISZ INFINITY" if math.isinf(od) else f"  DISZ {_r(od)}")
    g = _glas(lens.object_material)
    if g:
        out.append("  " + g)
    k = 0  # the last SURF number written

    def surf() -> int:
        nonlocal k
        k += 1
        out.append(f"SURF {k}")
        return k

    def coordbrk(p: Placement, thickness: float) -> None:
        surf()
        out.append("  TYPE COORDBRK")
        out.append("  CURV 0.0 0 0.0 0.0 0")
        order = 0 if p.order == "decenter-tilt" else 1
        vals = (p.decenter[0], p.decenter[1], *p.tilt, order)
        for j, v in enumerate(vals, start=1):
            out.append(f"  PARM {j} {_r(v) if v else '0'}")
        out.append(f"  DISZ {_r(thickness)}")
        if p.decenter[2]:
            raise PrescriptionError(
                "a decenter along z cannot be written to .zmx (a coordinate break has x and y "
                "only); write the lens as .toml instead",
                surface=k,
            )

    for i, s in enumerate(lens.surfaces, start=1):
        if s.coordinate_break:
            coordbrk(s.placement or Placement(), s.thickness)
            continue
        asph = list(s.aspheric)
        while asph and asph[-1] == 0.0:
            asph.pop()
        if len(asph) > 7:
            raise PrescriptionError(
                f"{len(s.aspheric)} aspheric coefficients cannot be written to .zmx: an "
                "EVENASPH surface holds A4 to A16 (7 terms)",
                surface=i,
            )
        q = s.qtype
        if q is not None and q.form != "qbfs":
            raise PrescriptionError(
                "a Qcon surface cannot be written to .zmx: orthoscope reads and writes "
                "OpticStudio's QED_TYPE in its Qbfs form only; write the lens as .toml instead",
                surface=i,
            )
        before, after_cb, after_tab = _tab_moves(s)
        if before is not None and not _tab_ok(before):
            coordbrk(before, 0.0)
            before = None
        surf()
        kind = "QED_TYPE" if q is not None else "EVENASPH" if asph else "STANDARD"
        out.append(f"  TYPE {kind}")
        if s.label:
            out.append(f"  COMM {_one_line(s.label)}")
        out.append(f'  CURV {_r(s.curvature)} 0 0 0 0 ""')
        if s.stop:
            out.append("  STOP")
        if before is not None:
            out.append("  " + _scbd(1, before))
        if after_tab is not None:
            out.append("  " + _scbd(2, after_tab))
        out.append(f"  DISZ {_r(0.0 if after_cb is not None else s.thickness)}")
        if s.mirror:
            out.append("  GLAS MIRROR 0 0 1.5 40 0 0 0 0 0 0")
        else:
            g = _glas(s.material)
            if g:
                out.append("  " + g)
        if s.stop and ap.kind == "float":
            out.append(f'  DIAM {_r(ap.value)} 1 0 0 1 ""')
        elif math.isfinite(s.semi_diameter):
            out.append(f'  DIAM {_r(s.semi_diameter)} 1 0 0 1 ""')
        else:
            out.append('  DIAM 0 0 0 0 1 ""')
        if s.conic != 0.0:
            out.append(f"  CONI {_r(s.conic)}")
        if asph:
            out.append("  PARM 1 0")
            for j in range(2, 9):
                out.append(f"  PARM {j} {_r(asph[j - 2]) if j - 2 < len(asph) else '0'}")
        if q is not None:  # QED_TYPE extra data (module docstring)
            xdat = (0.0, float(len(q.terms)), q.norm_radius, *q.terms)
            for j, v in enumerate(xdat, start=1):
                out.append(f'  XDAT {j} {_r(v)} 0 0 1 0 0 ""')
        a = s.aperture
        if a is not None:
            if a.shape == "circle":
                out.append(f"  CLAP 0 {_r(a.half_x)} 0")
            else:
                key = "SQAP" if a.shape == "rectangle" else "ELAP"
                out.append(f"  {key} {_r(a.half_x)} {_r(a.half_y)} 0")
            if a.x0 or a.y0:
                out.append(f"  OBDC {_r(a.x0)} {_r(a.y0)}")
        if after_cb is not None:
            coordbrk(after_cb, s.thickness)
    ip = lens.image_placement
    if ip is not None and not _tab_ok(ip):
        coordbrk(ip, 0.0)
        ip = None
    surf()
    out += ["  TYPE STANDARD", '  CURV 0.0 0 0 0 0 ""']
    if ip is not None:
        out.append("  " + _scbd(1, ip))
    out += ["  DISZ 0", ""]
    return "\r\n".join(out)


def _moves_commute(p: Placement) -> bool:
    """True when the order of the placement's moves does not matter (at most one of: a decenter,
    a tilt about x, about y, about z)."""
    n = sum(v != 0.0 for v in p.tilt) + (any(v != 0.0 for v in p.decenter[:2]))
    return n <= 1 and p.decenter[2] == 0.0


def _tab_ok(p: Placement) -> bool:
    """True when the Tilt/Decenter tab (``SCBD``, order flag 0 as OpticStudio writes it) holds
    ``p`` exactly: no z decenter, and the order is decenter-then-tilt or does not matter."""
    return p.decenter[2] == 0.0 and (p.order == "decenter-tilt" or _moves_commute(p))


def _scbd(which: int, p: Placement) -> str:
    """``SCBD 1|2 0 0 dx dy tx ty tz`` (before / after the surface, order flag 0, explicit)."""
    vals = (p.decenter[0], p.decenter[1], *p.tilt)
    return f"SCBD {which} 0 0 " + " ".join(_r(v) if v else "0" for v in vals)


def _tab_moves(s: Surface) -> tuple[Placement | None, Placement | None, Placement | None]:
    """(before, after as a coordinate break, after in the tab) of a traced surface: the moves
    the .zmx writer needs (``after`` modes turned into explicit moves)."""
    p = s.placement
    a = s.after
    after: Placement | None
    if isinstance(a, Placement):
        after = a
    elif a == "return":
        after = p.inverse() if p is not None else None
    elif a == "bend":
        after = Placement((0.0, 0.0, 0.0), p.tilt, p.order) if p is not None else None
    else:
        after = None
    if after is None:
        return p, None, None
    if _tab_ok(after):
        return p, None, after
    return p, after, None


def write_zmx(lens: Lens, path: str | Path, *, encoding: str = "utf-16", **options) -> None:
    """Write ``lens`` as a ``.zmx`` file, atomically. ``encoding`` ``"utf-16"`` (OpticStudio's
    own: UTF-16 LE with BOM, CRLF) or ``"ascii"`` (non-ASCII characters escaped as ``?``);
    ``options`` (``overwrite``, ``inputs``, ``flag``) as in
    :func:`raytrace.files.output.write_atomic`."""
    text = dumps_zmx(lens)  # what .zmx cannot hold is refused here, as the writer's own error
    check_reads_back(text, loads_zmx, path)
    if encoding == "utf-16":
        data = codecs.BOM_UTF16_LE + text.encode("utf-16-le")
    elif encoding == "ascii":
        data = text.encode("ascii", errors="replace")
    else:
        raise ValueError(f"encoding must be 'utf-16' or 'ascii', got {encoding!r}")
    write_atomic(path, data, **options)
