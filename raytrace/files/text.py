"""What every lens-file reader shares: bytes → text, file reading, number tokens, wavelength
units, the guarded parse (nothing but :class:`~raytrace.errors.PrescriptionError` leaves a reader),
and skipped-command warnings."""

from __future__ import annotations

import codecs
import errno
import math
import re
import warnings
from collections.abc import Callable
from dataclasses import dataclass, replace
from decimal import Decimal, InvalidOperation
from pathlib import Path

from ..errors import LensError, PrescriptionError
from ..lens import Lens, check_file_lens


class InteropWarning(UserWarning):
    """A lens file held commands orthoscope skipped (listed in the message)."""


@dataclass(frozen=True)
class ImportResult:
    """A lens read from a foreign format plus the list of things that were skipped or changed
    (each entry names the line)."""

    lens: Lens
    warnings: tuple[str, ...] = ()


# --------------------------------------------------------------------------------------------
# Bytes → text
# --------------------------------------------------------------------------------------------


def decode_text(raw: bytes, path: str | None, what: str, *, latin1: bool = True) -> str:
    """Decode a lens file: UTF-8 (with or without BOM), UTF-16 LE/BE (BOM, or recognised by its
    NUL bytes, as OpticStudio writes), else Latin-1 (``latin1=False``: invalid UTF-8 is an
    error, as TOML requires). Binary data raises PrescriptionError."""
    try:
        if raw.startswith(codecs.BOM_UTF8):
            text = raw[3:].decode("utf-8")
        elif raw.startswith(codecs.BOM_UTF16_LE):
            text = raw[2:].decode("utf-16-le")
        elif raw.startswith(codecs.BOM_UTF16_BE):
            text = raw[2:].decode("utf-16-be")
        elif b"\x00" in raw:
            sample = raw[:4096]
            even = sample[0::2].count(0)
            odd = sample[1::2].count(0)
            half = max(1, len(sample) // 2)
            if odd > 0.4 * half and even < 0.05 * half:
                text = raw.decode("utf-16-le")
            elif even > 0.4 * half and odd < 0.05 * half:
                text = raw.decode("utf-16-be")
            else:
                line = raw.count(b"\n", 0, raw.index(b"\x00")) + 1
                raise PrescriptionError(
                    f"not a text file (binary data, NUL byte): expected {what}",
                    path=path,
                    line=line,
                )
        else:
            try:
                text = raw.decode("utf-8")
            except UnicodeDecodeError as e:
                if not latin1:
                    line = raw.count(b"\n", 0, e.start) + 1
                    raise PrescriptionError(
                        f"not valid UTF-8 text (byte 0x{raw[e.start]:02x} at offset {e.start}): "
                        f"expected {what}",
                        path=path,
                        line=line,
                    ) from None
                text = raw.decode("latin-1")
    except UnicodeDecodeError as e:
        nl = b"\n\x00" if b"\n\x00" in raw else b"\n"
        line = raw.count(nl, 0, e.start) + 1
        raise PrescriptionError(
            f"cannot decode the file as text ({e.reason} at byte {e.start}): expected {what}",
            path=path,
            line=line,
        ) from None
    if "\x00" in text:
        line = text.count("\n", 0, text.index("\x00")) + 1
        raise PrescriptionError(
            f"not a text file (NUL character): expected {what}", path=path, line=line
        )
    return text


#: The largest lens file read (bytes): real lens files are kilobytes; this stops /dev/zero.
MAX_FILE_BYTES = 64 * 1024 * 1024


def read_capped(path: str | Path, limit: int = MAX_FILE_BYTES) -> bytes:
    """The bytes of a file (or a pipe) that holds at most ``limit`` bytes (default
    :data:`MAX_FILE_BYTES`). A larger one raises ``OSError(errno.EFBIG, ...)``, so that every
    reader's ``OSError`` branch names it (``/dev/zero`` or a video given by mistake would
    otherwise fill the memory)."""
    with open(path, "rb") as fh:
        data = fh.read(limit + 1)
    if len(data) > limit:
        raise OSError(errno.EFBIG, f"larger than {limit // (1024 * 1024)} MB, too large to read")
    return data


def read_bytes(path: str | Path) -> bytes:
    """Read a lens file (or a pipe) with :func:`read_capped`, turning OS errors into
    PrescriptionError."""
    p = Path(path)
    try:
        return read_capped(p)
    except FileNotFoundError:
        raise PrescriptionError("no such file", path=str(p)) from None
    except IsADirectoryError:
        raise PrescriptionError("is a directory, not a lens file", path=str(p)) from None
    except OSError as e:
        if e.errno == errno.EFBIG:
            raise PrescriptionError(f"{e.strerror}: not a lens file", path=str(p)) from None
        raise PrescriptionError(f"cannot read: {e.strerror}", path=str(p)) from None


def number(tok: str, what: str, err, line: int, *, allow_inf: bool = False) -> float:
    """Parse a finite float token (``INFINITY``/``INF`` → inf when ``allow_inf``)."""
    t = tok.strip()
    if allow_inf and t.upper() in ("INFINITY", "INF", "+INF", "+INFINITY"):
        return math.inf
    try:
        v = float(t)
    except (ValueError, OverflowError):
        raise err(f"{what}: expected a number, got {tok[:40]!r}", line) from None
    if not math.isfinite(v):
        if allow_inf and v == math.inf:
            return v
        raise err(f"{what}: expected a finite number, got {tok[:40]!r}", line)
    return v


def micron_to_nm(tok: str, err, line: int, what: str) -> float:
    """µm token → nm, by a decimal shift (so that nm → µm text → nm is exact)."""
    try:
        d = Decimal(tok.strip())
    except (InvalidOperation, ValueError):
        raise err(f"{what}: expected a wavelength in µm, got {tok[:40]!r}", line) from None
    if not d.is_finite():
        raise err(f"{what}: expected a finite wavelength in µm, got {tok[:40]!r}", line)
    try:
        return float(d.scaleb(3))
    except (OverflowError, InvalidOperation):
        raise err(f"{what}: wavelength out of range: {tok[:40]!r}", line) from None


def nm_to_micron_text(nm: float) -> str:
    """nm → µm text by a decimal shift of ``repr`` (inverse of :func:`micron_to_nm`)."""
    return format(Decimal(repr(float(nm))).scaleb(-3), "f")


def guarded_parse(parser, text: str | bytes, path: str | Path | None, what: str) -> ImportResult:
    """Decode ``text`` if it is bytes and run ``parser(text, path).parse()``, so that nothing but
    a PrescriptionError (with the file and a line) ever leaves a reader."""
    spath = None if path is None else str(path)
    if isinstance(text, bytes):
        text = decode_text(text, spath, what)
    try:
        return parser(text, spath).parse()
    except PrescriptionError:
        raise
    except (ValueError, ArithmeticError, RecursionError, MemoryError) as e:  # pragma: no cover
        raise PrescriptionError(
            f"cannot read the file ({type(e).__name__}: {e})", path=spath, line=1
        ) from None


def lens_error(err, e: Exception, surface_lines: list[int], default_line: int | None):
    """Map a LensError/ValueError from the Lens constructor to ``err(message, line, surface)``,
    using the surface number in the message to find the line."""
    msg = str(e)
    m = re.search(r"surface (\d+): ", msg)
    if m and 1 <= int(m.group(1)) <= len(surface_lines):
        no = int(m.group(1))
        return err(f"invalid lens: {msg[m.end() :]}", surface_lines[no - 1], no)
    return err(f"invalid lens: {msg}", default_line)


def solve_paraxial_image(
    lens: Lens,
    err,
    surface_lines: list[int],
    line: int,
    refusal: Callable[[float], str],
    *,
    trace_error: Callable[[Exception], Exception] | None = None,
) -> Lens:
    """The lens with its image plane at the paraxial image of its own object: a file's paraxial
    image solve (CODE V ``PIM``, OSLO ``PY 0``, the native ``t = "gaussian"``). A paraxial trace
    that fails raises ``trace_error(e)`` (default: :func:`lens_error` with ``surface_lines``); an
    image at infinity or virtual (before the last vertex) raises ``err(refusal(d), line)``, ``d``
    the distance from the last vertex (mm)."""
    from ..paraxial import paraxial

    try:
        d = float(paraxial(lens.with_image_distance(0.0)).gaussian_image_distance)
    except (LensError, ValueError, ArithmeticError) as e:
        if trace_error is not None:
            raise trace_error(e) from None
        raise lens_error(err, e, surface_lines, line) from None
    if not (math.isfinite(d) and d * lens.image_direction >= 0.0):
        raise err(refusal(d), line)
    return replace(lens.with_image_distance(d), image_solve="gaussian")


def emit_warnings(result: ImportResult, path: str | None) -> Lens:
    if result.warnings:
        where = f"{path}: " if path else ""
        warnings.warn(where + "; ".join(result.warnings), InteropWarning, stacklevel=3)
    return result.lens


#: at most this many warnings are kept per file read
MAX_WARNINGS = 50


class LineParser:
    """What the line-based readers (.zmx, .seq, .len) share: the file's text and path, the
    warnings (at most :data:`MAX_WARNINGS`), the unknown commands, and errors that name the file,
    the line and the surface. ``ITEM`` names a missing number in messages."""

    ITEM = "value"

    def __init__(self, text: str, path: str | None) -> None:
        self.text = text
        self.path = path
        self.warnings: list[str] = []
        self.unknown: dict[str, int] = {}

    def err(self, message: str, line: int | None, surface: int | None = None) -> PrescriptionError:
        return PrescriptionError(message, path=self.path, line=line or 1, surface=surface)

    def fail(self, message: str, line: int | None) -> PrescriptionError:
        return self.err(message, line)

    def warn(self, message: str) -> None:
        if len(self.warnings) < MAX_WARNINGS:
            self.warnings.append(message)

    def warn_unknown(self) -> None:
        """One warning naming the unknown commands skipped (the first 30, with their lines)."""
        if self.unknown:
            listing = ", ".join(f"{c} (line {ln})" for c, ln in list(self.unknown.items())[:30])
            self.warn(f"unknown commands skipped: {listing}")

    def file_lens(self, surface_lines: list[int], line: int, **kw) -> Lens:
        """``Lens(**kw)`` checked as a lens read from a file (:func:`check_file_lens`); what the
        constructor or the check refuses raises through :func:`lens_error` (``surface_lines``: the
        line of each surface; ``line`` where the message names no surface)."""
        try:
            lens = Lens(**kw)
            check_file_lens(lens)
        except (LensError, ValueError) as e:
            raise lens_error(self.err, e, surface_lines, line) from None
        return lens

    def num(self, args: list[str], i: int, cmd: str, line: int, *, allow_inf=False) -> float:
        """Number ``i`` of a command's arguments (finite; ``inf`` when ``allow_inf``)."""
        if i >= len(args):
            raise self.err(f"{cmd} needs a number ({self.ITEM} {i + 1} is missing)", line)
        return number(args[i], cmd, self.fail, line, allow_inf=allow_inf)
