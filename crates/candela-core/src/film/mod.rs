//! The film: where passes leave their estimates and images are developed.
//!
//! [`Film`] is the film's configuration (resolution, crop, filter, sensor,
//! output colour space and the layers it records, [`layout`]). A pass
//! renders into a [`PassBlock`] (f64, assembled from [`FilmTile`]s and
//! [`SplatBuffer`]s in a fixed order), which [`FilmState::add_pass`] adds in
//! fixed point ([`fixed`]), so the accumulated state of any split of the
//! passes merges into the bits of one run. [`develop`] turns a state into
//! named image channels: pbrt-v4's `rgb`, `gbuffer` and `spectral` films and
//! candela's `--aov` layers (Mitsuba 3's film/image-block split: estimators
//! write samples to a block; the film decides channels and development).
//!
//! A sample's spectral radiance L(λ) at the path's wavelengths is turned into
//! sensor RGB by the pixel sensor (for the default `cie1931` sensor: the
//! Monte Carlo estimate of XYZ times the imaging ratio), clamped to
//! `maxcomponentvalue`, and added with its filter weight.

mod bands;
mod block;
pub mod develop;
pub mod filter;
pub mod fixed;
pub mod layout;
mod state;
mod tile;

pub use bands::{BandRows, PassSplats, SplatBands};
pub use block::PassBlock;
pub use develop::{Channel, Developed};
pub use layout::{Aov, Buckets, FilmLayout, SurfaceAov};
pub use state::{FilmState, MergeError, PassSet};
pub use tile::{FilmTile, SplatBuffer, SplatRecord, SurfaceSample};

use crate::math::{Mat3, UVec2};
use crate::spectrum::{ColorSpace, PixelSensor};
use filter::Filter;
use tile::Encoder;

/// Film construction values (parsed from the `Film` directive).
#[derive(Clone, Debug)]
pub struct FilmSettings {
    /// Full resolution in pixels.
    pub resolution: UVec2,
    /// Half-open pixel range actually rendered (crop window).
    pub pixel_bounds: (UVec2, UVec2),
    /// Samples whose largest sensor-RGB component exceeds this are scaled down (pbrt: +∞).
    pub max_component_value: f32,
}

/// Which pbrt-v4 film the channels are named after.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FilmKind {
    /// `rgb`: R, G, B, and candela's `--aov` layers.
    Rgb,
    /// `gbuffer`: pbrt-v4's `GBufferFilm` channels.
    GBuffer,
    /// `spectral`: R, G, B and pbrt-v4's `S0.<λ>nm` buckets.
    Spectral,
}

/// The space first-hit positions and normals are recorded in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SurfaceSpace {
    /// World space.
    World,
    /// Camera space: the camera at the origin looking down +z, +y up
    /// (pbrt-v4's camera space; the `gbuffer` default).
    Camera,
}

/// The film's configuration.
#[derive(Clone, Debug)]
pub struct Film {
    settings: FilmSettings,
    filter: Filter,
    sensor: PixelSensor,
    output_from_sensor: Mat3,
    layout: FilmLayout,
    kind: FilmKind,
    surface_space: SurfaceSpace,
    color_space: &'static ColorSpace,
    illuminance_depth: u32,
}

impl Film {
    /// A film with the main RGB layer only; `output_from_sensor` maps sensor
    /// RGB to output RGB.
    pub fn new(
        settings: FilmSettings,
        filter: Filter,
        sensor: PixelSensor,
        output_from_sensor: Mat3,
    ) -> Self {
        Self {
            settings,
            filter,
            sensor,
            output_from_sensor,
            layout: FilmLayout::default(),
            kind: FilmKind::Rgb,
            surface_space: SurfaceSpace::World,
            color_space: ColorSpace::srgb(),
            illuminance_depth: 4,
        }
    }

    /// The same film whose first-hit illuminance estimates follow paths of
    /// at most `depth` scattering events after the surface (photometric
    /// layers; 4 by default, what a `maxdepth` 5 camera path leaves).
    pub fn with_illuminance_depth(mut self, depth: u32) -> Self {
        self.illuminance_depth = depth;
        self
    }

    /// Scattering events after the surface of the first-hit illuminance estimate.
    pub fn illuminance_depth(&self) -> u32 {
        self.illuminance_depth
    }

