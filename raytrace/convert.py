"""Convert lens files between formats, chosen by the file suffix.

Readers: ``.toml`` (native, :mod:`raytrace.prescription`), ``.zmx`` (Zemax OpticStudio,
:mod:`raytrace.zemax`), ``.seq`` (CODE V, :mod:`raytrace.codev`). Writers: ``.toml`` and ``.zmx``
(CODE V ``.seq`` is read only).
"""

from __future__ import annotations

from pathlib import Path

from .errors import PrescriptionError
from .lens import Lens

READ_SUFFIXES = (".toml", ".zmx", ".seq")
WRITE_SUFFIXES = (".toml", ".zmx")


def read_any(path: str | Path) -> Lens:
    """Read a lens file of any supported format (by suffix; anything else is read as native
    TOML). Raises :class:`PrescriptionError`."""
    suffix = Path(path).suffix.lower()
    if suffix == ".zmx":
        from .zemax import read_zmx

        return read_zmx(path)
    if suffix == ".seq":
        from .codev import read_seq

        return read_seq(path)
    from .prescription import read_lens

    return read_lens(path)


def write_any(lens: Lens, path: str | Path) -> None:
    """Write ``lens`` in the format of ``path``'s suffix (``.toml`` or ``.zmx``)."""
    suffix = Path(path).suffix.lower()
    if suffix == ".zmx":
        from .zemax import write_zmx

        write_zmx(lens, path)
    elif suffix == ".toml":
        from .prescription import write_lens

        write_lens(lens, path)
    else:
        raise PrescriptionError(
            f"cannot write {suffix or 'a file without suffix'}: the output must end in "
            f"{' or '.join(WRITE_SUFFIXES)} (CODE V .seq files can be read, not written)",
            path=str(path),
        )


def convert(in_path: str | Path, out_path: str | Path) -> Lens:
    """Convert a lens file: IN (.toml, .zmx or .seq) to OUT (.toml or .zmx), formats chosen by
    the suffixes. Zemax .zmx files may be ASCII or UTF-16 (written: UTF-16, as OpticStudio
    does); glass names in .zmx/.seq are resolved through the vendor catalogs of the optional
    'glass' extra; numbers are written at full double precision, so .toml -> .zmx -> .toml
    reproduces the lens exactly. Commands that cannot be converted stop the conversion with a
    message naming the file and line; skipped non-optical ones are listed in a warning.
    Returns the lens that was written."""
    suffix = Path(out_path).suffix.lower()
    if suffix not in WRITE_SUFFIXES:
        raise PrescriptionError(
            f"cannot write {suffix or 'a file without suffix'}: the output must end in "
            f"{' or '.join(WRITE_SUFFIXES)} (CODE V .seq files can be read, not written)",
            path=str(out_path),
        )
    lens = read_any(in_path)
    write_any(lens, out_path)
    return lens
