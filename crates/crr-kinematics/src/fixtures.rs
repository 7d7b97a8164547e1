//! Reference structures reused by tests, benchmarks and validation: closed-form cases and
//! reproducible random chains with non-parallel axes.

use nalgebra::{Matrix3, Rotation3, Vector3};

use crate::shapes::{AnnularSectorShape, BoxShape, PolyhedronShape, PrismShape};
use crate::spec::{BodySpec, ImpactLaw, InterfaceSpec, PivotSpec, RockingBaseSpec, StructureSpec};

/// A small deterministic generator (SplitMix64) so fixtures are reproducible from a seed.
#[derive(Clone, Debug)]
pub struct SplitMix(pub u64);

impl SplitMix {
    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [lo, hi).
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// A random unit vector.
    pub fn unit(&mut self) -> Vector3<f64> {
        loop {
            let v = Vector3::new(
                self.uniform(-1.0, 1.0),
                self.uniform(-1.0, 1.0),
                self.uniform(-1.0, 1.0),
            );
            let n = v.norm();
            if n > 0.2 && n <= 1.0 {
                return v / n;
            }
        }
    }
    /// Uniform integer in [0, n).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
}

/// A box body.
pub fn box_body(name: &str, density: f64, center: [f64; 3], size: [f64; 3]) -> BodySpec {
    BodySpec {
        name: name.into(),
        density: Some(density),
        mass: None,
        box_shape: Some(BoxShape {
            center,
            size,
            rotation: None,
        }),
        polyhedron: None,
        prism: None,
        annular_sector: None,
    }
}

/// A hinge interface.
pub fn hinge(
    name: &str,
    parent: &str,
    child: &str,
    axis: [f64; 3],
    pos: [f64; 3],
    neg: [f64; 3],
) -> InterfaceSpec {
    InterfaceSpec {
        name: name.into(),
        parent: parent.into(),
        child: child.into(),
        axis: Some(axis),
        pivot_positive: Some(PivotSpec::Point(pos)),
        pivot_negative: Some(PivotSpec::Point(neg)),
        rocking_base: None,
        impact: ImpactLaw::Momentum,
    }
}

/// A rocking-base interface.
pub fn rocking_base(
    name: &str,
    parent: &str,
    child: &str,
    corners: [[f64; 3]; 4],
) -> InterfaceSpec {
    InterfaceSpec {
        name: name.into(),
        parent: parent.into(),
        child: child.into(),
        axis: None,
        pivot_positive: None,
        pivot_negative: None,
        rocking_base: Some(RockingBaseSpec {
            corners: corners.to_vec(),
        }),
        impact: ImpactLaw::Momentum,
    }
}

/// Housner's block: half-width b (x), half-height h, depth 2b along y, on the ground, rocking about
/// y with P⁺ = (b, 0, 0) (a positive angle about +y tips the block towards +x... see
/// `docs/model-format.md`: a positive rotation about +y moves +x points down, so the block rocks
/// on its +x edge).
pub fn single_block(b: f64, h: f64, density: f64) -> StructureSpec {
    StructureSpec {
        name: "single_block".into(),
        gravity: crate::spec::DEFAULT_GRAVITY,
        body: vec![box_body(
            "block",
            density,
            [0.0, 0.0, h],
            [2.0 * b, 2.0 * b, 2.0 * h],
        )],
        interface: vec![hinge(
            "base",
            "ground",
            "block",
            [0.0, 1.0, 0.0],
            [b, 0.0, 0.0],
            [-b, 0.0, 0.0],
        )],
    }
}

