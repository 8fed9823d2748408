//! The photometric web of an IES LM-63 file: luminous intensity I(ω) \[cd\]
//! over the whole sphere, its flux, and emission sampling ∝ I.
//!
//! **Light frame.** Photometric zero (type C nadir, vertical angle 0) is the
//! light's **+z**; the type C horizontal angle 0 is **+x**. LM-63 measures
//! type C horizontal angles counterclockwise seen from above the luminaire
//! [LM-63-2002 §3, "Horizontal angles"]; with the zenith at −z, a right-handed
//! frame reproduces the luminaire unmirrored only if horizontal angle 90° is
//! **−y**, so that is our choice: light-space azimuth φ = atan2(y, x) = −H.
//! (Taking H = +φ would mirror every laterally asymmetric luminaire; files
//! with axial, quadrant or 0–180° symmetry look the same either way.)
//!
//! Types A and B have a polar axis perpendicular to photometric zero, which is
//! again +z (LM-63's photometric zero is H = V = 0 for type B; type A's beam
//! axis H = V = 0 is also put on +z, so that both aim along the light's +z):
//! - **type B**: the polar axis is light **+y**. V rotates +z towards +x
//!   (V = 90° is +x, LM-63's photometric horizontal as for type C), H is the
//!   latitude towards +y (clockwise seen from above, LM-63's sense for A and
//!   B): ω = (cos H sin V, sin H, cos H cos V);
//! - **type A**: type B turned 90° about the beam, polar axis light **+x**:
//!   H rotates +z towards +y, V is the latitude towards +x:
//!   ω = (sin V, cos V sin H, cos V cos H).
//!
//! The standard text available to us fixes the polar axes but not these
//! signs for A/B; they only matter for laterally asymmetric A/B files.
//!
//! **One grid for every type.** Each type is a spherical coordinate system
//! (polar angle ϑ about an axis e3, azimuth ψ from e1 towards e2):
//! C: (ψ, ϑ) = (H, V), e = (+x, −y, +z); B: (V, 90° − H), e = (+z, +x, +y);
//! A: (H, 90° − V), e = (+z, +y, +x). The lateral symmetry is first expanded
//! to the full range by mirroring the planes (I(−H) = I(H) for 0–180°
//! and A/B 0–90°; I(180° − H) = I(H) for 90–270°; both for 0–90°; one plane
//! copied to 0° and 360° for axial files), so type C's ψ spans exactly 360°
//! (periodic) and A/B's ψ spans [−90°, 90°]. Outside the tabulated ψ (A/B)
//! and ϑ ranges the intensity is zero.
//!
//! **Interpolation.** Bilinear in the file's two angles, as LM-63 prescribes
//! for type C; for A and B we do the same in their own angles (the change of
//! variables above is affine per axis, so bilinear in (ψ, ϑ) is bilinear in
//! (H, V)). Mirroring keeps cells whole, so every encoding of one light
//! gives the same I(ω).
//!
//! **Flux.** Φ = ∫ I dω = Σ_cells ∫∫ I(ψ, ϑ) sin ϑ dϑ dψ, integrated exactly
//! for the bilinear interpolant: with t = (ϑ − ϑ₀)/Δϑ, the ψ-average of a
//! cell is the linear (1 − t)·a + t·b (a, b the means of its lower and upper
//! corner pairs), and ∫ t sin ϑ dϑ = (sin ϑ₁ − sin ϑ₀ − Δϑ cos ϑ₁)/Δϑ,
//! ∫ sin ϑ dϑ = cos ϑ₀ − cos ϑ₁. For relative photometry,
//! [`IesWeb::flux_fraction`] is Φ over the rated lamp lumens.
//!
//! **Sampling** (`sample`): a cell is chosen with probability ∝ its flux
//! (marginal over ψ columns, conditional over ϑ rows, [`Distribution1D`]),
//! then within the cell ϑ from its marginal (a + (b − a)t)·sin ϑ by
//! safeguarded Newton inversion of its closed-form CDF, then ψ from the
//! linear conditional [`sample_linear`]. The density in (ψ, ϑ) is
//! I·sin ϑ/F_cell, so per unit solid angle it is
//! p(ω) = P(cell)·I(ω)/F_cell = I(ω)/Φ up to the f32 rounding of the cell
//! probabilities: β₀ = I/p = Φ for every sample, as for the other lights.
//! Directions computed from f32 vectors that fall within `ANGLE_EPS` (10⁻⁶ rad) outside
//! the tabulated range are clamped onto it.

