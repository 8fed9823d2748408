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
#[allow(dead_code)] // not every test crate measures
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

/// T5's room (validation.md): `WorldBegin` and a closed cube [−2, 2]³ of
/// diffuse albedo `rho` around a 10 000 lm isotropic point light at its
/// centre (area-mean illuminance Φ/(S(1 − ρ)), S = 96 m²).
#[allow(dead_code)] // not every test crate builds rooms
pub fn t5_cube_world(rho: f64) -> String {
    let mut p = String::new();
    for i in 0..8 {
        let c = |b: i32| if i >> b & 1 == 1 { 2 } else { -2 };
        p += &format!("{} {} {} ", c(0), c(1), c(2));
    }
    // Faces x−, x+, y−, y+, z−, z+ as two triangles each.
    let idx = "0 2 6 0 6 4 1 5 7 1 7 3 0 4 5 0 5 1 2 3 7 2 7 6 0 1 3 0 3 2 4 6 7 4 7 5";
    format!(
        "WorldBegin\n\
         LightSource \"point\" \"float lumens\" 10000 \"point3 from\" [0 0 0]\n\
         Material \"diffuse\" \"spectrum reflectance\" [300 {rho} 800 {rho}]\n\
         Shape \"trianglemesh\" \"point3 P\" [{p}] \"integer indices\" [{idx}]\n"
    )
}

/// T5's area-mean illuminance Φ/(S(1 − ρ)) \[lx\] of [`t5_cube_world`].
#[allow(dead_code)]
pub fn t5(rho: f64) -> f64 {
    10_000.0 / (96.0 * (1.0 - rho))
}
