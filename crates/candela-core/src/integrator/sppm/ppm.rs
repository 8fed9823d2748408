//! Probabilistic progressive photon mapping (`Integrator "ppm"`) [Knaus &
//! Zwicker 2011].
//!
//! Pass i (1-based) is an independent photon-mapping estimate with one
//! global radius r_i, r²_{i+1} = r²_i (i + α)/(i + 1), so
//! r²_i = r²_1 Π_{k<i} (k + α)/(k + 1) [Knaus & Zwicker 2011, eq. 16]; the
//! image is the average of the passes. Because passes are independent, a
//! render can be split: `--pass-range A..B` renders passes A ≤ i < B and
//! writes their sum to a partial file, and `candela merge` adds partial files.
//! Sums are kept in 2⁻⁴⁸ fixed point (i128), whose addition is associative,
//! so merged halves equal the full run bit for bit.

use super::passes::{camera_pass, pass_wavelengths, photon_pass, pixel_list};
use super::ALPHA;
use crate::film::RgbFilm;
use crate::integrator::photon::ShootSettings;
use crate::integrator::{Integrator, RenderContext};
use crate::math::UVec2;
use std::io::{Read, Write};
use std::path::{Path, PathBuf};

/// Parameters of `Integrator "ppm"`.
#[derive(Clone, Debug)]
pub struct PpmSettings {
    /// Photons per pass (`photonsperiteration`; ≤ 0: one per pixel).
    pub photons_per_pass: i64,
    /// Radius of the first pass (`radius`, default 1).
    pub radius: f32,
    /// Maximum path depth (`maxdepth`, default 5).
    pub max_depth: u32,
    /// Seed (`seed`).
    pub seed: u64,
    /// Passes to render (`--pass-range A..B`; default all `spp` passes).
    pub pass_range: Option<(u64, u64)>,
    /// Where to write the partial sums (with a pass range).
    pub partial_out: Option<PathBuf>,
}

/// The PPM integrator.
pub struct PpmIntegrator {
    /// Settings.
    pub settings: PpmSettings,
}

/// r²_i / r²_1 for pass `i` ≥ 1: Π_{k=1}^{i−1} (k + α)/(k + 1).
pub fn ppm_radius2(i: u64, alpha: f64) -> f64 {
    (1..i)
        .map(|k| (k as f64 + alpha) / (k as f64 + 1.0))
        .product()
}

/// Fixed-point scale of the pass sums.
const FIXED: f64 = (1u64 << 48) as f64;

/// Per-pixel sums of pass estimates over a range of passes.
#[derive(Clone, Debug, PartialEq)]
pub struct PpmPartial {
    /// Film pixel bounds (lo) and size of the rendered region.
    pub origin: UVec2,
    /// Width and height.
    pub size: UVec2,
    /// Passes [begin, end).
    pub passes: (u64, u64),
    /// Σ over passes of the sensor-RGB estimate, in 2⁻⁴⁸ units.
    pub sums: Vec<[i128; 3]>,
}

impl PpmPartial {
    /// Adds `other` (same region, disjoint passes).
    pub fn merge(&mut self, other: &PpmPartial) -> Result<(), String> {
        if other.origin != self.origin || other.size != self.size {
            return Err("partial results of different images".into());
        }
        let (a, b) = (self.passes, other.passes);
        if a.0 < b.1 && b.0 < a.1 {
            return Err(format!(
                "pass ranges {}..{} and {}..{} overlap",
                a.0, a.1, b.0, b.1
            ));
        }
        for (s, o) in self.sums.iter_mut().zip(&other.sums) {
            for c in 0..3 {
                s[c] += o[c];
            }
        }
        self.passes = (a.0.min(b.0), a.1.max(b.1));
        Ok(())
    }

    /// Number of passes summed (assuming the merged ranges are contiguous).
    pub fn count(&self) -> u64 {
        self.passes.1 - self.passes.0
    }

    /// Writes the averages into `film` (sensor RGB).
    pub fn write_film(&self, film: &mut RgbFilm) {
        let n = self.count().max(1) as f64;
        for (i, s) in self.sums.iter().enumerate() {
            let x = self.origin.x + i as u32 % self.size.x;
            let y = self.origin.y + i as u32 / self.size.x;
            film.set_pixel_sensor_rgb(UVec2::new(x, y), s.map(|v| v as f64 / FIXED / n));
        }
    }

