//! A doc that names a constant of the code with a value must give the code's value. The
//! documentation (README, ARCHITECTURE, NOTATION, `docs/`, the examples' and Python's READMEs)
//! is scanned for "`NAME` = 32 coordinates" and "at most 100 000 points per range
//! (`MAX_RANGE_POINTS`)"; the value is read from the constant's definition in the sources
//! (`const NAME: T = literal;`), not from the compiled crate, so both sides are text written by
//! people, compared as numbers.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn files_with(dir: &Path, ext: &str, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if path.is_dir() {
            if name != "target" && !name.starts_with('.') {
                files_with(&path, ext, out);
            }
        } else if name.ends_with(ext) {
            out.push(path);
        }
    }
}

/// A number as people write it: `100 000`, `1e-3`, `0.2`, `10³`, `2048`, `1_000`.
fn parse_number(text: &str) -> Option<f64> {
    let t: String = text
        .chars()
        .filter(|c| !matches!(c, ' ' | '\u{202f}' | '_'))
        .collect();
    if let Some(exp) = t.strip_prefix("10") {
        let digits: String = exp
            .chars()
            .map(|c| match c {
                '⁰' => Some('0'),
                '¹' => Some('1'),
                '²' => Some('2'),
                '³' => Some('3'),
                '⁴' => Some('4'),
                '⁵' => Some('5'),
                '⁶' => Some('6'),
                '⁷' => Some('7'),
                '⁸' => Some('8'),
                '⁹' => Some('9'),
                _ => None,
            })
            .collect::<Option<String>>()
            .unwrap_or_default();
        if !digits.is_empty() {
            return Some(10f64.powi(digits.parse().ok()?));
        }
    }
    t.parse().ok()
}

/// The numeric constants defined on one line with a literal value, by name. A name defined twice
/// with different values is left out (a doc could mean either).
fn code_constants() -> BTreeMap<String, f64> {
    let mut sources = Vec::new();
    files_with(&root().join("src"), ".rs", &mut sources);
    files_with(&root().join("crates"), ".rs", &mut sources);
    let mut found: BTreeMap<String, Vec<f64>> = BTreeMap::new();
    for file in sources {
        for line in std::fs::read_to_string(&file).unwrap().lines() {
            let line = line.trim();
            let Some(i) = line.find("const ") else {
                continue;
            };
            let rest = &line[i + "const ".len()..];
            let (Some(colon), Some(eq)) = (rest.find(':'), rest.find(" = ")) else {
                continue;
            };
            let name = &rest[..colon];
            let literal = rest[eq + 3..].trim_end_matches(';');
            let literal = literal
                .trim_end_matches("f64")
                .trim_end_matches("usize")
                .trim_end_matches("u64");
            if let Some(v) = parse_number(literal)
                && name
                    .chars()
                    .all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || c == '_')
            {
                found.entry(name.to_string()).or_default().push(v);
            }
        }
    }
    found
        .into_iter()
        .filter(|(_, v)| v.iter().all(|x| *x == v[0]))
        .map(|(k, v)| (k, v[0]))
        .collect()
}

/// Statements "`NAME` = value [unit]" and "value … (`NAME`" of a text, lines joined: (name,
/// value in the code's unit, the text quoted).
fn stated_values(text: &str) -> Vec<(String, Option<f64>, String)> {
    let text = text.replace('\n', " ");
    let mut out = Vec::new();
    let s = text;
    let mut at = 0;
    while let Some(k) = s[at..].find('`') {
        let start = at + k + 1;
        let Some(len) = s[start..].find('`') else {
            break;
        };
        let name = &s[start..start + len];
        at = start + len + 1;
        let is_constant = name.len() >= 3
            && name
                .chars()
                .all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || c == '_')
            && name.chars().any(|c| c == '_');
        if !is_constant {
            continue;
        }
        // "`NAME` = 32 coordinates", "`SEATED_MAX_STEP` = 1 ms"
        if let Some(after) = s[at..].strip_prefix(" = ") {
            let value: String = after
                .chars()
                .take_while(|c| c.is_ascii_digit() || "., e-⁰¹²³⁴⁵⁶⁷⁸⁹\u{202f}".contains(*c))
                .collect();
            let value = value.trim_end_matches([' ', '.', ',']);
            let unit_ms = after[value.len()..].trim_start().starts_with("ms");
            let v = parse_number(value).map(|v| if unit_ms { v * 1e-3 } else { v });
            out.push((name.to_string(), v, format!("`{name}` = {value}")));
        }
        // "at most 100 000 points per range (`MAX_RANGE_POINTS`)": the last number within the
        // 48 characters before "(`NAME`", in the same clause (no parenthesis between).
        // Only a parenthesis that holds the name alone: "(`NAME`)", not "(`NAME` set to …)".
        let alone = s[at..].starts_with([')', ';', ',']);
        if alone && s[..start - 1].ends_with('(') {
            let before: String = s[..start - 2]
                .chars()
                .rev()
                .take(48)
                .take_while(|c| *c != '(' && *c != ')' && *c != ';')
                .collect::<Vec<_>>()
                .into_iter()
                .rev()
                .collect();
            let words: Vec<&str> = before.split_whitespace().collect();
            // The number may be written in groups of three digits: "10 000 000".
            let mut best = None;
            let mut k = 0;
            while k < words.len() {
                if parse_number(words[k]).is_some() {
                    let mut j = k + 1;
                    while j < words.len()
                        && words[j].len() == 3
                        && words[j].chars().all(|c| c.is_ascii_digit())
                    {
                        j += 1;
                    }
                    best = Some(words[k..j].join(" "));
                    k = j;
                } else {
                    k += 1;
                }
            }
            if let Some(number) = best {
                out.push((
                    name.to_string(),
                    parse_number(&number),
                    format!("{number} … (`{name}`)"),
                ));
            }
        }
    }
    out
}