mod sample;

#[cfg(test)]
mod tests;

use crate::math::Vec3;
use crate::sampling::{Distribution1D, PdfSolidAngle};
use candela_scene::ies::{IesFile, PhotometricType, Symmetry};

pub use sample::IesSample;

/// Tolerance [rad] by which a direction may lie outside the tabulated
/// angular range and still take the boundary value (f32 round-off).
const ANGLE_EPS: f64 = 1e-6;

/// An IES file that cannot form a web (only for hand-built [`IesFile`]s:
/// the reader rejects these with a file location).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("invalid IES photometric web: {0}")]
pub struct IesWebError(String);

/// Luminous intensity of an IES luminaire over the sphere, in the light frame.
#[derive(Clone, Debug)]
pub struct IesWeb {
    /// Axes (e1, e2, e3) of the web's spherical coordinates in the light frame.
    axes: [[f64; 3]; 3],
    /// Azimuths ψ [rad], increasing; spanning exactly 2π when `periodic`.
    azimuth: Vec<f64>,
    periodic: bool,
    /// Polar angles ϑ [rad], increasing, in [0, π].
    polar: Vec<f64>,
    /// Intensities \[cd\] at the nodes, `values[j * polar.len() + i]`.
    values: Vec<f64>,
    /// Exact ∫ I dω over cell (j, i), `cell_flux[j * (polar.len() - 1) + i]`.
    cell_flux: Vec<f64>,
    flux: f64,
    /// Cell choice: a column j by its flux, then a row i within it.
    columns: Distribution1D,
    rows: Vec<Distribution1D>,
    lamp_lumens: Option<f64>,
}

/// Location of a direction in the grid: cell (j, i) and the fractions (s, t)
/// along ψ and ϑ within it.
#[derive(Clone, Copy, Debug)]
struct Cell {
    j: usize,
    i: usize,
    s: f64,
    t: f64,
}

impl IesWeb {
    /// The web of a parsed IES file (expanded to the full sphere).
    pub fn new(ies: &IesFile) -> Result<Self, IesWebError> {
        let err = |m: &str| Err(IesWebError(m.to_string()));
        let (v, h) = (&ies.vertical_angles, &ies.horizontal_angles);
        if v.len() < 2 || h.is_empty() || ies.candela.len() != v.len() * h.len() {
            return err("needs ≥ 2 vertical angles, ≥ 1 horizontal angle and nv·nh values");
        }
        let increasing = |a: &[f64]| a.windows(2).all(|w| w[0] < w[1]);
        if !increasing(v) || !increasing(h) || v.iter().chain(h).any(|a| !a.is_finite()) {
            return err("angles must be finite and strictly increasing");
        }
        let (vlo, vhi) = match ies.photometric_type {
            PhotometricType::C => (0.0, 180.0),
            _ => (-90.0, 90.0),
        };
        if v[0] < vlo || v[v.len() - 1] > vhi {
            return err("vertical angles out of range");
        }
        if ies.candela.iter().any(|c| !c.is_finite() || *c < 0.0) {
            return err("candela values must be finite and non-negative");
        }
        let Some(symmetry) = ies.symmetry() else {
            return err("horizontal angles are not an LM-63 range");
        };
        let planes: Vec<Vec<f64>> = ies.candela.chunks(v.len()).map(<[f64]>::to_vec).collect();
        let (h, planes) = expand(symmetry, h.clone(), planes);
        Ok(Self::from_grid(ies, v, &h, &planes))
    }

