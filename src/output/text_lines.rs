//! Reading a results file line by line in constant memory (history.csv can hold gigabytes): each
//! line at most [`MAX_LINE`] bytes, UTF-8, with its number for messages.

use std::io::{BufRead, Read};

/// The longest line read (bytes): a history row of a model of thousands of coordinates is far
/// shorter; a longer one is a damaged file, refused before it fills the memory.
pub const MAX_LINE: usize = 16 << 20;

/// One line read.
pub struct Line<'a> {
    /// The text, without its line end (`\n` or `\r\n`).
    pub text: &'a str,
    /// Whether it ended with a line end (the last line of a half-written file does not).
    pub ended: bool,
    /// Its number (1 = the first line).
    pub number: usize,
}

/// The lines of a reader, one at a time.
pub struct TextLines<R> {
    reader: R,
    buf: Vec<u8>,
    number: usize,
}

impl<R: BufRead> TextLines<R> {
    /// Lines of `reader`, the first numbered 1.
    pub fn new(reader: R) -> Self {
        TextLines {
            reader,
            buf: Vec::new(),
            number: 0,
        }
    }

    /// The reader, positioned after the last line read.
    pub fn into_inner(self) -> R {
        self.reader
    }

    /// The number of the line last read (1 = the first; 0 before any).
    pub fn number(&self) -> usize {
        self.number
    }

    /// The next line; None at the end. The error is a message naming the line (the caller adds
    /// the file).
    pub fn next_line(&mut self) -> Result<Option<Line<'_>>, String> {
        self.buf.clear();
        let read = (&mut self.reader)
            .take(MAX_LINE as u64 + 1)
            .read_until(b'\n', &mut self.buf)
            .map_err(|e| format!("cannot read the file: {e}"))?;
        if read == 0 {
            return Ok(None);
        }
        self.number += 1;
        let ended = self.buf.last() == Some(&b'\n');
        if !ended && read > MAX_LINE {
            return Err(format!(
                "line {}: longer than {} MiB (a damaged file)",
                self.number,
                MAX_LINE >> 20
            ));
        }
        if ended {
            self.buf.pop();
            if self.buf.last() == Some(&b'\r') {
                self.buf.pop();
            }
        }
        let text = std::str::from_utf8(&self.buf).map_err(|e| {
            format!(
                "line {}: not UTF-8 text (invalid byte at column {})",
                self.number,
                e.valid_up_to() + 1
            )
        })?;
        Ok(Some(Line {
            text,
            ended,
            number: self.number,
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_keep_their_numbers_and_say_whether_they_ended() {
        let mut lines = TextLines::new("a,b\r\n1,2\n\n3".as_bytes());
        let mut seen = Vec::new();
        while let Some(line) = lines.next_line().unwrap() {
            seen.push((line.text.to_string(), line.ended));
        }
        assert_eq!(
            seen,
            [
                ("a,b".to_string(), true),
                ("1,2".to_string(), true),
                (String::new(), true),
                ("3".to_string(), false)
            ]
        );
        assert_eq!(lines.number(), 4);
    }

    #[test]
    fn a_line_too_long_or_not_utf8_is_refused_naming_it() {
        let long = format!("x\n{}", "y".repeat(MAX_LINE + 10));
        let mut lines = TextLines::new(long.as_bytes());
        lines.next_line().unwrap();
        let e = lines.next_line().err().unwrap();
        assert!(e.starts_with("line 2: longer than 16 MiB"), "{e}");
        let mut lines = TextLines::new(&[b'o', b'k', b'\n', 0x66, 0xff, b'\n'][..]);
        lines.next_line().unwrap();
        let e = lines.next_line().err().unwrap();
        assert_eq!(e, "line 2: not UTF-8 text (invalid byte at column 2)");
    }
}
