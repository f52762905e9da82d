//! The Parquet encoding of the sink's parts (runs and series), on the arrow-rs crates.
//!
//! What a part stores is what the readers of contract §8 (polars, pandas/pyarrow, DuckDB) need to
//! read it fast and what a simulation's numbers compress to; each column gets the encoding
//! that suits its values, not one writer-wide default:
//! - Float64: BYTE_STREAM_SPLIT. The eight bytes of a double are stored as eight streams (all
//!   first bytes, all second bytes, …): a time series varies slowly, so its sign/exponent and
//!   leading-mantissa streams are nearly constant and zstd removes them, where PLAIN
//!   interleaves them with the noisy low mantissa bytes. Measured on the 400-run series of
//!   `benches/sweeps/overhead_1d.toml`: see [`codec`].
//! - Int64: DELTA_BINARY_PACKED (`step` is 0, 1, 2, …: a few bits a page).
//! - strings: a dictionary (a series part holds a handful of run ids over ~10⁵ rows).
//! - lists (the runs' contact-phase lists): plain; they are a few values a run.
//!
//! Series parts are zstd-compressed (level 1, [`codec`]); runs parts are not ([`write_runs`]).
//! Row groups are per part (a batch), not per run: zstd's throughput falls three-fold on the
//! 2 000-row groups a run gives. A reader of one run prunes *pages* instead: statistics are
//! kept per page and the page index (column and offset index) is written, and a run's rows
//! are contiguous, so the pages of `run_id` inside a run have min = max = its id. Page size:
//! [`PAGE_ROWS`].
//!
//! The arrow schema is not embedded (`ARROW:schema`): every column's type is then the Parquet
//! logical type alone (String, Int64, Float64, List), which every reader maps to its own
//! default type for it. Parts written by polars' encoder (before this module) embedded
//! `string_view` and `large_list`: polars and pandas read both kinds with the same types
//! (`tests/readers.rs` checks it), pyarrow's arrow-level types differ (string against
//! string_view, list against large_list) and its dataset casts between them.

use std::collections::HashSet;
use std::fs::File;
use std::io::Write;
use std::ops::Range;
use std::path::Path;
use std::sync::Arc;

use arrow_array::builder::{Float64Builder, Int64Builder, ListBuilder, StringBuilder};
use arrow_array::{
    Array, ArrayRef, Float64Array, Int64Array, RecordBatch, StringArray, new_null_array,
};
use arrow_buffer::NullBuffer;
use arrow_schema::{DataType, Field, Schema};
use parquet::arrow::ArrowWriter;
use parquet::arrow::ProjectionMask;
use parquet::arrow::arrow_reader::{
    ArrowReaderOptions, ParquetRecordBatchReaderBuilder, RowSelection,
};
use parquet::arrow::arrow_writer::ArrowWriterOptions;
use parquet::basic::{Compression, Encoding, ZstdLevel};
use parquet::errors::ParquetError;
use parquet::file::metadata::PageIndexPolicy;
use parquet::file::properties::{EnabledStatistics, WriterProperties};
use parquet::schema::types::ColumnPath;

use crate::run::Series;
use crate::run::observe::OPTIONAL_SERIES;
use crate::run::record::ColumnData;

/// Rows after which a data page ends (`data_page_row_count_limit`; the writer checks it after
/// each mini-batch, so a page holds fewer than 2·PAGE_ROWS rows). Chosen on the 400-run series of
/// `benches/sweeps/overhead_1d.toml` (runs of 240 to 24 000 stored steps, parts of ≈ 60 000
/// rows), zstd level 1 everywhere: 16.02 bytes per stored step with 16 384-row pages, 15.73
/// with 32 768 (≈ 2 % less writer CPU: fewer zstd frames); 4 096-row pages cost 17.3. A run
/// longer than a page is read without its part's other pages; shorter runs share a page or
/// two.
pub const PAGE_ROWS: usize = 32 * 1024;

/// Compression of the series parts (chosen by measurement, see [`PAGE_ROWS`]): zstd level 1.
/// After BYTE_STREAM_SPLIT it leaves the noisy low mantissa bytes and removes the rest; LZ4_RAW
/// takes 17.3 bytes per step (+10 %) for ≈ 15 % less writer CPU, zstd level 3 on the three
/// largest columns 1.2 % fewer bytes for ≈ 20 % more CPU.
pub fn codec() -> Compression {
    Compression::ZSTD(ZstdLevel::try_new(1).expect("1 is a valid zstd level"))
}

