//! Tetrahedral mesh input, validation and boundary surface.
