//! The walker's roulette, measured on light subpaths.

use super::*;
use crate::build::{build, Overrides};
use crate::sampling::StreamRng;
use std::path::Path;

/// A closed grey box lit by a quad light of radiance `l`.
fn grey_box(l: f32) -> crate::build::RenderSetup {
    let text = format!(
        r#"LookAt 0 1 -0.9  0 1 0  0 1 0
Camera "perspective" "float fov" [60]
Film "rgb" "integer xresolution" [8] "integer yresolution" [8]
WorldBegin
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [{l} {l} {l}]
  Shape "trianglemesh" "point3 P" [-0.3 1.99 -0.3  0.3 1.99 -0.3  0.3 1.99 0.3  -0.3 1.99 0.3]
"integer indices" [0 2 1 0 3 2]
AttributeEnd
Material "diffuse" "rgb reflectance" [0.7 0.7 0.7]
Shape "trianglemesh" "point3 P" [-1 0 -1  1 0 -1  1 0 1  -1 0 1  -1 2 -1  1 2 -1  1 2 1  -1 2 1]
  "integer indices" [0 1 2 0 2 3  4 6 5 4 7 6  0 3 7 0 7 4  1 5 6 1 6 2  3 2 6 3 6 7  0 4 5 0 5 1]
"#
    );
    let desc = candela_scene::parse_str(&text, Path::new("roulette.pbrt")).expect("parses");
    build(&desc, &Overrides::default()).expect("builds")
}

struct Count(u64);

impl<R: PathRng + ?Sized> Visitor<R> for Count {
    fn vertex(
        &mut self,
        _: &Vertex,
        _: &SurfaceInteraction,
        _: &mut SampledWavelengths,
        _: &mut R,
    ) -> Flow {
        self.0 += 1;
        Flow::Continue
    }
}

/// Vertices of `n` light subpaths walked with BDPT's roulette.
fn light_vertices(l: f32, n: u64) -> (u64, f32) {
    let rs = grey_box(l);
    let w = Walk {
        mode: TransportMode::Importance,
        max_depth: 1000,
        roulette: Some(Roulette::Bidirectional),
        regularize: false,
        dispersion: Dispersion::Fold,
    };
    let mut count = Count(0);
    let mut beta0 = 0.0;
    for i in 0..n {
        let mut rng = StreamRng::new(7, 0, i);
        let mut lambda = SampledWavelengths::sample_visible(0.37);
        let Some(ls) = start_light_subpath(&rs.scene, &lambda, &mut rng, Some(0.0)) else {
            continue;
        };
        beta0 = ls.start.beta.max_component();
        walk(&rs.scene, &mut lambda, &mut rng, &w, ls.start, &mut count);
    }
    (count.0, beta0)
}

/// Roulette weighs the share of its starting power a light subpath still
/// carries, so how long light subpaths are does not depend on the units
/// of emission. Under the old rule, which played the throughput itself
/// against one, the subpaths of the box lit by L = 1, starting with
/// β ≈ 0.011 (the spectral units of an RGB illuminant), were nearly all
/// ended at the fourth vertex, and those of the box lit by L = 1000
/// (β ≈ 11) not before their power fell below 1: the counts differed.
#[test]
fn light_subpath_lengths_do_not_depend_on_the_lights_units() {
    let (dim, beta_dim) = light_vertices(1.0, 2000);
    let (bright, beta_bright) = light_vertices(1000.0, 2000);
    assert!(
        beta_dim < 0.1 && beta_bright > 5.0,
        "{beta_dim} {beta_bright}"
    );
    assert_eq!(dim, bright, "same random numbers, same lengths");
    // In a closed box of albedo 0.7 a subpath has 1 / (1 − 0.7) ≈ 3.3
    // vertices with no roulette and more than 3 with roulette from the
    // fourth on: not cut short.
    let mean = dim as f64 / 2000.0;
    assert!(mean > 3.0, "mean light subpath length {mean}");
}
