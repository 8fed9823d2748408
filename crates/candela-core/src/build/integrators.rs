//! `Integrator` directives → integrators: one settings reader per
//! integrator, with pbrt-v4's parameter names and defaults (candela's own
//! integrators document theirs in their modules).
//!
//! Building is in two steps: [`integrator`] reads and checks every parameter
//! before the scene is built; [`finish`] then gives the photon integrators
//! their default radius (which depends on the scene, see
//! [`super::photon_scale`]) and claims their memory.

use super::budget::Budget;
use super::check::{Check, Domain};
use super::photon_scale::{self, SceneScale};
use super::{BuildError, Overrides};
use crate::integrator::photonmap::Kernel;
use crate::integrator::wavelengths::{DEFAULT_GROUPS, MAX_GROUPS};
use crate::integrator::{
    BdptIntegrator, BdptSettings, Connections, DirectMerges, Integrator, IntegratorKind,
    LightTracer, LightTracerSettings, PathIntegrator, PathSettings, PhotonMapIntegrator,
    PhotonMapSettings, PpmIntegrator, PpmSettings, SppmIntegrator, SppmSettings, VcmIntegrator,
    VcmMode, VcmSettings, Visualize,
};
use crate::light::LightSelection;
use candela_scene::{Entity, Loc, ParamSet, SceneDescription};

/// The settings of each integrator, read and checked.
enum Settings {
    Path(PathSettings),
    LightPath(LightTracerSettings),
    Bdpt(BdptSettings),
    Sppm(SppmSettings),
    Ppm(PpmSettings),
    PhotonMap(PhotonMapSettings),
    Vcm(VcmSettings),
}

/// The integrator a scene asks for (or `--integrator`), read and checked
/// but not yet given its scene-dependent defaults.
pub struct Planned<'a> {
    kind: IntegratorKind,
    settings: Settings,
    /// The directive (or pbrt-v4's default).
    entity: &'a Entity,
    /// `Integrator "NAME"` for errors, with the `--integrator` override.
    what: String,
    /// `"float radius"` as written (SPPM and PPM).
    radius: Option<f32>,
    /// The light samplers (`"string lightsampler"`; the photon estimators'
    /// `"uniform"` becomes `"power"`).
    pub light_selection: LightSelection,
    /// BDPT strategy layers the film must record (0 without visualisation).
    pub strategy_layers: usize,
    /// `"integer maxdepth"` (every integrator reads it; pbrt-v4's default 5).
    pub max_depth: u32,
}

/// Maps an integrator name to the estimator candela runs for it; the flag is
/// true when the name is rendered by a substitute (pbrt-v4's `volpath`
/// without media is `path`).
pub fn kind_from_name(name: &str) -> Option<(IntegratorKind, bool)> {
    Some(match name {
        "path" => (IntegratorKind::Path, false),
        "volpath" => (IntegratorKind::Path, true),
        "lightpath" => (IntegratorKind::LightPath, false),
        "bdpt" => (IntegratorKind::Bdpt, false),
        "sppm" => (IntegratorKind::Sppm, false),
        "ppm" => (IntegratorKind::Ppm, false),
        "photonmap" => (IntegratorKind::PhotonMap, false),
        "vcm" => (IntegratorKind::Vcm, false),
        _ => return None,
    })
}

/// True for the integrators whose defaults depend on the scene's scale
/// (the photon integrators and VCM: their radius).
pub fn needs_scale(kind: IntegratorKind) -> bool {
    matches!(
        kind,
        IntegratorKind::Sppm
            | IntegratorKind::Ppm
            | IntegratorKind::PhotonMap
            | IntegratorKind::Vcm
    )
}

/// Names accepted by [`kind_from_name`].
pub const INTEGRATOR_NAMES: &str = "path, volpath, lightpath, bdpt, sppm, ppm, photonmap, vcm";

