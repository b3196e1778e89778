//! Standard output: every command prints through [`Stdout`] ([`print`],
//! or as a writer handed to the library), never `print!`/`println!`, which
//! panic when standard output is closed or full.
//!
//! A failed write is returned as an error tagged [`StdoutError`]; `main`
//! treats a broken pipe ([`is_broken_pipe`]: the reader went away, as in
//! `palpate precomputed replay … | head -1`) as a normal end, exit 0 with
//! nothing on stderr, and any other failure (`> /dev/full`) as the usual
//! one-line error, exit 2.

use std::io::{self, Write};

/// A failed write to standard output (the underlying error).
#[derive(Debug, thiserror::Error)]
#[error("standard output: {0}")]
pub struct StdoutError(io::Error);

/// `err`, tagged as standard output's, of the same kind.
fn tagged(err: io::Error) -> io::Error {
    io::Error::new(err.kind(), StdoutError(err))
}

/// The process's standard output as a writer whose errors are tagged
/// [`StdoutError`]. Unbuffered beyond the standard library's line buffer:
/// call `flush` at the end.
#[derive(Clone, Copy, Debug, Default)]
pub struct Stdout;

impl Write for Stdout {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        io::stdout().lock().write(buf).map_err(tagged)
    }

    fn write_all(&mut self, buf: &[u8]) -> io::Result<()> {
        io::stdout().lock().write_all(buf).map_err(tagged)
    }

    fn flush(&mut self) -> io::Result<()> {
        io::stdout().lock().flush().map_err(tagged)
    }
}

/// Writes `text` to standard output and flushes it.
pub fn print(text: &str) -> io::Result<()> {
    let mut out = io::stdout().lock();
    out.write_all(text.as_bytes()).map_err(tagged)?;
    out.flush().map_err(tagged)
}

/// Writes `text` and a newline to standard output and flushes it.
pub fn println(text: &str) -> io::Result<()> {
    let mut out = io::stdout().lock();
    out.write_all(text.as_bytes()).map_err(tagged)?;
    out.write_all(b"\n").map_err(tagged)?;
    out.flush().map_err(tagged)
}

/// Whether `err` is a write to standard output that failed because its
/// reader closed the pipe: the command's output is no longer wanted, and
/// the run ends normally.
pub fn is_broken_pipe(err: &anyhow::Error) -> bool {
    err.chain().any(|cause| {
        cause.downcast_ref::<io::Error>().is_some_and(|e| {
            e.kind() == io::ErrorKind::BrokenPipe
                && e.get_ref().is_some_and(|inner| inner.is::<StdoutError>())
        })
    })
}
