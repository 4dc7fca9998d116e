//! A render split into parts and merged is the single render, bit for bit; part files
//! that do not make one render are refused with one line.

use std::path::{Path, PathBuf};

use cov_render::denoise::Denoise;
use cov_render::parts::{Part, PartFilm, merge};
use cov_render::{Method, RenderSettings, Renderer, World};

fn scene(name: &str, w: u32, h: u32) -> World {
    World::load(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../examples/scenes")
            .join(name),
    )
    .unwrap()
    .with_resolution(w, h)
}

fn settings(method: Method, seed: u64) -> RenderSettings {
    RenderSettings {
        method,
        spp: 8.0,
        seed,
        ..RenderSettings::default()
    }
}

/// A fresh file name in the temporary folder.
fn temp(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("covtrace-parts-{}-{name}", std::process::id()))
}

/// Renders `n` parts, through their files.
fn parts(world: &World, s: &RenderSettings, n: u32, tag: &str) -> Vec<PartFilm> {
    let s = RenderSettings {
        parts: n,
        ..s.clone()
    };
    (1..=n)
        .map(|index| {
            let part = Part { index, count: n };
            let p = Renderer::new(world, s.clone())
                .unwrap()
                .render_part(part, None)
                .unwrap();
            let f = temp(&format!("{tag}-{index}.exr"));
            p.write(&f).unwrap();
            let back = PartFilm::read(&f).unwrap();
            let _ = std::fs::remove_file(&f);
            assert!(back.film == p.film, "part {part}: the film survives its file");
            assert!(back.maps == p.maps, "part {part}: the maps survive their file");
            back
        })
        .collect()
}

/// Every method, on a scene with defocus, motion and material edges (chess) and on one
/// with soft shadows and a light's edge (cornell), tall enough that parts have margins
/// short of the image: the merged image, film and maps equal the bits of the render with
/// as many parts in one process.
#[test]
fn merged_parts_are_the_single_render() {
    for (name, w, h) in [("chess.ron", 40, 232), ("cornell.ron", 48, 200)] {
        let world = scene(name, w, h);
        for method in Method::ALL {
            for n in [1, 3, h.div_ceil(16)] {
                let s = RenderSettings {
                    parts: n,
                    ..settings(method, 3)
                };
                let mut single = Renderer::new(&world, s.clone()).unwrap();
                let one = single.render(None).unwrap();
                let merged = merge(&parts(&world, &s, n, &format!("{}-{n}", method.name()))).unwrap();
                assert!(
                    merged.film == one.film,
                    "{name} {}: film in {n} parts",
                    method.name()
                );
                let bits = |img: &cov_render::Image| -> Vec<[u64; 3]> {
                    img.pixels
                        .iter()
                        .map(|p| p.to_array().map(f64::to_bits))
                        .collect()
                };
                assert!(
                    bits(&merged.image) == bits(&one.image),
                    "{name} {}: image in {n} parts",
                    method.name()
                );
                assert!(
                    merged.maps.as_ref() == single.maps(),
                    "{name} {}: maps",
                    method.name()
                );
            }
        }
    }
}

/// Covariance tracing followed by a denoiser below 3 spp reads no Σ (no pilot): its parts
/// carry no maps, their files read back, and from 3 spp they carry them again. (Merging
/// denoises, which needs the `oidn` feature; the renderer's own test covers the image.)
#[test]
fn parts_without_a_pilot_carry_no_maps() {
    let world = scene("cornell.ron", 32, 48);
    for (spp, maps) in [(2.0, false), (3.0, true)] {
        let s = RenderSettings {
            spp,
            denoise: Denoise::Oidn,
            ..settings(Method::Cov, 5)
        };
        for p in parts(&world, &s, 2, &format!("denoised-{spp}")) {
            assert_eq!(p.maps.is_some(), maps, "{spp} spp, part {}", p.part);
        }
    }
}

