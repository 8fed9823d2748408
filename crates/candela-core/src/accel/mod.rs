//! Acceleration structures for ray queries over many primitives.
