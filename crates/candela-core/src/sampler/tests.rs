//! Sampler tests: determinism, range, stratification, and moments.

use super::*;

const KINDS: [SamplerKind; 4] = [
    SamplerKind::Independent,
    SamplerKind::PaddedSobol,
    SamplerKind::Halton,
    SamplerKind::ZSobol,
];

/// The first `dims` values (alternating 1D and 2D requests) of one pixel sample.
fn values(s: &mut Sampler, pixel: UVec2, index: u32, dims: usize) -> Vec<f32> {
    s.start_pixel_sample(pixel, index, 0);
    let mut out = Vec::new();
    while out.len() < dims {
        let p = s.get_pixel_2d();
        out.extend([p.x, p.y, s.get_1d()]);
    }
    out
}

#[test]
fn deterministic_across_clones_threads_and_order() {
    for kind in KINDS {
        let base = Sampler::new(kind, 16, 42);
        let pixel = UVec2::new(13, 7);
        let want = values(&mut base.clone(), pixel, 5, 30);
        // Other work in between, then replay.
        let mut s = base.clone();
        values(&mut s, UVec2::new(1, 2), 3, 30);
        assert_eq!(values(&mut s, pixel, 5, 30), want);
        let from_thread = std::thread::scope(|sc| {
            sc.spawn(|| values(&mut base.clone(), pixel, 5, 30))
                .join()
                .unwrap()
        });
        assert_eq!(from_thread, want);
        // A different seed changes the values; the same seed does not.
        assert_ne!(values(&mut base.clone_with_seed(43), pixel, 5, 30), want);
        assert_eq!(values(&mut base.clone_with_seed(42), pixel, 5, 30), want);
        // Starting at a later dimension replays the tail of the sequence.
        let mut s = base.clone();
        s.start_pixel_sample(pixel, 5, 3);
        let p = s.get_pixel_2d();
        assert_eq!([p.x, p.y, s.get_1d()], want[3..6]);
    }
}

#[test]
fn values_in_unit_interval() {
    for kind in KINDS {
        let mut s = Sampler::new(kind, 64, 0);
        for px in 0..16 {
            for i in 0..64 {
                for v in values(&mut s, UVec2::new(px, 3 * px), i, 24) {
                    assert!((0.0..1.0).contains(&v), "{kind:?}: {v}");
                }
            }
        }
    }
}

/// True when `pts` (2^k points) has exactly one point in every elementary
/// interval 2^a × 2^(k−a), a = 0..=k: a (0, k, 2)-net in base 2.
fn is_02_net(pts: &[Vec2]) -> bool {
    let k = pts.len().trailing_zeros();
    (0..=k).all(|a| {
        let (nx, ny) = (1usize << a, 1usize << (k - a));
        let mut count = vec![0u8; pts.len()];
        for p in pts {
            let (cx, cy) = ((p.x * nx as f32) as usize, (p.y * ny as f32) as usize);
            count[cy * nx + cx] += 1;
        }
        count.iter().all(|&c| c == 1)
    })
}

/// Every 2D request of a pixel's 2^k samples is a (0, k, 2)-net for the padded
/// Sobol sampler (k = 4, 6, 8), and (as a check that the test can fail) not
/// for independent samples.
#[test]
fn padded_sobol_2d_requests_are_nets() {
    for (spp, pixel) in [
        (16u32, UVec2::new(0, 0)),
        (64, UVec2::new(5, 9)),
        (256, UVec2::new(300, 2)),
    ] {
        for kind in KINDS {
            let mut s = Sampler::new(kind, spp, 7);
            for request in 0..6 {
                let pts: Vec<Vec2> = (0..spp)
                    .map(|i| {
                        s.start_pixel_sample(pixel, i, 2 * request);
                        s.get_2d()
                    })
                    .collect();
                assert_eq!(
                    is_02_net(&pts),
                    matches!(kind, SamplerKind::PaddedSobol | SamplerKind::ZSobol),
                    "{kind:?} {spp}"
                );
            }
        }
    }
}

