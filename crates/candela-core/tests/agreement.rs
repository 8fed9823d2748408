//! Integrators agree (validation.md, "Integrators agree"): the path tracer,
//! the light tracer and BDPT render the same small Cornell box and an
//! off-centre sphere furnace, and every 8×8
//! block's mean is compared with Welch's t-test [Jung, Hanika & Dachsbacher,
//! JCGT 2020]. Each integrator renders K independent seeds, so every block
//! has K independent estimates per integrator; the test fails if any block's
//! two-sided p-value is below the Šidák-corrected α' for α = 0.01 over all
//! blocks. A bias of a few per cent in any region fails it.

mod common;

use candela_core::build::Overrides;
use candela_core::image::RgbImage;
use common::{render_str, stats};

const K: usize = 8;
const RES: usize = 32;

fn cornell_small() -> String {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/cornell-box/scene.pbrt"
    ))
    .expect("bundled scene");
    text.replace(
        "\"integer xresolution\" [256] \"integer yresolution\" [256]",
        "\"integer xresolution\" [32] \"integer yresolution\" [32]",
    )
    .replace("\"integer maxdepth\" [100]", "\"integer maxdepth\" [8]")
}

/// validation.md T4(b) off-centre: a point light at (0, 0, 0.5) inside a
/// diffuse sphere (ρ = 0.5, R = 1) seen from the centre, so radiance varies
/// over the image.
fn sphere_furnace() -> String {
    r#"LookAt 0 0 0  0 0.3 1  0 1 0
Camera "perspective" "float fov" [70]
Film "rgb" "integer xresolution" [32] "integer yresolution" [32]
PixelFilter "box"
Sampler "independent"
Integrator "path" "integer maxdepth" [50]
WorldBegin
LightSource "point" "point3 from" [0 0 0.5] "rgb I" [1 1 1]
Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]
ReverseOrientation
Shape "sphere" "float radius" [1]
"#
    .to_string()
}

/// Block means of K renders, `[block][render]`.
fn block_means(scene: &str, integrator: &str, spp: u32) -> Vec<Vec<f64>> {
    assert!(scene.contains("[32]"), "resolution override did not apply");
    let renders: Vec<Vec<f64>> = renders(scene, integrator, spp)
        .iter()
        .map(|img| {
            assert_eq!((img.width, img.height), (RES, RES));
            stats::block_means(img)
        })
        .collect();
    stats::by_block(&renders)
}

#[test]
fn student_t_p_values_match_tables() {
    // Two-sided critical values: t(10) = 2.228 at 0.05, t(5) = 4.032 at 0.01, t(30) = 2.750 at 0.01.
    for (t, df, p) in [(2.228, 10.0, 0.05), (4.032, 5.0, 0.01), (2.750, 30.0, 0.01)] {
        let got = stats::t_two_sided_p(t, df);
        assert!((got - p).abs() < 2e-4, "t={t} df={df}: {got}");
    }
}

/// Σ over blocks of `a`'s variance between renders over the same of `b`'s.
fn variance_ratio(a: &[Vec<f64>], b: &[Vec<f64>]) -> f64 {
    let var = |x: &[Vec<f64>]| x.iter().map(|r| stats::mean_var(r).1).sum::<f64>();
    var(a) / var(b)
}

/// Welch's t-test per block between two integrators' K renders.
fn assert_agree(a: &[Vec<f64>], b: &[Vec<f64>], what: &str) {
    stats::assert_blocks_agree(a, b, what);
}

#[test]
fn path_light_and_bidirectional_tracers_agree_on_the_cornell_box() {
    let scene = cornell_small();
    let pt = block_means(&scene, "path", 64);
    let lt = block_means(&scene, "lightpath", 64);
    let bd = block_means(&scene, "bdpt", 16);
    assert_agree(&pt, &lt, "Cornell PT vs LT");
    assert_agree(&pt, &bd, "Cornell PT vs BDPT");
    assert_agree(&lt, &bd, "Cornell LT vs BDPT");
}

#[test]
fn path_light_and_bidirectional_tracers_agree_in_the_sphere_furnace() {
    let scene = sphere_furnace();
    let pt = block_means(&scene, "path", 16);
    let lt = block_means(&scene, "lightpath", 16);
    let bd = block_means(&scene, "bdpt", 8);
    assert_agree(&pt, &lt, "furnace PT vs LT");
    assert_agree(&pt, &bd, "furnace PT vs BDPT");
    assert_agree(&lt, &bd, "furnace LT vs BDPT");
}

