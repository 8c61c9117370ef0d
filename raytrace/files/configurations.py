"""Configurations of a lens that change thicknesses (focus positions, zoom positions).

A :class:`Configurations` holds, per configuration, the axial thicknesses that differ from the
base lens read by the normal readers (:func:`raytrace.files.read_lens_file`), and optionally the
object distance. :func:`apply_configuration` makes the :class:`~raytrace.lens.Lens` of one
configuration. Surfaces are numbered as in the listings (1 = first lens surface); surface 0 is
the object: its "thickness" is the object distance (mm from the object plane to the first vertex,
positive, ``inf`` allowed), as Zemax's ``THIC 0`` and CODE V's ``THI SO``.

Sources read (only thicknesses; every other multi-configuration operand is listed in
``Configurations.ignored``):

* Zemax ``.zmx`` — ``MNUM n [current]`` heads the multi-configuration editor (n configurations);
  each operand row is stored as one line per configuration,
  ``THIC surf config value status pickup-row pickup-config scale ...``: surface number (0 =
  object; the image surface's thickness is not used), configuration number (1-based) and value
  in lens units (``UNIT``). A value of 1e10 or more on surface 0 is an object at infinity, as
  OpticStudio treats it. The layout of the columns after the value is not used. ``CONF`` lines
  are skipped. This layout is that of OpticStudio's ``MOFF`` rows in single-configuration files
  (``MOFF 0 1 "" 0 0 0 1 1 0 0.0 ""``: operand, number, configuration, value, ...); it was not
  checked against a multi-configuration file written by OpticStudio (none was within reach).
* CODE V ``.seq`` — ``ZOO THI Sk v1 v2 ... vn`` (also ``ZOOM``; ``SO`` = the object, ``SI`` =
  the image surface, not used) gives surface k's thickness in each of n zoom positions, in the
  ``DIM`` unit (M, C, I). Other ``ZOO`` items (fields, wavelengths, apertures) are listed as
  ignored. Semicolons separate commands; ``!`` starts a comment; ``&`` continues a line.
* TOML (this package's format, appended after a lens written by :mod:`raytrace.files.native`)::

      [[configurations]]
      name = "1 m"
      thickness = { 0 = 842.61, 2 = 9.53 }   # surface -> mm; 0 = object distance ("inf" allowed)

  In a file with ``scale_to_efl`` (the lens scaled to that paraxial EFL) these lengths are
  scaled by the lens's factor (:func:`raytrace.files.native.efl_scale`; ``"inf"`` stays), so
  that the configurations are those of the scaled lens: its focus positions are the same
  conjugates scaled.

Every problem raises :class:`~raytrace.errors.PrescriptionError` naming the file and line.
"""

from __future__ import annotations

import math
import re
import tomllib
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from ..errors import LensError, PrescriptionError
from ..lens import Lens
from .output import write_atomic
from .text import decode_text, read_bytes

#: Zemax treats an object thickness of 1e10 or more as infinite.
ZEMAX_INFINITY = 1.0e10

_ZMX_UNITS = {"MM": 1.0, "CM": 10.0, "IN": 25.4, "M": 1000.0, "METER": 1000.0, "METR": 1000.0}
_SEQ_UNITS = {"M": 1.0, "C": 10.0, "I": 25.4}


@dataclass(frozen=True)
class Configuration:
    """One configuration: ``thicknesses`` = ((surface, mm), ...), surface 1-based as in the
    listings, sorted; ``object_distance`` (mm from the object plane to the first vertex, positive,
    ``inf``) or None = the base lens's. ``name``: a label (``"1"``, ``"1 m"``, ...)."""

    name: str
    thicknesses: tuple[tuple[int, float], ...] = ()
    object_distance: float | None = None

    def thickness(self, surface: int) -> float | None:
        """The thickness this configuration gives surface ``surface`` (1-based), or None."""
        for k, v in self.thicknesses:
            if k == surface:
                return v
        return None


