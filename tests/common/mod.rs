//! Helpers shared by the command-line tests: run `crr` (killed if it hangs), scratch folders,
//! the bundled models' text, and the check that an input is refused cleanly.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::Duration;

/// A `crr` run that has not answered within this time hangs: the slowest case of these tests
/// (the temple's GIF) takes about 20 s in the test profile on a quiet machine, so a loaded 2-core
/// machine running the other tests beside it stays far inside the limit (120 s was hit once).
pub const HANG_GUARD_S: u64 = 900;

/// Runs `crr` with `args` in `cwd`; a run that has not answered within [`HANG_GUARD_S`] is a
/// failure.
pub fn crr_in(cwd: &Path, args: &[&str]) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_crr"))
        .args(args)
        .current_dir(cwd)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("crr runs");
    for _ in 0..10 * HANG_GUARD_S {
        if child.try_wait().unwrap().is_some() {
            return child.wait_with_output().unwrap();
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    child.kill().unwrap();
    panic!("crr {args:?} did not answer within {HANG_GUARD_S} s");
}

/// Runs `crr` with `args` in the package's folder (bundled paths are relative to it).
pub fn crr(args: &[&str]) -> Output {
    crr_in(Path::new(env!("CARGO_MANIFEST_DIR")), args)
}

/// A fresh empty folder under the target's temporary folder.
pub fn scratch(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The text of the bundled model `examples/models/<name>.toml`.
pub fn bundled_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("examples/models/{name}.toml"))
}

/// The text of the bundled model `examples/models/<name>.toml`.
pub fn bundled_text(name: &str) -> String {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(root.join(format!("examples/models/{name}.toml"))).unwrap()
}

/// [`bundled_text`] with its record paths (`../records/`, relative to the bundled model) made
/// absolute, so that the text runs from any folder it is written to.
pub fn bundled_text_with_records(name: &str) -> String {
    let records = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/records");
    bundled_text(name).replace("../records/", &format!("{}/", records.display()))
}

