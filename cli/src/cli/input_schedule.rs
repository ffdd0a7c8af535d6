//! Time-varying inputs of `simulate`: `--ctrl-file` (actuator controls, MuJoCo's `ctrl`) and
//! `--tau-file` (applied joint forces, MuJoCo's `qfrc_applied`), read from CSV files.
//!
//! A file has a header `time,NAME,NAME,...` and one row per sample time, times strictly
//! increasing, every value a finite number. A control file's columns name actuators; a torque
//! file's name degrees of freedom: a one-dof joint by its name, any dof as `JOINT[k]` (a free
//! joint's six as `root[0]`…`root[5]`, MuJoCo's qvel order). Columns may be any subset: the
//! inputs not named keep their initial values (zero, or the keyframe's controls).
//!
//! Between two rows the value is interpolated linearly (`--input-interp linear`, the default) or
//! held from the earlier row (`--input-interp hold`, zero-order hold); before the first row the
//! first row's values apply, after the last row the last row's values are held.

use super::CliError;
use std::path::{Path, PathBuf};

/// How values between two rows are taken.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Interp {
    /// Linear interpolation between the neighbouring rows.
    Linear,
    /// The earlier row's value (zero-order hold).
    Hold,
}

/// A table of inputs over time, for some of a vector's entries.
pub struct Schedule {
    /// Index into the input vector of each column after `time`.
    targets: Vec<usize>,
    times: Vec<f64>,
    /// Row-major values, `times.len() × targets.len()`.
    values: Vec<f64>,
    interp: Interp,
    /// Row of the last lookup (lookups move forward in time: amortized O(1)).
    cursor: usize,
}

fn bad(file: &Path, detail: String) -> CliError {
    CliError::Usage(format!("{}: {detail}", file.display()))
}

impl Schedule {
    /// Reads `file`; `resolve` maps a column name to an input index, or explains the names it
    /// takes. `option` names the command-line option in messages.
    pub fn read(
        file: &Path,
        option: &str,
        interp: Interp,
        resolve: impl Fn(&str) -> Result<usize, String>,
    ) -> Result<Self, CliError> {
        let label = PathBuf::from(format!("{option} {}", file.display()));
        let mut reader = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .from_path(file)
            .map_err(|e| bad(&label, format!("cannot read the file: {e}")))?;
        let header =
            reader.headers().map_err(|e| bad(&label, format!("cannot read the header: {e}")))?.clone();
        if header.get(0) != Some("time") {
            return Err(bad(
                &label,
                format!(
                    "the first column is '{}', not 'time': the header is time,NAME,NAME,... (one column per input)",
                    header.get(0).unwrap_or("")
                ),
            ));
        }
        let mut targets = Vec::with_capacity(header.len() - 1);
        for name in header.iter().skip(1) {
            let target = resolve(name).map_err(|e| bad(&label, format!("column '{name}': {e}")))?;
            if targets.contains(&target) {
                return Err(bad(
                    &label,
                    format!("column '{name}' names an input already given by another column"),
                ));
            }
            targets.push(target);
        }
        let (mut times, mut values) = (Vec::new(), Vec::new());
        for (i, record) in reader.records().enumerate() {
            let line = i + 2;
            let record = record.map_err(|e| bad(&label, format!("line {line}: {e}")))?;
            if record.len() != header.len() {
                return Err(bad(
                    &label,
                    format!("line {line}: {} fields, the header has {}", record.len(), header.len()),
                ));
            }
            for (k, field) in record.iter().enumerate() {
                let x: f64 = field.parse().map_err(|_| {
                    bad(&label, format!("line {line}, column '{}': '{field}' is not a number", &header[k]))
                })?;
                if !x.is_finite() {
                    return Err(bad(
                        &label,
                        format!(
                            "line {line}, column '{}': {x} is not finite; give finite numbers",
                            &header[k]
                        ),
                    ));
                }
                if k == 0 {
                    if times.last().is_some_and(|&t: &f64| x <= t) {
                        return Err(bad(
                            &label,
                            format!("line {line}: time {x} does not come after the previous row's; times must increase"),
                        ));
                    }
                    times.push(x);
                } else {
                    values.push(x);
                }
            }
        }
        if times.is_empty() {
            return Err(bad(&label, "no rows: give at least one time and its values".into()));
        }
        Ok(Schedule { targets, times, values, interp, cursor: 0 })
    }

    /// Writes the inputs at time `t` into their entries of `out` (the others are left alone).
    pub fn apply(&mut self, t: f64, out: &mut [f64]) {
        let n = self.targets.len();
        // The row at or before t (0 before the first).
        while self.cursor + 1 < self.times.len() && self.times[self.cursor + 1] <= t {
            self.cursor += 1;
        }
        while self.cursor > 0 && self.times[self.cursor] > t {
            self.cursor -= 1;
        }
        let i = self.cursor;
        let row = |r: usize| &self.values[r * n..(r + 1) * n];
        let last = i + 1 >= self.times.len();
        if last || t <= self.times[i] || self.interp == Interp::Hold {
            for (&target, &x) in self.targets.iter().zip(row(i)) {
                out[target] = x;
            }
            return;
        }
        let s = (t - self.times[i]) / (self.times[i + 1] - self.times[i]);
        for ((&target, &a), &b) in self.targets.iter().zip(row(i)).zip(row(i + 1)) {
            out[target] = a + s * (b - a);
        }
    }
}

/// The actuator a `--ctrl-file` column names.
pub fn actuator_column(model: &lagrange::Model, name: &str) -> Result<usize, String> {
    let name = name.strip_prefix("ctrl:").unwrap_or(name);
    model.actuators.iter().position(|a| a.name == name).ok_or_else(|| {
        let known: Vec<&str> =
            model.actuators.iter().map(|a| a.name.as_str()).filter(|n| !n.is_empty()).collect();
        if model.actuators.is_empty() {
            "the model has no actuators; drive its joints with --tau-file".to_string()
        } else {
            format!("no actuator of that name (the model's: {})", known.join(", "))
        }
    })
}

/// The degree of freedom a `--tau-file` column names: `JOINT` (one-dof joints) or `JOINT[k]`.
pub fn dof_column(model: &lagrange::Model, name: &str) -> Result<usize, String> {
    let name = name.strip_prefix("tau:").unwrap_or(name);
    let (joint, k) = match name.strip_suffix(']').and_then(|s| s.rsplit_once('[')) {
        Some((joint, k)) => {
            (joint, Some(k.parse::<usize>().map_err(|_| format!("'{k}' is not a dof index"))?))
        }
        None => (name, None),
    };
    let Some(j) = model.joints.iter().find(|j| j.name == joint) else {
        let known: Vec<&str> =
            model.joints.iter().filter(|j| j.kind.nv() > 0).map(|j| j.name.as_str()).collect();
        return Err(format!("no joint of that name (the model's: {})", known.join(", ")));
    };
    let nv = j.kind.nv();
    match k {
        None if nv == 1 => Ok(j.dof_adr),
        None => Err(format!(
            "joint '{joint}' has {nv} dofs: name each as {joint}[0] … {joint}[{}]",
            nv.saturating_sub(1)
        )),
        Some(k) if k < nv => Ok(j.dof_adr + k),
        Some(k) => Err(format!("joint '{joint}' has {nv} dofs; [{k}] is out of range")),
    }
}
