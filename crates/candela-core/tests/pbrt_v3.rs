//! pbrt-v3 materials and lights build to exactly what their pbrt-v4
//! `--upgrade` rewrite builds to, with one warning per converted directive
//! (naming `file:line:col`) and no unused-parameter warnings.

use candela_core::build::{build, Overrides, RenderSetup};
use std::path::{Path, PathBuf};

const HEADER: &str = "Film \"rgb\" \"integer xresolution\" [4] \"integer yresolution\" [4]
Sampler \"independent\" Integrator \"path\"
WorldBegin
";

fn setup_at(world: &str, path: &Path) -> Result<RenderSetup, String> {
    let text = format!("{HEADER}{world}");
    let desc = candela_scene::parse_str(&text, path).map_err(|e| e.to_string())?;
    build(&desc, &Overrides::default()).map_err(|e| e.to_string())
}

/// The built materials and lights, printed.
fn built(s: &RenderSetup) -> String {
    format!("{:?}\n{:?}", s.scene.materials(), s.scene.lights())
}

/// Builds `v3` and `v4` (both at `path`), checks they build identically,
/// that `v4` gives no warning and that `v3` gives exactly one, at line 4
/// (the first directive after the header), containing each of `notes`.
fn check_at(v3: &str, v4: &str, notes: &[&str], path: &Path) {
    let a = setup_at(v3, path).unwrap_or_else(|e| panic!("{v3}: {e}"));
    let b = setup_at(v4, path).unwrap_or_else(|e| panic!("{v4}: {e}"));
    assert!(b.warnings.is_empty(), "{v4}: {:?}", b.warnings);
    assert_eq!(built(&a), built(&b), "{v3}\nvs\n{v4}");
    assert_eq!(a.warnings.len(), 1, "{v3}: {:#?}", a.warnings);
    let w = &a.warnings[0];
    assert!(w.starts_with(&format!("{}:4:", path.display())), "{w}");
    for n in notes {
        assert!(w.contains(n), "{v3}: {w:?} lacks {n:?}");
    }
}

fn check(v3: &str, v4: &str, notes: &[&str]) {
    check_at(v3, v4, notes, Path::new("v3.pbrt"));
}

#[test]
fn matte_is_diffuse() {
    check(
        "Material \"matte\" \"rgb Kd\" [0.2 0.4 0.6] \"float sigma\" [0]\nShape \"sphere\"",
        "Material \"diffuse\" \"rgb reflectance\" [0.2 0.4 0.6]\nShape \"sphere\"",
        &[
            "Material \"matte\" upgraded to \"diffuse\"",
            "\"Kd\" → \"reflectance\"",
        ],
    );
    check(
        "Material \"matte\" \"float sigma\" [20]\nShape \"sphere\"",
        "Material \"diffuse\"\nShape \"sphere\"",
        &["dropped \"float sigma\" [20.0]"],
    );
}

