//! The root crate's layers point one way: the command line (`src/bin/crr/`) → output → analysis →
//! input → the engine crates. A `use` or path in a lower layer that names a higher one fails here,
//! naming the file and the line (doc comments may mention a higher layer; code may not).

use std::path::{Path, PathBuf};

/// Every `.rs` file under `dir`.
fn sources(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            out.extend(sources(&path));
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
    out
}

/// The code lines of `file` (comments dropped) that name any of `higher` as a path
/// (`crate::output::…`, `super::super::output`), and the grouped imports
/// (`use crate::{Error, output::plot};`, over several lines) that name one of them.
fn upward_references(file: &Path, higher: &[&str]) -> Vec<String> {
    let text = std::fs::read_to_string(file).unwrap();
    let code: Vec<(usize, &str)> = text
        .lines()
        .enumerate()
        .map(|(k, line)| (k + 1, line.split("//").next().unwrap_or("")))
        .collect();
    let mut found: Vec<String> = code
        .iter()
        .filter(|(_, c)| higher.iter().any(|h| c.contains(h)))
        .map(|(k, c)| format!("{}:{k}: {}", file.display(), c.trim()))
        .collect();
    // Grouped imports: `crate::{` … `;`, the layer's name as one of the words inside.
    let layer_names: Vec<&str> = higher
        .iter()
        .filter_map(|h| h.rsplit("::").next())
        .filter(|n| n.chars().all(|c| c.is_ascii_lowercase()))
        .collect();
    for (i, (k, c)) in code.iter().enumerate() {
        let Some(start) = c.find("crate::{").or_else(|| c.find("crr::{")) else {
            continue;
        };
        let mut group = c[start..].to_string();
        for (_, next) in &code[i + 1..] {
            if group.contains(';') {
                break;
            }
            group.push_str(next);
        }
        let group = &group[..group.find(';').unwrap_or(group.len())];
        let words: Vec<&str> = group
            .split(|ch: char| !(ch.is_ascii_alphanumeric() || ch == '_'))
            .collect();
        if layer_names.iter().any(|n| words.contains(n)) {
            found.push(format!("{}:{k}: {}", file.display(), group.trim()));
        }
    }
    found
}

#[test]
fn no_layer_names_a_layer_above_it() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    // (layer, the names of the layers above it as code would write them)
    let layers: [(&str, &[&str]); 3] = [
        (
            "input",
            &[
                "crate::analysis",
                "crate::output",
                "crr::analysis",
                "crr::output",
            ],
        ),
        ("analysis", &["crate::output", "crr::output"]),
        // The command line is a binary: no library file can name it, but a path to its folder
        // would.
        ("output", &["bin/crr", "crate::cli"]),
    ];
    let mut wrong = Vec::new();
    for (layer, higher) in layers {
        let files = sources(&src.join(layer));
        assert!(!files.is_empty(), "src/{layer}/ holds no source");
        for file in files {
            wrong.extend(upward_references(&file, higher));
        }
    }
    assert!(
        wrong.is_empty(),
        "imports against the layers:\n{}",
        wrong.join("\n")
    );
}

#[test]
fn every_library_source_belongs_to_a_layer() {
    // Only the facade, the shared error type and the fuzzing entry points sit beside the layers.
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let loose: Vec<String> = std::fs::read_dir(&src)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".rs"))
        .filter(|n| !["lib.rs", "error.rs", "fuzzing.rs"].contains(&n.as_str()))
        .collect();
    assert!(
        loose.is_empty(),
        "source files outside the layers: {loose:?}"
    );
}

#[test]
fn the_check_sees_an_upward_import() {
    // The scan itself: a file of the analysis layer that imports the output layer is caught, one
    // that only mentions it in a comment is not.
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("layers");
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.rs");
    std::fs::write(
        &bad,
        "//! see crate::output::simulate\nuse crate::output::plot;\n",
    )
    .unwrap();
    let found = upward_references(&bad, &["crate::output"]);
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(
        found[0].contains(":2: use crate::output::plot;"),
        "{found:?}"
    );
}
