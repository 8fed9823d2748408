//! Description → render setup: turns the parser's plain entities into
//! cameras, films, samplers, materials, shapes, lights and an integrator,
//! with pbrt-v4's parameter names and defaults.
//!
//! Everything not supported is an error naming the entity and its
//! file:line:col; parameters nobody looked at become warnings. Every
//! parameter is checked against its domain (`check`) and the large
//! structures against a memory budget ([`budget`]) before they are
//! allocated.

pub mod budget;
mod check;
mod coated;
mod entities;
mod geometry;
mod image_textures;
mod integrators;
mod lights;
mod materials;
mod photometric;
mod photon_scale;
mod shapes;
mod spectra;
mod summary;
mod textures;

pub use budget::parse_memory;
pub use integrators::{kind_from_name, INTEGRATOR_NAMES};
pub use photon_scale::{FALLBACK_SHARE, FOOTPRINT_PIXELS, VCM_FOOTPRINT_PIXELS};
pub use summary::{summarize, Counts, SceneSummary};

use crate::camera::{Camera, PixelFootprint};
use crate::film::{Film, FilmLayout};
use crate::integrator::{Integrator, IntegratorKind};
use crate::sampler::Sampler;
use crate::scene::Scene;
use candela_scene::{Entity, Loc, ParamSet, SceneDescription, SceneError};
use std::path::PathBuf;
use thiserror::Error;