@dataclass(frozen=True)
class Configurations:
    """The configurations of one lens file.

    ``configurations``: in order (configuration 1 first); ``current``: the 1-based configuration
    the file's surface data hold (Zemax ``MNUM``'s second number; 1 otherwise); ``source``: the
    file; ``ignored``: operands / items that were not read (``"YFIE (line 40)"``)."""

    configurations: tuple[Configuration, ...]
    current: int = 1
    source: str = ""
    ignored: tuple[str, ...] = ()

    def __len__(self) -> int:
        return len(self.configurations)

    @property
    def surfaces(self) -> tuple[int, ...]:
        """The surfaces whose thickness changes between configurations (0 = object)."""
        ks = {k for c in self.configurations for k, _ in c.thicknesses}
        if any(c.object_distance is not None for c in self.configurations):
            ks.add(0)
        return tuple(sorted(ks))


# --------------------------------------------------------------------------------------------
# Applying a configuration
# --------------------------------------------------------------------------------------------


def apply_configuration(lens: Lens, configuration: Configuration) -> Lens:
    """The lens of ``configuration``: ``lens`` with its thicknesses (and object distance)
    replaced. Raises PrescriptionError for a surface the lens does not have, and LensError
    (from the Lens validation) for a lens that cannot exist (e.g. a glass thickness ≤ 0).

    Parameters
    ----------
    lens : Lens
        The base lens.
    configuration : Configuration
        Thicknesses ((surface, mm), …; surfaces 1-based as in the listings) and optionally the
        object distance (mm from the object plane to the first vertex, positive; ``inf``).

    Returns
    -------
    Lens
        A new lens; when the last thickness changes its image solve is dropped (the image plane
        is where the configuration puts it).

    Raises
    ------
    PrescriptionError
        A surface the lens does not have.
    LensError
        A lens that cannot exist.
    """
    n = lens.n_surfaces
    surfaces = list(lens.surfaces)
    last_changed = False
    for k, t in configuration.thicknesses:
        if not 1 <= k <= n:
            raise PrescriptionError(
                f"configuration {configuration.name!r}: surface {k} does not exist ({lens.name} "
                f"has surfaces 1–{n}; 0 is the object distance)"
            )
        surfaces[k - 1] = replace(surfaces[k - 1], thickness=float(t))
        last_changed |= k == n
    kw: dict[str, Any] = {"surfaces": tuple(surfaces)}
    if last_changed:
        kw["image_solve"] = None
    if configuration.object_distance is not None:
        kw["object_distance"] = float(configuration.object_distance)
    try:
        return replace(lens, **kw)
    except LensError as e:
        raise LensError(f"configuration {configuration.name!r} of {lens.name}: {e}") from None


def configured_lenses(lens: Lens, configurations: Configurations) -> tuple[Lens, ...]:
    """:func:`apply_configuration` for every configuration, in order."""
    return tuple(apply_configuration(lens, c) for c in configurations.configurations)


def check_surfaces(lens: Lens, configurations: Configurations) -> None:
    """Raise PrescriptionError when a configuration names a surface ``lens`` lacks."""
    for c in configurations.configurations:
        for k, _ in c.thicknesses:
            if not 1 <= k <= lens.n_surfaces:
                raise PrescriptionError(
                    f"configuration {c.name!r} changes the thickness of surface {k}, but the "
                    f"lens has surfaces 1–{lens.n_surfaces}: the configurations do not belong to "
                    "this lens",
                    path=configurations.source or None,
                )


# --------------------------------------------------------------------------------------------
# Building configurations
# --------------------------------------------------------------------------------------------


def _build(
    rows: dict[tuple[int, int], tuple[float, int]],
    n: int,
    *,
    current: int,
    source: str,
    ignored: list[str],
    names: list[str] | None = None,
) -> Configurations:
    configs = []
    for j in range(1, n + 1):
        th = []
        od = None
        for (k, cj), (v, _line) in sorted(rows.items()):
            if cj != j:
                continue
            if k == 0:
                od = v
            else:
                th.append((k, v))
        name = names[j - 1] if names else str(j)
        configs.append(Configuration(name, tuple(th), od))
    return Configurations(tuple(configs), current, source, tuple(ignored))


def _text(text: str | bytes, path: str | None, what: str) -> str:
    if isinstance(text, bytes):
        return decode_text(text, path, what)
    return text


def _err(msg: str, path: str | None, line: int | None) -> PrescriptionError:
    return PrescriptionError(msg, path=path, line=line)


def _float(tok: str, what: str, path: str | None, line: int) -> float:
    try:
        v = float(tok)
    except ValueError:
        raise _err(f"{what}: {tok!r} is not a number", path, line) from None
    if math.isnan(v):
        raise _err(f"{what}: NaN is not a thickness", path, line)
    return v


