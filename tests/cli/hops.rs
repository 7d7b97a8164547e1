//! `hops.csv`, the hops of summary.json and `[analysis] hop_tolerance` through the command line
//! (the measure itself is checked against closed forms in `crates/crr-impact/tests/hops.rs`).

use std::path::Path;

use crate::common::{bundled_text_with_records, crr, refused, scratch, write_model};

fn simulate(model: &Path, out: &Path) -> String {
    let o = crr(&[
        "simulate",
        model.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(o.status.success(), "{err}");
    err
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The rows of hops.csv, split at commas, without the header.
fn hop_rows(dir: &Path) -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(dir.join("hops.csv")).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some(
            "interface,start,pull_end,end,largest_pull,separation,departure,closed,opens,\
             within_tolerance"
        )
    );
    lines
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect()
}

/// The bundled drum column hops at `bed_7` after its impact at 0.5028 s, and at two beds after
/// its impact at 0.5303 s. By default the first is its first violation, which carries that hop
/// as hops.csv lists it; with a tolerance of 1 µm none is a violation and the run has none, its motion unchanged byte for byte; a
/// negative tolerance is refused, naming the key.
#[test]
fn a_hop_within_the_tolerance_is_no_violation_and_changes_no_motion() {
    let dir = scratch("cli_hops");
    let text = bundled_text_with_records("drum_column");
    let strict_model = write_model("drum_strict", &text);
    let strict = dir.join("strict");
    let err = simulate(&strict_model, &strict);
    assert!(
        err.contains("\"bed_7\" would need tension") && err.contains("hop_tolerance"),
        "{err}"
    );
    let summary = json(&strict.join("summary.json"));
    let v = &summary["hypothesis_violation"];
    let rows = hop_rows(&strict);
    assert_eq!(rows.len(), 3, "{rows:?}");
    let bed_7 = rows.iter().find(|r| r[0] == "bed_7").unwrap();
    let hop = &v["hop"];
    for (column, key) in [
        (1, "start"),
        (3, "end"),
        (5, "separation"),
        (6, "departure"),
    ] {
        let csv: f64 = bed_7[column].parse().unwrap();
        assert_eq!(csv.to_bits(), hop[key].as_f64().unwrap().to_bits(), "{key}");
    }
    assert_eq!(hop["start"], v["time"]);
    assert_eq!((bed_7[7].as_str(), bed_7[8].as_str()), ("true", "true"));
    assert_eq!(bed_7[9], "false");
    let hops = &summary["hops"];
    assert_eq!(
        (hops["count"].as_u64(), hops["beyond_tolerance"].as_u64()),
        (Some(3), Some(3))
    );
    let largest = rows
        .iter()
        .map(|r| r[5].parse::<f64>().unwrap())
        .fold(0.0, f64::max);
    assert_eq!(hops["largest_separation"].as_f64(), Some(largest));
    assert!(largest < 1e-6, "{largest}");

    let tolerant_model = write_model(
        "drum_tolerant",
        &text.replacen("[analysis]", "[analysis]\nhop_tolerance = 1e-6", 1),
    );
    let tolerant = dir.join("tolerant");
    let err = simulate(&tolerant_model, &tolerant);
    assert!(!err.contains("hypotheses fail"), "{err}");
    let summary = json(&tolerant.join("summary.json"));
    assert!(summary["hypothesis_violation"].is_null(), "{summary}");
    assert_eq!(summary["solver"]["hop_tolerance"].as_f64(), Some(1e-6));
    assert_eq!(summary["hops"]["beyond_tolerance"].as_u64(), Some(0));
    for file in ["history.csv", "impacts.csv", "openings.csv"] {
        let read = |d: &Path| std::fs::read(d.join(file)).unwrap();
        assert!(read(&strict) == read(&tolerant), "{file} differs");
    }
    let tolerant_rows = hop_rows(&tolerant);
    for (a, b) in rows.iter().zip(&tolerant_rows) {
        assert_eq!(a[..9], b[..9]);
        assert_eq!(b[9], "true");
    }

    let bad = write_model(
        "drum_bad_hop",
        &text.replacen("[analysis]", "[analysis]\nhop_tolerance = -1.0", 1),
    );
    refused(
        &[
            "simulate",
            bad.to_str().unwrap(),
            "--out",
            dir.join("bad").to_str().unwrap(),
        ],
        "hop_tolerance",
    );
}
