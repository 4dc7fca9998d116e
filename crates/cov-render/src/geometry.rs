//! Shapes, their motion, and ray queries through a BVH (the `obvhs` crate).
//!
//! Geometry is held in f64; the BVH traverses in f32 and each primitive is intersected in
//! f64 by the callback. A moving primitive's box covers its whole motion over the shutter,
//! and the primitive is intersected at the ray's time.

use std::time::Duration;

use glam::{DVec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::builder::build_bvh2;
use obvhs::ray::{Ray, RayHit};

/// What a primitive is.
#[derive(Clone, Copy, Debug)]
pub enum Shape {
    /// A sphere.
    Sphere {
        /// Centre at time 0.
        center: DVec3,
        /// Radius.
        radius: f64,
    },
    /// A triangle, with optional vertex normals.
    Triangle {
        /// Vertices at time 0.
        v: [DVec3; 3],
        /// Vertex normals.
        n: Option<[DVec3; 3]>,
    },
}

/// One primitive: a shape, its velocity, and what it is made of.
#[derive(Clone, Copy, Debug)]
pub struct Prim {
    /// The shape.
    pub shape: Shape,
    /// Velocity (m/s): the shape is at `position + velocity·t` at time `t`.
    pub velocity: DVec3,
    /// Material index (reflecting surfaces).
    pub material: u32,
    /// Light index (emitters: they do not reflect).
    pub light: Option<u32>,
}

/// A ray–surface intersection.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    /// Distance along the (unit) ray.
    pub t: f64,
    /// Point.
    pub p: DVec3,
    /// Shading normal, on the side the ray came from.
    pub n: DVec3,
    /// Geometric normal, on the side the ray came from.
    pub ng: DVec3,
    /// Whether the ray hit the front (outward) side.
    pub front: bool,
    /// Curvature seen from outside (1/m; a sphere of radius r: 1/r; flat: 0).
    pub curvature: f64,
    /// The primitive's velocity.
    pub velocity: DVec3,
    /// Material index.
    pub material: u32,
    /// Light index for emitters.
    pub light: Option<u32>,
}

/// The scene's primitives under a BVH.
pub struct Geometry {
    prims: Vec<Prim>,
    bvh: Bvh2,
}

impl std::fmt::Debug for Geometry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Geometry({} primitives)", self.prims.len())
    }
}

fn v3a(v: DVec3) -> Vec3A {
    Vec3A::new(v.x as f32, v.y as f32, v.z as f32)
}

impl Prim {
    fn bounds_at(&self, t: f64) -> (DVec3, DVec3) {
        let off = self.velocity * t;
        match self.shape {
            Shape::Sphere { center, radius } => (
                center + off - DVec3::splat(radius),
                center + off + DVec3::splat(radius),
            ),
            Shape::Triangle { v, .. } => (v[0].min(v[1]).min(v[2]) + off, v[0].max(v[1]).max(v[2]) + off),
        }
    }

    /// A box around the primitive over the times `t0..t1`, padded for f32 traversal.
    fn aabb(&self, t0: f64, t1: f64) -> Aabb {
        let (a0, b0) = self.bounds_at(t0);
        let (a1, b1) = self.bounds_at(t1);
        let (lo, hi) = (a0.min(a1), b0.max(b1));
        let pad = 1e-5 * (hi - lo).max_element().max(1e-3);
        Aabb::new(v3a(lo - DVec3::splat(pad)), v3a(hi + DVec3::splat(pad)))
    }

    /// The nearest intersection in `(tmin, tmax)` at `time`.
    fn intersect(&self, o: DVec3, d: DVec3, time: f64, tmin: f64, tmax: f64) -> Option<f64> {
        let o = o - self.velocity * time;
        match self.shape {
            Shape::Sphere { center, radius } => {
                let oc = o - center;
                let b = oc.dot(d);
                let c = oc.length_squared() - radius * radius;
                let disc = b * b - c;
                if disc < 0.0 {
                    return None;
                }
                let q = disc.sqrt();
                let (t0, t1) = (-b - q, -b + q);
                [t0, t1].into_iter().find(|&t| t > tmin && t < tmax)
            }
            Shape::Triangle { v, .. } => {
                let e1 = v[1] - v[0];
                let e2 = v[2] - v[0];
                let pv = d.cross(e2);
                let det = e1.dot(pv);
                if det.abs() < 1e-300 {
                    return None;
                }
                let inv = 1.0 / det;
                let tv = o - v[0];
                let u = tv.dot(pv) * inv;
                if !(0.0..=1.0).contains(&u) {
                    return None;
                }
                let qv = tv.cross(e1);
                let w = d.dot(qv) * inv;
                if w < 0.0 || u + w > 1.0 {
                    return None;
                }
                let t = e2.dot(qv) * inv;
                (t > tmin && t < tmax).then_some(t)
            }
        }
    }

