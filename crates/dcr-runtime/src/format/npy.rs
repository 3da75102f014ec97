//! `.npy` entries of the `.modes` archive (NumPy format 1.0, read also 2.0 and 3.0): the header
//! `{'descr': '<f8', 'fortran_order': False, 'shape': (n, 3)}` padded with spaces to a multiple
//! of 64 bytes and ended by a newline, then the elements in C order.
//!
//! Hand-written rather than through `ndarray-npy`: the header is a Python dict literal, and
//! `ndarray-npy` parses it with `py_literal`, a `pest` grammar whose stack guard
//! (`pest_stack_guard` → `stacker` → `psm`) compiles assembly through the `cc` crate at build
//! time. Measured with `cargo tree -p dcr-runtime -e normal` (2026-11-24): `ndarray-npy` with
//! `ndarray` and the parser stack were 15 of the runtime's 118 crates, and `psm` and `stacker`
//! the only build scripts in its tree that run a C compiler (none remain). The headers a base
//! holds use three keys, a type string, a
//! boolean and a tuple of integers, which the small non-recursive parser below reads exactly;
//! anything else (structured dtypes, nested values) is refused as unsupported. The writer (cargo
//! feature `write`) emits the bytes `ndarray-npy` and NumPy write, so bases stay bit-identical.

#[cfg(feature = "write")]
use std::io::{Seek, Write};

/// Magic string at the start of every `.npy` file.
#[cfg(feature = "write")]
const MAGIC: &[u8] = b"\x93NUMPY";

/// An element type of a `.modes` entry: its NumPy type descriptors and little-endian bytes.
pub(crate) trait NpyElement: Copy + Sized {
    /// Descriptor written (`'<f8'`).
    #[cfg(feature = "write")]
    const DESCR: &'static str;
    /// Size in bytes.
    const SIZE: usize;
    /// Descriptors read, and whether each stores the bytes big-endian.
    const READ: &'static [(&'static str, bool)];
    /// The element from its `SIZE` bytes, little-endian.
    fn from_le(bytes: &[u8]) -> Self;
    /// Appends the element's little-endian bytes.
    #[cfg(feature = "write")]
    fn put_le(self, out: &mut Vec<u8>);
}

macro_rules! npy_element {
    ($t:ty, $descr:expr, [$($read:expr),*]) => {
        impl NpyElement for $t {
            #[cfg(feature = "write")]
            const DESCR: &'static str = $descr;
            const SIZE: usize = std::mem::size_of::<$t>();
            const READ: &'static [(&'static str, bool)] = &[$($read),*];
            fn from_le(bytes: &[u8]) -> Self {
                <$t>::from_le_bytes(bytes.try_into().expect("SIZE bytes"))
            }
            #[cfg(feature = "write")]
            fn put_le(self, out: &mut Vec<u8>) {
                out.extend_from_slice(&self.to_le_bytes());
            }
        }
    };
}

npy_element!(f64, "<f8", [("<f8", false), (">f8", true)]);
npy_element!(f32, "<f4", [("<f4", false), (">f4", true)]);
npy_element!(u32, "<u4", [("<u4", false), (">u4", true)]);
npy_element!(u8, "|u1", [("|u1", false), ("u1", false), ("B", false)]);

/// What an entry's header declares.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct NpyHeader {
    /// The type descriptor, without quotes (`<f8`).
    pub descr: String,
    /// Whether the elements are stored in Fortran (column-major) order.
    pub fortran_order: bool,
    /// The array's shape (empty: a scalar).
    pub shape: Vec<usize>,
}

/// The header bytes NumPy and `ndarray-npy` write for `descr` and `shape` (format 1.0, or 2.0
/// when the text does not fit a 16-bit length).
#[cfg(feature = "write")]
pub(crate) fn header_bytes(descr: &str, shape: &[usize]) -> Vec<u8> {
    let dims = match shape {
        [] => "()".to_string(),
        [n] => format!("({n},)"),
        _ => {
            let parts: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
            format!("({})", parts.join(", "))
        }
    };
    let text = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {dims}}}");
    let (version, prefix) = if 10 + text.len() < 65_536 - 64 {
        (1u8, 10)
    } else {
        (2u8, 12)
    };
    let unpadded = prefix + text.len() + 1;
    let total = unpadded + (64 - unpadded % 64);
    let header_len = total - prefix;
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&[version, 0]);
    if version == 1 {
        out.extend_from_slice(&(header_len as u16).to_le_bytes());
    } else {
        out.extend_from_slice(&(header_len as u32).to_le_bytes());
    }
    out.extend_from_slice(text.as_bytes());
    out.resize(total - 1, b' ');
    out.push(b'\n');
    out
}