/// A scene that cannot be built.
#[derive(Debug, Error)]
pub enum BuildError {
    /// A problem at a place in the scene file.
    #[error("{loc}: {msg}")]
    At {
        /// Where.
        loc: Loc,
        /// What was expected or is unsupported.
        msg: String,
    },
    /// A problem without a location.
    #[error("{0}")]
    Other(String),
    /// A parameter access failed (wrong type, missing file, …).
    #[error(transparent)]
    Scene(#[from] SceneError),
}

impl BuildError {
    /// Error at a location.
    pub fn at(loc: &Loc, msg: impl Into<String>) -> Self {
        BuildError::At {
            loc: loc.clone(),
            msg: msg.into(),
        }
    }
}

/// A directive the scene did not give, with pbrt-v4's defaults.
fn default_entity(name: &str) -> Entity {
    Entity {
        name: name.to_string(),
        params: ParamSet::default(),
        color_space: "srgb".to_string(),
        loc: Loc::file_only(std::path::Path::new("(pbrt-v4 default)")),
    }
}

/// Command-line values that override the scene file, like pbrt-v4's flags.
#[derive(Clone, Debug, Default)]
pub struct Overrides {
    /// `--spp`.
    pub spp: Option<u32>,
    /// `--integrator`.
    pub integrator: Option<String>,
    /// `--outfile`.
    pub outfile: Option<PathBuf>,
    /// `--seed`.
    pub seed: Option<u64>,
    /// `--cropwindow x0,x1,y0,y1` (pbrt-v4's; replaces the film's
    /// `cropwindow` and `pixelbounds`).
    pub cropwindow: Option<[f32; 4]>,
    /// `--aov`: extra film layers.
    pub aovs: Vec<crate::film::Aov>,
    /// `--units photometric`: luminance [cd/m²] and first-hit illuminance
    /// \[lx\] layers with their standard errors instead of sensor RGB.
    pub photometric: bool,
    /// `--memory-limit` in bytes (default: [`budget::DEFAULT_SHARE`] of
    /// physical memory). Not part of a render's identity: it only decides
    /// whether the render may start.
    pub memory_limit: Option<u64>,
}

/// Everything needed to render.
pub struct RenderSetup {
    /// The traceable scene.
    pub scene: Scene,
    /// The camera.
    pub camera: Camera,
    /// The film.
    pub film: Film,
    /// The prototype sampler.
    pub sampler: Sampler,
    /// The light transport algorithm.
    pub integrator: Box<dyn Integrator>,
    /// Output image path.
    pub outfile: PathBuf,
    /// Non-fatal problems (unused parameters, substitutions).
    pub warnings: Vec<String>,
    /// The estimated memory of the render's large structures.
    pub budget: budget::Budget,
}

/// Builds the render setup.
pub fn build(desc: &SceneDescription, ov: &Overrides) -> Result<RenderSetup, BuildError> {
    check::finite_scene(desc)?;
    let mut budget = budget::Budget::new(ov.memory_limit);
    let mut warnings: Vec<String> = desc
        .warnings
        .iter()
        .map(|w| format!("{}: {}", w.loc, w.message))
        .collect();
    let (film, outfile) = entities::film(desc, ov, &mut budget)?;
    let camera = entities::camera(desc, &film)?;
    let sampler = entities::sampler(desc, ov, film.resolution(), &mut warnings)?;
    let default_integrator = default_entity("volpath");
    let plan = integrators::integrator(desc, ov, &default_integrator, &mut warnings)?;
    // The first-hit illuminance sees one scattering event fewer than the
    // camera ray's path, whose first is at that hit (module doc of
    // `render::surface`).
    let film = with_strategy_layers(film, plan.strategy_layers)
        .with_illuminance_depth(plan.max_depth.saturating_sub(1));
    claim_film(desc, &film, &mut budget)?;
    let kind = plan.kind();
    check_combination(&plan, &film, &camera)?;
    let materials::BuiltMaterials {
        materials,
        names,
        textures_used,
        reads_textures,
    } = materials::materials(desc, &mut warnings)?;
    let geometry::Built {
        prims,
        movers,
        mut lights,
        textures_used: alpha_used,
    } = geometry::primitives(desc, &names, &mut budget, &mut warnings)?;
    let textures_used: Vec<bool> = textures_used
        .iter()
        .zip(&alpha_used)
        .map(|(a, b)| *a || *b)
        .collect();
    lights.extend(lights::lights(desc, &mut warnings)?);
    let shutter = entities::shutter(desc)?;
    let selection = plan.light_selection;
    let mut scene = Scene::with_motion(prims, movers, shutter, materials, lights, selection);
    // Only textures read the differentials (filter widths, bump steps), and
    // every non-constant texture is a `Texture` directive: a hit on a
    // material that reads none needs no footprint, which costs time (several
    // per cent on the Cornell box; 8 % of a VCM render of the pool, whose
    // water and walls read none).
    if reads_textures.iter().any(|&r| r) {
        let footprint =
            PixelFootprint::new(&camera, film.resolution(), sampler.samples_per_pixel());
        scene.set_footprint(Some(footprint), reads_textures);
    }
    // 256 camera rays: the pixel footprint at the visible surfaces, for the
    // photon radii and the precision warning.
    let scale = photon_scale::SceneScale::measure(&scene, &camera, &film);
    warnings.extend(photon_scale::precision_warning(&scale));
    let integrator = match kind {
        k if integrators::needs_scale(k) => {
            integrators::finish(plan, &scale, &mut budget, &mut warnings)?
        }
        _ => integrators::finish(
            plan,
            &photon_scale::SceneScale::none(),
            &mut budget,
            &mut warnings,
        )?,
    };
    collect_unused(desc, &textures_used, &mut warnings);
    Ok(RenderSetup {
        scene,
        camera,
        film,
        sampler,
        integrator,
        outfile,
        warnings,
        budget,
    })
}

/// Refuses integrators that cannot render this film or camera.
fn check_combination(
    plan: &integrators::Planned<'_>,
    film: &Film,
    camera: &Camera,
) -> Result<(), BuildError> {
    if plan.kind() == IntegratorKind::Sppm && film.layout().photometric {
        return Err(BuildError::Other(
            "--units photometric needs independent passes for its standard errors; SPPM's iterations depend on each other (use ppm)".into(),
        ));
    }
    // Light tracing alone would render black without saying why.
    if plan.light_tracing_only() && !camera.is_connectable() {
        return Err(BuildError::Other(format!(
            "{}: the light tracer needs a camera that light paths can reach (perspective, or orthographic with a lens); this scene's camera has no importance function",
            plan.what()
        )));
    }
    Ok(())
}

/// The film with `n` strategy layers added (BDPT's visualisation).
fn with_strategy_layers(film: Film, n: usize) -> Film {
    if n == 0 {
        return film;
    }
    let layout = FilmLayout {
        strategies: n,
        ..film.layout().clone()
    };
    let (kind, space) = (film.kind(), film.surface_space());
    film.with_layers(layout, kind, space)
}

/// Claims the film's memory; past the limit, the error is at the Film
/// directive and names its resolution.
fn claim_film(
    desc: &SceneDescription,
    film: &Film,
    budget: &mut budget::Budget,
) -> Result<(), BuildError> {
    let (lo, hi) = film.pixel_bounds();
    let what = format!(
        "the film ({}×{} pixels of {}×{}, {} channels a pixel)",
        hi.x - lo.x,
        hi.y - lo.y,
        film.resolution().x,
        film.resolution().y,
        film.layout().state_stride()
    );
    let fix = "lower \"xresolution\"/\"yresolution\" of the Film or crop it";
    budget
        .claim(photon_scale::film_bytes(film), &what, fix)
        .map_err(|m| match &desc.film {
            Some(e) => BuildError::at(&e.loc, format!("Film \"{}\" {m}", e.name)),
            None => BuildError::Other(m),
        })
}

fn unused_of(params: &ParamSet, what: &str, warnings: &mut Vec<String>) {
    for (name, loc) in params.unused() {
        warnings.push(format!("{loc}: unused parameter \"{name}\" of {what}"));
    }
}

/// Reports every parameter that no builder looked at, and directives that
/// are read but have no effect (`Option`, `Accelerator`, textures no material uses).
fn collect_unused(desc: &SceneDescription, textures_used: &[bool], warnings: &mut Vec<String>) {
    for (name, p) in &desc.options {
        warnings.push(format!(
            "{}: Option \"{name}\" is not supported yet and is ignored",
            p.loc
        ));
    }
    if let Some(a) = &desc.accelerator {
        warnings.push(format!(
            "{}: Accelerator \"{}\" ignored: candela always builds its SAH BVH",
            a.loc, a.name
        ));
    }
    for (t, &used) in desc.textures.iter().zip(textures_used) {
        if used {
            unused_of(&t.params, &format!("Texture \"{}\"", t.name), warnings);
        } else {
            warnings.push(format!(
                "{}: texture \"{}\" is not used by any material; ignored",
                t.loc, t.name
            ));
        }
    }
    for (e, what) in [
        (&desc.film, "Film"),
        (&desc.sampler, "Sampler"),
        (&desc.integrator, "Integrator"),
        (&desc.filter, "PixelFilter"),
    ] {
        if let Some(e) = e {
            unused_of(&e.params, &format!("{what} \"{}\"", e.name), warnings);
        }
    }
    if let Some(c) = &desc.camera {
        unused_of(&c.params, &format!("Camera \"{}\"", c.name), warnings);
    }
    for m in desc
        .materials
        .iter()
        .chain(desc.named_materials.iter().map(|(_, m)| m))
    {
        unused_of(&m.params, &format!("Material \"{}\"", m.ty), warnings);
    }
    for s in desc.shapes.iter().chain(
        desc.instance_definitions
            .iter()
            .flat_map(|d| d.shapes.iter()),
    ) {
        unused_of(&s.params, &format!("Shape \"{}\"", s.name), warnings);
        if let Some(a) = &s.area_light {
            unused_of(
                &a.params,
                &format!("AreaLightSource \"{}\"", a.name),
                warnings,
            );
        }
    }
    for l in &desc.lights {
        unused_of(&l.params, &format!("LightSource \"{}\"", l.name), warnings);
    }
}
