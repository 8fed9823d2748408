//! Colour: RGB and XYZ triples, RGB colour spaces, and white balancing.

use super::rgb2spec::{fit_sigmoid, RgbSigmoidPolynomial};
use super::rgb2spec_table::{RgbToSpectrumTable, TABLE_RES};
use super::spectra::{spectrum_to_xyz, PiecewiseLinear, Spectrum};
use super::{cie_xyz, named, SampledSpectrum, SampledWavelengths, SpectrumKind};
use glam::{Mat3, Vec3};
use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

/// A linear RGB triple.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rgb {
    /// Red.
    pub r: f32,
    /// Green.
    pub g: f32,
    /// Blue.
    pub b: f32,
}

impl Rgb {
    /// New triple.
    pub fn new(r: f32, g: f32, b: f32) -> Self {
        Self { r, g, b }
    }
}

/// CIE XYZ tristimulus values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Xyz {
    /// X.
    pub x: f32,
    /// Y (luminance).
    pub y: f32,
    /// Z.
    pub z: f32,
}

impl Xyz {
    /// Chromaticity (x, y).
    pub fn xy(&self) -> (f32, f32) {
        let s = self.x + self.y + self.z;
        (self.x / s, self.y / s)
    }
    /// From chromaticity with luminance `y_lum`.
    pub fn from_xy(x: f32, y: f32, y_lum: f32) -> Self {
        if y == 0.0 {
            return Self {
                x: 0.0,
                y: 0.0,
                z: 0.0,
            };
        }
        Self {
            x: x * y_lum / y,
            y: y_lum,
            z: (1.0 - x - y) * y_lum / y,
        }
    }
    fn vec(self) -> Vec3 {
        Vec3::new(self.x, self.y, self.z)
    }
}

impl SampledSpectrum {
    /// Monte Carlo estimate of XYZ: the average over samples of x̄(λ)·s(λ)/p(λ),
    /// divided by ∫ȳ so the unit equal-energy spectrum has Y = 1.
    pub fn to_xyz(&self, lambda: &SampledWavelengths) -> Xyz {
        let v = sensor_response(*self, lambda);
        let k = super::CIE_Y_INTEGRAL;
        Xyz {
            x: v[0] / k,
            y: v[1] / k,
            z: v[2] / k,
        }
    }
}

/// Average of cmf(λ)·s(λ)/p(λ) per channel (estimates ∫ cmf·s dλ).
fn sensor_response(s: SampledSpectrum, lambda: &SampledWavelengths) -> [f32; 3] {
    let l = s.safe_div(lambda.pdf());
    let mut out = [0.0f32; 3];
    for i in 0..super::N_SPECTRUM_SAMPLES {
        let c = cie_xyz(lambda.lambda(i));
        for k in 0..3 {
            out[k] += c[k] * l[i];
        }
    }
    out.map(|v| v / super::N_SPECTRUM_SAMPLES as f32)
}

/// An RGB colour space: primaries, white point (from its standard illuminant)
/// and the RGB → spectrum model.
pub struct ColorSpace {
    /// Name as pbrt-v4 spells it.
    pub name: &'static str,
    /// The standard illuminant (normalised to luminance Y = 1).
    pub illuminant: Spectrum,
    /// The same illuminant as a table.
    pub illuminant_table: Arc<PiecewiseLinear>,
    /// XYZ from linear RGB.
    pub xyz_from_rgb: Mat3,
    /// Linear RGB from XYZ.
    pub rgb_from_xyz: Mat3,
    cache: Mutex<HashMap<[u32; 3], RgbSigmoidPolynomial>>,
    table: OnceLock<RgbToSpectrumTable>,
}

impl std::fmt::Debug for ColorSpace {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "ColorSpace({})", self.name)
    }
}

