//! The facade re-exports every operator crate and they compose in one chain.

use covtrace::brdf::{Lobe, Reflect};
use covtrace::curvature::Curvature;
use covtrace::occlusion::BlockerEdge;
use covtrace::projection::RotateFrame;
use covtrace::refraction::Refract;
use covtrace::travel::Travel;
use covtrace::{Chain, Cov, Operator};

#[test]
fn every_operator_in_one_5d_chain() {
    let chain = Chain::new()
        .with(Travel::new(1.0).unwrap())
        .with(BlockerEdge::new(0.1).unwrap())
        .with(RotateFrame::new(0.3).unwrap())
        .with(
            Reflect::new(
                0.7,
                0.7,
                Curvature::anisotropic(1.0, 2.0, 0.1).unwrap(),
                Lobe::ggx(0.2).unwrap(),
            )
            .unwrap(),
        )
        .with(Refract::new(1.0, 1.5, 0.9).unwrap())
        .with(Travel::new(3.0).unwrap());
    let start = Cov::<5>::gaussian([0.1, 0.1, f64::INFINITY, f64::INFINITY, f64::INFINITY]).unwrap();
    let trace = chain.trace(start).unwrap();
    assert_eq!(trace.steps.len(), 6);
    assert!(trace.last().validity().is_valid());
    // Time is untouched by static operators.
    assert_eq!(trace.last().get(4, 4), 0.0);
    assert_eq!(Operator::requires(&chain).smallest_layout(), 4);
}
