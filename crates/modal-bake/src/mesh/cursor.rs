//! A byte cursor over an MSH file that reads ASCII tokens and binary values, and reports
//! errors with a line number (ASCII) or byte offset (binary).
//!
//! ASCII data is read line by line, as gmsh writes it: a record (a node, an element, a
//! section or block header) opens with [`Cursor::mark`] or [`Cursor::line`], its values are
//! tokens that never cross a line break ([`MeshErrorKind::ShortLine`] otherwise), and
//! [`Cursor::end_record`] / [`Cursor::end_line`] require the rest of the line to be blank
//! ([`MeshErrorKind::ExtraValue`] otherwise). A value too many or too few is thus refused at
//! its line instead of shifting every later record.

use super::mesh_error::{shorten, Location, MeshError, MeshErrorKind};

/// Reads an MSH file front to back. Binary reads honour the file's endianness and
/// `size_t` width; ASCII reads split on whitespace.
pub(crate) struct Cursor<'a> {
    data: &'a [u8],
    pos: usize,
    file: &'a str,
    /// Data sections are binary (`file-type` 1).
    pub binary: bool,
    big_endian: bool,
    /// Width in bytes of `size_t` values in binary MSH 4.1 (the data-size field).
    size_width: usize,
    /// Inside an ASCII record: tokens stop at the end of the line.
    in_line: bool,
}

fn is_space(b: u8) -> bool {
    b.is_ascii_whitespace()
}

/// Blank space within a line (a `\r` before the line break included).
fn is_line_space(b: u8) -> bool {
    b != b'\n' && b.is_ascii_whitespace()
}

