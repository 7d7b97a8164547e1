//! Recorded accelerograms: PEER NGA `.AT2` files and time/acceleration tables
//! (CSV or whitespace-separated text), linearly interpolated.

use std::path::Path;

use super::GroundMotionError;
use super::Side;
use super::spec::{RecordFormat, STANDARD_GRAVITY, Units};

/// How many lines at the top of an `.AT2` file are searched for the NPTS/DT line.
pub const AT2_HEADER_SCAN_LINES: usize = 10;

#[derive(Debug, Clone, PartialEq)]
enum Times {
    /// `t_i = i · dt`.
    Uniform { dt: f64 },
    /// Explicit, strictly increasing sample times.
    Explicit(Vec<f64>),
}

/// A sampled accelerogram: sample times (s) and accelerations (m/s²).
///
/// Between samples the acceleration is interpolated linearly; before the first sample
/// and after the last one it is 0. Invariants (checked by the constructors): at least
/// 2 samples, all values finite, times strictly increasing.
#[derive(Debug, Clone, PartialEq)]
pub struct Record {
    source: String,
    times: Times,
    accel: Vec<f64>,
    /// `cumulative[i]` = ∫ from the first sample to `t_i` of a (trapezoidal, exact).
    cumulative: Vec<f64>,
    warnings: Vec<String>,
}

fn invalid(message: impl Into<String>) -> GroundMotionError {
    GroundMotionError::InvalidRecord {
        message: message.into(),
    }
}

