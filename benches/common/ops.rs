//! The bounce chain's 10 library operators for one ray (`baseline::Ray`), shared by
//! `benches/chain.rs` and `tools/chain-probe`: travel, projection from vectors,
//! curvature, mirror, Phong lobe, curvature back, unprojection, frame rotation (N ≥ 4),
//! travel, window; applied one by one through `Operator::apply`, or pushed on a `Chain`.

use covtrace::brdf::{Brdf, Lobe};
use covtrace::curvature::Curvature;
use covtrace::occlusion::Window;
use covtrace::projection::{Mirror, Project, RotateFrame, Unproject};
use covtrace::travel::Travel;
use covtrace::{Chain, CovError, Operator, Spectrum};
use glam::DVec3;

use crate::baseline::Ray;

/// The library's 10 operators for ray `r` in layout `n`.
pub struct Ops {
    t1: Travel,
    project: Project,
    k: Curvature,
    lobe: Brdf,
    k_back: Curvature,
    unproject: Unproject,
    turn: Option<RotateFrame>,
    t2: Travel,
    window: Window,
}

impl Ops {
    #[inline(always)]
    pub fn new(r: &Ray, n: usize) -> Ops {
        let v = |a: [f64; 3]| DVec3::from_array(a);
        // Flatland has no frame to turn: its projection is built from the cosine alone
        // (the same value `from_vectors` computes).
        let (project, out) = if n >= 4 {
            let p = Project::from_vectors(v(r.dir), v(r.fx), v(r.n)).expect("unit vectors");
            (p, r.angle_out)
        } else {
            (Project::new(v(r.dir).dot(v(r.n)).abs()).expect("cosine"), 0.0)
        };
        Ops {
            t1: Travel::new(r.d1).expect("distance"),
            project,
            k: Curvature::isotropic(r.k).expect("curvature"),
            lobe: Brdf::new(Lobe::Phong { exponent: r.e }).expect("lobe"),
            k_back: Curvature::isotropic(-r.k).expect("curvature"),
            unproject: Unproject::with_angle(r.cos_out, out).expect("cosine"),
            turn: (n >= 4).then(|| RotateFrame::new(r.turn).expect("angle")),
            t2: Travel::new(r.d2).expect("distance"),
            window: Window::isotropic(r.std).expect("std"),
        }
    }

    #[inline(always)]
    pub fn list(&self) -> [Option<&dyn Operator>; 10] {
        [
            Some(&self.t1),
            Some(&self.project),
            Some(&self.k),
            Some(&Mirror),
            Some(&self.lobe),
            Some(&self.k_back),
            Some(&self.unproject),
            self.turn.as_ref().map(|t| t as &dyn Operator),
            Some(&self.t2),
            Some(&self.window),
        ]
    }

    /// Through `Operator::apply`, as a chain or plugin calls them.
    #[inline(always)]
    pub fn apply(&self, s: &mut dyn Spectrum) -> bool {
        self.try_dyn(s).is_ok()
    }

    /// [`Ops::apply`] with the first error.
    #[inline(always)]
    pub fn try_dyn(&self, s: &mut dyn Spectrum) -> Result<(), CovError> {
        self.list().into_iter().flatten().try_for_each(|op| op.apply(s))
    }

    pub fn chain(&self) -> Chain {
        let mut c = Chain::new();
        c.push(self.t1);
        c.push(self.project);
        c.push(self.k);
        c.push(Mirror);
        c.push(self.lobe);
        c.push(self.k_back);
        c.push(self.unproject);
        if let Some(t) = self.turn {
            c.push(t);
        }
        c.push(self.t2);
        c.push(self.window);
        c
    }
}
