//! The BVH light sampler in a render: 64 small one-sided disk lights of
//! varied power facing a diffuse floor (the camera, above, sees their dark
//! backs, so all the light it sees comes through light sampling), rendered by the path tracer choosing lights
//! with the BVH sampler and with the power sampler. Both are unbiased, so
//! the per-block means of K independent renders must agree (Welch's t-test
//! per 8×8 block at family level α = 0.01, Šidák-corrected: the shared
//! block statistics of `common::stats`); the BVH sampler, which picks the
//! lights near each shading point, must also give the lower variance.

mod common;

use candela_core::build::Overrides;
use common::{seeded_block_means, stats};

const RES: usize = 32;
const K: usize = 8;

/// The scene text with `"string lightsampler"` set to `sampler`.
fn scene(sampler: &str) -> String {
    let mut s = format!(
        r#"LookAt 0 7 0  0 0 0  0 0 1
Camera "perspective" "float fov" 70
Sampler "independent" "integer pixelsamples" 32
Film "rgb" "integer xresolution" {RES} "integer yresolution" {RES} "string filename" "bvh.exr"
Integrator "path" "integer maxdepth" 1 "string lightsampler" "{sampler}"
WorldBegin
Material "diffuse" "rgb reflectance" [0.6 0.6 0.6]
Shape "trianglemesh" "point3 P" [-5 0 -5  5 0 -5  5 0 5  -5 0 5] "integer indices" [0 1 2 0 2 3]
"#
    );
    // An 8×8 grid at heights 0.15–0.6, radiance 2–60 (a fixed pattern),
    // facing down (Rotate takes the disk's +z to −y).
    for k in 0..64 {
        let (i, j) = ((k % 8) as f32, (k / 8) as f32);
        let h = 0.15 + 0.45 * ((k * 37 % 64) as f32 / 63.0);
        let l = 2.0 + 58.0 * ((k * 11 % 64) as f32 / 63.0);
        s += &format!(
            "AttributeBegin\n AreaLightSource \"diffuse\" \"rgb L\" [{l} {l} {l}]\n Translate {} {h} {}\n Rotate 90 1 0 0\n Shape \"disk\" \"float radius\" 0.2\nAttributeEnd\n",
            -4.2 + 1.2 * i,
            -4.2 + 1.2 * j
        );
    }
    s
}

/// Block means of K renders with seeds 100…, as `[block][render]`.
fn blocks(sampler: &str) -> Vec<Vec<f64>> {
    seeded_block_means(&scene(sampler), &Overrides::default(), 100, K)
}

#[test]
fn bvh_and_power_light_sampling_agree_and_bvh_has_less_variance() {
    let bvh = blocks("bvh");
    let power = blocks("power");
    stats::assert_blocks_agree(&bvh, &power, "path + bvh vs path + power");
    let var = |b: &[Vec<f64>]| b.iter().map(|x| stats::mean_var(x).1).sum::<f64>();
    let (vb, vp) = (var(&bvh), var(&power));
    assert!(vb < vp, "block variance: bvh {vb:.3e} vs power {vp:.3e}");
}