def _int(tok: str, what: str, path: str | None, line: int) -> int:
    try:
        return int(tok)
    except ValueError:
        raise _err(f"{what}: {tok!r} is not an integer", path, line) from None


# --------------------------------------------------------------------------------------------
# Zemax
# --------------------------------------------------------------------------------------------


def parse_zmx_configurations(
    text: str | bytes, *, path: str | Path | None = None
) -> Configurations:
    """The thickness configurations of a Zemax ``.zmx`` file (module docstring). A file without
    ``MNUM`` or with ``MNUM 1`` gives one configuration with no changes."""
    spath = None if path is None else str(path)
    text = _text(text, spath, "a Zemax .zmx file")
    scale = 1.0
    n = 1
    current = 1
    n_line: int | None = None
    n_surf = 0
    rows: dict[tuple[int, int], tuple[float, int]] = {}
    ignored: dict[str, int] = {}
    in_surface = False
    for lineno, raw in enumerate(text.splitlines(), start=1):
        parts = raw.split()
        if not parts:
            continue
        cmd = parts[0].upper()
        indented = raw[:1].isspace()
        if cmd == "SURF":
            n_surf += 1
            in_surface = True
            continue
        if indented and in_surface:
            continue  # surface data
        in_surface = False
        if cmd == "UNIT" and len(parts) > 1:
            scale = _ZMX_UNITS.get(parts[1].upper(), 1.0)
        elif cmd == "MNUM":
            if len(parts) < 2:
                raise _err("MNUM needs the number of configurations", spath, lineno)
            n = _int(parts[1], "MNUM", spath, lineno)
            if n < 1:
                raise _err(f"MNUM {n}: the number of configurations must be ≥ 1", spath, lineno)
            current = _int(parts[2], "MNUM current", spath, lineno) if len(parts) > 2 else 1
            n_line = lineno
        elif cmd == "THIC":
            if len(parts) < 4:
                raise _err(
                    "THIC operand row needs surface, configuration and value "
                    "(THIC surf config value ...)",
                    spath,
                    lineno,
                )
            k = _int(parts[1], "THIC surface", spath, lineno)
            j = _int(parts[2], "THIC configuration", spath, lineno)
            v = _float(parts[3], f"THIC {k} configuration {j}", spath, lineno)
            if n_line is None:
                raise _err(
                    "THIC operand before MNUM: not a multi-configuration file", spath, lineno
                )
            if not 1 <= j <= n:
                raise _err(
                    f"THIC {k}: configuration {j} is outside 1–{n} (MNUM {n}, line {n_line})",
                    spath,
                    lineno,
                )
            if k < 0:
                raise _err(f"THIC: surface {k} is negative", spath, lineno)
            if (k, j) in rows:
                raise _err(
                    f"THIC {k} configuration {j} given twice (first on line {rows[k, j][1]})",
                    spath,
                    lineno,
                )
            if k == 0:
                v = math.inf if v >= ZEMAX_INFINITY else v * scale
            else:
                v *= scale
            rows[(k, j)] = (v, lineno)
        elif cmd in ("CONF", "MOFF"):
            continue
        elif n_line is not None and _looks_like_operand(parts):
            ignored.setdefault(cmd, lineno)
    # the image surface's thickness means nothing: drop it, say so
    image = n_surf - 1
    for k, j in [key for key in rows if n_surf and key[0] >= image]:
        ignored.setdefault(f"THIC {k} (image surface)", rows[(k, j)][1])
        del rows[(k, j)]
    listing = [f"{c} (line {ln})" for c, ln in ignored.items()]
    return _build(rows, n, current=current, source=spath or "", ignored=listing)


def _looks_like_operand(parts: list[str]) -> bool:
    """A multi-configuration operand row: 4-letter name, two integers, then a value."""
    return (
        len(parts) >= 4
        and re.fullmatch(r"[A-Z0-9]{4}", parts[0]) is not None
        and parts[1].lstrip("-").isdigit()
        and parts[2].isdigit()
    )


# --------------------------------------------------------------------------------------------
# CODE V
# --------------------------------------------------------------------------------------------


