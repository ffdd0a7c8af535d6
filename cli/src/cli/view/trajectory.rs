//! Reading a `lagrange simulate --out` trajectory CSV for the viewer (the `csv` crate; the
//! format is `super::super::trajectory_csv`'s): the header names the columns (`time`,
//! `q:JOINT[k]`, `v:JOINT[k]`, `act:ACTUATOR`, `ctrl:ACTUATOR`, then the outputs); the rows are
//! kept at the display rate: for each n the row nearest to n / fps after the first row (the first
//! at or after it less half a row interval), and the last row.

use super::super::CliError;
use lagrange::Model;
use std::io::BufReader;
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
    /// The controls applied from this state on (one per actuator), when the file has them.
    pub ctrl: Option<Vec<f64>>,
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
    let mut reader = csv::ReaderBuilder::new().has_headers(true).from_reader(BufReader::new(file));
    let header = reader.headers().map_err(|e| bad(e.to_string()))?.clone();
    let index = |prefix: &str| -> Vec<usize> {
        header.iter().enumerate().filter(|(_, c)| c.starts_with(prefix)).map(|(i, _)| i).collect()
    };
    let (iq, iv, ia, ic) = (index("q:"), index("v:"), index("act:"), index("ctrl:"));
    let nu = model.actuators.len();
    if header.get(0) != Some("time")
        || iq.len() != model.nq
        || iv.len() != model.nv
        || ia.len() != model.na()
        || !(ic.is_empty() || ic.len() == nu)
    {
        return Err(bad(format!(
            "the header has {} q, {} v, {} act and {} ctrl columns; the model has nq = {}, nv = {}, na = {}, nu = {}: is this a `lagrange simulate --out` file of this model?",
            iq.len(),
            iv.len(),
            ia.len(),
            ic.len(),
            model.nq,
            model.nv,
            model.na(),
            nu
        )));
    }
    let interval = 1.0 / fps;
    let mut rows: Vec<Row> = Vec::new();
    let mut last: Option<Row> = None;
    let mut half_step: Option<f64> = None;
    for (i, record) in reader.records().enumerate() {
        let record = record.map_err(|e| bad(e.to_string()))?;
        let value = |c: usize| -> Result<f64, CliError> {
            let text = record.get(c).unwrap_or("");
            let x = text
                .trim()
                .parse::<f64>()
                .map_err(|e| bad(format!("row {}, column {}: {e} ('{text}')", i + 2, c + 1)))?;
            if !x.is_finite() {
                return Err(bad(format!(
                    "row {}, column {}: '{text}' is not a finite number; the page can only show finite states",
                    i + 2,
                    c + 1
                )));
            }
            Ok(x)
        };
        let take = |cols: &[usize]| cols.iter().map(|&c| value(c)).collect::<Result<Vec<f64>, CliError>>();
        let row = Row {
            time: value(0)?,
            qpos: take(&iq)?,
            qvel: take(&iv)?,
            act: take(&ia)?,
            ctrl: if ic.is_empty() { None } else { Some(take(&ic)?) },
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
