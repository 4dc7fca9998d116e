//! The main demo: a light path from an area light, past a blocker, onto a glossy curved
//! surface, then to the camera. Prints Σ after every step, the bandwidths, and what a
//! renderer would do with the result.
//!
//! Run: `cargo run --release --example demo`

use covtrace::brdf::{Lobe, Reflect};
use covtrace::curvature::Curvature;
use covtrace::occlusion::BlockerEdge;
use covtrace::travel::Travel;
use covtrace::{Axis, Chain, Cov, CovError, NYQUIST_K, Operator};

fn main() -> Result<(), CovError> {
    // A 10 cm Gaussian area light, emitting uniformly in angle (constant along u, v).
    let start = Cov::<4>::gaussian([0.1, 0.1, f64::INFINITY, f64::INFINITY])?;
    let chain = Chain::new()
        .with(Travel::new(1.0)?)
        .with(BlockerEdge::new(0.02)?)
        .with(Travel::new(0.5)?)
        .with(Reflect::new(
            0.8,
            0.9,
            Curvature::anisotropic(4.0, 1.0, 0.3)?,
            Lobe::phong(200.0)?,
        )?)
        .with(Travel::new(2.0)?);
    println!("covtrace demo: an area light, a blocker edge 2 cm from the ray, a glossy");
    println!("anisotropically curved reflector (Phong 200), and 2 m to the camera.\n");
    let trace = chain.trace(start)?;
    println!(
        "start (Σ in cycles²/unit², axes x y in m, u v in tangent units):\n{}\n",
        trace.start
    );
    for (i, step) in trace.steps.iter().enumerate() {
        let bw = step.cov.bandwidths();
        println!(
            "after step {i} ({:<11}) bandwidths [cycles/unit]: x {:>9.3}  y {:>9.3}  u {:>9.3}  v {:>9.3}",
            step.name, bw[0], bw[1], bw[2], bw[3]
        );
    }
    let last = trace.last();
    println!("\nfinal Σ:\n{last}\n");
    println!("validity: {}\n", last.validity());

    // At the camera: the spatial spectrum seen through a pinhole is the (x, y) marginal.
    let image = last.marginal(&[Axis::X, Axis::Y])?;
    let density = image.sampling_density(NYQUIST_K)?;
    let filter = image.reconstruction_filter(&[0.05, 0.05])?;
    println!(
        "sampling density over the image plane: {density:.3e} samples/m² (Nyquist factor k = {NYQUIST_K})"
    );
    println!(
        "reconstruction filter: principal std {:.4} m and {:.4} m{}",
        filter.extents[0],
        filter.extents[1],
        if filter.clamped { " (clamped at 5 cm)" } else { "" }
    );
    println!(
        "\nsteps: {}; operators used: {}",
        chain.len(),
        chain_names(&chain).join(" → ")
    );
    Ok(())
}

fn chain_names(chain: &Chain) -> Vec<String> {
    chain.operators().map(|o| Operator::name(o).to_string()).collect()
}
