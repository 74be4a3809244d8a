//! NPZ files: the writer makes a ZIP archive (stored, no compression) of one `.npy` array per
//! channel, as `numpy.load` reads it (`np.load("run.npz")["w1l_force_z"]`), with fixed
//! timestamps, so the same data give the same bytes; the reader takes NumPy's own archives too.

use std::io::{self, Write};

/// CRC-32 (IEEE 802.3, as ZIP uses).
fn crc32(data: &[u8]) -> u32 {
    crc32fast::hash(data)
}

/// A 1-D little-endian float64 (or float32) `.npy` file.
fn npy(values: &[f64], single: bool) -> Vec<u8> {
    let mut header = format!(
        "{{'descr': '{}', 'fortran_order': False, 'shape': ({},), }}",
        if single { "<f4" } else { "<f8" },
        values.len()
    );
    // Magic (6) + version (2) + length (2) + header + '\n' must be a multiple of 64.
    let total = 10 + header.len() + 1;
    header.push_str(&" ".repeat((64 - total % 64) % 64));
    header.push('\n');
    let mut out = Vec::with_capacity(10 + header.len() + 8 * values.len());
    out.extend_from_slice(b"\x93NUMPY\x01\x00");
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    for v in values {
        if single {
            out.extend_from_slice(&(*v as f32).to_le_bytes());
        } else {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    out
}

/// Writes named columns as an NPZ archive; with `float32`, every column but time and
/// position ([`super::keeps_f64`]) is stored as float32.
pub fn write_npz(w: &mut dyn Write, columns: &[(&str, &[f64])], float32: bool) -> io::Result<()> {
    let mut offset: u64 = 0;
    let mut central = Vec::new();
    let mut count: u16 = 0;
    for (name, values) in columns {
        let data = npy(values, float32 && !super::keeps_f64(name));
        let fname = format!("{name}.npy");
        let crc = crc32(&data);
        let size = u32::try_from(data.len())
            .map_err(|_| io::Error::other(format!("column {name} is too large for ZIP32")))?;
        let local = [
            &0x0403_4b50u32.to_le_bytes()[..],
            &20u16.to_le_bytes(),     // version needed
            &0u16.to_le_bytes(),      // flags
            &0u16.to_le_bytes(),      // stored
            &0u16.to_le_bytes(),      // time
            &0x0021u16.to_le_bytes(), // date 1980-01-01
            &crc.to_le_bytes(),
            &size.to_le_bytes(),
            &size.to_le_bytes(),
            &(fname.len() as u16).to_le_bytes(),
            &0u16.to_le_bytes(),
        ]
        .concat();
        w.write_all(&local)?;
        w.write_all(fname.as_bytes())?;
        w.write_all(&data)?;
        let entry = [
            &0x0201_4b50u32.to_le_bytes()[..],
            &20u16.to_le_bytes(), // version made by
            &20u16.to_le_bytes(),
            &0u16.to_le_bytes(),
            &0u16.to_le_bytes(),
            &0u16.to_le_bytes(),
            &0x0021u16.to_le_bytes(),
            &crc.to_le_bytes(),
            &size.to_le_bytes(),
            &size.to_le_bytes(),
            &(fname.len() as u16).to_le_bytes(),
            &0u16.to_le_bytes(), // extra
            &0u16.to_le_bytes(), // comment
            &0u16.to_le_bytes(), // disk
            &0u16.to_le_bytes(), // internal attributes
            &0u32.to_le_bytes(), // external attributes
            &u32::try_from(offset)
                .map_err(|_| io::Error::other("archive too large for ZIP32"))?
                .to_le_bytes(),
        ]
        .concat();
        central.extend_from_slice(&entry);
        central.extend_from_slice(fname.as_bytes());
        offset += (local.len() + fname.len() + data.len()) as u64;
        count += 1;
    }
    w.write_all(&central)?;
    let end = [
        &0x0605_4b50u32.to_le_bytes()[..],
        &0u16.to_le_bytes(),
        &0u16.to_le_bytes(),
        &count.to_le_bytes(),
        &count.to_le_bytes(),
        &(central.len() as u32).to_le_bytes(),
        &u32::try_from(offset)
            .map_err(|_| io::Error::other("archive too large for ZIP32"))?
            .to_le_bytes(),
        &0u16.to_le_bytes(),
    ]
    .concat();
    w.write_all(&end)
}

/// Reads an NPZ archive as `numpy.savez` or `savez_compressed` writes it (stored or deflated
/// entries, ZIP64 included; the ZIP layer is the `zip` crate's) or [`write_npz`] does:
/// `(name, values)` in the archive's order. Each entry must be a one-dimensional array of
/// floats, integers or booleans (either byte order); an error names the entry.
pub fn read_npz(bytes: &[u8]) -> io::Result<Vec<(String, Vec<f64>)>> {
    let bad = |m: String| io::Error::new(io::ErrorKind::InvalidData, m);
    let mut zip = zip::ZipArchive::new(io::Cursor::new(bytes))
        .map_err(|e| bad(format!("not a readable NPZ (ZIP) archive: {e}")))?;
    let mut out = Vec::with_capacity(zip.len());
    let mut data = Vec::new();
    for i in 0..zip.len() {
        let mut entry = zip
            .by_index(i)
            .map_err(|e| bad(format!("entry {i}: {e}")))?;
        let name = entry.name().trim_end_matches(".npy").to_string();
        data.clear();
        io::Read::read_to_end(&mut entry, &mut data)
            .map_err(|e| bad(format!("entry '{name}': {e}")))?;
        let values = parse_npy(&data).map_err(|m| bad(format!("entry '{name}': {m}")))?;
        out.push((name, values));
    }
    Ok(out)
}

/// The values of a one-dimensional `.npy` array (format versions 1–3).
fn parse_npy(data: &[u8]) -> Result<Vec<f64>, String> {
    if !data.starts_with(b"\x93NUMPY") || data.len() < 10 {
        return Err("not a .npy array".into());
    }
    let (hlen, start): (usize, usize) = match data[6] {
        1 => (u16::from_le_bytes([data[8], data[9]]) as usize, 10),
        2 | 3 if data.len() >= 12 => (
            u32::from_le_bytes([data[8], data[9], data[10], data[11]]) as usize,
            12,
        ),
        2 | 3 => return Err("truncated .npy header".into()),
        v => return Err(format!(".npy format version {v} is not one of 1, 2, 3")),
    };
    let header = start
        .checked_add(hlen)
        .and_then(|end| data.get(start..end))
        .ok_or("truncated .npy header")?;
    let header = String::from_utf8_lossy(header);
    let field = |key: &str| -> Option<String> {
        let at = header.find(&format!("'{key}'"))? + key.len() + 2;
        let rest = header[at..].trim_start().strip_prefix(':')?.trim_start();
        let end = if rest.starts_with('(') {
            rest.find(')')? + 1
        } else {
            rest.find([',', '}'])?
        };
        Some(rest[..end].trim().to_string())
    };
    let descr = field("descr").ok_or("the .npy header has no 'descr'")?;
    let descr = descr.trim_matches(['\'', '"']);
    let shape = field("shape").ok_or("the .npy header has no 'shape'")?;
    let dims: Vec<&str> = shape
        .trim_matches(['(', ')'])
        .split(',')
        .map(str::trim)
        .filter(|d| !d.is_empty())
        .collect();
    let n: usize = match dims.as_slice() {
        [n] | [n, "1"] | ["1", n] => n.parse().map_err(|_| format!("shape {shape}"))?,
        _ => return Err(format!("shape {shape}: a column needs one dimension")),
    };
    let body = &data[start + hlen..];
    let (order, kind) = match descr.char_indices().nth(1) {
        Some((i, _)) => descr.split_at(i),
        None => (descr, ""),
    };
    let big = match order {
        "<" | "|" | "=" => false,
        ">" => true,
        _ => return Err(format!("data type '{descr}' is not understood")),
    };
    macro_rules! read {
        ($t:ty) => {{
            const W: usize = std::mem::size_of::<$t>();
            // n from the file: its byte count checked, never trusted to fit.
            let need = n
                .checked_mul(W)
                .filter(|&b| b <= body.len())
                .ok_or_else(|| {
                    format!(
                        "truncated: {} bytes for {n} values of '{descr}'",
                        body.len()
                    )
                })?;
            body[..need]
                .chunks_exact(W)
                .map(|c| {
                    let b: [u8; W] = c.try_into().expect("width");
                    (if big {
                        <$t>::from_be_bytes(b)
                    } else {
                        <$t>::from_le_bytes(b)
                    }) as f64
                })
                .collect()
        }};
    }
    Ok(match kind {
        "f8" => read!(f64),
        "f4" => read!(f32),
        "i8" => read!(i64),
        "i4" => read!(i32),
        "i2" => read!(i16),
        "i1" => read!(i8),
        "u8" => read!(u64),
        "u4" => read!(u32),
        "u2" => read!(u16),
        "u1" | "b1" => read!(u8),
        _ => {
            return Err(format!(
                "data type '{descr}' is not a number (floats, integers or booleans)"
            ));
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A header from a file is never trusted: a non-ASCII type, a count whose bytes overflow,
    /// a length past the end, a version-2 header cut short: each an error, never a panic.
    #[test]
    fn malformed_npy_headers_are_errors() {
        let npy_with = |header: &str, version: u8, body: &[u8]| {
            let mut b = b"\x93NUMPY".to_vec();
            b.extend_from_slice(&[version, 0]);
            b.extend_from_slice(&(header.len() as u16).to_le_bytes());
            b.extend_from_slice(header.as_bytes());
            b.extend_from_slice(body);
            b
        };
        for (header, says) in [
            (
                "{'descr': '\u{e9}8', 'fortran_order': False, 'shape': (1,), }",
                "not understood",
            ),
            (
                "{'descr': '<f8', 'fortran_order': False, 'shape': (2305843009213693952,), }",
                "truncated",
            ),
            (
                "{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }",
                "one dimension",
            ),
        ] {
            let e = parse_npy(&npy_with(header, 1, &[0; 8])).unwrap_err();
            assert!(e.contains(says), "{header}: {e}");
        }
        let mut long = npy_with("{'descr': '<f8', 'shape': (1,), }", 1, &[0; 8]);
        long[8] = 0xFF;
        assert!(parse_npy(&long).unwrap_err().contains("truncated"));
        assert!(
            parse_npy(b"\x93NUMPY\x02\x00\x01\x00")
                .unwrap_err()
                .contains("truncated")
        );
    }

    #[test]
    fn crc32_known_value() {
        assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
    }

    #[test]
    fn npz_round_trip_and_npy_header_alignment() {
        let a = [1.0, -2.5, f64::MAX];
        let b: Vec<f64> = (0..1000).map(|i| i as f64 * 0.1).collect();
        let mut buf = Vec::new();
        write_npz(&mut buf, &[("a", &a), ("b_long_name", &b)], false).unwrap();
        let back = read_npz(&buf).unwrap();
        assert_eq!(back[0].0, "a");
        assert_eq!(back[0].1, a);
        assert_eq!(back[1].1, b);
        assert_eq!(
            (10 + u16::from_le_bytes([npy(&a, false)[8], npy(&a, false)[9]]) as usize) % 64,
            0
        );
    }
}
