//! The film: where camera-ray estimates are filtered into pixels.
//!
//! This module is shared: the pixel filters live in [`filter`]; the film
//! itself is added by its owner.

pub mod filter;
