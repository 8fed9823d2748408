//! End-to-end tests of the `candela` binary: outputs, errors with
//! file:line:col and a non-zero exit code, unused-parameter warnings, `diff`.

use std::path::PathBuf;
use std::process::Command;

fn candela() -> Command {
    Command::new(env!("CARGO_BIN_EXE_candela"))
}

fn tmpdir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("candela-cli-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

const SMALL: &str = r#"LookAt 0 0 -3  0 0 0  0 1 0
Option "bool disablepixeljitter" true
Camera "perspective" "float fov" [45] "float bogus" [1]
Film "rgb" "integer xresolution" [16] "integer yresolution" [12]
Sampler "independent" "integer pixelsamples" [4]
Integrator "path" "integer maxdepth" [3]
WorldBegin
LightSource "point" "point3 from" [0 2 -2] "rgb I" [5 5 5]
Material "diffuse" "rgb reflectance" [0.5 0.3 0.2]
Shape "sphere" "float radius" [1]
"#;

#[test]
fn render_writes_exr_and_png_and_warns_about_unused_parameters() {
    let d = tmpdir("render");
    let scene = d.join("s.pbrt");
    std::fs::write(&scene, SMALL).unwrap();
    let out = d.join("img.exr");
    let o = candela()
        .args(["render"])
        .arg(&scene)
        .args(["--spp", "2", "--quiet", "--outfile"])
        .arg(&out)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(out.exists() && d.join("img.png").exists());
    assert!(
        err.contains("unused parameter \"bogus\"") && err.contains("s.pbrt:2:"),
        "{err}"
    );
    // diff of an image against itself: ratio 1, zero error.
    let o = candela().arg("diff").arg(&out).arg(&out).output().unwrap();
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success() && text.contains("relMSE (eps 0.01)  0.000000"),
        "{text}"
    );
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn errors_name_file_line_column_and_exit_non_zero() {
    let d = tmpdir("errors");
    let cases = [
        (
            SMALL.replace("Shape \"sphere\"", "Shape \"hyperboloid\""),
            ":10:1",
            "hyperboloid",
        ),
        (
            SMALL.replace("\"float fov\" [45]", "\"float fov\" [\"wide\"]"),
            ":3:",
            "fov",
        ),
        (format!("{SMALL}Frobnicate 1 2 3\n"), ":11:1", "Frobnicate"),
        (
            SMALL.replace("Integrator \"path\"", "Integrator \"mlt\""),
            ":6:1",
            "mlt",
        ),
    ];
    for (i, (text, loc, word)) in cases.iter().enumerate() {
        let scene = d.join(format!("bad{i}.pbrt"));
        std::fs::write(&scene, text).unwrap();
        let o = candela()
            .arg("render")
            .arg(&scene)
            .args(["--quiet", "--outfile"])
            .arg(d.join("x.exr"))
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "case {i} should fail");
        assert!(
            err.contains(&format!("bad{i}.pbrt{loc}")) && err.contains(word),
            "case {i}: {err}"
        );
        assert!(!err.contains("panicked"), "case {i}: {err}");
    }
    let o = candela()
        .args(["render", "/no/such/file.pbrt"])
        .output()
        .unwrap();
    assert!(
        !o.status.success() && String::from_utf8_lossy(&o.stderr).contains("/no/such/file.pbrt")
    );
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn ppm_pass_ranges_merge_into_the_full_render_bit_for_bit() {
    let d = tmpdir("ppm");
    let scene = d.join("s.pbrt");
    let text = SMALL
        .replace(
            "Integrator \"path\" \"integer maxdepth\" [3]",
            "Integrator \"ppm\" \"float radius\" [0.3] \"integer photonsperiteration\" [3000]",
        )
        .replace(" \"float bogus\" [1]", "");
    std::fs::write(&scene, text).unwrap();
    let run = |args: &[&str], out: &str| {
        let o = candela()
            .arg("render")
            .arg(&scene)
            .args(args)
            .args(["--quiet", "--seed", "3", "--outfile"])
            .arg(d.join(out))
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    run(&["--spp", "5"], "full.exr");
    run(&["--spp", "5", "--pass-range", "0..2"], "a.exr");
    run(&["--spp", "5", "--pass-range", "2..5"], "b.exr");
    let o = candela()
        .arg("merge")
        .arg(&scene)
        .arg(d.join("b.passes-2-5.cndl"))
        .arg(d.join("a.passes-0-2.cndl"))
        .arg("--outfile")
        .arg(d.join("merged.exr"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let read = |f: &str| std::fs::read(d.join(f)).unwrap();
    assert_eq!(
        read("merged.exr"),
        read("full.exr"),
        "merged EXR differs from the full render"
    );
    // Overlapping or gapped ranges are refused.
    let o = candela()
        .arg("merge")
        .arg(&scene)
        .arg(d.join("a.passes-0-2.cndl"))
        .arg(d.join("a.passes-0-2.cndl"))
        .arg("-o")
        .arg(d.join("bad.exr"))
        .output()
        .unwrap();
    assert!(!o.status.success());
    let o = candela()
        .args(["render"])
        .arg(&scene)
        .args(["--integrator", "sppm", "--pass-range", "0..2", "--quiet"])
        .output()
        .unwrap();
    assert!(!o.status.success(), "SPPM passes are not independent");
}