#[test]
fn spectrum_kd_from_an_spd_file_beside_the_scene() {
    let d: PathBuf = std::env::temp_dir().join(format!("candela-v3-spd-{}", std::process::id()));
    std::fs::create_dir_all(d.join("spectra")).unwrap();
    std::fs::write(
        d.join("spectra/red.spd"),
        "# nm value\n400 0.1\n500 0.2\n600 0.8\n700 0.9\n",
    )
    .unwrap();
    check_at(
        "Material \"matte\" \"spectrum Kd\" \"spectra/red.spd\"\nShape \"sphere\"",
        "Material \"diffuse\" \"spectrum reflectance\" [400 0.1 500 0.2 600 0.8 700 0.9]\nShape \"sphere\"",
        &["\"Kd\" → \"reflectance\""],
        &d.join("scene.pbrt"),
    );
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn plastic_is_coateddiffuse_or_diffuse_without_specular() {
    check(
        "Material \"plastic\" \"rgb Kd\" [0.5 0.1 0.1] \"rgb Ks\" [0.25 0.25 0.25] \"float roughness\" [0.05]\nShape \"sphere\"",
        "Material \"coateddiffuse\" \"rgb reflectance\" [0.5 0.1 0.1] \"float roughness\" [0.05]\nShape \"sphere\"",
        &["upgraded to \"coateddiffuse\"", "dropped \"rgb Ks\" [0.25, 0.25, 0.25]"],
    );
    check(
        "Material \"plastic\" \"rgb Kd\" [0.5 0.1 0.1] \"rgb Ks\" [0 0 0] \"float roughness\" [0.05]\nShape \"sphere\"",
        "Material \"diffuse\" \"rgb reflectance\" [0.5 0.1 0.1]\nShape \"sphere\"",
        &["upgraded to \"diffuse\"", "dropped \"float roughness\" [0.05]"],
    );
}

#[test]
fn substrate_is_coateddiffuse() {
    check(
        "Material \"substrate\" \"rgb Kd\" [0.3 0.3 0.1] \"rgb Ks\" [1 1 1] \"float uroughness\" [0.2] \"float vroughness\" [0.1]\nShape \"sphere\"",
        "Material \"coateddiffuse\" \"rgb reflectance\" [0.3 0.3 0.1] \"float uroughness\" [0.2] \"float vroughness\" [0.1]\nShape \"sphere\"",
        &["upgraded to \"coateddiffuse\""],
    );
}

#[test]
fn metal_and_mirror_are_conductors() {
    check(
        "Material \"metal\" \"spectrum eta\" \"metal-Au-eta\" \"spectrum k\" \"metal-Au-k\" \"float roughness\" [0.1] \"rgb Kr\" [1 1 1]\nShape \"sphere\"",
        "Material \"conductor\" \"spectrum eta\" \"metal-Au-eta\" \"spectrum k\" \"metal-Au-k\" \"float roughness\" [0.1]\nShape \"sphere\"",
        &["upgraded to \"conductor\""],
    );
    check(
        "Material \"mirror\" \"rgb Kr\" [0.9 0.9 0.9]\nShape \"sphere\"",
        "Material \"conductor\" \"spectrum eta\" \"metal-Ag-eta\" \"spectrum k\" \"metal-Ag-k\" \"float roughness\" [0]\nShape \"sphere\"",
        &["upgraded to \"conductor\"", "dropped \"rgb Kr\"", "metal-Ag-eta"],
    );
}

#[test]
fn glass_is_dielectric_with_index_as_eta() {
    check(
        "Material \"glass\" \"float index\" [1.33] \"rgb Kr\" [1 1 1] \"rgb Kt\" [1 1 1]\nShape \"sphere\"",
        "Material \"dielectric\" \"float eta\" [1.33]\nShape \"sphere\"",
        &["upgraded to \"dielectric\"", "\"index\" → \"eta\""],
    );
    let e = setup_at(
        "Material \"glass\" \"float index\" [1.33] \"float eta\" [1.5]\nShape \"sphere\"",
        Path::new("v3.pbrt"),
    )
    .err()
    .expect("index and eta");
    assert!(
        e.starts_with("v3.pbrt:4:39: material \"glass\" has both"),
        "{e}"
    );
}

#[test]
fn uber_is_coateddiffuse_and_only_opaque() {
    check(
        "Material \"uber\" \"rgb Kd\" [0.4 0.4 0.2] \"rgb Ks\" [0.1 0.1 0.1] \"float index\" [1.4] \"rgb opacity\" [1 1 1]\nShape \"sphere\"",
        "Material \"coateddiffuse\" \"rgb reflectance\" [0.4 0.4 0.2] \"float eta\" [1.4]\nShape \"sphere\"",
        &["upgraded to \"coateddiffuse\"", "dropped \"rgb Ks\""],
    );
    check(
        "Material \"uber\" \"rgb Kd\" [0.4 0.4 0.2] \"rgb Ks\" [0 0 0] \"float index\" [1.4]\nShape \"sphere\"",
        "Material \"diffuse\" \"rgb reflectance\" [0.4 0.4 0.2]\nShape \"sphere\"",
        &["upgraded to \"diffuse\"", "dropped \"float eta\" [1.4]"],
    );
    let e = setup_at(
        "Material \"uber\" \"rgb opacity\" [0.5 0.5 0.5]\nShape \"sphere\"",
        Path::new("v3.pbrt"),
    )
    .err()
    .expect("translucent uber");
    assert!(
        e.starts_with("v3.pbrt:4:17: a non-opaque \"opacity\""),
        "{e}"
    );
}

#[test]
fn mix_reverses_its_named_materials_and_bumpmap_is_displacement() {
    let defs = "Texture \"bumps\" \"float\" \"wrinkled\"\n";
    let v3 = format!(
        "{defs}MakeNamedMaterial \"a\" \"string type\" \"matte\" \"texture bumpmap\" \"bumps\"\n\
         MakeNamedMaterial \"b\" \"string type\" \"diffuse\"\n\
         MakeNamedMaterial \"m\" \"string type\" \"mix\" \"string namedmaterial1\" \"a\" \"string namedmaterial2\" \"b\" \"rgb amount\" [0.25 0.25 0.25]\n\
         NamedMaterial \"m\"\nShape \"sphere\""
    );
    let v4 = format!(
        "{defs}MakeNamedMaterial \"a\" \"string type\" \"diffuse\" \"texture displacement\" \"bumps\"\n\
         MakeNamedMaterial \"b\" \"string type\" \"diffuse\"\n\
         MakeNamedMaterial \"m\" \"string type\" \"mix\" \"string materials\" [\"b\" \"a\"] \"float amount\" [0.25]\n\
         NamedMaterial \"m\"\nShape \"sphere\""
    );
    let a = setup_at(&v3, Path::new("v3.pbrt")).expect("v3 builds");
    let b = setup_at(&v4, Path::new("v3.pbrt")).expect("v4 builds");
    assert_eq!(built(&a), built(&b));
    assert!(b.warnings.is_empty(), "{:?}", b.warnings);
    assert_eq!(a.warnings.len(), 2, "{:#?}", a.warnings);
    assert!(a.warnings[0].starts_with("v3.pbrt:5:1: Material \"matte\" upgraded to \"diffuse\""));
    assert!(a.warnings[0].contains("\"bumpmap\" → \"displacement\""));
    assert!(a.warnings[1].starts_with("v3.pbrt:7:1: Material \"mix\" upgraded"));
    assert!(
        a.warnings[1].contains("→ \"materials\" [\"b\" \"a\"]"),
        "{}",
        a.warnings[1]
    );
}

#[test]
fn v3_area_lights_and_blackbody_scale_fold_into_scale() {
    check(
        "AreaLightSource \"area\" \"blackbody L\" [3000 2] \"integer nsamples\" [4] \"rgb scale\" [3 3 3]\nShape \"sphere\"",
        "AreaLightSource \"diffuse\" \"blackbody L\" [3000] \"float scale\" [6]\nShape \"sphere\"",
        &["AreaLightSource \"area\" upgraded to \"diffuse\"", "set \"float scale\" [6.0]"],
    );
    check(
        "LightSource \"point\" \"blackbody I\" [5000 0.5] \"float scale\" [4]",
        "LightSource \"point\" \"blackbody I\" [5000] \"float scale\" [2]",
        &["LightSource \"point\" upgraded"],
    );
}
