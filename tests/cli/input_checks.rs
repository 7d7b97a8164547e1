//! Inputs that used to be accepted silently get a clear error naming the item (exit 2).

use std::path::{Path, PathBuf};

use crate::common::{bundled_text as bundled, crr, refused};

fn write(name: &str, text: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join("input_checks");
    std::fs::create_dir_all(&d).unwrap();
    let p = d.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// The bundled block at rest under `component` (a `[ground_motion]` line) for `duration` s.
fn block_under(component: &str, duration: f64) -> String {
    let block = bundled("single_block").replace("[initial]\nangles = { base = 0.1 }\n", "");
    format!("{block}\n[ground_motion]\n{component}\n[analysis]\nduration = {duration}\n")
}

/// `crr simulate model` into a scratch folder is refused (exit 2) with `needle`.
fn simulate_refused(model: &Path, needle: &str) {
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("input_checks/refused_out");
    refused(
        &[
            "simulate",
            model.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--force",
        ],
        needle,
    );
}

#[test]
fn arrays_of_the_wrong_length_are_refused() {
    let block = bundled("single_block");
    let p = write(
        "size4.toml",
        &block.replace("size = [0.4, 0.4, 2.0]", "size = [0.4, 0.4, 2.0, 5.0]"),
    );
    refused(
        &["inspect", p.to_str().unwrap()],
        "body[0].box.size has 4 values, 3 expected",
    );
    let p = write(
        "size2.toml",
        &block.replace("size = [0.4, 0.4, 2.0]", "size = [0.4, 0.4]"),
    );
    refused(&["inspect", p.to_str().unwrap()], "size");
    let p = write(
        "pivot4.toml",
        &block.replace(
            "[0.2, -0.2, 0.0], [0.2, 0.2, 0.0]",
            "[0.2, -0.2, 0.0, 1.0], [0.2, 0.2, 0.0]",
        ),
    );
    refused(&["inspect", p.to_str().unwrap()], "pivot_positive");
    // A symmetry relates two coordinates: a third name was dropped.
    let trilithon = bundled("trilithon");
    let p = write(
        "symmetry3.toml",
        &format!(
            "{trilithon}\n[[symmetry]]\ncoordinates = [\"base_left\", \"base_right\", \"top_left\"]\nrelation = \"equal\"\n"
        ),
    );
    refused(
        &["inspect", p.to_str().unwrap()],
        "symmetry[0].coordinates has 3 values, 2 expected",
    );
}

#[test]
fn names_the_csv_outputs_cannot_carry_are_refused() {
    let block = bundled("single_block");
    for (tag, name) in [
        ("comma", "ba,se"),
        ("semicolon", "ba;se"),
        ("newline", "ba\\nse"),
        ("quote", "ba\\\"se"),
        ("tab", "ba\\tse"),
    ] {
        let p = write(
            &format!("name_{tag}.toml"),
            &block.replace("name = \"base\"", &format!("name = \"{name}\"")),
        );
        refused(&["inspect", p.to_str().unwrap()], "the name holds a comma");
    }
    let p = write(
        "body_comma.toml",
        &block
            .replace("name = \"block\"", "name = \"blo,ck\"")
            .replace("child = \"block\"", "child = \"blo,ck\""),
    );
    refused(&["inspect", p.to_str().unwrap()], "body \"blo,ck\"");
}

#[test]
fn pivots_far_outside_their_body_are_refused() {
    let block = bundled("single_block");
    // Millimetres typed for metres: the +x edge at 200 m from a 0.4 m block.
    let p = write(
        "far.toml",
        &block.replace(
            "[0.2, -0.2, 0.0], [0.2, 0.2, 0.0]",
            "[200.0, -0.2, 0.0], [200.0, 0.2, 0.0]",
        ),
    );
    refused(
        &["inspect", p.to_str().unwrap()],
        "interface \"base\": a pivot lies 2.",
    );
    // The bundled models, whose pivots lie on their bodies, pass.
    for m in [
        "single_block",
        "trilithon",
        "arch",
        "baldachin",
        "drum_column",
        "two_block_stack",
    ] {
        let o = crr(&["check", &format!("examples/models/{m}.toml")]);
        assert!(
            o.status.success(),
            "{m}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
}

#[test]
fn a_coordinate_given_twice_is_refused() {
    refused(
        &[
            "inspect",
            "examples/models/single_block.toml",
            "--q",
            "base=0.1",
            "--q",
            "base=0.2",
        ],
        "the coordinate \"base\" is given twice",
    );
}

#[test]
fn sizes_that_overflow_the_mass_properties_are_named_as_such() {
    let block = bundled("single_block");
    let p = write(
        "huge.toml",
        &block.replace("size = [0.4, 0.4, 2.0]", "size = [1e200, 1e200, 1e200]"),
    );
    refused(
        &["inspect", p.to_str().unwrap()],
        "body \"block\": its mass properties are not finite",
    );
}

/// Names whose output columns collide are refused, naming both interfaces (a hinge `x.1` beside
/// a rocking base `x` gave two coordinates `x.1`, `[initial]` took the first silently, and
/// interfaces named `t`, `kinetic`, `base_rate` or `base_state` doubled history.csv's columns).
#[test]
fn names_whose_output_columns_collide_are_refused() {
    let block = bundled("single_block");
    for (name, needle) in [
        (
            "t",
            "its output column \"t\" is also a column of the outputs of their own",
        ),
        // A Poincaré section's column (poincare.csv: k, t, the coordinates…).
        (
            "k",
            "its output column \"k\" is also a column of the outputs of their own",
        ),
        ("kinetic", "its output column \"kinetic\" is also a column"),
        ("dissipated_rate", "\"dissipated_rate\""),
    ] {
        let p = write(
            &format!("collide_{name}.toml"),
            &block
                .replace("name = \"base\"", &format!("name = \"{name}\""))
                .replace(
                    "angles = { base = 0.1 }",
                    &format!("angles = {{ {name} = 0.1 }}"),
                ),
        );
        let o = crr(&["inspect", p.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&o.stderr);
        if name == "dissipated_rate" {
            // No fixed column is `dissipated_rate`: the name is free.
            assert!(o.status.success(), "{err}");
            continue;
        }
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(err.contains(needle), "{name}: {err}");
    }
    // Two blocks: a hinge `x.1` under a rocking base `x` (whose tilts are `x.1`, `x.2`), and a
    // hinge `base_rate` over a hinge `base` (`base`'s rate column is `base_rate`).
    let stack = |lower: &str, upper: &str, upper_kind: &str| {
        format!(
            "name = \"stack\"\ngravity = 9.81\n\
             [[body]]\nname = \"a\"\ndensity = 2500.0\nbox = {{ center = [0.0, 0.0, 0.5], size = [0.4, 0.4, 1.0] }}\n\
             [[body]]\nname = \"b\"\ndensity = 2500.0\nbox = {{ center = [0.0, 0.0, 1.5], size = [0.4, 0.4, 1.0] }}\n\
             [[interface]]\nname = \"{lower}\"\nparent = \"ground\"\nchild = \"a\"\naxis = [0.0, 1.0, 0.0]\n\
             pivot_positive = [0.2, 0.0, 0.0]\npivot_negative = [-0.2, 0.0, 0.0]\n\
             [[interface]]\nname = \"{upper}\"\nparent = \"a\"\nchild = \"b\"\n{upper_kind}\n"
        )
    };
    let hinge = "axis = [0.0, 1.0, 0.0]\npivot_positive = [0.2, 0.0, 1.0]\npivot_negative = [-0.2, 0.0, 1.0]";
    let base = "rocking_base = { corners = [[0.2, -0.2, 1.0], [0.2, 0.2, 1.0], [-0.2, 0.2, 1.0], [-0.2, -0.2, 1.0]] }";
    for (tag, text, needle) in [
        (
            "dot",
            stack("x.1", "x", base),
            "interface \"x\": its output column \"x.1\" is also interface \"x.1\"'s",
        ),
        (
            "rate",
            stack("base", "base_rate", hinge),
            "interface \"base_rate\": its output column \"base_rate\" is also interface \"base\"'s",
        ),
        (
            "state",
            stack("base", "base_state", hinge),
            "interface \"base_state\": its output column \"base_state\" is also interface \"base\"'s",
        ),
    ] {
        let p = write(&format!("collide_{tag}.toml"), &text);
        refused(&["inspect", p.to_str().unwrap()], needle);
    }
    // The same stack with names that do not collide is a valid model.
    let p = write("collide_none.toml", &stack("x", "y", base));
    assert!(crr(&["inspect", p.to_str().unwrap()]).status.success());
}

/// Densities and gravities far outside any material's and planet's are refused naming the item:
/// the mass was a finite number but the weight overflowed (1e308 kg/m³ wrote U = NaN into the
/// history and `crr check` printed p = inf with exit 0), or the tolerances derived from √(L/g)
/// blamed a setting the user never gave (gravity 1e-6 m/s² blamed `seat_rate`).
#[test]
fn densities_and_gravities_outside_any_material_or_planet_are_refused() {
    let block = bundled("single_block");
    for (tag, text, needle) in [
        (
            "dense",
            block.replace("density = 2500.0", "density = 1e308"),
            "body \"block\": its density 1e308 kg/m³ is outside 1e-12…1e9 kg/m³",
        ),
        (
            "light",
            block.replace("density = 2500.0", "density = 1e-320"),
            "body \"block\": its density",
        ),
        (
            "mass",
            block.replace("density = 2500.0", "mass = 1e306"),
            "body \"block\": its density (its mass over its volume)",
        ),
        (
            "weak",
            block.replace("gravity = 9.81", "gravity = 1e-6"),
            "gravity: 1e-6 m/s² is outside 1e-2…1e3 m/s²",
        ),
        (
            "strong",
            block.replace("gravity = 9.81", "gravity = 1e300"),
            "gravity: 1e300 m/s² is outside",
        ),
    ] {
        let p = write(&format!("range_{tag}.toml"), &text);
        for command in ["inspect", "check"] {
            refused(&[command, p.to_str().unwrap()], needle);
        }
    }
    // Either end of the ranges is a model (osmium is 22 590 kg/m³, the Moon's gravity 1.62).
    for (tag, text) in [
        (
            "osmium",
            block.replace("density = 2500.0", "density = 22590.0"),
        ),
        ("moon", block.replace("gravity = 9.81", "gravity = 1.62")),
    ] {
        let p = write(&format!("range_{tag}.toml"), &text);
        assert!(
            crr(&["inspect", p.to_str().unwrap()]).status.success(),
            "{tag}"
        );
    }
}

/// A hinge axis is a direction whatever its length: [0, 1e160, 0] (whose norm overflows) and
/// [0, 1e-200, 0] (whose norm underflows) give the same model as [0, 1, 0] (inspect's report,
/// M(q) and U included, identical but for the name), where they gave a NaN axis and "the zero
/// vector".
#[test]
fn a_hinge_axis_of_any_length_is_its_direction() {
    let block = bundled("single_block");
    let report = |text: &str, tag: &str| {
        let p = write(&format!("axis_{tag}.toml"), text);
        let o = crr(&["inspect", p.to_str().unwrap(), "--json", "--q", "base=0.1"]);
        assert!(
            o.status.success(),
            "{tag}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        String::from_utf8_lossy(&o.stdout).into_owned()
    };
    let unit = report(&block, "unit");
    for (tag, axis) in [
        ("long", "[0.0, 1e160, 0.0]"),
        ("short", "[0.0, 1e-200, 0.0]"),
    ] {
        let scaled = report(
            &block.replace("axis = [0.0, 1.0, 0.0]", &format!("axis = {axis}")),
            tag,
        );
        assert_eq!(scaled, unit, "{tag}");
    }
}

/// Initial rates so large that the kinetic energy overflows are refused naming them (a rate of
/// 1e200 rad/s wrote kinetic = inf into history.csv with exit 0).
#[test]
fn initial_rates_whose_energy_overflows_are_refused() {
    let block = bundled("single_block");
    let p = write(
        "rate_huge.toml",
        &block.replace(
            "angles = { base = 0.1 }",
            "angles = { base = 0.1 }\nrates = { base = 1e200 }",
        ),
    );
    simulate_refused(
        &p,
        "initial.rates: the kinetic energy of the initial state is inf J",
    );
}

/// Ground accelerations beyond any ground motion are refused naming the component: a constant
/// 1e308 m/s² (finite) made every force infinite and the block stayed at rest with exit 0, as
/// did a rectangular pulse of that amplitude and a record scaled by 1e308.
#[test]
fn ground_accelerations_beyond_any_ground_motion_are_refused() {
    for (tag, component) in [
        ("constant", "x = { constant = { value = 1e308 } }"),
        (
            "pulse",
            "x = { rectangular_pulse = { amplitude = -1e308, duration = 0.1, start = 0.5 } }",
        ),
        (
            "scaled",
            "x = { sine = { amplitude = 1e300, period = 0.5 }, scale = 1e300 }",
        ),
    ] {
        let p = write(&format!("accel_{tag}.toml"), &block_under(component, 1.0));
        simulate_refused(&p, "ground_motion.x: its peak acceleration");
    }
}

/// A ground motion whose period (or a Ricker wavelet's 1/f) is below 1e-4 of the structure's
/// √(L/g) is refused before the run starts, naming it: the uplift test samples each period 32
/// times while joints are seated, and a 1e9 Hz sine over 2 s took hours (a Ricker of 1e10 Hz
/// did not pass 2e-4 s in 30 s). The bundled block's √(L/g) is 0.3255 s: 1e4 Hz runs.
#[test]
fn a_ground_motion_faster_than_any_run_can_sample_is_refused() {
    for (tag, component, period) in [
        (
            "sine",
            "x = { sine = { amplitude = 1.0, frequency = 1e9 } }",
            "1e-9",
        ),
        (
            "ricker",
            "x = { ricker = { amplitude = 5.0, frequency = 1e10, center = 1.0 } }",
            "1e-10",
        ),
    ] {
        let p = write(&format!("cycles_{tag}.toml"), &block_under(component, 2.0));
        simulate_refused(
            &p,
            &format!(
                "its shortest time scale {period} s (a period, or 1/f of a Ricker wavelet) is \
                 below 1e-4 of the structure's time scale √(L/g) = 0.3255 s"
            ),
        );
    }
    // Slower than the bound, a run is accepted (0.05 s of a 1e4 Hz sine).
    let p = write(
        "cycles_valid.toml",
        &block_under("x = { sine = { amplitude = 1.0, frequency = 1e4 } }", 0.05),
    );
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("input_checks/cycles_out");
    let o = crr(&[
        "simulate",
        p.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--force",
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// A pivot that is neither a point nor an edge says what a pivot is, at its line (it said "data
/// did not match any variant of untagged enum PivotSpec").
#[test]
fn a_pivot_that_is_no_point_or_edge_says_what_a_pivot_is() {
    let block = bundled("single_block");
    for pivot in ["[0.2, 0.0, 0.0, 1.0]", "[[0.2, -0.2, 0.0]]", "[]"] {
        let p = write(
            "pivot_shape.toml",
            &block.replace(
                "pivot_positive = [[0.2, -0.2, 0.0], [0.2, 0.2, 0.0]]",
                &format!("pivot_positive = {pivot}"),
            ),
        );
        refused(
            &["inspect", p.to_str().unwrap()],
            "expected a point [x, y, z] or an edge of two points [[x, y, z], [x, y, z]] (m)",
        );
    }
}

/// An empty list of points gets the count its shape or face needs (`corners = []` said "0
/// values, 3 expected", as if it were one point).
#[test]
fn an_empty_list_of_points_gets_the_count_it_needs() {
    let base = bundled("baldachin").replace(
        "rocking_base = { corners = [[-1.4, -1.4, 0.0], [-1.0, -1.4, 0.0], [-1.0, -1.0, 0.0], [-1.4, -1.0, 0.0]] }",
        "rocking_base = { corners = [] }",
    );
    let p = write("empty_corners.toml", &base);
    refused(
        &["inspect", p.to_str().unwrap()],
        "(rocking_base.corners): needs exactly 4 corners, got 0",
    );
}
