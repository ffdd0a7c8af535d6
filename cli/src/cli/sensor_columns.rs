//! The sensors in the command line's outputs: one CSV column per sensor component
//! (`sensor:NAME[i]`), the `simulate --json` summary's and each `eval` result's `"sensors"`.
//! Each CSV row's sensors are those of the row's state: `forward` on a scratch copy of the inputs and state (the simulation's own `Data`,
//! warm starts included, is untouched, so writing them does not change the trajectory).

use lagrange::forward::forward;
use lagrange::{Data, Model};
use serde_json::{json, Map, Value};
use std::io::Write;

/// A scratch `Data` evaluating the sensors at a simulation's state.
pub struct SensorProbe {
    data: Data,
}

/// The computed sensors, in model order (those a CSV and a summary report).
fn computed(model: &Model) -> impl Iterator<Item = &lagrange::sensor::Sensor> {
    model.sensors.iter().filter(|s| s.is_computed() && model.options.flags.sensor)
}

impl SensorProbe {
    /// A probe for `model`, or None when it computes no sensor.
    pub fn new(model: &Model) -> Option<Self> {
        computed(model).next().map(|_| SensorProbe { data: Data::new(model) })
    }

    /// `sensordata` at `state`'s state and inputs.
    pub fn read(&mut self, model: &Model, state: &Data) -> &[f64] {
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
        d.sensordata.as_slice()
    }
}

/// The number of sensor columns of the CSV.
pub fn count(model: &Model) -> usize {
    computed(model).map(|s| s.dim).sum()
}

/// The CSV header's sensor columns (`,sensor:NAME[i]` for each component).
pub fn write_header(w: &mut impl Write, model: &Model) -> std::io::Result<()> {
    for s in computed(model) {
        let label = s.label();
        for i in 0..s.dim {
            write!(w, ",sensor:{label}[{i}]")?;
        }
    }
    Ok(())
}

/// The row's sensor values, in the header's order.
pub fn write_values(w: &mut impl Write, model: &Model, sensordata: &[f64]) -> std::io::Result<()> {
    for s in computed(model) {
        for x in &sensordata[s.adr..s.adr + s.dim] {
            write!(w, ",{x}")?;
        }
    }
    Ok(())
}

/// `{"NAME": [values]}` for the computed sensors.
pub fn to_json(model: &Model, sensordata: &[f64]) -> Value {
    let mut map = Map::new();
    for s in computed(model) {
        map.insert(s.label(), json!(sensordata[s.adr..s.adr + s.dim]));
    }
    Value::Object(map)
}
