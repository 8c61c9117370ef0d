"""The bundled lens library: the prescription files in the repository's ``lenses/`` directory,
installed as the package ``orthoscope_lenses``.

``load_lens("topogon-us2031792-fig1")`` loads a bundled lens by name (with or without ``.toml``);
any existing file path is read as it is. ``list_lenses()`` summarises the library.
"""

from __future__ import annotations

import difflib
import importlib.resources
import math
from dataclasses import dataclass
from pathlib import Path

from ..errors import LensError, PrescriptionError
from ..lens import Field, Lens
from .native import provenance

PACKAGE = "orthoscope_lenses"


@dataclass(frozen=True)
class LensInfo:
    """One bundled lens.

    name:      the library name (file stem), what ``load_lens`` takes.
    title:     the lens's own ``name`` field.
    path:      the file.
    efl:       paraxial equivalent focal length, mm (at the lens's wavelength).
    fnumber:   infinite-conjugate f-number (EFL / EPD), None for an NA aperture.
    field:     the lens's field (``kind`` "angle" in degrees or "height" in mm).
    source:    provenance text (the patent or publication).
    kind:      "patent" | "derived" | "rescaled" (None if the file gives none).
    """

    name: str
    title: str
    path: Path
    efl: float
    fnumber: float | None
    field: Field
    source: str
    kind: str | None


def library_dir() -> Path:
    """Directory holding the bundled prescription files."""
    return Path(str(importlib.resources.files(PACKAGE)))


def bundled_file(folder: str, name: str | Path, suffix: str = ".toml") -> Path | None:
    """The bundled ``lenses/FOLDER/NAME.SUFFIX`` (``specs`` and ``tolerances`` .toml,
    ``calibrations`` .yml; ``""`` the library itself, e.g. its .csv tables) for a name as a person
    types it (spaces around it, capitals, with or without the suffix), or None when there is
    none."""
    stem = Path(name).name.strip().lower().removesuffix(suffix)
    p = library_dir() / folder / f"{stem}{suffix}"
    return p if p.is_file() else None


def bundled_or_given(path: str | Path, folder: str, suffix: str = ".toml") -> Path:
    """The file a command reads for a file argument: ``path`` itself when it exists, has a folder
    (a path with one is never a name) or a suffix other than ``suffix``; else, for a bare NAME or
    NAME.SUFFIX, the bundled ``lenses/FOLDER/NAME.SUFFIX`` (:func:`bundled_file`) when there is
    one; else ``path`` (its reader then says what is missing)."""
    p = Path(path)
    if p.exists() or p.suffix.lower() not in ("", suffix) or len(p.parts) != 1:
        return p
    return bundled_file(folder, p, suffix) or p


def bundled_names() -> list[str]:
    """Names of the bundled lenses (file stems), sorted."""
    return sorted(p.stem for p in library_dir().glob("*.toml"))


def _suggestions(query: str, names: list[str]) -> list[str]:
    """Bundled names that start with / contain the query, else the closest by spelling (whole
    name, its leading part, or one of its dash-separated words)."""
    q = Path(query).name.lower().removesuffix(".toml")
    hits = [n for n in names if n.startswith(q) or (len(q) >= 3 and q in n)]
    if hits or not q:
        return hits

    def score(n: str) -> float:
        parts = [n, n[: len(q)], *n.split("-")]
        return max(difflib.SequenceMatcher(None, q, x).ratio() for x in parts)

    scored = sorted(((score(n), n) for n in names), reverse=True)
    return [n for s, n in scored if s >= 0.75][:3]


def resolve_lens_path(name_or_path: str | Path) -> Path:
    """The file for ``name_or_path``: an existing file path wins; otherwise a bundled lens name,
    with or without ``.toml``. Raises :class:`PrescriptionError` listing the bundled names."""
    p = Path(name_or_path)
    if p.is_dir():
        raise PrescriptionError("is a directory, not a lens file", path=str(p))
    if p.exists():  # a file, or a FIFO / /dev/fd/N / process substitution
        return p
    names = bundled_names()
    key = str(name_or_path)
    stem = key.removesuffix(".toml")
    if stem in names:
        return library_dir() / f"{stem}.toml"
    sugg = _suggestions(key, names)
    did = f" (did you mean {', '.join(repr(s) for s in sugg)}?)" if sugg else ""
    raise PrescriptionError(
        f"no such file or bundled lens{did}; bundled lenses: {', '.join(names)}", path=key
    )


def load_lens(name_or_path: str | Path, *, strict: bool = False) -> Lens:
    """Load a lens: a bundled lens by name (``"topogon-us2031792-fig1"``, with or without
    ``.toml``; see ``orthoscope lenses``) or a file path (``.toml``, Zemax ``.zmx``, CODE V
    ``.seq``, chosen by suffix). An existing file path wins over a bundled name.

    Parameters
    ----------
    name_or_path : str or Path
        A bundled lens name or a lens file.
    strict : bool
        Refuse glass names that resolve only to a substitute glass (see
        :func:`raytrace.files.read_lens_file`); default False.

    Returns
    -------
    Lens
        Lengths in mm, wavelengths in nm.

    Raises
    ------
    PrescriptionError
        Naming the file, line and surface for a broken file, or listing the bundled names (with
        "did you mean") for an unknown one.
    """
    from . import read_lens_file

    return read_lens_file(resolve_lens_path(name_or_path), strict=strict)


def lens_info(lens: Lens, name: str | None = None) -> LensInfo:
    """Summary of ``lens`` (paraxial EFL and f-number at its own wavelength)."""
    from ..paraxial import paraxial

    try:
        par = paraxial(lens)
        efl, epd, f_number = float(par.efl), float(par.epd), par.f_number
    except LensError:
        efl, epd, f_number = math.nan, math.nan, math.nan
    if lens.aperture.kind == "fnumber":
        fno: float | None = lens.aperture.value
    elif lens.aperture.kind == "epd" and epd > 0:
        fno = f_number
    else:
        fno = None
    path = Path(lens.path) if lens.path else Path()
    return LensInfo(
        name=name if name is not None else (path.stem or lens.name),
        title=lens.name,
        path=path,
        efl=efl,
        fnumber=fno,
        field=lens.field,
        source=lens.source,
        kind=provenance(lens),
    )


def list_lenses() -> list[LensInfo]:
    """All bundled lenses, sorted by name (what ``orthoscope lenses`` lists).

    Returns
    -------
    list of LensInfo
        One per bundled lens: its name (what :func:`load_lens` takes), title, file, paraxial EFL
        (mm) and f-number at the lens's own wavelength, field (degrees or mm), source and kind.
    """
    return [lens_info(load_lens(n), n) for n in bundled_names()]
