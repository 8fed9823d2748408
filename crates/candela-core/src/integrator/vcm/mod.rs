//! Vertex connection and merging (`Integrator "vcm"`) [Georgiev, Křivánek,
//! Davidovič & Slusallek 2012, "Light transport simulation with vertex
//! connection and merging" and its tech. rep. "Implementing Vertex
//! Connection and Merging"; Hachisuka, Pantaleoni & Jensen 2012; SmallVCM
//! `vertexcm.hxx` for the shape of one estimator with several modes].
//!
//! A light-subpath vertex is at once a BDPT vertex and a photon: it carries
//! β = Le|cos θ|/(p_light p_pos p_dir) times the scatterings' f|cos|/p, and
//! a camera vertex either *connects* to it (a shadow ray, BDPT's s ≥ 1,
//! t ≥ 2 strategies) or *merges* with it when it lies within radius r
//! (density estimation, L += β_E f β_L/(π r² N_light)). VCM weighs all of
//! these, and light tracing, next-event estimation and emission hits, under
//! one MIS with the power heuristic, merging counted as a technique of
//! density π r² N_light times the light side's (the merge probability η,
//! [`mis`]).
//!
//! **An iteration is a pass.** Pass i: (1) [`light`] walks N_light light
//! subpaths (default one per pixel of the full film), stores their
//! non-specular vertices with their MIS quantities, and splats their
//! connections to the camera, from the light's own point x_0 on (a light
//! seen directly is shared between the camera's rays and light tracing, as
//! in BDPT; SmallVCM leaves it to the camera, whose one ray per pixel and
//! pass makes a pixel on a light's edge noisy: on the Cornell box at 128²,
//! 90 iterations, seeds 1–3, the error of the 10 × 32 pixels around the
//! light fell from 0.000119 / 0.000090 / 0.000085 to 0.000051 / 0.000053 /
//! 0.000064 of the image's relMSE, the image's from 0.000922 / 0.000870 /
//! 0.000882 to 0.000858 / 0.000849 / 0.000853, for 2.5 % more time); (2) a `HashGrid` over the stored vertices
//! with cells of 2r, and compact copies of them in its order (`merge`);
//! (3) `camera` walks one camera subpath per pixel, connecting to the light subpath of the same index and merging with every
//! stored vertex within r. The radius of pass i (0-based) is
//! r_i² = r₀² Π_{k=1}^{i} (k + α)/(k + 1) [Knaus & Zwicker 2011, eq. 16],
//! candela's `ppm` schedule, so pass i depends on i alone: passes are
//! independent and `--pass-range` renders merge exactly.
//!
//! **Spectral.** All subpaths of an iteration share its wavelengths (a
//! golden-ratio sequence over passes, as SPPM) and its time (one shutter
//! time per iteration), so light vertices carry spectral power at the
//! camera's wavelengths. Dispersion is folded into β on both sides
//! ([`crate::integrator::subpath::Dispersion::Fold`]); a join of two
//! subpaths that both kept only the hero wavelength takes the fold's factor
//! once.
//!
//! **Modes** (`"string mode"`): `vcm` (connections and merges), `bpt`
//! (connections only; equal to `bdpt` in expectation), `bpm` (merges at
//! every non-specular camera vertex), `ppm` (merges at the first
//! non-specular camera vertex, unweighted, then stops: materials mixing
//! specular and non-specular lobes lose their specular part there, as in
//! SmallVCM), `lt` (light tracing only, light points included).
//!
//! **Depth.** `maxdepth` bounds the scattering vertices of the whole path
//! (camera and light vertices together), as in `path` and `bdpt`, except in
//! mode `ppm`, which bounds the camera path and the light path each (the
//! camera's merge vertex at depth ≤ maxdepth, the light vertex too, no light
//! seen beyond vertex maxdepth), as `ppm` and `sppm` do after pbrt-v4's
//! SPPM: so mode `ppm` equals `ppm` at any depth. Through a slab of glass
//! under a point light at `maxdepth` 8 the whole-path bound leaves vcm
//! 1.5–2 % darker than `sppm`; at 40 they agree to 0.2 %.
//!
//! **Resampled connections** (`"string connections"`, `one` by default,
//! `all` for BDPT's estimator) and **join roulette** (`"float
//! joinroulette"` τ, 0.1 by default): the module doc of `resample.rs`.
//!
//! **Merges next to the light** (`"string directmerges"`, [`mis`]): by
//! default (`afterspecular`) a light vertex that the light reached
//! directly merges only with camera vertices reached through a specular
//! one (a floor seen through glass); elsewhere direct light is left to
//! next-event estimation, light tracing and hitting the light, as SPPM
//! does, and the MIS weights leave that merge out exactly where it does
//! not exist. `always` merges them everywhere (the modes without
//! connections must), `never` nowhere. Measured at equal time (16 s, 2
//! threads, half resolution, relMSE against long references, seed 1),
//! with the pilot's radius at K = 2 (below) and before the light-subpath
//! roulette fix: the Cornell box 0.000607 against
//! `always`'s 0.000714, with no bright seam where a lit box top meets its
//! dimmer side (the merge kernel averaged the two faces' direct light
//! there, +0.15 on the seam's pixels at radius 0.064); the pool 0.0145
//! against 0.0159; caustic-glass 0.0135 against 0.0119, where `never` gave
//! 0.0248 (the floor seen through the glass, in and out of its shadow).
//!
//! **Default radius**: without a written `radius`, the first pass runs a
//! pilot light pass and takes the radius whose disk holds three other
//! merging light vertices around the median one, within 2–6 pixel
//! footprints ([`pilot`]). A merge's noise is set by the vertices in its
//! disk and its kernel bias by the radius, and the vertex density per
//! pixel footprint differs twentyfold between these scenes. Measured at
//! 16 s as above, seeds 1 and 2, once light subpaths were played by the
//! share of their starting power ([`crate::integrator::roulette`]; they
//! used to end near the fourth vertex), with the neighbour count K: the
//! Cornell box 0.000551–0.000703 (K = 2), 0.000490–0.000589 (3),
//! 0.000483–0.000501 (4); the pool 0.0147–0.0150 (2), 0.0164–0.0209 (3),
//! 0.0222–0.0265 (4); caustic-glass 0.0148–0.0155 (2), 0.0127–0.0137 (3),
//! 0.0138–0.0141 (4). Diffuse interreflection wants many neighbours,
//! caustics few; K = 3 keeps all three scenes inside the equal-time
//! targets of the benchmark (`bench/vcm_equal_time.py`), where K = 2
//! missed on the Cornell box and K = 4 on the pool.
//!
//! **Local radius** (`"bool localradius"`, true by default; only without a
//! written `radius`): the same rule applied per cell of space instead of
//! once for the image, from four pilot light passes ([`field`]): small
//! where light vertices are dense (a caustic's lines), large where they are
//! sparse, each merge with its own vertex's η in the MIS weights; dropped
//! where it would equal the global radius (the Cornell box). Measured on
//! the pool at 8 s, two seeds: relMSE 0.0104 / 0.0101 against 0.0134 /
//! 0.0140 with one radius; the equal-time benchmark's ratio to sppm went
//! from 0.97 / 1.01 / 0.97 to about 0.8 / 0.75 / 0.75 (4 / 8 / 16 s).
//!
//! **Light tracing on direct light (a limit of density-based weights).** The
//! power heuristic weighs techniques by density alone. On the Cornell box
//! (128², one light path per pixel) about 1.7 light subpaths land in a
//! floor pixel's footprint per iteration against the camera's one sample,
//! so light tracing takes 46 % of the light reflected straight to the
//! camera, but its estimate for one pixel is a Poisson count of splats,
//! while next-event estimation on a small, evenly bright light has almost
//! constant f/p. Split by technique (depth 1, 36 iterations, per-pixel
//! variance over six seeds, weighted as relMSE weighs it): next-event
//! estimation 0.000185, light tracing 0.000914, hitting the light
//! 0.000158; without light tracing the direct light's relMSE is 0.0007
//! instead of 0.00125. The weights still sum to one (no bias); the heuristic
//! ignores the −I² term of a near-zero-variance technique [Veach 1997,
//! §9.2; Grittmann, Georgiev, Slusallek & Křivánek 2019, "Variance-aware
//! multiple importance sampling"]. Scaling light tracing's density by 1/4
//! in every weight helped the Cornell box (−6 % at full depth) and hurt
//! caustic-glass (+8–11 %, where light tracing carries the caustic seen on
//! the floor), so the factor is chosen per image block and path length
//! from the camera side's variance in a pilot ([`variance`], `"string
//! ltweights"`, `variance` by default, `density` for SmallVCM's weights):
//! the Cornell box's direct light 0.00065 instead of 0.00131 at 36
//! iterations, the whole image −17 %, caustic-glass within 1 %.
//!
//! **α.** The default is 0.5, below both the paper's 0.75 (Georgiev et al.
//! 2012, §7; SmallVCM) and Knaus and Zwicker's asymptotically best 2/3:
//! at the times renders are made, the merges' error is mostly the kernel's
//! bias, and a sharp caustic seen through water is blurred for longer by a
//! radius that shrinks slowly. Measured against low-bias references (the
//! pool at 160×120, vcm at radius 0.025 for 2 × 24 000 iterations;
//! caustic-glass at 175×250, radius 0.02 for 600 s), relMSE at 4 / 16 s,
//! two threads, one seed: the pool 0.0333 / 0.0235 at α = 0.75, 0.0275 /
//! 0.0163 at 2/3, 0.0207 / 0.0092 at 0.5 (sppm 0.0206 / 0.0094);
//! caustic-glass 0.0124 / 0.0047, 0.0123 / 0.0044, 0.0127 / 0.0046 (sppm
//! 0.0140 / 0.0051); the Cornell box at 128² against a path-traced
//! reference, two seeds, 0.00086 / 0.00034 at 0.75 and 0.00090 / 0.00030
//! at 0.5. Against references that were themselves means of vcm and sppm
//! renders of a few thousand iterations, blurred by their own kernels, the
//! slow 0.75 had looked best: a reference's kernel bias favours the
//! estimators that share it.

