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
        blocks: Vec::new(),
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
        normal: None,
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
            twist: false,
        }),
        normal: None,
        impact: ImpactLaw::Momentum,
    }
}

/// Housner's block: half-width b (x), half-height h, depth 2b along y, on the ground, rocking about
/// y with P⁺ = (b, 0, 0): a positive rotation about +y moves +x points down, so for a positive
/// angle the block rocks on its +x edge.
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
        symmetry: Vec::new(),
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
        symmetry: Vec::new(),
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
        let mut d = crate::closure::perpendicular(&u) * rng.uniform(0.1, 0.5);
        // The child's centre must lie clearly off the joint face through the two pivot lines
        // (the model refuses a face through it): if it lies near, turn the face about u by 90°.
        let off = |d: &Vector3<f64>| u.cross(d).normalize().dot(&(child_com - joint)).abs();
        if off(&d) < 1e-3 * (child_com - joint).norm() {
            d = u.cross(&d);
        }
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

/// A hinge with two pivot points `a`, `b`, oriented by the rule the model checks: P⁺ is the one
/// about which a positive rotation lifts the other towards the child's centre `child_com`.
pub fn oriented_hinge(
    name: &str,
    parent: &str,
    child: &str,
    axis: Vector3<f64>,
    a: Vector3<f64>,
    b: Vector3<f64>,
    child_com: Vector3<f64>,
) -> InterfaceSpec {
    let (pos, neg) = if axis.cross(&(b - a)).dot(&(child_com - a)) > 0.0 {
        (a, b)
    } else {
        (b, a)
    };
    hinge(name, parent, child, axis.into(), pos.into(), neg.into())
}

fn centroid(b: &BodySpec) -> Vector3<f64> {
    let shape = b.own_shapes().pop().expect("fixture bodies have one shape");
    shape
        .mass_properties()
        .expect("fixture shapes are valid")
        .centroid
}

/// A trilithon (Greek temple front, Makris & Vassiliou 2013): two identical columns 2b × 2h (depth
/// 2b) with centres `spacing` apart, and an architrave of height `beam_height` resting on their top
/// corners, spanning their outer faces, with mass ratio γ = m_beam / (2 m_column). All interfaces
/// rock about y with P⁺ on the +x edge. Coordinates: `base_left`, `top_left` (architrave on the
/// left column), `base_right`; `top_right` closes the loop.
pub fn trilithon(b: f64, h: f64, spacing: f64, beam_height: f64, gamma: f64) -> StructureSpec {
    let rho = 2500.0;
    let (xl, xr) = (-spacing / 2.0, spacing / 2.0);
    let d = 2.0 * b;
    let m_col = rho * 2.0 * b * 2.0 * h * d;
    let span = spacing + 2.0 * b;
    let rho_beam = gamma * 2.0 * m_col / (span * beam_height * d);
    let body = vec![
        box_body("column_left", rho, [xl, 0.0, h], [2.0 * b, d, 2.0 * h]),
        box_body("column_right", rho, [xr, 0.0, h], [2.0 * b, d, 2.0 * h]),
        box_body(
            "architrave",
            rho_beam,
            [0.0, 0.0, 2.0 * h + beam_height / 2.0],
            [span, d, beam_height],
        ),
    ];
    let y = [0.0, 1.0, 0.0];
    let interface = vec![
        hinge(
            "base_left",
            "ground",
            "column_left",
            y,
            [xl + b, 0.0, 0.0],
            [xl - b, 0.0, 0.0],
        ),
        hinge(
            "base_right",
            "ground",
            "column_right",
            y,
            [xr + b, 0.0, 0.0],
            [xr - b, 0.0, 0.0],
        ),
        hinge(
            "top_left",
            "column_left",
            "architrave",
            y,
            [xl + b, 0.0, 2.0 * h],
            [xl - b, 0.0, 2.0 * h],
        ),
        hinge(
            "top_right",
            "column_right",
            "architrave",
            y,
            [xr + b, 0.0, 2.0 * h],
            [xr - b, 0.0, 2.0 * h],
        ),
    ];
    StructureSpec {
        name: "trilithon".into(),
        gravity: crate::spec::DEFAULT_GRAVITY,
        body,
        interface,
        symmetry: Vec::new(),
    }
}

