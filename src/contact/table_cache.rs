//! The contact table shared: within a process by the geometry it tabulates
//! ([`WheelsetGeometry::shared_table`]), and on disk: built once per wheel–rail pair and
//! settings, then read back in milliseconds by every later process. A file is keyed by the exact geometry it tabulates
//! (the bits of the profiles, radius, gauge, flange back and range) and checked on read: its
//! magic, version, key and checksum must match and every window must index inside its strips,
//! or the table is built again and the file rewritten. The numbers are stored as their bits,
//! so a run from a cached table writes the same bytes as one from a fresh build.
//!
//! The key also carries a hash of the contact module's own source (build.rs), so a table
//! built by other code is never read back.
//!
//! Where: `$RAILFORCE_CACHE_DIR`, else `$XDG_CACHE_HOME/railforce`, else
//! `$HOME/.cache/railforce`; `RAILFORCE_CACHE_DIR=off` turns the cache off.

use super::codec::{Decoder, Encoder};
use super::geometry::WheelsetGeometry;
use super::geometry::{ContactState, WheelContact};
use super::hertz::HertzShape;
use super::table::ContactTable;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

/// The file's first bytes.
const MAGIC: &[u8; 8] = b"RFCTABLE";
/// Layout of the file: a change of what a table holds changes it, and old files are rebuilt.
const VERSION: u32 = 1;

/// The code that builds a table: a hash of the contact module's sources and the crate's
/// version, made by build.rs. A table built by other code is never read back, so a change of
/// the contact's physics can never be hidden by a cached table.
const CODE: &str = concat!(
    env!("CARGO_PKG_VERSION"),
    "-",
    env!("RAILFORCE_CONTACT_SOURCE_HASH")
);

/// The cache folder, or `None` when it is turned off or no home is known.
pub fn cache_dir() -> Option<PathBuf> {
    let var = |k: &str| std::env::var_os(k).filter(|v| !v.is_empty());
    if let Some(d) = var("RAILFORCE_CACHE_DIR") {
        return (d != "off").then(|| PathBuf::from(d));
    }
    if let Some(d) = var("XDG_CACHE_HOME") {
        return Some(PathBuf::from(d).join("railforce"));
    }
    var("HOME").map(|h| PathBuf::from(h).join(".cache").join("railforce"))
}

/// The table of `key` from the cache, or `build()`'s, which is then stored (a cache that
/// cannot be written costs nothing but the next build).
pub(super) fn load_or_build(key: &[u64], build: impl FnOnce() -> ContactTable) -> ContactTable {
    let Some(dir) = cache_dir() else {
        return build();
    };
    let mut key = key.to_vec();
    key.push(crate::io::fnv1a64(CODE.as_bytes()));
    let path = dir.join(format!(
        "contact-{:016x}.bin",
        crate::io::fnv1a64(&key.iter().flat_map(|k| k.to_le_bytes()).collect::<Vec<_>>())
    ));
    if let Ok(bytes) = std::fs::read(&path)
        && let Some(t) = read(&bytes, &key)
    {
        return t;
    }
    let table = build();
    let bytes = write(&table, &key);
    let _ = crate::io::write_atomic(&path, |w| w.write_all(&bytes));
    table
}

/// The file of `table` under `key`: magic, version, key, payload length, payload, checksum.
pub(super) fn write(table: &ContactTable, key: &[u64]) -> Vec<u8> {
    let mut e = Encoder::default();
    e.f64(table.y_min);
    e.f64(table.dy);
    e.len(table.states.len());
    for s in &table.states {
        e.f64s(&[s.y, s.yaw, s.roll, s.z]);
        for w in &s.wheels {
            wheel(&mut e, w);
        }
        for w in &s.secondary {
            match w {
                Some(w) => {
                    e.u32(1);
                    wheel(&mut e, w);
                }
                None => e.u32(0),
            }
        }
    }
    table.strips.encode(&mut e);
    let payload = e.into_bytes();
    let mut out = Vec::with_capacity(payload.len() + 64);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&VERSION.to_le_bytes());
    out.extend_from_slice(&(key.len() as u32).to_le_bytes());
    for k in key {
        out.extend_from_slice(&k.to_le_bytes());
    }
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    out.extend_from_slice(&payload);
    out.extend_from_slice(&crate::io::fnv1a64(&payload).to_le_bytes());
    out
}

