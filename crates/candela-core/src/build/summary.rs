//! What a built scene contains, for `candela info`: the directives as the
//! file wrote them (shapes, materials, textures by type) next to what the
//! builder made of them (primitives, triangles, lights), the camera, film,
//! sampler and integrator actually used, and every warning.
//!
//! Counts by directive come from the description; counts of primitives and
//! lights come from the traceable scene, so a `plymesh` shows up as one
//! shape and as its triangles, and an emitting mesh as one light per face.

use super::RenderSetup;
use crate::light::{Flux, Light};
use crate::shape::Shape;
use candela_scene::{ParamSet, SceneDescription};
use std::collections::BTreeMap;

/// Occurrences per name, in name order.
pub type Counts = BTreeMap<String, usize>;

/// A scene's contents as `candela info` prints them.
#[derive(Clone, Debug, Default)]
pub struct SceneSummary {
    /// Camera type and its main parameter.
    pub camera: String,
    /// Film type, resolution and output file.
    pub film: String,
    /// Sampler as written, what renders it, and the sample count.
    pub sampler: String,
    /// Integrator used and its maximum depth.
    pub integrator: String,
    /// `Shape` directives by type (inside object definitions too).
    pub shapes: Counts,
    /// `ObjectInstance` uses.
    pub instances: usize,
    /// Built primitives by kind (instances flattened).
    pub primitives: Counts,
    /// Built triangles (meshes, PLY files and refined subdivision surfaces).
    pub triangles: usize,
    /// Built lights by type (one area light per emitting primitive).
    pub lights: Counts,
    /// Total flux of the lights of each type, in type order.
    pub light_flux: BTreeMap<String, Flux>,
    /// `Material` and `MakeNamedMaterial` directives by (pbrt-v4) type.
    pub materials: Counts,
    /// `Texture` directives by kind and class.
    pub textures: Counts,
    /// World-space bounds of all geometry, if there is any.
    pub bounds: Option<([f32; 3], [f32; 3])>,
    /// Every warning, `file:line:col: message`.
    pub warnings: Vec<String>,
}

/// Counts `names`.
fn count<'a>(names: impl Iterator<Item = &'a str>) -> Counts {
    let mut c = Counts::new();
    for n in names {
        *c.entry(n.to_string()).or_default() += 1;
    }
    c
}

/// A float parameter's value without marking it used (`default` if absent or not one float).
fn peek_float(p: &ParamSet, name: &str, default: f32) -> f32 {
    match p.get(name).map(|p| &p.value) {
        Some(candela_scene::ParamValue::Floats(v)) if v.len() == 1 => v[0],
        _ => default,
    }
}

/// An integer parameter's value without marking it used.
fn peek_int(p: &ParamSet, name: &str, default: i32) -> i32 {
    match p.get(name).map(|p| &p.value) {
        Some(candela_scene::ParamValue::Ints(v)) if v.len() == 1 => v[0],
        _ => default,
    }
}

fn shape_kind(s: &Shape) -> &'static str {
    match s {
        Shape::Triangle(_) => "triangle",
        Shape::Sphere(_) => "sphere",
        Shape::Disk(_) => "disk",
        Shape::Cylinder(_) => "cylinder",
        Shape::BilinearPatch(_) => "bilinear patch",
    }
}

/// Total flux of the lights of each kind.
fn flux_by_kind(lights: &[Light]) -> BTreeMap<String, Flux> {
    let mut m = BTreeMap::<String, Flux>::new();
    for l in lights {
        *m.entry(light_kind(l).to_string()).or_default() += l.flux();
    }
    m
}

/// The name `candela info` gives a light's kind.
fn light_kind(l: &Light) -> &'static str {
    match l {
        Light::Point(_) => "point",
        Light::Spot(_) => "spot",
        Light::Goniometric(_) => "goniometric",
        Light::Projection(_) => "projection",
        Light::Distant(_) => "distant",
        Light::DiffuseArea(l) => match (l.has_image(), l.has_alpha()) {
            (false, false) => "diffuse area",
            (true, false) => "diffuse area (image)",
            (false, true) => "diffuse area (alpha)",
            (true, true) => "diffuse area (image, alpha)",
        },
        Light::UniformInfinite(_) => "infinite (uniform)",
        Light::ImageInfinite(_) => "infinite (image)",
    }
}

/// The camera line: type and field of view.
fn camera_line(desc: &SceneDescription) -> String {
    match &desc.camera {
        None => "perspective (pbrt-v4 default), fov 90°".to_string(),
        Some(c) if c.name == "perspective" => {
            format!("perspective, fov {}°", peek_float(&c.params, "fov", 90.0))
        }
        Some(c) => c.name.clone(),
    }
}

/// The sampler line: the name as written, the substitute if any, and spp.
fn sampler_line(written: &str, setup: &RenderSetup) -> String {
    let used = setup.sampler.kind().name();
    let spp = setup.sampler.samples_per_pixel();
    if written == used {
        format!("{written}, {spp} spp")
    } else {
        format!("{written} (rendered as {used}), {spp} spp")
    }
}

/// Summarizes the scene `desc` was built into.
pub fn summarize(desc: &SceneDescription, setup: &RenderSetup) -> SceneSummary {
    let defs = desc.instance_definitions.iter().flat_map(|d| &d.shapes);
    let scene = &setup.scene;
    let prims: Vec<_> = scene
        .primitives()
        .iter()
        .chain(scene.moving_groups().iter().flat_map(|m| m.primitives()))
        .collect();
    let triangles = prims
        .iter()
        .filter(|p| matches!(p.shape, Shape::Triangle(_)))
        .count();
    let res = setup.film.resolution();
    let sampler_name = desc.sampler.as_ref().map_or("zsobol", |s| s.name.as_str());
    let max_depth = desc
        .integrator
        .as_ref()
        .map_or(5, |e| peek_int(&e.params, "maxdepth", 5));
    let b = setup.scene.bounds();
    SceneSummary {
        camera: camera_line(desc),
        film: format!("rgb {}×{} → {}", res.x, res.y, setup.outfile.display()),
        sampler: sampler_line(sampler_name, setup),
        integrator: format!("{}, maxdepth {max_depth}", setup.integrator.kind()),
        shapes: count(desc.shapes.iter().chain(defs).map(|s| s.name.as_str())),
        instances: desc.instances.len(),
        primitives: count(prims.iter().map(|p| shape_kind(&p.shape))),
        triangles,
        lights: count(setup.scene.lights().iter().map(light_kind)),
        light_flux: flux_by_kind(setup.scene.lights()),
        materials: count(
            desc.materials
                .iter()
                .chain(desc.named_materials.iter().map(|(_, m)| m))
                .map(|m| m.ty.as_str()),
        ),
        textures: count(desc.textures.iter().map(|t| t.class.as_str())),
        bounds: (!prims.is_empty()).then(|| (b.min.to_array(), b.max.to_array())),
        warnings: setup.warnings.clone(),
    }
}