impl Record {
    /// A record sampled uniformly: `t_i = i · dt`, `i = 0 .. accel.len() − 1`.
    /// `accel` in m/s². Needs `dt > 0` finite, at least 2 finite samples.
    pub fn uniform(dt: f64, accel: Vec<f64>) -> Result<Self, GroundMotionError> {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(invalid(format!(
                "time step must be positive and finite, got {dt}"
            )));
        }
        let span = accel.len().saturating_sub(1) as f64 * dt;
        if !span.is_finite() {
            return Err(invalid(format!(
                "{} samples at a time step of {dt:e} s span {span} s",
                accel.len()
            )));
        }
        Self::build(Times::Uniform { dt }, accel)
    }

    /// A record from explicit sample times (s, strictly increasing) and accelerations (m/s²).
    pub fn from_samples(times: Vec<f64>, accel: Vec<f64>) -> Result<Self, GroundMotionError> {
        if times.len() != accel.len() {
            return Err(invalid(format!(
                "{} times but {} accelerations",
                times.len(),
                accel.len()
            )));
        }
        for (i, w) in times.windows(2).enumerate() {
            if !w[0].is_finite() || !w[1].is_finite() {
                return Err(invalid(format!("sample time {} is not finite", i)));
            }
            if w[1] <= w[0] {
                return Err(invalid(format!(
                    "times must be strictly increasing: t[{}] = {} follows t[{}] = {}",
                    i + 1,
                    w[1],
                    i,
                    w[0]
                )));
            }
        }
        Self::build(Times::Explicit(times), accel)
    }

    fn build(times: Times, accel: Vec<f64>) -> Result<Self, GroundMotionError> {
        if accel.len() < 2 {
            return Err(invalid(format!(
                "a record needs at least 2 samples, got {}",
                accel.len()
            )));
        }
        if let Some(i) = accel.iter().position(|a| !a.is_finite()) {
            return Err(invalid(format!(
                "acceleration sample {i} is not finite ({})",
                accel[i]
            )));
        }
        let mut record = Record {
            source: String::from("<memory>"),
            times,
            accel,
            cumulative: Vec::new(),
            warnings: Vec::new(),
        };
        let mut cumulative = Vec::with_capacity(record.accel.len());
        let mut sum = 0.0;
        cumulative.push(0.0);
        for i in 1..record.accel.len() {
            let h = record.t(i) - record.t(i - 1);
            sum += 0.5 * h * (record.accel[i - 1] + record.accel[i]);
            cumulative.push(sum);
        }
        record.cumulative = cumulative;
        Ok(record)
    }

    /// Sets the name used in messages (normally the file path).
    pub fn with_source(mut self, source: impl Into<String>) -> Self {
        self.source = source.into();
        self
    }

    /// Where the record came from (file path as given, or `<memory>`).
    pub fn source(&self) -> &str {
        &self.source
    }

    /// Non-fatal remarks made while reading (e.g. ignored trailing values).
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Number of samples (always ≥ 2).
    pub fn len(&self) -> usize {
        self.accel.len()
    }

    /// Always false (a record has at least 2 samples); provided for API symmetry.
    pub fn is_empty(&self) -> bool {
        self.accel.is_empty()
    }

    /// Time of sample `i` in s, or `None` if `i ≥ len()`.
    pub fn time(&self, i: usize) -> Option<f64> {
        (i < self.len()).then(|| self.t(i))
    }

    /// Sample times in s.
    pub fn times(&self) -> impl Iterator<Item = f64> + '_ {
        (0..self.len()).map(|i| self.t(i))
    }

    /// The uniform time step in s, if the record is uniformly sampled (`.AT2`).
    pub fn dt(&self) -> Option<f64> {
        match self.times {
            Times::Uniform { dt } => Some(dt),
            Times::Explicit(_) => None,
        }
    }

    /// Sampled accelerations in m/s².
    pub fn accel(&self) -> &[f64] {
        &self.accel
    }

    /// Time of the first sample, s.
    pub fn start_time(&self) -> f64 {
        self.t(0)
    }

    /// Time of the last sample, s; the record is 0 after it.
    pub fn end_time(&self) -> f64 {
        self.t(self.len() - 1)
    }

    /// Largest |sample|, m/s².
    pub fn peak(&self) -> f64 {
        self.accel.iter().fold(0.0, |m: f64, a| m.max(a.abs()))
    }

    /// Time of sample `i`; `i < len()` is guaranteed by callers.
    fn t(&self, i: usize) -> f64 {
        match &self.times {
            Times::Uniform { dt } => i as f64 * dt,
            Times::Explicit(v) => v[i],
        }
    }

    /// Number of samples with time ≤ t (binary search, O(log n)).
    fn count_le(&self, t: f64) -> usize {
        let (mut lo, mut hi) = (0, self.len());
        while lo < hi {
            let mid = lo + (hi - lo) / 2;
            if self.t(mid) <= t {
                lo = mid + 1;
            } else {
                hi = mid;
            }
        }
        lo
    }

    /// Interpolated value for `t` in `[t_0, t_{n−1}]` (caller checks the range).
    fn interpolate(&self, t: f64) -> (usize, f64) {
        let n = self.len();
        let k = self.count_le(t).clamp(1, n);
        if k == n {
            return (n - 1, self.accel[n - 1]);
        }
        let i = k - 1;
        let (t0, t1) = (self.t(i), self.t(i + 1));
        let w = (t - t0) / (t1 - t0);
        (i, self.accel[i] + w * (self.accel[i + 1] - self.accel[i]))
    }

    /// Acceleration at `t`, m/s²: linear interpolation, the sample value at a sample
    /// time (also at the first and last sample), 0 outside `[t_0, t_{n−1}]`.
    /// NaN for a NaN `t`.
    pub fn acceleration(&self, t: f64) -> f64 {
        if t.is_nan() {
            return f64::NAN;
        }
        if t < self.start_time() || t > self.end_time() {
            return 0.0;
        }
        self.interpolate(t).1
    }

    /// One-sided limit of the acceleration at `t` (differs from
    /// [`acceleration`](Self::acceleration) only at the first and last sample, where the
    /// record jumps from/to 0).
    pub fn acceleration_limit(&self, t: f64, side: Side) -> f64 {
        match side {
            Side::Before if t == self.start_time() => 0.0,
            Side::After if t == self.end_time() => 0.0,
            _ => self.acceleration(t),
        }
    }

    /// ∫ a dτ from the first sample time to `t`, m/s (exact for the piecewise-linear
    /// interpolant; 0 before the first sample, constant after the last one).
    pub fn integral(&self, t: f64) -> f64 {
        if t.is_nan() {
            return f64::NAN;
        }
        if t <= self.start_time() {
            return 0.0;
        }
        if t >= self.end_time() {
            return self.cumulative[self.len() - 1];
        }
        let (i, a) = self.interpolate(t);
        self.cumulative[i] + 0.5 * (t - self.t(i)) * (self.accel[i] + a)
    }

    /// First sample time strictly greater than `t` (O(log n)), if any.
    pub fn next_sample_time(&self, t: f64) -> Option<f64> {
        if t.is_nan() {
            return None;
        }
        let k = self.count_le(t);
        (k < self.len()).then(|| self.t(k))
    }
}

