//! Every `crr <subcommand>` that the documentation shows exists in the program.
//!
//! The Markdown files of the repository (README, ARCHITECTURE, NOTATION, `docs/`, `examples/`,
//! `validation/`) are scanned for command lines: inside code spans and fenced blocks, a word `crr`
//! (or a path ending in `/crr`) followed by a word that is not an option names a subcommand. The
//! subcommands the program has are read from its own `crr --help`. A doc that names one it does
//! not have (a stale page, or a command planned but not built) fails the test with the file and
//! line.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The subcommands listed under "Commands:" by `crr --help`.
fn program_subcommands() -> BTreeSet<String> {
    let out = Command::new(env!("CARGO_BIN_EXE_crr"))
        .arg("--help")
        .output()
        .expect("crr runs");
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).expect("utf-8 help");
    text.lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| !l.trim().is_empty())
        .filter_map(|l| l.split_whitespace().next().map(str::to_string))
        .collect()
}

/// The code of a Markdown text (fenced blocks' lines and inline code spans), with line numbers.
fn code_snippets(markdown: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut fenced = false;
    for (k, line) in markdown.lines().enumerate() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced {
            out.push((k + 1, line.to_string()));
        } else {
            // Inline spans: the text between the 1st and 2nd backtick, the 3rd and 4th…
            for (i, span) in line.split('`').enumerate() {
                if i % 2 == 1 {
                    out.push((k + 1, span.to_string()));
                }
            }
        }
    }
    out
}

/// The subcommands a piece of code names: the word after `crr` (or `…/crr`), unless it is an
/// option, a placeholder or not a plain word.
fn named_subcommands(code: &str) -> Vec<String> {
    let words: Vec<&str> = code.split_whitespace().collect();
    words
        .windows(2)
        .filter(|w| w[0] == "crr" || w[0].ends_with("/crr"))
        .map(|w| w[1].trim_end_matches([',', '.', ';', ':', ')']))
        .filter(|s| {
            s.chars().next().is_some_and(|c| c.is_ascii_lowercase())
                && s.chars().all(|c| c.is_ascii_lowercase() || c == '-')
        })
        .map(str::to_string)
        .collect()
}

fn markdown_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("readable folder") {
        let path = entry.expect("folder entry").path();
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if path.is_dir() {
            if !matches!(name, "target" | ".git" | "node_modules") && !name.starts_with('.') {
                markdown_files(&path, out);
            }
        } else if name.ends_with(".md") {
            out.push(path);
        }
    }
}

#[test]
fn the_extractor_finds_subcommands_in_code_only() {
    let md = "Run `crr simulate model.toml` or\n```sh\ntarget/release/crr check a.toml --json\n```\n\
              crr is a library; `crr --help`; `crr <COMMAND>`; `crr::analysis::check`.\n";
    let found: Vec<String> = code_snippets(md)
        .into_iter()
        .flat_map(|(_, c)| named_subcommands(&c))
        .collect();
    assert_eq!(found, vec!["simulate".to_string(), "check".to_string()]);
}

#[test]
fn every_subcommand_named_in_the_docs_exists() {
    let have = program_subcommands();
    for expected in ["inspect", "simulate", "check", "plot"] {
        assert!(have.contains(expected), "crr --help lists {have:?}");
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    markdown_files(root, &mut files);
    files.sort();
    let mut named = BTreeSet::new();
    let mut missing = Vec::new();
    for file in &files {
        let text = std::fs::read_to_string(file).expect("readable doc");
        for (line, code) in code_snippets(&text) {
            for sub in named_subcommands(&code) {
                if !have.contains(&sub) {
                    missing.push(format!(
                        "{}:{line}: `crr {sub}`",
                        file.strip_prefix(root).unwrap_or(file).display()
                    ));
                }
                named.insert(sub);
            }
        }
    }
    assert!(
        missing.is_empty(),
        "the docs name subcommands that crr does not have ({have:?}):\n{}",
        missing.join("\n")
    );
    // The scan sees the documented commands (it is not vacuous).
    assert!(named.len() >= 4, "only {named:?} found");
}
