"""What the ray-trace results share: the reading of the kernels' status codes
(:mod:`raytrace.kernels.codes`) for every result that carries a ``status`` array (``ok``,
``n_failed``, :func:`status_name`), and the words their summaries use for fields and objects."""

from __future__ import annotations

import math

import numpy as np

from ..kernels.codes import STATUS_NAMES, STATUS_OK


def status_name(code: int) -> str:
    """The word for a status code (``"ok"``, ``"aim_failed"``, ...); an unknown code as its
    number."""
    return STATUS_NAMES.get(int(code), str(int(code)))


class RayStatus:
    """Mixin for a ray result with a ``status`` array of status codes (any shape): ``ok`` and
    the count of failed rays."""

    @property
    def ok(self) -> np.ndarray:
        """Boolean mask, shaped like ``status``, of the rays whose status is OK (they reached
        the last surface)."""
        return self.status == STATUS_OK

    @property
    def n_failed(self) -> int:
        """How many rays failed (status not OK)."""
        return int(np.count_nonzero(self.status != STATUS_OK))


def field_unit(field_kind: str) -> str:
    """The unit of fields of ``field_kind``: ``"mm"`` for object heights (``"height"``), else
    ``"deg"`` (angles and nominal angles)."""
    return "mm" if field_kind == "height" else "deg"


def object_words(object_distance: float) -> str:
    """The object plane in a summary: ``"inf"`` for an object at infinity, else ``"<d> mm"``
    (the distance from the first vertex)."""
    return "inf" if math.isinf(object_distance) else f"{object_distance:g} mm"
