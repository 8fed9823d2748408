//! Hostile inputs through the binary: each gives one located error and a
//! non-zero exit (never a panic, a hang or unbounded memory), or works.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

use candela_core::image::RgbImage;

fn tmpdir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("candela-hostile-{name}-{}", std::process::id()));
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

/// Asserts a clean failure: exit 1, no panic, and returns stderr.
fn clean_error(o: &Output) -> String {
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(err.starts_with("candela: error: "), "{err}");
    err
}

const HEAD: &str = "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\n\
                    Film \"rgb\" \"integer xresolution\" [20] \"integer yresolution\" [10]\n\
                    Sampler \"independent\" \"integer pixelsamples\" [1]\nWorldBegin\n";

#[test]
fn include_of_dev_zero_is_refused_at_once() {
    let d = tmpdir("zero");
    std::fs::write(d.join("s.pbrt"), format!("{HEAD}Include \"/dev/zero\"\n")).unwrap();
    let t = Instant::now();
    let o = candela(&["render", "s.pbrt", "--quiet"], &d);
    assert!(t.elapsed() < Duration::from_secs(10), "{:?}", t.elapsed());
    let err = clean_error(&o);
    assert!(
        err.starts_with(
            "candela: error: s.pbrt:6:1: cannot read '/dev/zero': it is not a regular file"
        ),
        "{err}"
    );
}

#[test]
fn plymesh_with_a_two_index_face_is_a_located_error() {
    let d = tmpdir("ply2");
    std::fs::write(
        d.join("m.ply"),
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
         property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\
         0 0 0\n1 0 0\n0 1 0\n2 0 1\n",
    )
    .unwrap();
    std::fs::write(
        d.join("s.pbrt"),
        format!("{HEAD}Shape \"plymesh\" \"string filename\" \"m.ply\"\n"),
    )
    .unwrap();
    let err = clean_error(&candela(&["render", "s.pbrt", "--quiet"], &d));
    assert!(
        err.contains("s.pbrt:6:1: bad PLY file: m.ply:13:5: face 0 has 2 vertex indices"),
        "{err}"
    );
}

/// Issue 11: "a PLY whose header declares fewer vertices than it holds
/// ... yields 0 triangles silently". ASCII and binary, the left-over data is
/// a located error (a line, or a byte offset).
#[test]
fn plymesh_holding_more_than_its_header_declares_is_a_located_error() {
    let d = tmpdir("plycount");
    let header = |format: &str| {
        format!(
            "ply\nformat {format} 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
             property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
        )
    };
    let ascii = format!("{}0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n", header("ascii"));
    let mut binary = header("binary_little_endian").into_bytes();
    for x in [0f32, 0., 0., 1., 0., 0., 0., 1., 0., 1., 1., 0.] {
        binary.extend(x.to_le_bytes());
    }
    binary.push(3);
    for i in [0i32, 1, 2] {
        binary.extend(i.to_le_bytes());
    }
    std::fs::write(
        d.join("s.pbrt"),
        format!("{HEAD}Shape \"plymesh\" \"string filename\" \"m.ply\"\n"),
    )
    .unwrap();
    for (bytes, at) in [(ascii.into_bytes(), "m.ply:13:"), (binary, "m.ply: ")] {
        std::fs::write(d.join("m.ply"), bytes).unwrap();
        let err = clean_error(&candela(&["render", "s.pbrt", "--quiet"], &d));
        assert!(
            err.contains(&format!("s.pbrt:6:1: bad PLY file: {at}")),
            "{err}"
        );
    }
}