    /// Builds the (ψ, ϑ) grid of the expanded planes and its distributions.
    fn from_grid(ies: &IesFile, v: &[f64], h: &[f64], planes: &[Vec<f64>]) -> Self {
        let rad = |a: &f64| a.to_radians();
        let (x, y, z) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
        let (nv, nh) = (v.len(), h.len());
        let (axes, azimuth, polar, values): ([[f64; 3]; 3], Vec<f64>, Vec<f64>, Vec<f64>) =
            match ies.photometric_type {
                // ψ = H, ϑ = V.
                PhotometricType::C => (
                    [x, [0.0, -1.0, 0.0], z],
                    h.iter().map(rad).collect(),
                    v.iter().map(rad).collect(),
                    planes.concat(),
                ),
                // ψ = V, ϑ = 90° − H: column j is vertical angle j, row i is
                // horizontal angle nh − 1 − i.
                PhotometricType::B => (
                    [z, x, y],
                    v.iter().map(rad).collect(),
                    h.iter().rev().map(|a| (90.0 - a).to_radians()).collect(),
                    (0..nv)
                        .flat_map(|j| (0..nh).rev().map(move |k| planes[k][j]))
                        .collect(),
                ),
                // ψ = H, ϑ = 90° − V.
                PhotometricType::A => (
                    [z, y, x],
                    h.iter().map(rad).collect(),
                    v.iter().rev().map(|a| (90.0 - a).to_radians()).collect(),
                    planes
                        .iter()
                        .flat_map(|p| p.iter().rev().copied())
                        .collect(),
                ),
            };
        let np = polar.len();
        let cell_flux: Vec<f64> = (0..azimuth.len() - 1)
            .flat_map(|j| (0..np - 1).map(move |i| (j, i)))
            .map(|(j, i)| {
                let c = |jj: usize, ii: usize| values[jj * np + ii];
                let lower = 0.5 * (c(j, i) + c(j + 1, i));
                let upper = 0.5 * (c(j, i + 1) + c(j + 1, i + 1));
                let [w0, w1] = polar_weights(polar[i], polar[i + 1]);
                (azimuth[j + 1] - azimuth[j]) * (lower * w0 + upper * w1)
            })
            .collect();
        let rows: Vec<Distribution1D> = cell_flux
            .chunks(np - 1)
            .map(|r| Distribution1D::new(&r.iter().map(|&f| f as f32).collect::<Vec<_>>()))
            .collect();
        let column_flux: Vec<f32> = cell_flux
            .chunks(np - 1)
            .map(|r| r.iter().sum::<f64>() as f32)
            .collect();
        let periodic = ies.photometric_type == PhotometricType::C;
        debug_assert!(
            !periodic
                || (azimuth[azimuth.len() - 1] - azimuth[0] - 2.0 * std::f64::consts::PI).abs()
                    < 1e-9
        );
        Self {
            axes,
            azimuth,
            periodic,
            polar,
            values,
            flux: cell_flux.iter().sum(),
            cell_flux,
            columns: Distribution1D::new(&column_flux),
            rows,
            lamp_lumens: ies.lamp_lumens(),
        }
    }

    /// Luminous intensity \[cd\] towards unit light-frame direction `w`.
    pub fn intensity(&self, w: Vec3) -> f32 {
        self.locate(w).map_or(0.0, |c| self.bilinear(c) as f32)
    }

    /// Total luminous flux Φ = ∫ I dω \[lm\] of the interpolated web (exact).
    pub fn flux(&self) -> f64 {
        self.flux
    }

    /// Rated lamp lumens of the file (lamps × lumens per lamp); `None` for
    /// absolute photometry.
    pub fn lamp_lumens(&self) -> Option<f64> {
        self.lamp_lumens
    }

    /// Φ over the rated lamp lumens (the luminaire's efficiency times the
    /// file's multipliers); `None` for absolute photometry.
    pub fn flux_fraction(&self) -> Option<f64> {
        self.lamp_lumens.map(|l| self.flux / l)
    }

    /// Density per unit solid angle with which [`sample`](Self::sample)
    /// returns `w`: P(cell)·I(w)/F_cell (= I(w)/Φ).
    pub fn pdf(&self, w: Vec3) -> PdfSolidAngle {
        match self.locate(w) {
            Some(c) => PdfSolidAngle(self.cell_pdf(c, self.bilinear(c)) as f32),
            None => PdfSolidAngle(0.0),
        }
    }

    /// Solid-angle density of a point of cell `c` whose intensity is `i`.
    fn cell_pdf(&self, c: Cell, i: f64) -> f64 {
        let f = self.cell_flux[c.j * (self.polar.len() - 1) + c.i];
        if f <= 0.0 {
            return 0.0;
        }
        let p = self.columns.discrete_pmf(c.j) as f64 * self.rows[c.j].discrete_pmf(c.i) as f64;
        p * i / f
    }

