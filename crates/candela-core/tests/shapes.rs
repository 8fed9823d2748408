//! `cylinder`, `bilinearmesh` and `loopsubdiv` end to end: scene text →
//! description → built scene → intersections, warnings and errors, and
//! closed-form renders (validation.md T4a's emitting, reflecting enclosure,
//! L = Le/(1 − ρ), and T7's emitter filling the view).

mod common;

use candela_core::build::{build, BuildError, Overrides, RenderSetup};
use candela_core::math::{Ray, Vec3};
use common::{assert_region, render_str};
use std::path::Path;

const HEADER: &str = r#"LookAt 0 0 0  1 0 0  0 0 1
Camera "perspective" "float fov" [60]
Film "rgb" "integer xresolution" [32] "integer yresolution" [32]
PixelFilter "box"
Sampler "independent"
"#;

fn setup(world: &str) -> Result<RenderSetup, BuildError> {
    let text = format!("{HEADER}WorldBegin\n{world}");
    let desc = candela_scene::parse_str(&text, Path::new("shapes.pbrt")).expect("parses");
    build(&desc, &Overrides::default())
}

fn ov(spp: u32) -> Overrides {
    Overrides {
        spp: Some(spp),
        seed: Some(1),
        ..Default::default()
    }
}

#[test]
fn cylinder_is_built_and_hit() {
    let s = setup(
        r#"Translate 0 0 5
Shape "cylinder" "float radius" [2] "float zmin" [-1] "float zmax" [3] "float phimax" [270]
    "float bogus" [1]
"#,
    )
    .expect("builds");
    // From x = −10 along +x at z = 6: the side at φ = 180° (inside φ_max), t = 8.
    let si = s
        .scene
        .intersect(
            &Ray::new(Vec3::new(-10.0, 0.0, 6.0), Vec3::X),
            f32::INFINITY,
        )
        .expect("hit");
    assert!(
        si.p().distance(Vec3::new(-2.0, 0.0, 6.0)) < 1e-5,
        "{}",
        si.p()
    );
    assert!(
        si.n().distance(-Vec3::X) < 1e-5,
        "outward normal {}",
        si.n()
    );
    assert!((si.it.uv.x - 180.0 / 270.0).abs() < 1e-5 && (si.it.uv.y - 0.5).abs() < 1e-5);
    // φ = 315° is clipped away: the ray passes through to the far side at φ = 135°.
    let d = Vec3::new(-1.0, 1.0, 0.0).normalize();
    let far = s
        .scene
        .intersect(&Ray::new(Vec3::new(5.0, -5.0, 6.0), d), f32::INFINITY)
        .expect("far side");
    assert!(far.p().distance(Vec3::new(-2f32.sqrt(), 2f32.sqrt(), 6.0)) < 1e-4);
    let unused = s.warnings.iter().filter(|w| w.contains("\"bogus\""));
    assert_eq!(unused.count(), 1, "{:?}", s.warnings);
    assert!(s.warnings.iter().all(|w| !w.contains("radius")));
}

#[test]
fn bilinearmesh_is_built_and_hit_and_emits() {
    let s = setup(
        r#"AreaLightSource "diffuse" "rgb L" [1 1 1]
Shape "bilinearmesh" "point3 P" [3 -1 -1  3 1 -1  4 -1 1  3 1 1] "point2 uv" [0 0 1 0 0 1 1 1]
"#,
    )
    .expect("builds");
    assert_eq!(s.scene.lights().len(), 1);
    let d = Vec3::new(3.2, 0.3, -0.1).normalize();
    let si = s
        .scene
        .intersect(&Ray::new(Vec3::ZERO, d), f32::INFINITY)
        .expect("hit");
    assert!(si.area_light.is_some());
    // The hit lies on the bilinear surface at its (u, v) (uv is the identity map here).
    let (u, v) = (si.it.uv.x, si.it.uv.y);
    let [p00, p10, p01, p11] = [
        Vec3::new(3.0, -1.0, -1.0),
        Vec3::new(3.0, 1.0, -1.0),
        Vec3::new(4.0, -1.0, 1.0),
        Vec3::new(3.0, 1.0, 1.0),
    ];
    let want = p00.lerp(p01, v).lerp(p10.lerp(p11, v), u);
    assert!(si.p().distance(want) < 1e-5, "{} vs {want}", si.p());
    assert!(si.p().normalize().dot(d) > 1.0 - 1e-6);
}

