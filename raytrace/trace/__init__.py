"""Real-ray tracing: bulk traces of any rays (:mod:`.rays`) and chief rays aimed at the centre of
the real stop (:mod:`.chief`; on a 2-D field grid: :mod:`.chief2d`). The names load on first use
(a command that aims chief rays does not import the fans or the 2-D grid), and the numba kernels
with them."""

from typing import TYPE_CHECKING

from ..kernels.codes import (
    STATUS_AIM_FAILED,
    STATUS_BACKWARD,
    STATUS_CLIPPED,
    STATUS_MISSED,
    STATUS_NAMES,
    STATUS_OK,
    STATUS_TIR,
)
from ..lazy import lazy_names

#: public name -> submodule, loaded on first use
_NAMES: dict[str, str] = {
    **dict.fromkeys(("ChiefRays", "ChromaticChiefRays", "aim", "chief_rays"), ".chief"),
    **dict.fromkeys(("ChiefRays2D", "aim_2d", "chief_rays_2d"), ".chief2d"),
    **dict.fromkeys(("RayFan", "SpotDiagram", "ray_fan", "spot_diagram"), ".fans"),
    **dict.fromkeys(("Bundle", "aimed_bundle", "pupil_points"), ".pupil"),
    **dict.fromkeys(
        ("PARALLEL_THRESHOLD", "RayBatch", "RayPaths", "packed_lens", "ray_paths", "trace_rays"),
        ".rays",
    ),
}

if TYPE_CHECKING:
    from .chief import ChiefRays, ChromaticChiefRays, aim, chief_rays
    from .chief2d import ChiefRays2D, aim_2d, chief_rays_2d
    from .fans import RayFan, SpotDiagram, ray_fan, spot_diagram
    from .pupil import Bundle, aimed_bundle, pupil_points
    from .rays import PARALLEL_THRESHOLD, RayBatch, RayPaths, packed_lens, ray_paths, trace_rays


__getattr__, __dir__ = lazy_names(__name__, _NAMES)

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
