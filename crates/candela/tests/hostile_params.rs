//! Issue 11's parameter and transform cases through the binary: each is
//! refused before anything is allocated or rendered, by `candela info` and
//! `candela render` alike, with exit code 1, one error naming the entity and
//! the parameter at the parameter's file:line:col (the directive's, where
//! the fault is the directive itself), and no panic. Values given on the
//! command line name the flag instead of a place in the scene.
//!
//! The expected place is found from the case's own text (the first
//! occurrence of a marker), so a case cannot pass with the error pointing
//! at the wrong parameter or the wrong line.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn tmpdir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("candela-params-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn candela(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_candela"))
        .args(args)
        .current_dir(dir)
        .env("RUST_BACKTRACE", "0")
        .output()
        .unwrap()
}

/// Asserts exit code `code`, no panic and no `Debug` dump; returns stderr.
fn refused(o: &Output, code: i32, what: &str) -> String {
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    // A panic exits 101, an abort or stack overflow by a signal (no code).
    assert_eq!(o.status.code(), Some(code), "{what}: {:?}\n{err}", o.status);
    // "\u{7b}" is an opening brace (of a `Debug` struct), spelled so that
    // structure.rs's brace count stays balanced.
    for bad in ["panicked", "RUST_BACKTRACE", "\u{7b}", "Some("] {
        assert!(!err.contains(bad), "{what}: '{bad}' in\n{err}");
    }
    err
}

const FILM: &str = "\"integer xresolution\" [20] \"integer yresolution\" [10]";
const SAMPLER: &str = "\"integer pixelsamples\" [1]";

/// A small scene: `film` and `sampler` parameters, `opts` lines before
/// WorldBegin (Integrator, PixelFilter), then `world`.
fn scene(film: &str, sampler: &str, opts: &str, world: &str) -> String {
    format!(
        "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\nFilm \"rgb\" {film}\n\
         Sampler \"independent\" {sampler}\n{opts}\nWorldBegin\n{world}\n"
    )
}

/// `line:col` (1-based) of the first occurrence of `marker` in `text`.
fn place(text: &str, marker: &str) -> String {
    let at = text.find(marker).unwrap_or_else(|| panic!("no {marker}"));
    let before = &text[..at];
    let line = before.matches('\n').count() + 1;
    let col = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
    format!("{line}:{col}")
}

/// A triangle strip of `n` triangles in the z = 0 plane.
fn mesh(n: usize) -> String {
    let p: Vec<String> = (0..n + 2)
        .map(|i| format!("{} {} 0", i / 2, i % 2))
        .collect();
    let idx: Vec<String> = (0..n).map(|i| format!("{i} {} {}", i + 1, i + 2)).collect();
    format!(
        "Shape \"trianglemesh\" \"point3 P\" [{}] \"integer indices\" [{}]",
        p.join(" "),
        idx.join(" ")
    )
}

/// One case: the scene, the marker of the blamed place, the message.
struct Case {
    text: String,
    at: &'static str,
    msg: String,
}

fn world(world: &str, at: &'static str, msg: &str) -> Case {
    Case {
        text: scene(FILM, SAMPLER, "", world),
        at,
        msg: msg.into(),
    }
}

fn film(film: &str, at: &'static str, msg: &str) -> Case {
    Case {
        text: scene(film, SAMPLER, "", "Shape \"sphere\""),
        at,
        msg: msg.into(),
    }
}

fn opts(opts: &str, at: &'static str, msg: &str) -> Case {
    Case {
        text: scene(
            FILM,
            SAMPLER,
            opts,
            "LightSource \"point\"\nShape \"sphere\"",
        ),
        at,
        msg: msg.into(),
    }
}