/// Reads and checks the integrator of `desc` (or of `--integrator`).
pub fn integrator<'a>(
    desc: &'a SceneDescription,
    ov: &Overrides,
    default: &'a Entity,
    warnings: &mut Vec<String>,
) -> Result<Planned<'a>, BuildError> {
    let e = desc.integrator.as_ref().unwrap_or(default);
    let (name, from_flag) = match &ov.integrator {
        Some(n) => (n.as_str(), true),
        None => (e.name.as_str(), false),
    };
    let Some((kind, substitute)) = kind_from_name(name) else {
        let msg = format!("integrator \"{name}\" is not supported (supported: {INTEGRATOR_NAMES})");
        return Err(if from_flag {
            BuildError::Other(format!("--integrator: {msg}"))
        } else {
            BuildError::at(&e.loc, msg)
        });
    };
    if substitute {
        warnings.push(format!(
            "{}: integrator \"volpath\" rendered with \"path\" (participating media are not supported yet; identical without media)",
            e.loc
        ));
    }
    let p = &e.params;
    let what = if name == e.name {
        format!("Integrator \"{name}\"")
    } else {
        format!(
            "Integrator \"{}\" (rendered as \"{name}\" by --integrator)",
            e.name
        )
    };
    let ck = Check::new(p, &e.loc, &what);
    let selection = light_sampler(p, &e.loc)?;
    let seed = render_seed(desc, ov)?;
    let common = Common {
        max_depth: ck.int("maxdepth", 5, 0)? as u32,
        regularize: p.get_bool("regularize", false)?,
        seed,
        flag_seed: ov.seed,
    };
    let (settings, strategy_layers) = construct(kind, &ck, &common, selection, warnings)?;
    let radius = match kind {
        IntegratorKind::Sppm | IntegratorKind::Ppm | IntegratorKind::Vcm => {
            ck.float_opt("radius", Domain::Positive)?
        }
        _ => None,
    };
    // Photons are shot by power, as pbrt-v4's SPPM does.
    let photons = matches!(
        kind,
        IntegratorKind::Sppm
            | IntegratorKind::Ppm
            | IntegratorKind::PhotonMap
            | IntegratorKind::Vcm
    );
    let light_selection = match selection {
        LightSelection::Uniform if photons => LightSelection::Power,
        s => s,
    };
    Ok(Planned {
        kind,
        settings,
        entity: e,
        what,
        radius,
        light_selection,
        strategy_layers,
        max_depth: common.max_depth,
    })
}

impl Planned<'_> {
    /// The estimator that will run.
    pub fn kind(&self) -> IntegratorKind {
        self.kind
    }

    /// `Integrator "NAME"` at its place in the file, for errors that
    /// refuse it (`--integrator` replaces the name).
    pub fn what(&self) -> String {
        format!("{}: {}", self.entity.loc, self.what)
    }

    /// Every path is light tracing's (`lightpath`, vcm's mode `lt`), so the
    /// camera must be one that light paths can reach.
    pub fn light_tracing_only(&self) -> bool {
        match &self.settings {
            Settings::LightPath(_) => true,
            Settings::Vcm(s) => s.mode == VcmMode::Lt,
            _ => false,
        }
    }
}

/// The integrator of `plan` in the built scene: SPPM and PPM get their
/// default radius when the file gives none, and the photon integrators'
/// structures are claimed against `budget`.
pub fn finish(
    plan: Planned<'_>,
    scale: &SceneScale,
    budget: &mut Budget,
    warnings: &mut Vec<String>,
) -> Result<Box<dyn Integrator>, BuildError> {
    let e = plan.entity;
    let ck = Check::new(&e.params, &e.loc, &plan.what);
    let footprints = match plan.kind {
        IntegratorKind::Vcm => photon_scale::VCM_FOOTPRINT_PIXELS,
        _ => photon_scale::FOOTPRINT_PIXELS,
    };
    let radius = |warnings: &mut Vec<String>| match plan.radius {
        Some(r) => {
            warnings.extend(photon_scale::radius_warning(
                ck.loc_of("radius"),
                &e.name,
                r,
                scale,
                &photon_scale::default_radius_text(plan.kind, scale),
            ));
            r
        }
        None => scale.default_radius_in(footprints),
    };
    Ok(match plan.settings {
        Settings::Path(settings) => Box::new(PathIntegrator { settings }),
        Settings::LightPath(settings) => Box::new(LightTracer { settings }),
        Settings::Bdpt(settings) => bdpt(&ck, settings, scale, budget)?,
        Settings::Sppm(mut settings) => {
            settings.radius = radius(warnings);
            let photons = photon_scale::photons(settings.photons_per_iteration, scale);
            photon_scale::claim_progressive(
                &ck,
                settings.radius,
                photons,
                settings.wavelength_groups,
                scale,
                budget,
                warnings,
            )?;
            Box::new(SppmIntegrator {
                settings,
                visits: Default::default(),
            })
        }
        Settings::Ppm(mut settings) => {
            settings.radius = radius(warnings);
            let photons = photon_scale::photons(settings.photons_per_pass, scale);
            photon_scale::claim_progressive(
                &ck,
                settings.radius,
                photons,
                settings.wavelength_groups,
                scale,
                budget,
                warnings,
            )?;
            Box::new(PpmIntegrator {
                settings,
                visits: Default::default(),
            })
        }
        Settings::Vcm(mut settings) => {
            settings.radius = radius(warnings);
            settings.radius_from_density = plan.radius.is_none();
            let light_paths = photon_scale::photons(settings.light_paths, scale);
            let pilot =
                settings.variance_lt && matches!(settings.mode, VcmMode::Vcm | VcmMode::Bpt);
            photon_scale::claim_vcm(&ck, light_paths, pilot, scale, budget)?;
            Box::new(VcmIntegrator::new(settings))
        }
        Settings::PhotonMap(settings) => {
            photon_scale::claim_photon_map(&ck, &settings, budget)?;
            Box::new(PhotonMapIntegrator { settings })
        }
    })
}

