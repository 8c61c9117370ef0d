"""Lens files: the native TOML format (:mod:`.native`), Zemax ``.zmx`` (:mod:`.zemax`, read and
write), CODE V ``.seq`` (:mod:`.codev`, read), OSLO ``.len`` (:mod:`.oslo`, read), the bundled
library (:mod:`.library`) and the one atomic writer (:mod:`.output`). The format is chosen by the
file suffix.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..errors import PrescriptionError
from ..lens import Lens, require_lens

READ_SUFFIXES = (".toml", ".zmx", ".seq", ".len")
WRITE_SUFFIXES = (".toml", ".zmx")


def read_lens_file(path: str | Path, *, strict: bool = False) -> Lens:
    """Read a lens file of any supported format (by suffix; anything else is read as native
    TOML). Raises :class:`PrescriptionError`. ``strict``: a glass name that resolves only to a
    substitute (a successor, another vendor's glass, a moulded glass's parent, a model glass of
    the nd/vd the file prints; :func:`raytrace.glass.resolve_glass`) is refused instead of read
    with a warning."""
    if strict:
        from ..glass import strict_glasses

        with strict_glasses():
            return read_lens_file(path)
    suffix = Path(path).suffix.lower()
    try:
        return _read_by_suffix(path, suffix)
    except PrescriptionError as e:
        kind = _sniff(path)
        if kind is None or kind == (suffix if suffix in READ_SUFFIXES else ".toml"):
            raise
        raise PrescriptionError(
            f"{e.reason} (the file looks like {_FORMATS[kind]}: give it the suffix {kind})",
            path=e.path,
            line=e.line,
            surface=e.surface,
        ) from None


_FORMATS = {
    ".zmx": "a Zemax .zmx file",
    ".seq": "a CODE V .seq file",
    ".len": "an OSLO .len file",
    ".toml": "an orthoscope .toml file",
}


def _sniff(path: str | Path) -> str | None:
    """The suffix of the format the start of the file looks like, or None (unreadable, unclear).
    Only used to explain a failed read, never to choose a reader."""
    import re

    try:
        with open(path, "rb") as fh:
            raw = fh.read(4096)
    except OSError:
        return None
    if raw[:2] in (b"\xff\xfe", b"\xfe\xff") or raw[1:2] == b"\x00":
        text = raw.decode("utf-16", errors="ignore")
    else:
        text = raw.decode("utf-8", errors="ignore")
    lines = [ln.strip() for ln in re.split(r"[\r\n]+", text) if ln.strip()]
    heads = {ln.split()[0].upper() for ln in lines if ln.split()}
    if {"SURF", "VERS", "MODE", "UNIT"} & heads and "SURF" in heads:
        return ".zmx"
    if "SO" in heads and ("SI" in heads or "GO" in heads or "S" in heads):
        return ".seq"
    if "LEN" in heads and ("END" in heads or "UNI" in heads) and "DES" in heads:
        return ".len"
    if any(ln.startswith("surfaces") and "=" in ln for ln in lines):
        return ".toml"
    return None


def _read_by_suffix(path: str | Path, suffix: str) -> Lens:
    if suffix == ".zmx":
        from .zemax import read_zmx

        return read_zmx(path)
    if suffix == ".seq":
        from .codev import read_seq

        return read_seq(path)
    if suffix == ".len":
        from .oslo import read_len

        return read_len(path)
    if suffix == ".zar":
        raise PrescriptionError(
            "a Zemax archive (.zar) holds the lens file packed with its catalogs: unpack it "
            "(OpticStudio: File > Archive, or any ZAR extractor) and give the .zmx inside",
            path=str(path),
        )
    from .native import read_lens

    return read_lens(path)


def _check_suffix(path: str | Path) -> str:
    suffix = Path(path).suffix.lower()
    if suffix not in WRITE_SUFFIXES:
        raise PrescriptionError(
            f"cannot write {suffix or 'a file without suffix'}: the output must end in "
            f"{' or '.join(WRITE_SUFFIXES)} (CODE V .seq and OSLO .len files can be read, not "
            "written)",
            path=str(path),
        )
    return suffix


def write_lens_file(lens: Lens, path: str | Path, **options: Any) -> None:
    """Write ``lens`` in the format of ``path``'s suffix (``.toml`` or ``.zmx``), atomically;
    ``options`` (``overwrite``, ``inputs``, ``flag``) as in
    :func:`raytrace.files.output.write_atomic`. A text that would not read back (a writer's
    bug) is refused before anything is written (:func:`raytrace.files.output.check_reads_back`,
    in each writer)."""
    if _check_suffix(path) == ".zmx":
        from .zemax import write_zmx

        write_zmx(lens, path, **options)
    else:
        from .native import write_lens

        write_lens(lens, path, **options)


def save_lens(lens: Lens, path: str | Path, *, overwrite: bool = False) -> None:
    """Save ``lens`` to ``path``: native TOML (``.toml``, full precision, so reading it back gives
    the same lens) or Zemax ``.zmx``, chosen by the suffix. Written atomically; an existing file
    is replaced only with ``overwrite=True``, and never when it is the lens's own source file.

    Parameters
    ----------
    lens : Lens
    path : str or Path
        The file to write, ``.toml`` or ``.zmx``.
    overwrite : bool
        Replace an existing file (other than the lens's own source file).

    Raises
    ------
    TypeError
        ``lens`` is not a Lens (or the two arguments are swapped).
    PrescriptionError
        A suffix other than ``.toml`` or ``.zmx``.
    OutputError
        The file is the lens's source, exists without ``overwrite``, is a folder, or its folder
        is missing or not writable.
    """
    if isinstance(path, Lens) and not isinstance(lens, Lens):
        raise TypeError("save_lens(lens, path): the lens first, then the path (they are swapped)")
    require_lens(lens)
    inputs = [lens.path] if lens.path else []
    write_lens_file(lens, path, overwrite=overwrite, inputs=inputs)


def convert(
    in_path: str | Path, out_path: str | Path, *, overwrite: bool = False, **options
) -> Lens:
    """Convert a lens file: IN (.toml, .zmx or .seq, or a bundled lens name) to OUT (.toml or
    .zmx), formats chosen by the suffixes. Zemax .zmx files may be ASCII or UTF-16 (written:
    UTF-16, as OpticStudio does); numbers are written at full double precision, so .toml ->
    .zmx -> .toml reproduces the lens exactly. Commands that cannot be converted stop the
    conversion with a message naming the file and line; skipped non-optical ones are listed in
    a warning. OUT is never the same file as IN, and an existing OUT is replaced only with
    ``overwrite``. Returns the lens that was written.

    Parameters
    ----------
    in_path : str or Path
        The lens file (``.toml``, ``.zmx``, ``.seq``) or a bundled lens name.
    out_path : str or Path
        The file to write, ``.toml`` or ``.zmx``.
    overwrite : bool
        Replace an existing OUT.
    **options
        ``flag``: how messages name the override (``"--force"`` on the command line).

    Returns
    -------
    Lens
        The lens read from IN and written to OUT.

    Raises
    ------
    PrescriptionError
        OUT without a writable suffix, an unknown name, a broken IN, or commands that cannot be
        converted.
    OutputError
        OUT is IN, exists without ``overwrite``, is a folder, or its folder is missing or not
        writable.
    """
    from .library import resolve_lens_path
    from .output import check_output

    _check_suffix(out_path)
    in_path = resolve_lens_path(in_path)  # a file, or a bundled lens name (as load_lens)
    check_output(out_path, inputs=[in_path], overwrite=overwrite, **options)
    lens = read_lens_file(in_path)
    write_lens_file(lens, out_path, inputs=[in_path], overwrite=overwrite, **options)
    return lens
