//! Image-textured diffuse area lights: Φ against a numerical integral of
//! the emitted radiance over a unit-square quad, and pbrt-v4's `scale` and
//! `power` normalisation against the spectral light it generalises.

use super::*;
use crate::image::{MapImage, PixelFormat};
use crate::math::{Transform, PI};
use crate::shape::{Shape, Triangle, TriangleMesh};
use crate::spectrum::{ColorSpace, Rgb, SpectrumKind};
use std::sync::Arc;

/// The two triangles of the unit square [0, 1]² at z = 0, uv = (x, y), normal +z.
fn unit_quad() -> Vec<Shape> {
    let p = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
    let mesh = TriangleMesh::new(
        &Transform::IDENTITY,
        false,
        vec![0, 1, 2, 0, 2, 3],
        p.iter().map(|&(x, y)| Vec3::new(x, y, 0.0)).collect(),
        None,
        Some(p.iter().map(|&(x, y)| Vec2::new(x, y)).collect()),
        None,
    )
    .expect("valid quad");
    let mesh = Arc::new(mesh);
    (0..2)
        .map(|i| Shape::Triangle(Triangle::new(mesh.clone(), i)))
        .collect()
}

fn image(w: usize, h: usize, texels: &[[f32; 3]]) -> Arc<MapImage> {
    let data = texels.iter().flatten().copied().collect();
    Arc::new(MapImage::new(w, h, 3, data, PixelFormat::Float))
}

fn lights(im: &Arc<MapImage>, two_sided: bool) -> Vec<DiffuseAreaLight> {
    unit_quad()
        .into_iter()
        .map(|s| DiffuseAreaLight::new_image(s, im.clone(), ColorSpace::srgb(), 1.3, two_sided))
        .collect()
}

/// π·(sides)·∫ L dA over the unit square by an n×n midpoint rule, L from
/// `l()` along the normal (one-sided: the front side only).
fn phi_by_quadrature(
    l: &DiffuseAreaLight,
    sides: f32,
    lam: &SampledWavelengths,
) -> SampledSpectrum {
    const N_S: usize = crate::spectrum::N_SPECTRUM_SAMPLES;
    let n = 400;
    // f64 sums: 160 000 f32 additions would lose ~10⁻⁴.
    let mut sum = [0.0f64; N_S];
    for j in 0..n {
        for i in 0..n {
            let uv = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
            let v = l.l(uv.extend(0.0), Vec3::Z, uv, Vec3::Z, lam);
            (0..N_S).for_each(|k| sum[k] += v[k] as f64);
        }
    }
    let f = sides as f64 * std::f64::consts::PI / (n * n) as f64;
    SampledSpectrum::from_fn(|k| (sum[k] * f) as f32)
}

fn assert_close(a: &SampledSpectrum, b: &SampledSpectrum, rel: f32, what: &str) {
    for i in 0..crate::spectrum::N_SPECTRUM_SAMPLES {
        assert!(
            (a[i] - b[i]).abs() <= rel * b[i].abs().max(1e-6),
            "{what}, sample {i}: {} vs {}",
            a[i],
            b[i]
        );
    }
}

#[test]
fn uniform_image_phi_is_pi_a_l() {
    let lam = lambda();
    let rgb = [0.3, 0.5, 0.9];
    let cs = ColorSpace::srgb();
    let l = cs.sample_rgb(
        Rgb::new(rgb[0], rgb[1], rgb[2]),
        SpectrumKind::Illuminant,
        &lam,
    ) * 1.3;
    for two in [false, true] {
        let sides = if two { 2.0 } else { 1.0 };
        for light in lights(&image(2, 2, &[rgb; 4]), two) {
            // Each triangle has area 1/2.
            assert_close(&light.phi(&lam), &(l * (sides * 0.5 * PI)), 1e-5, "πAL");
        }
    }
}

#[test]
fn image_phi_matches_the_integral_over_a_unit_square_quad() {
    // Texels of one chromaticity (c and 3c): the RGB lift is then linear, so
    // the bilinear image's integral is exactly the texel mean (module doc).
    let lam = lambda();
    let c = [0.1, 0.2, 0.3];
    let im = image(2, 1, &[c, c.map(|v| 3.0 * v)]);
    for two in [false, true] {
        let ls = lights(&im, two);
        let total = ls[0].phi(&lam) + ls[1].phi(&lam);
        let want = phi_by_quadrature(&ls[0], if two { 2.0 } else { 1.0 }, &lam);
        assert_close(&total, &want, 1e-4, "Φ of the quad");
        // Against the closed form too: mean of c and 3c = 2c over area 1.
        let cs = ColorSpace::srgb();
        let two_c = cs.sample_rgb(Rgb::new(0.2, 0.4, 0.6), SpectrumKind::Illuminant, &lam);
        let sides = if two { 2.0 } else { 1.0 };
        assert_close(
            &total,
            &(two_c * (1.3 * sides * PI)),
            1e-4,
            "2c closed form",
        );
    }
}

#[test]
fn image_light_normalises_like_a_spectral_light_of_the_same_colour() {
    // A grey texel (v, v, v) in sRGB radiates like "rgb L" [v v v] under
    // `scale`; under `power` its Φ is that of any light given the same
    // power: k_e divides by the image's mean luminance (v), where pbrt-v4's
    // spectral light (k_e = 1) normalises "rgb L" [1 1 1] exactly.
    let lam = lambda();
    let cs = ColorSpace::srgb();
    let uv = Vec2::new(0.6, 0.3);
    let grey = |v: f32| crate::spectrum::Spectrum::rgb_illuminant(cs, Rgb::new(v, v, v));
    for v in [1.0, 0.5] {
        let im = image(1, 1, &[[v; 3]]);
        for shape in unit_quad() {
            let a = diffuse_area_image_light(shape.clone(), im.clone(), cs, cs, 2.0, true, None);
            let b = diffuse_area_light(shape.clone(), grey(v), 2.0, true, None);
            let (la, lb) = (
                a.l(uv.extend(0.0), Vec3::Z, uv, Vec3::Z, &lam),
                b.l(uv.extend(0.0), Vec3::Z, uv, Vec3::Z, &lam),
            );
            assert_close(&la, &lb, 1e-4, "radiance");
            let p = Some(250.0);
            let a = diffuse_area_image_light(shape.clone(), im.clone(), cs, cs, 2.0, true, p);
            let b = diffuse_area_light(shape, grey(1.0), 2.0, true, p);
            assert_close(&a.phi(&lam), &b.phi(&lam), 1e-4, "power");
        }
    }
}
