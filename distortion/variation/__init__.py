"""Variation of radial distortion with object distance (Fraser & Shortis 1992): the models of
Brown and Fraser–Shortis (:mod:`.models`), the analysis of profiles (:mod:`.analysis`), the CSV
reader of measured profiles (:mod:`.profiles`) and the prediction from a prescription
(:mod:`.traced`)."""

from .analysis import VariationAnalysis, analyze_variation
from .models import Conjugate, brown_gamma, brown_gamma_scales, fs_predict
from .profiles import analyze_csv, read_profiles_csv
from .traced import TracedVariation, parse_conjugate, parse_conjugates, trace_variation

__all__ = [
    "Conjugate",
    "TracedVariation",
    "VariationAnalysis",
    "analyze_csv",
    "analyze_variation",
    "brown_gamma",
    "brown_gamma_scales",
    "fs_predict",
    "parse_conjugate",
    "parse_conjugates",
    "read_profiles_csv",
    "trace_variation",
]
