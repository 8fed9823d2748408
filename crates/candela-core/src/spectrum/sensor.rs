//! The camera sensor of pbrt-v4's `rgb` film [pbrt-v4 `PixelSensor`,
//! `src/pbrt/film.h`; PBR 4th ed. §5.4.2].
//!
//! A sensor turns spectral radiance L(λ) into three responses
//! c_k = r · ∫ b̄_k(λ) L(λ) dλ, estimated from the path's wavelength samples,
//! with r the imaging ratio (exposure time · ISO / 100) and b̄_k the sensor's
//! spectral sensitivities. The film later maps these "sensor RGB" values to
//! the output colour space through `rgb_from_xyz · xyz_from_sensor_rgb`.
//!
//! * **`cie1931`** (the default) responds with x̄, ȳ, z̄ themselves, so sensor
//!   RGB is XYZ and `xyz_from_sensor_rgb` is the identity — unless a
//!   `whitebalance` temperature T is given, when it is the Bradford von Kries
//!   adaptation from the chromaticity of D(T) to the output space's white.
//! * **Camera sensors** (the measured curves pbrt-v4 ships, `canon_eos_5d_mkiv`
//!   …) have no exact linear map to XYZ. pbrt-v4 fits one by linear least
//!   squares over the 24 ColorChecker patches: with the patches lit by the
//!   sensor illuminant D(T) (T = `whitebalance`, 6500 K if unset) the sensor
//!   sees c_i = ∫ b̄ ρ_i D / ∫ ḡ D; the target is what the CIE observer sees
//!   of the same patches under the output space's illuminant W,
//!   t_i = ∫ x̄ ρ_i W / ∫ ȳ W · (∫ ȳ D / ∫ ḡ D). The matrix M minimising
//!   Σ_i ‖M c_i − t_i‖² therefore both converts to XYZ and white-balances
//!   D(T) to the output white; the last factor makes the green response of
//!   the sensor illuminant carry its luminance, so a camera and `cie1931`
//!   agree on the brightness of neutral surfaces.

use super::color::{white_balance, ColorSpace};
use super::data::swatches::{SWATCHES, SWATCH_START};
use super::daylight::daylight;
use super::spectra::{spectrum_to_xyz, PiecewiseLinear, Spectrum};
use super::{
    cie_xyz, cie_xyz_sampled, SampledSpectrum, SampledWavelengths, LAMBDA_MAX, LAMBDA_MIN,
};
use glam::{DMat3, DVec3, Mat3};
use std::sync::{Arc, OnceLock};

/// The measured r̄, ḡ, b̄ sensitivities of one camera.
#[derive(Debug)]
pub struct CameraCurves {
    /// Sensor name as pbrt-v4 spells it (`"nikon_d850"`).
    pub name: String,
    /// r̄, ḡ, b̄ (380–720 nm at 10 nm, ḡ peaks at 1).
    pub rgb: [Arc<PiecewiseLinear>; 3],
}

/// Every camera pbrt-v4 ships, parsed once from `data/camera_sensitivities.txt`.
pub fn cameras() -> &'static [CameraCurves] {
    static C: OnceLock<Vec<CameraCurves>> = OnceLock::new();
    C.get_or_init(|| {
        parse_curves(include_str!("../../data/camera_sensitivities.txt"))
            .chunks_exact(3)
            .filter_map(|c| {
                let base = c[0].0.strip_suffix("_r")?;
                let same = c[1].0.strip_suffix("_g") == Some(base)
                    && c[2].0.strip_suffix("_b") == Some(base);
                same.then(|| CameraCurves {
                    name: base.to_string(),
                    rgb: [c[0].1.clone(), c[1].1.clone(), c[2].1.clone()],
                })
            })
            .collect()
    })
}

/// (name, curve) pairs of the data file: `= name` lines open a curve,
/// other non-comment lines hold "λ value" pairs.
pub(super) fn parse_curves(text: &str) -> Vec<(String, Arc<PiecewiseLinear>)> {
    let mut out: Vec<(String, Vec<(f32, f32)>)> = Vec::new();
    for line in text.lines().map(str::trim) {
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        if let Some(name) = line.strip_prefix('=') {
            out.push((name.trim().to_string(), Vec::new()));
        } else if let Some((_, pairs)) = out.last_mut() {
            let v: Vec<f32> = line
                .split_whitespace()
                .filter_map(|t| t.parse().ok())
                .collect();
            pairs.extend(v.chunks_exact(2).map(|p| (p[0], p[1])));
        }
    }
    out.into_iter()
        .map(|(n, p)| (n, Arc::new(PiecewiseLinear::new(&p))))
        .collect()
}

/// A camera curve looked up by its pbrt-v4 named-spectrum name (`canon_eos_m_g`).
pub fn named_sensor_curve(name: &str) -> Option<Arc<PiecewiseLinear>> {
    let (base, k) = [("_r", 0), ("_g", 1), ("_b", 2)]
        .iter()
        .find_map(|(s, k)| name.strip_suffix(s).map(|b| (b, *k)))?;
    cameras()
        .iter()
        .find(|c| c.name == base)
        .map(|c| c.rgb[k].clone())
}

