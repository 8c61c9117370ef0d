"""orthoscope optics engine: lens model, prescription I/O, paraxial optics, numba ray tracer."""

from .errors import DataError, LensError, OrthoscopeError, PrescriptionError, TraceError
from .lens import Aperture, Field, Lens, PackedLens, Surface, pack
from .materials import AIR, Material, fixed_index, model_glass

__all__ = [
    "AIR",
    "Aperture",
    "DataError",
    "Field",
    "Lens",
    "LensError",
    "Material",
    "OrthoscopeError",
    "PackedLens",
    "PrescriptionError",
    "Surface",
    "TraceError",
    "fixed_index",
    "model_glass",
    "pack",
]