/// A voussoir of a semicircular arch in the x–z plane: the annular sector of `radii` = (inner,
/// outer, depth along y) between the angles `span` = (from, to) from +x, turning about −y (the
/// convention of `examples/models/arch.toml`).
fn voussoir(name: &str, density: f64, radii: (f64, f64, f64), span: (f64, f64)) -> BodySpec {
    BodySpec {
        name: name.into(),
        density: Some(density),
        mass: None,
        box_shape: None,
        polyhedron: None,
        prism: None,
        annular_sector: Some(AnnularSectorShape {
            center: [0.0, 0.0, 0.0],
            axis: [0.0, -1.0, 0.0],
            inner_radius: radii.0,
            outer_radius: radii.1,
            start: [1.0, 0.0, 0.0],
            from_angle: span.0,
            to_angle: span.1,
            thickness: radii.2,
        }),
        blocks: Vec::new(),
    }
}

/// A semicircular arch of three voussoirs (annular sectors of radii `r_in`, `r_out`, depth
/// `depth` along y, springings on z = 0 at x = ±r) with joints at 0°, 60°, 120° and 180° from
/// the +x springing. With `two_sided`, every joint can pivot on its intrados or extrados (P⁺ and
/// P⁻ assigned by the sign rule); otherwise each is a plain hinge alternating extrados, intrados,
/// extrados, intrados — the four-hinge mechanism. Coordinates: `springing_right`, `joint_60`,
/// `joint_120`; `springing_left` closes the loop.
pub fn four_hinge_arch(r_in: f64, r_out: f64, depth: f64, two_sided: bool) -> StructureSpec {
    let deg = std::f64::consts::PI / 180.0;
    let names = ["v1", "v2", "v3"];
    let body: Vec<BodySpec> = (0..3)
        .map(|k| {
            let (from, to) = (60.0 * deg * k as f64, 60.0 * deg * (k + 1) as f64);
            voussoir(names[k], 2200.0, (r_in, r_out, depth), (from, to))
        })
        .collect();
    let coms: Vec<Vector3<f64>> = body.iter().map(centroid).collect();
    let at = |beta: f64, r: f64| Vector3::new(r * (beta * deg).cos(), 0.0, r * (beta * deg).sin());
    let joints = [
        ("springing_right", "ground", 0usize, 0.0, true),
        ("joint_60", "v1", 1, 60.0, false),
        ("joint_120", "v2", 2, 120.0, true),
        ("springing_left", "ground", 2, 180.0, false),
    ];
    let interface = joints
        .iter()
        .map(|&(name, parent, child, beta, extrados)| {
            let (inn, out) = (at(beta, r_in), at(beta, r_out));
            if two_sided {
                oriented_hinge(
                    name,
                    parent,
                    names[child],
                    Vector3::y(),
                    inn,
                    out,
                    coms[child],
                )
            } else {
                let p: [f64; 3] = if extrados { out.into() } else { inn.into() };
                hinge(name, parent, names[child], [0.0, 1.0, 0.0], p, p)
            }
        })
        .collect();
    StructureSpec {
        name: "four_hinge_arch".into(),
        gravity: crate::spec::DEFAULT_GRAVITY,
        body,
        interface,
        symmetry: Vec::new(),
    }
}

/// A 2×2 colonnade (baldachin): four identical columns 2b × 2b × 2h at (±s, ±s) on rocking bases,
/// under a slab of thickness `slab` joined to each column top by a rocking base. Coordinates: the
/// four bases' tilts and the slab's on the first column; three top contacts close loops.
///
/// The bases tilt about x then y (e₁ = x, e₂ = y); the tops about y then −x (first edge along y),
/// so that the slab's rotation relative to a column, R_y(θ₁)R_x(−θ₂), can undo the column's
/// R_x(φ₁)R_y(φ₂) exactly (θ₁ = −φ₂, θ₂ = φ₁): the slab translates without rotating, the loops
/// close for finite tilts in both directions and DOF(2) = 2 holds away from rest too. With the
/// same order at both ends the slab would have to twist to follow a tilt in both directions.
pub fn colonnade(b: f64, h: f64, s: f64, slab: f64) -> StructureSpec {
    colonnade_with_top_order(b, h, s, slab, true)
}

