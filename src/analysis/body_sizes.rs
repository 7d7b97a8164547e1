//! Lengths typed in millimetres where crr reads metres. Such a model runs and answers with
//! confidence: its multipliers do not depend on the size, but its dynamics does (a block's
//! p = √(3g/4R)), so the bundled 2 m block typed in millimetres, a 2 km block, rocked through 21
//! impacts and stood under 1.5 × the record that overturns the real one at 6.93 s. A body larger
//! than any stone or masonry element is therefore a warning of `crr check` and `crr simulate`.

use crr_kinematics::Model;

/// The largest extent (m) of a body at rest above which it is reported: above the largest
/// monoliths (obelisks of some 30 m, quarried blocks of some 20 m) with a margin, and far below
/// the kilometres of a metre-sized stone typed in millimetres.
pub const LARGEST_PLAUSIBLE_BODY: f64 = 100.0;

/// The largest extent of a body's shape at rest (m): the longest side of its vertices' box
/// (an annular sector's arcs as chords); `None` where the shape has no surface.
fn extent(model: &Model, body: usize) -> Option<f64> {
    let surface = model.bodies[body].shape.surface().ok()?;
    let first = *surface.vertices.first()?;
    let (lo, hi) = surface
        .vertices
        .iter()
        .fold((first, first), |(lo, hi), v| (lo.inf(v), hi.sup(v)));
    Some((hi - lo).max())
}

/// One warning naming the largest body of `model` when it spans more than
/// [`LARGEST_PLAUSIBLE_BODY`], with how many others do.
pub fn bodies_too_large(model: &Model) -> Vec<String> {
    let mut large: Vec<(f64, usize)> = (0..model.bodies.len())
        .filter_map(|b| Some((extent(model, b)?, b)))
        .filter(|(e, _)| *e > LARGEST_PLAUSIBLE_BODY)
        .collect();
    large.sort_by(|a, b| b.0.total_cmp(&a.0));
    let Some(&(largest, body)) = large.first() else {
        return Vec::new();
    };
    let others = match large.len() - 1 {
        0 => String::new(),
        n => format!(
            ", and {n} more bod{} over {LARGEST_PLAUSIBLE_BODY} m",
            if n == 1 { "y" } else { "ies" }
        ),
    };
    vec![format!(
        "body \"{}\" spans {largest:.4e} m at rest (its largest extent{others}): larger than any \
         stone or masonry element; crr reads lengths in metres, so if the file gives millimetres \
         divide its lengths by 1000 (an assembly's OBJ files take `units = \"mm\"`): the \
         multipliers do not depend on the size, but the motion does (a block's \
         p = √(3g/4R)), and a model 1000 times too large rocks where the real one overturns",
        model.bodies[body].name
    )]
}
