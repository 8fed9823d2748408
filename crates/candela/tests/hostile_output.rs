//! Issue 11's output cases through the binary: a bad output path is
//! refused before rendering (naming `--outfile`, or the Film's `"filename"`
//! at its file:line:col), a render killed while it writes its image leaves
//! the previous image whole, identical runs write identical EXR bytes, and
//! progress shows as plain lines when stderr is not a terminal.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use candela_core::image::RgbImage;

fn tmpdir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("candela-output-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn command(args: &[&str], dir: &Path) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_candela"));
    c.args(args).current_dir(dir).env("RUST_BACKTRACE", "0");
    c
}

fn candela(args: &[&str], dir: &Path) -> Output {
    command(args, dir).output().unwrap()
}

/// A sphere lit by a constant environment, `w`×`h` pixels, `spp` samples.
fn scene(w: u32, h: u32, spp: u32, film_extra: &str) -> String {
    format!(
        "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\n\
         Film \"rgb\" \"integer xresolution\" [{w}] \"integer yresolution\" [{h}]{film_extra}\n\
         Sampler \"independent\" \"integer pixelsamples\" [{spp}]\nIntegrator \"path\"\n\
         WorldBegin\nLightSource \"infinite\" \"rgb L\" [0.5 0.5 0.5]\nShape \"sphere\"\n"
    )
}