/// [`colonnade`] with the tops' first edge along y (`swapped`, the consistent order) or along x
/// (the same order as the bases: the loops then close only to first order at rest).
pub fn colonnade_with_top_order(b: f64, h: f64, s: f64, slab: f64, swapped: bool) -> StructureSpec {
    let square = |x: f64, y: f64, z: f64| -> [[f64; 3]; 4] {
        [
            [x - b, y - b, z],
            [x + b, y - b, z],
            [x + b, y + b, z],
            [x - b, y + b, z],
        ]
    };
    let top_square = |x: f64, y: f64, z: f64| -> [[f64; 3]; 4] {
        let c = square(x, y, z);
        if swapped { [c[0], c[3], c[2], c[1]] } else { c }
    };
    let pos = [(-s, -s), (s, -s), (s, s), (-s, s)];
    let mut body: Vec<BodySpec> = pos
        .iter()
        .enumerate()
        .map(|(k, &(x, y))| {
            box_body(
                &format!("column_{}", k + 1),
                2500.0,
                [x, y, h],
                [2.0 * b, 2.0 * b, 2.0 * h],
            )
        })
        .collect();
    let w = 2.0 * (s + b);
    body.push(box_body(
        "slab",
        2500.0,
        [0.0, 0.0, 2.0 * h + slab / 2.0],
        [w, w, slab],
    ));
    let mut interface: Vec<InterfaceSpec> = pos
        .iter()
        .enumerate()
        .map(|(k, &(x, y))| {
            rocking_base(
                &format!("base_{}", k + 1),
                "ground",
                &format!("column_{}", k + 1),
                square(x, y, 0.0),
            )
        })
        .collect();
    interface.extend(pos.iter().enumerate().map(|(k, &(x, y))| {
        rocking_base(
            &format!("top_{}", k + 1),
            &format!("column_{}", k + 1),
            "slab",
            top_square(x, y, 2.0 * h),
        )
    }));
    StructureSpec {
        name: "colonnade".into(),
        gravity: crate::spec::DEFAULT_GRAVITY,
        body,
        interface,
        symmetry: Vec::new(),
    }
}

/// A spatial loop of three bodies and four plain hinges with non-parallel axes: rigid (DOF(2) = 0).
pub fn skew_four_hinge_loop() -> StructureSpec {
    let body = vec![
        box_body("a", 2000.0, [0.0, 0.0, 0.5], [0.2, 0.2, 1.0]),
        box_body("b", 2000.0, [0.5, 0.0, 1.0], [1.0, 0.2, 0.2]),
        box_body("c", 2000.0, [1.0, 0.0, 0.5], [0.2, 0.2, 1.0]),
    ];
    let interface = vec![
        hinge(
            "h1",
            "ground",
            "a",
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0],
            [0.0, 0.0, 0.0],
        ),
        hinge(
            "h2",
            "a",
            "b",
            [0.3, 1.0, 0.2],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, 1.0],
        ),
        hinge(
            "h3",
            "b",
            "c",
            [-0.2, 1.0, 0.4],
            [1.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
        ),
        hinge(
            "h4",
            "ground",
            "c",
            [0.1, 1.0, -0.3],
            [1.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
        ),
    ];
    StructureSpec {
        name: "skew_loop".into(),
        gravity: crate::spec::DEFAULT_GRAVITY,
        body,
        interface,
        symmetry: Vec::new(),
    }
}

/// A double pendulum of two boxes 0.1 × 0.1 × 1 m hanging from plain hinges about y.
pub fn double_pendulum() -> StructureSpec {
    StructureSpec {
        name: "double_pendulum".into(),
        gravity: crate::spec::DEFAULT_GRAVITY,
        body: vec![
            box_body("upper", 1000.0, [0.0, 0.0, -0.5], [0.1, 0.1, 1.0]),
            box_body("lower", 1000.0, [0.0, 0.0, -1.5], [0.1, 0.1, 1.0]),
        ],
        interface: vec![
            hinge(
                "shoulder",
                "ground",
                "upper",
                [0.0, 1.0, 0.0],
                [0.0; 3],
                [0.0; 3],
            ),
            hinge(
                "elbow",
                "upper",
                "lower",
                [0.0, 1.0, 0.0],
                [0.0, 0.0, -1.0],
                [0.0, 0.0, -1.0],
            ),
        ],
        symmetry: Vec::new(),
    }
}

