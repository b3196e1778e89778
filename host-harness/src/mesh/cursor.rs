//! A panic-free byte cursor shared by the ASCII and binary readers.

use core::str::FromStr;

use super::MeshError;

/// Capacity to reserve for `declared` items: never more than the input could possibly hold.
pub(crate) fn cap(declared: usize, input_len: usize) -> usize {
    declared.min(input_len / 2 + 16)
}

/// Reads tokens, lines and binary numbers from a byte buffer. Never panics.
pub(crate) struct Cursor<'a> {
    buf: &'a [u8],
    pos: usize,
    file: &'a str,
    /// What is being read, for messages (e.g. `$Nodes`).
    pub(crate) section: &'static str,
}

impl<'a> Cursor<'a> {
    pub(crate) fn new(buf: &'a [u8], file: &'a str) -> Self {
        Self {
            buf,
            pos: 0,
            file,
            section: "header",
        }
    }

    pub(crate) fn len(&self) -> usize {
        self.buf.len()
    }

    pub(crate) fn file(&self) -> &'a str {
        self.file
    }

    fn line_no(&self) -> usize {
        let end = self.pos.min(self.buf.len());
        self.buf
            .get(..end)
            .map_or(0, |b| b.iter().filter(|&&c| c == b'\n').count())
            + 1
    }

    /// A parse error at the current position.
    pub(crate) fn err(&self, msg: impl core::fmt::Display) -> MeshError {
        MeshError::Parse {
            file: self.file.to_string(),
            msg: format!("{} (line {}): {msg}", self.section, self.line_no()),
        }
    }

    /// An unexpected-end-of-file error.
    pub(crate) fn eof(&self, what: impl core::fmt::Display) -> MeshError {
        MeshError::Parse {
            file: self.file.to_string(),
            msg: format!(
                "{}: unexpected end of file (truncated?) while reading {what}",
                self.section
            ),
        }
    }

    /// The bytes not read yet.
    pub(crate) fn rest(&self) -> &'a [u8] {
        self.buf.get(self.pos..).unwrap_or(&[])
    }

    pub(crate) fn at_end(&self) -> bool {
        self.pos >= self.buf.len()
    }

    fn skip_ws(&mut self) {
        while let Some(c) = self.buf.get(self.pos) {
            if c.is_ascii_whitespace() {
                self.pos += 1;
            } else {
                break;
            }
        }
    }

    /// Next whitespace-separated token, or `None` at end of input.
    pub(crate) fn token(&mut self) -> Option<&'a [u8]> {
        self.skip_ws();
        let start = self.pos;
        while let Some(c) = self.buf.get(self.pos) {
            if c.is_ascii_whitespace() {
                break;
            }
            self.pos += 1;
        }
        if self.pos > start {
            self.buf.get(start..self.pos)
        } else {
            None
        }
    }

    /// The next token without consuming it.
    pub(crate) fn peek_token(&mut self) -> Option<&'a [u8]> {
        let save = self.pos;
        let t = self.token();
        self.pos = save;
        t
    }

    /// Next token, or an end-of-file error naming `what`.
    pub(crate) fn expect_token(
        &mut self,
        what: &dyn core::fmt::Display,
    ) -> Result<&'a [u8], MeshError> {
        self.token().ok_or_else(|| self.eof(what))
    }

    /// Next token parsed as `T`.
    pub(crate) fn parse<T: FromStr>(
        &mut self,
        what: &dyn core::fmt::Display,
    ) -> Result<T, MeshError> {
        let tok = self.expect_token(what)?;
        parse_tok(tok).ok_or_else(|| {
            self.err(format_args!(
                "{what}: expected a number, found {:?}",
                show(tok)
            ))
        })
    }

    /// Rest of the current line (without `\r\n`), advancing past the newline.
    pub(crate) fn line(&mut self) -> Option<&'a [u8]> {
        if self.at_end() {
            return None;
        }
        let rest = self.buf.get(self.pos..)?;
        let (line, adv) = match rest.iter().position(|&c| c == b'\n') {
            Some(i) => (rest.get(..i)?, i + 1),
            None => (rest, rest.len()),
        };
        self.pos += adv;
        Some(line.strip_suffix(b"\r").unwrap_or(line))
    }

    /// Next line holding something other than whitespace, trimmed.
    pub(crate) fn nonempty_line(&mut self) -> Option<&'a [u8]> {
        loop {
            let l = self.line()?;
            let t = l.trim_ascii();
            if !t.is_empty() {
                return Some(t);
            }
        }
    }

    /// Skip past the next newline (start of binary data after a header line).
    pub(crate) fn skip_line(&mut self) {
        let _ = self.line();
    }

    /// Advance past the next occurrence of `pat`; false if not found.
    pub(crate) fn skip_past(&mut self, pat: &[u8]) -> bool {
        let Some(rest) = self.buf.get(self.pos..) else {
            return false;
        };
        if pat.is_empty() {
            return true;
        }
        match rest.windows(pat.len()).position(|w| w == pat) {
            Some(i) => {
                self.pos += i + pat.len();
                true
            }
            None => {
                self.pos = self.buf.len();
                false
            }
        }
    }

    /// The next `n` raw bytes.
    pub(crate) fn bytes(
        &mut self,
        n: usize,
        what: &dyn core::fmt::Display,
    ) -> Result<&'a [u8], MeshError> {
        let end = self.pos.checked_add(n).ok_or_else(|| self.eof(what))?;
        let b = self.buf.get(self.pos..end).ok_or_else(|| self.eof(what))?;
        self.pos = end;
        Ok(b)
    }

    fn array<const N: usize>(
        &mut self,
        big: bool,
        what: &dyn core::fmt::Display,
    ) -> Result<[u8; N], MeshError> {
        let b = self.bytes(N, what)?;
        let mut a = [0u8; N];
        a.copy_from_slice(b);
        if big {
            a.reverse();
        }
        Ok(a)
    }

    /// Binary `i32` (little-endian unless `big`).
    pub(crate) fn i32(
        &mut self,
        big: bool,
        what: &dyn core::fmt::Display,
    ) -> Result<i32, MeshError> {
        Ok(i32::from_le_bytes(self.array(big, what)?))
    }

    /// Binary `i64`.
    pub(crate) fn i64(
        &mut self,
        big: bool,
        what: &dyn core::fmt::Display,
    ) -> Result<i64, MeshError> {
        Ok(i64::from_le_bytes(self.array(big, what)?))
    }

    /// Binary unsigned integer of `size` bytes (4 or 8), as `u64`.
    pub(crate) fn uint(
        &mut self,
        size: usize,
        big: bool,
        what: &dyn core::fmt::Display,
    ) -> Result<u64, MeshError> {
        match size {
            4 => Ok(u64::from(u32::from_le_bytes(self.array(big, what)?))),
            _ => Ok(u64::from_le_bytes(self.array(big, what)?)),
        }
    }

    /// Binary `f64`.
    pub(crate) fn f64(
        &mut self,
        big: bool,
        what: &dyn core::fmt::Display,
    ) -> Result<f64, MeshError> {
        Ok(f64::from_le_bytes(self.array(big, what)?))
    }

    /// Binary `f32`, widened.
    pub(crate) fn f32(
        &mut self,
        big: bool,
        what: &dyn core::fmt::Display,
    ) -> Result<f64, MeshError> {
        Ok(f64::from(f32::from_le_bytes(self.array(big, what)?)))
    }
}

/// A region id read as a number (an MSH tag, a VTK cell value, a TetGen attribute): an integer
/// in `0..=u32::MAX`, else `None`.
pub(crate) fn region_id(value: f64) -> Option<u32> {
    (value.fract() == 0.0 && (0.0..=f64::from(u32::MAX)).contains(&value)).then_some(value as u32)
}

/// The message of a value that is not a region id.
pub(crate) const NOT_A_REGION: &str = "is not a region id (an integer from 0 to 4294967295)";

/// Parse an ASCII token.
pub(crate) fn parse_tok<T: FromStr>(tok: &[u8]) -> Option<T> {
    core::str::from_utf8(tok).ok()?.parse().ok()
}

/// A token for an error message (lossy, at most 40 chars).
pub(crate) fn show(tok: &[u8]) -> String {
    String::from_utf8_lossy(tok).chars().take(40).collect()
}