/// Runs `args` in `dir`, killing it after `limit`: the output, or `None`
/// when it had to be killed.
fn run_within(args: &[&str], dir: &Path, limit: Duration) -> Option<Output> {
    let mut child = command(args, dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let t = Instant::now();
    while t.elapsed() < limit {
        if child.try_wait().unwrap().is_some() {
            return Some(child.wait_with_output().unwrap());
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let _ = child.kill();
    let _ = child.wait();
    None
}

/// A directory this process cannot write in: a read-only one, or (for
/// root, whom permissions do not stop) /sys. `None` if there is neither.
fn unwritable_dir(d: &Path) -> Option<PathBuf> {
    use std::os::unix::fs::PermissionsExt;
    let ro = d.join("ro");
    std::fs::create_dir_all(&ro).unwrap();
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).unwrap();
    let cannot = |dir: &Path| std::fs::write(dir.join(".probe"), b"").is_err();
    [ro, PathBuf::from("/sys")]
        .into_iter()
        .find(|dir| dir.is_dir() && cannot(dir))
}

#[test]
fn bad_output_paths_are_refused_before_rendering() {
    let d = tmpdir("paths");
    // Hours of work: an error that came after rendering would time out.
    std::fs::write(d.join("slow.pbrt"), scene(1000, 1000, 100_000, "")).unwrap();
    std::fs::write(d.join("a-file"), b"not a directory").unwrap();
    let mut cases = vec![
        (
            "x.pfm".to_string(),
            "output file x.pfm must end in .exr".to_string(),
        ),
        ("noext".into(), "output file noext must end in .exr".into()),
        (
            "a-file/o.exr".into(),
            "cannot write a-file/o.exr: a-file is not a directory".into(),
        ),
    ];
    match unwritable_dir(&d) {
        Some(ro) => cases.push((
            ro.join("o.exr").display().to_string(),
            format!("cannot write output files in {}: ", ro.display()),
        )),
        None => eprintln!("no unwritable directory here: that case is skipped"),
    }
    for (out, msg) in &cases {
        let args = ["render", "slow.pbrt", "--quiet", "--outfile", out];
        let o = run_within(&args, &d, Duration::from_secs(30))
            .unwrap_or_else(|| panic!("{out}: still rendering after 30 s"));
        let err = String::from_utf8_lossy(&o.stderr).into_owned();
        assert_eq!(o.status.code(), Some(1), "{out}: {err}");
        assert!(!err.contains("panicked"), "{err}");
        let want = format!("candela: error: --outfile: {msg}");
        assert!(err.contains(&want), "{out}:\n{err}\nwanted: {want}");
        // The OS's reason, if any, once.
        assert!(err.matches("(os error").count() <= 1, "{err}");
    }
    // Without --outfile the scene's "filename" is blamed, at its place.
    let text = scene(1000, 1000, 100_000, " \"string filename\" \"x.pfm\"");
    std::fs::write(d.join("named.pbrt"), &text).unwrap();
    let o = run_within(
        &["render", "named.pbrt", "--quiet"],
        &d,
        Duration::from_secs(30),
    )
    .expect("still rendering after 30 s");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    let col = text
        .lines()
        .nth(2)
        .unwrap()
        .find("\"string filename\"")
        .unwrap()
        + 1;
    let want = format!("candela: error: named.pbrt:3:{col}: Film \"filename\": output file x.pfm");
    assert!(err.contains(&want), "{err}\nwanted: {want}");
}

/// Whether the write of `exr` has begun: a temporary beside it holds bytes,
/// or `exr` itself is no longer what it was (`before`: length, mtime).
fn write_begun(dir: &Path, exr: &str, before: &(u64, std::time::SystemTime)) -> bool {
    let now = std::fs::metadata(dir.join(exr)).map(|m| (m.len(), m.modified().unwrap()));
    if now.as_ref().ok() != Some(before) {
        return true;
    }
    std::fs::read_dir(dir).unwrap().flatten().any(|e| {
        let name = e.file_name().to_string_lossy().into_owned();
        name != exr && name.contains(exr) && e.metadata().is_ok_and(|m| m.len() > 0)
    })
}

/// Issue 11: "SIGTERM during a write left a 0-byte EXR where the previous
/// good one was". A second render of a larger image is killed (SIGKILL: no
/// handler can finish the write) as soon as its image write is seen to
/// start; the first render's file must be untouched, byte for byte. Written
/// in place, the file would be truncated or partial at that moment.
#[test]
fn a_render_killed_while_writing_its_image_leaves_the_previous_image_intact() {
    let d = tmpdir("kill");
    std::fs::write(d.join("small.pbrt"), scene(32, 16, 4, "")).unwrap();
    std::fs::write(d.join("big.pbrt"), scene(1024, 1024, 1, "")).unwrap();
    let o = candela(
        &["render", "small.pbrt", "--quiet", "--outfile", "out.exr"],
        &d,
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let old = std::fs::read(d.join("out.exr")).unwrap();
    let old_png = std::fs::read(d.join("out.png")).unwrap();
    let m = std::fs::metadata(d.join("out.exr")).unwrap();
    let before = (m.len(), m.modified().unwrap());
    let mut child = command(
        &["render", "big.pbrt", "--quiet", "--outfile", "out.exr"],
        &d,
    )
    .stderr(Stdio::piped())
    .spawn()
    .unwrap();
    let t = Instant::now();
    loop {
        assert!(t.elapsed() < Duration::from_secs(120), "no write seen");
        if let Some(st) = child.try_wait().unwrap() {
            panic!("the render ended ({st}) before its write was caught");
        }
        if write_begun(&d, "out.exr", &before) {
            child.kill().unwrap();
            break;
        }
        std::thread::sleep(Duration::from_millis(1));
    }
    let st = child.wait().unwrap();
    assert_eq!(st.code(), None, "killed by the signal, not finished: {st}");
    assert!(
        std::fs::read(d.join("out.exr")).unwrap() == old,
        "out.exr changed"
    );
    assert!(std::fs::read(d.join("out.png")).unwrap() == old_png);
    let img = RgbImage::read_exr(&d.join("out.exr")).unwrap();
    assert_eq!((img.width, img.height), (32, 16));
}

#[test]
fn identical_runs_write_identical_exr_bytes() {
    let d = tmpdir("bytes");
    std::fs::write(d.join("s.pbrt"), scene(256, 128, 2, "")).unwrap();
    let mut outs = Vec::new();
    for k in 0..2 {
        let out = format!("o{k}.exr");
        let args = [
            "render",
            "s.pbrt",
            "--quiet",
            "--nthreads",
            "4",
            "--outfile",
            &out,
        ];
        let o = candela(&args, &d);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        outs.push(std::fs::read(d.join(&out)).unwrap());
    }
    assert!(outs[0].len() > 256 * 128, "{} bytes", outs[0].len());
    assert!(outs[0] == outs[1], "the two EXR files differ");
}

#[test]
fn progress_is_plain_lines_when_stderr_is_not_a_terminal() {
    let d = tmpdir("progress");
    std::fs::write(d.join("s.pbrt"), scene(32, 16, 4, "")).unwrap();
    // `output()` gives the child a pipe for stderr, as a CI log would.
    let o = candela(&["render", "s.pbrt", "--outfile", "o.exr"], &d);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    let line = err
        .lines()
        .find(|l| l.contains("%, ETA") && l.contains("pass "))
        .unwrap_or_else(|| panic!("no progress line in\n{err}"));
    assert!(line.starts_with("candela: "), "{line}");
    assert!(
        !err.contains('\r') && !err.contains('\x1b'),
        "terminal codes: {err:?}"
    );
    let quiet = candela(&["render", "s.pbrt", "--quiet", "--outfile", "o.exr"], &d);
    assert!(!String::from_utf8_lossy(&quiet.stderr).contains("%, ETA"));
}

/// Issue 11: "SIGINT/SIGTERM/SIGHUP kill the render with nothing written".
/// SIGINT is tested with resuming in `passes.rs`; here the other two stop a
/// long render, which writes its image (of the passes done) and exits 130.
#[test]
fn sigterm_and_sighup_stop_the_render_and_write_its_image() {
    let d = tmpdir("signals");
    std::fs::write(d.join("s.pbrt"), scene(64, 32, 100_000, "")).unwrap();
    for sig in ["TERM", "HUP"] {
        let out = format!("{sig}.exr");
        let child = command(&["render", "s.pbrt", "--quiet", "--outfile", &out], &d)
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        std::thread::sleep(Duration::from_millis(1500));
        let kill = Command::new("kill")
            .args([&format!("-{sig}"), &child.id().to_string()])
            .status()
            .unwrap();
        assert!(kill.success());
        let o = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(130), "SIG{sig}: {err}");
        assert!(!err.contains("panicked"), "{err}");
        let img = RgbImage::read_exr(&d.join(&out)).unwrap();
        assert_eq!((img.width, img.height), (64, 32));
        assert!(
            img.pixels.iter().any(|p| p[0] > 0.0),
            "SIG{sig}: black image"
        );
    }
}