/// A serial chain of `n` boxes stacked along z, each on a plain hinge whose axis turns by 40°
/// about z from one to the next (non-parallel axes), hanging below the ground so that it swings.
pub fn serial_chain(n: usize) -> StructureSpec {
    let mut body = Vec::new();
    let mut interface = Vec::new();
    for k in 0..n {
        let z = -(k as f64) * 0.5;
        body.push(box_body(
            &format!("link{k}"),
            1000.0,
            [0.05 * (k % 3) as f64, 0.0, z - 0.25],
            [0.2, 0.15, 0.5],
        ));
        let a = 40f64.to_radians() * k as f64;
        let parent = if k == 0 {
            "ground".to_string()
        } else {
            format!("link{}", k - 1)
        };
        interface.push(hinge(
            &format!("j{k}"),
            &parent,
            &format!("link{k}"),
            [a.cos(), a.sin(), 0.0],
            [0.0, 0.0, z],
            [0.0, 0.0, z],
        ));
    }
    StructureSpec {
        name: format!("serial_chain_{n}"),
        gravity: crate::spec::DEFAULT_GRAVITY,
        body,
        interface,
        symmetry: Vec::new(),
    }
}

/// A planar colonnade in the x–z plane: `columns` columns of `drums` drums each (2b × 2b × h_d,
/// b = 0.3 m, h_d = 1.3 m, at x = 2.5 m·i), every bed a hinge about +y with P⁺ at the +x edge,
/// and an architrave (0.6 m high, 2b deep) between each pair of neighbouring columns, resting on
/// the right half of the left column's top and the left half of the right column's: `columns − 1`
/// architraves, each on its left column in the tree and closing a loop on its right one. Bodies
/// `c{i}_d{j}` and `a{i}`, interfaces `c{i}_bed{j}`, `a{i}_on_c{i}` and `a{i}_on_c{i+1}`. The
/// family on which the cost of loops is measured as it grows (benches/simulation.rs).
pub fn colonnade_row(columns: usize, drums: usize) -> StructureSpec {
    let (b, h_d, spacing, h_a) = (0.3, 1.3, 2.5, 0.6);
    let about_y = [0.0, 1.0, 0.0];
    let mut body = Vec::new();
    let mut interface = Vec::new();
    for i in 0..columns {
        let x = i as f64 * spacing;
        for j in 0..drums {
            let name = format!("c{i}_d{j}");
            let z = j as f64 * h_d;
            body.push(box_body(
                &name,
                2500.0,
                [x, 0.0, z + 0.5 * h_d],
                [2.0 * b, 2.0 * b, h_d],
            ));
            let parent = if j == 0 {
                "ground".to_string()
            } else {
                format!("c{i}_d{}", j - 1)
            };
            interface.push(hinge(
                &format!("c{i}_bed{j}"),
                &parent,
                &name,
                about_y,
                [x + b, 0.0, z],
                [x - b, 0.0, z],
            ));
        }
    }
    let top = drums as f64 * h_d;
    let last = drums.saturating_sub(1);
    for i in 0..columns.saturating_sub(1) {
        let (x0, x1) = (i as f64 * spacing, (i + 1) as f64 * spacing);
        let name = format!("a{i}");
        body.push(box_body(
            &name,
            2500.0,
            [0.5 * (x0 + x1), 0.0, top + 0.5 * h_a],
            [x1 - x0, 2.0 * b, h_a],
        ));
        interface.push(hinge(
            &format!("a{i}_on_c{i}"),
            &format!("c{i}_d{last}"),
            &name,
            about_y,
            [x0 + b, 0.0, top],
            [x0, 0.0, top],
        ));
        interface.push(hinge(
            &format!("a{i}_on_c{}", i + 1),
            &format!("c{}_d{last}", i + 1),
            &name,
            about_y,
            [x1, 0.0, top],
            [x1 - b, 0.0, top],
        ));
    }
    StructureSpec {
        name: format!("colonnade_row_{columns}x{drums}"),
        gravity: crate::spec::DEFAULT_GRAVITY,
        body,
        interface,
        symmetry: Vec::new(),
    }
}

