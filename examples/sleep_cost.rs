//! Steps a model N times with `<flag sleep>` on or off, for `validation/sleep_cost.sh` (callgrind
//! instruction counts per step; docs/constraints.md, "Sleeping islands"), and prints how many
//! trees sleep, the rows and the collision pairs tested at the last step.
//!
//!     cargo run --release --example sleep_cost -- MODEL on|off N

use lagrange::prelude::*;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let [_, path, mode, n] = &args[..] else {
        return Err("usage: sleep_cost MODEL on|off N".into());
    };
    let mut model = Model::from_file(path)?;
    model.options.flags.sleep = match mode.as_str() {
        "on" => true,
        "off" => false,
        other => return Err(format!("mode '{other}': use on or off").into()),
    };
    let n: usize = n.parse()?;
    let mut data = Data::new(&model);
    for _ in 0..n {
        step(&model, &mut data)?;
    }
    println!(
        "{n} steps, sleep {mode}: {} of {} trees asleep, {} rows, {} collision pairs tested",
        data.sleep.nasleep(),
        model.sleep.ntree(),
        data.nefc,
        data.sleep.pairs_tested
    );
    Ok(())
}
