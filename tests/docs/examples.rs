//! Every model shown in the documentation is valid and says what the text says.
//!
//! Each ```` ```toml ```` block of `docs/model-format.md` (and of `README.md`, if present) is a
//! complete model file: it must parse as a `crr::input::model_file::ModelFile` (structure plus the optional
//! `[ground_motion]`, `[initial]` and `[analysis]` tables) and its structure must build with
//! `Model::from_spec`; the optional tables must be usable (ground motion built, initial state
//! solved, analysis parameters accepted). A `toml-fragment` whose first line is
//! `# appended to the "<name>" example` is appended to that example and checked the same way.
//! Each ```` ```json ```` block that is a whole object is checked the same way. Partial snippets
//! are fenced `toml-fragment` and skipped. Every model is then checked against the facts the
//! text states about it (found by the model's `name`): DOF(1), coordinate order, closure rows,
//! masses, M(0), pivot corners, Φ(0) = 0. A block whose name has no facts here fails the test, so
//! a new example cannot go unchecked. The error messages quoted in the text are regenerated and
//! must appear verbatim.

use std::path::Path;

use crr::dynamics::ground_motion::GroundMotion;
use crr::dynamics::{InitialState, solve_initial};
use crr::impact::{Parameters, Simulation};
use crr::input::model_file::ModelFile;
use crr::kinematics::{
    ActivePivots, Data, ImpactLaw, InterfaceKind, Model, Role, Side, StructureSpec,
    constraint_residual, forward_kinematics, mass_matrix,
};
use nalgebra::{DVector, Vector3};

/// A fenced block: its language tag, its text and the line of its opening fence.
struct Block {
    lang: String,
    text: String,
    line: usize,
}

fn fenced_blocks(markdown: &str) -> Vec<Block> {
    let mut out = Vec::new();
    let mut current: Option<Block> = None;
    for (k, line) in markdown.lines().enumerate() {
        let t = line.trim_start();
        match current.as_mut() {
            None => {
                if let Some(lang) = t.strip_prefix("```") {
                    current = Some(Block {
                        lang: lang.trim().to_string(),
                        text: String::new(),
                        line: k + 1,
                    });
                }
            }
            Some(b) => {
                if t.starts_with("```") {
                    out.push(current.take().expect("open block"));
                } else {
                    b.text.push_str(line);
                    b.text.push('\n');
                }
            }
        }
    }
    assert!(current.is_none(), "an unclosed code fence");
    out
}

fn read_doc(rel: &str) -> Option<String> {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)).ok()
}

/// Parses a whole model file and checks its optional tables; the structure, its model, the ground
/// motion, the solved initial state (if `[initial]` is given) and the simulation parameters.
fn build_file(at: &str, file: &ModelFile) -> Built {
    let spec = file.structure();
    let model = Model::from_spec(&spec).unwrap_or_else(|e| panic!("{at}: model is invalid: {e}"));
    let docs = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs");
    let ground = file
        .ground_motion
        .as_ref()
        .map_or_else(GroundMotion::none, |g| {
            GroundMotion::from_spec(g, &docs)
                .unwrap_or_else(|e| panic!("{at}: ground motion is invalid: {e}"))
        });
    let initial = file
        .initial
        .as_ref()
        .map(|i| solve_initial(&model, i).unwrap_or_else(|e| panic!("{at}: initial state: {e}")));
    let params = Parameters::from_analysis(&file.analysis.clone().unwrap_or_default(), 10.0)
        .unwrap_or_else(|e| panic!("{at}: analysis: {e}"));
    Built {
        at: at.to_string(),
        file: file.clone(),
        spec,
        model,
        ground,
        initial,
        params,
    }
}

/// One documented model file, built.
struct Built {
    at: String,
    file: ModelFile,
    spec: StructureSpec,
    model: Model,
    ground: GroundMotion,
    initial: Option<InitialState>,
    params: Parameters,
}

