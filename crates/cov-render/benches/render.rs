//! Renderer speed: primary rays per second (camera ray, BVH hit, shading with one light
//! sample and one bounce) and covariance paths per second at each depth, on the bundled
//! scenes at a small size; and the guard's stages against the path tracing they serve. Run:
//! `cargo bench -p cov-render --bench render`; compare within one run.

use std::hint::black_box;
use std::path::Path;

use cov_render::adaptive::Guide;
use cov_render::covpass::covariance_rows;
use cov_render::film::Film;
use cov_render::guard::{candidates, chosen_filters, guarded};
use cov_render::{World, covariance_maps, render};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};

const W: u32 = 64;
const H: u32 = 48;

/// A bundled scene at `w × h`.
fn scene(name: &str, w: u32, h: u32) -> World {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes");
    World::load(&dir.join(format!("{name}.ron")))
        .expect("bundled scene")
        .with_resolution(w, h)
}

/// A pool of one thread: the figures are per core.
fn one_thread() -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool")
}

fn scenes(c: &mut Criterion) {
    let pool = one_thread();
    for name in ["cornell", "pool", "glossy"] {
        let world = scene(name, W, H);
        let mut g = c.benchmark_group(format!("render/{name}"));
        g.sample_size(10);
        g.throughput(Throughput::Elements((W * H) as u64));
        g.bench_function("path tracing, 1 spp, 1 thread (elements = camera samples)", |b| {
            b.iter(|| pool.install(|| black_box(render(&world, 1, 1))))
        });
        // The tracer's cost per depth (`max_depth`; the scene's own is 2, the line above).
        if name == "cornell" {
            for depth in [1, 3, 5, 32] {
                let mut deep = scene(name, W, H);
                deep.max_depth = depth;
                g.bench_function(
                    format!("path tracing, 1 spp, max_depth {depth}, 1 thread (elements = camera samples)"),
                    |b| b.iter(|| pool.install(|| black_box(render(&deep, 1, 1)))),
                );
            }
        }
        // The pass's cost per depth (surface vertices per path, up to the scene's).
        for depth in 1..=world.max_depth {
            g.bench_function(
                format!("covariance pass, 1 path per pixel, depth {depth}, 1 thread (elements = paths)"),
                |b| {
                    b.iter(|| {
                        pool.install(|| {
                            black_box(covariance_rows(&world, 1, 1, depth, 1, 0..H, None).expect("maps"))
                        })
                    })
                },
            );
        }
        g.finish();
    }
}

/// The guard's stages at the renderer's defaults (one covariance path per 4×4 block), on
/// a film of 4 samples per pixel (a 16-spp render's pilot), one thread, beside the path
/// tracing of those 4 samples: what the guard costs relative to the sampling it directs.
/// Cornell also at 512×384, where its filters are four times as wide in pixels (a
/// splat's cost is its area; wide filters splat by blocks, `film::BLOCK_STD`).
fn guard(c: &mut Criterion) {
    let pool = one_thread();
    for (name, (w, h)) in [
        ("cornell", (128, 96)),
        ("chess", (128, 96)),
        ("cornell", (512, 384)),
    ] {
        let world = scene(name, w, h);
        let maps = covariance_maps(&world, 1, 4, 1, None).expect("maps");
        let guide = Guide::new(&maps, 0.0);
        let counts = vec![4; (w * h) as usize];
        let sample = || {
            let mut film = Film::new(w, h);
            film.render(&world, &counts, 1, f64::INFINITY, None);
            film
        };
        let film = pool.install(sample);
        let cands = candidates(&guide, 0..h);
        let mut g = c.benchmark_group(format!("guard/{name}/{w}x{h}"));
        g.sample_size(10);
        g.bench_function("path tracing, 4 spp", |b| {
            b.iter(|| pool.install(|| black_box(sample())))
        });
        g.bench_function("candidates (guard::SCALES, edge clamp)", |b| {
            b.iter(|| pool.install(|| black_box(candidates(&guide, 0..h))))
        });
        g.bench_function("pilot choice (luminance splats)", |b| {
            b.iter(|| pool.install(|| black_box(chosen_filters(&cands, &film, 16.0, 0..h))))
        });
        g.bench_function("reconstruction (colour splats)", |b| {
            b.iter(|| pool.install(|| black_box(guarded(&cands, &film, 0..h))))
        });
        g.finish();
    }
}

criterion_group!(benches, scenes, guard);
criterion_main!(benches);
