//! The line reading of the trace readers (`candump::Reader` and
//! `trace::Reader`): numbered lines of at most
//! [`MAX_LINE_LEN`] bytes, an over-long line consumed without being stored,
//! and no more lines once reading failed.

use std::io::{self, BufRead, Read};
use std::vec::Vec;

/// The longest line the readers accept, in bytes (a candump text-form
/// line of an extended frame with a timestamp and a 15-character interface
/// name is under 80).
pub const MAX_LINE_LEN: usize = 1024;

/// Why [`Lines::next_line`] gave no line.
#[derive(Debug)]
pub(crate) enum LineError {
    /// Reading the input failed: the last item of the reader.
    Io(io::Error),
    /// The line is longer than [`MAX_LINE_LEN`] bytes (its rest was
    /// skipped, not stored).
    TooLong,
}

/// Numbered lines of an input.
#[derive(Debug)]
pub(crate) struct Lines<R> {
    input: R,
    line: usize,
    buf: Vec<u8>,
    failed: bool,
}

impl<R: BufRead> Lines<R> {
    /// The lines of `input`, starting at line 1; `capacity` bytes of line
    /// buffer to begin with.
    pub(crate) fn new(input: R, capacity: usize) -> Lines<R> {
        Lines {
            input,
            line: 0,
            buf: Vec::with_capacity(capacity),
            failed: false,
        }
    }

    /// The number of the last line read (1-based; 0 before the first).
    pub(crate) fn number(&self) -> usize {
        self.line
    }

    /// The capacity of the line buffer (tests: over-long lines are not
    /// stored).
    #[cfg(test)]
    pub(crate) fn buffer_capacity(&self) -> usize {
        self.buf.capacity()
    }

    /// Gives the input back.
    pub(crate) fn into_inner(self) -> R {
        self.input
    }

    /// The first item `parse` makes of the next lines (given as
    /// [`Lines::next_line`] gives them; a line it makes nothing of is
    /// skipped); `None` at the end of the input.
    pub(crate) fn next_item<T>(
        &mut self,
        mut parse: impl FnMut(usize, Result<&[u8], LineError>) -> Option<T>,
    ) -> Option<T> {
        loop {
            let (line, bytes) = self.next_line()?;
            if let Some(item) = parse(line, bytes) {
                return Some(item);
            }
        }
    }

    /// The next line, its number and its bytes without the line end
    /// (`\n` or `\r\n`); `None` at the end of the input and after a
    /// failure to read (given once, as [`LineError::Io`]).
    pub(crate) fn next_line(&mut self) -> Option<(usize, Result<&[u8], LineError>)> {
        if self.failed {
            return None;
        }
        match read_bounded_line(&mut self.input, &mut self.buf) {
            Ok(false) => return None,
            Ok(true) => self.line += 1,
            Err(e) => {
                self.failed = true;
                return Some((self.line + 1, Err(LineError::Io(e))));
            }
        }
        let bytes = self.buf.strip_suffix(b"\n").unwrap_or(&self.buf);
        let bytes = bytes.strip_suffix(b"\r").unwrap_or(bytes);
        if bytes.len() > MAX_LINE_LEN {
            return Some((self.line, Err(LineError::TooLong)));
        }
        Some((self.line, Ok(bytes)))
    }
}

/// Reads the next line of `input` into `buf` (cleared first); `false` at
/// the end of the input. A line longer than [`MAX_LINE_LEN`] bytes (plus
/// its line end) is consumed but only its start is kept: `buf` then holds
/// more than [`MAX_LINE_LEN`] bytes, and nothing more is stored.
fn read_bounded_line<R: BufRead>(input: &mut R, buf: &mut Vec<u8>) -> io::Result<bool> {
    buf.clear();
    let limit = MAX_LINE_LEN as u64 + 2; // room for "\r\n"
    let n = Read::take(&mut *input, limit).read_until(b'\n', buf)?;
    if n == 0 {
        return Ok(false);
    }
    if buf.last() != Some(&b'\n') && buf.len() as u64 == limit {
        // Too long: skip the rest of the line without storing it.
        loop {
            let available = input.fill_buf()?;
            if available.is_empty() {
                break;
            }
            match available.iter().position(|&b| b == b'\n') {
                Some(pos) => {
                    input.consume(pos + 1);
                    break;
                }
                None => {
                    let len = available.len();
                    input.consume(len);
                }
            }
        }
    }
    Ok(true)
}