#[test]
fn a_byte_order_mark_is_accepted() {
    let d = tmpdir("bom");
    std::fs::write(
        d.join("s.pbrt"),
        format!("\u{feff}{HEAD}Shape \"sphere\"\n"),
    )
    .unwrap();
    let o = candela(&["render", "s.pbrt", "--quiet", "--outfile", "o.exr"], &d);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn cropwindow_flag_renders_only_the_window_and_is_validated() {
    let d = tmpdir("crop");
    // The scene's own crop window and pixel bounds are overridden.
    let head = HEAD.replace(
        "[10]\n",
        "[10] \"float cropwindow\" [0 1 0 1] \"integer pixelbounds\" [0 20 0 10]\n",
    );
    std::fs::write(d.join("s.pbrt"), format!("{head}Shape \"sphere\"\n")).unwrap();
    let o = candela(
        &[
            "render",
            "s.pbrt",
            "--quiet",
            "--outfile",
            "o.exr",
            "--cropwindow",
            "0.25,0.5,0,0.3",
        ],
        &d,
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let img = RgbImage::read_exr(&d.join("o.exr")).unwrap();
    // x: ceil(0.25·20)..ceil(0.5·20) = 5..10; y: 0..ceil(0.3·10) = 0..3.
    assert_eq!((img.width, img.height), (5, 3));
    for bad in ["0.5,0.25,0,1", "0,1,0", "0,1.5,0,1", "a,b,c,d", "nan,1,0,1"] {
        let o = candela(&["render", "s.pbrt", "--cropwindow", bad], &d);
        assert_eq!(
            o.status.code(),
            Some(2),
            "{bad}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
}

#[test]
fn diff_reports_non_finite_pixels_and_fails() {
    let d = tmpdir("nan");
    let mut a = RgbImage::new(8, 4);
    a.pixels.iter_mut().for_each(|p| *p = [0.5; 3]);
    let b = a.clone();
    a.pixels[8 + 3][1] = f32::NAN;
    a.pixels[2 * 8 + 6][0] = f32::INFINITY;
    a.write_exr(&d.join("a.exr")).unwrap();
    b.write_exr(&d.join("b.exr")).unwrap();
    let err = clean_error(&candela(&["diff", "a.exr", "b.exr"], &d));
    assert_eq!(
        err.trim_end(),
        "candela: error: a.exr: 2 non-finite (NaN or infinite) pixels, the first at (3, 1)"
    );
    // Both sides are checked, and finite images still compare.
    let err = clean_error(&candela(&["diff", "b.exr", "a.exr"], &d));
    assert!(err.contains("a.exr: 2 non-finite"), "{err}");
    // In a region, positions stay those of the full image.
    let err = clean_error(&candela(
        &["diff", "a.exr", "b.exr", "--region", "4,1,8,4"],
        &d,
    ));
    assert!(
        err.contains("a.exr: 1 non-finite (NaN or infinite) pixels, the first at (6, 2)"),
        "{err}"
    );
    let o = candela(&["diff", "b.exr", "b.exr"], &d);
    assert!(o.status.success());
}

#[test]
fn os_errors_are_printed_once() {
    let d = tmpdir("once");
    for args in [
        &["diff", "nope.exr", "b.exr"][..],
        &["render", "nope.pbrt"][..],
    ] {
        let err = clean_error(&candela(args, &d));
        assert_eq!(err.matches("No such file or directory").count(), 1, "{err}");
        assert_eq!(err.matches("nope.").count(), 1, "{err}");
    }
}

/// Every saved fuzz finding (`crates/candela-fuzz/findings/*.pbrt`) stays
/// fixed: it renders or gives one located error, within a time limit, and
/// never panics, aborts or hangs.
#[test]
fn every_saved_fuzz_finding_renders_or_fails_cleanly() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../candela-fuzz/findings");
    let out = tmpdir("findings").join("o.exr");
    let mut n = 0;
    for e in std::fs::read_dir(&dir).unwrap().flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if !name.ends_with(".pbrt") {
            continue;
        }
        n += 1;
        let mut child = Command::new(env!("CARGO_BIN_EXE_candela"))
            .args(["render", &name, "--spp", "1", "--quiet", "--outfile"])
            .arg(&out)
            .current_dir(&dir)
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        let t = Instant::now();
        while child.try_wait().unwrap().is_none() {
            if t.elapsed() > Duration::from_secs(60) {
                let _ = child.kill();
                panic!("{name}: still running after 60 s");
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        let o = child.wait_with_output().unwrap();
        if !o.status.success() {
            let err = clean_error(&o);
            assert!(
                err.starts_with(&format!("candela: error: {name}:")),
                "{err}"
            );
        }
    }
    assert!(n >= 6, "only {n} findings");
}
