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
