//! Issue 11: `candela render` of the bundled Cornell box with
//! `--integrator sppm` and no radius in the file runs in bounded memory and
//! converges to the path tracer, and pbrt-v4's radius 1, when written, is
//! refused under a memory limit with the parameter to change.
//!
//! Convergence is tested per 8×8 block as in candela-core's `agreement.rs`
//! (Welch's t-test on K independent renders per integrator, Šidák-corrected
//! for α = 0.01 over all blocks [Jung, Hanika & Dachsbacher, JCGT 2020]; its
//! helpers are shared). SPPM is consistent but biased at a finite radius;
//! the test allows no bias term, so it passes only while the kernel bias of
//! the default radius (3 pixel footprints, shrinking by pbrt-v4's α = 2/3)
//! after the iterations used stays below the per-block noise this test
//! resolves; a radius of 1 (29 % of the box) fails it at once. SPPM runs 32
//! iterations: after 8, block (22, 28) (floor in the short block's shadow,
//! by its base) is 19 % dark (3 × mean 0.0177 over seeds 1000–1005 against
//! 0.0218 from 1024 spp of the path tracer), which this test resolves
//! (p = 8e-6 to 1e-5 against the level 9.8e-6); after 32 it is 8 % bright
//! (0.0235), within the path tracer's 8-spp noise there.

#[path = "../../candela-core/tests/common/stats.rs"]
mod stats;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;

use candela_core::image::RgbImage;

/// Independent renders per integrator.
const K: u64 = 6;

fn cornell() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box/scene.pbrt")
}

fn tmpdir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("candela-sppm-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Peak resident memory (VmHWM) of process `pid` in KiB, if still readable.
fn peak_kib(pid: u32) -> Option<u64> {
    let s = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// Renders the Cornell box with `args` into `out`; returns the image and
/// the largest peak RSS seen while it ran (KiB; 0 where /proc is missing).
fn render(args: &[&str], out: &Path) -> (RgbImage, u64) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_candela"))
        .arg("render")
        .arg(cornell())
        .args(args)
        .args(["--quiet", "--outfile"])
        .arg(out)
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut peak = 0;
    while child.try_wait().unwrap().is_none() {
        peak = peak.max(peak_kib(child.id()).unwrap_or(0));
        std::thread::sleep(Duration::from_millis(5));
    }
    let o = child.wait_with_output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    (RgbImage::read_exr(out).unwrap(), peak)
}

/// Block means of K seeds of `args` (`[block][render]`) and the peak RSS.
fn blocks(d: &Path, args: &[&str]) -> (Vec<Vec<f64>>, u64) {
    let mut peak = 0;
    let renders: Vec<Vec<f64>> = (0..K)
        .map(|k| {
            let seed = (1000 + k).to_string();
            let mut a = args.to_vec();
            a.extend(["--seed", &seed]);
            let (img, p) = render(&a, &d.join(format!("r{k}.exr")));
            assert_eq!((img.width, img.height), (256, 256));
            peak = peak.max(p);
            stats::block_means(&img)
        })
        .collect();
    (stats::by_block(&renders), peak)
}

#[test]
fn sppm_without_a_radius_converges_to_the_path_tracer_in_bounded_memory() {
    let text = std::fs::read_to_string(cornell()).unwrap();
    let integrator = text.lines().find(|l| l.starts_with("Integrator")).unwrap();
    assert!(
        !integrator.contains("radius"),
        "the scene must not give a radius"
    );
    let d = tmpdir("agree");
    let (pt, _) = blocks(&d, &["--spp", "8"]);
    // The limit is the budget's: a run estimated above it is refused.
    let (sppm, peak) = blocks(
        &d,
        &[
            "--integrator",
            "sppm",
            "--spp",
            "32",
            "--memory-limit",
            "256M",
        ],
    );
    eprintln!("sppm peak RSS {:.1} MiB", peak as f64 / 1024.0);
    assert!(peak < 256 * 1024, "peak RSS {peak} KiB");
    stats::assert_blocks_agree(&pt, &sppm, "Cornell PT vs SPPM (default radius)");
}

#[test]
fn a_written_radius_of_one_is_refused_under_a_memory_limit_naming_it() {
    let text = std::fs::read_to_string(cornell()).unwrap();
    let line = "Integrator \"path\" \"integer maxdepth\" [100]";
    assert!(text.contains(line));
    let text = text.replace(
        line,
        "Integrator \"sppm\" \"integer maxdepth\" [100] \"float radius\" [1]",
    );
    let d = tmpdir("radius1");
    std::fs::write(d.join("s.pbrt"), &text).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_candela"))
        .args(["render", "s.pbrt", "--quiet", "--memory-limit", "1G"])
        .current_dir(&d)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    let at = text
        .lines()
        .position(|l| l.contains("\"float radius\""))
        .unwrap();
    let col = text
        .lines()
        .nth(at)
        .unwrap()
        .find("\"float radius\"")
        .unwrap()
        + 1;
    let want = format!(
        "candela: error: s.pbrt:{}:{col}: Integrator \"sppm\" \"radius\" needs about",
        at + 1
    );
    assert!(err.starts_with(&want), "{err}\nwanted: {want}");
    assert!(err.contains("over the --memory-limit of 1.0 GB"), "{err}");
    assert!(err.contains("lower \"radius\""), "{err}");
    assert!(!d.join("pbrt.exr").exists() && !d.join("cornell-box.exr").exists());
}