#[test]
fn photon_integrators_agree_with_the_path_tracer_on_the_cornell_box() {
    // SPPM and PPM are consistent but biased at finite radius; with a
    // 0.02 initial radius (1 % of the box), 32 iterations of 20 000 photons
    // the kernel bias is below the per-block noise this test resolves (a 6 %
    // error in the photon term fails it).
    let scene = cornell_small().replace(
        "Integrator \"path\" \"integer maxdepth\" [8]",
        "Integrator \"sppm\" \"integer maxdepth\" [8] \"float radius\" [0.02] \"integer photonsperiteration\" [20000]",
    );
    assert!(scene.contains("\"float radius\" [0.02]"));
    let pt = block_means(&scene, "path", 64);
    let sppm = block_means(&scene, "sppm", 32);
    let ppm = block_means(&scene, "ppm", 32);
    assert_agree(&pt, &sppm, "Cornell PT vs SPPM");
    assert_agree(&pt, &ppm, "Cornell PT vs PPM");
}

/// A black square sliding under a point light casts a moving shadow on a
/// white floor: light subpaths must see the square at their path's time, so
/// the light tracer's and BDPT's shadows blur exactly like the path tracer's
/// (a light tracer whose paths all ran at time 0 leaves a sharp shadow at the
/// start position and fails here). vcm too, by connections and merges.
#[test]
fn path_light_and_bidirectional_tracers_agree_on_a_moving_shadow() {
    let scene = r#"LookAt 0 -4 6  0 0 0  0 0 1
Camera "perspective" "float fov" [45]
Film "rgb" "integer xresolution" [32] "integer yresolution" [32]
PixelFilter "box"
Sampler "independent"
Integrator "path" "integer maxdepth" [3]
WorldBegin
LightSource "point" "point3 from" [0 0 4] "rgb I" [20 20 20]
Material "diffuse" "rgb reflectance" [0.8 0.8 0.8]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
    "point3 P" [-3 -3 0  3 -3 0  3 3 0  -3 3 0]
AttributeBegin
  Material "diffuse" "rgb reflectance" [0 0 0]
  Translate -1 0 2
  ActiveTransform EndTime
  Translate 2 0 0
  ActiveTransform All
  Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
      "point3 P" [-0.5 -0.5 0  0.5 -0.5 0  0.5 0.5 0  -0.5 0.5 0]
AttributeEnd
"#;
    let pt = block_means(scene, "path", 16);
    let lt = block_means(scene, "lightpath", 16);
    let bd = block_means(scene, "bdpt", 8);
    // vcm draws one shutter time per iteration for all its subpaths; in
    // its mode bpm (merges alone) the floor's shadow is wherever the
    // iteration's photons were blocked, so light subpaths traced at
    // another time than the camera's (time 0: tried once) fail it.
    let vc = block_means(scene, "vcm", 16);
    let bpm = scene.replace(
        "Integrator \"path\" \"integer maxdepth\" [3]",
        "Integrator \"vcm\" \"string mode\" \"bpm\" \"float radius\" [0.05] \"integer maxdepth\" [3]",
    );
    assert!(bpm.contains("bpm"));
    let vm = block_means(&bpm, "vcm", 16);
    assert_agree(&pt, &lt, "moving shadow PT vs LT");
    assert_agree(&pt, &bd, "moving shadow PT vs BDPT");
    assert_agree(&pt, &vc, "moving shadow PT vs VCM");
    assert_agree(&pt, &vm, "moving shadow PT vs VCM mode bpm");
}

