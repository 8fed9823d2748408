//! `Integrator` directives → integrators: one settings reader per
//! integrator, with pbrt-v4's parameter names and defaults (candela's own
//! integrators document theirs in their modules).

use super::{BuildError, Overrides};
use crate::integrator::photonmap::Kernel;
use crate::integrator::{
    BdptIntegrator, BdptSettings, Integrator, IntegratorKind, LightTracer, LightTracerSettings,
    PathIntegrator, PathSettings, PhotonMapIntegrator, PhotonMapSettings, PpmIntegrator,
    PpmSettings, SppmIntegrator, SppmSettings, Visualize,
};
use candela_scene::{Entity, Loc, ParamSet, SceneDescription};

/// The integrator a scene asks for (or `--integrator`), built.
pub struct BuiltIntegrator {
    /// The integrator.
    pub integrator: Box<dyn Integrator>,
    /// Lights are chosen in proportion to power (else uniformly).
    pub power_sampling: bool,
    /// BDPT strategy layers the film must record (0 without visualisation).
    pub strategy_layers: usize,
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
        _ => return None,
    })
}

/// Names accepted by [`kind_from_name`].
pub const INTEGRATOR_NAMES: &str = "path, volpath, lightpath, bdpt, sppm, ppm, photonmap";

/// Builds the integrator of `desc` (or of `--integrator`).
pub fn integrator(
    desc: &SceneDescription,
    ov: &Overrides,
    warnings: &mut Vec<String>,
) -> Result<BuiltIntegrator, BuildError> {
    let empty = super::default_entity("volpath");
    let e = desc.integrator.as_ref().unwrap_or(&empty);
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
    let power_sampling = light_sampler(p, &e.loc)?;
    let seed = render_seed(desc, ov)?;
    let common = Common {
        max_depth: p.get_int("maxdepth", 5)?.max(0) as u32,
        regularize: p.get_bool("regularize", false)?,
        seed,
        flag_seed: ov.seed,
    };
    let (integrator, strategy_layers) = construct(kind, e, &common, power_sampling, warnings)?;
    // Photons are shot by power, as pbrt-v4's SPPM does.
    let power_sampling = power_sampling
        || matches!(
            kind,
            IntegratorKind::Sppm | IntegratorKind::Ppm | IntegratorKind::PhotonMap
        );
    Ok(BuiltIntegrator {
        integrator,
        power_sampling,
        strategy_layers,
    })
}

