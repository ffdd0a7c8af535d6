//! The sensors in the command line's outputs: one CSV column per sensor component
//! (`sensor:NAME[i]`, written by [`super::trajectory_csv`] at each row's own state), the
//! `simulate --json` summary's and each `eval` result's `"sensors"`.

use lagrange::Model;
use serde_json::{json, Map, Value};

/// The computed sensors, in model order (those a CSV and a summary report).
fn computed(model: &Model) -> impl Iterator<Item = &lagrange::sensor::Sensor> {
    model.sensors.iter().filter(|s| s.is_computed() && model.options.flags.sensor)
}

/// The number of sensor columns of the CSV.
pub fn count(model: &Model) -> usize {
    computed(model).map(|s| s.dim).sum()
}

/// The CSV header's sensor columns (`sensor:NAME[i]` for each component).
pub fn labels(model: &Model) -> impl Iterator<Item = String> + '_ {
    computed(model).flat_map(|s| {
        let label = s.label();
        (0..s.dim).map(move |i| format!("sensor:{label}[{i}]"))
    })
}

/// A row's sensor values, in the header's order.
pub fn values<'a>(model: &'a Model, sensordata: &'a [f64]) -> impl Iterator<Item = &'a f64> + 'a {
    computed(model).flat_map(move |s| &sensordata[s.adr..s.adr + s.dim])
}

/// `{"NAME": [values]}` for the computed sensors.
pub fn to_json(model: &Model, sensordata: &[f64]) -> Value {
    let mut map = Map::new();
    for s in computed(model) {
        map.insert(s.label(), json!(sensordata[s.adr..s.adr + s.dim]));
    }
    Value::Object(map)
}