def _seq_commands(text: str) -> list[tuple[int, list[str]]]:
    out: list[tuple[int, list[str]]] = []
    pending: list[str] = []
    start = 0
    for lineno, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("!", 1)[0]
        cont = line.rstrip().endswith("&")
        if cont:
            line = line.rstrip()[:-1]
        if not pending:
            start = lineno
        pending.append(line)
        if cont:
            continue
        for cmd in " ".join(pending).split(";"):
            toks = cmd.split()
            if toks:
                out.append((start, toks))
        pending = []
    if pending:
        for cmd in " ".join(pending).split(";"):
            if cmd.split():
                out.append((start, cmd.split()))
    return out


def parse_seq_configurations(
    text: str | bytes, *, path: str | Path | None = None
) -> Configurations:
    """The thickness zoom positions of a CODE V ``.seq`` file (module docstring). A file without
    ``ZOO THI`` gives one configuration with no changes."""
    spath = None if path is None else str(path)
    text = _text(text, spath, "a CODE V .seq file")
    scale = 1.0
    rows: dict[tuple[int, int], tuple[float, int]] = {}
    ignored: dict[str, int] = {}
    n: int | None = None
    n_line = 0
    for lineno, toks in _seq_commands(text):
        cmd = toks[0].upper()
        if cmd == "DIM" and len(toks) > 1:
            scale = _SEQ_UNITS.get(toks[1][:1].upper(), 1.0)
            continue
        if cmd not in ("ZOO", "ZOOM"):
            continue
        if len(toks) == 2:  # "ZOO n": the number of positions, when given on its own
            n_given = _int(toks[1], "ZOO", spath, lineno)
            if n is not None and n != n_given:
                raise _err(f"ZOO {n_given}: {n} positions given on line {n_line}", spath, lineno)
            n, n_line = n_given, lineno
            continue
        item = toks[1].upper()
        if item not in ("THI", "THC") or len(toks) < 4:
            ignored.setdefault(f"ZOO {item}", lineno)
            continue
        if item == "THC":
            ignored.setdefault("ZOO THC (solve/variable codes)", lineno)
            continue
        q = toks[2].upper()
        if q == "SO":
            k = 0
        elif q == "SI":
            ignored.setdefault("ZOO THI SI (image surface)", lineno)
            continue
        elif re.fullmatch(r"S\d+", q):
            k = int(q[1:])
        else:
            raise _err(
                f"ZOO THI {toks[2]}: expected a surface SO, S1, S2, ... (ranges are not read)",
                spath,
                lineno,
            )
        values = [_float(t, f"ZOO THI {q}", spath, lineno) for t in toks[3:]]
        if n is None:
            n, n_line = len(values), lineno
        elif len(values) != n:
            raise _err(
                f"ZOO THI {q}: {len(values)} values, but {n} zoom positions (line {n_line})",
                spath,
                lineno,
            )
        for j, v in enumerate(values, start=1):
            if (k, j) in rows:
                raise _err(f"ZOO THI {q} given twice", spath, lineno)
            if k == 0 and v >= ZEMAX_INFINITY:
                rows[(k, j)] = (math.inf, lineno)
            else:
                rows[(k, j)] = (v * scale, lineno)
    listing = [f"{c} (line {ln})" for c, ln in ignored.items()]
    return _build(rows, n or 1, current=1, source=spath or "", ignored=listing)


# --------------------------------------------------------------------------------------------
# TOML
# --------------------------------------------------------------------------------------------


