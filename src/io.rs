//! File helpers: atomic writes, so an interrupted run never leaves a half-written file.

use crate::error::{Error, Result};
use std::fs;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// Writes a file atomically: the content goes to a temporary file in the same folder, which is
/// flushed, synced and then renamed over `path`. Readers see either the old file or the whole
/// new one, never a part.
pub fn write_atomic<F>(path: &Path, fill: F) -> Result<()>
where
    F: FnOnce(&mut dyn Write) -> std::io::Result<()>,
{
    let tmp = temp_path(path);
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    }
    let result = (|| -> std::io::Result<()> {
        let file = fs::File::create(&tmp)?;
        let mut w = BufWriter::new(file);
        fill(&mut w)?;
        let file = w.into_inner().map_err(|e| e.into_error())?;
        file.sync_all()?;
        Ok(())
    })();
    if let Err(e) = result {
        let _ = fs::remove_file(&tmp);
        return Err(Error::io(path, e));
    }
    fs::rename(&tmp, path).map_err(|e| {
        let _ = fs::remove_file(&tmp);
        Error::io(path, e)
    })
}

/// Refuses a CSV text (header line, then rows) with a cell that reads as a non-finite number
/// (`NaN`, `inf`, `-inf`, any case), naming the file, the column and the row: a table is
/// checked before it is written, so none carries NaN.
pub fn check_csv_finite(text: &str, path: &Path) -> Result<()> {
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    for (r, line) in lines.enumerate() {
        for (c, cell) in line.split(',').enumerate() {
            let t = cell
                .trim()
                .trim_start_matches(['+', '-'])
                .to_ascii_lowercase();
            if t == "nan" || t == "inf" || t == "infinity" {
                return Err(Error::Domain(format!(
                    "{}: not written: column {} holds {} at row {}",
                    path.display(),
                    header.get(c).copied().unwrap_or("?"),
                    cell.trim(),
                    r + 1
                )));
            }
        }
    }
    Ok(())
}

/// Temporary sibling of `path` used by [`write_atomic`]: `.NAME.tmp-PID-N`, N unique within
/// the process so that two threads writing the same file never share a temporary.
fn temp_path(path: &Path) -> PathBuf {
    static COUNTER: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let n = COUNTER.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    path.with_file_name(format!(".{name}.tmp-{}-{n}", std::process::id()))
}

/// FNV-1a 64 of bytes: the project's one content hash (file hashes, resume keys, the seed of a
/// varied key's stream).
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    h
}

/// Reads a whole text file, naming the path in the error.
pub fn read_text(path: &Path) -> Result<String> {
    fs::read_to_string(path).map_err(|e| Error::io(path, e))
}

/// Parses TOML text into `T`; the error names the file and carries the parser's message (key,
/// line and column), as every configuration error does.
///
/// Every number of the document passes the declared ranges first ([`crate::bounds`]):
/// finite, and within the physical range its field's unit declares.
pub fn parse_toml<T: serde::de::DeserializeOwned>(text: &str, path: &Path) -> Result<T> {
    let parse_err = |e: toml::de::Error| Error::Parse {
        file: path.to_path_buf(),
        message: e.to_string().trim_end().to_string(),
    };
    let table: toml::Table = toml::from_str(text).map_err(parse_err)?;
    crate::bounds::check_toml(&table, path)?;
    toml::from_str(text).map_err(parse_err)
}

/// Reads and parses a TOML file into `T` (see [`parse_toml`]).
pub fn read_toml<T: serde::de::DeserializeOwned>(path: &Path) -> Result<T> {
    parse_toml(&read_text(path)?, path)
}

/// Reads and parses a JSON file into `T`; the error names the file and carries the parser's
/// message (line and column).
pub fn read_json<T: serde::de::DeserializeOwned>(path: &Path) -> Result<T> {
    serde_json::from_str(&read_text(path)?).map_err(|e| Error::Parse {
        file: path.to_path_buf(),
        message: e.to_string(),
    })
}

/// Serialises `value` as pretty JSON after checking that it holds no non-finite number:
/// `serde_json` writes NaN and infinity as `null`, which would pass a NaN into a model file,
/// a manifest or a report without a word. The error names `path` and the field
/// (`columns[3].mean`).
pub fn to_json_pretty<T: serde::Serialize + ?Sized>(value: &T, path: &Path) -> Result<String> {
    check_json_finite(value, path)?;
    serde_json::to_string_pretty(value)
        .map_err(|e| Error::Domain(format!("{}: {e}", path.display())))
}

/// Compact form of [`to_json_pretty`].
pub fn to_json<T: serde::Serialize + ?Sized>(value: &T, path: &Path) -> Result<String> {
    check_json_finite(value, path)?;
    serde_json::to_string(value).map_err(|e| Error::Domain(format!("{}: {e}", path.display())))
}

