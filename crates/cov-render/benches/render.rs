//! Renderer speed: primary rays per second (camera ray, BVH hit, shading with one light
//! sample and one bounce) and covariance paths per second, on the bundled scenes at a
//! small size. Run: `cargo bench -p cov-render --bench render`; compare within one run.

use std::hint::black_box;
use std::path::Path;

use cov_render::{World, covariance_maps, render};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};

const W: u32 = 64;
const H: u32 = 48;

fn scenes(c: &mut Criterion) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes");
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool");
    for name in ["cornell", "pool", "glossy"] {
        let world = World::load(&dir.join(format!("{name}.ron")))
            .expect("bundled scene")
            .with_resolution(W, H);
        let mut g = c.benchmark_group(format!("render/{name}"));
        g.sample_size(10);
        g.throughput(Throughput::Elements((W * H) as u64));
        g.bench_function("path tracing, 1 spp, 1 thread (elements = camera samples)", |b| {
            b.iter(|| pool.install(|| black_box(render(&world, 1, 1))))
        });
        g.bench_function(
            "covariance pass, 1 path per pixel, 1 thread (elements = paths)",
            |b| b.iter(|| pool.install(|| black_box(covariance_maps(&world, 1, 1, 1, None).expect("maps")))),
        );
        g.finish();
    }
}

criterion_group!(benches, scenes);
criterion_main!(benches);
