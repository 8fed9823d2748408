//! The pixels one live-view update carries.

use super::DisplayError;
use crate::image::{ExrLayer, RgbImage};

/// `width × height` pixels of interleaved `f32` channels, row-major, top row
/// first: `data[(y·width + x)·channels.len() + c]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// Width in pixels.
    width: usize,
    /// Height in pixels.
    height: usize,
    /// Channel names, in the order of the interleaved values.
    channels: Vec<String>,
    /// The samples.
    data: Vec<f32>,
}

impl Frame {
    /// A frame of `channels` interleaved in `data`; checks that the sizes
    /// agree, that the protocol can carry them (sizes within `i32`, names
    /// without NUL) and that channel names are distinct.
    pub fn new(
        width: usize,
        height: usize,
        channels: Vec<String>,
        data: Vec<f32>,
    ) -> Result<Self, DisplayError> {
        let invalid = |m: String| Err(DisplayError::Invalid(m));
        let fits = |v: usize| v >= 1 && i32::try_from(v).is_ok();
        if !fits(width) || !fits(height) {
            return invalid(format!("frame size {width}x{height}"));
        }
        if channels.is_empty() {
            return invalid("frame without channels".into());
        }
        for (i, c) in channels.iter().enumerate() {
            if c.is_empty() || c.contains('\0') {
                return invalid(format!("channel name {c:?} is empty or holds a NUL"));
            }
            if channels[..i].contains(c) {
                return invalid(format!("channel {c:?} appears twice"));
            }
        }
        let n = width
            .checked_mul(height)
            .and_then(|p| p.checked_mul(channels.len()));
        if n != Some(data.len()) {
            return invalid(format!(
                "{} values for {width}x{height} pixels of {} channels",
                data.len(),
                channels.len()
            ));
        }
        Ok(Self {
            width,
            height,
            channels,
            data,
        })
    }

    /// The pixels of `image` as channels `R`, `G`, `B`.
    pub fn from_rgb(image: &RgbImage) -> Result<Self, DisplayError> {
        let data = image.pixels.iter().flatten().copied().collect();
        let names = ["R", "G", "B"].map(String::from).to_vec();
        Self::new(image.width, image.height, names, data)
    }

    /// The channels of `layers`, named as in an EXR file (`R`, `albedo.R`),
    /// in the order given.
    pub fn from_exr_layers(
        width: usize,
        height: usize,
        layers: &[ExrLayer],
    ) -> Result<Self, DisplayError> {
        let planes: Vec<(String, &[f32])> = layers
            .iter()
            .flat_map(|l| {
                l.channels.iter().map(move |c| {
                    let name = if l.name.is_empty() {
                        c.name.clone()
                    } else {
                        format!("{}.{}", l.name, c.name)
                    };
                    (name, c.samples.as_slice())
                })
            })
            .collect();
        let n = width.saturating_mul(height);
        if let Some((name, p)) = planes.iter().find(|(_, p)| p.len() != n) {
            return Err(DisplayError::Invalid(format!(
                "channel {name:?} has {} samples, not {width}x{height}",
                p.len()
            )));
        }
        let mut data = Vec::with_capacity(n.saturating_mul(planes.len()));
        for i in 0..n {
            data.extend(planes.iter().map(|(_, p)| p[i]));
        }
        Self::new(
            width,
            height,
            planes.into_iter().map(|p| p.0).collect(),
            data,
        )
    }

    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// Channel names.
    pub fn channels(&self) -> &[String] {
        &self.channels
    }

    /// All samples, interleaved.
    pub fn data(&self) -> &[f32] {
        &self.data
    }

    /// The channel values of pixel (x, y).
    #[inline]
    pub fn pixel(&self, x: usize, y: usize) -> &[f32] {
        let nc = self.channels.len();
        let i = (y * self.width + x) * nc;
        &self.data[i..i + nc]
    }
}
