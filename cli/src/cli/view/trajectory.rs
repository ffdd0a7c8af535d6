//! Reading a `lagrange simulate --out` trajectory CSV for the viewer: the header names the
//! columns (`time`, `q:JOINT[k]`, `v:JOINT[k]`, `act:ACTUATOR`, then energy, violation and
//! sensors); the rows are kept at the display rate: for each n the row nearest to n / fps after
//! the first row (the first at or after it less half a row interval), and the last row.

use super::super::CliError;
use lagrange::Model;
use std::io::{BufRead, BufReader};
use std::path::Path;

/// One kept row of the trajectory.
pub struct Row {
    /// Time (s).
    pub time: f64,
    /// Joint positions (nq).
    pub qpos: Vec<f64>,
    /// Joint velocities (nv).
    pub qvel: Vec<f64>,
    /// Actuator activations (na).
    pub act: Vec<f64>,
}

/// The rows of the CSV at `path` for `model`, sampled at `fps` frames per second.
///
/// # Errors
/// The file cannot be read, its header does not match the model (another model's trajectory), or
/// a row has a value that is not a number.
pub fn read(path: &Path, model: &Model, fps: f64) -> Result<Vec<Row>, CliError> {
    let file_name = path.display().to_string();
    let bad = |detail: String| CliError::Input { file: file_name.clone(), detail };
    let file =
        std::fs::File::open(path).map_err(|source| CliError::Io { file: file_name.clone(), source })?;
    let mut lines = BufReader::new(file).lines();
    let header = match lines.next() {
        Some(line) => line.map_err(|source| CliError::Io { file: file_name.clone(), source })?,
        None => {
            return Err(bad("the file is empty: expected the header of `lagrange simulate --out`".into()))
        }
    };
    let columns: Vec<&str> = header.split(',').collect();
    let count = |prefix: &str| columns.iter().filter(|c| c.starts_with(prefix)).count();
    let (nq, nv, na) = (count("q:"), count("v:"), count("act:"));
    if columns.first() != Some(&"time") || nq != model.nq || nv != model.nv || na != model.na() {
        return Err(bad(format!(
            "the header has {nq} q, {nv} v and {na} act columns; the model has nq = {}, nv = {}, na = {}: is this a `lagrange simulate --out` file of this model?",
            model.nq,
            model.nv,
            model.na()
        )));
    }
    let interval = 1.0 / fps;
    let mut rows: Vec<Row> = Vec::new();
    let mut last: Option<Row> = None;
    let mut half_step: Option<f64> = None;
    for (i, line) in lines.enumerate() {
        let line = line.map_err(|source| CliError::Io { file: file_name.clone(), source })?;
        if line.is_empty() {
            continue;
        }
        let values: Result<Vec<f64>, _> =
            line.split(',').take(1 + nq + nv + na).map(str::parse::<f64>).collect();
        let values = values.map_err(|e| bad(format!("line {}: {e}", i + 2)))?;
        if values.len() < 1 + nq + nv + na {
            return Err(bad(format!(
                "line {}: {} values, expected at least {}",
                i + 2,
                values.len(),
                1 + nq + nv + na
            )));
        }
        let row = Row {
            time: values[0],
            qpos: values[1..1 + nq].to_vec(),
            qvel: values[1 + nq..1 + nq + nv].to_vec(),
            act: values[1 + nq + nv..1 + nq + nv + na].to_vec(),
        };
        // Frame n is the first row at or after n / fps from the first row less half a row
        // interval (the state nearest to n / fps, as `simulate --view` keeps).
        if rows.len() == 1 && half_step.is_none() {
            half_step = Some(0.5 * (row.time - rows[0].time));
        }
        let due = rows.first().is_none_or(|r0| {
            row.time - r0.time >= rows.len() as f64 * interval - half_step.unwrap_or(0.0) * (1.0 + 1e-6)
        });
        if due {
            rows.push(row);
            last = None;
        } else {
            last = Some(row);
        }
    }
    rows.extend(last);
    if rows.is_empty() {
        return Err(bad("no rows after the header".into()));
    }
    Ok(rows)
}