mod camera;
pub mod densities;
pub mod field;
mod iteration;
pub mod light;
mod merge;
pub mod mis;
#[cfg(test)]
mod mis_brute;
pub mod pilot;
mod resample;
pub mod variance;

use super::{Integrator, IntegratorKind, IntegratorState, PassOutcome, PassWork, RenderContext};
use crate::film::PassBlock;
use crate::integrator::lt_weights::{Pilot, PILOT_PASSES};
use crate::integrator::sppm::ppm_radius2;
use crate::sampling::hash_u64s;
use crate::sampling::PdfSolidAngle;
use field::{FactorField, RadiusField};
use light::LightVertex;
use mis::DirectMerges;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::OnceLock;

/// Memory of one stored light vertex in bytes (position, normals, BSDF,
/// β, MIS quantities: [`LightVertex`]); an iteration stores
/// about N_light × (mean non-specular light-subpath length) of them.
pub const LIGHT_VERTEX_BYTES: usize = std::mem::size_of::<LightVertex>();

/// Memory of one stored light vertex with its merge copy and grid entry
/// (the claim at build time adds its light path's 4-byte end index).
pub const STORED_VERTEX_BYTES: usize = LIGHT_VERTEX_BYTES + merge::MERGE_BYTES;

pub use crate::integrator::lt_weights::PILOT_BYTES_PER_PIXEL;

