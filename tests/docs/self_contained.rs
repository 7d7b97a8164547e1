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

/// GitHub's anchor of a heading: lower case, letters, digits, `-` and `_` kept, spaces turned
/// into `-`, everything else (backticks, parentheses, punctuation, dashes other than `-`) dropped.
fn heading_anchor(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
            _ => None,
        })
        .collect()
}

/// The anchors of a Markdown file's headings (outside code blocks); a heading met again gets
/// `-1`, `-2`, … as on GitHub.
fn anchors_of(markdown: &str) -> std::collections::BTreeSet<String> {
    let mut seen = std::collections::BTreeMap::<String, usize>::new();
    let mut out = std::collections::BTreeSet::new();
    let mut in_code = false;
    for line in markdown.lines() {
        if line.trim_start().starts_with("```") {
            in_code = !in_code;
            continue;
        }
        if in_code || !line.starts_with('#') {
            continue;
        }
        let anchor = heading_anchor(line.trim_start_matches('#'));
        let n = seen.entry(anchor.clone()).or_insert(0);
        out.insert(if *n == 0 {
            anchor.clone()
        } else {
            format!("{anchor}-{n}")
        });
        *n += 1;
    }
    out
}

/// The targets of a Markdown file's inline links `[text](target)`, with their line numbers.
fn link_targets(markdown: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    for (n, line) in markdown.lines().enumerate() {
        for (i, _) in line.match_indices("](") {
            let rest = &line[i + 2..];
            if let Some(end) = rest.find(')') {
                out.push((n + 1, rest[..end].to_string()));
            }
        }
    }
    out
}

/// Every link of the project's Markdown files to a file of the repository names a file that
/// exists, and a link to a section (`file.md#anchor`, `#anchor`) names a heading that file has
/// (README.md and docs/simulation.md linked a section of docs/model-format.md by the heading it
/// had before it was renamed).
#[test]
fn every_link_of_the_docs_reaches_a_file_and_a_heading() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut broken = Vec::new();
    let mut checked = 0;
    for file in project_files(root) {
        if file.extension().is_none_or(|e| e != "md") || file.starts_with(root.join("fuzz")) {
            continue;
        }
        let text = std::fs::read_to_string(&file).unwrap();
        for (line, target) in link_targets(&text) {
            if target.contains("://") || target.starts_with("mailto:") || target.contains(' ') {
                continue;
            }
            let (path, anchor) = match target.split_once('#') {
                Some((p, a)) => (p, Some(a)),
                None => (target.as_str(), None),
            };
            let linked = if path.is_empty() {
                file.clone()
            } else {
                file.parent().unwrap().join(path)
            };
            let at = format!("{}:{line}: {target}", file.display());
            if !linked.exists() {
                broken.push(format!("{at} (no such file)"));
                continue;
            }
            checked += 1;
            if let Some(anchor) = anchor
                && linked.extension().is_some_and(|e| e == "md")
                && !anchors_of(&std::fs::read_to_string(&linked).unwrap()).contains(anchor)
            {
                broken.push(format!("{at} (no such heading)"));
            }
        }
    }
    assert!(broken.is_empty(), "broken links: {broken:#?}");
    assert!(checked > 50, "only {checked} links checked");
}

#[test]
fn heading_anchors_are_githubs() {
    assert_eq!(
        heading_anchor(" Rocking bases: the order of the two tilts"),
        "rocking-bases-the-order-of-the-two-tilts"
    );
    assert_eq!(
        heading_anchor(" The `crr check` report (λ, μ) — 3D"),
        "the-crr-check-report-λ-μ--3d"
    );
    let anchors = anchors_of("# A\n```\n# not a heading\n```\n## A\n### b c\n");
    let expected: std::collections::BTreeSet<String> =
        ["a", "a-1", "b-c"].iter().map(|s| s.to_string()).collect();
    assert_eq!(anchors, expected);
}
