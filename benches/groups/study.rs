//! Benchmark of `crr study`: a 12 × 12 overturning map of Housner's block (b = 0.2 m, h = 1 m,
//! `examples/models/single_block.toml`) under one-sine pulses, a_p/(g tan α) from 1 to 7 and
//! ω_p/p from 1 to 12 (the bundled `housner_map.toml` on a coarser grid), 8 s per case: the whole
//! run (cases, streaming of `cases.csv`, final sort, `study.json`) with 1 and 2 worker threads,
//! so that the speed-up from 1 to 2 threads is measured. Each iteration writes into a fresh
//! folder (a folder holding the cases would be resumed, not rerun). The study is read once,
//! outside the timing; the run is checked once before it is timed (144 rows, no error).

use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::time::Duration;

use criterion::{BenchmarkId, Criterion};

use crr::analysis::study::Study;
use crr::output::study::{Shard, StudyOptions, run_study};

fn scratch() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("crr_bench_study_{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a scratch folder");
    dir
}

fn small_map(dir: &Path) -> PathBuf {
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/single_block.toml");
    let text = format!(
        "name = \"bench_map\"\nmodel = \"{}\"\nduration = 8.0\n\n[pulses]\n\
         kind = \"one_sine_pulse\"\namplitude_ratios = {{ from = 1.0, to = 7.0, count = 12 }}\n\
         frequency_ratios = {{ from = 1.0, to = 12.0, count = 12 }}\n",
        model.display()
    );
    let path = dir.join("bench_map.toml");
    std::fs::write(&path, text).expect("the study file");
    path
}

fn run(study: &Study, file: &Path, out: &Path, jobs: usize) -> usize {
    let _ = std::fs::remove_dir_all(out);
    let outcome = run_study(
        study,
        file,
        &StudyOptions {
            out: out.to_path_buf(),
            jobs: Some(jobs),
            shard: Shard::ALL,
            quiet: true,
            cancel: None,
        },
    )
    .expect("the study runs");
    outcome.ran
}

pub fn bench_study(c: &mut Criterion) {
    let dir = scratch();
    let file = small_map(&dir);
    let study = Study::load(&file).expect("the study loads");
    let out = dir.join("out");
    let ran = run(&study, &file, &out, 2);
    assert_eq!(ran, 144);
    let csv = std::fs::read_to_string(out.join("cases.csv")).expect("cases.csv");
    assert_eq!(csv.lines().count(), 145);
    assert!(!csv.contains(",error,"));
    let mut group = c.benchmark_group("study_map_12x12");
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(8));
    for jobs in [1usize, 2] {
        group.bench_with_input(BenchmarkId::new("threads", jobs), &jobs, |b, &jobs| {
            b.iter(|| black_box(run(&study, &file, &out, jobs)))
        });
    }
    group.finish();
    let _ = std::fs::remove_dir_all(&dir);
}