/// The models of the toml and whole-object json blocks of one document, and of the fragments
/// appended to a named example.
fn models_of(rel: &str) -> Vec<Built> {
    let Some(text) = read_doc(rel) else {
        return Vec::new();
    };
    let mut out: Vec<Built> = Vec::new();
    let mut sources: Vec<(String, String)> = Vec::new();
    for b in fenced_blocks(&text) {
        let file: ModelFile = match b.lang.as_str() {
            "toml" => toml::from_str(&b.text)
                .unwrap_or_else(|e| panic!("{rel}:{}: toml block does not parse: {e}", b.line)),
            "json" if b.text.trim_start().starts_with('{') => serde_json::from_str(&b.text)
                .unwrap_or_else(|e| panic!("{rel}:{}: json block does not parse: {e}", b.line)),
            "toml-fragment" => {
                let first = b.text.lines().next().unwrap_or("");
                let Some(name) = first
                    .strip_prefix("# appended to the \"")
                    .and_then(|r| r.strip_suffix("\" example"))
                else {
                    continue;
                };
                let (_, base) = sources
                    .iter()
                    .find(|(n, _)| n == name)
                    .unwrap_or_else(|| panic!("{rel}:{}: no example \"{name}\" above", b.line));
                let whole = format!("{base}\n{}", b.text);
                let file: ModelFile = toml::from_str(&whole).unwrap_or_else(|e| {
                    panic!(
                        "{rel}:{}: fragment appended to {name} does not parse: {e}",
                        b.line
                    )
                });
                out.push(build_file(&format!("{rel}:{} (fragment)", b.line), &file));
                continue;
            }
            _ => continue,
        };
        if b.lang == "toml" {
            sources.push((file.name.clone(), b.text.clone()));
        }
        out.push(build_file(&format!("{rel}:{} ({})", b.line, b.lang), &file));
    }
    out
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs().max(1e-300)
}

fn coord_names(m: &Model) -> Vec<&str> {
    m.coords.iter().map(|c| c.name.as_str()).collect()
}

/// M(0) and Φ(0) with every pivot on P⁺.
fn at_rest(m: &Model) -> Data {
    let mut data = Data::new(m);
    let q = DVector::zeros(m.dof());
    let pivots = ActivePivots::uniform(m, Side::Positive);
    forward_kinematics(m, &mut data, &q, &pivots);
    mass_matrix(m, &mut data);
    constraint_residual(m, &mut data, &pivots, &q);
    data
}

fn closure_rows(m: &Model) -> Vec<(&str, usize)> {
    m.closures
        .iter()
        .map(|c| (m.interfaces[c.interface].name.as_str(), c.rows))
        .collect()
}

