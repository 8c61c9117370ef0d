"""Tolerancing distortion: how much the distortion of manufactured lenses scatters
and which tolerance drives it — the outputs of many perturbed instances computed together
(:mod:`.outputs`), compensators (:mod:`.compensators`), sensitivity analysis
(:mod:`.sensitivity`), Fraser & Shortis's g_ss' per instance (:mod:`.gfactor`) and a seeded,
chunked, resumable Monte Carlo on this machine or a Dask cluster (:mod:`.montecarlo`) whose
summary can be streamed (:mod:`.summary`). Specs and the perturbation model:
:mod:`raytrace.tolerance`.
"""

from .compensators import best_focus_planes, image_planes, pupil_bundle
from .montecarlo import MonteCarloResult, monte_carlo, run_chunk
from .outputs import (
    CURVES,
    SCALARS,
    ToleranceOutputs,
    ToleranceSetup,
    default_fields,
    evaluate,
    prepare,
)
from .sensitivity import SensitivityResult, sensitivity
from .summary import StreamedSummary, StreamingSummary

#: the names under which ``import orthoscope`` offers the two entry points
tolerance_sensitivity = sensitivity
tolerance_monte_carlo = monte_carlo

__all__ = [
    "CURVES",
    "SCALARS",
    "MonteCarloResult",
    "SensitivityResult",
    "StreamedSummary",
    "StreamingSummary",
    "ToleranceOutputs",
    "ToleranceSetup",
    "best_focus_planes",
    "default_fields",
    "evaluate",
    "image_planes",
    "monte_carlo",
    "prepare",
    "pupil_bundle",
    "run_chunk",
    "sensitivity",
    "tolerance_monte_carlo",
    "tolerance_sensitivity",
]
