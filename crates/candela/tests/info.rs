//! `candela info` and its alias `candela render --check-only`: the scene is
//! parsed and built, its contents and warnings printed, and nothing rendered.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn candela() -> Command {
    Command::new(env!("CARGO_BIN_EXE_candela"))
}

fn tmpdir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("candela-info-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Two triangles, a sphere, a disk emitter, a point light, three materials
/// (one named), a used and an unused texture, and an unused parameter.
const SCENE: &str = r#"LookAt 0 0 -3  0 0 0  0 1 0
Camera "perspective" "float fov" [45]
Film "rgb" "integer xresolution" [32] "integer yresolution" [24] "string filename" "never.exr"
Sampler "pmj02bn" "integer pixelsamples" [4]
Integrator "path" "integer maxdepth" [7]
WorldBegin
LightSource "point" "point3 from" [0 2 -2] "rgb I" [5 5 5]
Texture "checks" "spectrum" "checkerboard" "float uscale" [4]
Texture "lonely" "float" "fbm"
Material "diffuse" "texture reflectance" "checks"
Shape "trianglemesh" "point3 P" [-1 -1 0 1 -1 0 1 1 0 -1 1 0] "integer indices" [0 1 2 0 2 3]
MakeNamedMaterial "gold" "string type" "conductor" "float roughness" [0.1] "float sparkle" [2]
NamedMaterial "gold"
Shape "sphere" "float radius" [0.5]
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [1 1 1]
  Material "dielectric"
  Shape "disk" "float radius" [0.25]
AttributeEnd
"#;

fn run(args: &[&str], scene: &Path) -> Output {
    candela().args(args).arg(scene).output().unwrap()
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

#[test]
fn info_prints_counts_settings_and_warnings_and_renders_nothing() {
    let d = tmpdir("counts");
    let scene = d.join("s.pbrt");
    std::fs::write(&scene, SCENE).unwrap();
    let o = run(&["info"], &scene);
    let out = stdout(&o);
    assert!(
        o.status.success(),
        "{out}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    for want in [
        "camera      perspective, fov 45°",
        "film        rgb 32×24 → never.exr",
        "sampler     pmj02bn (rendered as paddedsobol), 4 spp",
        "integrator  path, maxdepth 7",
        "shapes      3 (disk 1, sphere 1, trianglemesh 1)",
        "primitives  4 (disk 1, sphere 1, triangle 2)",
        "triangles   2",
        "lights      2 (diffuse area 1, point 1)",
        "materials   3 (conductor 1, dielectric 1, diffuse 1)",
        "textures    2 (checkerboard 1, fbm 1)",
        "warnings    3",
        "s.pbrt:4:1: sampler \"pmj02bn\" is not implemented",
        "s.pbrt:9:1: texture \"lonely\" is not used by any material",
        "s.pbrt:12:76: unused parameter \"sparkle\" of Material \"conductor\"",
        "load        ",
    ] {
        assert!(out.contains(want), "missing {want:?} in\n{out}");
    }
    assert!(!d.join("never.exr").exists() && !Path::new("never.exr").exists());
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn render_check_only_is_info_with_the_render_overrides() {
    let d = tmpdir("check");
    let scene = d.join("s.pbrt");
    std::fs::write(&scene, SCENE).unwrap();
    let out = d.join("img.exr");
    let o = candela()
        .args([
            "render",
            "--check-only",
            "--spp",
            "9",
            "--integrator",
            "bdpt",
        ])
        .arg(&scene)
        .arg("--outfile")
        .arg(&out)
        .output()
        .unwrap();
    let text = stdout(&o);
    assert!(o.status.success(), "{text}");
    assert!(text.contains("paddedsobol), 9 spp"), "{text}");
    assert!(text.contains("integrator  bdpt, maxdepth 7"), "{text}");
    assert!(text.contains("triangles   2"), "{text}");
    assert!(!out.exists(), "--check-only must not render");
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn info_errors_exit_non_zero_with_the_location() {
    let d = tmpdir("err");
    let scene = d.join("bad.pbrt");
    std::fs::write(&scene, SCENE.replace("\"disk\"", "\"hyperboloid\"")).unwrap();
    for args in [&["info"][..], &["render", "--check-only"][..]] {
        let o = run(args, &scene);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{args:?}");
        assert!(
            err.contains("bad.pbrt:18:3: shape \"hyperboloid\" is not supported"),
            "{args:?}: {err}"
        );
        assert!(stdout(&o).is_empty(), "{args:?}: no summary on error");
    }
    std::fs::remove_dir_all(&d).ok();
}
