"""Numba kernels of the real-ray trace. They see only contiguous float64 / int arrays and scalars;
the Python layer (:mod:`raytrace.trace`) owns objects, validation and errors.

Modules: :mod:`.codes` (status and surface-kind codes, importable without numba), :mod:`.jit`
(the ``@kernel`` decorator and its cache rules), :mod:`.surface` (intersection, refraction, one
surface step), :mod:`.forbes` (the Qbfs/Qcon basis sums, shared with :mod:`raytrace.qtype`),
:mod:`.bulk` (batches of rays), :mod:`.aim` (chief-ray aiming), :mod:`.aim2d` (chief-ray aiming
on a 2-D field grid), :mod:`.paths` (every surface intersection of a few rays),
:mod:`.instances` (many perturbed lenses in one launch, for tolerancing). Importing this package
imports none of them.
"""
