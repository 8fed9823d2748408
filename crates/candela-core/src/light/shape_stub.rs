//! INTERIM stand-in for the `shape` module (branch `shapes`), with exactly
//! the API the area light uses: `area`, `bounds`, `sample_area`,
//! `sample_from`, `pdf_from`. Deleted when `shapes` is merged.

use crate::interaction::Interaction;
use crate::math::{safe_sqrt, Bounds3, Frame, Vec2, Vec3, PI};
use crate::sampling::{
    pdf_area_to_solid_angle, sample_uniform_cone, sample_uniform_disk_concentric,
    sample_uniform_sphere, sample_uniform_triangle, uniform_cone_pdf, PdfArea, PdfSolidAngle,
};

/// Receiving point of a shape-sampling query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapeSampleContext {
    /// Position.
    pub p: Vec3,
    /// Error bound of `p`.
    pub p_error: Vec3,
    /// Geometric normal.
    pub n: Vec3,
    /// Shading normal.
    pub ns: Vec3,
}

/// Area-measure sample.
#[derive(Clone, Copy, Debug)]
pub struct ShapeSample {
    /// Sampled point.
    pub intr: Interaction,
    /// Density per unit area.
    pub pdf: PdfArea,
}

/// Solid-angle-measure sample.
#[derive(Clone, Copy, Debug)]
pub struct ShapeSampleSa {
    /// Sampled point.
    pub intr: Interaction,
    /// Density per unit solid angle at the reference point.
    pub pdf: PdfSolidAngle,
}

/// Interim shapes (render space).
#[derive(Clone, Debug)]
pub enum Shape {
    /// Sphere, outward normal.
    Sphere {
        /// Centre.
        center: Vec3,
        /// Radius.
        radius: f32,
    },
    /// Disk with normal `n`.
    Disk {
        /// Centre.
        center: Vec3,
        /// Unit normal.
        n: Vec3,
        /// Radius.
        radius: f32,
    },
    /// Triangle, normal (p1 − p0) × (p2 − p0).
    Triangle {
        /// Vertices.
        p: [Vec3; 3],
    },
    /// Parallelogram p0 + s·e1 + t·e2, normal e1 × e2.
    Quad {
        /// Corner.
        p0: Vec3,
        /// First edge.
        e1: Vec3,
        /// Second edge.
        e2: Vec3,
    },
}

fn surface(p: Vec3, n: Vec3) -> Interaction {
    Interaction {
        p,
        p_error: Vec3::ZERO,
        n,
        uv: Vec2::ZERO,
    }
}

impl Shape {
    /// Surface area.
    pub fn area(&self) -> f32 {
        match self {
            Shape::Sphere { radius, .. } => 4.0 * PI * radius * radius,
            Shape::Disk { radius, .. } => PI * radius * radius,
            Shape::Triangle { p } => 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length(),
            Shape::Quad { e1, e2, .. } => e1.cross(*e2).length(),
        }
    }

    /// Bounding box.
    pub fn bounds(&self) -> Bounds3 {
        match self {
            Shape::Sphere { center, radius } => Bounds3::from_points(
                *center - Vec3::splat(*radius),
                *center + Vec3::splat(*radius),
            ),
            Shape::Disk { center, radius, .. } => Bounds3::from_points(
                *center - Vec3::splat(*radius),
                *center + Vec3::splat(*radius),
            ),
            Shape::Triangle { p } => Bounds3::from_points(p[0], p[1]).union_point(p[2]),
            Shape::Quad { p0, e1, e2 } => Bounds3::from_points(*p0, *p0 + *e1)
                .union_point(*p0 + *e2)
                .union_point(*p0 + *e1 + *e2),
        }
    }

    /// Uniform point by area.
    pub fn sample_area(&self, u: Vec2) -> Option<ShapeSample> {
        let intr = match self {
            Shape::Sphere { center, radius } => {
                let n = sample_uniform_sphere(u);
                surface(*center + *radius * n, n)
            }
            Shape::Disk { center, n, radius } => {
                let d = sample_uniform_disk_concentric(u) * *radius;
                surface(*center + Frame::from_z(*n).from_local(d.extend(0.0)), *n)
            }
            Shape::Triangle { p } => {
                let b = sample_uniform_triangle(u);
                let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize();
                surface(b[0] * p[0] + b[1] * p[1] + b[2] * p[2], n)
            }
            Shape::Quad { p0, e1, e2 } => {
                surface(*p0 + u.x * *e1 + u.y * *e2, e1.cross(*e2).normalize())
            }
        };
        Some(ShapeSample {
            intr,
            pdf: PdfArea(1.0 / self.area()),
        })
    }