/// Writes `data` (C order, `shape`) as the archive entry `NAME.npy`.
#[cfg(feature = "write")]
pub(crate) fn write_entry<W: Write + Seek, A: NpyElement>(
    zip: &mut zip::ZipWriter<W>,
    name: &str,
    options: zip::write::SimpleFileOptions,
    shape: &[usize],
    data: &[A],
) -> Result<(), String> {
    debug_assert_eq!(shape.iter().product::<usize>(), data.len());
    let mut bytes = header_bytes(A::DESCR, shape);
    bytes.reserve(data.len() * A::SIZE);
    for &x in data {
        x.put_le(&mut bytes);
    }
    zip.start_file(format!("{name}.npy"), options)
        .map_err(|e| e.to_string())?;
    zip.write_all(&bytes).map_err(|e| e.to_string())
}

/// Parses the header text after the preamble (`{...}` plus padding and the final newline).
pub(crate) fn parse_header_text(text: &[u8]) -> Result<NpyHeader, String> {
    let Some((&b'\n', body)) = text.split_last() else {
        return Err("bad .npy header: newline missing at end of header".into());
    };
    let body =
        std::str::from_utf8(body).map_err(|_| "bad .npy header: not UTF-8 text".to_string())?;
    let mut p = Parser { s: body, pos: 0 };
    let header = p.dict().map_err(|e| format!("bad .npy header: {e}"))?;
    p.skip_ws();
    if p.pos != body.len() {
        return Err(format!(
            "bad .npy header: unexpected text after the dict at byte {}",
            p.pos
        ));
    }
    Ok(header)
}

/// The elements of `data` as `A`, after checking `descr` is one of `A`'s descriptors.
pub(crate) fn decode<A: NpyElement>(descr: &str, data: &[u8]) -> Result<Vec<A>, String> {
    let Some(&(_, big)) = A::READ.iter().find(|(d, _)| *d == descr) else {
        return Err(format!("unexpected dtype '{descr}'"));
    };
    Ok(data
        .chunks_exact(A::SIZE)
        .map(|c| {
            if big {
                let mut le = c.to_vec();
                le.reverse();
                A::from_le(&le)
            } else {
                A::from_le(c)
            }
        })
        .collect())
}

/// A cursor over the header's dict literal: `{'key': value, ...}` with string, boolean and
/// integer-tuple values, single or double quotes, optional trailing commas.
struct Parser<'a> {
    s: &'a str,
    pos: usize,
}