/// Runs `info` and `render` on every case and checks the one located error.
fn check_all(name: &str, cases: &[Case]) {
    let d = tmpdir(name);
    for (k, c) in cases.iter().enumerate() {
        let file = format!("c{k}.pbrt");
        std::fs::write(d.join(&file), &c.text).unwrap();
        let want = format!("candela: error: {file}:{}: {}", place(&c.text, c.at), c.msg);
        for args in [
            &["info", &file][..],
            // A limit of its own, so no case depends on this machine's memory.
            &[
                "render",
                &file,
                "--quiet",
                "--outfile",
                "o.exr",
                "--memory-limit",
                "8G",
            ],
        ] {
            let err = refused(&candela(args, &d), 1, &c.msg);
            assert!(err.starts_with(&want), "{args:?}:\n{err}\nwanted: {want}");
            assert_eq!(err.lines().count(), 1, "{err}");
        }
        assert!(!d.join("o.exr").exists(), "{}: rendered", c.msg);
    }
}

#[test]
fn shape_radii_and_transforms_must_be_finite_and_in_their_domain() {
    let must = "must be a positive number";
    let nan = "has the value NaN: parameters must be finite numbers";
    let shape_transform = "the transformation of Shape \"trianglemesh\" is not finite";
    check_all(
        "shapes",
        &[
            world(
                "Shape \"sphere\" \"float radius\" [-1]",
                "\"float radius\"",
                &format!("Shape \"sphere\" \"radius\" {must}, found -1"),
            ),
            world(
                "Shape \"sphere\" \"float radius\" [nan]",
                "\"float radius\"",
                &format!("Shape \"sphere\" \"radius\" {nan}"),
            ),
            world(
                "Shape \"disk\" \"float radius\" [-2]",
                "\"float radius\"",
                &format!("Shape \"disk\" \"radius\" {must}, found -2"),
            ),
            world(
                "Shape \"cylinder\" \"float radius\" [nan]",
                "\"float radius\"",
                &format!("Shape \"cylinder\" \"radius\" {nan}"),
            ),
            world(
                &format!("Translate 0 1e39 0\n{}", mesh(100)),
                "Shape",
                shape_transform,
            ),
            world(
                &mesh(100).replacen("[0 0 0", "[0 0 nan", 1),
                "\"point3 P\"",
                &format!("Shape \"trianglemesh\" \"P\" (point3) {nan}"),
            ),
            world(
                "Scale nan 1 1\nShape \"sphere\"",
                "nan",
                "Scale: NaN is not a finite number",
            ),
            world(
                "Rotate 45 0 0 0\nShape \"sphere\"",
                "Rotate",
                "Rotate: the axis (0, 0, 0) has no direction",
            ),
        ],
    );
}

#[test]
fn material_and_light_parameters_must_be_in_their_domain() {
    let nan = "has the value NaN: parameters must be finite numbers";
    let on = |m: &str| format!("{m}\nShape \"sphere\"");
    let mat = |m: &str, at: &'static str, msg: &str| world(&on(m), at, msg);
    check_all(
        "materials",
        &[
            mat(
                "Material \"conductor\" \"float roughness\" [-0.5]",
                "\"float roughness\"",
                "Material \"conductor\" \"roughness\" must be a number ≥ 0, found -0.5",
            ),
            mat(
                "Material \"conductor\" \"float roughness\" [nan]",
                "\"float roughness\"",
                &format!("Material \"conductor\" \"roughness\" {nan}"),
            ),
            mat(
                "Material \"dielectric\" \"float eta\" [-1]",
                "\"float eta\"",
                "Material \"dielectric\" \"eta\" must be a positive number, found -1",
            ),
            mat(
                "Material \"dielectric\" \"float eta\" [nan]",
                "\"float eta\"",
                &format!("Material \"dielectric\" \"eta\" {nan}"),
            ),
            mat(
                "Material \"coateddiffuse\" \"float thickness\" [-1]",
                "\"float thickness\"",
                "Material \"coateddiffuse\" \"thickness\" must be a positive number, found -1",
            ),
            mat(
                "Material \"coatedconductor\" \"float thickness\" [nan]",
                "\"float thickness\"",
                &format!("Material \"coatedconductor\" \"thickness\" {nan}"),
            ),
            // One message, no Rust `Debug` dump of the colour (`refused`).
            mat(
                "Material \"diffuse\" \"rgb reflectance\" [2 2 2]",
                "\"rgb reflectance\"",
                "\"reflectance\": a reflectance RGB must be at most 1 in each channel, found 2 2 2",
            ),
            mat(
                "LightSource \"point\" \"float scale\" [nan]",
                "\"float scale\"",
                &format!("LightSource \"point\" \"scale\" {nan}"),
            ),
            mat(
                "LightSource \"spot\" \"float coneangle\" [-10]",
                "\"float coneangle\"",
                "LightSource \"spot\" \"coneangle\" must be a number in (0, 180], found -10",
            ),
            mat(
                "LightSource \"spot\" \"float conedeltaangle\" [nan]",
                "\"float conedeltaangle\"",
                &format!("LightSource \"spot\" \"conedeltaangle\" {nan}"),
            ),
        ],
    );
}

