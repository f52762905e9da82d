//! A bit-exact text digest of a sweep's output folder, for the bit-for-bit guard
//! (`scripts/engine_bits.sh`): two folders hold the same results exactly when their digests are
//! the same text.
//!
//! Per run id (sorted): every column of `DIR/runs` with floats as their IEEE-754 bits
//! (`f64::to_bits` in hex, so −0.0, NaN payloads and the last ulp all count), one line per
//! column; then a SHA-256 of the run's `DIR/series` rows (every column of every row, in stored
//! order, as the same exact text) and the SHA-256 of each `DIR/references/*.ref` file. The
//! columns that measure the machine rather than the numbers (wall, set-up, stepping and observe
//! times) are left out: they differ between two runs of one binary.
//!
//! Generic over the Parquet schema (arrow's types, not the crate's columns), so one digest
//! program reads a base commit's folder and HEAD's alike, and a column added or dropped shows
//! as a difference.
//!
//! `cargo run --release --example runs_digest -- DIR > digest.txt`

use std::collections::BTreeMap;
use std::fs::File;
use std::path::Path;

use arrow_array::cast::AsArray;
use arrow_array::types::{
    Float32Type, Float64Type, Int8Type, Int16Type, Int32Type, Int64Type, UInt8Type, UInt16Type,
    UInt32Type, UInt64Type,
};
use arrow_array::{Array, RecordBatch};
use arrow_schema::DataType;
use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
use sha2::{Digest, Sha256};

/// Columns that time the run on this machine: never equal twice, whatever the engine.
const TIMINGS: [&str; 6] = [
    "wall_time_s",
    "wall_time_min_s",
    "wall_time_max_s",
    "setup_time_s",
    "stepping_time_s",
    "observe_time_s",
];

/// Exact text of one value: floats as bits, strings quoted, lists bracketed, nulls `null`.
fn value(a: &dyn Array, i: usize) -> String {
    if a.is_null(i) {
        return "null".into();
    }
    match a.data_type() {
        DataType::Float64 => format!(
            "{:016x}",
            a.as_primitive::<Float64Type>().value(i).to_bits()
        ),
        DataType::Float32 => format!("{:08x}", a.as_primitive::<Float32Type>().value(i).to_bits()),
        DataType::Int64 => a.as_primitive::<Int64Type>().value(i).to_string(),
        DataType::Int32 => a.as_primitive::<Int32Type>().value(i).to_string(),
        DataType::Int16 => a.as_primitive::<Int16Type>().value(i).to_string(),
        DataType::Int8 => a.as_primitive::<Int8Type>().value(i).to_string(),
        DataType::UInt64 => a.as_primitive::<UInt64Type>().value(i).to_string(),
        DataType::UInt32 => a.as_primitive::<UInt32Type>().value(i).to_string(),
        DataType::UInt16 => a.as_primitive::<UInt16Type>().value(i).to_string(),
        DataType::UInt8 => a.as_primitive::<UInt8Type>().value(i).to_string(),
        DataType::Boolean => a.as_boolean().value(i).to_string(),
        DataType::Utf8 => format!("{:?}", a.as_string::<i32>().value(i)),
        DataType::LargeUtf8 => format!("{:?}", a.as_string::<i64>().value(i)),
        DataType::Utf8View => format!("{:?}", a.as_string_view().value(i)),
        DataType::Dictionary(_, _) => {
            let d = a.as_any_dictionary();
            value(d.values().as_ref(), d.normalized_keys()[i])
        }
        DataType::List(_) => list(a.as_list::<i32>().value(i).as_ref()),
        DataType::LargeList(_) => list(a.as_list::<i64>().value(i).as_ref()),
        t => panic!("runs_digest: no exact text for a column of type {t}"),
    }
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

fn list(a: &dyn Array) -> String {
    let items: Vec<String> = (0..a.len()).map(|i| value(a, i)).collect();
    format!("[{}]", items.join(","))
}

/// Every record batch of the Parquet parts of `dir` (committed parts: `*.parquet` not starting
/// with a dot), in name order; none if absent. Not the crate's own part listing: the program is
/// built against the base commit's crate too, whose API may differ.
fn batches(dir: &Path) -> anyhow::Result<Vec<RecordBatch>> {
    let mut parts = Vec::new();
    if dir.is_dir() {
        for e in std::fs::read_dir(dir)? {
            let p = e?.path();
            let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
            if !name.starts_with('.') && name.ends_with(".parquet") {
                parts.push(p);
            }
        }
    }
    parts.sort();
    let mut out = Vec::new();
    for p in parts {
        for b in ParquetRecordBatchReaderBuilder::try_new(File::open(&p)?)?.build()? {
            out.push(b?);
        }
    }
    Ok(out)
}

/// The row's run id (the `run_id` column).
fn run_id(b: &RecordBatch, i: usize) -> anyhow::Result<String> {
    let c = b
        .column_by_name("run_id")
        .ok_or_else(|| anyhow::anyhow!("a part without a run_id column"))?;
    Ok(value(c.as_ref(), i))
}

fn main() -> anyhow::Result<()> {
    let dir = std::env::args()
        .nth(1)
        .ok_or_else(|| anyhow::anyhow!("usage: runs_digest DIR"))?;
    let dir = Path::new(&dir);

    // run id → its lines (a run id twice would show as its lines twice).
    let mut runs: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for b in batches(&dir.join("runs"))? {
        let schema = b.schema();
        for i in 0..b.num_rows() {
            let lines = runs.entry(run_id(&b, i)?).or_default();
            for (f, c) in schema.fields().iter().zip(b.columns()) {
                if f.name() == "run_id" || TIMINGS.contains(&f.name().as_str()) {
                    continue;
                }
                lines.push(format!("{} {}", f.name(), value(c.as_ref(), i)));
            }
        }
    }

    let mut series: BTreeMap<String, (Sha256, usize)> = BTreeMap::new();
    for b in batches(&dir.join("series"))? {
        let schema = b.schema();
        for i in 0..b.num_rows() {
            let e = series
                .entry(run_id(&b, i)?)
                .or_insert_with(|| (Sha256::new(), 0));
            for (f, c) in schema.fields().iter().zip(b.columns()) {
                e.0.update(format!("{}={};", f.name(), value(c.as_ref(), i)).as_bytes());
            }
            e.0.update(b"\n");
            e.1 += 1;
        }
    }

    println!("runs {}", runs.len());
    for (id, lines) in &runs {
        for l in lines {
            println!("{id} {l}");
        }
        match series.remove(id) {
            Some((h, n)) => println!("{id} series {n} rows sha256 {}", hex(&h.finalize())),
            None => println!("{id} series none"),
        }
    }
    for (id, (h, n)) in series {
        println!(
            "{id} series-without-run {n} rows sha256 {}",
            hex(&h.finalize())
        );
    }

    let refs = dir.join("references");
    if refs.is_dir() {
        let mut names: Vec<_> = std::fs::read_dir(&refs)?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "ref"))
            .collect();
        names.sort();
        for p in names {
            let h = Sha256::digest(std::fs::read(&p)?);
            let name = p.file_name().unwrap_or_default().to_string_lossy();
            println!("reference {name} sha256 {}", hex(&h));
        }
    }
    Ok(())
}