/// The integrator of `kind` from the directive `e`, and the BDPT strategy
/// layers it needs.
fn construct(
    kind: IntegratorKind,
    e: &Entity,
    common: &Common,
    power_sampling: bool,
    warnings: &mut Vec<String>,
) -> Result<(Box<dyn Integrator>, usize), BuildError> {
    let p = &e.params;
    Ok(match kind {
        IntegratorKind::Path => (
            Box::new(PathIntegrator {
                settings: path_settings(common),
            }),
            0,
        ),
        IntegratorKind::LightPath => (
            Box::new(LightTracer {
                settings: LightTracerSettings {
                    max_depth: common.max_depth,
                    seed: common.seed,
                },
            }),
            0,
        ),
        IntegratorKind::Bdpt => {
            let settings = bdpt_settings(p, common)?;
            let layers = match settings.visualize {
                Some(_) => Visualize::strategy_count(settings.max_depth),
                None => 0,
            };
            (Box::new(BdptIntegrator { settings }), layers)
        }
        IntegratorKind::Sppm => (
            Box::new(SppmIntegrator {
                settings: sppm_settings(e, common)?,
            }),
            0,
        ),
        IntegratorKind::Ppm => (
            Box::new(PpmIntegrator {
                settings: ppm_settings(e, common)?,
            }),
            0,
        ),
        IntegratorKind::PhotonMap => {
            if !power_sampling {
                warnings.push(format!(
                    "{}: \"photonmap\" always chooses lights by power; \"lightsampler\" is ignored",
                    e.loc
                ));
            }
            let settings = photonmap_settings(p, common, &e.loc)?;
            (Box::new(PhotonMapIntegrator { settings }), 0)
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

/// `"string lightsampler"`: true for power-proportional selection.
fn light_sampler(p: &ParamSet, loc: &Loc) -> Result<bool, BuildError> {
    match p.get_string("lightsampler", "bvh")?.as_str() {
        "uniform" => Ok(false),
        "power" | "bvh" => Ok(true),
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

fn path_settings(c: &Common) -> PathSettings {
    PathSettings {
        max_depth: c.max_depth,
        regularize: c.regularize,
    }
}

fn bdpt_settings(p: &ParamSet, c: &Common) -> Result<BdptSettings, BuildError> {
    let strategies = p.get_bool("visualizestrategies", false)?;
    let weights = p.get_bool("visualizeweights", false)?;
    Ok(BdptSettings {
        max_depth: c.max_depth,
        regularize: c.regularize,
        visualize: (strategies || weights).then_some(Visualize { weighted: weights }),
        ..BdptSettings::default()
    })
}

/// `"float radius"` of the photon integrators (pbrt-v4's default 1).
fn photon_radius(e: &Entity) -> Result<f32, BuildError> {
    let p = &e.params;
    let radius = p.get_float("radius", 1.0)?;
    if radius.is_nan() || radius <= 0.0 || radius.is_infinite() {
        return Err(BuildError::at(
            p.param_loc("radius").unwrap_or(&e.loc),
            format!("\"radius\" must be a positive finite number, found {radius}"),
        ));
    }
    Ok(radius)
}

/// `"integer seed"` of SPPM/PPM (pbrt-v4's): `--seed`, else the integrator's own.
fn photon_seed(e: &Entity, c: &Common) -> Result<u64, BuildError> {
    Ok(match c.flag_seed {
        Some(s) => s,
        None => e.params.get_int("seed", 0)? as u64,
    })
}

fn sppm_settings(e: &Entity, c: &Common) -> Result<SppmSettings, BuildError> {
    Ok(SppmSettings {
        photons_per_iteration: e.params.get_int("photonsperiteration", -1)? as i64,
        radius: photon_radius(e)?,
        max_depth: c.max_depth,
        seed: photon_seed(e, c)?,
    })
}

fn ppm_settings(e: &Entity, c: &Common) -> Result<PpmSettings, BuildError> {
    Ok(PpmSettings {
        photons_per_pass: e.params.get_int("photonsperiteration", -1)? as i64,
        radius: photon_radius(e)?,
        max_depth: c.max_depth,
        seed: photon_seed(e, c)?,
    })
}

/// `Integrator "photonmap"` parameters (table in `integrator::photonmap`).
fn photonmap_settings(
    p: &ParamSet,
    c: &Common,
    loc: &Loc,
) -> Result<PhotonMapSettings, BuildError> {
    let d = PhotonMapSettings::default();
    let count = |name: &str, def: u64| -> Result<u64, BuildError> {
        Ok(p.get_int(name, def as i32)?.max(0) as u64)
    };
    let kernel = match p.get_string("kernel", "cone")?.as_str() {
        "cone" => match p.get_float("conek", 1.1)? {
            k if k >= 1.0 => Kernel::Cone(k),
            _ => return Err(BuildError::at(loc, "\"conek\" must be at least 1")),
        },
        "epanechnikov" => Kernel::Epanechnikov,
        "disk" => Kernel::Disk,
        other => {
            return Err(BuildError::at(
                loc,
                format!("unknown kernel \"{other}\" (known: cone, epanechnikov, disk)"),
            ))
        }
    };
    let radius = |name: &str| match p.get_floats(name)? {
        None => Ok(None),
        Some(v) if v.len() == 1 && v[0] > 0.0 => Ok(Some(v[0])),
        Some(_) => Err(BuildError::at(
            loc,
            format!("\"{name}\" must be one positive float"),
        )),
    };
    Ok(PhotonMapSettings {
        max_depth: c.max_depth,
        photons: count("photons", d.photons)?,
        caustic_photons: count("causticphotons", d.caustic_photons)?,
        lookup: count("lookup", d.lookup as u64)?.max(2) as usize,
        max_radius: radius("maxradius")?,
        caustic_max_radius: radius("causticmaxradius")?,
        kernel,
        final_gather: p.get_bool("finalgather", d.final_gather)?,
        gather_rays: count("gatherrays", d.gather_rays as u64)? as u32,
        seed: c.seed,
    })
}
