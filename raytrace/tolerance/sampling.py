"""Seeded draws of perturbed instances: instance ``i`` of a run is the same lens whatever the
chunking, the number of workers or the host's thread count.

Generator (docs/tolerance.md, "Random numbers, determinism"): every instance has its own stream,
``numpy.random.Generator(PCG64(SeedSequence(seed, spawn_key=(i,))))`` — exactly the i-th child
of ``SeedSequence(seed).spawn(n)``, built directly from the index so that any instance can be
drawn alone. From its stream an instance draws one value per item, in the spec's item order:

* ``"normal"``: standard normal deviates ``z`` (``Generator.standard_normal``) until
  ``|z| <= sigma`` (rejection), value ``mean + z·(max − min)/(2 sigma)``;
* ``"uniform"``: ``u = Generator.random()``, value ``min + u (max − min)``;
* ``"endpoints"``: ``u = Generator.random()``, value ``min`` if ``u < 0.5`` else ``max``.

The streams are numpy's: the same numpy version gives the same draws on every platform (numpy's
policy for ``SeedSequence`` and ``PCG64``; ``standard_normal`` uses the ziggurat method of the
Generator API, stable across versions since numpy 1.17 except where numpy documents a change).
"""

from __future__ import annotations

import numpy as np

from .spec import ToleranceSpec

#: the name the outputs record for the generator
GENERATOR = "numpy PCG64, SeedSequence(seed, spawn_key=(instance,)) per instance"


def _draw_one(rng: np.random.Generator, items, out: np.ndarray) -> None:
    for k, it in enumerate(items):
        if it.distribution == "normal":
            z = rng.standard_normal()
            while abs(z) > it.sigma:
                z = rng.standard_normal()
            out[k] = it.mean + z * (it.max - it.min) / (2.0 * it.sigma)
        elif it.distribution == "uniform":
            out[k] = it.min + rng.random() * (it.max - it.min)
        else:
            out[k] = it.min if rng.random() < 0.5 else it.max


def draw_instances(spec: ToleranceSpec, seed: int, indices) -> np.ndarray:
    """The perturbation values of instances ``indices`` (a range or array of non-negative
    instance numbers) of the run with ``seed``: array (len(indices), n_items), one row per
    instance, in the items' units (:data:`raytrace.tolerance.spec.UNITS`)."""
    idx = np.asarray(indices, dtype=np.int64).ravel()
    if idx.size and idx.min() < 0:
        raise ValueError("instance numbers are non-negative")
    seed = int(seed)
    if seed < 0:
        raise ValueError(f"the seed must be a non-negative whole number, got {seed}")
    out = np.empty((idx.size, spec.n_items))
    for r, i in enumerate(idx):
        ss = np.random.SeedSequence(seed, spawn_key=(int(i),))
        _draw_one(np.random.Generator(np.random.PCG64(ss)), spec.items, out[r])
    return out


def one_at_a_time(spec: ToleranceSpec, which: str = "limits") -> tuple[np.ndarray, list[str]]:
    """The instances of a sensitivity analysis: each item alone at its ``min`` and at its
    ``max`` (``which="limits"``), the others nominal. Returns (values (2 n_items, n_items),
    labels); row 2k is item k at min, row 2k + 1 at max."""
    if which != "limits":
        raise ValueError("which must be 'limits'")
    n = spec.n_items
    v = np.zeros((2 * n, n))
    labels = []
    for k, it in enumerate(spec.items):
        v[2 * k, k] = it.min
        v[2 * k + 1, k] = it.max
        labels += [f"{it.name} min", f"{it.name} max"]
    return v, labels
