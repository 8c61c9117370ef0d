"""JSON output: the one converter from results to strict JSON.

Rules (documented in the README, "JSON"): NaN → ``null``; +inf / −inf → the strings ``"inf"`` /
``"-inf"``; numpy scalars and arrays → Python numbers and lists; tuples → lists. Keys carry their
units (``_mm``, ``_deg``, ``_nm``, ``_pct``, ``_um``).
"""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np


def jsonable(obj: Any) -> Any:
    """``obj`` with every value strict-JSON-ready (see the module docstring)."""
    if isinstance(obj, dict):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return jsonable(obj.tolist())
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        v = float(obj)
        if math.isnan(v):
            return None
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return v
    return obj


def float_list(a: Any) -> list[float]:
    """``a`` (a number or an array of any shape) flattened to a list of Python floats; NaN and
    infinities stay as they are (:func:`jsonable` converts them)."""
    return np.asarray(a, dtype=float).ravel().tolist()


def copy_fields(obj: Any, *names: str) -> dict[str, Any]:
    """The attributes ``names`` of ``obj`` under their own names, in that order, each made
    strict-JSON-ready by :func:`jsonable`: the part of a JSON dict that copies a result's fields
    as they are."""
    return {n: jsonable(getattr(obj, n)) for n in names}


def dumps(obj: Any) -> str:
    """Strict JSON text of ``obj`` (indented, UTF-8 characters kept)."""
    return json.dumps(jsonable(obj), indent=2, ensure_ascii=False, allow_nan=False)
