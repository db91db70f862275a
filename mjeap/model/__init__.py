"""Model data and building: the catalog (SI), sections, discretisation, the beam builders (MJCF), closed-form beam theory and linearised modes."""

from . import mjcf, rod  # noqa: E402,F401  (the beam builders register: hinge and cable in mjcf, the rod)
