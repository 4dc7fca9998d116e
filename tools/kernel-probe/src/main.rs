//! One kernel of cov-core, called 25,600 times on a fixed 4D state with literal axes, as
//! Rust code calls it directly (`mode` picks it; `none` is the loop alone). Run under
//! `valgrind --tool=callgrind` by `compare.sh`; the method names are those of every build
//! since the square-root form existed, so the same file builds against an older cov-core.

use cov_core::*;
use std::hint::black_box;
macro_rules! run {
    ($base:expr, $f:ident, $body:expr) => {{
        let mut acc = 0.0;
        for k in 0..25_600u32 {
            let mut $f = black_box($base);
            let _ = black_box(k);
            $body.unwrap();
            acc += $f.get(0, 0) + $f.get(3, 3);
        }
        acc
    }};
}
fn main() {
    let mode = std::env::args().nth(1).unwrap_or_default();
    let mut c = Cov::<4>::gaussian([0.5, 0.7, 1.3, 2.0]).unwrap();
    c.shear(Axis::U, Axis::X, 0.7).unwrap();
    c.shear(Axis::Y, Axis::V, 0.3).unwrap();
    let f = CovFactor::from_cov(&c);
    let w2 = [2.0, 0.3, 0.3, 1.5];
    let s2 = [3.0, 0.5, 0.5, 2.0];
    let acc = match mode.as_str() {
        "none" => run!(c, x, Ok::<(), CovError>(())),
        "c_shear" => run!(c, x, x.shear(Axis::X, Axis::U, 0.8)),
        "c_scale" => run!(c, x, x.scale(Axis::U, 1.7)),
        "c_rotate" => run!(c, x, x.rotate(Axis::X, Axis::Y, 0.4)),
        "c_rotate_frame" => run!(c, x, x.rotate_frame(0.4)),
        "c_add_variance" => run!(c, x, x.add_variance(Axis::X, 0.5)),
        "c_window2" => run!(c, x, x.add_window(&[Axis::X, Axis::Y], &w2)),
        "c_convolve1" => run!(c, x, x.convolve(&[Axis::U], &[3.0])),
        "c_convolve2" => run!(c, x, x.convolve(&[Axis::U, Axis::V], &s2)),
        "c_integrate1" => run!(c, x, x.integrate(&[Axis::U])),
        "f_shear" => run!(f, x, x.shear(Axis::X, Axis::U, 0.8)),
        "f_scale" => run!(f, x, x.scale(Axis::U, 1.7)),
        "f_rotate" => run!(f, x, x.rotate(Axis::X, Axis::Y, 0.4)),
        "f_rotate_frame" => run!(f, x, x.rotate_frame(0.4)),
        "f_add_variance" => run!(f, x, x.add_variance(Axis::X, 0.5)),
        "f_window2" => run!(f, x, x.add_window(&[Axis::X, Axis::Y], &w2)),
        "f_convolve1" => run!(f, x, x.convolve(&[Axis::U], &[3.0])),
        "f_convolve2" => run!(f, x, x.convolve(&[Axis::U, Axis::V], &s2)),
        "f_integrate1" => run!(f, x, x.integrate(&[Axis::U])),
        _ => panic!("mode"),
    };
    println!("{acc}");
}
