//! Bytes per column of the Parquet parts of a folder (compressed, summed over row groups and
//! parts), per stored row: where the size of `DIR/series` goes.
//!
//! `cargo run --release --example parquet_columns -- DIR/series`

use std::collections::BTreeMap;
use std::fs::File;

use polars::prelude::*;

fn main() -> anyhow::Result<()> {
    let dir = std::env::args()
        .nth(1)
        .ok_or_else(|| anyhow::anyhow!("usage: parquet_columns DIR"))?;
    let parts = contact_sweep::sink::parquet_parts(std::path::Path::new(&dir))?;
    let mut bytes: BTreeMap<String, (usize, i64, i64)> = BTreeMap::new();
    let (mut rows, mut groups, mut file_bytes) = (0usize, 0usize, 0u64);
    for (order, p) in parts.iter().enumerate() {
        file_bytes += std::fs::metadata(p)?.len();
        let mut reader = ParquetReader::new(File::open(p)?);
        let md = reader.get_metadata()?.clone();
        for rg in &md.row_groups {
            rows += rg.num_rows();
            groups += 1;
            for (i, c) in rg.parquet_columns().iter().enumerate() {
                let name = c.descriptor().path_in_schema.join(".");
                let e = bytes.entry(name).or_insert((order * 100 + i, 0, 0));
                e.1 += c.compressed_size();
                e.2 += c.uncompressed_size();
            }
        }
    }
    let mut cols: Vec<_> = bytes.into_iter().collect();
    cols.sort_by_key(|(_, (o, _, _))| *o);
    println!(
        "{} parts, {groups} row groups, {rows} rows, {file_bytes} bytes = {:.2} bytes/row",
        parts.len(),
        file_bytes as f64 / rows.max(1) as f64
    );
    for (name, (_, c, u)) in cols {
        println!(
            "{name:>22}  {:>7.2} B/row compressed  {:>7.2} B/row uncompressed",
            c as f64 / rows.max(1) as f64,
            u as f64 / rows.max(1) as f64
        );
    }
    Ok(())
}