/// The facts the text states about the model `name`. Returns false for an unknown name.
fn check_facts(built: &Built) -> bool {
    let (at, spec, m) = (built.at.as_str(), &built.spec, &built.model);
    let data = at_rest(m);
    let m00 = data.mass_matrix[(0, 0)];
    // Φ = 0 at rest for every example with loops.
    assert!(
        data.phi.amax() <= 1e-12 * m.size,
        "{at}: Φ(0) = {}",
        data.phi
    );
    match spec.name.as_str() {
        "single_block" | "rotated_block" => {
            assert_eq!(m.dof(), 1, "{at}");
            let mass = 2500.0 * 0.4 * 0.4 * 2.0;
            assert!(close(m.bodies[0].mass, 800.0, 1e-14), "{at}");
            // I₀ = (4/3) m R², R² = 0.2² + 1².
            let i0 = 4.0 / 3.0 * mass * (0.04 + 1.0);
            assert!(close(m00, i0, 1e-12), "{at}: M(0) = {m00}, I₀ = {i0}");
            assert!(close(i0, 1_109.333_333_333_333, 1e-12));
        }
        "pier_on_plinth" => {
            // A plinth 1 × 1 × 0.5 m at ρ = 2400 (1200 kg, centre 0.25 m) and a shaft
            // 0.6 × 0.6 × 2 m at ρ = 2600 (1872 kg, centre 1.5 m): 3072 kg, centre at
            // (1200·0.25 + 1872·1.5)/3072 = 3108/3072 m.
            assert_eq!(m.dof(), 1, "{at}");
            let b = &m.bodies[0];
            assert_eq!(b.shape.kind(), "compound");
            assert!(close(b.mass, 3072.0, 1e-14), "{at}");
            assert!(close(b.volume, 1.22, 1e-14), "{at}");
            assert!(close(b.com.z, 3108.0 / 3072.0, 1e-14), "{at}");
        }
        "frustum" => {
            assert_eq!(m.dof(), 1, "{at}");
            assert_eq!(m.bodies[0].shape.kind(), "polyhedron");
            assert!(close(m.bodies[0].volume, 0.98, 1e-12), "{at}");
            assert!(close(m.bodies[0].mass, 2352.0, 1e-12), "{at}");
        }
        "tapered_wall" => {
            assert_eq!(m.dof(), 1, "{at}");
            let b = &m.bodies[0];
            assert_eq!(b.shape.kind(), "prism");
            assert!(close(b.volume, 2.0, 1e-12), "{at}");
            assert!(close(b.mass, 3000.0, 1e-12), "{at}");
            assert!(close(b.density, 1500.0, 1e-12), "{at}");
            // Centroid height of the trapezoid: h (b₁ + 2b₂) / (3 (b₁ + b₂)).
            assert!(close(b.com.z, 2.0 * (0.6 + 0.8) / 3.0, 1e-12), "{at}");
        }
        "four_hinged_arch" => {
            assert_eq!(coord_names(m), ["A", "D", "B"], "{at}");
            assert_eq!(closure_rows(m), [("C", 5)], "{at}");
            assert_eq!(m.constraint_rows, 5);
            let v = 0.5 * std::f64::consts::FRAC_PI_3 * (2.5f64.powi(2) - 4.0);
            for b in &m.bodies {
                assert_eq!(b.shape.kind(), "annular_sector");
                assert!(close(b.volume, v, 1e-12), "{at}: {}", b.name);
                assert!(close(b.mass, 2000.0 * v, 1e-12), "{at}");
                assert!(close(b.mass, 2_356.194_490_192_345, 1e-9), "{at}");
            }
            // The voussoirs run from +x up through +z: the crown's centre is on +z.
            let crown = &m.bodies[m.body_index("crown").unwrap()];
            assert!(crown.com.x.abs() < 1e-12 && crown.com.z > 2.0, "{at}");
            let laws: Vec<ImpactLaw> = m.interfaces.iter().map(|i| i.impact).collect();
            assert_eq!(
                laws,
                [
                    ImpactLaw::Momentum,
                    ImpactLaw::Restitution(0.9),
                    ImpactLaw::Dirac { r: 0.9, c: 1.0 },
                    ImpactLaw::DiracRegularised {
                        r: 0.9,
                        c: 1.0,
                        width: 0.001
                    },
                ],
                "{at}"
            );
        }
        "block_3d" => {
            assert_eq!(coord_names(m), ["base.1", "base.2"], "{at}");
            let InterfaceKind::RockingBase {
                corners,
                normal,
                e1,
                e2,
                ..
            } = &m.interfaces[0].kind
            else {
                panic!("{at}: a rocking base");
            };
            assert_eq!(*e1, Vector3::x(), "{at}");
            assert_eq!(*e2, Vector3::y(), "{at}");
            assert_eq!(*normal, Vector3::z(), "{at}");
            // The table of pivot corners.
            use Side::{Negative as N, Positive as P};
            for (sides, corner) in [([P, P], 1), ([P, N], 0), ([N, P], 2), ([N, N], 3)] {
                assert_eq!(
                    m.interfaces[0].kind.pivot(&sides),
                    corners[corner],
                    "{at}: sides {sides:?}"
                );
            }
            // M₁₁(0) = m/12 (0.6² + 2²) + m (0.3² + 1²), m = 1200 kg.
            assert!(close(m.bodies[0].mass, 1200.0, 1e-14), "{at}");
            assert!(close(m00, 1744.0, 1e-12), "{at}: {m00}");
        }
        "two_drum_column" => {
            assert_eq!(
                coord_names(m),
                ["base.1", "base.2", "bed.1", "bed.2"],
                "{at}"
            );
            assert!(m.closures.is_empty(), "{at}");
            assert_eq!(m.interfaces[1].impact, ImpactLaw::Restitution(0.8));
        }
        "trilithon" => {
            assert_eq!(
                coord_names(m),
                [
                    "left_foot.1",
                    "left_foot.2",
                    "right_foot.1",
                    "right_foot.2",
                    "left_head.1",
                    "left_head.2"
                ],
                "{at}"
            );
            assert_eq!(closure_rows(m), [("right_head", 4)], "{at}");
            // Heads in the inverse tilt order: the loop moves for finite tilts too. DOF(2) = 3:
            // in-plane sway, out-of-plane sway of the posts, the lintel rocking about its length.
            let finite = crr::dynamics::mobility_after_step(m, 0.01).unwrap();
            assert_eq!(finite.dof2, 3, "{at}: {finite:?}");
            if let Some(init) = &built.initial {
                // The fragment gives left_foot.2 = 0.01: the frame sways as a parallelogram.
                let k = |name: &str| m.coord_index(name).unwrap();
                assert!((init.q[k("left_foot.2")] - 0.01).abs() < 1e-15, "{at}");
                assert!((init.q[k("right_foot.2")] - 0.01).abs() < 1e-9, "{at}");
                assert!((init.q[k("left_head.1")] + 0.01).abs() < 1e-9, "{at}");
                assert!((init.qdot[k("right_foot.2")] - 0.2).abs() < 1e-9, "{at}");
            }
        }
        "released_block" => {
            assert_eq!(coord_names(m), ["base"], "{at}");
            let init = built.initial.as_ref().expect("an [initial] table");
            assert_eq!(init.q[0], 0.1, "{at}");
            assert_eq!(
                (built.params.duration, built.params.output_interval),
                (2.0, 0.005),
                "{at}"
            );
            let run = Simulation::new(m, &built.ground, init, built.params.clone())
                .unwrap()
                .run()
                .map_err(|f| f.error)
                .unwrap();
            // Every impact multiplies the rate by r = 1 − 1.5 sin²α (momentum law).
            let alpha = 0.2f64.atan();
            let r = 1.0 - 1.5 * alpha.sin().powi(2);
            let first = &run.impacts[0];
            assert!(
                (first.rates_after[0] / first.rates_before[0] - r).abs() < 1e-12,
                "{at}"
            );
            assert!(run.collapse.is_none(), "{at}");
        }
        "block_under_sine" => {
            assert_eq!(coord_names(m), ["base"], "{at}");
            assert!(close(built.ground.pga().x, 2.0, 1e-12), "{at}");
            assert!(built.initial.is_none(), "{at}");
            assert_eq!(built.params.duration, 4.0, "{at}");
            assert_eq!(built.params.friction, Some(0.7), "{at}");
            // 2.0 m/s² > g tan α = 1.962 m/s²: the block uplifts during the first half cycle.
            let rest = solve_initial(m, &Default::default()).unwrap();
            let run = Simulation::new(m, &built.ground, &rest, built.params.clone())
                .unwrap()
                .run()
                .map_err(|f| f.error)
                .unwrap();
            let up = run.uplift_time.expect("uplift");
            // The first instant a_x = 2 sin(4π t) reaches g tan α (tan α = b/h = 0.2/1.0):
            // 0.1094628 s (the run finds it to 2.7e-9 s; 1e-6 s is far beyond the uplift
            // test's root finding and far below the sine's quarter period, 0.125 s).
            let closed = (m.gravity * 0.2 / 2.0).asin() / (4.0 * std::f64::consts::PI);
            assert!(
                (up - closed).abs() < 1e-6,
                "{at}: uplift at {up}, closed form {closed}"
            );
        }
        "block_3d_symmetric" => {
            assert_eq!(coord_names(m), ["base.1", "base.2"], "{at}");
            let mob = crr::dynamics::mobility(
                m,
                &DVector::zeros(2),
                &ActivePivots::uniform(m, Side::Positive),
            );
            assert_eq!((mob.dof1, mob.dof2, mob.dof3), (2, 2, 1), "{at}");
            assert!(built.file.symmetry.len() == 1, "{at}");
        }
        _ => return false,
    }
    true
}

