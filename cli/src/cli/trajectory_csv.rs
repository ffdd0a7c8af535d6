//! The trajectory CSV of `simulate --out`, written through the `csv` crate (names with commas or
//! quotes are quoted). One row per state, the initial one first:
//!
//! `time`, `q:JOINT[k]` (qpos), `v:JOINT[k]` (qvel), `act:ACTUATOR` (activations),
//! `ctrl:ACTUATOR` (the controls applied from this state on), `actuator_force:ACTUATOR` (MuJoCo's
//! `actuator_force` at this state), `energy`, `constraint_violation`, `sensor:NAME[i]` (the
//! computed sensors at this state). Unnamed actuators are `actuator{i}`.
//!
//! `actuator_force` and the sensors are the row's own: `forward` on a scratch copy of the state
//! and inputs ([`RowProbe`]); the simulation itself is untouched, so writing a CSV does not change
//! the trajectory.

use super::sensor_columns;
use lagrange::forward::forward;
use lagrange::sim::{display_time, Simulation};
use lagrange::{Data, Model};
use std::fmt::Write as _;

/// A scratch `Data` evaluating a row's outputs (actuator forces, sensors) at a simulation's state.
pub struct RowProbe {
    data: Data,
}

impl RowProbe {
    /// A probe for `model`, or None when a row needs no evaluation (no actuators, no computed
    /// sensors).
    pub fn new(model: &Model) -> Option<Self> {
        (sensor_columns::count(model) > 0 || !model.actuators.is_empty())
            .then(|| RowProbe { data: Data::new(model) })
    }

    /// `forward` at `state`'s state and inputs; the evaluated data.
    pub fn read(&mut self, model: &Model, state: &Data) -> &Data {
        let d = &mut self.data;
        d.time = state.time;
        d.qpos.copy_from(&state.qpos);
        d.qvel.copy_from(&state.qvel);
        d.act.copy_from(&state.act);
        d.ctrl.copy_from(&state.ctrl);
        d.qfrc_applied.copy_from(&state.qfrc_applied);
        d.xfrc_applied.copy_from_slice(&state.xfrc_applied);
        d.mocap_pos.copy_from_slice(&state.mocap_pos);
        d.mocap_quat.copy_from_slice(&state.mocap_quat);
        forward(model, d);
        d
    }
}

fn actuator_label(model: &Model, i: usize) -> String {
    match model.actuators[i].name.as_str() {
        "" => format!("actuator{i}"),
        name => name.to_string(),
    }
}

/// The header's column names.
pub fn columns(model: &Model) -> Vec<String> {
    let mut out = vec!["time".to_string()];
    for (prefix, n) in [("q", 0), ("v", 1)] {
        for j in &model.joints {
            let count = if n == 0 { j.kind.nq() } else { j.kind.nv() };
            out.extend((0..count).map(|k| format!("{prefix}:{}[{k}]", j.name)));
        }
    }
    // Activations (MuJoCo's act), one column per actuator with activation dynamics.
    for (i, _) in model.actuators.iter().enumerate().filter(|(_, a)| a.actnum() == 1) {
        out.push(format!("act:{}", actuator_label(model, i)));
    }
    for prefix in ["ctrl", "actuator_force"] {
        out.extend((0..model.actuators.len()).map(|i| format!("{prefix}:{}", actuator_label(model, i))));
    }
    out.push("energy".into());
    out.push("constraint_violation".into());
    out.extend(sensor_columns::labels(model));
    out
}

/// The bytes the csv writer has flushed, taken out after each record (the writer owns its sink
/// and only lends it immutably).
#[derive(Default)]
struct Pending(std::cell::RefCell<Vec<u8>>);

