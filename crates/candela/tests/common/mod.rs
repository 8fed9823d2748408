//! Helpers shared by the CLI tests that run `candela measure`.

use std::path::{Path, PathBuf};
use std::process::Command;

/// A fresh temporary directory for one test, named `candela-{kind}-{name}-{pid}`.
pub fn dir(kind: &str, name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("candela-{kind}-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Writes `scene` and `points` into `d`, runs `candela measure` with `args`
/// and returns (E, stderr) per point, checking the CSV header.
pub fn measure(d: &Path, scene: &str, points: &str, args: &[&str]) -> Vec<(f64, f64)> {
    std::fs::write(d.join("s.pbrt"), scene).unwrap();
    std::fs::write(d.join("p.txt"), points).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_candela"))
        .args(["measure", "s.pbrt", "--points", "p.txt"])
        .args(args)
        .current_dir(d)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("x,y,z,nx,ny,nz,illuminance_lx,stderr_lx")
    );
    lines
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            (v[6], v[7])
        })
        .collect()
}
