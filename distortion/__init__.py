"""The science of the two papers: Pestrecov (1958) characteristic and calibrated distortion in any
image plane and compensation; Fraser & Shortis (1992) variation with object distance; radial
distortion coefficients. Imports :mod:`raytrace`, never the CLI or the report layer."""

from typing import TYPE_CHECKING

from raytrace.lazy import lazy_names

#: public name -> submodule; loaded on first use, so that importing one submodule (e.g. the
#: names of the definitions for the command line's choices) does not load the others
_NAMES: dict[str, str] = {
    "METHODS": ".calibration",
    "CalibrationResult": ".calibration",
    "calibrate": ".calibration",
    "REFERENCES": ".characteristic",
    "CharacteristicDistortion": ".characteristic",
    "characteristic_distortion": ".characteristic",
    "CompensationResult": ".compensation",
    "compensate": ".compensation",
    "DistortionCurve": ".curve",
    "make_curve": ".curve",
    "CalibrationError": ".errors",
    "DataError": ".errors",
    "read_distortion_table": ".tablefile",
}

if TYPE_CHECKING:
    from .calibration import METHODS, CalibrationResult, calibrate
    from .characteristic import REFERENCES, CharacteristicDistortion, characteristic_distortion
    from .compensation import CompensationResult, compensate
    from .curve import DistortionCurve, make_curve
    from .errors import CalibrationError, DataError
    from .tablefile import read_distortion_table


__getattr__, __dir__ = lazy_names(__name__, _NAMES)

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