#[test]
fn every_documented_model_is_valid_and_matches_its_text() {
    let mut models = models_of("docs/model-format.md");
    assert!(
        models.len() >= 8,
        "docs/model-format.md should hold its examples"
    );
    assert!(
        models
            .iter()
            .any(|b| b.at.ends_with("(fragment)") && b.initial.is_some()),
        "the [initial] fragment appended to the trilithon is checked"
    );
    models.extend(models_of("README.md"));
    for built in &models {
        assert!(
            check_facts(built),
            "{}: model \"{}\" has no facts in tests/docs/examples.rs: add them",
            built.at,
            built.spec.name
        );
    }
    // An example of every shape and every interface kind, tree and closure.
    let mut shapes: Vec<&str> = models
        .iter()
        .flat_map(|b| b.model.bodies.iter().map(|b| b.shape.kind()))
        .collect();
    shapes.sort();
    shapes.dedup();
    assert_eq!(
        shapes,
        ["annular_sector", "box", "compound", "polyhedron", "prism"]
    );
    let kinds = |closure: bool| -> Vec<usize> {
        let mut k: Vec<usize> = models
            .iter()
            .flat_map(|b| b.model.interfaces.iter())
            .filter(|i| matches!(i.role, Role::Closure { .. }) == closure)
            .map(|i| i.kind.angle_count())
            .collect();
        k.sort();
        k.dedup();
        k
    };
    assert_eq!(kinds(false), [1, 2], "tree hinges and rocking bases");
    assert_eq!(kinds(true), [1, 2], "hinge and rocking-base closures");
}