/// `crr args` exits with status 2 and one `crr: error:` message containing `needle`, no panic.
pub fn refused(args: &[&str], needle: &str) {
    let o = crr(args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
    assert!(
        err.starts_with("crr: error: ") && err.contains(needle),
        "{args:?}: {err}"
    );
    assert!(!err.contains("panicked"), "{err}");
}

/// Writes `text` as `<tag>.toml` in a scratch folder and runs it with `crr::run` (`duration`
/// overriding `[analysis]`); the run must complete. The model
/// file stays in the folder (the record paths of a test may be relative to it).
pub fn run_model_text(
    tag: &str,
    text: &str,
    duration: Option<f64>,
) -> (crr::kinematics::Model, crr::impact::Trajectory) {
    let path = write_model(tag, text);
    let opts = crr::RunOptions {
        duration,
        ..Default::default()
    };
    let model = crr::ModelInput::read(&path).unwrap_or_else(|e| panic!("{tag}: {e}"));
    let run = crr::run(&model, &opts).unwrap_or_else(|e| panic!("{tag}: {e}"));
    assert!(run.completed(), "{tag}: {:?}", run.summary.error);
    (run.model, run.trajectory)
}

/// Writes `text` as `<tag>.toml` in the scratch folder `models` and returns its path.
pub fn write_model(tag: &str, text: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("models");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{tag}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

/// Runs `crr simulate` on `text` (written as `<tag>.toml` in the scratch folder `models`) into a
/// fresh folder, expects it to fail, and returns its stderr and the results folder (the partial
/// results a failed run keeps).
#[allow(dead_code)]
pub fn simulate_failing(tag: &str, text: &str) -> (String, PathBuf) {
    let path = write_model(tag, text);
    let out = scratch(&format!("failing_{tag}"));
    let o = crr(&[
        "simulate",
        path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
        "--force",
    ]);
    assert!(!o.status.success(), "{tag}: the run was accepted");
    (String::from_utf8_lossy(&o.stderr).into_owned(), out)
}

/// The bundled baldachin's text with the base of its first column a hinge about y instead of a
/// rocking base (a line across the column's foot, at its centre line): a model that is not
/// planar with one hinge.
#[allow(dead_code)]
pub fn baldachin_with_a_hinge_base() -> String {
    let text = bundled_text_with_records("baldachin").replace(
        "rocking_base = { corners = [[-1.4, -1.4, 0.0], [-1.0, -1.4, 0.0], [-1.0, -1.0, 0.0], [-1.4, -1.0, 0.0]] }",
        "axis = [0.0, 1.0, 0.0]\npivot_positive = [-1.0, -1.2, 0.0]\npivot_negative = [-1.4, -1.2, 0.0]",
    );
    assert!(
        text.contains("pivot_positive = [-1.0, -1.2, 0.0]"),
        "the base was not replaced"
    );
    text
}

/// The structure of the bundled model `examples/models/<name>.toml`.
pub fn bundled_model(name: &str) -> crr::kinematics::Model {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("examples/models/{name}.toml"));
    crr::load_model(&path).expect("bundled model loads").1
}

/// The structure mirrored by x → −x (bodies that are boxes; hinges and rocking bases). A
/// reflection R reverses orientation: a hinge's axis becomes −R u with its pivots R P⁺, R P⁻ (so
/// that u × (P⁻ − P⁺), the face normal, maps to R n), a rocking base's corners are listed in the
/// reverse order (so that their normal still points into the child).
pub fn mirrored_x(
    spec: &crr::kinematics::spec::StructureSpec,
) -> crr::kinematics::spec::StructureSpec {
    let r = nalgebra::Matrix3::new(-1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0);
    let map = |p: [f64; 3]| -> [f64; 3] { (r * nalgebra::Vector3::from(p)).into() };
    let mut out = spec.clone();
    for body in &mut out.body {
        let b = body.box_shape.as_mut().expect("a box");
        assert!(b.rotation.is_none(), "axis-aligned boxes only");
        b.center = map(b.center);
    }
    for interface in &mut out.interface {
        if let Some(axis) = interface.axis {
            interface.axis = Some(map(axis).map(|x| -x));
            for pivot in [&mut interface.pivot_positive, &mut interface.pivot_negative]
                .into_iter()
                .flatten()
            {
                *pivot = match *pivot {
                    crr::kinematics::spec::PivotSpec::Point(p) => {
                        crr::kinematics::spec::PivotSpec::Point(map(p))
                    }
                    crr::kinematics::spec::PivotSpec::Segment([a, b]) => {
                        crr::kinematics::spec::PivotSpec::Segment([map(a), map(b)])
                    }
                };
            }
        }
        if let Some(base) = &mut interface.rocking_base {
            for c in &mut base.corners {
                *c = map(*c);
            }
            base.corners.reverse();
        }
    }
    out
}

/// A block on a parallelogram section (base x ∈ [−0.2, 0.2], top shifted 0.1 m along +x, 2 m
/// high, 0.4 m deep, 2000 kg/m³): its centroid lies at x = 0.05, 1 m up, so it tips about its
/// +x edge at λ = 0.15 and about its −x edge at 0.25 (Housner's tan α of each side). Its hinge
/// has axis (0, `axis`, 0) and pivots at x = `plus` (P⁺) and `minus` (P⁻): (1, 0.2, −0.2) and
/// (−1, −0.2, 0.2) are the same joint written in the two senses of its coordinate.
#[allow(dead_code)]
pub fn leaning_block(axis: f64, plus: f64, minus: f64) -> String {
    format!(
        "name = \"leaning\"\n[[body]]\nname = \"block\"\ndensity = 2000.0\n\
         prism = {{ polygon = [[-0.2, -0.2, 0.0], [0.2, -0.2, 0.0], [0.3, -0.2, 2.0], \
         [-0.1, -0.2, 2.0]], extrude = [0.0, 0.4, 0.0] }}\n[[interface]]\nname = \"base\"\n\
         parent = \"ground\"\nchild = \"block\"\naxis = [0.0, {axis}, 0.0]\n\
         pivot_positive = [{plus}, 0.0, 0.0]\npivot_negative = [{minus}, 0.0, 0.0]\n"
    )
}

/// The bundled single block (2 m tall, 0.4 m wide: b/h = 0.2) turned by θ about x, so that its
/// hinge axis R_x(θ)ŷ = (0, cos θ, sin θ) rises θ from the horizontal. Written out, pivots and
/// centre turned by R_x(θ): (x, y, z) ↦ (x, y cos θ − z sin θ, y sin θ + z cos θ).
#[allow(dead_code)]
pub fn tilted_block(theta: f64) -> String {
    let (c, s) = (theta.cos(), theta.sin());
    let turn =
        |x: f64, y: f64, z: f64| format!("[{x:?}, {:?}, {:?}]", y * c - z * s, y * s + z * c);
    format!(
        "name = \"tilted_block\"\ngravity = 9.81\n\n\
         [[body]]\nname = \"block\"\ndensity = 2500.0\n\
         box = {{ center = {}, size = [0.4, 0.4, 2.0], rotation = [{theta:?}, 0.0, 0.0] }}\n\n\
         [[interface]]\nname = \"base\"\nparent = \"ground\"\nchild = \"block\"\n\
         axis = [0.0, {c:?}, {s:?}]\n\
         pivot_positive = [{}, {}]\npivot_negative = [{}, {}]\n",
        turn(0.0, 0.0, 1.0),
        turn(0.2, -0.2, 0.0),
        turn(0.2, 0.2, 0.0),
        turn(-0.2, -0.2, 0.0),
        turn(-0.2, 0.2, 0.0),
    )
}

/// A `[[body]]` table of an assembly: a box of 2000 kg/m³ centred at `centre` (m) of `size` (m).
pub fn box_body(name: &str, centre: [f64; 3], size: [f64; 3]) -> String {
    format!(
        "[[body]]\nname = \"{name}\"\ndensity = 2000.0\nbox = {{ center = {centre:?}, \
         size = {size:?} }}\n"
    )
}

/// The bundled models whose static multipliers the statics tests certify.
pub const BUNDLED_STATICS: [&str; 9] = [
    "single_block",
    "two_block_stack",
    "drum_column",
    "trilithon",
    "arch",
    "arch_3d",
    "baldachin",
    "temple",
    "wall",
];