/// pbrt-v4 skips alpha-0 surfaces when tracing but keeps an emitter with
/// constant `"float alpha" 0` as an invisible light (kroken's lights.pbrt
/// does this): it is never hit, yet stays in the light list, not hittable.
#[test]
fn emitter_with_alpha_zero_is_an_invisible_light() {
    let s = setup(
        r#"AttributeBegin
Translate 5 0 0
AreaLightSource "diffuse" "rgb L" [50 50 50]
Shape "sphere" "float radius" 1 "float alpha" 0
AttributeEnd
LightSource "point" "rgb I" [1 1 1]
"#,
    )
    .expect("builds");
    assert_eq!(s.scene.lights().len(), 2, "the invisible light stays");
    assert_eq!(
        s.scene.lights().iter().filter(|l| l.is_hittable()).count(),
        0,
        "neither the point light nor the invisible one can be hit"
    );
    assert!(
        s.warnings.iter().all(|w| !w.contains("unused")),
        "{:?}",
        s.warnings
    );
    assert!(s
        .scene
        .intersect(
            &Ray::new(Vec3::ZERO, Vec3::new(1.0, 0.0, 0.0)),
            f32::INFINITY
        )
        .is_none());
    // A partial alpha masks the emission instead (area_light_image.rs).
    let s = setup(
        r#"AreaLightSource "diffuse" "rgb L" [1 1 1]
Shape "sphere" "float alpha" 0.5
"#,
    )
    .expect("partial alpha on an emitter builds");
    assert!(matches!(
        s.scene.lights(),
        [candela_core::light::Light::DiffuseArea(l)] if l.has_alpha()
    ));
}

/// A singular CTM is valid pbrt-v4 input (exporters write zero scales for
/// hidden objects, as transparent-machines does): the scene builds, the
/// flattened shape and instance are left out with a warning at their place,
/// and their parameters are not reported as unused.
#[test]
fn shapes_under_a_singular_transform_are_skipped_with_a_warning() {
    let s = setup(
        r#"ObjectBegin "bolt"
Shape "sphere" "float radius" 1
ObjectEnd
AttributeBegin
ConcatTransform [ 0 0 0 0  0 1 0 0  0 0 1 0  5 0 0 1 ]
Shape "sphere" "float radius" 2
ObjectInstance "bolt"
AttributeEnd
AttributeBegin
Translate 5 0 0
Shape "sphere" "float radius" 0.5
AttributeEnd
"#,
    )
    .expect("builds");
    assert_eq!(s.scene.primitives().len(), 1, "only the regular sphere");
    let singular: Vec<_> = s
        .warnings
        .iter()
        .filter(|w| w.contains("singular"))
        .collect();
    assert_eq!(singular.len(), 2, "{:?}", s.warnings);
    assert!(singular[0].contains("shapes.pbrt:12:1"), "{singular:?}");
    assert!(singular[1].contains("shapes.pbrt:13:1"), "{singular:?}");
    assert!(
        s.warnings.iter().all(|w| !w.contains("unused")),
        "{:?}",
        s.warnings
    );
}

#[test]
fn loopsubdiv_is_built_and_hit() {
    let s = setup(
        r#"Translate 5 0 0
Shape "loopsubdiv" "integer levels" [2] "point3 P" [1 0 0 -1 0 0 0 1 0 0 -1 0 0 0 1 0 0 -1]
    "integer indices" [0 2 4 2 1 4 1 3 4 3 0 4 2 0 5 1 2 5 3 1 5 0 3 5]
"#,
    )
    .expect("builds");
    assert_eq!(s.scene.primitive_count(), 8 * 16);
    let si = s
        .scene
        .intersect(&Ray::new(Vec3::ZERO, Vec3::X), f32::INFINITY)
        .expect("hit");
    // The ray meets the limit point of the control vertex (4, 0, 0): valence 4,
    // β = 3/32, γ = 1/8, so (1 − 4γ)·4 + γ·(4 · 5) = 4.5.
    assert!(
        si.p().distance(Vec3::new(4.5, 0.0, 0.0)) < 1e-4,
        "{}",
        si.p()
    );
    // pbrt-v4's limit normals point against the counter-clockwise winding.
    assert!(si.shading.n.distance(Vec3::X) < 1e-3, "{}", si.shading.n);
}