/// The table a file holds for `key`, or `None` if anything in it is off.
pub(super) fn read(bytes: &[u8], key: &[u64]) -> Option<ContactTable> {
    let mut d = Decoder::new(bytes);
    if d.take(8)? != MAGIC || d.u32()? != VERSION || d.u32()? as usize != key.len() {
        return None;
    }
    for k in key {
        if d.u64()? != *k {
            return None;
        }
    }
    let n = usize::try_from(d.u64()?).ok()?;
    let payload = d.take(n)?;
    if d.u64()? != crate::io::fnv1a64(payload) || !d.is_empty() {
        return None;
    }
    let mut d = Decoder::new(payload);
    let (y_min, dy) = (d.f64()?, d.f64()?);
    // A state is at least 4 + 2 × 14 numbers and two flags.
    let count = d.len_of(8 * (4 + 2 * 14) + 8)?;
    if count < 2 || !(dy > 0.0 && y_min.is_finite()) {
        return None;
    }
    let mut states = Vec::with_capacity(count);
    for _ in 0..count {
        let [y, yaw, roll, z] = d.f64s::<4>()?;
        let wheels = [unwheel(&mut d)?, unwheel(&mut d)?];
        let mut secondary = [None, None];
        for s in &mut secondary {
            *s = match d.u32()? {
                0 => None,
                1 => Some(unwheel(&mut d)?),
                _ => return None,
            };
        }
        states.push(ContactState {
            y,
            yaw,
            roll,
            z,
            wheels,
            secondary,
        });
    }
    let strips = super::elastic::StripTable::decode(&mut d, count)?;
    d.is_empty().then_some(ContactTable {
        y_min,
        dy,
        states,
        strips,
    })
}

fn wheel(e: &mut Encoder, w: &WheelContact) {
    let h = &w.hertz;
    e.f64s(&[
        w.wheel_y,
        w.rail_y,
        w.point[0],
        w.point[1],
        w.point[2],
        w.rolling_radius,
        w.angle,
        w.wheel_curvature,
        w.rail_curvature,
        h.curvature_sum,
        h.ma,
        h.mb,
        h.k_over_e,
        w.gap,
    ]);
}

fn unwheel(d: &mut Decoder) -> Option<WheelContact> {
    let v = d.f64s::<14>()?;
    Some(WheelContact {
        wheel_y: v[0],
        rail_y: v[1],
        point: [v[2], v[3], v[4]],
        rolling_radius: v[5],
        angle: v[6],
        wheel_curvature: v[7],
        rail_curvature: v[8],
        hertz: HertzShape {
            curvature_sum: v[9],
            ma: v[10],
            mb: v[11],
            k_over_e: v[12],
        },
        gap: v[13],
    })
}

/// Tables built in this process, by the exact geometry (and range) they tabulate: most wagons
/// of a fleet differ from each other in mass, friction or stiffness, not in profiles.
static BUILT: Mutex<Vec<(Vec<u64>, Arc<ContactTable>)>> = Mutex::new(Vec::new());

/// Tables [`BUILT`] keeps (the newest).
const KEPT: usize = 8;

impl WheelsetGeometry {
    /// [`WheelsetGeometry::table`], shared within the process: a geometry tabulated before
    /// (bit for bit the same profiles, radius, gauge and flange back) gets the same table back
    /// instead of building it again (about 1.4 s on two cores). A table is a function of its
    /// geometry alone, so the runs' bytes do not change.
    pub fn shared_table(&self, y_max: f64, dy: f64) -> Arc<ContactTable> {
        let mut key = vec![
            y_max.to_bits(),
            dy.to_bits(),
            self.nominal_radius.to_bits(),
            self.tape_circle_half.to_bits(),
            self.half_gauge.to_bits(),
            self.flange_back.to_bits(),
        ];
        self.wheel().fingerprint(&mut key);
        self.rail().fingerprint(&mut key);
        // Held while building: two runs needing the same new table build it once (the build
        // itself uses every core).
        let mut built = BUILT.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((_, t)) = built.iter().find(|(k, _)| *k == key) {
            return t.clone();
        }
        // On disk across processes: a run's first result need not wait for the build.
        let table = Arc::new(load_or_build(&key, || self.table(y_max, dy)));
        if built.len() == KEPT {
            built.remove(0);
        }
        built.push((key, table.clone()));
        table
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::geometry::WheelsetGeometry;

    fn small_table() -> (ContactTable, Vec<u64>) {
        use crate::contact::profile::{rail_60kg, s1002};
        let geo =
            WheelsetGeometry::new(s1002(), rail_60kg(), 1.0 / 40.0, 1.435, 1.353, 0.070, 0.42)
                .unwrap();
        (geo.table(0.004, 0.001), vec![1, 2, 3])
    }

    #[test]
    fn a_table_reads_back_bit_for_bit_and_a_damaged_file_is_refused() {
        let (t, key) = small_table();
        let bytes = write(&t, &key);
        let back = read(&bytes, &key).expect("its own file reads back");
        assert_eq!(back.states, t.states);
        assert_eq!(write(&back, &key), bytes, "the same bits, written again");
        // Another key, a cut, any flipped byte: refused, never a panic.
        assert!(read(&bytes, &[1, 2, 4]).is_none());
        for cut in [0, 7, 20, bytes.len() / 2, bytes.len() - 1] {
            assert!(read(&bytes[..cut], &key).is_none(), "cut at {cut}");
        }
        for i in (0..bytes.len()).step_by(97) {
            let mut b = bytes.clone();
            b[i] ^= 0x5a;
            assert!(read(&b, &key).is_none(), "byte {i} flipped was trusted");
        }
    }
}