/// Options for [`read_table`] / [`parse_table`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TableOptions {
    /// Comma-separated (`Csv`) or whitespace-separated (`Text`). `PeerAt2` is rejected.
    pub format: RecordFormat,
    /// Units of the acceleration column.
    pub units: Units,
    /// 0-based column holding the time in s (default 0).
    pub time_column: usize,
    /// 0-based column holding the acceleration (default 1).
    pub accel_column: usize,
    /// Number of lines skipped at the top before parsing (default 0).
    pub skip_rows: usize,
}

impl TableOptions {
    /// Defaults: time in column 0, acceleration in column 1, no skipped rows.
    pub fn new(format: RecordFormat, units: Units) -> Self {
        TableOptions {
            format,
            units,
            time_column: 0,
            accel_column: 1,
            skip_rows: 0,
        }
    }
}

fn read_text(path: &Path) -> Result<String, GroundMotionError> {
    match crate::input::read_regular_file(path, crate::input::DATA_FILE_LIMIT) {
        Ok(bytes) => {
            let text = String::from_utf8_lossy(&bytes);
            Ok(text.strip_prefix('\u{feff}').unwrap_or(&text).to_string())
        }
        Err(error) => Err(GroundMotionError::Io {
            path: path.display().to_string(),
            error,
        }),
    }
}

/// Reads a PEER NGA `.AT2` file (values in g, converted to m/s² with g₀ = 9.80665).
pub fn read_at2(path: &Path) -> Result<Record, GroundMotionError> {
    let text = read_text(path)?;
    parse_at2(&text, &path.display().to_string())
}

/// Reads a CSV or whitespace-separated time/acceleration table.
pub fn read_table(path: &Path, options: &TableOptions) -> Result<Record, GroundMotionError> {
    let text = read_text(path)?;
    parse_table(&text, &path.display().to_string(), options)
}

/// Reads a record in any supported format with default columns. `units` must be
/// given for `csv`/`text`; for `peer-at2` it must be absent or `g`.
pub fn read_record(
    path: &Path,
    format: RecordFormat,
    units: Option<Units>,
) -> Result<Record, GroundMotionError> {
    let source = path.display().to_string();
    match format {
        RecordFormat::PeerAt2 => {
            check_at2_units(&source, units)?;
            read_at2(path)
        }
        RecordFormat::Csv | RecordFormat::Text => {
            let units = units.ok_or_else(|| GroundMotionError::Format {
                path: source.clone(),
                message: format!("units are required for {format} records (g, m/s2 or cm/s2)"),
            })?;
            read_table(path, &TableOptions::new(format, units))
        }
    }
}

pub(super) fn check_at2_units(source: &str, units: Option<Units>) -> Result<(), GroundMotionError> {
    match units {
        None | Some(Units::G) => Ok(()),
        Some(u) => Err(GroundMotionError::Format {
            path: source.to_string(),
            message: format!("peer-at2 values are always in g; units = \"{u}\" is not allowed"),
        }),
    }
}

/// Parses a number written by Fortran or C: `1.5`, `.1234E-02`, `-0.12E-01`, `1.2D-03`,
/// `0.1234-102` (exponent without letter). Non-finite values are rejected.
pub fn parse_fortran_float(token: &str) -> Option<f64> {
    let direct = token.replace(['D', 'd'], "E");
    let value = direct.parse::<f64>().ok().or_else(|| {
        // Fortran drops the `E` for 3-digit exponents: 0.1234-102.
        let bytes = direct.as_bytes();
        let pos = (1..bytes.len()).rev().find(|&i| {
            (bytes[i] == b'-' || bytes[i] == b'+')
                && bytes[i - 1].is_ascii_digit()
                && !direct[..i].contains(['E', 'e'])
        })?;
        format!("{}E{}", &direct[..pos], &direct[pos..])
            .parse::<f64>()
            .ok()
    })?;
    // Rust accepts "inf"/"nan"; a record value must be a finite number.
    value.is_finite().then_some(value)
}