impl Parser<'_> {
    fn skip_ws(&mut self) {
        while self
            .s
            .as_bytes()
            .get(self.pos)
            .is_some_and(u8::is_ascii_whitespace)
        {
            self.pos += 1;
        }
    }

    fn peek(&mut self) -> Option<u8> {
        self.skip_ws();
        self.s.as_bytes().get(self.pos).copied()
    }

    fn expect(&mut self, c: u8) -> Result<(), String> {
        if self.peek() == Some(c) {
            self.pos += 1;
            Ok(())
        } else {
            Err(format!("expected '{}' at byte {}", c as char, self.pos))
        }
    }

    fn string(&mut self) -> Result<String, String> {
        let q = self.peek().filter(|&c| c == b'\'' || c == b'"');
        let Some(q) = q else {
            return Err(format!("expected a string at byte {}", self.pos));
        };
        let start = self.pos + 1;
        let Some(len) = self.s[start..].bytes().position(|c| c == q || c == b'\\') else {
            return Err(format!("unterminated string at byte {}", self.pos));
        };
        if self.s.as_bytes()[start + len] == b'\\' {
            return Err(format!("escapes are not supported (byte {})", start + len));
        }
        self.pos = start + len + 1;
        Ok(self.s[start..start + len].to_string())
    }

    fn word(&mut self) -> &str {
        self.skip_ws();
        let start = self.pos;
        while self
            .s
            .as_bytes()
            .get(self.pos)
            .is_some_and(u8::is_ascii_alphanumeric)
        {
            self.pos += 1;
        }
        &self.s[start..self.pos]
    }

    fn boolean(&mut self) -> Result<bool, String> {
        let at = self.pos;
        match self.word() {
            "True" => Ok(true),
            "False" => Ok(false),
            other => Err(format!(
                "illegal value for key fortran_order: {other:?} (byte {at})"
            )),
        }
    }

    fn shape(&mut self) -> Result<Vec<usize>, String> {
        self.expect(b'(')?;
        let mut dims = Vec::new();
        loop {
            if self.peek() == Some(b')') {
                self.pos += 1;
                return Ok(dims);
            }
            let at = self.pos;
            let w = self.word();
            let d = w
                .parse::<usize>()
                .map_err(|_| format!("illegal value for key shape: {w:?} (byte {at})"))?;
            dims.push(d);
            match self.peek() {
                Some(b',') => self.pos += 1,
                Some(b')') => {}
                _ => return Err(format!("expected ',' or ')' in shape at byte {}", self.pos)),
            }
        }
    }

    fn dict(&mut self) -> Result<NpyHeader, String> {
        self.expect(b'{')?;
        let (mut descr, mut fortran, mut shape) = (None, None, None);
        loop {
            if self.peek() == Some(b'}') {
                self.pos += 1;
                break;
            }
            let key = self.string()?;
            self.expect(b':')?;
            match key.as_str() {
                "descr" if self.peek() == Some(b'[') => {
                    return Err("structured dtypes are not supported".into())
                }
                "descr" => descr = Some(self.string()?),
                "fortran_order" => fortran = Some(self.boolean()?),
                "shape" => shape = Some(self.shape()?),
                other => return Err(format!("unknown key: {other:?}")),
            }
            match self.peek() {
                Some(b',') => self.pos += 1,
                Some(b'}') => {}
                _ => return Err(format!("expected ',' or '}}' at byte {}", self.pos)),
            }
        }
        Ok(NpyHeader {
            descr: descr.ok_or("missing key: descr")?,
            fortran_order: fortran.ok_or("missing key: fortran_order")?,
            shape: shape.ok_or("missing key: shape")?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The writer's header is NumPy's: 64-byte aligned, newline last, and it parses back.
    #[cfg(feature = "write")]
    #[test]
    fn header_round_trips_and_is_aligned() {
        for shape in [vec![], vec![10], vec![188, 3], vec![188, 3, 10]] {
            let h = header_bytes("<f8", &shape);
            assert_eq!(h.len() % 64, 0);
            assert_eq!(&h[..8], b"\x93NUMPY\x01\x00");
            assert_eq!(u16::from_le_bytes([h[8], h[9]]) as usize, h.len() - 10);
            let parsed = parse_header_text(&h[10..]).unwrap();
            assert_eq!(parsed.shape, shape);
            assert_eq!(parsed.descr, "<f8");
            assert!(!parsed.fortran_order);
        }
        assert!(header_bytes("<u4", &[188])[10..]
            .starts_with(b"{'descr': '<u4', 'fortran_order': False, 'shape': (188,)}   "));
    }

    /// What NumPy writes (double quotes, trailing commas) reads; malformed text is refused.
    #[test]
    fn numpy_variants_read_and_bad_headers_are_refused() {
        let ok = parse_header_text(
            b"{\"descr\": \"<u4\", \"fortran_order\": True, \"shape\": (2, 3,), }  \n",
        )
        .unwrap();
        assert_eq!(ok.shape, vec![2, 3]);
        assert!(ok.fortran_order);
        for bad in [
            &b"{'descr': '<f8', 'fortran_order': False, 'shape': (3,)}"[..],
            b"{'descr': '<f8', 'fortran_order': False}\n",
            b"{'descr': [('a', '<f8')], 'fortran_order': False, 'shape': ()}\n",
            b"{'descr': '<f8', 'fortran_order': Maybe, 'shape': ()}\n",
            b"{'descr': '<f8', 'fortran_order': False, 'shape': (-1,)}\n",
            b"{'descr': '<f8', 'fortran_order': False, 'shape': (3,), 'x': 1}\n",
            b"{'descr': '<f8' 'fortran_order': False, 'shape': (3,)}\n",
            b"((((((\n",
        ] {
            assert!(
                parse_header_text(bad).is_err(),
                "{}",
                String::from_utf8_lossy(bad)
            );
        }
    }

    /// Elements decode from either byte order their descriptor names; other types are refused.
    #[test]
    fn elements_decode_in_both_byte_orders() {
        let le: Vec<u8> = [1.5f64, -2.0]
            .iter()
            .flat_map(|x| x.to_le_bytes())
            .collect();
        let be: Vec<u8> = [1.5f64, -2.0]
            .iter()
            .flat_map(|x| x.to_be_bytes())
            .collect();
        assert_eq!(decode::<f64>("<f8", &le).unwrap(), vec![1.5, -2.0]);
        assert_eq!(decode::<f64>(">f8", &be).unwrap(), vec![1.5, -2.0]);
        assert!(decode::<u32>("<i4", &le)
            .unwrap_err()
            .contains("unexpected dtype"));
        assert_eq!(decode::<u8>("|u1", &[7, 9]).unwrap(), vec![7, 9]);
    }
}