    /// Point as seen from `ctx`, density per solid angle.
    pub fn sample_from(&self, ctx: &ShapeSampleContext, u: Vec2) -> Option<ShapeSampleSa> {
        if let Shape::Sphere { center, radius } = self {
            let d2 = ctx.p.distance_squared(*center);
            if d2 > radius * radius {
                let d = d2.sqrt();
                let cos_max = safe_sqrt(1.0 - radius * radius / d2);
                let frame = Frame::from_z((*center - ctx.p) / d);
                let w = frame.from_local(sample_uniform_cone(u, cos_max));
                let cos_t = w.dot(frame.z);
                let ds = d * cos_t - safe_sqrt(radius * radius - d2 * (1.0 - cos_t * cos_t));
                let p = ctx.p + ds * w;
                let intr = surface(p, (p - *center).normalize());
                return Some(ShapeSampleSa {
                    intr,
                    pdf: PdfSolidAngle(uniform_cone_pdf(cos_max)),
                });
            }
        }
        let ss = self.sample_area(u)?;
        let wi = ss.intr.p - ctx.p;
        let d2 = wi.length_squared();
        if d2 == 0.0 {
            return None;
        }
        let cos = ss.intr.n.dot(wi / d2.sqrt()).abs();
        let pdf = pdf_area_to_solid_angle(ss.pdf, d2, cos);
        (pdf.0.is_finite() && pdf.0 > 0.0).then_some(ShapeSampleSa { intr: ss.intr, pdf })
    }

    /// Density of [`sample_from`](Self::sample_from) for direction `wi`.
    pub fn pdf_from(&self, ctx: &ShapeSampleContext, wi: Vec3) -> PdfSolidAngle {
        if let Shape::Sphere { center, radius } = self {
            let d2 = ctx.p.distance_squared(*center);
            if d2 > radius * radius {
                let cos_max = safe_sqrt(1.0 - radius * radius / d2);
                let cos = wi.normalize().dot((*center - ctx.p).normalize());
                return PdfSolidAngle(if cos >= cos_max {
                    uniform_cone_pdf(cos_max)
                } else {
                    0.0
                });
            }
        }
        let Some((t, n)) = self.intersect(ctx.p, wi.normalize()) else {
            return PdfSolidAngle(0.0);
        };
        let cos = n.dot(wi.normalize()).abs();
        pdf_area_to_solid_angle(PdfArea(1.0 / self.area()), t * t, cos)
    }

    /// Nearest hit along unit `d` from `o`: (t, normal).
    fn intersect(&self, o: Vec3, d: Vec3) -> Option<(f32, Vec3)> {
        let plane = |q: Vec3, n: Vec3| -> Option<(f32, Vec3)> {
            let den = d.dot(n);
            let t = (q - o).dot(n) / den;
            (den != 0.0 && t > 0.0 && t.is_finite()).then_some((t, o + t * d))
        };
        match self {
            Shape::Sphere { center, radius } => {
                let oc = o - *center;
                let b = oc.dot(d);
                let disc = b * b - (oc.length_squared() - radius * radius);
                if disc < 0.0 {
                    return None;
                }
                let (t0, t1) = (-b - disc.sqrt(), -b + disc.sqrt());
                let t = if t0 > 0.0 { t0 } else { t1 };
                (t > 0.0).then(|| (t, (o + t * d - *center).normalize()))
            }
            Shape::Disk { center, n, radius } => {
                let (t, p) = plane(*center, *n)?;
                (p.distance_squared(*center) <= radius * radius).then_some((t, *n))
            }
            Shape::Triangle { p } => {
                let n = (p[1] - p[0]).cross(p[2] - p[0]);
                let (t, x) = plane(p[0], n.normalize())?;
                let inside = (0..3).all(|i| (p[(i + 1) % 3] - p[i]).cross(x - p[i]).dot(n) >= 0.0);
                inside.then_some((t, n.normalize()))
            }
            Shape::Quad { p0, e1, e2 } => {
                let n = e1.cross(*e2);
                let (t, x) = plane(*p0, n.normalize())?;
                let r = x - *p0;
                let s = r.cross(*e2).dot(n) / n.length_squared();
                let v = e1.cross(r).dot(n) / n.length_squared();
                ((0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&v)).then_some((t, n.normalize()))
            }
        }
    }
}
