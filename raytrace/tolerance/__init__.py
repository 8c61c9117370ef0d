"""Tolerancing of a lens: the tolerance spec (TOML, or the TOL lines of a .zmx file), seeded
draws of perturbed instances, the perturbation model and the instance kernels that trace many
perturbed lenses in one launch. The distortion outputs, compensators, sensitivity analysis and
Monte Carlo driver are in :mod:`distortion.tolerance`.
"""

from .model import (
    InstanceArrays,
    ParaxialBatch,
    pack_instances,
    paraxial_batch,
    perturbed_indices,
    perturbed_lens,
)
from .sampling import GENERATOR, draw_instances, one_at_a_time
from .spec import (
    COMPENSATORS,
    DISTRIBUTIONS,
    ITEM_TYPES,
    Compensator,
    ToleranceItem,
    ToleranceSpec,
    ToleranceSpecError,
    check_against_lens,
    make_item,
    read_tolerance_spec,
    spec_from_dict,
)
from .trace import InstanceChiefRays, NominalAim, aim_instances, nominal_aim, trace_instances
from .zemax_tol import ZemaxTolerances, parse_zmx_tolerances, read_zmx_tolerances

__all__ = [
    "COMPENSATORS",
    "DISTRIBUTIONS",
    "GENERATOR",
    "ITEM_TYPES",
    "Compensator",
    "InstanceArrays",
    "InstanceChiefRays",
    "NominalAim",
    "ParaxialBatch",
    "ToleranceItem",
    "ToleranceSpec",
    "ToleranceSpecError",
    "ZemaxTolerances",
    "aim_instances",
    "check_against_lens",
    "draw_instances",
    "make_item",
    "nominal_aim",
    "one_at_a_time",
    "pack_instances",
    "paraxial_batch",
    "parse_zmx_tolerances",
    "perturbed_indices",
    "perturbed_lens",
    "read_tolerance_spec",
    "spec_from_dict",
    "trace_instances",
    "read_zmx_tolerances",
]
