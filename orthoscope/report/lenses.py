"""Text and JSON of the bundled-lens list (``orthoscope lenses``)."""

from __future__ import annotations

from typing import Any

from raytrace.files.library import LensInfo
from raytrace.lens import Field


def _field_text(f: Field) -> str:
    return f"{f.value:g} deg" if f.kind == "angle" else f"{f.value:g} mm"


def format_lens_table(infos: list[LensInfo]) -> str:
    """Plain-text table of the library (name, EFL mm, f-number, half-field, kind, source)."""
    head = ("name", "EFL mm", "f/#", "field", "kind", "source")
    rows = [
        (
            i.name,
            f"{i.efl:.2f}",
            "-" if i.fnumber is None else f"{i.fnumber:g}",
            _field_text(i.field),
            i.kind or "-",
            i.source,
        )
        for i in infos
    ]
    widths = [max(len(r[j]) for r in [head, *rows]) for j in range(5)]
    lines = []
    for r in [head, *rows]:
        lines.append("  ".join(r[j].ljust(widths[j]) for j in range(5)) + "  " + r[5])
    return "\n".join(lines)


def lens_infos_to_dict(infos: list[LensInfo]) -> list[dict[str, Any]]:
    """JSON-ready list of the library entries."""
    return [
        {
            "name": i.name,
            "title": i.title,
            "path": str(i.path),
            "efl_mm": i.efl,
            "fnumber": i.fnumber,
            "field": {"kind": i.field.kind, "value": i.field.value},
            "source": i.source,
            "kind": i.kind,
        }
        for i in infos
    ]
