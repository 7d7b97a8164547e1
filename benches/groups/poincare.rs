//! Benchmark of `crr poincare`: a 200-period stroboscopic section (no transient kept apart:
//! M = 0, N = 200) of the bundled single block (`examples/models/single_block.toml`, b = 0.2 m,
//! h = 1 m) from rest under a_g = 4 sin(2π·2 t) m/s² in x, the setting of the stable symmetric
//! 1:1 orbit of `tests/analysis/poincare.rs`. The model is read outside the timing; the run is checked
//! once before it is timed (200 points, no overturning, the last 20 points one point).

use std::hint::black_box;
use std::path::Path;
use std::time::Duration;

use criterion::Criterion;

use crr::analysis::poincare::{
    PoincareOptions, SAME_POINT_TOLERANCE, SectionKind, distinct_points, prepare, run_section,
};

pub fn section_200_periods(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/single_block.toml");
    let opts = PoincareOptions {
        amplitude: 4.0,
        frequency: Some(2.0),
        periods: 200,
        transient: 0,
        rest: true,
        out: Some(Path::new(env!("CARGO_TARGET_TMPDIR")).join("bench_poincare")),
        force: true,
        ..Default::default()
    };
    let p = prepare(&path, &opts).expect("the bundled model and options are valid");
    assert_eq!(p.settings.kind, SectionKind::Stroboscopic);
    let s = run_section(&p.model, &p.initial, &p.params, &p.settings);
    assert_eq!(s.points.len(), 200, "{:?}", s.error);
    assert!(s.collapse.is_none());
    // Converged onto the 1:1 orbit by then (the distance shrinks about tenfold in 25 periods).
    assert_eq!(distinct_points(&s.points[180..], SAME_POINT_TOLERANCE), 1);
    let mut group = c.benchmark_group("poincare");
    group.measurement_time(Duration::from_secs(10));
    group.sample_size(10);
    group.bench_function("single_block_200_periods", |b| {
        b.iter(|| {
            let s = run_section(
                black_box(&p.model),
                black_box(&p.initial),
                &p.params,
                &p.settings,
            );
            black_box(s.points.len())
        })
    });
    group.finish();
}