/// Which estimator the one VCM loop runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VcmMode {
    /// Vertex connection and merging.
    Vcm,
    /// Bidirectional path tracing (connections only).
    Bpt,
    /// Bidirectional photon mapping (merges only).
    Bpm,
    /// Progressive photon mapping (one merge at the first diffuse vertex).
    Ppm,
    /// Light tracing only.
    Lt,
}

impl VcmMode {
    /// The mode named `s`, if any.
    pub fn from_name(s: &str) -> Option<Self> {
        Some(match s {
            "vcm" => VcmMode::Vcm,
            "bpt" => VcmMode::Bpt,
            "bpm" => VcmMode::Bpm,
            "ppm" => VcmMode::Ppm,
            "lt" => VcmMode::Lt,
            _ => return None,
        })
    }

    /// Names accepted by [`VcmMode::from_name`].
    pub const NAMES: &'static str = "vcm, bpt, bpm, ppm, lt";

    /// Merges without connections: its merges next to the light are its
    /// only technique for direct light, so all of them exist ([`mis`]).
    pub fn merges_only(self) -> bool {
        let t = self.techniques();
        t.merge && !t.connect
    }

    fn techniques(self) -> Techniques {
        let (connect, merge) = match self {
            VcmMode::Vcm => (true, true),
            VcmMode::Bpt => (true, false),
            VcmMode::Bpm | VcmMode::Ppm => (false, true),
            VcmMode::Lt => (false, false),
        };
        Techniques {
            connect,
            merge,
            ppm: self == VcmMode::Ppm,
            light_only: self == VcmMode::Lt,
        }
    }
}

