//! The pass-shaped render loop end to end: every integrator with independent
//! passes splits into pass ranges that `candela merge` joins into the very
//! bytes of one run; one and two threads give the same bytes; a render
//! stopped by SIGINT resumes from its checkpoint to the bytes of an
//! uninterrupted run; mismatched and damaged checkpoints are refused.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Duration;

fn candela() -> Command {
    Command::new(env!("CARGO_BIN_EXE_candela"))
}

fn tmpdir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("candela-passes-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A 37×29 box (not a multiple of the tile size) lit by a quad light, with a
/// glass sphere so every estimator has caustics and connections to do.
fn scene(integrator: &str) -> String {
    format!(
        r#"LookAt 0 1 -3.2  0 1 0  0 1 0
Camera "perspective" "float fov" [45]
Film "rgb" "integer xresolution" [37] "integer yresolution" [29]
Sampler "independent" "integer pixelsamples" [8]
Integrator {integrator}
WorldBegin
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [8 8 8]
  Translate 0 1.99 0
  Shape "trianglemesh" "point3 P" [-0.3 0 -0.3  0.3 0 -0.3  0.3 0 0.3  -0.3 0 0.3]
    "integer indices" [0 1 2 0 2 3]
AttributeEnd
Material "diffuse" "rgb reflectance" [0.6 0.5 0.4]
Shape "trianglemesh" "point3 P" [-1 0 -1  1 0 -1  1 0 1  -1 0 1  -1 2 -1  1 2 -1  1 2 1  -1 2 1]
  "integer indices" [0 1 2 0 2 3  4 6 5 4 7 6  0 3 7 0 7 4  1 5 6 1 6 2  3 2 6 3 6 7]
Material "dielectric" "float eta" [1.5]
AttributeBegin
  Translate 0.3 0.4 0.2
  Shape "sphere" "float radius" [0.35]
AttributeEnd
"#
    )
}

const INTEGRATORS: [(&str, &str); 8] = [
    ("path", r#""path" "integer maxdepth" [5]"#),
    ("lightpath", r#""lightpath" "integer maxdepth" [5]"#),
    ("bdpt", r#""bdpt" "integer maxdepth" [5]"#),
    (
        "ppm",
        r#""ppm" "float radius" [0.1] "integer photonsperiteration" [4000]"#,
    ),
    (
        "photonmap",
        r#""photonmap" "integer photons" [3000] "integer causticphotons" [3000] "integer gatherrays" [2]"#,
    ),
    (
        "vcm",
        r#""vcm" "float radius" [0.1] "integer maxdepth" [5]"#,
    ),
    // The default radius comes from a pilot light pass that every process
    // must repeat identically.
    ("vcm-default-radius", r#""vcm" "integer maxdepth" [5]"#),
    // With few light paths the pilot's radius is above its lower bound and
    // the radius field is kept (status line: radius 0.1220, over the scene
    // 0.1168–0.2439); its four pilot passes too must be the same in every
    // process.
    (
        "vcm-radius-field",
        r#""vcm" "integer maxdepth" [5] "integer photonsperiteration" [300]"#,
    ),
];

fn run(scene: &Path, args: &[&str], out: &Path) -> Output {
    let o = candela()
        .arg("render")
        .arg(scene)
        .args(args)
        .args(["--quiet", "--seed", "5", "--outfile"])
        .arg(out)
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

fn bytes(p: &Path) -> Vec<u8> {
    std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

#[test]
fn uneven_pass_ranges_merge_into_the_bytes_of_one_run_for_every_integrator() {
    for (name, directive) in INTEGRATORS {
        let d = tmpdir(name);
        let s = d.join("s.pbrt");
        std::fs::write(&s, scene(directive)).unwrap();
        run(&s, &["--spp", "7"], &d.join("full.exr"));
        for (a, b) in [(0, 1), (1, 5), (5, 7)] {
            let r = format!("{a}..{b}");
            run(
                &s,
                &["--spp", "7", "--pass-range", &r],
                &d.join(format!("p{a}.exr")),
            );
        }
        merge_equals_full(
            &d,
            &s,
            name,
            &[
                "p5.passes-5-7.cndl",
                "p0.passes-0-1.cndl",
                "p1.passes-1-5.cndl",
            ],
        );
        assert!(
            bytes(&d.join("merged.png")) == bytes(&d.join("full.png")),
            "{name}: PNG"
        );
        // Overlapping parts are refused with a message.
        let o = candela()
            .arg("merge")
            .arg(&s)
            .args(["p1.passes-1-5.cndl", "p1.passes-1-5.cndl"].map(|p| d.join(p)))
            .arg("-o")
            .arg(d.join("bad.exr"))
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            !o.status.success() && err.contains("overlap"),
            "{name}: {err}"
        );
        std::fs::remove_dir_all(&d).ok();
    }
}

/// With layers (first-hit values, variance, spectral buckets, pbrt-v4's
/// gbuffer, photometric luminance and illuminance with their standard
/// errors) pass ranges still merge into the bytes of one run: the merge
/// rebuilds the layers from the `aov=` and `units=` settings stored in the
/// parts. Photometric renders write false-colour PNGs, which must match too.
#[test]
fn pass_ranges_with_layers_merge_into_the_bytes_of_one_run() {
    let cases: [(&str, &str, &str, &[&str]); 6] = [
        (
            "aov-path",
            r#""path" "integer maxdepth" [5]"#,
            "rgb",
            &["--aov", "albedo,depth,normal,uv,dzdxy,variance"],
        ),
        (
            "aov-ppm",
            INTEGRATORS[3].1,
            "rgb",
            &["--aov", "position,shading_normal,variance"],
        ),
        ("gbuffer-bdpt", INTEGRATORS[2].1, "gbuffer", &[]),
        (
            "spectral-lightpath",
            INTEGRATORS[1].1,
            "spectral",
            &["--aov", "albedo"],
        ),
        (
            "photometric-path",
            r#""path" "integer maxdepth" [5]"#,
            "rgb",
            &["--units", "photometric", "--aov", "depth"],
        ),
        (
            "photometric-lightpath",
            INTEGRATORS[1].1,
            "spectral",
            &["--units", "photometric"],
        ),
    ];
    for (name, directive, film, extra) in cases {
        let d = tmpdir(name);
        let s = d.join("s.pbrt");
        let text = scene(directive).replace(r#"Film "rgb""#, &format!(r#"Film "{film}""#));
        std::fs::write(&s, text).unwrap();
        let mut flags = vec!["--spp", "5"];
        flags.extend(extra);
        run(&s, &flags, &d.join("full.exr"));
        for (a, b) in [(0, 2), (2, 5)] {
            let r = format!("{a}..{b}");
            let mut f = flags.clone();
            f.extend(["--pass-range", &r]);
            run(&s, &f, &d.join(format!("p{a}.exr")));
        }
        merge_equals_full(&d, &s, name, &["p2.passes-2-5.cndl", "p0.passes-0-2.cndl"]);
        let layers = candela_core::image::read_exr_layers(&d.join("full.exr")).unwrap();
        assert!(layers.layers.len() > 1, "{name}: no layers written");
        if extra.contains(&"photometric") {
            assert!(layers.layer("illuminance_stderr").is_some(), "{name}");
            for png in ["luminance.png", "illuminance.png"] {
                assert!(
                    bytes(&d.join(format!("merged.{png}")))
                        == bytes(&d.join(format!("full.{png}"))),
                    "{name}: {png} differs"
                );
            }
        }
        std::fs::remove_dir_all(&d).ok();
    }
}

/// Merges the `parts` in `d` and checks the EXR equals `full.exr`.
fn merge_equals_full(d: &Path, s: &Path, name: &str, parts: &[&str]) {
    let o = candela()
        .arg("merge")
        .arg(s)
        .args(parts.iter().map(|p| d.join(p)))
        .arg("-o")
        .arg(d.join("merged.exr"))
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "{name}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(
        bytes(&d.join("merged.exr")) == bytes(&d.join("full.exr")),
        "{name}: merged EXR differs from one run"
    );
}

#[test]
fn one_and_two_threads_write_the_same_bytes() {
    let mut all = INTEGRATORS.to_vec();
    all.push((
        "sppm",
        r#""sppm" "float radius" [0.1] "integer photonsperiteration" [4000]"#,
    ));
    for (name, directive) in all {
        let d = tmpdir(&format!("threads-{name}"));
        let s = d.join("s.pbrt");
        std::fs::write(&s, scene(directive)).unwrap();
        run(&s, &["--spp", "3", "--nthreads", "1"], &d.join("one.exr"));
        run(&s, &["--spp", "3", "--nthreads", "2"], &d.join("two.exr"));
        assert!(
            bytes(&d.join("one.exr")) == bytes(&d.join("two.exr")),
            "{name}: thread count changed the image"
        );
        std::fs::remove_dir_all(&d).ok();
    }
}

/// Passes counted in the state file's closing report line.
fn passes_reported(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).to_string()
}

#[test]
fn sigint_writes_image_and_checkpoint_and_resume_gives_the_uninterrupted_bytes() {
    let d = tmpdir("resume");
    let s = d.join("s.pbrt");
    std::fs::write(&s, scene(r#""path" "integer maxdepth" [5]"#)).unwrap();
    let args = ["--spp", "4000", "--seed", "2", "--nthreads", "2"];
    let child = candela()
        .arg("render")
        .arg(&s)
        .args(args)
        .arg("--outfile")
        .arg(d.join("stopped.exr"))
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(1500));
    let kill = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let o = child.wait_with_output().unwrap();
    let err = passes_reported(&o);
    assert_eq!(o.status.code(), Some(130), "{err}");
    assert!(err.contains("interrupted"), "{err}");
    let ckpt = d.join("stopped.cndl");
    assert!(ckpt.exists() && d.join("stopped.exr").exists(), "{err}");
    // Resume to the end, and render the same passes without a stop.
    let resumed = d.join("resumed.exr");
    let o = candela()
        .arg("render")
        .arg(&s)
        .args(args)
        .arg("--resume")
        .arg(&ckpt)
        .args(["--quiet", "--outfile"])
        .arg(&resumed)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let whole = d.join("whole.exr");
    let o = candela()
        .arg("render")
        .arg(&s)
        .args(args)
        .args(["--quiet", "--outfile"])
        .arg(&whole)
        .output()
        .unwrap();
    assert!(o.status.success());
    assert!(
        bytes(&resumed) == bytes(&whole),
        "resumed render differs from an uninterrupted one"
    );

    refusals(&d, &s, &ckpt, &args);
    std::fs::remove_dir_all(&d).ok();
}

/// A checkpoint of another scene, of other flags, truncated or not a
/// checkpoint at all is refused with a message, and no image is written.
fn refusals(d: &Path, s: &Path, ckpt: &Path, args: &[&str]) {
    let other = d.join("other.pbrt");
    std::fs::write(&other, scene(r#""path" "integer maxdepth" [4]"#)).unwrap();
    let refuse = |scene: &Path, ckpt: &Path, extra: &[&str], word: &str| {
        let o = candela()
            .arg("render")
            .arg(scene)
            .args(extra)
            .arg("--resume")
            .arg(ckpt)
            .args(["--quiet", "--outfile"])
            .arg(d.join("never.exr"))
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && err.contains(word), "{err}");
        assert!(!err.contains("panicked"), "{err}");
        assert!(
            !d.join("never.exr").exists(),
            "a refused resume wrote an image"
        );
    };
    refuse(&other, ckpt, args, "another scene");
    refuse(s, ckpt, &["--spp", "4000", "--seed", "3"], "another scene");
    let cut = d.join("cut.cndl");
    let full = bytes(ckpt);
    std::fs::write(&cut, &full[..full.len() / 2]).unwrap();
    refuse(s, &cut, args, "truncated or damaged");
    std::fs::write(&cut, b"not a checkpoint at all, just text").unwrap();
    refuse(s, &cut, args, "not a candela render state");
}