    /// The same film with output colour space `cs` (whose illuminant and
    /// primaries turn first-hit albedos into output RGB; sRGB by default).
    pub fn with_color_space(mut self, cs: &'static ColorSpace) -> Self {
        self.color_space = cs;
        self
    }

    /// The output colour space.
    pub fn color_space(&self) -> &'static ColorSpace {
        self.color_space
    }

    /// The same film recording `layout`, with channels named as `kind`.
    pub fn with_layers(mut self, layout: FilmLayout, kind: FilmKind, space: SurfaceSpace) -> Self {
        self.layout = layout;
        self.kind = kind;
        self.surface_space = space;
        self
    }

    /// Full resolution.
    pub fn resolution(&self) -> UVec2 {
        self.settings.resolution
    }
    /// Rendered pixel range.
    pub fn pixel_bounds(&self) -> (UVec2, UVec2) {
        self.settings.pixel_bounds
    }
    /// Number of pixels in the pixel bounds.
    pub fn pixel_count(&self) -> usize {
        let (lo, hi) = self.settings.pixel_bounds;
        (hi.x - lo.x) as usize * (hi.y - lo.y) as usize
    }
    /// The construction values.
    pub fn settings(&self) -> &FilmSettings {
        &self.settings
    }
    /// The pixel filter.
    pub fn filter(&self) -> &Filter {
        &self.filter
    }
    /// The pixel sensor.
    pub fn sensor(&self) -> &PixelSensor {
        &self.sensor
    }
    /// Sensor RGB → output RGB.
    pub fn output_from_sensor(&self) -> Mat3 {
        self.output_from_sensor
    }
    /// The layers recorded.
    pub fn layout(&self) -> &FilmLayout {
        &self.layout
    }
    /// Which pbrt-v4 film the channels are named after.
    pub fn kind(&self) -> FilmKind {
        self.kind
    }
    /// The space of recorded positions and normals.
    pub fn surface_space(&self) -> SurfaceSpace {
        self.surface_space
    }

    /// Rows of `output_from_sensor` in f64.
    pub(crate) fn output_from_sensor_f64(&self) -> [[f64; 3]; 3] {
        let m = self.output_from_sensor;
        [0, 1, 2].map(|r| [0, 1, 2].map(|c| m.col(c)[r] as f64))
    }

    fn encoder(&self) -> Encoder {
        Encoder {
            sensor: self.sensor.clone(),
            max_component_value: self.settings.max_component_value,
            buckets: self.layout.spectral,
            luminance: self.layout.photometric,
        }
    }

    pub(crate) fn encoder_for_empty(&self) -> Encoder {
        Encoder {
            buckets: None,
            luminance: false,
            ..self.encoder()
        }
    }

    /// An empty tile covering `[lo, hi)`.
    pub fn tile(&self, lo: UVec2, hi: UVec2) -> FilmTile {
        FilmTile::new(lo, hi, &self.layout, self.encoder())
    }

    /// An empty splat buffer over the pixel bounds.
    pub fn splat_buffer(&self) -> SplatBuffer {
        let (lo, hi) = self.settings.pixel_bounds;
        SplatBuffer::new(lo, hi, self.filter.clone(), self.encoder())
    }

    /// An empty splat buffer over the pixels `lo..hi` (within the pixel bounds).
    pub fn splat_buffer_over(&self, lo: UVec2, hi: UVec2) -> SplatBuffer {
        SplatBuffer::new(lo, hi, self.filter.clone(), self.encoder())
    }

    /// An empty RGB-only splat buffer (for BDPT's strategy layers).
    pub fn strategy_buffer(&self) -> SplatBuffer {
        let (lo, hi) = self.settings.pixel_bounds;
        let enc = Encoder {
            buckets: None,
            luminance: false,
            ..self.encoder()
        };
        SplatBuffer::new(lo, hi, self.filter.clone(), enc)
    }

    /// An empty pass block.
    pub fn block(&self) -> PassBlock {
        let (lo, hi) = self.settings.pixel_bounds;
        PassBlock::new(lo, hi, &self.layout)
    }

    /// An empty accumulated state.
    pub fn state(&self) -> FilmState {
        FilmState::new(self)
    }

    /// Bytes of one pass block and of the accumulated state (for memory budgets).
    pub fn memory_estimate(&self) -> (u64, u64) {
        let n = self.pixel_count() as u64;
        (
            n * self.layout.pass_stride() as u64 * 8,
            n * self.layout.state_stride() as u64 * 16,
        )
    }
}