/// How a camera vertex joins the light subpath of its pixel
/// (`"string connections"`; module doc, "Resampled connections").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Connections {
    /// A shadow ray to every light vertex (`all`): the BDPT estimator.
    All,
    /// One shadow ray, to a light vertex drawn in proportion to its
    /// unoccluded contribution (`one`).
    One,
}

impl Connections {
    /// The setting named `s`, if any.
    pub fn from_name(s: &str) -> Option<Self> {
        match s {
            "all" => Some(Connections::All),
            "one" => Some(Connections::One),
            _ => None,
        }
    }

    /// The setting's name in a scene file.
    pub fn name(self) -> &'static str {
        match self {
            Connections::All => "all",
            Connections::One => "one",
        }
    }

    /// Names accepted by [`Connections::from_name`].
    pub const NAMES: &'static str = "all, one";
}

/// The techniques a mode runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Techniques {
    /// Connections: light tracing, next-event estimation, vertex connections.
    pub connect: bool,
    /// Merges.
    pub merge: bool,
    /// Merge once, unweighted, and stop (mode `ppm`).
    pub ppm: bool,
    /// No camera subpaths (mode `lt`).
    pub light_only: bool,
}

/// Parameters of `Integrator "vcm"`.
#[derive(Clone, Debug)]
pub struct VcmSettings {
    /// Maximum number of scattering vertices of a path (`maxdepth`, 5).
    pub max_depth: u32,
    /// Merge radius of the first iteration (`radius`; scene-scale default).
    pub radius: f32,
    /// `radius` was not written: it is one pixel footprint, and the first
    /// pass replaces it by the light vertices' density ([`pilot`]).
    pub radius_from_density: bool,
    /// Radius reduction α (`alpha`, 0.5; module doc).
    pub alpha: f32,
    /// Light paths per iteration (`photonsperiteration`; ≤ 0: one per pixel
    /// of the full film).
    pub light_paths: i64,
    /// Seed (`seed`).
    pub seed: u64,
    /// Roughen near-specular lobes on camera subpaths (`regularize`).
    pub regularize: bool,
    /// The algorithm (`mode`).
    pub mode: VcmMode,
    /// Connections per camera vertex (`connections`).
    pub connections: Connections,
    /// Merges at the vertex next to the light (`directmerges`; module doc
    /// of [`mis`]).
    pub direct_merges: DirectMerges,
    /// Light tracing weighed by the camera side's variance from a pilot
    /// (`"string ltweights" "variance"`) or by density alone (`"density"`)
    /// ([`variance`]).
    pub variance_lt: bool,
    /// Joins (shadow rays) whose MIS weight is below this are made with
    /// probability weight / value (`joinroulette`; 0: all; [`mis::thin`]).
    pub join_roulette: f32,
    /// A camera subpath whose first vertex is a smooth dielectric forks
    /// there to count the emission its reflection reaches (`splitspecular`;
    /// module doc of [`crate::integrator::subpath`], "Splitting").
    pub split_specular: bool,
    /// Without a written `radius`, the merge radius varies over the scene
    /// with the light vertices' density (`localradius`; [`field`]).
    pub local_radius: bool,
}