/// A random chain of `n` box bodies with non-parallel hinge axes and rocking bases, each body
/// joined to the ground or to an earlier body; with `closures`, extra interfaces between bodies
/// close loops (Φ = 0 holds at rest, q = 0). Reproducible from `seed`.
pub fn random_chain(seed: u64, n: usize, closures: usize) -> StructureSpec {
    let mut rng = SplitMix(seed);
    let mut body = Vec::new();
    let mut interface = Vec::new();
    let mut centers: Vec<Vector3<f64>> = Vec::new();
    for k in 0..n {
        let parent = if k == 0 {
            None
        } else {
            Some(rng.below(k + 1)).filter(|&p| p < k)
        };
        let base = parent.map_or(Vector3::zeros(), |p| centers[p]);
        let c = base
            + Vector3::new(
                rng.uniform(-0.5, 0.5),
                rng.uniform(-0.5, 0.5),
                rng.uniform(0.8, 1.5),
            );
        let mut b = box_body(
            &format!("b{k}"),
            rng.uniform(1000.0, 3000.0),
            c.into(),
            [
                rng.uniform(0.2, 0.8),
                rng.uniform(0.2, 0.8),
                rng.uniform(0.3, 1.2),
            ],
        );
        if let Some(bx) = b.box_shape.as_mut() {
            bx.rotation = Some((rng.unit() * rng.uniform(0.0, 1.0)).into());
        }
        body.push(b);
        centers.push(c);
        let pname = parent.map_or("ground".to_string(), |p| format!("b{p}"));
        let joint = (base + c) * 0.5 - Vector3::new(0.0, 0.0, 0.3);
        interface.push(random_interface(
            &mut rng,
            &format!("j{k}"),
            &pname,
            &format!("b{k}"),
            joint,
            c,
        ));
    }
    for m in 0..closures.min(n) {
        // A second interface of body `child` to the ground or an earlier body.
        let child = n - 1 - m;
        let parent = rng.below(child + 1);
        let pname = if parent == child {
            "ground".to_string()
        } else {
            format!("b{parent}")
        };
        let c = centers[child];
        let joint = c - Vector3::new(rng.uniform(-0.3, 0.3), rng.uniform(-0.3, 0.3), 0.6);
        interface.push(random_interface(
            &mut rng,
            &format!("c{m}"),
            &pname,
            &format!("b{child}"),
            joint,
            c,
        ));
    }
    StructureSpec {
        name: format!("random_{seed}"),
        gravity: 9.81,
        body,
        interface,
    }
}

fn random_interface(
    rng: &mut SplitMix,
    name: &str,
    parent: &str,
    child: &str,
    joint: Vector3<f64>,
    child_com: Vector3<f64>,
) -> InterfaceSpec {
    if rng.below(3) == 0 {
        // Rocking base: a rectangle through `joint` with a random normal (child on its + side).
        let mut n = rng.unit();
        if n.dot(&(child_com - joint)) < 0.0 {
            n = -n;
        }
        let e1 = crate::closure::perpendicular(&n);
        let e2 = n.cross(&e1);
        let (a, b) = (rng.uniform(0.1, 0.4), rng.uniform(0.1, 0.4));
        let corner = |s: f64, t: f64| -> [f64; 3] { (joint + e1 * (s * a) + e2 * (t * b)).into() };
        rocking_base(
            name,
            parent,
            child,
            [
                corner(-1.0, -1.0),
                corner(1.0, -1.0),
                corner(1.0, 1.0),
                corner(-1.0, 1.0),
            ],
        )
    } else {
        let u = rng.unit();
        let d = crate::closure::perpendicular(&u) * rng.uniform(0.1, 0.5);
        let (mut pos, mut neg) = (joint - d * 0.5, joint + d * 0.5);
        if u.cross(&(neg - pos)).dot(&(child_com - pos)) < 0.0 {
            std::mem::swap(&mut pos, &mut neg);
        }
        hinge(name, parent, child, u.into(), pos.into(), neg.into())
    }
}

/// The same structure moved rigidly: every point x ↦ R x + t, every direction ↦ R d.
pub fn transformed(spec: &StructureSpec, rot: &Matrix3<f64>, t: &Vector3<f64>) -> StructureSpec {
    let p = |x: &[f64; 3]| -> [f64; 3] { (rot * Vector3::from(*x) + t).into() };
    let d = |x: &[f64; 3]| -> [f64; 3] { (rot * Vector3::from(*x)).into() };
    let mut out = spec.clone();
    for b in &mut out.body {
        if let Some(bx) = &mut b.box_shape {
            let r0 =
                crate::rotation::rotation_vector(&Vector3::from(bx.rotation.unwrap_or([0.0; 3])));
            let r = Rotation3::from_matrix_unchecked(rot * r0);
            bx.rotation = Some(r.scaled_axis().into());
            bx.center = p(&bx.center);
        }
        if let Some(PolyhedronShape { vertices }) = &mut b.polyhedron {
            vertices.iter_mut().for_each(|v| *v = p(v));
        }
        if let Some(PrismShape { polygon, extrude }) = &mut b.prism {
            polygon.iter_mut().for_each(|v| *v = p(v));
            *extrude = d(extrude);
        }
        if let Some(AnnularSectorShape {
            center,
            axis,
            start,
            ..
        }) = &mut b.annular_sector
        {
            *center = p(center);
            *axis = d(axis);
            *start = d(start);
        }
    }
    for i in &mut out.interface {
        i.axis = i.axis.as_ref().map(d);
        for piv in [&mut i.pivot_positive, &mut i.pivot_negative]
            .into_iter()
            .flatten()
        {
            match piv {
                PivotSpec::Point(x) => *x = p(x),
                PivotSpec::Segment(s) => s.iter_mut().for_each(|x| *x = p(x)),
            }
        }
        if let Some(rb) = &mut i.rocking_base {
            rb.corners.iter_mut().for_each(|x| *x = p(x));
        }
    }
    out
}