def configurations_from_toml(
    data: dict[str, Any], *, path: str | Path | None = None, scale: float | None = None
) -> Configurations:
    """The ``[[configurations]]`` tables of a parsed TOML lens file (module docstring); none
    gives one configuration with no changes. Every length (thicknesses, finite object
    distances) is multiplied by ``scale``; None = the factor of the file's ``scale_to_efl``
    (:func:`raytrace.files.native.efl_scale`, which builds the lens; 1.0 without the key)."""
    spath = None if path is None else str(path)
    tables = data.get("configurations", [])
    if scale is None:
        from .native import efl_scale

        scale = efl_scale(data, path=spath) if tables else 1.0
    if not isinstance(tables, list) or not all(isinstance(t, dict) for t in tables):
        raise _err("configurations must be an array of tables ([[configurations]])", spath, None)
    configs = []
    for i, t in enumerate(tables, start=1):
        extra = set(t) - {"name", "thickness"}
        if extra:
            raise _err(
                f"configuration {i}: unknown key(s) {', '.join(sorted(extra))} "
                "(allowed: name, thickness)",
                spath,
                None,
            )
        name = str(t.get("name", i))
        th = t.get("thickness", {})
        if not isinstance(th, dict):
            raise _err(
                f"configuration {name!r}: thickness must be a table {{ surface = mm, ... }}",
                spath,
                None,
            )
        od = None
        pairs = []
        for key, val in th.items():
            try:
                k = int(key)
            except ValueError:
                raise _err(
                    f"configuration {name!r}: thickness key {key!r} is not a surface number",
                    spath,
                    None,
                ) from None
            if isinstance(val, str) and val.strip().lower() in ("inf", "infinity"):
                v = math.inf
            elif isinstance(val, int | float) and not isinstance(val, bool):
                v = float(val)
            else:
                raise _err(
                    f"configuration {name!r}, surface {k}: thickness must be a number in mm "
                    f'(or "inf" for the object distance), got {val!r}',
                    spath,
                    None,
                )
            if k < 0 or (math.isinf(v) and k != 0) or math.isnan(v):
                raise _err(
                    f"configuration {name!r}, surface {k}: {val!r} is not a thickness",
                    spath,
                    None,
                )
            v *= scale  # scale_to_efl: a length of the scaled lens ("inf" stays inf)
            if k == 0:
                od = v
            else:
                pairs.append((k, v))
        configs.append(Configuration(name, tuple(sorted(pairs)), od))
    if not configs:
        configs = [Configuration("1")]
    return Configurations(tuple(configs), 1, spath or "", ())


def parse_toml_configurations(
    text: str | bytes, *, path: str | Path | None = None
) -> Configurations:
    """:func:`configurations_from_toml` of TOML text."""
    spath = None if path is None else str(path)
    if isinstance(text, bytes):
        text = decode_text(text, spath, "a TOML lens prescription", latin1=False)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise _err(f"TOML syntax error: {e}", spath, None) from None
    except RecursionError:
        raise _err("the TOML nests too deeply to hold configurations", spath, None) from None
    scale = 1.0
    if "scale_to_efl" in data and data.get("configurations"):
        from .native import efl_scale

        scale = efl_scale(data, text=text, path=spath)
    return configurations_from_toml(data, path=spath, scale=scale)


def _toml_number(v: float) -> str:
    return '"inf"' if math.isinf(v) else repr(float(v))


def dumps_configurations(configurations: Configurations) -> str:
    """The ``[[configurations]]`` TOML block (full float precision), to append after a lens."""
    out = [
        "\n# Configurations: per configuration the thicknesses that differ from the surfaces\n"
        "# above (surface number = the row number; 0 = the object distance, mm from the object\n"
        '# plane to the first vertex, or "inf").\n'
    ]
    for c in configurations.configurations:
        cells = []
        if c.object_distance is not None:
            cells.append(f"0 = {_toml_number(c.object_distance)}")
        cells += [f"{k} = {_toml_number(v)}" for k, v in c.thicknesses]
        name = c.name.replace("\\", "\\\\").replace('"', '\\"')
        out.append(f'[[configurations]]\nname = "{name}"\nthickness = {{ {", ".join(cells)} }}\n')
    return "".join(out)


def dumps_with_configurations(lens: Lens, configurations: Configurations) -> str:
    """The native TOML text of ``lens`` followed by its configurations; reading it back with
    :func:`read_configured` gives the same lens and configurations."""
    from .native import dumps

    check_surfaces(lens, configurations)
    return dumps(lens) + dumps_configurations(configurations)


def write_lens_with_configurations(
    lens: Lens, configurations: Configurations, path: str | Path, **options: Any
) -> None:
    """Write :func:`dumps_with_configurations` to ``path`` atomically (``options`` as in
    :func:`raytrace.files.output.write_atomic`).

    Parameters
    ----------
    lens : Lens
    configurations : Configurations
        Configurations of ``lens``.
    path : str or Path
        The file to write (native TOML text, whatever the suffix).
    **options
        ``overwrite`` (bool: replace an existing file), ``inputs`` (files the output must not
        be), ``encoding``, ``flag`` (how messages name the override).

    Raises
    ------
    PrescriptionError
        A configuration changes a surface the lens does not have.
    OutputError
        The file cannot or must not be written (it exists without ``overwrite``, is an input,
        its folder is missing, …).
    """
    write_atomic(path, dumps_with_configurations(lens, configurations), **options)


