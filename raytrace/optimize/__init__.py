"""Lens design optimization: specs (:mod:`.spec`), operands (:mod:`.operands`), the damped
least-squares solver (:mod:`.solver`). Imports scipy; nothing else in the engine needs it."""

from .operands import OperandValue, evaluate, merit
from .solver import OptimizationResult, apply, check_spec, optimize
from .spec import DesignSpec, Operand, Pickup, SpecError, Variable, read_spec, start_lens

__all__ = [
    "DesignSpec",
    "Operand",
    "OperandValue",
    "OptimizationResult",
    "Pickup",
    "SpecError",
    "Variable",
    "apply",
    "check_spec",
    "evaluate",
    "merit",
    "optimize",
    "read_spec",
    "start_lens",
]