/// Several structures side by side as one: part i is `parts[i]` translated by `spacing`·i along
/// x, its body and interface names prefixed with `p<i>_`. Nothing joins the parts (each keeps its
/// own interfaces to the ground), so the model has at least `parts.len()` connected parts.
pub fn forest(parts: &[StructureSpec], spacing: f64) -> StructureSpec {
    let mut out = StructureSpec {
        name: "forest".into(),
        gravity: crate::spec::DEFAULT_GRAVITY,
        body: Vec::new(),
        interface: Vec::new(),
        symmetry: Vec::new(),
    };
    for (i, spec) in parts.iter().enumerate() {
        let moved = transformed(
            spec,
            &Matrix3::identity(),
            &Vector3::new(spacing * i as f64, 0.0, 0.0),
        );
        let name = |n: &str| format!("p{i}_{n}");
        for mut b in moved.body {
            b.name = name(&b.name);
            out.body.push(b);
        }
        for mut f in moved.interface {
            f.name = name(&f.name);
            if f.parent != "ground" {
                f.parent = name(&f.parent);
            }
            f.child = name(&f.child);
            out.interface.push(f);
        }
        for mut s in moved.symmetry {
            s.coordinates = [name(&s.coordinates[0]), name(&s.coordinates[1])];
            out.symmetry.push(s);
        }
    }
    out
}

/// Density of the masonry fixtures below ([`voussoir_arch`], [`stacked_panel`],
/// [`running_bond_wall`], [`running_bond_wall_3d`]) (kg/m³).
pub const MASONRY_DENSITY: f64 = 2000.0;

/// A semicircular arch of `n` voussoirs of equal angle π/n: annular sectors of radii `r_in`,
/// `r_out` and depth `depth` along y, centred on the origin in the x–z plane (the convention of
/// `examples/models/arch.toml`: axis −y, angle 0 along +x, so angle β is the point
/// (r cos β, 0, r sin β)), springings on z = 0 at x = ±r. Voussoir `v{k}` (k = 1 … n) spans
/// [(k − 1)π/n, kπ/n]. Every radial joint is a hinge about +y that pivots on its extrados or its
/// intrados: `springing_right` (ground → `v1`, at 0), `joint_{j}` (`v{j}` → `v{j+1}`, at jπ/n) and
/// `springing_left` (ground → `v{n}`, at π). The child is the voussoir of larger index (or the
/// arch above the ground at a springing), and P⁺, P⁻ are chosen so that the face normal
/// n = u × (P⁻ − P⁺)/|…| points into it: P⁺ the extrados and P⁻ the intrados at the springing
/// at 0 and at the inner joints (n the direction of increasing angle), P⁺ the intrados and P⁻ the
/// extrados at the springing at π (n = +z). Density [`MASONRY_DENSITY`].
pub fn voussoir_arch(n: usize, r_in: f64, r_out: f64, depth: f64) -> StructureSpec {
    assert!(n >= 1, "an arch needs at least one voussoir");
    let step = std::f64::consts::PI / n as f64;
    let body: Vec<BodySpec> = (0..n)
        .map(|k| {
            let to = if k + 1 == n {
                std::f64::consts::PI
            } else {
                step * (k + 1) as f64
            };
            let name = format!("v{}", k + 1);
            voussoir(
                &name,
                MASONRY_DENSITY,
                (r_in, r_out, depth),
                (step * k as f64, to),
            )
        })
        .collect();
    // The point at radius r on the joint j (angle jπ/n, exact at the springings).
    let at = |j: usize, r: f64| -> [f64; 3] {
        if j == 0 {
            [r, 0.0, 0.0]
        } else if j == n {
            [-r, 0.0, 0.0]
        } else {
            let beta = step * j as f64;
            [r * beta.cos(), 0.0, r * beta.sin()]
        }
    };
    let y = [0.0, 1.0, 0.0];
    let mut interface = Vec::with_capacity(n + 1);
    interface.push(hinge(
        "springing_right",
        "ground",
        "v1",
        y,
        at(0, r_out),
        at(0, r_in),
    ));
    for j in 1..n {
        interface.push(hinge(
            &format!("joint_{j}"),
            &format!("v{j}"),
            &format!("v{}", j + 1),
            y,
            at(j, r_out),
            at(j, r_in),
        ));
    }
    interface.push(hinge(
        "springing_left",
        "ground",
        &format!("v{n}"),
        y,
        at(n, r_in),
        at(n, r_out),
    ));
    StructureSpec {
        name: format!("voussoir_arch_{n}"),
        gravity: crate::spec::DEFAULT_GRAVITY,
        body,
        interface,
        symmetry: Vec::new(),
    }
}

