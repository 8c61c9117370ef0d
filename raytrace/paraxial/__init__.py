"""Paraxial optics: first-order data of a centred lens and the one y-nu trace (:mod:`.firstorder`),
Pestrecov's constants of orthoscopy (:mod:`.orthoscopy`) and the object / image-plane vocabulary
(:mod:`.conjugates`). No numba here: paraxial-only commands stay fast to start."""

from .conjugates import (
    ImagePlane,
    checked_wavelength,
    image_planes,
    object_distance_for_s,
    object_distance_for_scale,
    plane_z,
    resolve_object_distance,
    resolve_paraxial,
)
from .firstorder import (
    ParaxialResult,
    element_power,
    gaussian_solved,
    paraxial,
    ynu_matrix,
    ynu_trace,
)
from .orthoscopy import (
    PestrecovConstants,
    distortion_slope,
    ideal_heights,
    orthoscopy_abscissa,
    orthoscopy_constant_slope,
    orthoscopy_constants,
    paraxial_chief_heights,
    pestrecov_constants,
)

__all__ = [
    "ImagePlane",
    "ParaxialResult",
    "PestrecovConstants",
    "checked_wavelength",
    "distortion_slope",
    "element_power",
    "gaussian_solved",
    "ideal_heights",
    "image_planes",
    "object_distance_for_s",
    "object_distance_for_scale",
    "orthoscopy_abscissa",
    "orthoscopy_constant_slope",
    "orthoscopy_constants",
    "paraxial",
    "paraxial_chief_heights",
    "pestrecov_constants",
    "plane_z",
    "resolve_object_distance",
    "resolve_paraxial",
    "ynu_matrix",
    "ynu_trace",
]
