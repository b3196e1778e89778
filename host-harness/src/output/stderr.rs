//! Standard error: every progress line, warning, summary and the final
//! `error: …` line goes through `line` (or, for a progress bar,
//! [`progress_bar`]), never `eprintln!`, which panics (an abort in the
//! release build) when standard error is closed or full (`2>/dev/full`,
//! `2>&-`).
//!
//! Standard error carries diagnostics, not results: a failed write to it
//! is ignored, and the run goes on to write its outputs and end with its
//! own status (`0`, or `2` for an error that could not be shown).
//! indicatif's bars draw to standard error too and discard their own write
//! errors (indicatif 0.18: `BarState` ignores each draw's result); without
//! a terminal they are hidden and [`progress_bar`]'s callers print lines
//! through `line` instead.

use std::io::{self, Write};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Writes `text` and a newline to standard error in one locked write; a
/// failure is ignored (module docs).
pub fn line(text: &str) {
    let mut err = io::stderr().lock();
    let _ = err
        .write_all(text.as_bytes())
        .and_then(|()| err.write_all(b"\n"))
        .and_then(|()| err.flush());
}

/// A progress bar of `len` steps drawn on standard error with `template`
/// (indicatif's syntax; the default style if it does not parse), or a
/// hidden one when `shown` is false.
pub fn progress_bar(len: u64, template: &str, shown: bool) -> ProgressBar {
    if !shown {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
    if let Ok(style) = ProgressStyle::with_template(template) {
        bar.set_style(style);
    }
    bar
}
