"""Real-ray tracing: bulk traces of any rays (:mod:`.rays`) and chief rays aimed at the centre of
the real stop (:mod:`.chief`). The numba kernels load on first use."""

from ..kernels.codes import (
    STATUS_AIM_FAILED,
    STATUS_CLIPPED,
    STATUS_MISSED,
    STATUS_NAMES,
    STATUS_OK,
    STATUS_TIR,
)
from .chief import ChiefRays, aim, chief_rays
from .rays import PARALLEL_THRESHOLD, RayBatch, RayPaths, packed_lens, ray_paths, trace_rays

__all__ = [
    "PARALLEL_THRESHOLD",
    "STATUS_AIM_FAILED",
    "STATUS_CLIPPED",
    "STATUS_MISSED",
    "STATUS_NAMES",
    "STATUS_OK",
    "STATUS_TIR",
    "ChiefRays",
    "RayBatch",
    "RayPaths",
    "aim",
    "chief_rays",
    "packed_lens",
    "ray_paths",
    "trace_rays",
]
