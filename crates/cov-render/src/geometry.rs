//! Shapes, their motion, and ray queries through a BVH (the `obvhs` crate).
//!
//! Geometry is held in f64; the BVH traverses in f32 and each primitive is intersected in
//! f64 by the callback. A moving primitive's box covers its whole motion over the shutter,
//! and the primitive is intersected at the ray's time.

use std::f64::consts::PI;
use std::time::Duration;

use glam::{DVec2, DVec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::builder::build_bvh2;
use obvhs::ray::{Ray, RayHit};

/// What a primitive is.
// Nearly every primitive of a scene is a triangle, so a sphere's unused bytes cost
// little, and boxing the triangle would add a pointer chase to every hit.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug)]
pub enum Shape {
    /// A sphere.
    Sphere {
        /// Centre at time 0.
        center: DVec3,
        /// Radius.
        radius: f64,
        /// Angular velocity about the centre (rad/s, axis times rate): the surface, its
        /// texture coordinates with it, is turned by `spin · t` at time `t`. The shape is
        /// the same at every angle, so only the coordinates and the points' velocities
        /// (`velocity + spin × (p − centre)`) see it.
        spin: DVec3,
    },
    /// A triangle, with optional vertex normals and texture coordinates.
    Triangle {
        /// Vertices at time 0.
        v: [DVec3; 3],
        /// Vertex normals.
        n: Option<[DVec3; 3]>,
        /// Vertex texture coordinates `(u, v)`.
        uv: Option<[DVec2; 3]>,
        /// The shading surface's curvature, seen from the geometric normal's side
        /// ([`Shape::triangle`]): the same at every point of the triangle.
        bend: Bend,
    },
}

impl Shape {
    /// A triangle of vertices `v` (at time 0), with optional vertex normals `n` and
    /// texture coordinates `uv`. The curvature its normals give (`shading_curvature`,
    /// bounded by the smallest sphere allowed at its farthest vertex, [`min_size`]) is
    /// computed here once, not at every hit: the path tracer's hits do not read it.
    pub fn triangle(v: [DVec3; 3], n: Option<[DVec3; 3]>, uv: Option<[DVec2; 3]>) -> Shape {
        let ng = (v[1] - v[0]).cross(v[2] - v[0]).normalize_or_zero();
        let far = v[0].abs().max(v[1].abs()).max(v[2].abs());
        let bend = n.map_or(Bend::isotropic(0.0, ng), |vn| {
            shading_curvature(v, vn, ng).bounded(1.0 / min_size(far))
        });
        Shape::Triangle { v, n, uv, bend }
    }
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
    /// Curvature seen from the side the ray came from (a sphere of radius r from outside:
    /// 1/r both ways; flat: 0; a triangle with vertex normals: that of its shading surface,
    /// `shading_curvature`).
    pub curvature: Bend,
    /// The primitive's velocity.
    pub velocity: DVec3,
    /// Material index.
    pub material: u32,
    /// Light index for emitters.
    pub light: Option<u32>,
    /// Texture coordinates `(u, v)` of the hit (0 where the shape has none).
    pub uv: DVec2,
    /// `∂p/∂u` and `∂p/∂v` at the hit (m per unit; 0 where the shape has no coordinates
    /// or they are degenerate).
    pub dpduv: [DVec3; 2],
}

/// A surface's principal curvatures at a point (1/m; positive where the surface bends
/// away from the side its normal points to, as a sphere's outside): `k1` along the unit
/// tangent `dir1`, `k2` across it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bend {
    /// Curvature along `dir1`.
    pub k1: f64,
    /// Curvature across `dir1`.
    pub k2: f64,
    /// Principal direction of `k1` (unit, tangent to the surface).
    pub dir1: DVec3,
}

impl Bend {
    /// The same curvature `k` in every direction of the plane normal to `n`.
    pub fn isotropic(k: f64, n: DVec3) -> Bend {
        Bend {
            k1: k,
            k2: k,
            dir1: n.any_orthonormal_vector(),
        }
    }

