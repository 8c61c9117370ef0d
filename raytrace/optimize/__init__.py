"""Lens design optimization: specs (:mod:`.spec`; the language in ``docs/spec.md``), operands
(:mod:`.operands`), damped least squares (:mod:`.solver`), minimax by sequential linear
programming (:mod:`.minimax`; run it as ``optimize(lens, spec, method="minimax")``), the
glass-substitution pool (:mod:`.glasses`), the global search (:mod:`.global_search`) and element
splitting / adding with the spec renumbered (:mod:`.elements`). Imports
scipy; nothing else in the engine needs it."""

from .elements import SplitTrial, insert_design, scan_splits, split_design
from .glasses import GlassPool, availability, glass_pool
from .global_search import GlassChoice, GlobalResult, SearchProgress, global_optimize
from .operands import OperandValue, evaluate, merit
from .solver import OptimizationResult, apply, check_spec, optimize
from .spec import (
    METHODS,
    DesignSpec,
    GlassSettings,
    Operand,
    Pickup,
    SearchSettings,
    SpecError,
    Variable,
    parse_duration,
    read_spec,
    start_lens,
)

__all__ = [
    "METHODS",
    "DesignSpec",
    "GlassChoice",
    "GlassPool",
    "GlassSettings",
    "GlobalResult",
    "Operand",
    "OperandValue",
    "OptimizationResult",
    "Pickup",
    "SearchProgress",
    "SearchSettings",
    "SpecError",
    "SplitTrial",
    "Variable",
    "apply",
    "availability",
    "check_spec",
    "evaluate",
    "global_optimize",
    "glass_pool",
    "insert_design",
    "merit",
    "optimize",
    "parse_duration",
    "read_spec",
    "scan_splits",
    "split_design",
    "start_lens",
]
