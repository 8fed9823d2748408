//! Photometric units end to end through the CLI: `candela measure` against
//! closed forms (inverse-square law, E = πL under a uniform sky, an IES
//! file's intensity) and `candela info` reading back a flux given in lumens.
//!
//! Tolerances: each measured point must lie within 5σ of the closed form,
//! σ its own reported standard error (i.i.d. samples, fixed seed); the few
//! points per scene make the family-wise false-alarm rate < 10⁻⁵.

use std::path::{Path, PathBuf};
use std::process::Command;

mod common;

/// A fresh temporary directory for one test.
fn dir(name: &str) -> PathBuf {
    common::dir("photometry", name)
}

/// Runs `candela measure` (4000 samples, seed 7) and returns (E, stderr) per point.
fn measure(d: &Path, scene: &str, points: &str) -> Vec<(f64, f64)> {
    common::measure(d, scene, points, &["--samples", "4000", "--seed", "7"])
}

/// Asserts `got` is within 5σ of `want` (and that σ is sane).
fn within_5_sigma((got, se): (f64, f64), want: f64) {
    assert!(se < 0.01 * want, "stderr {se} too large for {want}");
    assert!(
        (got - want).abs() <= 5.0 * se.max(1e-9 * want),
        "E = {got} ± {se}, expected {want}"
    );
}

const POINTS: &str = "0 0 0 0 0 1\n# off axis\n1 0 0 0 0 1\n0 1.5 0 0 0 1\n";

/// I·cos θ/r² at the three POINTS for a source at (0, 0, 2).
fn inverse_square(i: f64) -> Vec<f64> {
    [(0.0, 0.0), (1.0, 0.0), (0.0, 1.5)]
        .iter()
        .map(|&(x, y): &(f64, f64)| {
            let r2 = x * x + y * y + 4.0;
            i * (2.0 / r2.sqrt()) / r2
        })
        .collect()
}

#[test]
fn point_light_in_lumens_follows_the_inverse_square_law_for_any_spectrum() {
    let d = dir("point");
    // T8: 1000 lm isotropic → 79.577 cd → 19.894 lx 2 m below, any spectrum;
    // an RGB colour too (pbrt-v4's normalisation by the RGB's illuminant
    // alone would give Y(rgb) = 0.40 of it for this orange).
    for spectrum in [
        "\"blackbody I\" 2856",
        "\"spectrum I\" \"stdillum-D65\"",
        "\"rgb I\" [0.9 0.3 0.1]",
        "",
    ] {
        let scene = format!(
            "LookAt 0 0 5 0 0 0 0 1 0\nCamera \"perspective\"\nWorldBegin\n\
             LightSource \"point\" \"float lumens\" 1000 {spectrum} \"point3 from\" [0 0 2]\n"
        );
        let got = measure(&d, &scene, POINTS);
        let want = inverse_square(1000.0 / (4.0 * std::f64::consts::PI));
        assert!((want[0] - 19.894).abs() < 1e-3);
        for (g, w) in got.into_iter().zip(want) {
            within_5_sigma(g, w);
        }
    }
}

#[test]
fn ies_goniometric_light_gives_its_tabulated_candela() {
    let d = dir("ies");
    // I(V) = 100 + 50·V/90 cd for V ≤ 90°, linear between the tabulated
    // angles, so the bilinear web reproduces it exactly; nadir along −z.
    std::fs::write(
        d.join("t.ies"),
        "IESNA:LM-63-2002\n[TEST] linear\nTILT=NONE\n1 -1 1 3 1 1 1 0 0 0\n1 1 0\n0 90 180\n0\n100 150 0\n",
    )
    .unwrap();
    // The file is in candela: an RGB `I` sets the colour only.
    let scene = "LookAt 0 0 5 0 0 0 0 1 0\nCamera \"perspective\"\nWorldBegin\n\
                 LightSource \"goniometric\" \"string filename\" \"t.ies\" \"rgb I\" [0.3 0.6 0.9] \"point3 from\" [0 0 2] \"point3 to\" [0 0 0]\n";
    let got = measure(&d, scene, POINTS);
    for ((x, y), g) in [(0.0f64, 0.0f64), (1.0, 0.0), (0.0, 1.5)]
        .into_iter()
        .zip(got)
    {
        let r2 = x * x + y * y + 4.0;
        let v = (x.hypot(y) / 2.0).atan().to_degrees();
        let i = 100.0 + 50.0 * v / 90.0;
        within_5_sigma(g, i * (2.0 / r2.sqrt()) / r2);
    }
}

