//! How much memory a plan may take: `--max-memory` or what the machine has available, and the
//! choice of full-resolution or corridor search that follows from the DEM's size, made from
//! its header before its samples are read.

use anyhow::bail;

use sandslope::plan::Objective;

use super::{PlanRequest, PlanSearch, Search, AUTO_FULL_MAX_CELLS, MAX_MEMORY};
use crate::error::{check_range, RequestError, Result};

/// The memory limit: `--max-memory` (checked), else what the machine has available; `None`
/// where that cannot be read.
fn memory_limit(args: &PlanRequest) -> Result<Option<(f64, String)>> {
    Ok(match args.max_memory {
        Some(gib) => {
            let gib = check_range(MAX_MEMORY.flag, gib, 0.0, f64::INFINITY)?;
            if gib <= 0.0 {
                return Err(RequestError::invalid(
                    MAX_MEMORY.flag,
                    format!("{} = {gib} must be a number of GiB greater than 0", MAX_MEMORY.long()),
                ));
            }
            Some((gib * GIB, format!("the {} limit", MAX_MEMORY.long())))
        }
        None => available_memory().map(|bytes| {
            (
                bytes as f64,
                format!(
                    "the memory available (MemAvailable in /proc/meminfo; {} sets another limit)",
                    MAX_MEMORY.long()
                ),
            )
        }),
    })
}

const GIB: f64 = (1u64 << 30) as f64;

/// Rows the corridor search's coarse pass reads at once (at most: a band of strips or tiles).
const STREAM_BAND_ROWS: u64 = 512;

/// The cache of decoded chunks of a GeoTIFF read window by window, at most (`raster/windows.rs`).
const STREAM_CACHE_BYTES: u64 = 160 << 20;

/// Decides how a `cols` x `rows` DEM is searched (`--search`; `full_only` when an output needs
/// the full-resolution planner) and refuses it when that would need more memory than
/// `--max-memory` (default: what the machine has available), naming the limit and the bytes a
/// cell; called from the DEM's header, before its samples are read.
pub(super) fn choose_search(
    args: &PlanRequest,
    cols: usize,
    rows: usize,
    objectives: &[Objective],
    full_only: bool,
    in_memory: bool,
) -> anyhow::Result<Search> {
    let mut objectives = objectives.to_vec();
    objectives.push(Objective::Distance);
    objectives.sort();
    objectives.dedup();
    let searches = objectives.len().min(rayon::current_num_threads().max(1)) as u64;
    let cells = cols as u64 * rows as u64;
    let corridor = match args.search {
        PlanSearch::Full => false,
        PlanSearch::Corridor => true,
        PlanSearch::Auto => !full_only && cells > AUTO_FULL_MAX_CELLS,
    };
    let limit = memory_limit(args).map_err(RequestError::into_anyhow)?;
    if !corridor {
        let per_cell = sandslope::plan::bytes_per_cell(searches);
        let need = (cells * per_cell) as f64;
        if let Some((limit, what)) = limit.filter(|(limit, _)| need > *limit) {
            bail!(
                "{}: planning on {} x {} cells needs about {:.3} GiB ({per_cell} bytes a cell: {} for the grid and \
                 gradients, {} for each of {searches} route searches at once), more than {what} of {:.3} GiB; crop or \
                 resample the DEM (for example with gdal_translate -srcwin or -tr), or plan in a corridor \
                 (--search corridor)",
                args.dem.display(),
                cols,
                rows,
                need / GIB,
                sandslope::plan::PLANNER_BYTES_PER_CELL,
                sandslope::plan::SEARCH_BYTES_PER_CELL,
                limit / GIB
            );
        }
        return Ok(Search::Full);
    }
    // The coarse planner with its searches, the coarse pass's band of rows (its window and
    // the decoded chunks it spans, `f32`), the cache of decoded chunks, and the heights where a
    // file is read whole (an ASCII grid); what is left is shared by the corridors searched at
    // once. The full-resolution map is never held.
    let f = args.coarse_factor.max(1) as u64;
    let coarse = cols.div_ceil(f as usize) as u64 * rows.div_ceil(f as usize) as u64;
    let held = if in_memory { cells * 4 } else { 0 };
    let cache = if in_memory { 0 } else { STREAM_CACHE_BYTES };
    let stream = cols as u64 * STREAM_BAND_ROWS * 4 * 2 + cache;
    let need = held + stream + coarse * (sandslope::plan::bytes_per_cell(searches) + 4);
    let Some((limit, what)) = limit else { return Ok(Search::Corridor(None)) };
    if need as f64 > limit {
        bail!(
            "{}: planning on {} x {} cells in a corridor needs about {:.3} GiB before the corridors (the coarse \
             planner of {coarse} cells at {} bytes a cell, {:.3} GiB of rows read at once{}), more than {what} of \
             {:.3} GiB; coarsen more (--coarse-factor), or crop or resample the DEM (for example with \
             gdal_translate -srcwin or -tr)",
            args.dem.display(),
            cols,
            rows,
            need as f64 / GIB,
            sandslope::plan::bytes_per_cell(searches) + 4,
            stream as f64 / GIB,
            if in_memory { format!(", and the heights read whole, {:.3} GiB", held as f64 / GIB) } else { String::new() },
            limit / GIB
        );
    }
    Ok(Search::Corridor(Some(((limit - need as f64) / searches as f64) as u64)))
}

/// The memory the kernel says is available for new allocations (MemAvailable), in bytes;
/// `None` where /proc/meminfo cannot be read (not Linux).
fn available_memory() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}