/// ZSobol's samples of every aligned square of pixels form one net too (the
/// blue-noise property, module doc of `zsobol`): 2×2 pixels of 16 samples,
/// 4×4 of 4 and 2×2 of 8 (odd log2 spp: binary lowest digit), at several
/// squares and requests, over films whose side is and is not a power of
/// two; padded Sobol's independent pixels are not (the test can fail).
#[test]
fn zsobol_squares_of_pixels_are_nets() {
    for (spp, side, film) in [(16u32, 2u32, 256u32), (4, 4, 100), (8, 2, 640)] {
        for kind in [SamplerKind::ZSobol, SamplerKind::PaddedSobol] {
            let mut s = match kind {
                SamplerKind::ZSobol => Sampler::ZSobol(ZSobolSampler::new(
                    spp,
                    3,
                    UVec2::new(film, film / 2 + 1),
                    ZSobolRandomize::FastOwen,
                )),
                _ => Sampler::new(kind, spp, 3),
            };
            for (corner, request) in [
                (UVec2::new(0, 0), 0),
                (UVec2::new(8, 4), 1),
                (UVec2::new(36, 20), 5),
            ] {
                let mut pts = Vec::new();
                for dy in 0..side {
                    for dx in 0..side {
                        for i in 0..spp {
                            s.start_pixel_sample(corner + UVec2::new(dx, dy), i, 2 * request);
                            pts.push(s.get_2d());
                        }
                    }
                }
                assert_eq!(
                    is_02_net(&pts),
                    kind == SamplerKind::ZSobol,
                    "{kind:?} {spp} spp, {side}² pixels at {corner}"
                );
            }
        }
    }
}

/// Every ZSobol randomisation keeps the nets of a pixel, and the passes of
/// a second epoch (sample indices ≥ spp) are a net again, but a different one.
#[test]
fn zsobol_randomizations_and_epochs_keep_nets() {
    for r in ["none", "permutedigits", "fastowen", "owen"] {
        let randomize = ZSobolRandomize::from_name(r).expect("a pbrt-v4 name");
        let mut s = ZSobolSampler::new(16, 9, UVec2::new(64, 64), randomize);
        let pixel = UVec2::new(5, 6);
        let pts = |s: &mut ZSobolSampler, first: u32| -> Vec<Vec2> {
            (first..first + 16)
                .map(|i| {
                    s.start_pixel_sample(pixel, i, 4);
                    s.get_2d()
                })
                .collect()
        };
        let (a, b) = (pts(&mut s, 0), pts(&mut s, 16));
        assert!(is_02_net(&a) && is_02_net(&b), "{r}");
        assert_ne!(a, b, "{r}");
    }
    assert_eq!(ZSobolRandomize::from_name("sobol"), None);
}

/// Mean over many dimensions is 1/2 and neighbouring dimensions are
/// uncorrelated (E[x_d x_{d+1}] = 1/4), within 5σ with σ measured.
#[test]
fn moments_over_many_dimensions() {
    for kind in KINDS {
        let mut s = Sampler::new(kind, 32, 3);
        let (mut m, mut c) = (Vec::new(), Vec::new());
        for px in 0..64 {
            for i in 0..32 {
                let v = values(&mut s, UVec2::new(px % 8, px / 8), i, 48);
                m.extend(v.iter().map(|&x| x as f64));
                c.extend(v.windows(2).map(|w| (w[0] * w[1]) as f64));
            }
        }
        for (xs, want) in [(&m, 0.5), (&c, 0.25)] {
            let n = xs.len() as f64;
            let mean = xs.iter().sum::<f64>() / n;
            let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
            let tol = 5.0 * (var / n).sqrt();
            assert!(
                (mean - want).abs() <= tol,
                "{kind:?}: {mean} vs {want} ± {tol}"
            );
        }
    }
}

#[test]
fn pbrt_names_map_to_samplers() {
    assert_eq!(
        SamplerKind::from_name("independent"),
        Some((SamplerKind::Independent, true))
    );
    assert_eq!(
        SamplerKind::from_name("paddedsobol"),
        Some((SamplerKind::PaddedSobol, true))
    );
    assert_eq!(
        SamplerKind::from_name("halton"),
        Some((SamplerKind::Halton, true))
    );
    assert_eq!(
        SamplerKind::from_name("zsobol"),
        Some((SamplerKind::ZSobol, true))
    );
    for n in ["sobol", "pmj02bn", "stratified"] {
        assert_eq!(
            SamplerKind::from_name(n),
            Some((SamplerKind::PaddedSobol, false))
        );
    }
    assert_eq!(SamplerKind::from_name("nope"), None);
}