/// Every sensor name the `rgb` film accepts: `cie1931` and the cameras.
pub fn sensor_names() -> Vec<&'static str> {
    std::iter::once("cie1931")
        .chain(cameras().iter().map(|c| c.name.as_str()))
        .collect()
}

/// A sensor name that is neither `cie1931` nor a known camera.
#[derive(Debug, thiserror::Error)]
#[error("unknown sensor \"{name}\" (known: {})", sensor_names().join(", "))]
pub struct UnknownSensor {
    /// The name asked for.
    pub name: String,
}

/// What the sensor responds with.
#[derive(Clone, Debug)]
enum Response {
    /// x̄, ȳ, z̄ (CIE 1931 2°).
    Xyz,
    /// A camera's r̄, ḡ, b̄.
    Camera(&'static CameraCurves),
}

/// The pixel sensor of the `rgb` film (see the module docs).
#[derive(Clone, Debug)]
pub struct PixelSensor {
    response: Response,
    xyz_from_sensor_rgb: Mat3,
    imaging_ratio: f32,
}

impl PixelSensor {
    /// The CIE 1931 sensor without white balance.
    pub fn cie1931(imaging_ratio: f32) -> Self {
        Self {
            response: Response::Xyz,
            xyz_from_sensor_rgb: Mat3::IDENTITY,
            imaging_ratio,
        }
    }

    /// The CIE 1931 sensor white-balanced from the chromaticity of `illuminant`
    /// to the white of `cs` (Bradford adaptation) [pbrt-v4 `PixelSensor`].
    pub fn cie1931_balanced(cs: &ColorSpace, illuminant: &Spectrum, imaging_ratio: f32) -> Self {
        let src = spectrum_to_xyz(illuminant).xy();
        Self {
            xyz_from_sensor_rgb: white_balance(src, cs.white_xy()),
            ..Self::cie1931(imaging_ratio)
        }
    }

    /// A camera sensor whose XYZ matrix is fitted with the patches lit by
    /// `illuminant` and targeted at the white of `cs`.
    pub fn camera(
        curves: &'static CameraCurves,
        cs: &ColorSpace,
        illuminant: &Spectrum,
        imaging_ratio: f32,
    ) -> Self {
        Self {
            response: Response::Camera(curves),
            xyz_from_sensor_rgb: fit_xyz_from_sensor_rgb(curves, cs, illuminant),
            imaging_ratio,
        }
    }

    /// The sensor pbrt-v4 builds for `"string sensor" name` and
    /// `"float whitebalance" t` (0: none for `cie1931`, 6500 K for cameras).
    pub fn from_name(
        name: &str,
        cs: &ColorSpace,
        white_balance: f32,
        imaging_ratio: f32,
    ) -> Result<Self, UnknownSensor> {
        if name == "cie1931" {
            if white_balance == 0.0 {
                return Ok(Self::cie1931(imaging_ratio));
            }
            let d = Spectrum::PiecewiseLinear(Arc::new(daylight(white_balance)));
            return Ok(Self::cie1931_balanced(cs, &d, imaging_ratio));
        }
        let curves = cameras()
            .iter()
            .find(|c| c.name == name)
            .ok_or_else(|| UnknownSensor {
                name: name.to_string(),
            })?;
        let t = if white_balance == 0.0 {
            6500.0
        } else {
            white_balance
        };
        let d = Spectrum::PiecewiseLinear(Arc::new(daylight(t)));
        Ok(Self::camera(curves, cs, &d, imaging_ratio))
    }

    /// Sensor RGB of sampled radiance: imaging ratio × (∫ b̄_k L) estimated
    /// from the samples. No 1/∫ȳ here: pbrt-v4 folds that into the lights'
    /// 1/`SpectrumToPhotometric` scale, so a 1-nit white light reads 1.
    pub fn to_sensor_rgb(&self, l: SampledSpectrum, lambda: &SampledWavelengths) -> [f32; 3] {
        let l = l.safe_div(lambda.pdf());
        let b = match self.response {
            Response::Xyz => cie_xyz_sampled(lambda.lambdas()),
            Response::Camera(_) => std::array::from_fn(|i| self.sensitivities(lambda.lambda(i))),
        };
        let mut out = [0.0f32; 3];
        for i in 0..super::N_SPECTRUM_SAMPLES {
            for k in 0..3 {
                out[k] += b[i][k] * l[i];
            }
        }
        let n = super::N_SPECTRUM_SAMPLES as f32;
        [
            out[0] / n * self.imaging_ratio,
            out[1] / n * self.imaging_ratio,
            out[2] / n * self.imaging_ratio,
        ]
    }

    /// (b̄_r, b̄_g, b̄_b) at `lambda`.
    #[inline]
    fn sensitivities(&self, lambda: f32) -> [f32; 3] {
        match self.response {
            Response::Xyz => cie_xyz(lambda),
            Response::Camera(c) => [
                c.rgb[0].eval(lambda),
                c.rgb[1].eval(lambda),
                c.rgb[2].eval(lambda),
            ],
        }
    }

