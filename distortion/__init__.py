"""The science of the two papers: Pestrecov (1958) characteristic and calibrated distortion in any
image plane and compensation; Fraser & Shortis (1992) variation with object distance; radial
distortion coefficients. Imports :mod:`raytrace`, never the CLI or the report layer."""

from .calibration import METHODS, CalibrationResult, calibrate
from .characteristic import REFERENCES, CharacteristicDistortion, characteristic_distortion
from .compensation import CompensationResult, compensate
from .curve import DistortionCurve, make_curve
from .errors import CalibrationError, DataError
from .tablefile import read_distortion_table

__all__ = [
    "METHODS",
    "REFERENCES",
    "CalibrationError",
    "CalibrationResult",
    "CharacteristicDistortion",
    "CompensationResult",
    "DataError",
    "DistortionCurve",
    "calibrate",
    "characteristic_distortion",
    "compensate",
    "make_curve",
    "read_distortion_table",
]
