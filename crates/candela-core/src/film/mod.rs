//! The film: where camera-ray estimates and light-tracing splats are
//! filtered into pixels, and the pixel filters.

pub mod filter;
mod rgb_film;

pub use rgb_film::{FilmSettings, FilmTile, RgbFilm, SplatBuffer};