    /// XYZ from sensor RGB.
    pub fn xyz_from_sensor_rgb(&self) -> Mat3 {
        self.xyz_from_sensor_rgb
    }

    /// Exposure time · ISO / 100.
    pub fn imaging_ratio(&self) -> f32 {
        self.imaging_ratio
    }

    /// `cie1931` or the camera's name.
    pub fn name(&self) -> &str {
        match self.response {
            Response::Xyz => "cie1931",
            Response::Camera(c) => &c.name,
        }
    }

    /// Noise-free sensor RGB of a spectrum (∫ at 1 nm over 360–830 nm, × imaging ratio).
    pub fn response_of(&self, s: impl Fn(f32) -> f32) -> [f32; 3] {
        let mut out = [0.0f64; 3];
        for l in LAMBDA_MIN as i32..=LAMBDA_MAX as i32 {
            let b = self.sensitivities(l as f32);
            let v = s(l as f32) as f64;
            for k in 0..3 {
                out[k] += b[k] as f64 * v;
            }
        }
        out.map(|v| (v * self.imaging_ratio as f64) as f32)
    }
}

/// The ColorChecker patches as spectra (zero outside 380–730 nm, as in pbrt-v4).
pub(super) fn swatches() -> &'static [PiecewiseLinear] {
    static S: OnceLock<Vec<PiecewiseLinear>> = OnceLock::new();
    S.get_or_init(|| {
        SWATCHES
            .iter()
            .map(|r| PiecewiseLinear::from_even(SWATCH_START, 10.0, r))
            .collect()
    })
}

/// (Σ b̄₁ ρ I, Σ b̄₂ ρ I, Σ b̄₃ ρ I) / Σ b̄₂ I at 1 nm over 360–830 nm
/// [pbrt-v4 `ProjectReflectance`].
fn project(rho: &PiecewiseLinear, illum: &Spectrum, b: impl Fn(f32) -> [f32; 3]) -> DVec3 {
    let (mut out, mut norm) = (DVec3::ZERO, 0.0f64);
    for l in LAMBDA_MIN as i32..=LAMBDA_MAX as i32 {
        let l = l as f32;
        let (bb, i) = (b(l), illum.eval(l) as f64);
        norm += bb[1] as f64 * i;
        out += DVec3::new(bb[0] as f64, bb[1] as f64, bb[2] as f64) * rho.eval(l) as f64 * i;
    }
    out / norm
}

/// The training pairs (sensor RGB c_i, target XYZ t_i) of the 24 patches.
pub(super) fn training_pairs(
    curves: &CameraCurves,
    cs: &ColorSpace,
    illuminant: &Spectrum,
) -> Vec<(DVec3, DVec3)> {
    let sensor = |l: f32| [0, 1, 2].map(|k| curves.rgb[k].eval(l));
    let (mut white_g, mut white_y) = (0.0f64, 0.0f64);
    for l in LAMBDA_MIN as i32..=LAMBDA_MAX as i32 {
        let i = illuminant.eval(l as f32) as f64;
        white_g += curves.rgb[1].eval(l as f32) as f64 * i;
        white_y += cie_xyz(l as f32)[1] as f64 * i;
    }
    swatches()
        .iter()
        .map(|rho| {
            let c = project(rho, illuminant, sensor);
            let t = project(rho, &cs.illuminant, cie_xyz) * (white_y / white_g);
            (c, t)
        })
        .collect()
}

/// M = argmin Σ‖M c_i − t_i‖², i.e. Mᵀ = (CᵀC)⁻¹ CᵀT [pbrt-v4 `LinearLeastSquares`].
pub(super) fn fit_xyz_from_sensor_rgb(
    curves: &CameraCurves,
    cs: &ColorSpace,
    illuminant: &Spectrum,
) -> Mat3 {
    let pairs = training_pairs(curves, cs, illuminant);
    let outer = |a: DVec3, b: DVec3| DMat3::from_cols(a * b.x, a * b.y, a * b.z);
    let (mut ctc, mut ctt) = (DMat3::ZERO, DMat3::ZERO);
    for (c, t) in &pairs {
        ctc += outer(*c, *c);
        ctt += outer(*c, *t);
    }
    // outer(a, b) has entry (row i, column j) a_i b_j, so with the patches as
    // the rows of C and T, ctc = CᵀC and ctt = CᵀT; the normal equations give
    // Mᵀ = (CᵀC)⁻¹ CᵀT. The 24 patches span RGB for any real sensor, so CᵀC
    // is invertible (the shipped sensors are all checked by a test).
    let m = (ctc.inverse() * ctt).transpose();
    m.as_mat3()
}

impl ColorSpace {
    /// Chromaticity of the white point (of the standard illuminant).
    pub fn white_xy(&self) -> (f32, f32) {
        spectrum_to_xyz(&self.illuminant).xy()
    }
}