/// A coated floor with a near-mirror coat (pbrt-v4's caustic-glass floor:
/// roughness 0.0104) under a uniform sky. Photons never land here after a
/// bounce, so SPPM's image is its camera pass's direct light alone; it must
/// agree with the path tracer per block, and, since both combine light and
/// BSDF sampling by MIS, be about as noisy at equal samples. Light sampling
/// alone finds the sky's reflection in the coat's narrow lobe rarely: that
/// camera pass had 169× the path tracer's block variance here (with MIS:
/// 1.05×; it was the salt noise on the distant floor of caustic-glass), so
/// the bound of 3× fails it.
#[test]
fn sppm_direct_light_on_a_glossy_floor_under_a_sky_matches_the_path_tracer_and_its_noise() {
    let scene = r#"LookAt 0 0.6 -3  0 0 2  0 1 0
Camera "perspective" "float fov" [40]
Film "rgb" "integer xresolution" [32] "integer yresolution" [32]
PixelFilter "box"
Sampler "independent"
Integrator "sppm" "integer maxdepth" [5] "float radius" [0.05] "integer photonsperiteration" [1000]
WorldBegin
LightSource "infinite" "rgb L" [1 1 1]
Material "coateddiffuse" "rgb reflectance" [0.5 0.5 0.5] "float roughness" [0.0104]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
    "point3 P" [-50 0 -50  50 0 -50  50 0 50  -50 0 50]
"#;
    let pt = block_means(scene, "path", 16);
    let sppm = block_means(scene, "sppm", 16);
    assert_agree(&pt, &sppm, "glossy floor PT vs SPPM");
    let ratio = variance_ratio(&sppm, &pt);
    assert!(
        ratio < 3.0,
        "SPPM block variance {ratio:.2}× the path tracer's"
    );
}

/// A spot lights only a wall; the floor before it receives the wall's
/// bounce alone, so its image is SPPM's photon estimate. Visible points seen
/// directly gather the photons of every wavelength group (sppm/passes.rs), so
/// four groups must agree with one per block and be about as noisy (1.00×
/// with seeds 100–107): when a point gathered only its own group's quarter
/// of the photons, the block variance was 2.65× that of one group, and the
/// bound of 1.6× fails it. The same holds for points seen through glass: a
/// dielectric's Fresnel terms are
/// the same at every wavelength, so β is too. The camera sits at the centre of
/// a glass sphere, so its rays leave the glass unbent and the image is the
/// same but for the Fresnel loss, every visible point one refraction behind
/// (0.91×; 2.06× while such points gathered their own group's photons only).
#[test]
fn sppm_points_seen_directly_or_through_glass_gather_every_wavelength_groups_photons() {
    let lens = "Material \"dielectric\" \"float eta\" [1.5]\nTranslate 0 2 -2\nShape \"sphere\" \"float radius\" [0.3]";
    for lens in ["", lens] {
        groups_agree(lens);
    }
}

fn groups_agree(lens: &str) {
    let scene = |groups: u32| {
        format!(
            r#"LookAt 0 2 -2  0 0 0.5  0 1 0
Camera "perspective" "float fov" [50]
Film "rgb" "integer xresolution" [32] "integer yresolution" [32]
PixelFilter "box"
Sampler "independent"
Integrator "sppm" "integer maxdepth" [5] "float radius" [0.05] "integer photonsperiteration" [2000]
    "integer wavelengthgroups" [{groups}]
WorldBegin
LightSource "spot" "point3 from" [0 1.5 -1] "point3 to" [0 1 3] "float coneangle" [15] "rgb I" [20 20 20]
Material "diffuse" "rgb reflectance" [0.8 0.8 0.8]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
    "point3 P" [-3 0 -3  3 0 -3  3 0 3  -3 0 3]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
    "point3 P" [-3 0 2  3 0 2  3 3 2  -3 3 2]
{lens}
"#
        )
    };
    let one = block_means(&scene(1), "sppm", 16);
    let four = block_means(&scene(4), "sppm", 16);
    assert_agree(&one, &four, "SPPM one vs four wavelength groups");
    let ratio = variance_ratio(&four, &one);
    assert!(
        ratio < 1.6,
        "four groups' block variance {ratio:.2}× one group's ({lens})"
    );
}

