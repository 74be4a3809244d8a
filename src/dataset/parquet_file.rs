//! Parquet writer: one required DOUBLE (or FLOAT, for float32 data sets) column per channel,
//! one row group, no compression (the
//! crate's codecs stay out of the build); pandas, polars and pyarrow read it directly
//! (`pd.read_parquet("run.parquet")`).

use parquet::basic::{Repetition, Type as PhysicalType};
use parquet::data_type::{DoubleType, FloatType};
use parquet::errors::ParquetError;
use parquet::file::properties::WriterProperties;
use parquet::file::reader::{FileReader, SerializedFileReader};
use parquet::file::writer::SerializedFileWriter;
use parquet::schema::types::Type;
use std::sync::Arc;

/// Encodes named columns as a Parquet file in memory; with `float32`, every column but time and
/// position ([`super::keeps_f64`]) is FLOAT.
pub fn write_parquet(columns: &[(&str, &[f64])], float32: bool) -> Result<Vec<u8>, ParquetError> {
    let single = |name: &str| float32 && !super::keeps_f64(name);
    let fields = columns
        .iter()
        .map(|(name, _)| {
            let t = if single(name) {
                PhysicalType::FLOAT
            } else {
                PhysicalType::DOUBLE
            };
            Type::primitive_type_builder(name, t)
                .with_repetition(Repetition::REQUIRED)
                .build()
                .map(Arc::new)
        })
        .collect::<Result<Vec<_>, _>>()?;
    let schema = Arc::new(
        Type::group_type_builder("run")
            .with_fields(fields)
            .build()?,
    );
    let props = Arc::new(
        WriterProperties::builder()
            .set_created_by(format!("railforce {}", env!("CARGO_PKG_VERSION")))
            .build(),
    );
    let mut buf = Vec::new();
    let mut writer = SerializedFileWriter::new(&mut buf, schema, props)?;
    let mut group = writer.next_row_group()?;
    for (name, values) in columns {
        let mut col = group
            .next_column()?
            .ok_or_else(|| ParquetError::General(format!("no column writer for {name}")))?;
        if single(name) {
            let v: Vec<f32> = values.iter().map(|&x| x as f32).collect();
            col.typed::<FloatType>().write_batch(&v, None, None)?;
        } else {
            col.typed::<DoubleType>().write_batch(values, None, None)?;
        }
        col.close()?;
    }
    group.close()?;
    writer.close()?;
    Ok(buf)
}

/// Reads a Parquet file of numeric columns (as [`write_parquet`], pandas or polars write it, with
/// any of the snappy, zstd, gzip or lz4 codecs) into named columns.
pub fn read_parquet(bytes: Vec<u8>) -> Result<Vec<(String, Vec<f64>)>, ParquetError> {
    let reader = SerializedFileReader::new(bytes::Bytes::from(bytes))?;
    let schema = reader.metadata().file_metadata().schema_descr_ptr();
    let mut cols: Vec<(String, Vec<f64>)> = schema
        .columns()
        .iter()
        .map(|c| (c.name().to_string(), Vec::new()))
        .collect();
    for (r, row) in reader.get_row_iter(None)?.enumerate() {
        let row = row?;
        for (k, (_, field)) in row.get_column_iter().enumerate() {
            use parquet::record::Field as F;
            let v = match field {
                F::Double(v) => *v,
                F::Float(v) => f64::from(*v),
                F::Long(v) => *v as f64,
                F::Int(v) => f64::from(*v),
                F::Short(v) => f64::from(*v),
                F::Byte(v) => f64::from(*v),
                F::ULong(v) => *v as f64,
                F::UInt(v) => f64::from(*v),
                F::UShort(v) => f64::from(*v),
                F::UByte(v) => f64::from(*v),
                F::Bool(v) => f64::from(u8::from(*v)),
                F::Null => {
                    return Err(ParquetError::General(format!(
                        "column {} is empty at row {}",
                        cols[k].0,
                        r + 1
                    )));
                }
                other => {
                    return Err(ParquetError::General(format!(
                        "column {} holds {other:?} at row {}, not a number",
                        cols[k].0,
                        r + 1
                    )));
                }
            };
            cols[k].1.push(v);
        }
    }
    Ok(cols)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parquet_round_trip() {
        let a = [1.0, -2.5, 1e300];
        let b = [0.0, 0.1, 0.2];
        let bytes = write_parquet(&[("a", &a), ("b_x", &b)], false).unwrap();
        assert_eq!(&bytes[..4], b"PAR1");
        let back = read_parquet(bytes.clone()).unwrap();
        assert_eq!(
            back,
            vec![
                ("a".to_string(), a.to_vec()),
                ("b_x".to_string(), b.to_vec())
            ]
        );
        // float32: values to f32 precision, time kept f64.
        let t = [0.005, 1e-9 + 0.01, 0.015];
        let single = write_parquet(&[("a", &b), ("time_s", &t)], true).unwrap();
        let back = read_parquet(single).unwrap();
        assert_eq!(
            back[0].1,
            b.iter().map(|&x| x as f32 as f64).collect::<Vec<_>>()
        );
        assert_eq!(back[1].1, t.to_vec());
        // Deterministic bytes.
        assert_eq!(
            bytes,
            write_parquet(&[("a", &a), ("b_x", &b)], false).unwrap()
        );
    }
}
