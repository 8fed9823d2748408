//! Variance of the image mean per channel over seeds for a photon
//! estimator on the bundled Cornell box, to compare wavelength-group counts
//! (`integrator::wavelengths`).
//!
//! `wavelength_variance INTEGRATOR PARAMS SPP SEEDS [GROUPS]`, e.g.
//! `wavelength_variance sppm '"integer photonsperiteration" [500000]' 1 16 1`.
//! Without GROUPS the parameter is not written (the integrator's default).
//! Prints the mean, the standard deviation over seeds of the image mean per
//! channel, and the mean per-pixel variance across seeds (pixel noise).

use candela_core::build::{build, Overrides};
use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 5 {
        eprintln!("usage: wavelength_variance INTEGRATOR PARAMS SPP SEEDS [GROUPS]");
        std::process::exit(2);
    }
    let spp: u32 = args[3].parse().unwrap_or(1);
    let seeds: u64 = args[4].parse().unwrap_or(16);
    let groups = args
        .get(5)
        .map(|g| format!(" \"integer wavelengthgroups\" [{g}]"))
        .unwrap_or_default();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box");
    let path = root.join("scene.pbrt");
    let text = std::fs::read_to_string(&path).unwrap_or_default();
    let line = format!(
        "Integrator \"{}\" \"integer maxdepth\" [100] {}{groups}",
        args[1], args[2]
    );
    let text = text.replace("Integrator \"path\" \"integer maxdepth\" [100] ", &line);
    let mut means = Vec::new();
    let mut pixels: Vec<Vec<[f32; 3]>> = Vec::new();
    for seed in 0..seeds {
        let Ok(desc) = candela_scene::parse_str(&text, &path) else {
            eprintln!("scene does not parse");
            std::process::exit(1);
        };
        let ov = Overrides {
            spp: Some(spp),
            seed: Some(seed),
            ..Default::default()
        };
        let setup = match build(&desc, &ov) {
            Ok(s) => s,
            Err(e) => {
                eprintln!("{e}");
                std::process::exit(1);
            }
        };
        let (dev, _) = candela_core::render::render_all(&setup);
        let img = dev.rgb();
        means.push(img.channel_means());
        let (w, h) = (256, 256);
        pixels.push(
            (0..h)
                .flat_map(|y| (0..w).map(move |x| (x, y)))
                .map(|(x, y)| img.get(x, y))
                .collect(),
        );
        eprintln!("seed {seed}: {:?}", img.channel_means());
    }
    let n = means.len() as f64;
    for c in 0..3 {
        let m = means.iter().map(|v| v[c]).sum::<f64>() / n;
        let var = means.iter().map(|v| (v[c] - m).powi(2)).sum::<f64>() / (n - 1.0);
        let px = pixels[0].len();
        let pix_var = (0..px)
            .map(|i| {
                let pm = pixels.iter().map(|p| f64::from(p[i][c])).sum::<f64>() / n;
                pixels
                    .iter()
                    .map(|p| (f64::from(p[i][c]) - pm).powi(2))
                    .sum::<f64>()
                    / (n - 1.0)
            })
            .sum::<f64>()
            / px as f64;
        println!(
            "channel {c}: mean {m:.5}  sd(image mean) {:.5} (rel {:.4})  mean pixel var {pix_var:.6}",
            var.sqrt(),
            var.sqrt() / m
        );
    }
}