#[test]
fn bad_shape_parameters_are_errors_with_locations() {
    let cases = [
        (
            r#"Shape "loopsubdiv" "integer levels" [-1] "point3 P" [0 0 0 1 0 0 0 1 0] "integer indices" [0 1 2]"#,
            "\"levels\" must be at least 0, found -1",
        ),
        (
            r#"Shape "loopsubdiv" "point3 P" [0 0 0 1 0 0 0 1 0 0 0 1] "integer indices" [0 1 2 0 1 3 1 0 3]"#,
            "inconsistent winding",
        ),
        (
            r#"Shape "loopsubdiv" "point3 P" [0 0 0 1 0 0 0 1 0] "integer indices" [0 1 5]"#,
            "out of range",
        ),
        (
            r#"Shape "bilinearmesh" "point3 P" [0 0 0 1 0 0 0 1 0 1 1 0 2 2 2] "integer indices" [0 1 2 3 4]"#,
            "not a multiple of 4",
        ),
        (
            r#"Shape "bilinearmesh" "point3 P" [0 0 0 1 0 0 0 1 0 1 1 0] "string emissionfilename" "e.exr""#,
            "emissionfilename",
        ),
        (
            r#"Shape "bilinearmesh" "point3 P" [0 0 0 1 0 0 0 1 0]"#,
            "indices",
        ),
    ];
    for (world, want) in cases {
        let e = match setup(world) {
            Ok(_) => panic!("{world}: built"),
            Err(e) => e.to_string(),
        };
        assert!(
            e.contains(want) && e.contains("shapes.pbrt:"),
            "{world}: {e}"
        );
    }
}

#[test]
fn killeroo_geometry_builds_with_a_diffuse_material() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes/killeroo-simple/geometry/killeroo.pbrt");
    assert!(file.exists(), "bundled scene missing: {}", file.display());
    let world = format!("Material \"diffuse\"\nInclude \"{}\"\n", file.display());
    let s = setup(&world).expect("builds");
    let text = format!("{HEADER}WorldBegin\n{world}");
    let desc = candela_scene::parse_str(&text, Path::new("k.pbrt")).expect("parses");
    let faces = desc.shapes[0]
        .params
        .get_ints("indices")
        .unwrap()
        .unwrap()
        .len()
        / 3;
    let levels = desc.shapes[0].params.get_int("levels", 3).unwrap() as u32;
    assert_eq!(s.scene.primitive_count(), faces * 4usize.pow(levels));
    eprintln!(
        "killeroo: {faces} control faces, {} triangles",
        s.scene.primitive_count()
    );
    // A ray at the centre of its bounds hits it.
    let b = s.scene.bounds();
    let c = b.centroid();
    let o = c - Vec3::new(0.0, 3.0 * (b.max.y - b.min.y), 0.0);
    assert!(s
        .scene
        .intersect(&Ray::new(o, c - o), f32::INFINITY)
        .is_some());
    assert!(
        s.warnings.iter().all(|w| !w.contains("unused")),
        "{:?}",
        s.warnings
    );
}

/// A furnace: every surface emits Le = 1 and reflects ρ = 0.8, so L = 5 everywhere.
fn furnace(shapes: &str) -> String {
    format!(
        r#"{HEADER}Integrator "path" "integer maxdepth" [200]
WorldBegin
Material "diffuse" "rgb reflectance" [0.8 0.8 0.8]
AreaLightSource "diffuse" "rgb L" [1 1 1]
{shapes}"#
    )
}

#[test]
fn closed_anisotropic_cylinder_furnace_renders_le_over_one_minus_rho() {
    // An elliptic cylinder (non-uniform area sampling) closed by two disks,
    // all normals inward.
    let shapes = r#"Scale 1.5 1 2
AttributeBegin
    ReverseOrientation
    Shape "cylinder" "float radius" [1] "float zmin" [-1] "float zmax" [1]
    Shape "disk" "float height" [1]
AttributeEnd
Shape "disk" "float height" [-1]
"#;
    let img = render_str(&furnace(shapes), &ov(64));
    assert_region(&img, (0, 32, 0, 32), 5.0, 2e-3 * 5.0, "cylinder furnace");
}

#[test]
fn closed_bilinear_hexahedron_furnace_renders_le_over_one_minus_rho() {
    // Six patches on a perturbed cube (four of them curved), normals inward.
    let shapes = r#"Shape "bilinearmesh"
    "point3 P" [-1 -1 -1  1 -1 -1  -1 1 -1  1 1 -1  -1.2 -0.9 1.1  1 -1 1  -1 1 1  1.3 1.2 1.5]
    "integer indices" [0 1 2 3  4 6 5 7  0 4 1 5  2 3 6 7  0 2 4 6  1 5 3 7]
"#;
    let img = render_str(&furnace(shapes), &ov(64));
    assert_region(&img, (0, 32, 0, 32), 5.0, 2e-3 * 5.0, "bilinear furnace");
}