/// BDPT with its variance pilot's estimates claimed against `budget`.
fn bdpt(
    ck: &Check<'_>,
    settings: BdptSettings,
    scale: &SceneScale,
    budget: &mut Budget,
) -> Result<Box<dyn Integrator>, BuildError> {
    if settings.variance_lt && settings.visualize.is_none() {
        photon_scale::claim_pilot(ck, scale, budget)?;
    }
    Ok(Box::new(BdptIntegrator::new(settings)))
}

/// The settings of `kind` from the directive `ck`, and the BDPT strategy
/// layers it needs.
fn construct(
    kind: IntegratorKind,
    ck: &Check<'_>,
    common: &Common,
    selection: LightSelection,
    warnings: &mut Vec<String>,
) -> Result<(Settings, usize), BuildError> {
    Ok(match kind {
        IntegratorKind::Path => (Settings::Path(path_settings(ck, common)?), 0),
        IntegratorKind::LightPath => (
            Settings::LightPath(LightTracerSettings {
                max_depth: common.max_depth,
                seed: common.seed,
            }),
            0,
        ),
        IntegratorKind::Bdpt => {
            let settings = bdpt_settings(ck, common)?;
            let layers = match settings.visualize {
                Some(_) => Visualize::strategy_count(settings.max_depth),
                None => 0,
            };
            (Settings::Bdpt(settings), layers)
        }
        IntegratorKind::Sppm => (Settings::Sppm(sppm_settings(ck, common)?), 0),
        IntegratorKind::Ppm => (Settings::Ppm(ppm_settings(ck, common)?), 0),
        IntegratorKind::Vcm => (Settings::Vcm(vcm_settings(ck, common)?), 0),
        IntegratorKind::PhotonMap => {
            if selection == LightSelection::Uniform {
                warnings.push(format!(
                    "{}: \"photonmap\" always chooses lights by power; \"lightsampler\" is ignored",
                    ck.loc
                ));
            }
            (Settings::PhotonMap(photonmap_settings(ck, common)?), 0)
        }
    })
}

/// Parameters every integrator reads.
struct Common {
    max_depth: u32,
    regularize: bool,
    /// `--seed`, else the sampler's `seed`.
    seed: u64,
    /// `--seed` alone.
    flag_seed: Option<u64>,
}

/// `"string lightsampler"` (pbrt-v4's default `"bvh"`).
fn light_sampler(p: &ParamSet, loc: &Loc) -> Result<LightSelection, BuildError> {
    match p.get_string("lightsampler", "bvh")?.as_str() {
        "uniform" => Ok(LightSelection::Uniform),
        "power" => Ok(LightSelection::Power),
        "bvh" => Ok(LightSelection::Bvh),
        other => Err(BuildError::at(
            p.param_loc("lightsampler").unwrap_or(loc),
            format!("unknown light sampler \"{other}\" (known: uniform, power, bvh)"),
        )),
    }
}

