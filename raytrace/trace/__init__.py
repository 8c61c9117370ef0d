"""Real-ray tracing: bulk traces of any rays (:mod:`.rays`) and chief rays aimed at the centre of
the real stop (:mod:`.chief`; on a 2-D field grid: :mod:`.chief2d`). The numba kernels load on
first use."""

from ..kernels.codes import (
    STATUS_AIM_FAILED,
    STATUS_BACKWARD,
    STATUS_CLIPPED,
    STATUS_MISSED,
    STATUS_NAMES,
    STATUS_OK,
    STATUS_TIR,
)
from .chief import ChiefRays, ChromaticChiefRays, aim, chief_rays
from .chief2d import ChiefRays2D, aim_2d, chief_rays_2d
from .fans import RayFan, SpotDiagram, ray_fan, spot_diagram
from .pupil import Bundle, aimed_bundle, pupil_points
from .rays import PARALLEL_THRESHOLD, RayBatch, RayPaths, packed_lens, ray_paths, trace_rays

__all__ = [
    "PARALLEL_THRESHOLD",
    "STATUS_AIM_FAILED",
    "STATUS_BACKWARD",
    "STATUS_CLIPPED",
    "STATUS_MISSED",
    "STATUS_NAMES",
    "STATUS_OK",
    "STATUS_TIR",
    "Bundle",
    "ChiefRays",
    "ChiefRays2D",
    "aim_2d",
    "chief_rays_2d",
    "RayFan",
    "SpotDiagram",
    "aimed_bundle",
    "pupil_points",
    "ray_fan",
    "spot_diagram",
    "ChromaticChiefRays",
    "RayBatch",
    "RayPaths",
    "aim",
    "chief_rays",
    "packed_lens",
    "ray_paths",
    "trace_rays",
]
