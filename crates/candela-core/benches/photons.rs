//! Photon shooting throughput: 65 536 photons traced (and deposited into a
//! counter) on the bundled Cornell box and caustic-glass, with rayon pools
//! of 1 and 2 threads, so the report gives photons/s and the 1 → 2 thread
//! scaling of the photon pass.

#![allow(missing_docs)]

use candela_core::build::{build, Overrides, RenderSetup};
use candela_core::integrator::photon::{trace_photon, ShootSettings};
use candela_core::spectrum::SampledWavelengths;
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use rayon::prelude::*;
use std::path::Path;

const PHOTONS: u64 = 1 << 16;

fn load(scene: &str) -> RenderSetup {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(scene);
    let desc = candela_scene::parse_file(&path).expect("scene parses");
    build(&desc, &Overrides::default()).expect("scene builds")
}

fn shoot(rs: &RenderSetup, pass: u64) -> u64 {
    let lambda = SampledWavelengths::sample_visible(0.3);
    let settings = ShootSettings {
        max_depth: 20,
        seed: 1,
        caustic_only: false,
    };
    (0..PHOTONS / 1024)
        .into_par_iter()
        .map(|c| {
            let mut hits = 0u64;
            for i in c * 1024..(c + 1) * 1024 {
                trace_photon(&rs.scene, &lambda, &settings, pass, i, |_| hits += 1);
            }
            hits
        })
        .sum()
}

fn photons(c: &mut Criterion) {
    let mut g = c.benchmark_group("photon pass");
    g.throughput(Throughput::Elements(PHOTONS));
    g.sample_size(10);
    for scene in ["cornell-box/scene.pbrt", "caustic-glass/scene.pbrt"] {
        let rs = load(scene);
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool");
            let mut pass = 0;
            g.bench_function(format!("{scene} {threads} thread(s)"), |b| {
                b.iter(|| {
                    pass += 1;
                    pool.install(|| shoot(&rs, pass))
                })
            });
        }
    }
    g.finish();
}

criterion_group!(benches, photons);
criterion_main!(benches);