/// A panel of half-width `b` (x), total height `2h` and depth `depth` (y) standing on the ground
/// at z = 0, cut into `courses` equal courses `course{k}` (k = 0 from the bottom). Each course
/// rests on the one below (the bottom one on the ground) by a hinge `bed{k}` about +y with
/// P⁺ = (b, 0, z) and P⁻ = (−b, 0, z), the two bottom edges (face normal +z). With one course it
/// is a single block on the ground. Density [`MASONRY_DENSITY`].
pub fn stacked_panel(courses: usize, b: f64, h: f64, depth: f64) -> StructureSpec {
    assert!(courses >= 1, "a panel needs at least one course");
    let hc = 2.0 * h / courses as f64;
    let mut body = Vec::with_capacity(courses);
    let mut interface = Vec::with_capacity(courses);
    for k in 0..courses {
        let z = hc * k as f64;
        body.push(box_body(
            &format!("course{k}"),
            MASONRY_DENSITY,
            [0.0, 0.0, z + hc / 2.0],
            [2.0 * b, depth, hc],
        ));
        let parent = if k == 0 {
            "ground".to_string()
        } else {
            format!("course{}", k - 1)
        };
        interface.push(hinge(
            &format!("bed{k}"),
            &parent,
            &format!("course{k}"),
            [0.0, 1.0, 0.0],
            [b, 0.0, z],
            [-b, 0.0, z],
        ));
    }
    StructureSpec {
        name: format!("stacked_panel_{courses}"),
        gravity: crate::spec::DEFAULT_GRAVITY,
        body,
        interface,
        symmetry: Vec::new(),
    }
}

/// One block of a running-bond wall: its name and its extent along x and z.
struct WallBlock {
    name: String,
    x: [f64; 2],
    z: [f64; 2],
}

/// One bed-joint contact of a running-bond wall: the block below (`None`: the ground), the block
/// above, and the overlap segment [x₀, x₁] at height z.
struct BedContact {
    below: Option<usize>,
    above: usize,
    x: [f64; 2],
    z: f64,
}

/// The blocks and bed-joint contacts of [`running_bond_wall`].
fn running_bond_layout(
    courses: usize,
    blocks: usize,
    block_length: f64,
    block_height: f64,
) -> (Vec<WallBlock>, Vec<BedContact>) {
    assert!(
        courses >= 1 && blocks >= 1,
        "a wall needs a course and a block"
    );
    let half_total = blocks as f64 * block_length / 2.0;
    let mut list: Vec<WallBlock> = Vec::new();
    let mut by_course: Vec<Vec<usize>> = Vec::with_capacity(courses);
    for c in 0..courses {
        // Block ends along the course, from −L_tot/2 to +L_tot/2.
        let ends: Vec<f64> = if c % 2 == 0 {
            (0..=blocks)
                .map(|i| -half_total + block_length * i as f64)
                .collect()
        } else {
            let mut e = vec![-half_total];
            e.extend((0..blocks).map(|i| -half_total + block_length * (i as f64 + 0.5)));
            e.push(half_total);
            e
        };
        let z0 = block_height * c as f64;
        let mut row = Vec::new();
        for (i, w) in ends.windows(2).enumerate() {
            row.push(list.len());
            list.push(WallBlock {
                name: format!("c{c}_b{i}"),
                x: [w[0], w[1]],
                z: [z0, z0 + block_height],
            });
        }
        by_course.push(row);
    }
    let tol = 1e-9 * block_length;
    let mut contacts = Vec::new();
    for c in 0..courses {
        for &a in &by_course[c] {
            let xa = list[a].x;
            let z = list[a].z[0];
            if c == 0 {
                contacts.push(BedContact {
                    below: None,
                    above: a,
                    x: xa,
                    z,
                });
                continue;
            }
            for &b in &by_course[c - 1] {
                let xb = list[b].x;
                let (lo, hi) = (xa[0].max(xb[0]), xa[1].min(xb[1]));
                if hi - lo > tol {
                    contacts.push(BedContact {
                        below: Some(b),
                        above: a,
                        x: [lo, hi],
                        z,
                    });
                }
            }
        }
    }
    (list, contacts)
}

