//! The products of a finished study folder (`cases.csv` + `study.json`): the cases read back as
//! numbers, the rocking spectra (peak θ/α against size), and the fragility table (empirical
//! exceedance fractions per intensity level and their lognormal fit, written to `fragility.csv`).
//! The figures are drawn by `crate::output::plot::plot_study`.
//!
//! The response measure is **peak θ/α**: the largest peak joint rotation of a case
//! (`peak_<coordinate>_rad`) over the slenderness α_eq of the model's equivalent block
//! (`alpha_eq_rad` of `study.json`: α itself for one block; for a drum column the whole column
//! rocking on its base joint, atan(b/h_cm)). Without α_eq (a model that is not a one-DOF
//! mechanism at rest) it is the largest of the `peak_<coordinate>_over_alpha` columns. A collapsed case counts as exceeding every threshold and, in medians, as
//! +∞; a case whose row holds an error is left out (and counted in `errors`). A case whose run
//! left crr's model (a hypotheses violation, its `violation_*` columns) is kept with the measures
//! its run reached and counted in `outside_model`, in `fragility.csv` and in the figures' captions.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::Error;
use crate::analysis::study::fragility::{FragilityPoint, LognormalFit, fit_lognormal};

/// The thresholds of peak θ/α of the fragility curves (besides collapse).
pub const THRESHOLDS: [f64; 3] = [0.2, 0.5, 1.0];

/// One motion's spectrum: its name and (size, peak θ/α) points, sizes ascending.
pub type Spectrum = (String, Vec<(f64, f64)>);

/// One case read back from `cases.csv`.
#[derive(Clone, Debug, PartialEq)]
pub struct CaseResult {
    /// Scale factor (1 without a size axis).
    pub scale: f64,
    /// Height of the scaled structure (m), when written.
    pub height: Option<f64>,
    /// The motion without the scale: the record's file, or the pulse's two grid values as text.
    pub motion: String,
    /// Pulse studies: (x, y) of the overturning map: (ω_p/p, a_p/(g tan α)) when the ratios were
    /// given, else (T_p in s, a_p in m/s²).
    pub pulse: Option<(f64, f64)>,
    /// Records studies: the intensity level.
    pub level: Option<f64>,
    /// Whether it collapsed (None: the case failed).
    pub collapse: Option<bool>,
    /// Peak θ/α (None: failed, or no coordinate with a slenderness).
    pub peak_ratio: Option<f64>,
    /// Its run left crr's model (a hypotheses violation in its `violation_time_s`): its
    /// measures hold the motion past that time, which the model does not describe.
    pub outside_model: bool,
}

/// A study folder read back.
#[derive(Clone, Debug)]
pub struct StudyResults {
    /// The folder.
    pub dir: PathBuf,
    /// The study's name.
    pub name: String,
    /// Pulse study (else records).
    pub pulses: bool,
    /// The map's axes are the dimensionless ratios.
    pub ratios: bool,
    /// Whether the study has a size axis.
    pub sized: bool,
    /// Column name of the intensity level (records studies).
    pub intensity: Option<String>,
    /// The finished cases.
    pub cases: Vec<CaseResult>,
    /// Rows holding an error.
    pub errors: usize,
    /// Finished cases whose run left crr's model ([`CaseResult::outside_model`]).
    pub outside_model: usize,
}

/// Splits one CSV line (fields optionally in double quotes, `""` for a quote).
pub(crate) fn split_csv(line: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' if quoted && chars.peek() == Some(&'"') => {
                cur.push('"');
                chars.next();
            }
            '"' => quoted = !quoted,
            ',' if !quoted => out.push(std::mem::take(&mut cur)),
            _ => cur.push(c),
        }
    }
    out.push(cur);
    out
}

/// Whether `dir` holds a study's results (`cases.csv` and `study.json`).
pub fn is_study_dir(dir: &Path) -> bool {
    dir.join("cases.csv").is_file() && dir.join("study.json").is_file()
}

