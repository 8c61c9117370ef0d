"""Distortion analysis (Pestrecov 1958; Fraser & Shortis 1992) and the orthoscope CLI."""