/// The seed of integrators that draw their own random numbers (`--seed`,
/// else the sampler's `seed`).
fn render_seed(desc: &SceneDescription, ov: &Overrides) -> Result<u64, BuildError> {
    Ok(match (ov.seed, &desc.sampler) {
        (Some(s), _) => s,
        (None, Some(e)) => e.params.get_int("seed", 0)? as u64,
        (None, None) => 0,
    })
}

fn path_settings(ck: &Check<'_>, c: &Common) -> Result<PathSettings, BuildError> {
    Ok(PathSettings {
        max_depth: c.max_depth,
        regularize: c.regularize,
        split_specular: split_specular(ck)?,
    })
}

/// Deepest `maxdepth` whose strategies BDPT can write as images.
const MAX_VISUALIZED_DEPTH: u32 = 63;

fn bdpt_settings(ck: &Check<'_>, c: &Common) -> Result<BdptSettings, BuildError> {
    let p = ck.params;
    let strategies = p.get_bool("visualizestrategies", false)?;
    let weights = p.get_bool("visualizeweights", false)?;
    if (strategies || weights) && c.max_depth > MAX_VISUALIZED_DEPTH {
        return Err(ck.error(
            "maxdepth",
            format!(
                "must be at most {MAX_VISUALIZED_DEPTH} to visualize strategies (one image per strategy), found {}",
                c.max_depth
            ),
        ));
    }
    Ok(BdptSettings {
        max_depth: c.max_depth,
        regularize: c.regularize,
        visualize: (strategies || weights).then_some(Visualize { weighted: weights }),
        variance_lt: lt_weights(ck)?,
        ..BdptSettings::default()
    })
}

/// `"integer seed"` of SPPM/PPM (pbrt-v4's): `--seed`, else the integrator's own.
fn photon_seed(ck: &Check<'_>, c: &Common) -> Result<u64, BuildError> {
    Ok(match c.flag_seed {
        Some(s) => s,
        None => ck.params.get_int("seed", 0)? as u64,
    })
}

/// `"integer photonsperiteration"`: positive, or −1 (pbrt-v4's default: one
/// photon per pixel; any value ≤ 0 means that, as in pbrt-v4).
fn photons_per_iteration(ck: &Check<'_>) -> Result<i64, BuildError> {
    Ok(ck.params.get_int("photonsperiteration", -1)? as i64)
}

/// `"integer wavelengthgroups"`: wavelength groups per photon pass, 1 to
/// [`MAX_GROUPS`] (see `integrator::wavelengths`).
fn wavelength_groups(ck: &Check<'_>) -> Result<u32, BuildError> {
    Ok(ck.int_in(
        "wavelengthgroups",
        DEFAULT_GROUPS as i32,
        1,
        MAX_GROUPS as i32,
    )? as u32)
}

/// SPPM's settings; the radius is set by [`finish`].
fn sppm_settings(ck: &Check<'_>, c: &Common) -> Result<SppmSettings, BuildError> {
    Ok(SppmSettings {
        photons_per_iteration: photons_per_iteration(ck)?,
        radius: 1.0,
        max_depth: c.max_depth,
        seed: photon_seed(ck, c)?,
        wavelength_groups: wavelength_groups(ck)?,
        split_specular: split_specular(ck)?,
    })
}

/// `"bool splitspecular"` of the integrators whose camera walks fork at a
/// first smooth dielectric (`integrator::subpath`, "Splitting"; default on).
fn split_specular(ck: &Check<'_>) -> Result<bool, BuildError> {
    Ok(ck.params.get_bool("splitspecular", true)?)
}

/// PPM's settings; the radius is set by [`finish`].
fn ppm_settings(ck: &Check<'_>, c: &Common) -> Result<PpmSettings, BuildError> {
    Ok(PpmSettings {
        photons_per_pass: photons_per_iteration(ck)?,
        radius: 1.0,
        max_depth: c.max_depth,
        seed: photon_seed(ck, c)?,
        wavelength_groups: wavelength_groups(ck)?,
        split_specular: split_specular(ck)?,
    })
}

