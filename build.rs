//! Build script: a hash of the contact module's sources, so the contact tables cached on disk
//! (`src/contact/table_cache.rs`) are keyed by the code that builds them.

use std::path::Path;

fn main() {
    let dir = Path::new("src/contact");
    println!("cargo:rerun-if-changed=src/contact");
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .map(|d| d.flatten().map(|e| e.path()).collect())
        .unwrap_or_default();
    files.sort();
    // FNV-1a 64 over each file's name and bytes, in name order.
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for f in files {
        let mut bytes = f
            .file_name()
            .map_or(Vec::new(), |n| n.as_encoded_bytes().to_vec());
        bytes.extend(std::fs::read(&f).unwrap_or_default());
        for b in bytes {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    }
    println!("cargo:rustc-env=RAILFORCE_CONTACT_SOURCE_HASH={h:016x}");
}