#[test]
fn film_sampler_and_integrator_settings_must_be_in_their_domain() {
    let xy = "\"integer xresolution\" [20] \"integer yresolution\" [10]";
    check_all(
        "settings",
        &[
            film(
                "\"integer xresolution\" [0] \"integer yresolution\" [10]",
                "\"integer xresolution\"",
                "Film \"rgb\" \"xresolution\" must be at least 1, found 0",
            ),
            film(
                "\"integer xresolution\" [20] \"integer yresolution\" [-16]",
                "\"integer yresolution\"",
                "Film \"rgb\" \"yresolution\" must be at least 1, found -16",
            ),
            film(
                &format!("{xy} \"float maxcomponentvalue\" [-1]"),
                "\"float maxcomponentvalue\"",
                "Film \"rgb\" \"maxcomponentvalue\" must be a positive number, found -1",
            ),
            film(
                &format!("{xy} \"float cropwindow\" [2 3 2 3]"),
                "\"float cropwindow\"",
                "Film \"cropwindow\" must be 4 floats x0 x1 y0 y1 in [0, 1]",
            ),
            Case {
                text: scene(FILM, "\"integer pixelsamples\" [0]", "", "Shape \"sphere\""),
                at: "\"integer pixelsamples\"",
                msg: "Sampler \"independent\" \"pixelsamples\" must be at least 1, found 0".into(),
            },
            Case {
                text: scene(FILM, "", "", "Shape \"sphere\"").replace(
                    "Sampler \"independent\"",
                    "Sampler \"halton\" \"string randomization\" \"fastowen\"",
                ),
                at: "\"string randomization\"",
                msg: "Sampler \"halton\" \"randomization\" \"fastowen\" is not supported by the \
                      Halton sampler (supported: none, permutedigits, owen)"
                    .into(),
            },
            opts(
                "Integrator \"path\" \"integer maxdepth\" [-1]",
                "\"integer maxdepth\"",
                "Integrator \"path\" \"maxdepth\" must be at least 0, found -1",
            ),
            opts(
                "Integrator \"vcm\" \"string mode\" \"bpm\" \"string directmerges\" \"never\"",
                "\"string directmerges\"",
                "Integrator \"vcm\" \"directmerges\" \"never\" needs connections (mode \"vcm\"): \
                 this mode has no other technique for direct light",
            ),
            opts(
                "Integrator \"vcm\" \"string ltweights\" \"power\"",
                "\"string ltweights\"",
                "Integrator \"vcm\" \"ltweights\" \"power\" is unknown (known: variance, density)",
            ),
            opts(
                "Integrator \"bdpt\" \"string ltweights\" \"balance\"",
                "\"string ltweights\"",
                "Integrator \"bdpt\" \"ltweights\" \"balance\" is unknown (known: variance, density)",
            ),
            opts(
                "Integrator \"vcm\" \"float joinroulette\" [1.5]",
                "\"float joinroulette\"",
                "Integrator \"vcm\" \"joinroulette\" must be a number in [0, 1], found 1.5",
            ),
        ],
    );
}