/// One part is the render itself; parts change only where the budget goes, not how much.
#[test]
fn one_part_is_the_render_and_parts_keep_the_budget() {
    let world = scene("cornell.ron", 32, 96);
    let s = settings(Method::Cov, 1);
    let one = Renderer::new(&world, s.clone()).unwrap().render(None).unwrap();
    let merged = merge(&parts(&world, &s, 1, "whole")).unwrap();
    assert!(merged.image == one.image && merged.film == one.film);
    let split = Renderer::new(&world, RenderSettings { parts: 3, ..s })
        .unwrap()
        .render(None)
        .unwrap();
    assert!(split.film.count != one.film.count, "the allocation is split");
    let ratio = split.samples as f64 / one.samples as f64;
    assert!(
        (ratio - 1.0).abs() < 0.01,
        "{} against {}",
        split.samples,
        one.samples
    );
}

/// Each part samples its own rows only; the pilot and the pass reach only its margins.
#[test]
fn a_part_takes_its_own_samples() {
    let world = scene("cornell.ron", 32, 256);
    let s = RenderSettings {
        parts: 4,
        ..settings(Method::Cov, 1)
    };
    let one = Renderer::new(&world, s.clone()).unwrap().render(None).unwrap();
    let total: u64 = parts(&world, &s, 4, "share").iter().map(PartFilm::samples).sum();
    assert_eq!(total, one.samples);
}

