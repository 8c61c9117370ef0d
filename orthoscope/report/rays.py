"""Text, JSON and CSV of ray fans and spot diagrams (``orthoscope fan``, ``orthoscope spot``).

A field that cannot be traced comes as a :class:`NotTraced` in place of its fan or spot: it is
reported (its status word, e.g. ``aim_failed``, in the text, under ``field_status`` in a fan's
JSON, ``status`` in a spot's, and in the CSV's ``status`` column) and its values are empty.
"""

from __future__ import annotations

from dataclasses import dataclass

from raytrace.trace import RayFan, SpotDiagram
from raytrace.trace.fans import FieldNotTracedError
from raytrace.trace.results import status_name

from .text import csv_text, untraced


@dataclass(frozen=True)
class NotTraced:
    """A field of ``fan`` or ``spot`` that could not be traced: the API's error for it, and (for
    a fan) the fan's axis ("y" or "x")."""

    error: FieldNotTracedError
    axis: str | None = None

    def __getattr__(self, name):  # field, field_kind, status, ... of the error
        if name == "error":
            raise AttributeError(name)
        return getattr(self.error, name)


def _field(f) -> str:
    return f"{f.field:g} deg" if f.field_kind == "angle" else f"object height {f.field:g} mm"


def _field_keys(f) -> dict:
    """The field as the trace JSON keys it (``angle_deg`` or ``object_height_mm``: the unit in
    the key, README "JSON output"), after the unitless ``field`` / ``field_kind`` pair."""
    unit_key = "angle_deg" if f.field_kind == "angle" else "object_height_mm"
    return {"field": f.field, "field_kind": f.field_kind, unit_key: f.field}


def _where(f) -> dict:
    return {
        "object_distance_mm": f.object_distance,
        "image_plane_z_mm": f.z_plane,
        "chief_height_mm": None if isinstance(f, NotTraced) else f.chief_height,
        "wavelength_nm": f.wavelength,
    }


def _field_status(items) -> tuple[list[float], list[int]]:
    """(fields, status codes) of ``items``, for :func:`~orthoscope.report.text.untraced` and
    ``--strict``: 0 for a traced field."""
    return [i.field for i in items], [i.status if isinstance(i, NotTraced) else 0 for i in items]


def field_status(items) -> list[int]:
    """The status code of each item's field (0: traced) for ``--strict``."""
    return _field_status(items)[1]


def _axis_word(axis: str) -> str:
    return "tangential" if axis == "y" else "sagittal"


def fan_to_dict(f: RayFan | NotTraced) -> dict:
    if isinstance(f, NotTraced):
        return {
            "axis": _axis_word(f.axis),
            **_field_keys(f),
            **_where(f),
            "field_status": f.status_name,
            "pupil": [],
            "eps_x_mm": [],
            "eps_y_mm": [],
            "status": [],
        }
    return {
        "axis": _axis_word(f.axis),
        **_field_keys(f),
        **_where(f),
        "field_status": "ok",
        "pupil": f.pupil.tolist(),
        "eps_x_mm": f.ex.tolist(),
        "eps_y_mm": f.ey.tolist(),
        "status": [status_name(c) for c in f.status],
    }


def format_fans(fans: list[RayFan | NotTraced]) -> str:
    out = []
    for f in fans:
        kind = "tangential (eps_y vs py)" if f.axis == "y" else "sagittal (eps_x vs px)"
        if isinstance(f, NotTraced):
            out.append(
                f"Ray fan, {kind}, field {_field(f)}, {f.wavelength:g} nm: not traced "
                f"({f.status_name}: the real chief ray fails)"
            )
            out.append("")
            continue
        out.append(
            f"Ray fan, {kind}, field {_field(f)}, {f.wavelength:g} nm; image plane z = "
            f"{f.z_plane:.6f} mm, chief ray at y = {f.chief_height:.6f} mm"
        )
        out.append(f"{'pupil':>8} {'eps (um)':>12}")
        for p, e, s in zip(f.pupil, f.aberration, f.status, strict=True):
            out.append(
                f"{p:8.3f} {1000 * e:12.4f}" if s == 0 else f"{p:8.3f} {'-':>12}  {status_name(s)}"
            )
        out.append("")
    return "\n".join(out).rstrip()


def fans_csv(fans: list[RayFan | NotTraced]) -> str:
    rows = []
    for f in fans:
        if isinstance(f, NotTraced):  # one row: the field, no ray, the field's status
            rows.append([f.axis, f.field, None, None, None, f.status_name])
            continue
        rows += [
            [f.axis, f.field, p, ex, ey, status_name(s)]
            for p, ex, ey, s in zip(f.pupil, f.ex, f.ey, f.status, strict=True)
        ]
    return csv_text(["axis", "field", "pupil", "eps_x_mm", "eps_y_mm", "status"], rows)


def spot_to_dict(s: SpotDiagram | NotTraced) -> dict:
    if isinstance(s, NotTraced):
        return {
            **_field_keys(s),
            **_where(s),
            "status": s.status_name,
            "rays": s.rays,
            "rays_ok": 0,
            "centroid_x_mm": None,
            "centroid_y_mm": None,
            "rms_radius_mm": None,
            "geometric_radius_mm": None,
            "x_mm": [None] * s.rays,
            "y_mm": [None] * s.rays,
        }
    return {
        **_field_keys(s),
        **_where(s),
        "status": "ok",
        "rays": int(s.x.size),
        "rays_ok": s.n_ok,
        "centroid_x_mm": s.centroid_x,
        "centroid_y_mm": s.centroid_y,
        "rms_radius_mm": s.rms_radius,
        "geometric_radius_mm": s.geometric_radius,
        "x_mm": s.x.tolist(),
        "y_mm": s.y.tolist(),
    }


def format_spots(spots: list[SpotDiagram | NotTraced]) -> str:
    out = [
        "Spot diagrams (relative to the real chief ray; RMS and geometric radius about the "
        "centroid)",
        f"{'field':>22} {'rays':>9} {'centroid y (um)':>16} {'RMS (um)':>10} {'geo (um)':>10}",
    ]
    for s in spots:
        if isinstance(s, NotTraced):
            rays = f"0/{s.rays}"
            out.append(f"{_field(s):>22} {rays:>9} {'-':>16} {'-':>10} {'-':>10}  {s.status_name}")
            continue
        out.append(
            f"{_field(s):>22} {s.n_ok:>4}/{s.x.size:<4} {1000 * s.centroid_y:16.4f} "
            f"{1000 * s.rms_radius:10.4f} {1000 * s.geometric_radius:10.4f}"
        )
    return "\n".join(out + untraced(*_field_status(spots)))


def spots_csv(spots: list[SpotDiagram | NotTraced]) -> str:
    rows = [
        [s.field, 0, None, None, None, None, s.status_name]
        if isinstance(s, NotTraced)
        else [s.field, s.n_ok, s.centroid_x, s.centroid_y, s.rms_radius, s.geometric_radius, "ok"]
        for s in spots
    ]
    head = [
        "field",
        "rays_ok",
        "centroid_x_mm",
        "centroid_y_mm",
        "rms_radius_mm",
        "geometric_radius_mm",
        "status",
    ]
    return csv_text(head, rows)
