"""Figures: distortion charts in the style of Pestrecov's figures (:mod:`.distortion`), the
variation study of Fraser & Shortis (:mod:`.variation`), the lens layout (:mod:`.layout`), and
saving (:mod:`.save`). Only this package imports matplotlib."""