    /// The curvatures clamped to `±k_max` (a NaN reads 0): a mesh whose normals turn
    /// within a sliver of a triangle bends no tighter than the smallest sphere allowed
    /// at the point ([`min_size`]).
    pub fn bounded(self, k_max: f64) -> Bend {
        let clamp = |k: f64| if k.is_nan() { 0.0 } else { k.clamp(-k_max, k_max) };
        Bend {
            k1: clamp(self.k1),
            k2: clamp(self.k2),
            ..self
        }
    }

    /// The surface seen from its other side.
    pub fn flipped(self) -> Bend {
        Bend {
            k1: -self.k1,
            k2: -self.k2,
            ..self
        }
    }

    /// The angle (rad) of `dir1` from the tangent `x` towards the tangent `y`.
    pub fn angle(&self, x: DVec3, y: DVec3) -> f64 {
        self.dir1.dot(y).atan2(self.dir1.dot(x))
    }
}

/// The curvature that a triangle's vertex normals `n` give its shading surface, seen from
/// the side of the geometric normal `ng` (as a sphere's outside is positive).
///
/// Along each edge `e` the normal turns by `Δn`, and `Δn·e = eᵀ S e` for the shape
/// operator `S` (exact for a sphere's normals: `|e|²/r`); the three edges give the three
/// entries of `S` in the triangle's plane, and its eigenvectors the principal directions.
/// A triangle whose edges do not determine `S` (degenerate, or `S` not finite) reads
/// flat.
fn shading_curvature(v: [DVec3; 3], n: [DVec3; 3], ng: DVec3) -> Bend {
    let side = if (n[0] + n[1] + n[2]).dot(ng) < 0.0 {
        -1.0
    } else {
        1.0
    };
    let a = (v[1] - v[0]).normalize_or_zero();
    let b = ng.cross(a);
    let rows = [(0, 1), (0, 2), (1, 2)].map(|(i, j)| {
        let e = v[j] - v[i];
        let (x, y) = (e.dot(a), e.dot(b));
        ([x * x, 2.0 * x * y, y * y], side * (n[j] - n[i]).dot(e))
    });
    // Cramer's rule on the 3×3 system for (Sxx, Sxy, Syy).
    let det3 = |m: [[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let m = rows.map(|r| r.0);
    let d = det3(m);
    // Relative to the edges' scale (|e|⁶): below it the edges are too close to parallel.
    let scale = rows.iter().map(|r| r.0[0] + r.0[2]).fold(0.0, f64::max).powi(3);
    // (A NaN determinant fails the test too.)
    let flat = Bend {
        k1: 0.0,
        k2: 0.0,
        dir1: a,
    };
    if d.abs().partial_cmp(&(1e-12 * scale)) != Some(std::cmp::Ordering::Greater) {
        return flat;
    }
    let solve = |k: usize| {
        let mut mk = m;
        for (row, r) in mk.iter_mut().zip(&rows) {
            row[k] = r.1;
        }
        det3(mk) / d
    };
    let (sxx, sxy, syy) = (solve(0), solve(1), solve(2));
    let (mean, half) = (0.5 * (sxx + syy), (0.25 * (sxx - syy).powi(2) + sxy * sxy).sqrt());
    // The larger eigenvalue's eigenvector, at θ from `a` with tan 2θ = 2 Sxy / (Sxx − Syy).
    let theta = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    let bend = Bend {
        k1: mean + half,
        k2: mean - half,
        dir1: a * theta.cos() + b * theta.sin(),
    };
    if bend.k1.is_finite() && bend.k2.is_finite() && bend.dir1.is_finite() {
        bend
    } else {
        flat
    }
}

/// `(∂p/∂u, ∂p/∂v)` of a triangle with edges `e1, e2` and texture coordinates `uv`
/// (zero when the coordinates are degenerate).
fn triangle_dpduv(e1: DVec3, e2: DVec3, uv: [DVec2; 3]) -> [DVec3; 2] {
    let (d1, d2) = (uv[1] - uv[0], uv[2] - uv[0]);
    let det = d1.x * d2.y - d2.x * d1.y;
    // Relative to the coordinates' own scale: below this the map from (u, v) to the
    // surface is singular to rounding.
    if det.abs() <= 1e-12 * (d1.length_squared() + d2.length_squared()) {
        return [DVec3::ZERO; 2];
    }
    [(e1 * d2.y - e2 * d1.y) / det, (e2 * d1.x - e1 * d2.x) / det]
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

/// The largest |coordinate| any of `prims` reaches over the times `t0..t1` ([`Prim::reach`]).
pub fn reach(prims: &[Prim], t0: f64, t1: f64) -> f64 {
    prims.iter().map(|p| p.reach(t0, t1)).fold(0.0, f64::max)
}

fn v3a(v: DVec3) -> Vec3A {
    Vec3A::new(v.x as f32, v.y as f32, v.z as f32)
}

/// Largest distance (m) from the origin that a primitive may reach over the shutter: the
/// BVH is built and traversed in single precision, and its boxes' areas, up to
/// `(2 · MAX_COORD)² = 4e24` m², must stay finite there (3.4e38); a box past that range
/// breaks the build. Checked where the scene is read and for each frame of an animation.
pub const MAX_COORD: f64 = 1e12;

/// Smallest size of a sphere's radius or a quad's edge, relative to `1 m +` the largest
/// |coordinate| of the point it is placed at ([`min_size`]): ten times the offset of a ray
/// spawned from a surface there (`trace::SPAWN_EPS`, 1e-7 of the same scale). A smaller
/// shape can be skipped by the rays that leave it, and its own f64 arithmetic (differences
/// of coordinates of that scale) has lost its digits: a sphere of radius 1e-100 m at 1 m
/// gave NaN normals.
pub const MIN_SIZE: f64 = 1e-6;

/// The smallest size (m) of a shape placed at `at` ([`MIN_SIZE`]).
pub fn min_size(at: DVec3) -> f64 {
    MIN_SIZE * (1.0 + at.abs().max_element())
}

impl Prim {
    /// The largest |coordinate| the primitive reaches over the times `t0..t1` (∞ where its
    /// motion overflows).
    pub fn reach(&self, t0: f64, t1: f64) -> f64 {
        let (a0, b0) = self.bounds_at(t0);
        let (a1, b1) = self.bounds_at(t1);
        let m = a0.abs().max(b0.abs()).max(a1.abs()).max(b1.abs());
        if m.is_finite() {
            m.max_element()
        } else {
            f64::INFINITY
        }
    }

    fn bounds_at(&self, t: f64) -> (DVec3, DVec3) {
        let off = self.velocity * t;
        match self.shape {
            Shape::Sphere { center, radius, .. } => (
                center + off - DVec3::splat(radius),
                center + off + DVec3::splat(radius),
            ),
            Shape::Triangle { v, .. } => (v[0].min(v[1]).min(v[2]) + off, v[0].max(v[1]).max(v[2]) + off),
        }
    }

    /// The bits of the corners of the box the BVH holds: equal for primitives whose boxes the BVH
    /// builder cannot tell apart.
    pub fn box_key(&self, t0: f64, t1: f64) -> [u32; 6] {
        let b = self.aabb(t0, t1);
        let (lo, hi) = (b.min.to_array(), b.max.to_array());
        [lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]].map(f32::to_bits)
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
            Shape::Sphere { center, radius, .. } => {
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
        // The point at rest (shapes move rigidly: their coordinates move with them).
        let q = p - self.velocity * time;
        let mut velocity = self.velocity;
        let (n_out, ns_out, curvature, uv, dpduv) = match self.shape {
            Shape::Sphere { center, radius, spin } => {
                let n = (q - center) / radius;
                // The surface's own direction of the point: turned back by the spin.
                let (turn, m) = if spin == DVec3::ZERO {
                    (None, n)
                } else {
                    velocity += spin.cross(q - center);
                    let turn = glam::DQuat::from_scaled_axis(spin * time);
                    (Some(turn), turn.inverse() * n)
                };
                // Longitude u from +x towards −z, latitude v from the south pole (−y): seen
                // from outside, u runs to the right and v up (∂p/∂u × ∂p/∂v points out of
                // the sphere), so an image reads as it does on a quad, not mirrored.
                let phi = (-m.z).atan2(m.x);
                let theta = m.y.clamp(-1.0, 1.0).acos();
                let (sp, cp, st, ct) = (phi.sin(), phi.cos(), theta.sin(), theta.cos());
                let uv = DVec2::new(0.5 + phi / (2.0 * PI), 1.0 - theta / PI);
                let dpdu = DVec3::new(-st * sp, 0.0, -st * cp) * (2.0 * PI * radius);
                let dpdv = -DVec3::new(ct * cp, -st, -ct * sp) * (PI * radius);
                let dpduv = match turn {
                    Some(r) => [r * dpdu, r * dpdv],
                    None => [dpdu, dpdv],
                };
                (n, n, Bend::isotropic(1.0 / radius, n), uv, dpduv)
            }
            Shape::Triangle { v, n, uv, bend } => {
                let (e1, e2) = (v[1] - v[0], v[2] - v[0]);
                let area = e1.cross(e2);
                let ng = area.normalize();
                // Barycentric weights of the hit at rest.
                let a2 = area.length_squared().max(1e-300);
                let b1 = (q - v[0]).cross(e2).dot(area) / a2;
                let b2 = e1.cross(q - v[0]).dot(area) / a2;
                let b0 = 1.0 - b1 - b2;
                let ns = match n {
                    Some(vn) => {
                        let s = (vn[0] * b0 + vn[1] * b1 + vn[2] * b2).normalize_or_zero();
                        if s == DVec3::ZERO { ng } else { s }
                    }
                    None => ng,
                };
                let (uvh, dp) = match uv {
                    Some(c) => (c[0] * b0 + c[1] * b1 + c[2] * b2, triangle_dpduv(e1, e2, c)),
                    None => (DVec2::ZERO, [DVec3::ZERO; 2]),
                };
                (ng, ns, bend, uvh, dp)
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
            curvature: if front { curvature } else { curvature.flipped() },
            velocity,
            material: self.material,
            light: self.light,
            uv,
            dpduv,
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

    /// The same primitives under a BVH for the times `t0..t1` (an animation's frame).
    pub fn retimed(&self, t0: f64, t1: f64) -> Geometry {
        Geometry::new(self.prims.clone(), t0, t1)
    }

    /// The largest |coordinate| any primitive reaches over the times `t0..t1`.
    pub fn reach(&self, t0: f64, t1: f64) -> f64 {
        reach(&self.prims, t0, t1)
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

    /// Whether anything lies on the ray in `(tmin, tmax)` at `time`; the primitives of
    /// light `except` are not looked at (a shadow ray towards a point sampled on that
    /// light: an emitter is convex, so nothing of it lies before the point, and a ray that
    /// grazes its outline would otherwise find it there by rounding, which darkened a
    /// sphere light's direct light by 0.6% at a radius of 0.3 of its distance; the test
    /// `a_furnace_of_any_depth_matches_its_closed_form`).
    pub fn occluded(&self, o: DVec3, d: DVec3, time: f64, tmin: f64, tmax: f64, except: Option<u32>) -> bool {
        if self.prims.is_empty() {
            return false;
        }
        let ray = Ray::new(v3a(o), v3a(d), tmin as f32, tmax.min(f32::MAX as f64) as f32);
        !self.bvh.ray_traverse_miss(ray, |_, id| {
            if except.is_some() && self.prims[id].light == except {
                return f32::INFINITY;
            }
            match self.prims[id].intersect(o, d, time, tmin, tmax) {
                Some(t) => t as f32,
                None => f32::INFINITY,
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A triangle of three points on a surface, with the surface's normals there.
    fn on(f: impl Fn(f64, f64) -> (DVec3, DVec3), pts: [(f64, f64); 3]) -> ([DVec3; 3], [DVec3; 3], DVec3) {
        let v = pts.map(|(s, t)| f(s, t).0);
        let n = pts.map(|(s, t)| f(s, t).1);
        let ng = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
        let ng = if ng.dot(n[0] + n[1] + n[2]) < 0.0 { -ng } else { ng };
        (v, n, ng)
    }

    /// A sphere's texture reads from outside as an image does on a quad: `u` grows to the
    /// viewer's right and `v` up, wherever the viewer stands, so `∂p/∂u × ∂p/∂v` points out
    /// of the sphere (the old longitude, from +x towards +z, mirrored every image), and the
    /// derivatives are those of the coordinates (finite differences along the surface).
    #[test]
    fn a_sphere_texture_is_not_mirrored() {
        let (c, r) = (DVec3::new(0.3, -0.2, 0.5), 0.7);
        let prim = Prim {
            shape: Shape::Sphere {
                center: c,
                radius: r,
                spin: DVec3::ZERO,
            },
            velocity: DVec3::ZERO,
            material: 0,
            light: None,
        };
        // The hit of a ray from outside, towards the centre, from direction `dir`.
        let at = |dir: DVec3| {
            let o = c + 3.0 * dir.normalize();
            prim.hit(o, -dir.normalize(), 3.0 - r, 0.0)
        };
        for dir in [
            DVec3::Z,
            DVec3::X,
            -DVec3::Z,
            DVec3::new(-1.0, 0.4, 0.3),
            DVec3::new(0.2, -0.7, -0.5),
        ] {
            let h = at(dir);
            let [du, dv] = h.dpduv;
            assert!(du.cross(dv).dot(h.n) > 0.0, "{dir}: {:?}", h.dpduv);
            // The viewer's right, for a view along −dir with +y up.
            let right = (-dir).cross(DVec3::Y).normalize();
            let step = 1e-4;
            let beside = at(dir.normalize() + right * step);
            let above = at(dir.normalize() + DVec3::Y * step);
            assert!(
                beside.uv.x > h.uv.x && above.uv.y > h.uv.y,
                "{dir}: {:?} {:?} {:?}",
                h.uv,
                beside.uv,
                above.uv
            );
            // ∂p/∂u predicts where a small step in u lands.
            let d = beside.uv - h.uv;
            let predicted = h.p + du * d.x + dv * d.y;
            assert!((predicted - beside.p).length() < 1e-3 * step * r, "{dir}");
        }
    }

    #[test]
    fn a_smooth_shaded_triangle_has_its_surface_curvature() {
        // A sphere of radius 2: 1/2 both ways, at any orientation.
        let sphere = |s: f64, t: f64| {
            let n = DVec3::new(s.cos() * t.sin(), t.cos(), s.sin() * t.sin());
            (DVec3::new(1.0, -3.0, 0.5) + 2.0 * n, n)
        };
        for pts in [
            [(0.1, 1.0), (0.15, 1.02), (0.12, 1.07)],
            [(2.0, 0.6), (2.1, 0.5), (2.05, 0.7)],
        ] {
            let (v, n, ng) = on(sphere, pts);
            let b = shading_curvature(v, n, ng);
            assert!((b.k1 - 0.5).abs() < 1e-9 && (b.k2 - 0.5).abs() < 1e-9, "{b:?}");
            // Seen with the geometric normal the other way, concave; normals flipped, the same.
            let b = shading_curvature(v, n, -ng);
            assert!((b.k1 + 0.5).abs() < 1e-9 && (b.k2 + 0.5).abs() < 1e-9, "{b:?}");
            let b = shading_curvature(v, n.map(|x| -x), ng);
            assert!((b.k1 - 0.5).abs() < 1e-9 && (b.k2 - 0.5).abs() < 1e-9, "{b:?}");
        }
        // A cylinder of radius 0.25 along z: 4 around it, 0 along its axis.
        let cyl = |s: f64, z: f64| {
            let n = DVec3::new(s.cos(), s.sin(), 0.0);
            (0.25 * n + DVec3::Z * z, n)
        };
        let (v, n, ng) = on(cyl, [(0.3, 0.0), (0.35, 0.1), (0.31, 0.2)]);
        let b = shading_curvature(v, n, ng);
        assert!((b.k1 - 4.0).abs() < 1e-2 && b.k2.abs() < 1e-2, "{b:?}");
        assert!(b.dir1.dot(DVec3::Z).abs() < 1e-3 && (b.dir1.length() - 1.0).abs() < 1e-12);
        // A saddle z = (x² − 3y²)/2 at the origin, normal up: it bends towards the normal
        // along x (−1) and away from it along y (3).
        let saddle = |x: f64, y: f64| {
            let n = DVec3::new(-x, 3.0 * y, 1.0).normalize();
            (DVec3::new(x, y, 0.5 * (x * x - 3.0 * y * y)), n)
        };
        let pts = [(-0.01, -0.01), (0.012, -0.008), (0.0, 0.011)];
        let (v, n, ng) = on(saddle, pts);
        let b = shading_curvature(v, n, ng);
        assert!((b.k1 - 3.0).abs() < 0.05 && (b.k2 + 1.0).abs() < 0.05, "{b:?}");
        assert!(b.dir1.dot(DVec3::Y).abs() > 0.999, "{b:?}");
        // Turned by 30° about z: the direction turns with it.
        let turned = |x: f64, y: f64| {
            let r = glam::DQuat::from_rotation_z(std::f64::consts::FRAC_PI_6);
            let (p, n) = saddle(x, y);
            (r * p, r * n)
        };
        let (v, n, ng) = on(turned, pts);
        let b = shading_curvature(v, n, ng);
        let want = glam::DQuat::from_rotation_z(std::f64::consts::FRAC_PI_6) * DVec3::Y;
        assert!(
            (b.k1 - 3.0).abs() < 0.05 && b.dir1.dot(want).abs() > 0.999,
            "{b:?}"
        );
        // Normals that turn by 90° over a micrometre: bounded as the smallest sphere there.
        let tiny = [DVec3::ZERO, DVec3::X * 1e-6, DVec3::Y * 1e-6];
        let b = shading_curvature(tiny, [DVec3::Z, DVec3::X, DVec3::Y], DVec3::Z);
        assert!(b.k1.abs() > 1e5, "{b:?}");
        let b = b.bounded(1.0 / min_size(DVec3::ZERO));
        assert!(
            b.k1.abs() <= 1e6 && b.k2.abs() <= 1e6 && b.k1.abs() == 1e6,
            "{b:?}"
        );
        // Flat shading, and a degenerate triangle: flat.
        let z = [DVec3::Z; 3];
        let b = shading_curvature([DVec3::ZERO, DVec3::X, DVec3::Y], z, DVec3::Z);
        assert_eq!((b.k1, b.k2), (0.0, 0.0));
        let line = [DVec3::ZERO, DVec3::X, 2.0 * DVec3::X];
        let b = shading_curvature(line, [DVec3::Z, DVec3::Y, DVec3::X], DVec3::Z);
        assert_eq!((b.k1, b.k2), (0.0, 0.0));
    }
}