/// Parts that do not make one render: one line each, naming what is wrong.
#[test]
fn bad_parts_are_refused_with_one_line() {
    let world = scene("cornell.ron", 32, 96);
    let s = settings(Method::Cov, 1);
    let ps = parts(&world, &s, 3, "bad");
    let line = |e: cov_render::RenderError| {
        let m = e.to_string();
        assert!(!m.contains('\n'), "{m}");
        m
    };
    let m = line(merge(&ps[..2]).unwrap_err());
    assert!(m.contains("part 3/3 (rows 64..96) is missing"), "{m}");
    let twice = vec![ps[0].clone(), ps[1].clone(), ps[1].clone(), ps[2].clone()];
    assert!(line(merge(&twice).unwrap_err()).contains("part 2/3 is given twice"));
    let other = parts(&world, &settings(Method::Cov, 2), 3, "other");
    let mixed = vec![ps[0].clone(), other[1].clone(), ps[2].clone()];
    let m = line(merge(&mixed).unwrap_err());
    assert!(
        m.contains("different renders") && m.contains("`seed` is 2 against 1"),
        "{m}"
    );
    assert!(line(merge(&[]).unwrap_err()).contains("at least one part"));
    // A truncated part, a foreign EXR, a file that is not an EXR, a missing file.
    let f = temp("whole.exr");
    ps[0].write(&f).unwrap();
    let bytes = std::fs::read(&f).unwrap();
    let cut = temp("cut.exr");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let foreign = temp("foreign.exr");
    cov_render::output::write_aovs(&ps[0].film.aovs(), &foreign).unwrap();
    let text = temp("text.exr");
    std::fs::write(&text, "not an image").unwrap();
    for (path, want) in [
        (&cut, "cannot read its pixels"),
        (&foreign, "not a covtrace part file"),
        (&text, "not a readable OpenEXR file"),
        (&temp("absent.exr"), "no such file"),
        (&std::env::temp_dir(), "a directory, not a part file"),
    ] {
        let m = line(PartFilm::read(path).unwrap_err());
        assert!(m.contains(want), "{m}");
    }
    // A byte of the pixel data changed after the file was written: every such file is
    // refused, most by the digest of the data (the compressed blocks still decode).
    let (mut refused, mut by_digest) = (0, 0);
    let damaged = temp("damaged.exr");
    let flips: Vec<usize> = (1..=40).map(|k| bytes.len() - k * bytes.len() / 100).collect();
    for &at in &flips {
        let mut b = bytes.clone();
        b[at] ^= 0x40;
        std::fs::write(&damaged, &b).unwrap();
        if let Err(e) = PartFilm::read(&damaged) {
            refused += 1;
            by_digest += usize::from(line(e).contains("do not match the digest it was written with"));
        }
    }
    let _ = std::fs::remove_file(&damaged);
    // A header whose covariance layout is not one (the data intact).
    let mut odd = ps[0].clone();
    odd.layout = 9;
    odd.write(&damaged).unwrap();
    let m = line(PartFilm::read(&damaged).unwrap_err());
    assert!(m.contains("a damaged part header: layout 9"), "{m}");
    // A key or a timing edited by hand: refused before they reach the image or the report.
    let mut huge = ps[0].clone();
    huge.key.spp = 1e308;
    let mut deep = ps[0].clone();
    deep.key.cov_depth = 33;
    let mut late = ps[0].clone();
    late.key.frame = u32::MAX;
    let mut slow = ps[0].clone();
    slow.timing.sampling = 1e308;
    for (p, want) in [
        (
            huge,
            "a damaged part key: spp must be 1 to 65536 samples per pixel",
        ),
        (deep, "a damaged part key: cov_depth must be 1 to 32"),
        (late, "a damaged part key: frame 4294967295; at most 1000000"),
        (slow, "a damaged part header: timing"),
    ] {
        p.write(&damaged).unwrap();
        let m = line(PartFilm::read(&damaged).unwrap_err());
        assert!(m.contains(want), "{m}");
    }
    let _ = std::fs::remove_file(&damaged);
    assert_eq!(refused, flips.len(), "every damaged file is refused");
    assert!(by_digest > 0, "some damage decodes, and the digest refuses it");
    for p in [f, cut, foreign, text] {
        let _ = std::fs::remove_file(p);
    }
    // More parts than tile rows; a part of another count than the settings'; a time limit.
    let e = Renderer::new(
        &world,
        RenderSettings {
            parts: 7,
            ..s.clone()
        },
    )
    .unwrap_err();
    assert!(line(e).contains("1 to 6 for this image"));
    let three = RenderSettings {
        parts: 3,
        ..s.clone()
    };
    let e = Renderer::new(&world, three.clone())
        .unwrap()
        .render_part(Part { index: 1, count: 2 }, None)
        .unwrap_err();
    assert!(line(e).contains("part 1/2"));
    let timed = RenderSettings {
        time: Some(1.0),
        ..three
    };
    let e = Renderer::new(&world, timed)
        .unwrap()
        .render_part(Part { index: 1, count: 3 }, None)
        .unwrap_err();
    assert!(line(e).contains("time"));
    // A renderer given a guide has no maps for the part file.
    let maps = cov_render::covariance_maps(&world, 1, 4, 1, None).unwrap();
    let guide = cov_render::adaptive::Guide::new(&maps, 0.0);
    let e = Renderer::new(&world, RenderSettings { parts: 3, ..s })
        .and_then(|r| r.with_guide(guide))
        .unwrap()
        .render_part(Part { index: 1, count: 3 }, None)
        .unwrap_err();
    assert!(line(e).contains("its own covariance pass"));
}

/// A frame moves the shutter by frame / frame_rate: a moving object is where its velocity
/// takes it, and the key tells frames apart.
#[test]
fn frames_move_the_shutter() {
    let world = scene("chess.ron", 16, 16);
    let (a, b) = world.camera.shutter.expect("chess has a shutter");
    let rate = world.camera.frame_rate;
    let f = world.at_frame(48).unwrap();
    assert_eq!(f.camera.shutter, Some((a, b)));
    assert_eq!(f.camera.time_offset, 48.0 / rate);
    let ray = f.camera.ray(8.0, 8.0, (0.5, 0.5), 0.25);
    assert!((ray.time - (48.0 / rate + a + 0.25 * (b - a))).abs() < 1e-12);
    assert_eq!(f.frame, 48);
    assert_eq!(f.at_frame(0).unwrap().camera.time_offset, 0.0);
    let far = scene("chess.ron", 16, 16).at_frame(cov_render::world::MAX_FRAME + 1);
    assert!(far.is_err());
}