# --------------------------------------------------------------------------------------------
# Files
# --------------------------------------------------------------------------------------------


def parse_configurations(
    text: str | bytes, *, kind: str, path: str | Path | None = None
) -> Configurations:
    """Configurations from file text; ``kind`` is ``"zmx"``, ``"seq"`` or ``"toml"``."""
    if kind == "zmx":
        return parse_zmx_configurations(text, path=path)
    if kind == "seq":
        return parse_seq_configurations(text, path=path)
    if kind == "toml":
        return parse_toml_configurations(text, path=path)
    raise PrescriptionError(f"unknown configuration file kind {kind!r} (zmx, seq or toml)")


def read_configurations(path: str | Path) -> Configurations:
    """The configurations of a lens file (.zmx, .seq, else native TOML by suffix).

    Parameters
    ----------
    path : str or Path
        A lens file path (bundled names: :func:`read_configured`): Zemax ``.zmx`` (``THIC``
        operands of the multi-configuration editor), CODE V ``.seq`` (``ZOO THI``), anything else
        but an OSLO ``.len`` (refused: it holds none that are read) native TOML
        (``[[configurations]]``). Lengths in the file's unit, returned in mm (a
        TOML file's ``scale_to_efl`` scales them with the lens).

    Returns
    -------
    Configurations

    Raises
    ------
    PrescriptionError
        Naming the file and line, for a missing or unreadable file and every problem in it.
    """
    suffix = Path(path).suffix.lower()
    if suffix == ".len":
        raise _err(
            "an OSLO .len file holds no configurations orthoscope reads: they come from a .zmx "
            "(THIC in the multi-configuration editor), a .seq (ZOO THI) or a TOML lens "
            "([[configurations]])",
            str(path),
            None,
        )
    kind = {".zmx": "zmx", ".seq": "seq"}.get(suffix, "toml")
    return parse_configurations(read_bytes(path), kind=kind, path=path)


def read_configured(path: str | Path) -> tuple[Lens, Configurations]:
    """The base lens of a file (read by :func:`raytrace.files.read_lens_file`, or a bundled
    name) and its configurations, checked to belong together.

    Parameters
    ----------
    path : str or Path
        A lens file (``.toml``, ``.zmx``, ``.seq``) or a bundled lens name.

    Returns
    -------
    (Lens, Configurations)

    Raises
    ------
    PrescriptionError
        An unknown name, a broken file, or a configuration that changes a surface the lens does
        not have.
    """
    from . import read_lens_file
    from .library import resolve_lens_path

    p = resolve_lens_path(path)
    both = _toml_configured(p)
    if both is not None:
        return both
    lens = read_lens_file(p)
    configs = read_configurations(p)
    check_surfaces(lens, configs)
    return lens, configs


def _toml_configured(p: Path) -> tuple[Lens, Configurations] | None:
    """:func:`read_configured` of a native TOML file, read, parsed and built once: the build
    gives the factor ``scale_to_efl`` scales the ``[[configurations]]`` by (reading the lens and
    the configurations apart parses the file twice and, with ``scale_to_efl``, builds the lens
    twice). None for a file of another format, or one that cannot be read or parsed (the
    ordinary path says why)."""
    from . import READ_SUFFIXES
    from .native import WHAT, build_lens

    if p.suffix.lower() in READ_SUFFIXES[1:] or p.suffix.lower() == ".zar":
        return None  # read by another reader (read_lens_file, by suffix)
    spath = str(p)
    try:
        text = decode_text(read_bytes(p), spath, WHAT, latin1=False)
        data = tomllib.loads(text)
    except (PrescriptionError, tomllib.TOMLDecodeError, RecursionError):
        return None
    try:
        lens, factor = build_lens(data, text=text, path=spath)  # checks the configurations too
    except PrescriptionError:
        from . import read_lens_file

        read_lens_file(p)  # the error it gives (with its hint for a file of another format)
        raise
    configs = configurations_from_toml(data, path=spath, scale=factor)
    check_surfaces(lens, configs)
    return lens, configs