impl std::io::Write for Pending {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        self.0.get_mut().extend_from_slice(bytes);
        Ok(bytes.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// Formats rows into a caller's byte buffer; reuses its buffers from row to row.
pub struct TrajectoryCsv {
    writer: csv::Writer<Pending>,
    field: String,
    probe: Option<RowProbe>,
}

impl TrajectoryCsv {
    /// A writer for `model`'s trajectories.
    pub fn new(model: &Model) -> Self {
        TrajectoryCsv {
            writer: csv::WriterBuilder::new().has_headers(false).from_writer(Pending::default()),
            field: String::new(),
            probe: RowProbe::new(model),
        }
    }

    /// Moves the formatted record into `out`.
    fn take(&mut self, out: &mut Vec<u8>) -> std::io::Result<()> {
        self.writer.flush()?;
        let mut pending = self.writer.get_ref().0.borrow_mut();
        out.extend_from_slice(&pending);
        pending.clear();
        Ok(())
    }

    /// Appends the header line to `out`.
    pub fn header(&mut self, model: &Model, out: &mut Vec<u8>) -> std::io::Result<()> {
        self.writer.write_record(columns(model))?;
        self.take(out)
    }

    fn number(&mut self, x: f64) -> std::io::Result<()> {
        self.field.clear();
        // Writing into a String does not fail.
        let _ = write!(self.field, "{x}");
        self.writer.write_field(&self.field)?;
        Ok(())
    }

    /// Appends the row of `sim`'s current state to `out`, or says which evaluated value (an
    /// actuator force, a sensor) is not finite: no row with a NaN or an infinity is written.
    pub fn row(
        &mut self,
        model: &Model,
        sim: &Simulation,
        energy: f64,
        violation: f64,
        out: &mut Vec<u8>,
    ) -> Result<(), RowFailure> {
        let d = &sim.data;
        let Some(mut probe) = self.probe.take() else {
            self.state_fields(d)?;
            self.number(energy)?;
            self.number(violation)?;
            return self.end(out);
        };
        let evaluated = probe.read(model, d);
        let result = match non_finite(model, evaluated) {
            Some(what) => Err(RowFailure::NonFinite(what)),
            None => (|| {
                self.state_fields(d)?;
                for &x in evaluated.actuator_force.iter() {
                    self.number(x)?;
                }
                self.number(energy)?;
                self.number(violation)?;
                for &x in sensor_columns::values(model, evaluated.sensordata.as_slice()) {
                    self.number(x)?;
                }
                self.end(out)
            })(),
        };
        self.probe = Some(probe);
        result
    }

    /// time, qpos, qvel, act, ctrl.
    fn state_fields(&mut self, d: &Data) -> std::io::Result<()> {
        self.number(display_time(d.time))?;
        for &x in d.qpos.iter().chain(d.qvel.iter()).chain(d.act.iter()).chain(d.ctrl.iter()) {
            self.number(x)?;
        }
        Ok(())
    }

    /// Ends the record and moves it into `out`.
    fn end(&mut self, out: &mut Vec<u8>) -> Result<(), RowFailure> {
        self.writer.write_record(None::<&[u8]>).map_err(std::io::Error::from)?;
        Ok(self.take(out)?)
    }
}

/// Why a row was not written.
#[derive(Debug)]
pub enum RowFailure {
    /// A value evaluated at the row's state is not finite (named).
    NonFinite(String),
    /// Formatting failed.
    Io(std::io::Error),
}

impl From<std::io::Error> for RowFailure {
    fn from(e: std::io::Error) -> Self {
        RowFailure::Io(e)
    }
}

/// The first actuator force or computed sensor value of `data` that is not finite, named.
fn non_finite(model: &Model, data: &Data) -> Option<String> {
    if let Some(i) = data.actuator_force.iter().position(|x| !x.is_finite()) {
        return Some(format!(
            "actuator_force of '{}' is {}",
            actuator_label(model, i),
            data.actuator_force[i]
        ));
    }
    let bad = sensor_columns::labels(model)
        .zip(sensor_columns::values(model, data.sensordata.as_slice()))
        .find(|(_, x)| !x.is_finite());
    bad.map(|(label, x)| format!("{label} is {x}"))
}