impl<'a> Cursor<'a> {
    pub fn new(data: &'a [u8], file: &'a str) -> Cursor<'a> {
        Cursor {
            data,
            pos: 0,
            file,
            binary: false,
            big_endian: false,
            size_width: 8,
            in_line: false,
        }
    }

    pub fn set_binary(&mut self, big_endian: bool, size_width: usize) {
        self.binary = true;
        self.big_endian = big_endian;
        self.size_width = size_width;
    }

    pub fn pos(&self) -> usize {
        self.pos
    }

    pub fn remaining(&self) -> usize {
        self.data.len() - self.pos
    }

    /// 1-based line of byte `pos`.
    pub fn line_at(&self, pos: usize) -> usize {
        let end = pos.min(self.data.len());
        1 + self.data[..end].iter().filter(|&&b| b == b'\n').count()
    }

    /// An error at `pos`: a byte offset when `binary`, else a line number.
    pub fn error_at(&self, pos: usize, binary: bool, kind: MeshErrorKind) -> MeshError {
        let location = if binary {
            Location::Byte(pos)
        } else {
            Location::Line(self.line_at(pos))
        };
        MeshError::new(self.file, location, kind)
    }

    /// An error at `pos` located the way the data sections of this file are (bytes or lines).
    pub fn data_error(&self, pos: usize, kind: MeshErrorKind) -> MeshError {
        self.error_at(pos, self.binary, kind)
    }

    /// Start of the next data record: in ASCII files, skips blank space and opens a line
    /// record (close it with [`Cursor::end_record`]).
    ///
    /// Inside an open record, the start of its next value on the same line.
    pub fn mark(&mut self) -> usize {
        if !self.binary {
            self.line();
        }
        self.pos
    }

    /// Opens an ASCII line record even in a binary file (the count lines of MSH 2.2 binary
    /// sections, `$PhysicalNames`); close it with [`Cursor::end_line`]. Inside an open
    /// record, the start of its next value on the same line.
    pub fn line(&mut self) -> usize {
        if self.in_line {
            while self.pos < self.data.len() && is_line_space(self.data[self.pos]) {
                self.pos += 1;
            }
        } else {
            self.skip_space();
            self.in_line = true;
        }
        self.pos
    }

    /// Closes an ASCII line record: the rest of the line must be blank.
    ///
    /// # Errors
    /// [`MeshErrorKind::ExtraValue`] at the line, naming `record`.
    pub fn end_line(&mut self, record: &'static str) -> Result<(), MeshError> {
        self.in_line = false;
        while self.pos < self.data.len() && is_line_space(self.data[self.pos]) {
            self.pos += 1;
        }
        match self.data.get(self.pos) {
            None => Ok(()),
            Some(b'\n') => {
                self.pos += 1;
                Ok(())
            }
            Some(_) => {
                let start = self.pos;
                while self.pos < self.data.len() && !is_space(self.data[self.pos]) {
                    self.pos += 1;
                }
                Err(self.error_at(
                    start,
                    false,
                    MeshErrorKind::ExtraValue {
                        record,
                        found: shorten(&self.data[start..self.pos]),
                    },
                ))
            }
        }
    }

    /// Closes a data record opened by [`Cursor::mark`]: [`Cursor::end_line`] in ASCII files,
    /// nothing in binary ones.
    ///
    /// # Errors
    /// As [`Cursor::end_line`].
    pub fn end_record(&mut self, record: &'static str) -> Result<(), MeshError> {
        if self.binary {
            Ok(())
        } else {
            self.end_line(record)
        }
    }

    pub fn skip_space(&mut self) {
        while self.pos < self.data.len() && is_space(self.data[self.pos]) {
            self.pos += 1;
        }
    }

    pub fn at_end(&mut self) -> bool {
        self.skip_space();
        self.pos >= self.data.len()
    }

    /// The next whitespace-separated token and its start; inside a line record, on the
    /// same line.
    pub fn token(&mut self, expected: &'static str) -> Result<(usize, &'a [u8]), MeshError> {
        if self.in_line {
            while self.pos < self.data.len() && is_line_space(self.data[self.pos]) {
                self.pos += 1;
            }
            if self.data.get(self.pos) == Some(&b'\n') {
                return Err(self.error_at(self.pos, false, MeshErrorKind::ShortLine(expected)));
            }
        } else {
            self.skip_space();
        }
        let start = self.pos;
        while self.pos < self.data.len() && !is_space(self.data[self.pos]) {
            self.pos += 1;
        }
        if start == self.pos {
            return Err(self.error_at(start, false, MeshErrorKind::Truncated(expected)));
        }
        Ok((start, &self.data[start..self.pos]))
    }

    /// The rest of the current line (without the line break), consuming the line break; closes
    /// a line record.
    pub fn rest_of_line(&mut self) -> &'a [u8] {
        self.in_line = false;
        let start = self.pos;
        while self.pos < self.data.len() && self.data[self.pos] != b'\n' {
            self.pos += 1;
        }
        let line = &self.data[start..self.pos];
        if self.pos < self.data.len() {
            self.pos += 1;
        }
        line.strip_suffix(b"\r").unwrap_or(line)
    }

    /// Requires the next token to be `keyword`.
    pub fn expect(&mut self, keyword: &'static str) -> Result<(), MeshError> {
        let (start, tok) = self.token(keyword)?;
        if tok != keyword.as_bytes() {
            return Err(self.error_at(
                start,
                false,
                MeshErrorKind::Unexpected {
                    expected: keyword.to_string(),
                    found: shorten(tok),
                },
            ));
        }
        Ok(())
    }

    fn not_a_number(&self, start: usize, expected: &'static str, tok: &[u8]) -> MeshError {
        self.error_at(
            start,
            false,
            MeshErrorKind::NotANumber {
                expected,
                found: shorten(tok),
            },
        )
    }

    pub fn ascii_u64(&mut self, expected: &'static str) -> Result<u64, MeshError> {
        let (start, tok) = self.token(expected)?;
        std::str::from_utf8(tok)
            .ok()
            .and_then(|s| s.parse::<u64>().ok())
            .ok_or_else(|| self.not_a_number(start, expected, tok))
    }

    pub fn ascii_i64(&mut self, expected: &'static str) -> Result<i64, MeshError> {
        let (start, tok) = self.token(expected)?;
        std::str::from_utf8(tok)
            .ok()
            .and_then(|s| s.parse::<i64>().ok())
            .ok_or_else(|| self.not_a_number(start, expected, tok))
    }

    pub fn ascii_f64(&mut self, expected: &'static str) -> Result<f64, MeshError> {
        let (start, tok) = self.token(expected)?;
        std::str::from_utf8(tok)
            .ok()
            .and_then(|s| s.parse::<f64>().ok())
            .ok_or_else(|| self.not_a_number(start, expected, tok))
    }

    /// The next `n` raw bytes.
    pub fn bytes(&mut self, n: usize, expected: &'static str) -> Result<&'a [u8], MeshError> {
        match self.pos.checked_add(n) {
            Some(end) if end <= self.data.len() => {
                let b = &self.data[self.pos..end];
                self.pos = end;
                Ok(b)
            }
            _ => Err(self.error_at(self.pos, true, MeshErrorKind::Truncated(expected))),
        }
    }

    fn bin_u32(&mut self, expected: &'static str) -> Result<u32, MeshError> {
        let b: [u8; 4] = self.bytes(4, expected)?.try_into().expect("4 bytes");
        Ok(if self.big_endian {
            u32::from_be_bytes(b)
        } else {
            u32::from_le_bytes(b)
        })
    }

    fn bin_u64(&mut self, expected: &'static str) -> Result<u64, MeshError> {
        let b: [u8; 8] = self.bytes(8, expected)?.try_into().expect("8 bytes");
        Ok(if self.big_endian {
            u64::from_be_bytes(b)
        } else {
            u64::from_le_bytes(b)
        })
    }

    /// A C `int`: 4 bytes in binary, a token in ASCII.
    pub fn int(&mut self, expected: &'static str) -> Result<i64, MeshError> {
        if self.binary {
            Ok(self.bin_u32(expected)? as i32 as i64)
        } else {
            self.ascii_i64(expected)
        }
    }

    /// A `size_t` (MSH 4.1): data-size bytes in binary, a token in ASCII.
    pub fn size(&mut self, expected: &'static str) -> Result<u64, MeshError> {
        if !self.binary {
            self.ascii_u64(expected)
        } else if self.size_width == 4 {
            Ok(u64::from(self.bin_u32(expected)?))
        } else {
            self.bin_u64(expected)
        }
    }

    /// A `double`: 8 bytes in binary, a token in ASCII.
    pub fn float(&mut self, expected: &'static str) -> Result<f64, MeshError> {
        if self.binary {
            Ok(f64::from_bits(self.bin_u64(expected)?))
        } else {
            self.ascii_f64(expected)
        }
    }

    /// Bytes of one binary `size_t`.
    pub fn size_width(&self) -> usize {
        self.size_width
    }

    /// Checks that `count` items of at least `min_bytes` each fit in the rest of the file and
    /// returns it as `usize` (safe to preallocate).
    ///
    /// # Errors
    /// [`MeshErrorKind::CountTooLarge`] at `pos` (a byte offset when `binary`).
    pub fn check_count(
        &self,
        pos: usize,
        binary: bool,
        count: u64,
        min_bytes: usize,
        what: &'static str,
    ) -> Result<usize, MeshError> {
        let fits = count
            .checked_mul(min_bytes as u64)
            .is_some_and(|need| need <= self.remaining() as u64);
        if !fits {
            return Err(self.error_at(pos, binary, MeshErrorKind::CountTooLarge { what, count }));
        }
        Ok(count as usize)
    }

    /// Skips everything up to and including `$End<name>`.
    pub fn skip_section(&mut self, name: &[u8]) -> Result<(), MeshError> {
        let mut marker = b"$End".to_vec();
        marker.extend_from_slice(name);
        let rest = &self.data[self.pos..];
        match rest
            .windows(marker.len())
            .position(|w| w == marker.as_slice())
        {
            Some(i) => {
                self.pos += i + marker.len();
                Ok(())
            }
            None => Err(self.error_at(
                self.data.len(),
                false,
                MeshErrorKind::Truncated("end of section"),
            )),
        }
    }
}