    /// Node value at azimuth index `j`, polar index `i`.
    fn node(&self, j: usize, i: usize) -> f64 {
        self.values[j * self.polar.len() + i]
    }

    /// Bilinear interpolation inside cell `c`.
    fn bilinear(&self, c: Cell) -> f64 {
        let lo = lerp(c.s, self.node(c.j, c.i), self.node(c.j + 1, c.i));
        let hi = lerp(c.s, self.node(c.j, c.i + 1), self.node(c.j + 1, c.i + 1));
        lerp(c.t, lo, hi)
    }

    /// Cell and fractions of direction `w`, `None` outside the tabulated range.
    fn locate(&self, w: Vec3) -> Option<Cell> {
        let w = [w.x as f64, w.y as f64, w.z as f64];
        let dot = |e: &[f64; 3]| e[0] * w[0] + e[1] * w[1] + e[2] * w[2];
        let [a, b, c] = self.axes.each_ref().map(dot);
        let theta = a.hypot(b).atan2(c);
        let mut psi = b.atan2(a);
        let az = &self.azimuth;
        if self.periodic {
            psi = az[0] + (psi - az[0]).rem_euclid(2.0 * std::f64::consts::PI);
        }
        let (j, s) = interval(az, psi)?;
        let (i, t) = interval(&self.polar, theta)?;
        Some(Cell { j, i, s, t })
    }
}

/// The interval of increasing `grid` holding `x` and the fraction along it;
/// `None` beyond the ends by more than [`ANGLE_EPS`].
fn interval(grid: &[f64], x: f64) -> Option<(usize, f64)> {
    let (first, last) = (grid[0], grid[grid.len() - 1]);
    if x < first - ANGLE_EPS || x > last + ANGLE_EPS {
        return None;
    }
    let x = x.clamp(first, last);
    let k = grid.partition_point(|&g| g <= x).clamp(1, grid.len() - 1) - 1;
    let t = (x - grid[k]) / (grid[k + 1] - grid[k]);
    Some((k, t.clamp(0.0, 1.0)))
}

/// [∫(1 − t) sin ϑ dϑ, ∫ t sin ϑ dϑ] over [ϑ₀, ϑ₁], t = (ϑ − ϑ₀)/(ϑ₁ − ϑ₀).
fn polar_weights(t0: f64, t1: f64) -> [f64; 2] {
    let d = t1 - t0;
    let w1 = (t1.sin() - t0.sin() - d * t1.cos()) / d;
    [(t0.cos() - t1.cos()) - w1, w1]
}

/// `a + t·(b − a)`.
fn lerp(t: f64, a: f64, b: f64) -> f64 {
    a + t * (b - a)
}

/// Expands the planes (angles `h`, one column of values per angle) of a
/// lateral symmetry to its full range (module doc).
fn expand(symmetry: Symmetry, h: Vec<f64>, planes: Vec<Vec<f64>>) -> (Vec<f64>, Vec<Vec<f64>>) {
    match symmetry {
        Symmetry::Asymmetric => (h, planes),
        Symmetry::Axial => (vec![0.0, 360.0], vec![planes[0].clone(), planes[0].clone()]),
        Symmetry::Bilateral => mirror(h, planes, 0.0, false),
        Symmetry::Bilateral90 => mirror(h, planes, 90.0, false),
        Symmetry::Quadrant => {
            let (h, p) = mirror(h, planes, 0.0, false);
            mirror(h, p, 90.0, true)
        }
    }
}

/// Adds the mirror images a ↦ 2c − a of the planes about the plane at `c`,
/// which is the first angle (`above` false: images go below) or the last.
fn mirror(h: Vec<f64>, p: Vec<Vec<f64>>, c: f64, above: bool) -> (Vec<f64>, Vec<Vec<f64>>) {
    let n = h.len();
    let images: Vec<usize> = if above {
        (0..n - 1).rev().collect()
    } else {
        (1..n).rev().collect()
    };
    let (mh, mp): (Vec<f64>, Vec<Vec<f64>>) = images
        .iter()
        .map(|&k| (2.0 * c - h[k], p[k].clone()))
        .unzip();
    if above {
        ([h, mh].concat(), [p, mp].concat())
    } else {
        ([mh, h].concat(), [mp, p].concat())
    }
}
