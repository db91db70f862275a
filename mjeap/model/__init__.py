"""Model data and building: the catalog (SI), sections, discretisation, the beam builders (MJCF), closed-form beam theory and linearised modes."""
