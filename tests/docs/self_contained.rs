//! The documentation stands alone: no file of the project points outside the repository (the
//! paper is cited by its title, the theory is in docs/physics.md), and every reference to a
//! section of docs/physics.md names a section it has.

use std::path::{Path, PathBuf};

/// The project's own text files (sources, docs, models, scripts), not build outputs.
fn project_files(root: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().to_string();
            if path.is_dir() {
                if !name.starts_with('.') && name != "target" && name != "venv" {
                    stack.push(path);
                }
            } else if ["md", "rs", "toml", "py", "txt"]
                .iter()
                .any(|e| name.ends_with(&format!(".{e}")))
            {
                out.push(path);
            }
        }
    }
    out
}

#[test]
fn no_file_points_outside_the_repository() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    // Spelled in two halves so that this file does not match itself.
    let needles = [
        format!("{}{}", "/work/", "shared"),
        format!("{}{}", "../", "shared/"),
        format!("{}{}", "crr-paper", ".txt"),
    ];
    let mut found = Vec::new();
    for file in project_files(root) {
        let Ok(text) = std::fs::read_to_string(&file) else {
            continue;
        };
        for needle in &needles {
            if text.contains(needle.as_str()) {
                found.push(format!("{}: {needle}", file.display()));
            }
        }
    }
    assert!(found.is_empty(), "paths outside the repository: {found:#?}");
}

#[test]
fn references_to_sections_of_physics_md_name_sections_it_has() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let physics = std::fs::read_to_string(root.join("docs/physics.md")).unwrap();
    let sections: Vec<u32> = physics
        .lines()
        .filter_map(|l| l.strip_prefix("## "))
        .filter_map(|l| l.split('.').next()?.parse().ok())
        .collect();
    assert_eq!(sections, (1..=7).collect::<Vec<_>>());
    let mut checked = 0;
    for file in project_files(root) {
        let Ok(text) = std::fs::read_to_string(&file) else {
            continue;
        };
        for (i, _) in text.match_indices("physics.md §") {
            let rest = &text[i + "physics.md §".len()..];
            let digits: String = rest.chars().take_while(|c| c.is_ascii_digit()).collect();
            // This file's own pattern is followed by a quote, not a section number.
            let Ok(n) = digits.parse::<u32>() else {
                continue;
            };
            assert!(sections.contains(&n), "{}: §{n}", file.display());
            checked += 1;
        }
    }
    assert!(checked >= 4, "only {checked} references found");
}
