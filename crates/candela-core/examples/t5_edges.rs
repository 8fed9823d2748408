//! validation.md's T5 cube through a photon estimator: the mean of the back
//! face (seen whole by an orthographic camera) against the closed form, and
//! the outer 10 % band of the face against the path tracer, for issue 16
//! (photon density estimation at edges and corners).
//!
//! `t5_edges INTEGRATOR RADIUS ITERATIONS PHOTONS [SEED]`, e.g.
//! `t5_edges sppm 1 256 100000`. The cube has side 10, ρ = 2/3 (a flat
//! spectrum), a centred isotropic point light of I = 75 (rgb), so the mean
//! face radiance is ρΦ/(πS(1 − ρ)) = 1; maxdepth 1000. `photonmap` reads
//! the radius as `maxradius` with a disk kernel and a lookup large enough
//! that the radius is fixed. `path` renders the reference (ITERATIONS spp).

use candela_core::build::{build, Overrides};
use std::path::Path;

/// The T5 cube scene for `integrator` at gather radius `radius`.
fn scene(integrator: &str, radius: f32, photons: u64, res: u32) -> String {
    let params = match integrator {
        "photonmap" => format!(
            "\"float maxradius\" [{radius}] \"string kernel\" \"disk\" \"integer lookup\" [100000] \"integer photons\" [{photons}] \"integer causticphotons\" [0] \"bool finalgather\" false"
        ),
        "path" => String::new(),
        _ => format!("\"float radius\" [{radius}] \"integer photonsperiteration\" [{photons}]"),
    };
    format!(
        r#"LookAt 0 0 0  0 0 1  0 1 0
Camera "orthographic" "float screenwindow" [-5 5 -5 5]
Film "rgb" "integer xresolution" [{res}] "integer yresolution" [{res}]
PixelFilter "box"
Sampler "independent"
Integrator "{integrator}" "integer maxdepth" [1000] {params}
WorldBegin
LightSource "point" "point3 from" [0 0 0] "rgb I" [75 75 75]
Material "diffuse" "spectrum reflectance" [300 0.6666667 800 0.6666667]
Shape "trianglemesh" "point3 P" [-5 -5 -5  5 -5 -5  5 5 -5  -5 5 -5  -5 -5 5  5 -5 5  5 5 5  -5 5 5]
  "integer indices" [0 2 1 0 3 2  4 5 6 4 6 7  0 1 5 0 5 4  3 7 6 3 6 2  0 4 7 0 7 3  1 2 6 1 6 5]
"#
    )
}

/// Mean of the green channel over the whole image and over its outer band.
fn means(img: &candela_core::image::RgbImage, res: usize) -> (f64, f64) {
    let band = res / 10;
    let (mut all, mut edge, mut n_edge) = (0.0, 0.0, 0usize);
    for y in 0..res {
        for x in 0..res {
            let v = img.get(x, y)[1] as f64;
            all += v;
            if x < band || y < band || x >= res - band || y >= res - band {
                edge += v;
                n_edge += 1;
            }
        }
    }
    (all / (res * res) as f64, edge / n_edge as f64)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 5 {
        eprintln!("usage: t5_edges INTEGRATOR RADIUS ITERATIONS PHOTONS [SEED]");
        std::process::exit(2);
    }
    let radius: f32 = args[2].parse().unwrap_or(1.0);
    let iterations: u32 = args[3].parse().unwrap_or(256);
    let photons: u64 = args[4].parse().unwrap_or(100_000);
    let seed: u64 = args.get(5).and_then(|s| s.parse().ok()).unwrap_or(1);
    let res = 40;
    let text = scene(&args[1], radius, photons, res as u32);
    let Ok(desc) = candela_scene::parse_str(&text, Path::new("t5.pbrt")) else {
        eprintln!("scene does not parse");
        std::process::exit(1);
    };
    let ov = Overrides {
        spp: Some(iterations),
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
    let (all, edge) = means(&dev.rgb(), res);
    println!(
        "{} r={radius} iterations={iterations} photons={photons}: face mean {all:.5} (closed form 1), outer band {edge:.5}",
        args[1]
    );
}
