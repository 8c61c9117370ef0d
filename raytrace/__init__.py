"""orthoscope's optics engine, in pipeline order: lens files (:mod:`.files`) → the validated
:class:`Lens` (:mod:`.lens`, :mod:`.materials`, :mod:`.glass`) → paraxial optics
(:mod:`.paraxial`) → packed arrays (:mod:`.packing`) → numba kernels (:mod:`.kernels`) → real-ray
traces and chief rays (:mod:`.trace`); plus the design optimizer (:mod:`.optimize`).

The user-facing API is the top-level package :mod:`orthoscope`; this package never imports the
distortion package or the CLI.
"""

from .errors import LensError, OrthoscopeError, OutputError, PrescriptionError, TraceError
from .lens import Aperture, Field, Lens, Surface
from .materials import AIR, Material, fixed_index, model_glass

__all__ = [
    "AIR",
    "Aperture",
    "Field",
    "Lens",
    "LensError",
    "Material",
    "OrthoscopeError",
    "OutputError",
    "PrescriptionError",
    "Surface",
    "TraceError",
    "fixed_index",
    "model_glass",
]
