//! Progress bars of the commands that can run long (`simulate`, `eval` with many states,
//! `workprec`), on stderr. indicatif draws them only when stderr is a terminal, so pipes, files
//! and the tests see nothing; stdout (tables, JSON) is never touched.

use indicatif::{ProgressBar, ProgressStyle};

/// A bar over `len` items called `unit` ("steps", "runs"), or a counter when the length is not
/// known in advance (`None`: states streamed from a file).
pub fn bar(len: Option<u64>, unit: &str) -> ProgressBar {
    match len {
        Some(len) => {
            let bar = ProgressBar::new(len);
            bar.set_style(
                ProgressStyle::with_template(&format!(
                    "{{bar:40}} {{pos}}/{{len}} {unit}, {{elapsed}} elapsed, eta {{eta}}"
                ))
                .expect("static template"),
            );
            bar
        }
        None => {
            let bar = ProgressBar::no_length();
            bar.set_style(
                ProgressStyle::with_template(&format!(
                    "{{spinner}} {{pos}} {unit}, {{elapsed}} elapsed, {{per_sec}}"
                ))
                .expect("static template"),
            );
            bar
        }
    }
}