/// Light tracing alone (`lightpath`, vcm's mode `lt`) with a camera that
/// light paths cannot reach (no importance function: spherical, or an
/// orthographic pinhole) would render black; it is refused at the
/// Integrator directive, as `lightpath` already was (vcm's mode `lt` was
/// not: a black image and exit code 0).
#[test]
fn light_tracing_alone_needs_a_camera_light_paths_can_reach() {
    // Equirectangular: the default equal-area mapping needs a square film.
    const SPHERICAL: &str = "Camera \"spherical\" \"string mapping\" \"equirectangular\"";
    let msg = "the light tracer needs a camera that light paths can reach (perspective, or orthographic with a lens); this scene's camera has no importance function";
    let case = |camera: &str, integrator: &str| {
        let o = opts(integrator, "Integrator", "");
        let text = o.text.replace("Camera \"perspective\"", camera);
        assert_ne!(text, o.text, "camera replaced");
        let name = integrator.split('"').nth(1).unwrap_or_default();
        Case {
            text,
            at: "Integrator",
            msg: format!("Integrator \"{name}\": {msg}"),
        }
    };
    check_all(
        "lt-camera",
        &[
            case(SPHERICAL, "Integrator \"lightpath\""),
            case(
                "Camera \"orthographic\"",
                "Integrator \"vcm\" \"string mode\" \"lt\"",
            ),
            case(SPHERICAL, "Integrator \"vcm\" \"string mode\" \"lt\""),
        ],
    );
}

/// A shutter that closes when it opens (or before) would give a black image
/// (the exposure time scales the sensor's response): refused at the Camera
/// directive, as pbrt-v4 does (it said nothing and rendered black before).
#[test]
fn the_shutter_must_open() {
    let case = |times: &str, msg: &str| {
        let o = opts("", "Camera", "");
        Case {
            text: o.text.replace(
                "Camera \"perspective\"",
                &format!("Camera \"perspective\" {times}"),
            ),
            at: "Camera",
            msg: msg.into(),
        }
    };
    check_all(
        "shutter",
        &[
            case(
                "\"float shutteropen\" [0.5] \"float shutterclose\" [0.5]",
                "\"shutteropen\" and \"shutterclose\" are both 0.5: the shutter never opens, so the exposure time is 0 and the image would be black",
            ),
            case(
                "\"float shutterclose\" [0]",
                "\"shutteropen\" and \"shutterclose\" are both 0: the shutter never opens, so the exposure time is 0 and the image would be black",
            ),
            case(
                "\"float shutteropen\" [1] \"float shutterclose\" [0.5]",
                "\"shutterclose\" is before \"shutteropen\"",
            ),
        ],
    );
}

