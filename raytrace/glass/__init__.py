"""Glass catalogs shipped as data, dispersion formulas, air index and temperature effects.

Lens files from Zemax and CODE V name their glasses (``N-SK16``, ``NSK16_SCHOTT``, ``S-BSL7``).
:func:`lookup_glass` resolves such a name in the shipped catalogs (Schott, Ohara, Hoya, CDGM,
Hikari, Sumita, and ``Misc`` for fused silica, crystals, window glasses and optical plastics;
see :mod:`.catalog`) to a :class:`CatalogGlass`, whose ``.material`` computes the vendor's own
dispersion formula (:mod:`.formulas`) at any wavelength — relative to air at the catalog's
reference conditions (:mod:`.air`); other temperatures and pressures through Schott's dn/dT
model (:mod:`.thermal`). :func:`search_glass` finds the catalog glasses nearest to an nd/vd pair.

A name found in several catalogs with different nd/vd is ambiguous: the error lists the
candidates and how to pick one (a catalog suffix ``_SCHOTT``, a Zemax ``GCAT`` line, or a model
glass). Six-digit glass codes (``620603`` → nd 1.620, vd 60.3) and ``nd:vd`` strings are parsed
by :func:`parse_glass_code` without any catalog. The file readers resolve names through
:func:`resolve_glass` (:mod:`.legacy`): the file's catalogs first, then Schott's ``N-``
successors of old glasses, the parents of moulded glasses and the nd/vd a file prints, each
substitution with a warning (refused in a strict reading, :func:`strict_glasses`).
"""

from ..materials import OutOfRangeError, OutOfRangeWarning
from .air import absolute_to_relative, air_index, relative_to_absolute
from .catalog import (
    CATALOGS,
    DATA_FILE,
    PRIVATE,
    CatalogGlass,
    GlassMatch,
    catalog_available,
    catalog_glasses,
    catalog_sources,
    find_glass,
    lookup_glass,
    normalize_name,
    parse_glass_code,
    private_material,
    search_glass,
    split_catalog_suffix,
)
from .formulas import FORMULAS, evaluate
from .legacy import (
    GlassResolution,
    ModelGlassError,
    model_glass_error,
    printed_nd_vd,
    resolve_glass,
    strict_glasses,
)
from .thermal import delta_n_absolute, dn_dt_absolute, index_at

__all__ = [
    "CATALOGS",
    "DATA_FILE",
    "FORMULAS",
    "CatalogGlass",
    "GlassMatch",
    "GlassResolution",
    "ModelGlassError",
    "OutOfRangeError",
    "OutOfRangeWarning",
    "PRIVATE",
    "absolute_to_relative",
    "air_index",
    "catalog_available",
    "catalog_glasses",
    "catalog_sources",
    "delta_n_absolute",
    "dn_dt_absolute",
    "evaluate",
    "find_glass",
    "index_at",
    "lookup_glass",
    "model_glass_error",
    "normalize_name",
    "parse_glass_code",
    "printed_nd_vd",
    "private_material",
    "relative_to_absolute",
    "resolve_glass",
    "search_glass",
    "split_catalog_suffix",
    "strict_glasses",
]
