//! Each kind of scene mistake gives exactly one error line, naming
//! `file:line:col`, and a non-zero exit: a missing PLY mesh, a missing
//! `Include`, a missing `.spd` spectrum, a malformed PLY file, a parameter
//! of the wrong type, an unknown directive, and an error inside an included
//! file. `info`, `render --check-only` and `render` report alike.

use std::path::{Path, PathBuf};
use std::process::Command;

fn tmpdir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("candela-errors-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

const HEADER: &str = r#"LookAt 0 0 -3  0 0 0  0 1 0
Camera "perspective" "float fov" [45]
Film "rgb" "integer xresolution" [8] "integer yresolution" [8]
WorldBegin
"#;

/// Runs `candela ARGS scene` and returns stderr after checking it is one
/// error line and the exit code is non-zero.
fn one_error(args: &[&str], scene: &Path) -> String {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_candela"));
    cmd.args(args).arg(scene);
    if args[0] == "render" {
        cmd.args(["--quiet", "--outfile"])
            .arg(scene.with_extension("exr"));
    }
    let o = cmd.output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(
        !o.status.success(),
        "{args:?} {}: succeeded",
        scene.display()
    );
    assert_eq!(err.lines().count(), 1, "{args:?}: not one line:\n{err}");
    assert!(err.starts_with("candela: error: "), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    err
}

/// Writes `world` after the header to `dir/name` and checks every command
/// reports `loc` (relative to the scene file) followed by `what`.
fn check(dir: &Path, name: &str, world: &str, loc: &str, what: &str) {
    let scene = dir.join(name);
    std::fs::write(&scene, format!("{HEADER}{world}")).unwrap();
    for args in [&["info"][..], &["render", "--check-only"], &["render"]] {
        let err = one_error(args, &scene);
        let want = format!("candela: error: {}:{loc}: {what}", scene.display());
        assert!(err.starts_with(&want), "{args:?}: {err}\nwanted: {want}");
    }
}

#[test]
fn missing_files_are_named_at_the_directive_or_parameter() {
    let d = tmpdir("missing");
    check(
        &d,
        "ply.pbrt",
        "Shape \"plymesh\" \"string filename\" \"geo/nope.ply\"\n",
        "5:17",
        &format!("cannot read '{}'", d.join("geo/nope.ply").display()),
    );
    check(
        &d,
        "include.pbrt",
        "Shape \"sphere\"\n  Include \"parts/nope.pbrt\"\n",
        "6:3",
        &format!("cannot read '{}'", d.join("parts/nope.pbrt").display()),
    );
    check(
        &d,
        "spd.pbrt",
        "Material \"diffuse\" \"spectrum reflectance\" \"nope.spd\"\nShape \"sphere\"\n",
        "5:20",
        &format!("cannot read '{}'", d.join("nope.spd").display()),
    );
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn malformed_ply_names_the_shape_and_the_place_in_the_mesh() {
    let d = tmpdir("badply");
    std::fs::write(
        d.join("bad.ply"),
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0\n1\n",
    )
    .unwrap();
    check(
        &d,
        "s.pbrt",
        "Shape \"plymesh\" \"string filename\" \"bad.ply\"\n",
        "5:1",
        &format!("bad PLY file: {}", d.join("bad.ply").display()),
    );
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn wrong_parameter_types_and_unknown_directives_are_located() {
    let d = tmpdir("syntax");
    let scene = d.join("fov.pbrt");
    std::fs::write(
        &scene,
        HEADER.replace("\"float fov\" [45]", "\"string fov\" \"wide\""),
    )
    .unwrap();
    for args in [&["info"][..], &["render", "--check-only"], &["render"]] {
        let err = one_error(args, &scene);
        assert!(
            err.contains(&format!(
                "{}:2:22: expected a float for 'fov', found string",
                scene.display()
            )),
            "{err}"
        );
    }
    check(
        &d,
        "directive.pbrt",
        "Shape \"sphere\"\n   Frobnicate \"x\"\n",
        "6:4",
        "unknown directive 'Frobnicate'",
    );
    check(
        &d,
        "radius.pbrt",
        "Shape \"sphere\" \"integer radius\" [2]\n",
        "5:16",
        "expected a float for 'radius', found integer",
    );
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn errors_in_included_files_name_the_included_file() {
    let d = tmpdir("incl");
    std::fs::create_dir_all(d.join("parts")).unwrap();
    std::fs::write(d.join("parts/a.pbrt"), "Shape \"sphere\"\n\n  Bogus 1\n").unwrap();
    let scene = d.join("main.pbrt");
    std::fs::write(&scene, format!("{HEADER}Include \"parts/a.pbrt\"\n")).unwrap();
    let err = one_error(&["info"], &scene);
    assert!(
        err.contains(&format!(
            "{}:3:3: unknown directive 'Bogus'",
            d.join("parts/a.pbrt").display()
        )),
        "{err}"
    );
    std::fs::remove_dir_all(&d).ok();
}
