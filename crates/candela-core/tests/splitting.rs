//! The reflection fork of camera walks (`"bool splitspecular"`, on by
//! default in `path`, `vcm`, `sppm`, `ppm` and `photonmap`; module doc of
//! `integrator::subpath`, "Splitting"): where a camera subpath's first
//! vertex is smooth water or glass, a fork follows the reflection alone and
//! counts the emission it reaches through delta scatterings, at F times its
//! radiance, and the subpath leaves that emission out when it took the
//! reflection.
//!
//! The scene: a bright sphere seen in a flat water surface over a dark
//! floor, so that in the four blocks at the centre of the image most of the
//! light is E S L, the light's reflection, which only the camera subpath
//! samples. Each estimator with the fork must agree per 8×8 block with
//! itself without it (Welch's t-test at the Šidák-corrected level for
//! α = 0.01 over all blocks, K = 8 seeds; `common::stats`), the side
//! without the fork at 16× the passes so that its noise at the glint does
//! not hide an error there; `vcm` also with the path tracer (forking too). And the fork
//! must do what it is for: at the glint's four blocks the variance of the
//! block means over the seeds falls (F-test with both sides at the same
//! passes, α = 0.01 with 7 and 7 degrees of freedom: F > 6.99).

mod common;

use candela_core::build::Overrides;
use common::{seeded_block_means, stats};

const K: usize = 8;

fn glint(integrator: &str) -> String {
    glint_over(0.1, integrator)
}

/// [`glint`] with floor reflectance `floor`.
fn glint_over(floor: f32, integrator: &str) -> String {
    format!(
        r#"LookAt 0 2.5 -2  0 -2 2  0 1 0
Camera "perspective" "float fov" [45]
Film "rgb" "integer xresolution" [32] "integer yresolution" [32]
PixelFilter "box"
Sampler "independent"
Integrator {integrator} "integer maxdepth" [6]
WorldBegin
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [50 50 50]
  Translate 0 3 2
  Shape "sphere" "float radius" [0.4]
AttributeEnd
Material "diffuse" "rgb reflectance" [{floor} {floor} {floor}]
Shape "trianglemesh" "point3 P" [-4 0 -4  4 0 -4  4 0 4  -4 0 4] "integer indices" [0 2 1 0 3 2]
AttributeBegin
  Material "dielectric" "float eta" [1.33]
  Shape "trianglemesh" "point3 P" [-4 0.5 -4  4 0.5 -4  4 0.5 4  -4 0.5 4] "integer indices" [0 2 1 0 3 2]
AttributeEnd
"#
    )
}

/// Block means of K renders with seeds 100…, `[block][render]`.
fn block_means(scene: &str, spp: u32) -> Vec<Vec<f64>> {
    let ov = Overrides {
        spp: Some(spp),
        ..Default::default()
    };
    seeded_block_means(scene, &ov, 100, K)
}

/// Blocks of 8×8 pixels, four by four; the glint is where the centre four
/// meet.
const GLINT_BLOCKS: [usize; 4] = [5, 6, 9, 10];

/// Renders `integrator` with and without the fork, checks that they agree
/// and that the fork lowers the variance at the glint (module doc), and
/// returns the block means with the fork.
fn check_fork(name: &str, integrator: &str) -> Vec<Vec<f64>> {
    check_fork_in(glint, name, integrator)
}

/// [`check_fork`] in the scene `scene(integrator)`.
fn check_fork_in(scene: fn(&str) -> String, name: &str, integrator: &str) -> Vec<Vec<f64>> {
    let unsplit = format!("{integrator} \"bool splitspecular\" false");
    let split = block_means(&scene(integrator), 32);
    let reference = block_means(&scene(&unsplit), 512);
    stats::assert_blocks_agree(
        &reference,
        &split,
        &format!("glint: {name} unsplit vs split"),
    );
    let unsplit_32 = block_means(&scene(&unsplit), 32);
    for b in GLINT_BLOCKS {
        let (m_s, v_s) = stats::mean_var(&split[b]);
        let (m_u, v_u) = stats::mean_var(&unsplit_32[b]);
        let f = v_u / v_s;
        eprintln!(
            "glint block {b}, {name}: split {m_s:.4}, variance {v_s:.2e}; unsplit {m_u:.4}, {v_u:.2e}; F = {f:.1}"
        );
        assert!(
            f > 6.99,
            "glint block {b}, {name}: the fork does not lower the variance (F = {f:.2})"
        );
    }
    split
}

/// VCM's fork. Measured once with these seeds: without the subpath leaving
/// the fork's emission out (counted twice) the agreement fails (block 5:
/// 0.44 against 0.68, p = 7·10⁻⁶), without the fork counting it (lost)
/// too (0.44 against 0.12, p = 7·10⁻⁸), and with no fork the F-test; the
/// variance ratios at the glint are 30–150.
#[test]
fn vcm_forks_at_the_glint() {
    let split = check_fork("vcm", "\"vcm\" \"float radius\" [0.05]");
    let pt = block_means(&glint("\"path\""), 512);
    stats::assert_blocks_agree(&pt, &split, "glint: path vs vcm split");
}

/// The path tracer forks in its own loop, the same way. Over a black
/// floor: the path tracer finds the floor under the water only by BSDF
/// samples that refract out onto the light (next-event estimation is
/// blocked by the water), noise that hides the glint's (F = 1.8 with the
/// dark floor of [`glint`]). Measured once with these seeds: counted
/// twice, block 5 is 0.32 against 0.56 (p = 1·10⁻⁶); lost, 0 (p = 3·10⁻⁷);
/// with no fork F = 1.00.
#[test]
fn the_path_tracer_forks_at_the_glint() {
    check_fork_in(|i| glint_over(0.0, i), "path", "\"path\"");
}

/// The photon estimators' camera walk forks the same way; its visible
/// points are the subpath's alone. Measured once with these seeds (sppm):
/// counted twice, block 5 is 0.44 against 0.67 (p = 5·10⁻⁵); lost, 0.44
/// against 0.11 (p = 3·10⁻⁸); with no fork F = 1.00.
#[test]
fn the_photon_estimators_fork_at_the_glint() {
    check_fork("sppm", "\"sppm\" \"float radius\" [0.05]");
    check_fork("ppm", "\"ppm\" \"float radius\" [0.05]");
    check_fork(
        "photonmap",
        "\"photonmap\" \"integer photons\" [2000] \"integer causticphotons\" [2000] \"bool finalgather\" false",
    );
}