/// Shading normals tilted 22° from two diffuse faces' geometric normals
/// make the BSDF non-symmetric, and light transport then needs the adjoint
/// BSDF: light subpaths scatter with Veach's correction
/// |ωo·ns||ωi·ng| / (|ωo·ng||ωi·ns|) [Veach 1997, eq. 5.19], which pbrt-v4
/// leaves out. With it the light tracer and BDPT agree with the path tracer
/// on the light that bounced once; without it they do not.
#[test]
fn light_subpaths_scatter_with_the_adjoint_bsdf_of_tilted_shading_normals() {
    let scene = r#"LookAt -1.5 1.2 -1.5  0.5 0.3 0.5  0 1 0
Camera "perspective" "float fov" [60]
Film "rgb" "integer xresolution" [32] "integer yresolution" [32]
PixelFilter "box"
Sampler "independent"
Integrator "path" "integer maxdepth" [2]
WorldBegin
LightSource "point" "point3 from" [-0.5 1.5 -0.5] "rgb I" [3 3 3]
Material "diffuse" "rgb reflectance" [0.8 0.8 0.8]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
    "point3 P" [-3 0 -3  1 0 -3  1 0 3  -3 0 3]
    "normal N" [0.4 1 0  0.4 1 0  0.4 1 0  0.4 1 0]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
    "point3 P" [1 0 -3  1 0 3  1 3 3  1 3 -3]
    "normal N" [-1 0.4 0  -1 0.4 0  -1 0.4 0  -1 0.4 0]
"#;
    let pt = block_means(scene, "path", 64);
    let lt = block_means(scene, "lightpath", 64);
    let bd = block_means(scene, "bdpt", 16);
    assert_agree(&pt, &lt, "tilted normals PT vs LT");
    assert_agree(&pt, &bd, "tilted normals PT vs BDPT");
}

/// BDPT's variance-aware light-tracing weights (its default; module doc of
/// `integrator::lt_weights`) against pbrt-v4's weights by density, on the
/// small Cornell box's direct light alone (maxdepth 1), where next-event
/// estimation is nearly noise-free on the diffuse walls and light tracing's
/// density share of the light is mostly its variance. Both are unbiased,
/// so every block agrees (Welch, as above); the factors the pilot passes
/// measure must cut the pixels' variance between renders. The statistic is
/// Σ_pixels s²/(m² + 0.01) over K renders, the regularised relative variance
/// of `candela diff`'s relMSE (the light's own bright pixels, equally noisy
/// either way, would dominate absolute variances; unregularised, the few
/// dark penumbra pixels, whose relative noise the factors of their lit
/// blocks raise a little, would). Each pixel's s² has K − 1 = 7 degrees of
/// freedom, a relative standard deviation of √(2/7) ≈ 0.53, so the sum over
/// the ~1000 pixels has about 0.025 and the ratio of two sums about 0.035.
/// Measured 0.63; the bound 0.8 is some 7σ above that and 6σ below 1
/// (factors that change nothing).
#[test]
fn bdpt_variance_aware_light_tracing_weights_lower_direct_light_noise_without_bias() {
    let direct = cornell_small().replace("\"integer maxdepth\" [8]", "\"integer maxdepth\" [1]");
    let density = direct.replace(
        "Integrator \"path\"",
        "Integrator \"bdpt\" \"string ltweights\" \"density\"",
    );
    assert_ne!(density, direct, "the integrator line did not change");
    let var = renders(&direct, "bdpt", 16);
    let den = renders(&density, "bdpt", 16);
    let blocks = |r: &[RgbImage]| -> Vec<Vec<f64>> {
        stats::by_block(&r.iter().map(stats::block_means).collect::<Vec<_>>())
    };
    assert_agree(
        &blocks(&var),
        &blocks(&den),
        "BDPT variance vs density weights",
    );
    let ratio = relative_pixel_variance(&var) / relative_pixel_variance(&den);
    assert!(ratio < 0.8, "pixel variance {ratio:.3}× density weights'");
}

/// K renders of `scene` by `integrator`, seeds 100 … 100 + K − 1.
fn renders(scene: &str, integrator: &str, spp: u32) -> Vec<RgbImage> {
    (0..K)
        .map(|k| {
            let ov = Overrides {
                spp: Some(spp),
                seed: Some(100 + k as u64),
                integrator: Some(integrator.into()),
                ..Default::default()
            };
            render_str(scene, &ov)
        })
        .collect()
}

/// Σ over pixels of the variance between renders over the squared mean
/// plus 0.01 (channel means).
fn relative_pixel_variance(renders: &[RgbImage]) -> f64 {
    let n = renders[0].pixels.len();
    (0..n)
        .map(|i| {
            let v: Vec<f64> = renders
                .iter()
                .map(|r| r.pixels[i].iter().map(|&c| c as f64).sum::<f64>() / 3.0)
                .collect();
            let (m, s2) = stats::mean_var(&v);
            s2 / (m * m + 0.01)
        })
        .sum()
}