#[test]
fn memory_hungry_settings_are_refused_before_allocating_even_by_info() {
    let over = "over the memory limit";
    check_all(
        "memory",
        &[
            film(
                "\"integer xresolution\" [100000] \"integer yresolution\" [100000]",
                "Film",
                "Film \"rgb\" needs about",
            ),
            opts(
                "PixelFilter \"gaussian\" \"float xradius\" [1e6] \"float yradius\" [1e6]",
                "\"float xradius\"",
                "PixelFilter \"gaussian\" \"xradius\" needs about",
            ),
            opts(
                "Integrator \"sppm\" \"integer photonsperiteration\" [1000000000]",
                "\"integer photonsperiteration\"",
                "Integrator \"sppm\" \"photonsperiteration\" needs about",
            ),
            opts(
                "Integrator \"photonmap\" \"integer photons\" [2000000000]",
                "\"integer photons\"",
                "Integrator \"photonmap\" \"photons\" needs about",
            ),
            opts(
                "Integrator \"vcm\" \"integer photonsperiteration\" [2000000000]",
                "\"integer photonsperiteration\"",
                "Integrator \"vcm\" \"photonsperiteration\" needs about",
            ),
        ],
    );
    // Each error names the parameter to change, after the limit.
    let d = tmpdir("memory-fix");
    // The long fuzz run's cap hits: a 2³¹-wide film whose 2 % crop still
    // has 43 M pixels, run (as the fuzzer now runs it) under a 1 GB budget.
    let wide = "\"integer xresolution\" [2147483647] \"integer yresolution\" [64]";
    std::fs::write(
        d.join("w.pbrt"),
        scene(wide, SAMPLER, "", "Shape \"sphere\""),
    )
    .unwrap();
    let args = ["render", "w.pbrt", "--cropwindow", "0.26,0.28,0.88,0.9"];
    let o = candela(
        &[&args[..], &["--memory-limit", "1G", "--quiet"]].concat(),
        &d,
    );
    let err = refused(&o, 1, "wide film");
    assert!(
        err.starts_with("candela: error: w.pbrt:3:1: Film \"rgb\" needs about"),
        "{err}"
    );
    assert!(err.contains("over the --memory-limit of 1.0 GB"), "{err}");
    for (opt, fix) in [
        (
            "PixelFilter \"gaussian\" \"float xradius\" [1e6]",
            "lower \"xradius\"/\"yradius\"",
        ),
        (
            "Integrator \"photonmap\" \"integer photons\" [2000000000]",
            "lower \"photons\"",
        ),
    ] {
        std::fs::write(
            d.join("s.pbrt"),
            scene(FILM, SAMPLER, opt, "Shape \"sphere\""),
        )
        .unwrap();
        let err = refused(&candela(&["info", "s.pbrt"], &d), 1, opt);
        let tail = &err[err.find(over).unwrap_or_else(|| panic!("{err}"))..];
        assert!(tail.contains(fix), "{err}");
    }
}

#[test]
fn command_line_values_name_the_flag_not_the_scene() {
    let d = tmpdir("flags");
    std::fs::write(
        d.join("s.pbrt"),
        scene(FILM, SAMPLER, "", "Shape \"sphere\""),
    )
    .unwrap();
    let render = |extra: &[&str]| {
        let mut args = vec!["render", "s.pbrt", "--quiet", "--outfile", "o.exr"];
        args.extend_from_slice(extra);
        candela(&args, &d)
    };
    let err = refused(&render(&["--integrator", "bogus"]), 1, "bogus");
    assert!(
        err.starts_with("candela: error: --integrator: integrator \"bogus\" is not supported"),
        "{err}"
    );
    assert!(!err.contains("s.pbrt"), "blames the scene: {err}");
    // The file's parameters read by the flag's integrator say so.
    let opt = "Integrator \"path\" \"integer photonsperiteration\" [1000000000]";
    std::fs::write(
        d.join("p.pbrt"),
        scene(FILM, SAMPLER, opt, "Shape \"sphere\""),
    )
    .unwrap();
    let args = [
        "render",
        "p.pbrt",
        "--integrator",
        "sppm",
        "--memory-limit",
        "1G",
    ];
    let err = refused(&candela(&args, &d), 1, "override");
    let what = "Integrator \"path\" (rendered as \"sppm\" by --integrator) \"photonsperiteration\"";
    assert!(
        err.contains(&format!("p.pbrt:5:19: {what} needs about")),
        "{err}"
    );
    let err = refused(&render(&["--nthreads", "0"]), 1, "nthreads");
    assert!(err.contains("--nthreads must be at least 1"), "{err}");
    // clap's usage errors exit 2 and quote the flag.
    for (flag, value) in [("--spp", "0"), ("--memory-limit", "lots"), ("--seed", "x")] {
        let err = refused(&render(&[flag, value]), 2, flag);
        assert!(err.contains(&format!("'{flag} <")), "{err}");
    }
    assert!(!d.join("o.exr").exists());
}
