//! NPZ writer: a ZIP archive (stored, no compression) of one `.npy` array per channel, as
//! `numpy.load` reads it (`np.load("run.npz")["w1l_force_z"]`). Fixed timestamps, so the same
//! data give the same bytes.

use std::io::{self, Write};

/// CRC-32 (IEEE 802.3, as ZIP uses).
fn crc32(data: &[u8]) -> u32 {
    static TABLE: std::sync::OnceLock<[u32; 256]> = std::sync::OnceLock::new();
    let table = TABLE.get_or_init(|| {
        let mut t = [0u32; 256];
        for (i, e) in t.iter_mut().enumerate() {
            let mut c = i as u32;
            for _ in 0..8 {
                c = if c & 1 != 0 {
                    0xEDB8_8320 ^ (c >> 1)
                } else {
                    c >> 1
                };
            }
            *e = c;
        }
        t
    });
    let mut c = 0xFFFF_FFFFu32;
    for &b in data {
        c = table[((c ^ u32::from(b)) & 0xFF) as usize] ^ (c >> 8);
    }
    c ^ 0xFFFF_FFFF
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

/// Reads back an NPZ written by [`write_npz`] (stored entries only): `(name, values)`.
pub fn read_npz(bytes: &[u8]) -> io::Result<Vec<(String, Vec<f64>)>> {
    let bad = |m: &str| io::Error::new(io::ErrorKind::InvalidData, m.to_string());
    let mut out = Vec::new();
    let mut p = 0usize;
    let u16_at = |b: &[u8], i: usize| u16::from_le_bytes([b[i], b[i + 1]]) as usize;
    let u32_at =
        |b: &[u8], i: usize| u32::from_le_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]) as usize;
    while p + 30 <= bytes.len() && u32_at(bytes, p) == 0x0403_4b50 {
        let size = u32_at(bytes, p + 18);
        let nlen = u16_at(bytes, p + 26);
        let xlen = u16_at(bytes, p + 28);
        let name_start = p + 30;
        let data_start = name_start + nlen + xlen;
        let data = bytes
            .get(data_start..data_start + size)
            .ok_or_else(|| bad("truncated entry"))?;
        let name = String::from_utf8_lossy(&bytes[name_start..name_start + nlen])
            .trim_end_matches(".npy")
            .to_string();
        if !data.starts_with(b"\x93NUMPY") {
            return Err(bad("entry is not a .npy array"));
        }
        if data.len() < 10 {
            return Err(bad("truncated .npy header"));
        }
        let hlen = u16_at(data, 8);
        let header = data
            .get(10..10 + hlen)
            .ok_or_else(|| bad("truncated .npy header"))?;
        let header = String::from_utf8_lossy(header);
        let body = &data[10 + hlen..];
        let values = if header.contains("'<f4'") {
            body.chunks_exact(4)
                .map(|c| f64::from(f32::from_le_bytes(c.try_into().expect("4 bytes"))))
                .collect()
        } else if header.contains("'<f8'") {
            body.chunks_exact(8)
                .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")))
                .collect()
        } else {
            return Err(bad("entry is neither float64 nor float32"));
        };
        out.push((name, values));
        p = data_start + size;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

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
