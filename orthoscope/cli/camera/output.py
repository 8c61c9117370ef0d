"""What ``orthoscope camera`` writes: files (``-o``, ``--picture``, ``--maps``, the table of
models) and text, JSON or CSV on stdout; the flags that set something of another flag's
output."""

from __future__ import annotations

from ..common import CliError, given_flags, print_json


def write_output(path, data, args) -> None:
    from raytrace.files.output import write_atomic

    write_atomic(path, data, inputs=args._inputs, overwrite=args.force, flag="--force")
    import sys

    print(f"wrote {path}", file=sys.stderr)


def emit(args, text: str, data: dict, csv: str | None = None, note: str | None = None) -> None:
    """Text, JSON or CSV on stdout; with CSV (which has no room for it) ``note`` — the
    projection centre — goes to stderr, so that every output states it."""
    import sys

    if args.json:
        print_json(data)
    elif getattr(args, "csv", False) and csv is not None:
        print(csv, end="" if csv.endswith("\n") else "\n")
        if note:
            print(f"orthoscope camera: note: {note}", file=sys.stderr)
    else:
        print(text)


def table_kind(path, what: str) -> str:
    """``"csv"`` or ``"json"``, by the suffix of ``-o PATH``; a CliError for any other suffix
    (``what``: what the command writes there)."""
    suffix = str(path).lower().rsplit(".", 1)[-1]
    if suffix not in ("csv", "json"):
        raise CliError(f"-o {path}: {what} is written as .csv or .json")
    return suffix


#: the flags that set something of another flag's output: the flag each needs, the attribute
#: of its value and what it sets (without that flag it would do nothing)
NEEDS = {
    "--pattern": ("--picture", "picture", "the pattern of --picture"),
    "--maps-direction": ("--maps", "maps", "the direction of --maps"),
    "--format": ("-o", "output", "the file format of -o"),
}


def refuse_idle_flags(args) -> None:
    """CliError for a flag given (:func:`given_flags`, so also at its default value) without
    the flag whose output it sets (:data:`NEEDS`)."""
    given = given_flags(args)
    for flag, (needs, dest, what) in NEEDS.items():
        if flag in given and not getattr(args, dest, None):
            raise CliError(f"{flag} sets {what}: give {needs}, or drop {flag}")


def model_table_out(args, table, kind: str | None, note: str | None = None) -> None:
    """A table of camera models per object distance: written to ``-o`` as ``kind`` (.csv or
    .json, :func:`table_kind` before the run) when given, and shown as text, JSON or CSV
    (:func:`emit`, ``note`` as there)."""
    from ...report.camera import format_model_table, model_table_csv, model_table_to_dict

    data = {"models_by_distance": model_table_to_dict(table)}
    if args.output:
        from ...report.jsonout import dumps

        text = model_table_csv(table) if kind == "csv" else dumps(data) + "\n"
        write_output(args.output, text, args)
    emit(args, format_model_table(table), data, model_table_csv(table), note)


def png_bytes(image) -> bytes:
    import cv2

    ok, buf = cv2.imencode(".png", image)
    if not ok:  # pragma: no cover - OpenCV always encodes a uint8 image
        raise CliError("OpenCV could not encode the picture as PNG")
    return buf.tobytes()


def npz_bytes(maps) -> bytes:
    import io

    import numpy as np

    buf = io.BytesIO()
    np.savez(
        buf,
        map1=maps.map1,
        map2=maps.map2,
        camera_matrix=maps.camera_matrix,
        direction=np.array(maps.direction),
        scale=np.array(maps.scale),
    )
    return buf.getvalue()