impl Default for VcmSettings {
    fn default() -> Self {
        Self {
            max_depth: 5,
            radius: 1.0,
            radius_from_density: false,
            alpha: 0.5,
            light_paths: -1,
            seed: 0,
            regularize: false,
            mode: VcmMode::Vcm,
            connections: Connections::One,
            direct_merges: DirectMerges::AfterSpecular,
            variance_lt: true,
            join_roulette: 0.1,
            split_specular: true,
            local_radius: true,
        }
    }
}

/// The VCM integrator.
pub struct VcmIntegrator {
    /// Settings.
    pub settings: VcmSettings,
    techniques: Techniques,
    /// Light vertices the last finished light pass stored (for the status
    /// line only; the image never depends on it).
    stored: AtomicU64,
    /// Storage reused from one iteration to the next.
    pools: Pools,
    /// The first iteration's radius once known (the written one, or the
    /// pilot's), and the pilot's radius field (`localradius`).
    radius0: OnceLock<(f32, Option<RadiusField>)>,
    /// Light tracing's factors in the weights, and their pilot ([`variance`]).
    pilot: Pilot,
}

/// The buffers a pass hands to the next ([`light::Pool`]).
#[derive(Default)]
struct Pools {
    chunks: light::Pool<light::PathChunk>,
}

impl VcmIntegrator {
    /// The integrator with `settings`.
    pub fn new(settings: VcmSettings) -> Self {
        let techniques = settings.mode.techniques();
        Self {
            settings,
            techniques,
            stored: AtomicU64::new(0),
            pools: Pools::default(),
            radius0: OnceLock::new(),
            pilot: Pilot::default(),
        }
    }

    /// The first iteration's radius: the written one, or the light vertices'
    /// density radius of a pilot pass ([`pilot`]); `None` if cancelled.
    fn radius0(&self, ctx: &RenderContext<'_>) -> Option<f32> {
        if let Some((r, _)) = self.radius0.get() {
            return Some(*r);
        }
        let r = if self.settings.radius_from_density && self.techniques.merge {
            pilot::density_radius(self, ctx, self.settings.radius)?
        } else {
            (self.settings.radius, None)
        };
        Some(self.radius0.get_or_init(|| r).0)
    }

    /// The MIS factors and merge radii of (0-based) pass `pass` with
    /// `n_light` light paths: from the radius field where there is one
    /// ([`field`]), else uniform at [`VcmIntegrator::radius`].
    fn factors(&self, pass: u64, n_light: f32) -> FactorField<'_> {
        let t = self.techniques;
        let r = self.radius(pass);
        let f = FactorField::uniform(r, n_light, t.connect, t.merge, self.direct_merges());
        match self.radius0.get() {
            Some((r0, Some(field))) => FactorField::of_field(field, r / r0, r, f),
            _ => f,
        }
    }

    /// Which merges at a vertex next to the light are a technique: the
    /// `directmerges` setting, every one in the merge-only modes ([`mis`]).
    fn direct_merges(&self) -> DirectMerges {
        if self.settings.mode.merges_only() {
            DirectMerges::Always
        } else {
            self.settings.direct_merges
        }
    }

    /// Light subpaths per iteration.
    pub fn light_paths(&self, ctx: &RenderContext<'_>) -> u64 {
        if self.settings.light_paths > 0 {
            self.settings.light_paths as u64
        } else {
            full_pixels(ctx)
        }
    }

    /// The merge radius of (0-based) pass `pass` (before the first pass of
    /// a density-derived radius: from the footprint default).
    pub fn radius(&self, pass: u64) -> f32 {
        let r0 = self.radius0.get().map_or(self.settings.radius, |r| r.0) as f64;
        (r0 * r0 * ppm_radius2(pass + 1, self.settings.alpha as f64)).sqrt() as f32
    }

    /// Solid-angle density per unit pixel area of a camera ray whose
    /// film-normalised direction density is `pdf_dir` (times the full
    /// film's pixel count).
    fn pixel_density(&self, pdf_dir: PdfSolidAngle, ctx: &RenderContext<'_>) -> f32 {
        pdf_dir.0 * full_pixels(ctx) as f32
    }

    /// Factor of light-tracing splats: the film counts one light path per
    /// pixel of the full film in a pass.
    fn splat_scale(&self, ctx: &RenderContext<'_>) -> f32 {
        full_pixels(ctx) as f32 / self.light_paths(ctx).max(1) as f32
    }

    /// The iteration's shutter time.
    fn time(&self, ctx: &RenderContext<'_>, pass: u64) -> f32 {
        let h = hash_u64s(&[self.settings.seed, pass, 0x5643_4d54]);
        let u = (h >> 40) as f32 / (1u64 << 24) as f32;
        ctx.scene.sample_time(|| u)
    }
}