    /// Binary file: magic, origin, size, passes, then the sums (little endian).
    pub fn save(&self, path: &Path) -> std::io::Result<()> {
        let mut out = Vec::with_capacity(48 + self.sums.len() * 48);
        out.extend_from_slice(b"CNDLPPM1");
        for v in [self.origin.x, self.origin.y, self.size.x, self.size.y] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out.extend_from_slice(&self.passes.0.to_le_bytes());
        out.extend_from_slice(&self.passes.1.to_le_bytes());
        for s in &self.sums {
            for v in s {
                out.extend_from_slice(&v.to_le_bytes());
            }
        }
        std::fs::File::create(path)?.write_all(&out)
    }

    /// Reads a file written by [`PpmPartial::save`].
    pub fn load(path: &Path) -> Result<Self, String> {
        let mut bytes = Vec::new();
        std::fs::File::open(path)
            .and_then(|mut f| f.read_to_end(&mut bytes))
            .map_err(|e| format!("{}: {e}", path.display()))?;
        let bad = || format!("{}: not a candela PPM partial result", path.display());
        if bytes.len() < 40 || &bytes[..8] != b"CNDLPPM1" {
            return Err(bad());
        }
        let u32_at = |o: usize| u32::from_le_bytes(bytes[o..o + 4].try_into().unwrap_or([0; 4]));
        let u64_at = |o: usize| u64::from_le_bytes(bytes[o..o + 8].try_into().unwrap_or([0; 8]));
        let origin = UVec2::new(u32_at(8), u32_at(12));
        let size = UVec2::new(u32_at(16), u32_at(20));
        let passes = (u64_at(24), u64_at(32));
        let n = size.x as usize * size.y as usize;
        if bytes.len() != 40 + n * 48 || passes.0 > passes.1 {
            return Err(bad());
        }
        let sums = (0..n)
            .map(|i| {
                [0, 1, 2].map(|c| {
                    let o = 40 + i * 48 + c * 16;
                    i128::from_le_bytes(bytes[o..o + 16].try_into().unwrap_or([0; 16]))
                })
            })
            .collect();
        Ok(Self {
            origin,
            size,
            passes,
            sums,
        })
    }
}

impl PpmIntegrator {
    /// Renders passes [begin, end) into fixed-point sums.
    pub fn render_partial(&self, ctx: &RenderContext<'_>, film: &RgbFilm) -> PpmPartial {
        let st = &self.settings;
        let pixels = pixel_list(film);
        let (lo, hi) = film.pixel_bounds();
        let (begin, end) = st
            .pass_range
            .unwrap_or((0, ctx.sampler.samples_per_pixel() as u64));
        let n_photons = if st.photons_per_pass > 0 {
            st.photons_per_pass as u64
        } else {
            pixels.len() as u64
        };
        let shoot = ShootSettings {
            max_depth: st.max_depth,
            seed: st.seed,
            caustic_only: false,
        };
        let mut sums = vec![[0i128; 3]; pixels.len()];
        ctx.progress.start(end.saturating_sub(begin), "passes");
        let t0 = std::time::Instant::now();
        for pass in begin..end {
            let lambda = pass_wavelengths(st.seed, pass);
            let visits = camera_pass(ctx, film, &pixels, pass as u32, &lambda, st.max_depth);
            let r2 = (st.radius as f64).powi(2) * ppm_radius2(pass + 1, ALPHA);
            let radius = vec![r2.sqrt() as f32; pixels.len()];
            let gathered = photon_pass(
                ctx.scene, &visits, &radius, &lambda, &shoot, pass, n_photons,
            );
            let norm = 1.0 / (n_photons as f64 * std::f64::consts::PI * r2);
            for ((sum, v), g) in sums.iter_mut().zip(&visits).zip(&gathered) {
                let phi = match &v.vp {
                    Some(vp) if g.m > 0 => film.sensor().to_sensor_rgb(vp.beta * g.phi, &lambda),
                    _ => [0.0; 3],
                };
                for c in 0..3 {
                    let l = v.ld[c] as f64 + phi[c] as f64 * norm;
                    if l.is_finite() {
                        sum[c] += (l * FIXED).round() as i128;
                    }
                }
            }
            ctx.progress.advance(1);
            let rate = (pass - begin + 1) as f64 * n_photons as f64 / t0.elapsed().as_secs_f64();
            ctx.progress.message(&format!(
                "{:.2} M photons/s, radius {:.4}",
                rate / 1e6,
                r2.sqrt()
            ));
        }
        ctx.progress.finish();
        PpmPartial {
            origin: lo,
            size: hi - lo,
            passes: (begin, end),
            sums,
        }
    }
}

impl Integrator for PpmIntegrator {
    fn render(&self, ctx: &RenderContext<'_>, film: &mut RgbFilm) {
        let partial = self.render_partial(ctx, film);
        if let Some(path) = &self.settings.partial_out {
            if let Err(e) = partial.save(path) {
                eprintln!("warning: could not write {}: {e}", path.display());
            }
        }
        partial.write_film(film);
    }
}
