//! CSV of large grids, fast: rows are formatted in parallel chunks (floats by the `ryu`
//! shortest-round-trip formatter, the same text the `csv` crate writes) and written in order
//! through one buffered writer, atomically.

use std::io::Write;
use std::path::Path;

use anyhow::Result;
use rayon::prelude::*;

/// Rows per formatting chunk.
const CHUNK_ROWS: usize = 1 << 14;

/// Appends `v` to `buf` as the `csv` crate would (`100000.0`, `1e-7`, `NaN`, `inf`).
pub fn push_f64(buf: &mut Vec<u8>, v: f64) {
    let mut b = ryu::Buffer::new();
    buf.extend_from_slice(b.format(v).as_bytes());
}

/// Writes `header` and then rows `0..rows` to `out`, where `row(i, buf)` appends row `i`
/// (without its newline) to `buf`. Chunks of rows are formatted in parallel, a bounded
/// number at a time, and written in order.
pub fn write_rows(
    out: &mut dyn Write,
    header: &str,
    rows: usize,
    row: &(dyn Fn(usize, &mut Vec<u8>) + Sync),
) -> std::io::Result<()> {
    out.write_all(header.as_bytes())?;
    out.write_all(b"\n")?;
    let chunks = rows.div_ceil(CHUNK_ROWS);
    let batch = 4 * rayon::current_num_threads().max(1);
    for first in (0..chunks).step_by(batch) {
        let texts: Vec<Vec<u8>> = (first..(first + batch).min(chunks))
            .into_par_iter()
            .map(|c| {
                let mut buf = Vec::with_capacity(64 * CHUNK_ROWS);
                for i in c * CHUNK_ROWS..((c + 1) * CHUNK_ROWS).min(rows) {
                    row(i, &mut buf);
                    buf.push(b'\n');
                }
                buf
            })
            .collect();
        for t in &texts {
            out.write_all(t)?;
        }
    }
    Ok(())
}

/// [`write_rows`] into the file `path`, atomically (nothing is left on failure).
pub fn write_rows_file(
    path: &Path,
    header: &str,
    rows: usize,
    row: &(dyn Fn(usize, &mut Vec<u8>) + Sync),
) -> Result<()> {
    sandslope_files::write_output(path, |file| {
        let mut w = std::io::BufWriter::with_capacity(1 << 22, file);
        write_rows(&mut w, header, rows, row)
            .and_then(|_| w.flush())
            .map_err(|source| sandslope_files::WriteError { path: path.to_path_buf(), source }.into())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Same text as the `csv` crate's serializer, in order, across chunk boundaries.
    #[test]
    fn rows_match_the_csv_crate_in_order() {
        let n = 2 * CHUNK_ROWS + 7;
        let value = |i: usize| if i % 1000 == 3 { f64::NAN } else { (i as f64 * 1.37).exp2() * 1e-9 };
        let mut ours = Vec::new();
        write_rows(&mut ours, "i,x", n, &|i, buf| {
            buf.extend_from_slice(i.to_string().as_bytes());
            buf.push(b',');
            push_f64(buf, value(i % 60));
        })
        .unwrap();
        let mut w = csv::Writer::from_writer(Vec::new());
        w.write_record(["i", "x"]).unwrap();
        for i in 0..n {
            w.serialize((i, value(i % 60))).unwrap();
        }
        assert_eq!(String::from_utf8(ours).unwrap(), String::from_utf8(w.into_inner().unwrap()).unwrap());
    }
}