/// The bodies and contacts of a running-bond wall, with the interfaces made by `joint` from
/// (name, parent, child, x₀, x₁, z).
fn running_bond_spec(
    name: &str,
    courses: usize,
    blocks: usize,
    block_length: f64,
    block_height: f64,
    depth: f64,
    joint: impl Fn(&str, &str, &str, f64, f64, f64) -> InterfaceSpec,
) -> StructureSpec {
    let (list, contacts) = running_bond_layout(courses, blocks, block_length, block_height);
    let body = list
        .iter()
        .map(|b| {
            box_body(
                &b.name,
                MASONRY_DENSITY,
                [(b.x[0] + b.x[1]) / 2.0, 0.0, (b.z[0] + b.z[1]) / 2.0],
                [b.x[1] - b.x[0], depth, b.z[1] - b.z[0]],
            )
        })
        .collect();
    let interface = contacts
        .iter()
        .map(|c| {
            let above = &list[c.above].name;
            let below = c.below.map_or("ground", |b| list[b].name.as_str());
            joint(
                &format!("{above}_on_{below}"),
                below,
                above,
                c.x[0],
                c.x[1],
                c.z,
            )
        })
        .collect();
    StructureSpec {
        name: format!("{name}_{courses}x{blocks}"),
        gravity: crate::spec::DEFAULT_GRAVITY,
        body,
        interface,
        symmetry: Vec::new(),
    }
}

/// A planar running-bond wall in the x–z plane (depth `depth` along y) standing on the ground at
/// z = 0, centred on x = 0: `courses` courses of height `block_height`; even courses (0, 2, …)
/// are `blocks` whole blocks of length `block_length`, odd courses are offset by half a block,
/// with a half block at each end, so every course spans the same length `blocks · block_length`.
/// Bodies `c{course}_b{index}` (index from −x). Every contact of a block with a block below (or
/// with the ground), over the overlap segment [x₀, x₁] at height z, is a hinge
/// `{above}_on_{below}` about +y with P⁺ = (x₁, 0, z) (the +x end) and P⁻ = (x₀, 0, z) (the −x
/// end): face normal +z, into the block above. Head joints (between blocks of one course) are not
/// contacts. Density [`MASONRY_DENSITY`].
pub fn running_bond_wall(
    courses: usize,
    blocks: usize,
    block_length: f64,
    block_height: f64,
    depth: f64,
) -> StructureSpec {
    running_bond_spec(
        "running_bond_wall",
        courses,
        blocks,
        block_length,
        block_height,
        depth,
        |name, parent, child, x0, x1, z| {
            hinge(
                name,
                parent,
                child,
                [0.0, 1.0, 0.0],
                [x1, 0.0, z],
                [x0, 0.0, z],
            )
        },
    )
}

/// [`running_bond_wall`] with rocking bases instead of hinges: every bed-joint contact is the
/// overlap rectangle [x₀, x₁] × [−depth/2, depth/2] at height z, its corners in the order of
/// [`colonnade`]'s bases, (x₀, −d/2), (x₁, −d/2), (x₁, d/2), (x₀, d/2), counter-clockwise seen from
/// above (normal +z, e₁ = x, e₂ = y).
pub fn running_bond_wall_3d(
    courses: usize,
    blocks: usize,
    block_length: f64,
    block_height: f64,
    depth: f64,
) -> StructureSpec {
    let e = depth / 2.0;
    running_bond_spec(
        "running_bond_wall_3d",
        courses,
        blocks,
        block_length,
        block_height,
        depth,
        |name, parent, child, x0, x1, z| {
            rocking_base(
                name,
                parent,
                child,
                [[x0, -e, z], [x1, -e, z], [x1, e, z], [x0, e, z]],
            )
        },
    )
}