impl StudyResults {
    /// Reads `dir/cases.csv` and `dir/study.json`.
    pub fn read(dir: &Path) -> Result<Self, Error> {
        let csv = dir.join("cases.csv");
        let io = |file: &Path| {
            let file = file.to_path_buf();
            move |source| Error::Io { file, source }
        };
        let text = std::fs::read_to_string(&csv).map_err(io(&csv))?;
        let json_path = dir.join("study.json");
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&json_path).map_err(io(&json_path))?)
                .map_err(|e| Error::Parse {
                    file: json_path.clone(),
                    message: e.to_string(),
                })?;
        let name = json["name"]
            .as_str()
            .or_else(|| json["study"]["name"].as_str())
            .unwrap_or("study")
            .to_string();
        let mut lines = text.lines();
        let header = split_csv(lines.next().unwrap_or_default());
        let col = |n: &str| header.iter().position(|h| h == n);
        let bad = |m: String| Error::Parse {
            file: csv.clone(),
            message: m,
        };
        let status = col("status").ok_or_else(|| bad("no `status` column".into()))?;
        let pulses = col("amplitude_m_s2").is_some();
        let ratio_cols = (col("frequency_ratio"), col("amplitude_ratio"));
        // The level's column comes before the `factor` column in records studies (Sa(T₁) too:
        // its fragility is fitted against Sa, not against the scale factor).
        let intensity = ["pga_g", "pgv_m_s", "sa_g", "factor"]
            .into_iter()
            .find(|n| !pulses && col(n).is_some())
            .map(String::from);
        let alpha_eq = json["alpha_eq_rad"]
            .as_f64()
            .filter(|a| a.is_finite() && *a > 0.0);
        let rad: Vec<usize> = header
            .iter()
            .enumerate()
            .filter(|(_, h)| h.starts_with("peak_") && h.ends_with("_rad"))
            .map(|(i, _)| i)
            .collect();
        let over: Vec<usize> = header
            .iter()
            .enumerate()
            .filter(|(_, h)| h.starts_with("peak_") && h.ends_with("_over_alpha"))
            .map(|(i, _)| i)
            .collect();
        // (Absent from the files of crr before 2026-12-01: no case is then known to be outside.)
        let violation_time = col(super::folder::VIOLATION_TIME_COLUMN);
        let mut cases = Vec::new();
        let mut errors = 0;
        let mut ratios = pulses;
        for (n, line) in lines.enumerate() {
            let f = split_csv(line);
            if f.len() != header.len() {
                return Err(bad(format!(
                    "row {}: {} fields, the header has {}",
                    n + 2,
                    f.len(),
                    header.len()
                )));
            }
            if let Some(why) = header
                .iter()
                .zip(&f)
                .find_map(|(column, value)| super::folder::invalid_field(column, value))
            {
                return Err(bad(format!("row {}: {why}", n + 2)));
            }
            let num = |i: Option<usize>| i.and_then(|i| f[i].parse::<f64>().ok());
            if f[status] != "ok" {
                errors += 1;
                continue;
            }
            let pulse = if pulses {
                let (fr, ar) = (num(ratio_cols.0), num(ratio_cols.1));
                match (fr, ar) {
                    (Some(x), Some(y)) => Some((x, y)),
                    _ => {
                        ratios = false;
                        // (None, and no map cell, when the row's numbers do not parse.)
                        num(col("period_s")).zip(num(col("amplitude_m_s2")))
                    }
                }
            } else {
                None
            };
            let motion = if pulses {
                format!(
                    "{}|{}",
                    f[col("amplitude_m_s2").unwrap_or(0)],
                    f[col("period_s").unwrap_or(0)]
                )
            } else {
                f[col("record").unwrap_or(0)].clone()
            };
            let peaks: Vec<f64> = match alpha_eq {
                Some(a) => rad
                    .iter()
                    .filter_map(|&i| f[i].parse::<f64>().ok())
                    .map(|p| p / a)
                    .collect(),
                None => over.iter().filter_map(|&i| f[i].parse().ok()).collect(),
            };
            let peak_ratio =
                (!peaks.is_empty()).then(|| peaks.iter().fold(0.0f64, |m, p| m.max(*p)));
            cases.push(CaseResult {
                scale: num(col("scale")).unwrap_or(1.0),
                height: num(col("height_m")),
                motion,
                pulse,
                level: intensity.as_deref().and_then(|n| num(col(n))),
                collapse: Some(f[col("collapse").unwrap_or(status)] == "1"),
                peak_ratio,
                outside_model: violation_time.is_some_and(|i| !f[i].is_empty()),
            });
        }
        Ok(StudyResults {
            dir: dir.to_path_buf(),
            name,
            pulses,
            ratios,
            sized: col("scale").is_some(),
            intensity,
            outside_model: cases.iter().filter(|c| c.outside_model).count(),
            cases,
            errors,
        })
    }

    /// The rocking spectra: for each motion (record or pulse), peak θ/α at each size (x = height
    /// when every case has one, else the scale factor), with collapse as +∞; and the median over
    /// the motions at each size (+∞ when at least half collapsed). Sizes ascending.
    pub fn spectra(&self) -> (Vec<Spectrum>, Vec<(f64, f64)>) {
        let by_height = self.cases.iter().all(|c| c.height.is_some());
        let x = |c: &CaseResult| {
            if by_height {
                c.height.unwrap_or(c.scale)
            } else {
                c.scale
            }
        };
        let mut series: BTreeMap<String, Vec<(f64, f64)>> = BTreeMap::new();
        let mut at_size: BTreeMap<u64, (f64, Vec<f64>)> = BTreeMap::new();
        for c in &self.cases {
            let y = if c.collapse == Some(true) {
                f64::INFINITY
            } else {
                match c.peak_ratio {
                    Some(y) => y,
                    None => continue,
                }
            };
            let xv = x(c);
            series.entry(c.motion.clone()).or_default().push((xv, y));
            at_size
                .entry(xv.to_bits())
                .or_insert_with(|| (xv, Vec::new()))
                .1
                .push(y);
        }
        let mut series: Vec<Spectrum> = series.into_iter().collect();
        for (_, s) in &mut series {
            s.sort_by(|a, b| a.0.total_cmp(&b.0));
        }
        let mut median: Vec<(f64, f64)> = at_size
            .into_values()
            .map(|(xv, mut ys)| {
                ys.sort_by(|a, b| a.total_cmp(b));
                let n = ys.len();
                let m = if n % 2 == 1 {
                    ys[n / 2]
                } else {
                    0.5 * (ys[n / 2 - 1] + ys[n / 2])
                };
                (xv, m)
            })
            .collect();
        median.sort_by(|a, b| a.0.total_cmp(&b.0));
        (series, median)
    }

    /// The fragility curves of a records study with one size: for collapse and each of
    /// [`THRESHOLDS`], the empirical fraction of cases exceeding at each level (levels ≤ 0 are
    /// left out: a lognormal curve is 0 there) and the lognormal maximum-likelihood fit.
    pub fn fragility(&self) -> Vec<FragilityCurve> {
        let mut curves = Vec::new();
        let mut measures: Vec<Option<f64>> = vec![None];
        measures.extend(THRESHOLDS.iter().map(|t| Some(*t)));
        for threshold in measures {
            // Levels equal to 12 significant digits are one level.
            let mut by_level: BTreeMap<String, (FragilityPoint, usize)> = BTreeMap::new();
            for c in &self.cases {
                let (Some(level), Some(collapse)) = (c.level, c.collapse) else {
                    continue;
                };
                if level.is_nan() || level <= 0.0 {
                    continue;
                }
                let exceed = match threshold {
                    None => collapse,
                    Some(t) => collapse || c.peak_ratio.is_some_and(|p| p > t),
                };
                let (p, outside) = by_level.entry(format!("{level:.11e}")).or_insert((
                    FragilityPoint {
                        im: level,
                        trials: 0.0,
                        exceed: 0.0,
                    },
                    0,
                ));
                p.trials += 1.0;
                if exceed {
                    p.exceed += 1.0;
                }
                *outside += usize::from(c.outside_model);
            }
            let mut levels: Vec<(FragilityPoint, usize)> = by_level.into_values().collect();
            levels.sort_by(|a, b| a.0.im.total_cmp(&b.0.im));
            let (points, outside_model): (Vec<FragilityPoint>, Vec<usize>) =
                levels.into_iter().unzip();
            let fit = fit_lognormal(&points);
            curves.push(FragilityCurve {
                threshold,
                points,
                outside_model,
                fit,
            });
        }
        curves
    }
}

