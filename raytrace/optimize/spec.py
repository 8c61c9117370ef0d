"""Design specs: variables, pick-ups and operands with targets, read from a TOML spec file.

See :mod:`raytrace.optimize.operands` for what each operand type computes and
``lenses/specs/*.toml`` for complete examples.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import OrthoscopeError, PrescriptionError
from ..lens import Lens

VARIABLE_KINDS = ("curvature", "thickness", "index", "conic", "A4", "A6", "A8", "A10")
ASPHERIC_KINDS = ("A4", "A6", "A8", "A10")  # coefficients of r^4, r^6, r^8, r^10
OPERAND_TYPES = (
    "efl",
    "m_e",
    "HE0",
    "HpE0p",
    "distortion",
    "distortion_rel",
    "image_height",
    "best_focus",
    "rms_spot",
    "center_thickness",
    "edge_thickness",
)
INDEX_BOUNDS = (1.40, 2.05)  # glass-like bounds for index variables


class SpecError(OrthoscopeError):
    """A design spec is invalid (unknown variable, operand on a missing surface, bad bounds)."""


@dataclass(frozen=True)
class Variable:
    """A free parameter: ``kind`` of ``surface`` (1-based), within [lower, upper]."""

    kind: str
    surface: int
    lower: float = -math.inf
    upper: float = math.inf


@dataclass(frozen=True)
class Pickup:
    """``kind`` of ``surface`` := factor × (``kind`` of ``source``) + offset, applied after the
    variables (e.g. ``R5 = −R4`` is curvature 5 = −1 × curvature 4)."""

    kind: str
    surface: int
    source: int
    factor: float = 1.0
    offset: float = 0.0


@dataclass(frozen=True)
class Operand:
    """A target: ``type`` (see module docstring), ``target``, ``weight`` and its parameters."""

    type: str
    target: float = 0.0
    weight: float = 1.0
    params: dict = field(default_factory=dict)

    def label(self) -> str:
        extra = ", ".join(f"{k}={v}" for k, v in self.params.items())
        return f"{self.type}({extra})" if extra else self.type


@dataclass(frozen=True)
class DesignSpec:
    """A reproducible design: start lens, variables, pick-ups, operands, solver settings."""

    start: str
    variables: tuple[Variable, ...]
    operands: tuple[Operand, ...]
    pickups: tuple[Pickup, ...] = ()
    name: str = ""
    max_evaluations: int = 2000
    tolerance: float = 1e-12
    merit_goal: float | None = None  # a run that ends above it is reported as failed
    path: str | None = None


# ----------------------------------------------------------------------------- spec files
def _num(d: dict, key: str, where: str, default=None) -> float:
    v = d.get(key, default)
    if v is None:
        raise SpecError(f"{where}: missing '{key}'")
    if isinstance(v, str) and v.strip().lower() in ("inf", "-inf"):
        return float(v)
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise SpecError(f"{where}: '{key}' must be a number, got {v!r}")
    return float(v)


def read_spec(path: str | Path) -> DesignSpec:
    """Read a TOML design spec (see ``lenses/*.spec.toml`` for examples)::

    name = "my-design"
    start = "cooke-triplet-f4"        # bundled name or a path relative to the spec
    max_evaluations = 500
    merit_goal = 1e-6                 # optional: above it the run is a failure
    variables = [
      { kind = "curvature", surface = 1 },
      { kind = "thickness", surface = 2, min = 0.5, max = 12 },
    ]
    pickups = [ { kind = "curvature", surface = 6, source = 1, factor = -1 } ]
    operands = [
      { type = "efl", target = 50.0, weight = 10 },
      { type = "distortion", field = 20, target = 0.0, plane = "gaussian" },
    ]
    """
    p = Path(path)
    try:
        raw = p.read_bytes()
        d = tomllib.loads(raw.decode("utf-8"))
    except FileNotFoundError:
        raise SpecError(f"{p}: no such spec file") from None
    except UnicodeDecodeError:
        raise SpecError(f"{p}: not a UTF-8 text file") from None
    except tomllib.TOMLDecodeError as e:
        raise SpecError(f"{p}: {e}") from None
    known = {
        "name",
        "start",
        "variables",
        "pickups",
        "operands",
        "max_evaluations",
        "tolerance",
        "merit_goal",
        "notes",
    }
    for k in d:
        if k not in known:
            raise SpecError(f"{p}: unknown key {k!r} (known: {', '.join(sorted(known))})")
    if "start" not in d or not isinstance(d["start"], str):
        raise SpecError(f"{p}: 'start' (the start lens: bundled name or path) is required")
    variables = []
    for i, v in enumerate(d.get("variables", []), 1):
        w = f"{p}: variables[{i}]"
        if not isinstance(v, dict) or "kind" not in v or "surface" not in v:
            raise SpecError(f"{w}: needs 'kind' and 'surface'")
        extra = set(v) - {"kind", "surface", "min", "max"}
        if extra:
            raise SpecError(f"{w}: unknown key(s) {', '.join(sorted(extra))}")
        variables.append(
            Variable(
                str(v["kind"]),
                int(_num(v, "surface", w)),
                _num(v, "min", w, -math.inf),
                _num(v, "max", w, math.inf),
            )
        )
    pickups = []
    for i, v in enumerate(d.get("pickups", []), 1):
        w = f"{p}: pickups[{i}]"
        if not isinstance(v, dict):
            raise SpecError(f"{w}: must be a table")
        pickups.append(
            Pickup(
                str(v.get("kind", "")),
                int(_num(v, "surface", w)),
                int(_num(v, "source", w)),
                _num(v, "factor", w, 1.0),
                _num(v, "offset", w, 0.0),
            )
        )
    operands = []
    for i, o in enumerate(d.get("operands", []), 1):
        w = f"{p}: operands[{i}]"
        if not isinstance(o, dict) or "type" not in o:
            raise SpecError(f"{w}: needs 'type'")
        params = {k: v for k, v in o.items() if k not in ("type", "target", "weight")}
        operands.append(
            Operand(str(o["type"]), _num(o, "target", w, 0.0), _num(o, "weight", w, 1.0), params)
        )
    return DesignSpec(
        start=d["start"],
        variables=tuple(variables),
        operands=tuple(operands),
        pickups=tuple(pickups),
        name=str(d.get("name", p.stem)),
        max_evaluations=int(d.get("max_evaluations", 2000)),
        tolerance=float(d.get("tolerance", 1e-12)),
        merit_goal=None if d.get("merit_goal") is None else float(d["merit_goal"]),
        path=str(p),
    )


def start_lens(spec: DesignSpec) -> Lens:
    """Load the spec's start lens (a path relative to the spec file, or a bundled name)."""
    from ..files.library import load_lens

    if spec.path is not None:
        cand = Path(spec.path).parent / spec.start
        if cand.is_file():
            return load_lens(str(cand))
    try:
        return load_lens(spec.start)
    except PrescriptionError as e:
        raise SpecError(f"start lens {spec.start!r}: {e}") from None