#[test]
fn uniform_sky_in_luminance_gives_pi_l() {
    let d = dir("sky");
    for colour in ["", "\"rgb L\" [0.2 0.5 0.9]"] {
        let scene = format!(
            "LookAt 0 0 5 0 0 0 0 1 0\nCamera \"perspective\"\nWorldBegin\n\
             LightSource \"infinite\" \"float luminance\" 100 {colour}\n"
        );
        for g in measure(&d, &scene, POINTS) {
            within_5_sigma(g, std::f64::consts::PI * 100.0);
        }
    }
}

#[test]
fn a_small_luminaire_is_found_by_light_sampling() {
    // A Lambertian disk of radius R and luminance L, parallel to the sensor
    // at height h on its axis: E = πL·R²/(h² + R²) [the disk's form factor].
    // It subtends 0.25 % of the cosine-weighted hemisphere, so cosine
    // sampling alone would hit it in ~10 of 4000 samples (σ ≈ 30 %); the
    // 1 % bound on σ of `within_5_sigma` needs the light samples.
    let d = dir("disk");
    let (l, r, h) = (1000.0, 0.1, 2.0);
    let want = std::f64::consts::PI * l * r * r / (h * h + r * r);
    // A blackbody, and an RGB colour (whose luminance must not scale the
    // requested cd/m² by Y(rgb) = 0.46, as pbrt-v4's normalisation would).
    for colour in ["\"blackbody L\" 3000", "\"rgb L\" [0.2 0.5 0.9]"] {
        let scene = format!(
            "LookAt 0 0 5 0 0 0 0 1 0\nCamera \"perspective\"\nWorldBegin\n\
             AttributeBegin\nTranslate 0 0 2\n\
             AreaLightSource \"diffuse\" \"float luminance\" 1000 {colour} \"bool twosided\" true\n\
             Shape \"disk\" \"float radius\" 0.1\nAttributeEnd\n"
        );
        let got = measure(&d, &scene, "0 0 0 0 0 1\n");
        eprintln!(
            "disk {colour}: {:.4} ± {:.4} lx (expected {want:.4})",
            got[0].0, got[0].1
        );
        within_5_sigma(got[0], want);
    }
}

#[test]
fn info_reads_back_a_flux_given_in_lumens() {
    let d = dir("info");
    let scene = "LookAt 0 0 5 0 0 0 0 1 0\nCamera \"perspective\"\nWorldBegin\n\
                 AttributeBegin\nAreaLightSource \"diffuse\" \"float lumens\" 500 \"blackbody L\" 4000\n\
                 Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 1 3 0 0 1 0] \"integer indices\" [0 1 2 0 2 3]\n\
                 AttributeEnd\n";
    std::fs::write(d.join("s.pbrt"), scene).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_candela"))
        .args(["info", "s.pbrt"])
        .current_dir(&d)
        .output()
        .unwrap();
    let text = String::from_utf8(out.stdout).unwrap();
    let line = text
        .lines()
        .find(|l| l.contains("flux      total"))
        .unwrap();
    let lm: f64 = line
        .split(',')
        .nth(1)
        .unwrap()
        .trim()
        .trim_end_matches(" lm")
        .parse()
        .unwrap();
    assert!((lm - 500.0).abs() < 0.05, "{line}");
}

/// An IES LM-63 type C file with vertical angles 0, 90, 180 and the given
/// horizontal angles and one candela column per horizontal plane.
fn ies_file(h: &[f64], planes: &[[f64; 3]]) -> String {
    let join = |v: &[f64]| {
        v.iter()
            .map(|x| x.to_string())
            .collect::<Vec<_>>()
            .join(" ")
    };
    let values: Vec<String> = planes.iter().map(|p| join(p)).collect();
    format!(
        "IESNA:LM-63-2002\n[TEST] encodings\nTILT=NONE\n1 -1 1 3 {} 1 1 0 0 0\n1 1 0\n0 90 180\n{}\n{}\n",
        h.len(),
        join(h),
        values.join("\n")
    )
}