/// Value following `KEY=` (or `KEY:`) in an upper-cased header line.
fn keyword_value<'a>(upper: &'a str, key: &str) -> Option<&'a str> {
    let mut from = 0;
    while let Some(off) = upper[from..].find(key) {
        let at = from + off;
        from = at + key.len();
        let before_ok = upper[..at]
            .chars()
            .next_back()
            .is_none_or(|c| !c.is_ascii_alphanumeric());
        if !before_ok {
            continue;
        }
        let rest = upper[from..].trim_start();
        let Some(rest) = rest.strip_prefix(['=', ':']) else {
            continue;
        };
        let rest = rest.trim_start();
        let end = rest
            .find(|c: char| !(c.is_ascii_digit() || matches!(c, '.' | '+' | '-' | 'E' | 'D')))
            .unwrap_or(rest.len());
        if end > 0 {
            return Some(&rest[..end]);
        }
    }
    None
}

/// The first two whitespace/comma separated tokens, if they read as `int float`.
fn two_numbers(line: &str) -> Option<(usize, f64)> {
    let mut tokens = line.split([' ', '\t', ',', '\r']).filter(|s| !s.is_empty());
    let npts = tokens.next()?.parse::<usize>().ok()?;
    let dt = parse_fortran_float(tokens.next()?)?;
    Some((npts, dt))
}

/// Finds (line index, NPTS, DT) in the header.
fn at2_header(lines: &[&str], source: &str) -> Result<(usize, usize, f64), GroundMotionError> {
    for (idx, line) in lines.iter().enumerate().take(AT2_HEADER_SCAN_LINES) {
        let upper = line.to_ascii_uppercase();
        let found = if upper.contains("NPTS") {
            let keyed = keyword_value(&upper, "NPTS").zip(keyword_value(&upper, "DT"));
            let parsed = match keyed {
                Some((n, d)) => n.parse::<usize>().ok().zip(parse_fortran_float(d)),
                None => two_numbers(line),
            };
            match parsed {
                Some(p) => Some(p),
                None => {
                    return Err(GroundMotionError::Parse {
                        path: source.to_string(),
                        line: idx + 1,
                        message: format!(
                            "cannot read NPTS and DT from header line `{}`",
                            line.trim()
                        ),
                    });
                }
            }
        } else if idx >= 3 {
            let count = line
                .split([' ', '\t', ',', '\r'])
                .filter(|s| !s.is_empty())
                .count();
            if count == 2 { two_numbers(line) } else { None }
        } else {
            None
        };
        if let Some((npts, dt)) = found {
            let err = |message: String| GroundMotionError::Parse {
                path: source.to_string(),
                line: idx + 1,
                message,
            };
            if npts < 2 {
                return Err(err(format!("NPTS must be at least 2, got {npts}")));
            }
            if !(dt.is_finite() && dt > 0.0) {
                return Err(err(format!("DT must be positive, got {dt}")));
            }
            if !((npts - 1) as f64 * dt).is_finite() {
                return Err(err(format!(
                    "NPTS = {npts} samples at DT = {dt:e} s span more than any time"
                )));
            }
            return Ok((idx, npts, dt));
        }
    }
    Err(GroundMotionError::Format {
        path: source.to_string(),
        message: format!(
            "no NPTS/DT header found in the first {AT2_HEADER_SCAN_LINES} lines \
             (expected a line like `NPTS=  5000, DT=   .0100 SEC`, or `5000   0.0100` \
             after 3 text lines)"
        ),
    })
}

/// Parses the text of a PEER NGA `.AT2` file. `source` names the file in messages.
///
/// Header: the first line (among the first [`AT2_HEADER_SCAN_LINES`]) that holds
/// `NPTS= n, DT= dt` in any case and spacing, or — from the 4th line on — exactly two
/// numbers `n dt`. Then exactly `n` values in g (any number per line). Values after the
/// `n`-th are ignored and reported in [`Record::warnings`].
pub fn parse_at2(text: &str, source: &str) -> Result<Record, GroundMotionError> {
    let lines: Vec<&str> = text.lines().collect();
    let (header, npts, dt) = at2_header(&lines, source)?;
    // Each value takes at least two characters (a digit and a separator): a header's NPTS larger
    // than the text can hold is caught below without allocating for it.
    let mut values = Vec::with_capacity(npts.min(text.len() / 2 + 1));
    let mut extra = 0usize;
    let mut extra_line = 0usize;
    for (idx, line) in lines.iter().enumerate().skip(header + 1) {
        for token in line.split([' ', '\t', ',', '\r']).filter(|s| !s.is_empty()) {
            if values.len() == npts {
                if extra == 0 {
                    extra_line = idx + 1;
                }
                extra += 1;
                continue;
            }
            match parse_fortran_float(token) {
                Some(v) => values.push(v * STANDARD_GRAVITY),
                None => {
                    return Err(GroundMotionError::Parse {
                        path: source.to_string(),
                        line: idx + 1,
                        message: format!(
                            "invalid number `{token}` (value {} of NPTS = {npts})",
                            values.len() + 1
                        ),
                    });
                }
            }
        }
    }
    if values.len() < npts {
        return Err(GroundMotionError::Parse {
            path: source.to_string(),
            line: lines.len(),
            message: format!("file ends after {} of NPTS = {npts} values", values.len()),
        });
    }
    let mut record = Record::uniform(dt, values)
        .map_err(|e| GroundMotionError::Format {
            path: source.to_string(),
            message: e.to_string(),
        })?
        .with_source(source);
    if extra > 0 {
        record.warnings.push(format!(
            "{source}:{extra_line}: {extra} value(s) after the NPTS = {npts} values ignored"
        ));
    }
    Ok(record)
}