fn doc_files() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = ["README.md", "ARCHITECTURE.md", "NOTATION.md"]
        .iter()
        .map(|f| root().join(f))
        .collect();
    files_with(&root().join("docs"), ".md", &mut files);
    files_with(&root().join("examples"), ".md", &mut files);
    files.push(root().join("python/README.md"));
    files.retain(|f| f.exists());
    files
}

#[test]
fn every_constant_a_doc_states_has_the_codes_value() {
    let code = code_constants();
    let mut checked = 0;
    let mut wrong = Vec::new();
    for file in doc_files() {
        let text = std::fs::read_to_string(&file).unwrap();
        for (name, stated, quote) in stated_values(&text) {
            let Some(&value) = code.get(&name) else {
                continue;
            };
            checked += 1;
            match stated {
                Some(v) if (v - value).abs() <= 1e-12 * value.abs() => {}
                _ => wrong.push(format!(
                    "{}: {quote}, the code has {name} = {value}",
                    file.strip_prefix(root()).unwrap().display()
                )),
            }
        }
    }
    assert!(
        wrong.is_empty(),
        "docs against the code:\n{}",
        wrong.join("\n")
    );
    // The docs state at least these: FAER_CHOLESKY_MIN, ARTICULATED_BODY_MIN_DOF,
    // REPARTITION_THRESHOLD, DENSE_TRUST, SEATED_MAX_STEP (twice), MAX_COORDINATES,
    // MAX_RANGE_POINTS, MAX_GRID_CASES, MAX_PERIODS.
    assert!(
        checked >= 10,
        "only {checked} statements found: the scan is broken"
    );
}

#[test]
fn the_scan_reads_both_forms_and_sees_a_wrong_value() {
    let text = "blocks of `FAER_CHOLESKY_MIN` = 32 coordinates, a cap of `SEATED_MAX_STEP` = 1 ms,\n\
                at most 10 000 000 `--periods` or `--transient` (`MAX_PERIODS`), and \
                `DENSE_TRUST` = 10³ tolerances; `SELECTION_CACHE` = 32; 596 µs against\n\
                (`FAER_CHOLESKY_MIN` set to `usize::MAX`).";
    let found = stated_values(text);
    let value = |n: &str| found.iter().find(|(k, _, _)| k == n).and_then(|f| f.1);
    assert_eq!(value("FAER_CHOLESKY_MIN"), Some(32.0));
    // "(`NAME` set to …)" states no value.
    assert_eq!(
        found
            .iter()
            .filter(|(k, _, _)| k == "FAER_CHOLESKY_MIN")
            .count(),
        1
    );
    assert_eq!(value("SEATED_MAX_STEP"), Some(1e-3));
    assert_eq!(value("MAX_PERIODS"), Some(1e7));
    assert_eq!(value("DENSE_TRUST"), Some(1e3));
    // The code's SELECTION_CACHE is 256: this statement would fail the test above.
    let code = code_constants();
    assert_eq!(code.get("SELECTION_CACHE"), Some(&256.0));
    assert_eq!(value("SELECTION_CACHE"), Some(32.0));
}