/// (flux \[lm\] from `candela info`, E per POINTS_IES) for an IES file.
fn ies_light(d: &PathBuf, text: &str) -> (f64, Vec<(f64, f64)>) {
    std::fs::write(d.join("t.ies"), text).unwrap();
    let scene = "LookAt 0 0 5 0 0 0 0 1 0\nCamera \"perspective\"\nWorldBegin\n\
                 LightSource \"goniometric\" \"string filename\" \"t.ies\" \"point3 from\" [0 0 2] \"point3 to\" [0 0 0]\n";
    let e = measure(d, scene, POINTS_IES);
    let out = Command::new(env!("CARGO_BIN_EXE_candela"))
        .args(["info", "s.pbrt"])
        .current_dir(d)
        .output()
        .unwrap();
    let text = String::from_utf8(out.stdout).unwrap();
    let line = text
        .lines()
        .find(|l| l.contains("flux      total"))
        .unwrap();
    let lm = line
        .split(',')
        .nth(1)
        .unwrap()
        .trim()
        .trim_end_matches(" lm");
    (lm.parse().unwrap(), e)
}

/// Floor points 2 m below the luminaire at horizontal angles 0°, 90°, 45°
/// and 122° (folds to 58° in a quadrant-symmetric light).
const POINTS_IES: &str = "0 0 0 0 0 1\n1 0 0 0 0 1\n0 1.5 0 0 0 1\n1 1 0 0 0 1\n-0.5 0.8 0 0 0 1\n";

#[test]
fn ies_symmetry_encodings_give_the_same_light_and_flux() {
    // I(V, H) = 100 + (c(H) − 100)·V/90° for V ≤ 90°, c(H)·(180° − V)/90°
    // beyond, with c linear in the horizontal angle folded into [0°, 90°]
    // (c = 150 at 0°, 210 at 90°): bilinear in the angles, so the web is
    // exact and E = I·cos θ/r² at each point. Its flux
    // Φ = ∫₀^{2π} [100(1 − 2/π) + c(H)·4/π] dH = 200π − 400 + 8·mean(c);
    // the axial light (c = 150 everywhere) the same with mean(c) = 150.
    let d = dir("encodings");
    let axial = [150.0; 5];
    let quad = [150.0, 210.0, 150.0, 210.0, 150.0];
    let col = |c: f64| [100.0, c, 0.0];
    let all: [&[f64]; 4] = [
        &[0.0],
        &[0.0, 90.0],
        &[0.0, 90.0, 180.0],
        &[0.0, 90.0, 180.0, 270.0, 360.0],
    ];
    let pi = std::f64::consts::PI;
    for (c, mean_c, encodings) in [(axial, 150.0, &all[..]), (quad, 180.0, &all[1..])] {
        let flux = 200.0 * pi - 400.0 + 8.0 * mean_c;
        for h in encodings {
            let planes: Vec<[f64; 3]> = c[..h.len()].iter().map(|&c| col(c)).collect();
            let (lm, got) = ies_light(&d, &ies_file(h, &planes));
            assert!(
                (lm - flux).abs() < 1e-3 * flux,
                "{h:?}: {lm} lm, expected {flux}"
            );
            let pts = [
                (0.0f64, 0.0f64),
                (1.0, 0.0),
                (0.0, 1.5),
                (1.0, 1.0),
                (-0.5, 0.8),
            ];
            for ((x, y), g) in pts.into_iter().zip(got) {
                let r2 = x * x + y * y + 4.0;
                let v = (x.hypot(y) / 2.0).atan().to_degrees();
                let hf = y.abs().atan2(x.abs()).to_degrees();
                let ch = if mean_c > 150.0 {
                    150.0 + 60.0 * hf / 90.0
                } else {
                    150.0
                };
                let i = 100.0 + (ch - 100.0) * v / 90.0;
                within_5_sigma(g, i * (2.0 / r2.sqrt()) / r2);
            }
        }
    }
}