/// A record batch of the given typed columns (every field nullable, as the schema of the
/// parts has always been).
pub fn record_batch(columns: Vec<(&'static str, ColumnData)>) -> Result<RecordBatch, ParquetError> {
    let mut fields = Vec::with_capacity(columns.len());
    let mut arrays: Vec<ArrayRef> = Vec::with_capacity(columns.len());
    for (name, data) in columns {
        let array: ArrayRef = match data {
            ColumnData::F64(v) => Arc::new(Float64Array::from(v)),
            ColumnData::I64(v) => Arc::new(Int64Array::from(v)),
            ColumnData::Str(v) => Arc::new(StringArray::from(v)),
            ColumnData::ListI64(v) => {
                let mut b = ListBuilder::new(Int64Builder::new());
                for l in &v {
                    match l {
                        Some(l) => {
                            b.values().append_slice(l);
                            b.append(true);
                        }
                        None => b.append_null(),
                    }
                }
                Arc::new(b.finish())
            }
            ColumnData::ListF64(v) => {
                let mut b = ListBuilder::new(Float64Builder::new());
                for l in &v {
                    match l {
                        Some(l) => {
                            for x in l {
                                b.values().append_option(*x);
                            }
                            b.append(true);
                        }
                        None => b.append_null(),
                    }
                }
                Arc::new(b.finish())
            }
        };
        fields.push(Field::new(name, array.data_type().clone(), true));
        arrays.push(array);
    }
    RecordBatch::try_new(Arc::new(Schema::new(fields)), arrays).map_err(ParquetError::from)
}

/// The writer properties of a part with this schema: encodings per column type, zstd, page
/// statistics and the page index (see the module header).
fn properties(schema: &Schema, compression: Compression) -> WriterProperties {
    let mut b = WriterProperties::builder()
        .set_compression(compression)
        .set_statistics_enabled(EnabledStatistics::Page)
        .set_dictionary_enabled(false)
        .set_data_page_row_count_limit(PAGE_ROWS)
        // One row group per part: a batch is at most a few 10⁶ rows.
        .set_max_row_group_row_count(Some(1 << 24))
        .set_created_by(format!("contact-sweep {}", env!("CARGO_PKG_VERSION")));
    for field in schema.fields() {
        let path = ColumnPath::from(field.name().as_str());
        b = match field.data_type() {
            DataType::Float64 => b.set_column_encoding(path, Encoding::BYTE_STREAM_SPLIT),
            DataType::Int64 => b.set_column_encoding(path, Encoding::DELTA_BINARY_PACKED),
            DataType::Utf8 => b.set_column_dictionary_enabled(path, true),
            _ => b,
        };
    }
    b.build()
}

/// Encode a runs part (`batch`: a batch's [`RunRecord`](crate::run::RunRecord)s) as one
/// Parquet file into `out`. Uncompressed: a runs part is ~160 columns of ~16 rows, and a zstd
/// context per column chunk cost 0.065 s of writer CPU on the 400-run sweep (25 parts) to save
/// 0.6 MB (1.5 kB a run, against the series' 60 kB).
pub fn write_runs<W: Write + Send>(out: W, batch: &RecordBatch) -> Result<(), ParquetError> {
    let options = ArrowWriterOptions::new()
        .with_properties(properties(&batch.schema(), Compression::UNCOMPRESSED))
        .with_skip_arrow_metadata(true);
    let mut writer = ArrowWriter::try_new_with_options(out, batch.schema(), options)?;
    writer.write(batch)?;
    writer.close()?;
    Ok(())
}

/// The schema of a series part: every series column, all nullable (as the parts have always
/// been).
pub fn series_schema() -> Arc<Schema> {
    let mut fields = vec![
        Field::new("run_id", DataType::Utf8, true),
        Field::new("step", DataType::Int64, true),
    ];
    for name in ["t", "u_contact", "v_contact", "sigma_contact", "energy"]
        .into_iter()
        .chain(OPTIONAL_SERIES)
    {
        fields.push(Field::new(name, DataType::Float64, true));
    }
    Arc::new(Schema::new(fields))
}

/// Encode the series of a batch's runs as one Parquet file (one row group, a record batch per
/// run: each column of a [`Series`] is moved into its array as it is, never copied).
pub fn write_series<W: Write + Send>(
    out: W,
    runs: Vec<(String, Series)>,
) -> Result<(), ParquetError> {
    let schema = series_schema();
    let options = ArrowWriterOptions::new()
        .with_properties(properties(&schema, codec()))
        .with_skip_arrow_metadata(true);
    let mut writer = ArrowWriter::try_new_with_options(out, Arc::clone(&schema), options)?;
    for (id, s) in runs {
        let n = s.len();
        let mut ids = StringBuilder::with_capacity(n, n * id.len());
        for _ in 0..n {
            ids.append_value(&id);
        }
        let mut columns: Vec<ArrayRef> = vec![
            Arc::new(ids.finish()),
            Arc::new(Int64Array::from(s.step)),
            Arc::new(Float64Array::from(s.t)),
            Arc::new(Float64Array::from(s.u_contact)),
            Arc::new(Float64Array::from(s.v_contact)),
            Arc::new(Float64Array::from(s.sigma_contact)),
            Arc::new(Float64Array::from(s.energy)),
        ];
        for (values, valid) in s.optional.into_iter().zip(s.valid) {
            columns.push(if valid.is_empty() {
                new_null_array(&DataType::Float64, n)
            } else {
                let nulls = (!valid.iter().all(|&v| v)).then(|| NullBuffer::from(valid));
                Arc::new(Float64Array::new(values.into(), nulls))
            });
        }
        writer.write(&RecordBatch::try_new(Arc::clone(&schema), columns)?)?;
    }
    writer.close()?;
    Ok(())
}

/// Whether a part already has exactly the columns of `current` (the current
/// [`RunRecord`](crate::run::RunRecord) schema, or [`series_schema`]), in order.
pub fn part_is_current(path: &Path, current: &Schema) -> Result<bool, ParquetError> {
    let b = builder(path)?;
    let names =
        |s: &Schema| -> Vec<String> { s.fields().iter().map(|f| f.name().clone()).collect() };
    Ok(names(b.schema()) == names(current))
}

/// Rewrite a part written by an older version into `out` with the columns of `current`:
/// its own columns as stored (read by their Parquet logical types, as every reader reads
/// them), a column it lacks as nulls of the current type, in the current order; a column the
/// current schema no longer has is kept, after the others (nothing computed is dropped).
///
/// Why: readers of a folder glob take the first part's columns as the folder's. Polars
/// refuses a later part with a column the first lacks ("extra column in file outside of
/// expected schema"), pyarrow's dataset (pandas) silently drops it — so a folder resumed by a
/// version with new columns (`rho_inf`, `pressure_oscillation`, …; the series' friction columns
/// of issue 32) must hold one schema. `compression`: the parts' own (none for runs parts,
/// [`codec`] for series parts, whose size it keeps).
pub fn conform_part<W: Write + Send>(
    path: &Path,
    current: &Schema,
    compression: Compression,
    out: W,
) -> Result<(), ParquetError> {
    let file = File::open(path).map_err(|e| ParquetError::External(Box::new(e)))?;
    let b = ParquetRecordBatchReaderBuilder::try_new_with_options(
        file,
        ArrowReaderOptions::new().with_skip_arrow_metadata(true),
    )?;
    let stored = b.schema().clone();
    let batches = b.build()?.collect::<Result<Vec<_>, _>>()?;
    let mut fields: Vec<Field> = Vec::new();
    let mut source: Vec<Option<usize>> = Vec::new();
    for f in current.fields() {
        match stored.index_of(f.name()) {
            Ok(k) => {
                fields.push(stored.field(k).clone().with_nullable(true));
                source.push(Some(k));
            }
            Err(_) => {
                fields.push(f.as_ref().clone());
                source.push(None);
            }
        }
    }
    for (k, f) in stored.fields().iter().enumerate() {
        if current.index_of(f.name()).is_err() {
            fields.push(f.as_ref().clone().with_nullable(true));
            source.push(Some(k));
        }
    }
    let schema = Arc::new(Schema::new(fields));
    let options = ArrowWriterOptions::new()
        .with_properties(properties(&schema, compression))
        .with_skip_arrow_metadata(true);
    let mut writer = ArrowWriter::try_new_with_options(out, Arc::clone(&schema), options)?;
    for batch in batches {
        let columns: Vec<ArrayRef> = source
            .iter()
            .zip(schema.fields())
            .map(|(k, f)| match k {
                Some(k) => Arc::clone(batch.column(*k)),
                None => new_null_array(f.data_type(), batch.num_rows()),
            })
            .collect();
        writer.write(&RecordBatch::try_new(Arc::clone(&schema), columns)?)?;
    }
    writer.close()?;
    Ok(())
}

fn builder(path: &Path) -> Result<ParquetRecordBatchReaderBuilder<File>, ParquetError> {
    let file = File::open(path).map_err(|e| ParquetError::External(Box::new(e)))?;
    ParquetRecordBatchReaderBuilder::try_new_with_options(
        file,
        ArrowReaderOptions::new().with_page_index_policy(PageIndexPolicy::Optional),
    )
}

/// The string column `name` of a part, every row (null rows as None).
fn strings(path: &Path, name: &str) -> Result<Vec<Option<String>>, ParquetError> {
    let b = builder(path)?;
    let index = b
        .schema()
        .index_of(name)
        .map_err(|_| ParquetError::General(format!("no column `{name}`")))?;
    let mask = ProjectionMask::roots(b.parquet_schema(), [index]);
    let mut out = Vec::new();
    for batch in b.with_projection(mask).build()? {
        let batch = batch?;
        let col = batch.column(0);
        let col = arrow_cast_str(col)?;
        out.extend(col.iter().map(|s| s.map(String::from)));
    }
    Ok(out)
}

/// A string column as a StringArray (parts written by polars' encoder store LargeUtf8 or
/// Utf8View in their embedded schema; both are read here).
fn arrow_cast_str(col: &ArrayRef) -> Result<StringArray, ParquetError> {
    if let Some(s) = col.as_any().downcast_ref::<StringArray>() {
        return Ok(s.clone());
    }
    if let Some(s) = col.as_any().downcast_ref::<arrow_array::LargeStringArray>() {
        return Ok(s.iter().collect());
    }
    if let Some(s) = col.as_any().downcast_ref::<arrow_array::StringViewArray>() {
        return Ok(s.iter().collect());
    }
    Err(ParquetError::General(format!(
        "a string column was expected, found {}",
        col.data_type()
    )))
}

/// The `run_id` of every row of a part, in order.
pub fn run_ids(path: &Path) -> Result<Vec<Option<String>>, ParquetError> {
    strings(path, "run_id")
}

/// Why a part cannot be read, if it cannot: `whole` decodes every page (a runs part: small,
/// and a damaged page fails only when decoded); otherwise the footer only (a series part may
/// be large).
pub fn problem(path: &Path, whole: bool) -> Option<String> {
    let check = || -> Result<(), ParquetError> {
        let b = builder(path)?;
        if whole {
            for batch in b.build()? {
                batch?;
            }
        }
        Ok(())
    };
    check().err().map(|e| {
        let text = e.to_string();
        text.lines()
            .next()
            .unwrap_or("unreadable")
            .trim()
            .to_string()
    })
}

/// Contiguous row ranges of the runs `wanted` in a part: (run id, rows).
pub fn run_ranges(
    path: &Path,
    wanted: &HashSet<&str>,
) -> Result<Vec<(String, Range<usize>)>, ParquetError> {
    let mut out: Vec<(String, Range<usize>)> = Vec::new();
    for (row, id) in run_ids(path)?.into_iter().enumerate() {
        let Some(id) = id.filter(|id| wanted.contains(id.as_str())) else {
            continue;
        };
        match out.last_mut() {
            Some((last, r)) if *last == id && r.end == row => r.end += 1,
            _ => out.push((id, row..row + 1)),
        }
    }
    Ok(out)
}

/// The float columns `columns` (missing ones as nulls) of the rows `ranges` of a part, in row
/// order, with the page index pruning the pages outside them: the report reads ≤ 8 runs of a
/// part holding many.
pub fn read_rows_f64(
    path: &Path,
    ranges: &[Range<usize>],
    columns: &[&str],
) -> Result<Vec<Vec<Option<f64>>>, ParquetError> {
    let b = builder(path)?;
    let schema = b.schema().clone();
    let present: Vec<(usize, usize)> = columns
        .iter()
        .enumerate()
        .filter_map(|(k, c)| schema.index_of(c).ok().map(|i| (k, i)))
        .collect();
    let rows: usize = ranges.iter().map(|r| r.len()).sum();
    let mut out = vec![Vec::with_capacity(rows); columns.len()];
    if present.is_empty() {
        for col in &mut out {
            col.resize(rows, None);
        }
        return Ok(out);
    }
    let total = b.metadata().file_metadata().num_rows() as usize;
    let mask = ProjectionMask::roots(b.parquet_schema(), present.iter().map(|(_, i)| *i));
    let selection = RowSelection::from_consecutive_ranges(ranges.iter().cloned(), total);
    let reader = b
        .with_projection(mask)
        .with_row_selection(selection)
        .build()?;
    for batch in reader {
        let batch = batch?;
        for (k, name) in columns.iter().enumerate() {
            let Ok(col) = batch.schema().index_of(name) else {
                out[k].extend(std::iter::repeat_n(None, batch.num_rows()));
                continue;
            };
            let col = batch.column(col);
            match col.as_any().downcast_ref::<Float64Array>() {
                Some(f) => out[k].extend(f.iter()),
                None => out[k].extend(std::iter::repeat_n(None, batch.num_rows())),
            }
        }
    }
    Ok(out)
}