/// One fragility curve: the outcomes per level and the fit (None when the data have no
/// transition: every case exceeding, or none, or fewer than two levels).
#[derive(Clone, Debug, PartialEq)]
pub struct FragilityCurve {
    /// None: collapse; Some(t): peak θ/α > t (or collapse).
    pub threshold: Option<f64>,
    /// Levels ascending, with trials and exceedances.
    pub points: Vec<FragilityPoint>,
    /// Per level (in the order of `points`), the cases whose run left crr's model: counted in
    /// the trials with the measures their runs reached.
    pub outside_model: Vec<usize>,
    /// The lognormal fit.
    pub fit: Option<LognormalFit>,
}

impl FragilityCurve {
    /// Label: `collapse` or `peak θ/α > t`.
    pub fn label(&self) -> String {
        match self.threshold {
            None => "collapse".into(),
            Some(t) => format!("peak θ/α > {t}"),
        }
    }
}

/// The texts of `fragility.csv`: one row per curve, `measure,threshold,median_<IM>,dispersion,
/// log_likelihood,levels_used,cases_used,level_min,level_max,cases_outside_model` (median,
/// dispersion and likelihood empty when there is no fit; the last the cases used whose run left
/// crr's model); and of `fragility_points.csv`, the empirical table
/// `measure,threshold,level,trials,exceed,fraction,outside_model`.
pub fn fragility_csv(curves: &[FragilityCurve], intensity: &str) -> (String, String) {
    let mut s = format!(
        "measure,threshold,median_{intensity},dispersion,log_likelihood,levels_used,cases_used,\
         level_min,level_max,cases_outside_model\n"
    );
    let name = |c: &FragilityCurve| match c.threshold {
        None => ("collapse".to_string(), String::new()),
        Some(t) => ("peak_theta_over_alpha".to_string(), format!("{t}")),
    };
    for c in curves {
        let (m, t) = name(c);
        let (med, disp, ll) = c
            .fit
            .map_or((String::new(), String::new(), String::new()), |f| {
                (
                    format!("{}", f.median),
                    format!("{}", f.dispersion),
                    format!("{}", f.log_likelihood),
                )
            });
        let cases: f64 = c.points.iter().map(|p| p.trials).sum();
        let (lo, hi) = (
            c.points
                .first()
                .map(|p| format!("{}", p.im))
                .unwrap_or_default(),
            c.points
                .last()
                .map(|p| format!("{}", p.im))
                .unwrap_or_default(),
        );
        let outside: usize = c.outside_model.iter().sum();
        s.push_str(&format!(
            "{m},{t},{med},{disp},{ll},{},{cases},{lo},{hi},{outside}\n",
            c.points.len()
        ));
    }
    let mut e = String::from("measure,threshold,level,trials,exceed,fraction,outside_model\n");
    for c in curves {
        let (m, t) = name(c);
        for (p, outside) in c.points.iter().zip(&c.outside_model) {
            e.push_str(&format!(
                "{m},{t},{},{},{},{},{outside}\n",
                p.im,
                p.trials,
                p.exceed,
                p.exceed / p.trials
            ));
        }
    }
    (s, e)
}