#[test]
fn first_example_is_the_bundled_single_block() {
    let doc = read_doc("docs/model-format.md").expect("docs/model-format.md");
    let first = fenced_blocks(&doc)
        .into_iter()
        .find(|b| b.lang == "toml")
        .expect("a toml block");
    let file = read_doc("examples/models/single_block.toml").expect("the example file");
    assert_eq!(first.text, file);
}

#[test]
fn quoted_error_messages_are_the_real_ones() {
    let doc = read_doc("docs/model-format.md").expect("docs/model-format.md");
    let file = read_doc("examples/models/single_block.toml").expect("the example file");
    let build = |text: &str| {
        let file: ModelFile = toml::from_str(text).expect("parses");
        Model::from_spec(&file.structure())
    };
    // Exchanged edges: "pivots swapped".
    let pos = "pivot_positive = [[0.2, -0.2, 0.0], [0.2, 0.2, 0.0]]";
    let neg = "pivot_negative = [[-0.2, -0.2, 0.0], [-0.2, 0.2, 0.0]]";
    let swapped = file
        .replace(pos, "POS")
        .replace(neg, "NEG")
        .replace("POS", &neg.replace("negative", "positive"))
        .replace("NEG", &pos.replace("positive", "negative"));
    let e = build(&swapped).expect_err("swapped pivots are rejected");
    assert!(e.problem.starts_with("pivots swapped"), "{e}");
    assert!(doc.contains(&e.to_string()), "the doc quotes: {e}");
    // Reversing the axis as well makes it valid again.
    assert!(build(&swapped.replace("axis = [0.0, 1.0, 0.0]", "axis = [0.0, -1.0, 0.0]")).is_ok());
    // A body with no interface.
    let lonely = format!(
        "{file}\n[[body]]\nname = \"lonely\"\ndensity = 1.0\nbox = {{ center = [3.0, 0.0, 0.5], size = [1.0, 1.0, 1.0] }}\n"
    );
    let e = build(&lonely).expect_err("an unreachable body is rejected");
    assert!(doc.contains(&e.to_string()), "the doc quotes: {e}");
}