/// `Integrator "photonmap"` parameters (table in `integrator::photonmap`).
fn photonmap_settings(ck: &Check<'_>, c: &Common) -> Result<PhotonMapSettings, BuildError> {
    let p = ck.params;
    let d = PhotonMapSettings::default();
    let count = |name: &str, def: u64, min: i32| -> Result<u64, BuildError> {
        Ok(ck.int(name, def as i32, min)? as u64)
    };
    let kernel = match p.get_string("kernel", "cone")?.as_str() {
        "cone" => Kernel::Cone(ck.float("conek", 1.1, Domain::AtLeast(1.0))?),
        "epanechnikov" => Kernel::Epanechnikov,
        "disk" => Kernel::Disk,
        other => {
            return Err(ck.error(
                "kernel",
                format!("\"{other}\" is unknown (known: cone, epanechnikov, disk)"),
            ))
        }
    };
    Ok(PhotonMapSettings {
        max_depth: c.max_depth,
        photons: count("photons", d.photons, 0)?,
        caustic_photons: count("causticphotons", d.caustic_photons, 0)?,
        lookup: count("lookup", d.lookup as u64, 2)? as usize,
        max_radius: ck.float_opt("maxradius", Domain::Positive)?,
        caustic_max_radius: ck.float_opt("causticmaxradius", Domain::Positive)?,
        kernel,
        final_gather: p.get_bool("finalgather", d.final_gather)?,
        gather_rays: count("gatherrays", d.gather_rays as u64, 1)? as u32,
        seed: c.seed,
        wavelength_groups: wavelength_groups(ck)?,
        split_specular: split_specular(ck)?,
    })
}

/// `Integrator "vcm"` parameters (table in `integrator::vcm`); the radius
/// is set by [`finish`].
fn vcm_settings(ck: &Check<'_>, c: &Common) -> Result<VcmSettings, BuildError> {
    let name = ck.params.get_string("mode", "vcm")?;
    let Some(mode) = VcmMode::from_name(&name) else {
        return Err(ck.error(
            "mode",
            format!("\"{name}\" is unknown (known: {})", VcmMode::NAMES),
        ));
    };
    let name = ck
        .params
        .get_string("connections", VcmSettings::default().connections.name())?;
    let Some(connections) = Connections::from_name(&name) else {
        return Err(ck.error(
            "connections",
            format!("\"{name}\" is unknown (known: {})", Connections::NAMES),
        ));
    };
    Ok(VcmSettings {
        max_depth: c.max_depth,
        radius: 1.0,
        radius_from_density: false,
        alpha: ck.float(
            "alpha",
            VcmSettings::default().alpha,
            Domain::LeftOpen(0.0, 1.0),
        )?,
        light_paths: photons_per_iteration(ck)?,
        seed: photon_seed(ck, c)?,
        regularize: c.regularize,
        mode,
        connections,
        direct_merges: vcm_direct_merges(ck, mode)?,
        variance_lt: lt_weights(ck)?,
        join_roulette: ck.float(
            "joinroulette",
            VcmSettings::default().join_roulette,
            Domain::Closed(0.0, 1.0),
        )?,
        split_specular: split_specular(ck)?,
        local_radius: ck
            .params
            .get_bool("localradius", VcmSettings::default().local_radius)?,
    })
}

/// `"string ltweights"` of `vcm` and `bdpt`: light tracing weighed by the
/// camera side's variance (`variance`, the default) or by density alone
/// (`density`) (`integrator::lt_weights`).
fn lt_weights(ck: &Check<'_>) -> Result<bool, BuildError> {
    match ck.params.get_string("ltweights", "variance")?.as_str() {
        "variance" => Ok(true),
        "density" => Ok(false),
        other => Err(ck.error(
            "ltweights",
            format!("\"{other}\" is unknown (known: variance, density)"),
        )),
    }
}

/// `"string directmerges"`: which merges next to the light exist
/// (`integrator::vcm::mis`); all of them in the modes whose only technique
/// for direct light they are.
fn vcm_direct_merges(ck: &Check<'_>, mode: VcmMode) -> Result<DirectMerges, BuildError> {
    let default = if mode.merges_only() {
        "always"
    } else {
        "afterspecular"
    };
    let name = ck.params.get_string("directmerges", default)?;
    let Some(d) = DirectMerges::from_name(&name) else {
        return Err(ck.error(
            "directmerges",
            format!("\"{name}\" is unknown (known: {})", DirectMerges::NAMES),
        ));
    };
    if d != DirectMerges::Always && mode.merges_only() {
        return Err(ck.error(
            "directmerges",
            format!("\"{name}\" needs connections (mode \"vcm\"): this mode has no other technique for direct light"),
        ));
    }
    Ok(d)
}