/// Refuses a value holding a non-finite float anywhere, naming `path` and the field.
pub fn check_json_finite<T: serde::Serialize + ?Sized>(value: &T, path: &Path) -> Result<()> {
    value
        .serialize(finite::Check::default())
        .map_err(|e| Error::Domain(format!("{}: {} (nothing written)", path.display(), e.0)))
}

mod finite {
    //! A serde serialiser that writes nothing and fails on the first non-finite float,
    //! naming the field it met it at.
    use serde::ser::{self, Serialize};

    #[derive(Debug)]
    pub struct Bad(pub String);
    impl std::fmt::Display for Bad {
        fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            f.write_str(&self.0)
        }
    }
    impl std::error::Error for Bad {}
    impl ser::Error for Bad {
        fn custom<T: std::fmt::Display>(msg: T) -> Self {
            Bad(msg.to_string())
        }
    }

    /// The field path walked so far.
    #[derive(Default, Clone)]
    pub struct Check {
        at: String,
    }
    impl Check {
        fn key(&self, k: &str) -> Check {
            Check {
                at: if self.at.is_empty() {
                    k.to_string()
                } else {
                    format!("{}.{k}", self.at)
                },
            }
        }
        fn index(&self, i: usize) -> Check {
            Check {
                at: format!("{}[{i}]", self.at),
            }
        }
        fn float(&self, v: f64) -> Result<(), Bad> {
            if v.is_finite() {
                Ok(())
            } else {
                let at = if self.at.is_empty() {
                    "the value"
                } else {
                    &self.at
                };
                Err(Bad(format!(
                    "{at} is {v}: a non-finite number is never written"
                )))
            }
        }
    }

    /// A sequence, tuple or map being walked.
    pub struct Seq {
        at: Check,
        n: usize,
        key: Option<String>,
    }

    macro_rules! ok {
        ($($name:ident: $t:ty),*) => {
            $(fn $name(self, _v: $t) -> Result<(), Bad> { Ok(()) })*
        };
    }

    impl ser::Serializer for Check {
        type Ok = ();
        type Error = Bad;
        type SerializeSeq = Seq;
        type SerializeTuple = Seq;
        type SerializeTupleStruct = Seq;
        type SerializeTupleVariant = Seq;
        type SerializeMap = Seq;
        type SerializeStruct = Seq;
        type SerializeStructVariant = Seq;
        ok!(serialize_bool: bool, serialize_i8: i8, serialize_i16: i16, serialize_i32: i32,
            serialize_i64: i64, serialize_u8: u8, serialize_u16: u16, serialize_u32: u32,
            serialize_u64: u64, serialize_char: char, serialize_str: &str,
            serialize_bytes: &[u8], serialize_unit_struct: &'static str);
        fn serialize_f32(self, v: f32) -> Result<(), Bad> {
            self.float(f64::from(v))
        }
        fn serialize_f64(self, v: f64) -> Result<(), Bad> {
            self.float(v)
        }
        fn serialize_none(self) -> Result<(), Bad> {
            Ok(())
        }
        fn serialize_some<T: Serialize + ?Sized>(self, v: &T) -> Result<(), Bad> {
            v.serialize(self)
        }
        fn serialize_unit(self) -> Result<(), Bad> {
            Ok(())
        }
        fn serialize_unit_variant(
            self,
            _: &'static str,
            _: u32,
            _: &'static str,
        ) -> Result<(), Bad> {
            Ok(())
        }
        fn serialize_newtype_struct<T: Serialize + ?Sized>(
            self,
            _: &'static str,
            v: &T,
        ) -> Result<(), Bad> {
            v.serialize(self)
        }
        fn serialize_newtype_variant<T: Serialize + ?Sized>(
            self,
            _: &'static str,
            _: u32,
            variant: &'static str,
            v: &T,
        ) -> Result<(), Bad> {
            v.serialize(self.key(variant))
        }
        fn serialize_seq(self, _: Option<usize>) -> Result<Seq, Bad> {
            Ok(Seq {
                at: self,
                n: 0,
                key: None,
            })
        }
        fn serialize_tuple(self, _: usize) -> Result<Seq, Bad> {
            self.serialize_seq(None)
        }
        fn serialize_tuple_struct(self, _: &'static str, _: usize) -> Result<Seq, Bad> {
            self.serialize_seq(None)
        }
        fn serialize_tuple_variant(
            self,
            _: &'static str,
            _: u32,
            v: &'static str,
            _: usize,
        ) -> Result<Seq, Bad> {
            self.key(v).serialize_seq(None)
        }
        fn serialize_map(self, _: Option<usize>) -> Result<Seq, Bad> {
            self.serialize_seq(None)
        }
        fn serialize_struct(self, _: &'static str, _: usize) -> Result<Seq, Bad> {
            self.serialize_seq(None)
        }
        fn serialize_struct_variant(
            self,
            _: &'static str,
            _: u32,
            v: &'static str,
            _: usize,
        ) -> Result<Seq, Bad> {
            self.key(v).serialize_seq(None)
        }
    }

    impl Seq {
        fn element<T: Serialize + ?Sized>(&mut self, v: &T) -> Result<(), Bad> {
            let at = self.at.index(self.n);
            self.n += 1;
            v.serialize(at)
        }
        fn field<T: Serialize + ?Sized>(&mut self, k: &str, v: &T) -> Result<(), Bad> {
            v.serialize(self.at.key(k))
        }
    }
    /// The compound walks whose items are positional: each is an element of the field.
    macro_rules! positional {
        ($($trait:ident :: $method:ident),*) => {$(
            impl ser::$trait for Seq {
                type Ok = ();
                type Error = Bad;
                fn $method<T: Serialize + ?Sized>(&mut self, v: &T) -> Result<(), Bad> {
                    self.element(v)
                }
                fn end(self) -> Result<(), Bad> {
                    Ok(())
                }
            }
        )*};
    }
    positional!(
        SerializeSeq::serialize_element,
        SerializeTuple::serialize_element,
        SerializeTupleStruct::serialize_field,
        SerializeTupleVariant::serialize_field
    );
    impl ser::SerializeMap for Seq {
        type Ok = ();
        type Error = Bad;
        fn serialize_key<T: Serialize + ?Sized>(&mut self, k: &T) -> Result<(), Bad> {
            // Keys name the field; a non-string key is shown by its JSON text.
            self.key = Some(
                serde_json::to_string(k)
                    .map(|s| s.trim_matches('"').to_string())
                    .unwrap_or_default(),
            );
            Ok(())
        }
        fn serialize_value<T: Serialize + ?Sized>(&mut self, v: &T) -> Result<(), Bad> {
            let k = self.key.take().unwrap_or_default();
            self.field(&k, v)
        }
        fn end(self) -> Result<(), Bad> {
            Ok(())
        }
    }
    /// The compound walks whose items are named fields.
    macro_rules! named {
        ($($trait:ident),*) => {$(
            impl ser::$trait for Seq {
                type Ok = ();
                type Error = Bad;
                fn serialize_field<T: Serialize + ?Sized>(
                    &mut self,
                    k: &'static str,
                    v: &T,
                ) -> Result<(), Bad> {
                    self.field(k, v)
                }
                fn end(self) -> Result<(), Bad> {
                    Ok(())
                }
            }
        )*};
    }
    named!(SerializeStruct, SerializeStructVariant);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atomic_write_replaces_whole_file_and_leaves_no_temp() {
        let dir = std::env::temp_dir().join(format!("railforce-io-{}", std::process::id()));
        let path = dir.join("a.txt");
        write_atomic(&path, |w| w.write_all(b"first")).unwrap();
        write_atomic(&path, |w| w.write_all(b"second")).unwrap();
        assert_eq!(fs::read_to_string(&path).unwrap(), "second");
        // A failing writer keeps the old content and removes its temporary file.
        let err = write_atomic(&path, |w| {
            w.write_all(b"half")?;
            Err(std::io::Error::other("interrupted"))
        });
        assert!(err.is_err());
        assert_eq!(fs::read_to_string(&path).unwrap(), "second");
        let leftovers: Vec<_> = fs::read_dir(&dir)
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().contains(".tmp-"))
            .collect();
        assert!(leftovers.is_empty());
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn json_with_a_non_finite_number_is_refused_by_field() {
        #[derive(serde::Serialize)]
        struct Col {
            name: String,
            mean: f64,
        }
        let mut m = std::collections::BTreeMap::new();
        m.insert(
            "cols",
            vec![
                Col {
                    name: "a".into(),
                    mean: 1.0,
                },
                Col {
                    name: "b".into(),
                    mean: f64::NAN,
                },
            ],
        );
        let e = to_json_pretty(&m, Path::new("out/model.json"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("out/model.json") && e.contains("cols[1].mean"),
            "{e}"
        );
        m.get_mut("cols").unwrap()[1].mean = 2.0;
        assert!(
            to_json_pretty(&m, Path::new("x"))
                .unwrap()
                .contains("\"mean\": 2.0")
        );
        let opt: Option<f64> = None;
        assert_eq!(to_json(&opt, Path::new("x")).unwrap(), "null");
    }
}