#[test]
fn loopsubdiv_emitter_around_the_camera_renders_its_radiance() {
    // A black, one-sided emitter of L = 2 enclosing the camera: counter-clockwise
    // faces seen from outside, so pbrt-v4's limit normals point inward.
    let scene = format!(
        r#"{HEADER}Integrator "path" "integer maxdepth" [5]
WorldBegin
Material "diffuse" "rgb reflectance" [0 0 0]
AreaLightSource "diffuse" "rgb L" [2 2 2]
Scale 3 3 3
Shape "loopsubdiv" "integer levels" [2] "point3 P" [1 0 0 -1 0 0 0 1 0 0 -1 0 0 0 1 0 0 -1]
    "integer indices" [0 2 4 2 1 4 1 3 4 3 0 4 2 0 5 1 2 5 3 1 5 0 3 5]
"#
    );
    let img = render_str(&scene, &ov(16));
    assert_region(&img, (0, 32, 0, 32), 2.0, 2e-3 * 2.0, "loopsubdiv emitter");
}

#[test]
fn plymesh_file_errors_name_the_parameter_or_the_place_in_the_file() {
    let d = std::env::temp_dir().join(format!("candela-shapes-ply-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let missing = d.join("missing.ply");
    let world = format!(
        "Material \"diffuse\"\nShape \"plymesh\"  \"string filename\" \"{}\"\n",
        missing.display()
    );
    let e = setup(&world).err().expect("missing file").to_string();
    // Line 8 (after the 5-line header, WorldBegin and Material), at the parameter.
    assert!(
        e.starts_with(&format!(
            "shapes.pbrt:8:18: cannot read '{}': ",
            missing.display()
        )),
        "{e}"
    );
    let bad = d.join("bad.ply");
    std::fs::write(&bad, "ply\nformat ascii 1.0\nelement vertex 3\nbogus\n").unwrap();
    let world = format!(
        "Shape \"plymesh\" \"string filename\" \"{}\"\n",
        bad.display()
    );
    let e = setup(&world).err().expect("malformed file").to_string();
    assert!(
        e.starts_with(&format!(
            "shapes.pbrt:7:1: bad PLY file: {}:4:1: ",
            bad.display()
        )),
        "{e}"
    );
    std::fs::remove_dir_all(&d).ok();
}

/// A floor triangle reaching `reach` from the origin under a 2-unit room
/// seen from inside: build warnings.
fn reach_warnings(reach: f32) -> Vec<String> {
    let text = format!(
        r#"LookAt 0 0 3  0 0 0  0 1 0
Camera "perspective" "float fov" [40]
Film "rgb" "integer xresolution" [64] "integer yresolution" [48]
WorldBegin
LightSource "point" "point3 from" [0 0.8 0] "rgb I" [1 1 1]
Material "diffuse"
Shape "trianglemesh" "point3 P" [-1 -1 -1  1 -1 -1  1 1 -1  -1 1 -1] "integer indices" [0 1 2 0 2 3]
Shape "trianglemesh" "point3 P" [-{reach} -0.9 -{reach}  {reach} -0.9 -{reach}  0 -0.9 {reach}] "integer indices" [0 1 2]
"#
    );
    let desc = candela_scene::parse_str(&text, Path::new("t.pbrt")).expect("parses");
    build(&desc, &Overrides::default())
        .unwrap_or_else(|e| panic!("{e}"))
        .warnings
}

/// Single precision spaces positions |x|·2⁻²³ apart: a triangle reaching
/// 10¹⁰ (spacing ≈ 1,200) under a room whose pixels are ≈ 0.05 wide is
/// rounded by far more than a pixel, and the scene says so (it rendered
/// silently wrong: invisible to camera rays, yet shadowing the room); at
/// 10⁴ (spacing ≈ 0.0012) it is fine and says nothing.
#[test]
fn geometry_too_far_for_single_precision_is_warned_about() {
    let far = reach_warnings(1e10);
    assert!(
        far.iter()
            .any(|w| w.contains("single-precision positions are")),
        "{far:?}"
    );
    let near = reach_warnings(1e4);
    assert!(
        !near.iter().any(|w| w.contains("single-precision")),
        "{near:?}"
    );
}