/// Parses a time/acceleration table. `source` names the file in messages.
///
/// Lines: the first `skip_rows` lines are skipped; `#` starts a comment; blank lines are
/// ignored; the first remaining line is a header (skipped) if its time or acceleration
/// field is missing or not a number while some field is text. Times in s must be strictly increasing; at least 2 samples.
pub fn parse_table(
    text: &str,
    source: &str,
    options: &TableOptions,
) -> Result<Record, GroundMotionError> {
    // A UTF-8 byte-order mark (spreadsheets write one) is not part of the first field: left in,
    // it made a headerless file's first line look like a header, and its sample was lost.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let err = |line: usize, message: String| GroundMotionError::Parse {
        path: source.to_string(),
        line,
        message,
    };
    if options.format == RecordFormat::PeerAt2 {
        return Err(GroundMotionError::Format {
            path: source.to_string(),
            message: "peer-at2 is not a table format (use read_at2)".to_string(),
        });
    }
    if options.time_column == options.accel_column {
        return Err(GroundMotionError::Format {
            path: source.to_string(),
            message: format!(
                "time_column and accel_column are both {}",
                options.time_column
            ),
        });
    }
    // Saturating: a column index of usize::MAX asks for more columns than any line has (the
    // error below), not for an overflow.
    let needed = options
        .time_column
        .max(options.accel_column)
        .saturating_add(1);
    let mut times: Vec<f64> = Vec::new();
    let mut accel: Vec<f64> = Vec::new();
    let mut previous_line = 0usize;
    let mut first_row = true;
    for (idx, raw) in text.lines().enumerate().skip(options.skip_rows) {
        let line_no = idx + 1;
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let fields: Vec<&str> = match options.format {
            RecordFormat::Csv => line.split(',').map(str::trim).collect(),
            _ => line.split_whitespace().collect(),
        };
        if std::mem::take(&mut first_row) {
            let numeric = |c: usize| {
                fields
                    .get(c)
                    .is_some_and(|f| parse_fortran_float(f).is_some())
            };
            let any_text = fields.iter().any(|f| parse_fortran_float(f).is_none());
            if any_text && !(numeric(options.time_column) && numeric(options.accel_column)) {
                continue; // header row
            }
        }
        if fields.len() < needed {
            return Err(err(
                line_no,
                format!("expected at least {needed} columns, found {}", fields.len()),
            ));
        }
        let number = |column: usize, what: &str| {
            let token = fields[column];
            parse_fortran_float(token).ok_or_else(|| {
                err(
                    line_no,
                    format!("invalid {what} `{token}` in column {column}"),
                )
            })
        };
        let t = number(options.time_column, "time")?;
        let a = number(options.accel_column, "acceleration")?;
        if let Some(&prev) = times.last()
            && t <= prev
        {
            return Err(err(
                line_no,
                format!(
                    "time {t} is not greater than the previous time {prev} (line {previous_line}); \
                     times must be strictly increasing"
                ),
            ));
        }
        times.push(t);
        accel.push(options.units.to_si(a));
        previous_line = line_no;
    }
    if times.len() < 2 {
        return Err(GroundMotionError::Format {
            path: source.to_string(),
            message: format!("a record needs at least 2 samples, found {}", times.len()),
        });
    }
    Record::from_samples(times, accel)
        .map(|r| r.with_source(source))
        .map_err(|e| GroundMotionError::Format {
            path: source.to_string(),
            message: e.to_string(),
        })
}