impl ColorSpace {
    fn new(
        name: &'static str,
        r: (f32, f32),
        g: (f32, f32),
        b: (f32, f32),
        illum: Arc<PiecewiseLinear>,
    ) -> Self {
        let illuminant = Spectrum::PiecewiseLinear(illum.clone());
        // [pbrt-v4 RGBColorSpace]: scale the primaries so that RGB (1,1,1) is the white point.
        let w = spectrum_to_xyz(&illuminant).vec();
        let m = Mat3::from_cols(
            Xyz::from_xy(r.0, r.1, 1.0).vec(),
            Xyz::from_xy(g.0, g.1, 1.0).vec(),
            Xyz::from_xy(b.0, b.1, 1.0).vec(),
        );
        let c = m.inverse() * w;
        let xyz_from_rgb = m * Mat3::from_diagonal(c);
        Self {
            name,
            illuminant,
            illuminant_table: illum,
            xyz_from_rgb,
            rgb_from_xyz: xyz_from_rgb.inverse(),
            cache: Mutex::new(HashMap::new()),
            table: OnceLock::new(),
        }
    }

    /// Linear sRGB (Rec. 709 primaries, D65).
    pub fn srgb() -> &'static ColorSpace {
        static CS: OnceLock<ColorSpace> = OnceLock::new();
        CS.get_or_init(|| {
            ColorSpace::new(
                "srgb",
                (0.64, 0.33),
                (0.30, 0.60),
                (0.15, 0.06),
                named::d65(),
            )
        })
    }
    /// Rec. 2020 (D65).
    pub fn rec2020() -> &'static ColorSpace {
        static CS: OnceLock<ColorSpace> = OnceLock::new();
        CS.get_or_init(|| {
            ColorSpace::new(
                "rec2020",
                (0.708, 0.292),
                (0.170, 0.797),
                (0.131, 0.046),
                named::d65(),
            )
        })
    }
    /// DCI-P3 primaries with a D65 white (pbrt-v4's "dci-p3").
    pub fn dci_p3() -> &'static ColorSpace {
        static CS: OnceLock<ColorSpace> = OnceLock::new();
        CS.get_or_init(|| {
            ColorSpace::new(
                "dci-p3",
                (0.680, 0.320),
                (0.265, 0.690),
                (0.150, 0.060),
                named::d65(),
            )
        })
    }
    /// ACES2065-1: the AP0 primaries, which enclose the spectral locus (the
    /// green and blue ones are not physical colours), with the ACES D60 white
    /// [pbrt-v4 `RGBColorSpace::ACES2065_1`; SMPTE ST 2065-1].
    pub fn aces2065_1() -> &'static ColorSpace {
        static CS: OnceLock<ColorSpace> = OnceLock::new();
        CS.get_or_init(|| {
            ColorSpace::new(
                "aces2065-1",
                (0.7347, 0.2653),
                (0.0, 1.0),
                (0.0001, -0.077),
                named::aces_d60(),
            )
        })
    }
    /// Looks up a colour space by pbrt-v4 name.
    pub fn by_name(name: &str) -> Option<&'static ColorSpace> {
        match name {
            "srgb" => Some(Self::srgb()),
            "rec2020" => Some(Self::rec2020()),
            "dci-p3" => Some(Self::dci_p3()),
            "aces2065-1" => Some(Self::aces2065_1()),
            _ => None,
        }
    }

    /// Linear RGB of an XYZ value.
    pub fn to_rgb(&self, xyz: Xyz) -> Rgb {
        let v = self.rgb_from_xyz * xyz.vec();
        Rgb::new(v.x, v.y, v.z)
    }

    /// Sigmoid-polynomial coefficients of an RGB in \[0,1\]³, fitted on demand
    /// by Gauss–Newton [Jakob & Hanika 2019] and memoised per distinct RGB.
    pub fn to_rgb_coeffs(&self, rgb: Rgb) -> RgbSigmoidPolynomial {
        let rgb = Rgb::new(
            rgb.r.clamp(0.0, 1.0),
            rgb.g.clamp(0.0, 1.0),
            rgb.b.clamp(0.0, 1.0),
        );
        if rgb.r == rgb.g && rgb.g == rgb.b {
            return RgbSigmoidPolynomial::constant(rgb.r);
        }
        let key = [rgb.r.to_bits(), rgb.g.to_bits(), rgb.b.to_bits()];
        if let Some(p) = self.cache.lock().ok().and_then(|c| c.get(&key).copied()) {
            return p;
        }
        let p = fit_sigmoid(self, rgb);
        if let Ok(mut c) = self.cache.lock() {
            c.insert(key, p);
        }
        p
    }

    /// The tabulated RGB → spectrum fit for per-lookup conversions (image
    /// textures and maps), built on first use (see `rgb2spec_table`).
    pub fn rgb_table(&self) -> &RgbToSpectrumTable {
        self.table.get_or_init(|| {
            let on_worker = rayon::current_thread_index().is_some();
            RgbToSpectrumTable::build(self, TABLE_RES, !on_worker)
        })
    }

    /// The spectrum of `rgb` read with meaning `kind`, at the path's
    /// wavelengths, through the table [pbrt-v4 `RGBAlbedoSpectrum`,
    /// `RGBUnboundedSpectrum`, `RGBIlluminantSpectrum`]: albedos are clamped
    /// to [0, 1]³; other kinds are s(λ) of rgb/(2m) scaled by 2m, m the largest
    /// component (× the illuminant for emission). Negative components count as 0.
    pub fn sample_rgb(
        &self,
        rgb: Rgb,
        kind: SpectrumKind,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        let table = self.rgb_table();
        let rgb = Rgb::new(rgb.r.max(0.0), rgb.g.max(0.0), rgb.b.max(0.0));
        if kind == SpectrumKind::Albedo {
            let p = table.coeffs(rgb);
            return p.sample(lambda);
        }
        let scale = 2.0 * rgb.r.max(rgb.g).max(rgb.b);
        if scale == 0.0 {
            return SampledSpectrum::zero();
        }
        let p = table.coeffs(Rgb::new(rgb.r / scale, rgb.g / scale, rgb.b / scale));
        let v = p.sample(lambda) * scale;
        match kind {
            SpectrumKind::Illuminant => v * self.illuminant_table.sample(lambda),
            _ => v,
        }
    }
}