/// Pixels of the full film (the camera's importance is normalised over it).
fn full_pixels(ctx: &RenderContext<'_>) -> u64 {
    let res = ctx.film.resolution();
    res.x as u64 * res.y as u64
}

impl Integrator for VcmIntegrator {
    fn kind(&self) -> IntegratorKind {
        IntegratorKind::Vcm
    }

    fn pass_work(&self, ctx: &RenderContext<'_>) -> PassWork {
        let cam = if self.techniques.light_only {
            0
        } else {
            ctx.film.pixel_count() as u64
        };
        PassWork {
            units: self.light_paths(ctx) + cam,
            unit: "paths",
            light_paths: self.light_paths(ctx),
        }
    }

    fn render_pass(
        &self,
        ctx: &RenderContext<'_>,
        pass: u64,
        _state: &mut IntegratorState,
        block: &mut PassBlock,
    ) -> PassOutcome {
        if self.radius0(ctx).is_none() {
            return PassOutcome::Cancelled;
        }
        // The first passes are the variance pilot's ([`variance`]).
        let (lt, record) = if self.variance_pilot(ctx) && pass < PILOT_PASSES {
            (&*variance::NO_LT, self.pilot.get().is_none())
        } else {
            match self.lt_weights(ctx) {
                Some(lt) => (lt, false),
                None => return PassOutcome::Cancelled,
            }
        };
        let Some(it) = self.iteration(ctx, pass, lt, record) else {
            return PassOutcome::Cancelled;
        };
        if let Some(splats) = &it.splats {
            splats.add_to(block);
        }
        for tile in &it.tiles {
            block.add_tile(tile);
        }
        if let Some(samples) = it.samples {
            self.pilot.keep(ctx.film.resolution(), pass, samples);
        }
        PassOutcome::Done
    }

    fn status(&self, _state: &IntegratorState, next_pass: u64) -> Option<String> {
        let pending = self.settings.radius_from_density
            && self.techniques.merge
            && self.radius0.get().is_none();
        let mut s = if pending {
            format!("iteration {}, radius from a pilot pass", next_pass + 1)
        } else {
            let r = self.radius(next_pass);
            let local = match self.radius0.get() {
                Some((r0, Some(field))) => {
                    let (lo, hi) = field.range();
                    format!(" (over the scene {:.4}–{:.4})", lo * r / r0, hi * r / r0)
                }
                _ => String::new(),
            };
            format!("iteration {}, radius {r:.4}{local}", next_pass + 1)
        };
        let stored = self.stored.load(Ordering::Relaxed);
        if stored > 0 {
            let merge = if self.techniques.merge {
                merge::MERGE_BYTES
            } else {
                0
            };
            s.push_str(&format!(
                ", {stored} light vertices stored × {LIGHT_VERTEX_BYTES} B (+ {merge} B to merge) = {:.1} MB",
                (stored * (LIGHT_VERTEX_BYTES + merge) as u64) as f64 / 1e6
            ));
        }
        Some(s)
    }
}
