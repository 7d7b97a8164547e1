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
/// into `-`, everything else (backticks, parentheses, punctuation, dashes other than `-`) dropped;
/// a link in it counts by its text.
fn heading_anchor(heading: &str) -> String {
    let mut text = String::new();
    let mut rest = heading.trim();
    // [text](target) → text.
    while let Some(open) = rest.find('[') {
        let Some(close) = rest[open..].find("](").map(|c| open + c) else {
            break;
        };
        let Some(end) = rest[close..].find(')').map(|e| close + e) else {
            break;
        };
        text.push_str(&rest[..open]);
        text.push_str(&rest[open + 1..close]);
        rest = &rest[end + 1..];
    }
    text.push_str(rest);
    text.to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
            _ => None,
        })
        .collect()
}

/// The lines of a Markdown file outside fenced code blocks (``` or ~~~), with their numbers and
/// their inline code spans blanked out.
fn prose_lines(markdown: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut fence: Option<&str> = None;
    for (n, line) in markdown.lines().enumerate() {
        let trimmed = line.trim_start();
        let marker = ["```", "~~~"].into_iter().find(|m| trimmed.starts_with(m));
        match (fence, marker) {
            (None, Some(m)) => fence = Some(m),
            (Some(f), Some(m)) if f == m => fence = None,
            _ => {}
        }
        if fence.is_some() || marker.is_some() {
            continue;
        }
        // Inline code: every other segment between backticks.
        let prose: String = line
            .split('`')
            .enumerate()
            .map(|(k, part)| {
                if k % 2 == 0 {
                    part.to_string()
                } else {
                    " ".repeat(part.len())
                }
            })
            .collect::<Vec<_>>()
            .join(" ");
        out.push((n + 1, prose));
    }
    out
}

/// The anchors of a Markdown file's headings (ATX `#` and setext, outside code); a heading met
/// again gets `-1`, `-2`, … as on GitHub.
fn anchors_of(markdown: &str) -> std::collections::BTreeSet<String> {
    let mut seen = std::collections::BTreeMap::<String, usize>::new();
    let mut out = std::collections::BTreeSet::new();
    let lines = prose_lines(markdown);
    let all: Vec<&str> = markdown.lines().collect();
    for (n, _) in &lines {
        let line = all[n - 1];
        let next = all.get(*n).map(|l| l.trim()).unwrap_or("");
        let setext = !line.trim().is_empty()
            && !line.starts_with('#')
            && !line.trim_start().starts_with(['|', '-', '*', '>'])
            && !next.is_empty()
            && (next.chars().all(|c| c == '=') || next.chars().all(|c| c == '-'));
        let heading = if line.starts_with('#') {
            line.trim_start_matches('#')
        } else if setext {
            line
        } else {
            continue;
        };
        let anchor = heading_anchor(heading);
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

/// The targets of a Markdown file's links outside code: inline `[text](target "title")` (the
/// target without its title) and reference definitions `[label]: target`, with line numbers.
fn link_targets(markdown: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    for (n, line) in prose_lines(markdown) {
        for (i, _) in line.match_indices("](") {
            let rest = &line[i + 2..];
            if let Some(end) = rest.find(')') {
                let target = rest[..end].split_whitespace().next().unwrap_or("");
                out.push((n, target.trim_matches(['<', '>']).to_string()));
            }
        }
        let t = line.trim_start();
        if t.starts_with('[')
            && let Some(close) = t.find("]:")
        {
            let target = t[close + 2..].split_whitespace().next().unwrap_or("");
            out.push((n, target.trim_matches(['<', '>']).to_string()));
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
            if target.is_empty() || target.contains("://") || target.starts_with("mailto:") {
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
    assert_eq!(
        heading_anchor(" See [the format](x.md) here"),
        "see-the-format-here"
    );
    let anchors = anchors_of(
        "# A\n```\n# not a heading\n```\n~~~\n# nor this\n~~~\n## A\n### b c\nSetext\n======\n",
    );
    let expected: std::collections::BTreeSet<String> = ["a", "a-1", "b-c", "setext"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    assert_eq!(anchors, expected);
    // Links in code are none; a titled link's target and a reference definition's are read.
    let links = link_targets(
        "`v[0](x)` and\n```\nf[0](z)\n```\n[a](b.md \"title\") [c][r]\n[r]: <d.md#e>\n",
    );
    let targets: Vec<&str> = links.iter().map(|(_, t)| t.as_str()).collect();
    assert_eq!(targets, ["b.md", "d.md#e"]);
}