/// Bradford matrices of pbrt-v4 (`src/pbrt/util/color.h`), row-major:
/// LMS cone responses from XYZ and back.
const LMS_FROM_XYZ: [f32; 9] = [
    0.8951, 0.2664, -0.1614, -0.7502, 1.7135, 0.0367, 0.0389, -0.0685, 1.0296,
];
const XYZ_FROM_LMS: [f32; 9] = [
    0.986993,
    -0.147054,
    0.159963,
    0.432305,
    0.51836,
    0.0492912,
    -0.00852866,
    0.0400428,
    0.968487,
];

/// The von Kries white balance in Bradford LMS space that maps the white of
/// chromaticity `src` to `dst` (both at Y = 1) [pbrt-v4 `WhiteBalance`]:
/// XYZ_from_LMS · diag(LMS(dst)/LMS(src)) · LMS_from_XYZ.
pub fn white_balance(src: (f32, f32), dst: (f32, f32)) -> Mat3 {
    let lms_from_xyz = Mat3::from_cols_array(&LMS_FROM_XYZ).transpose();
    let xyz_from_lms = Mat3::from_cols_array(&XYZ_FROM_LMS).transpose();
    let s = lms_from_xyz * Xyz::from_xy(src.0, src.1, 1.0).vec();
    let d = lms_from_xyz * Xyz::from_xy(dst.0, dst.1, 1.0).vec();
    xyz_from_lms * Mat3::from_diagonal(d / s) * lms_from_xyz
}
