//! Tests of intersection, error bounds and sampling for all shapes.