    fn hit(&self, o: DVec3, d: DVec3, t: f64, time: f64) -> Hit {
        let p = o + d * t;
        let (n_out, ns_out, curvature) = match self.shape {
            Shape::Sphere { center, radius } => {
                let n = ((p - self.velocity * time) - center) / radius;
                (n, n, 1.0 / radius)
            }
            Shape::Triangle { v, n } => {
                let ng = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
                let ns = match n {
                    Some(vn) => {
                        // Barycentric weights of the hit at rest.
                        let q = p - self.velocity * time;
                        let area = (v[1] - v[0]).cross(v[2] - v[0]);
                        let a2 = area.length_squared().max(1e-300);
                        let b1 = (q - v[0]).cross(v[2] - v[0]).dot(area) / a2;
                        let b2 = (v[1] - v[0]).cross(q - v[0]).dot(area) / a2;
                        let s = vn[0] * (1.0 - b1 - b2) + vn[1] * b1 + vn[2] * b2;
                        let s = s.normalize_or_zero();
                        if s == DVec3::ZERO { ng } else { s }
                    }
                    None => ng,
                };
                (ng, ns, 0.0)
            }
        };
        let front = n_out.dot(d) < 0.0;
        let sign = if front { 1.0 } else { -1.0 };
        let ng = n_out * sign;
        let mut n = ns_out * sign;
        if n.dot(ng) <= 0.0 {
            n = ng;
        }
        Hit {
            t,
            p,
            n,
            ng,
            front,
            curvature: if front { curvature } else { -curvature },
            velocity: self.velocity,
            material: self.material,
            light: self.light,
        }
    }
}

impl Geometry {
    /// Builds the BVH over `prims`, whose motion spans the times `t0..t1`.
    pub fn new(prims: Vec<Prim>, t0: f64, t1: f64) -> Geometry {
        let aabbs: Vec<Aabb> = prims.iter().map(|p| p.aabb(t0, t1)).collect();
        let bvh = build_bvh2(&aabbs, BvhBuildParams::medium_build(), &mut Duration::default());
        // Reorder once, so that the traversal's ids index `prims` directly.
        let ordered = bvh.primitive_indices.iter().map(|&i| prims[i as usize]).collect();
        Geometry { prims: ordered, bvh }
    }

    /// Number of primitives.
    pub fn len(&self) -> usize {
        self.prims.len()
    }

    /// Whether there is no primitive.
    pub fn is_empty(&self) -> bool {
        self.prims.is_empty()
    }

    /// The nearest hit of the ray `o + t·d` (`d` unit) with `t` in `(tmin, tmax)` at `time`.
    pub fn intersect(&self, o: DVec3, d: DVec3, time: f64, tmin: f64, tmax: f64) -> Option<Hit> {
        if self.prims.is_empty() {
            return None;
        }
        let ray = Ray::new(v3a(o), v3a(d), tmin as f32, tmax.min(f32::MAX as f64) as f32);
        let mut best: Option<(f64, usize)> = None;
        let mut rh = RayHit::none();
        self.bvh.ray_traverse(ray, &mut rh, |_, id| {
            let limit = best.map_or(tmax, |b| b.0);
            match self.prims[id].intersect(o, d, time, tmin, limit) {
                Some(t) => {
                    best = Some((t, id));
                    t as f32
                }
                None => f32::INFINITY,
            }
        });
        best.map(|(t, id)| self.prims[id].hit(o, d, t, time))
    }

    /// Whether anything lies on the ray in `(tmin, tmax)` at `time`.
    pub fn occluded(&self, o: DVec3, d: DVec3, time: f64, tmin: f64, tmax: f64) -> bool {
        if self.prims.is_empty() {
            return false;
        }
        let ray = Ray::new(v3a(o), v3a(d), tmin as f32, tmax.min(f32::MAX as f64) as f32);
        !self.bvh.ray_traverse_miss(ray, |_, id| {
            match self.prims[id].intersect(o, d, time, tmin, tmax) {
                Some(t) => t as f32,
                None => f32::INFINITY,
            }
        })
    }
}
