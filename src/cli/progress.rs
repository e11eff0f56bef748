//! Progress on the terminal: a spinner line per phase (refinement has no known total), hidden with
//! `--quiet`; when stderr is not a terminal, a line per finished level instead.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use radiosity::pipeline::Progress;
use std::io::IsTerminal;
use std::time::Duration;

/// A progress display that may be hidden.
pub struct Reporter {
    bar: ProgressBar,
    /// Not a terminal and not quiet: each finished level as a line of its own (a log of a long
    /// solve in a batch job).
    lines: bool,
}

impl Reporter {
    /// Visible only when `!quiet` and stderr is a terminal.
    pub fn new(quiet: bool) -> Reporter {
        let lines = !quiet && !std::io::stderr().is_terminal();
        let bar = if quiet || !std::io::stderr().is_terminal() {
            ProgressBar::with_draw_target(None, ProgressDrawTarget::hidden())
        } else {
            let bar = ProgressBar::new_spinner();
            bar.set_style(ProgressStyle::with_template("{spinner} [{elapsed_precise}] {msg}").expect("static template"));
            bar.enable_steady_tick(Duration::from_millis(120));
            bar
        };
        Reporter { bar, lines }
    }

    /// Shows a phase name.
    pub fn phase(&self, msg: &str) {
        self.bar.set_message(msg.to_string());
    }

    /// Shows a pipeline event.
    pub fn event(&self, p: Progress) {
        if let (true, Progress::Level { level, report }) = (self.lines, &p) {
            let estimate = report.error_estimate.map_or(String::new(), |e| format!(", estimated error {:.2}%", 100.0 * e));
            let refined = report.polygons_refined.map_or(String::new(), |n| format!(", {n} polygons refined further"));
            let t = &report.phases;
            eprintln!(
                "level {level}: {} links{estimate}{refined} ({:.1} s; this level: refine {:.1} s, solve {:.1} s of which leaf operator {:.1} s, estimate {:.1} s)",
                report.links, report.time_s, t.refine, t.solve, t.leaf_operator, t.estimate
            );
        }
        let msg = match p {
            Progress::Refine { level, pass, links, pending } => {
                format!("level {level}, refine pass {pass}: {links} links, {pending} candidates pending")
            }
            Progress::LeafSolve { entries, over_budget } => {
                format!(
                    "leaf-resolution solve: {entries} coefficients{}",
                    if over_budget { " (over budget: recomputed each iteration)" } else { "" }
                )
            }
            Progress::Solved { pass, iterations, residual } => {
                format!("solve pass {pass}: {iterations} iterations, residual {residual:.1e}")
            }
            Progress::Level { level, report } => match report.error_estimate {
                Some(e) => format!("level {level}: {} links, estimated error {:.2}%", report.links, 100.0 * e),
                None => format!("level {level}: {} links", report.links),
            },
        };
        self.bar.set_message(msg);
    }

    /// Removes the line.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}
