//! The ESRI ASCII grid reader (`.asc`): header keys, size checks before allocating, values.

use std::path::Path;

use anyhow::{anyhow, bail, Context, Result};

use super::grid::{check_raster_size, memory_limit, GeoRef, Raster, SizeCheck};

/// An ESRI ASCII grid (its CRS from a `.prj` beside it, if any), and the factor converting its
/// heights to metres.
pub(super) fn read_asc(path: &Path, fits: SizeCheck) -> Result<(Raster, f64)> {
    let name = path.display();
    let bytes = std::fs::metadata(path).with_context(|| format!("cannot read {name}"))?.len();
    // The text is held whole while it is parsed.
    let (limit, what) = memory_limit();
    if bytes > limit {
        bail!("{name}: {bytes} bytes of text is more than {what} of {limit} bytes; convert it to a GeoTIFF");
    }
    let text = std::fs::read_to_string(path).with_context(|| format!("cannot read {name}"))?;
    let mut header = std::collections::HashMap::new();
    let mut lines = text.lines().enumerate().peekable();
    // Header lines: a key starting with a letter, then a number.
    while let Some((i, line)) = lines.peek().copied() {
        let mut it = line.split_whitespace();
        let Some(key) = it.next() else {
            lines.next();
            continue;
        };
        if !key.starts_with(|c: char| c.is_ascii_alphabetic()) {
            break;
        }
        let value = it
            .next()
            .and_then(|v| v.parse::<f64>().ok())
            .ok_or_else(|| anyhow!("{name}: line {}: header `{key}` needs a numeric value", i + 1))?;
        header.insert(key.to_ascii_lowercase(), value);
        lines.next();
    }
    let get = |k: &str| header.get(k).copied();
    let need = |k: &str| get(k).ok_or_else(|| anyhow!("{name}: missing header `{k}`"));
    let count = |k: &str| -> Result<usize> {
        let v = need(k)?;
        if v >= 1.0 && v.fract() == 0.0 && v < 1e9 {
            Ok(v as usize)
        } else {
            bail!("{name}: header {k} = {v} must be a positive whole number")
        }
    };
    let (cols, rows) = (count("ncols")?, count("nrows")?);
    fits(cols, rows)?;
    check_raster_size(&name, cols as u64, rows as u64, 8)?;
    // Every value takes at least two bytes (a digit and a separator): a header that claims more
    // cells than the file can hold is refused before the grid is allocated.
    if cols.saturating_mul(rows) > text.len() / 2 + 1 {
        bail!(
            "{name}: the header claims ncols x nrows = {cols} x {rows} = {} values, but the file has only \
             {} bytes",
            cols * rows,
            text.len()
        );
    }
    let (cell_x, cell_y) = match (get("cellsize"), get("dx"), get("dy")) {
        (Some(c), _, _) => (c, c),
        (None, Some(x), Some(y)) => (x, y),
        _ => bail!("{name}: missing header `cellsize` (or `dx` and `dy`)"),
    };
    if !(cell_x.is_finite() && cell_x > 0.0 && cell_y.is_finite() && cell_y > 0.0) {
        bail!("{name}: cellsize = {cell_x} must be a finite number greater than 0");
    }
    let west = match (get("xllcorner"), get("xllcenter")) {
        (Some(x), _) => x,
        (None, Some(x)) => x - 0.5 * cell_x,
        _ => bail!("{name}: missing header `xllcorner` (or `xllcenter`)"),
    };
    let south = match (get("yllcorner"), get("yllcenter")) {
        (Some(y), _) => y,
        (None, Some(y)) => y - 0.5 * cell_y,
        _ => bail!("{name}: missing header `yllcorner` (or `yllcenter`)"),
    };
    let nodata = get("nodata_value");
    let mut values = Vec::with_capacity(cols * rows);
    for (i, line) in lines {
        for tok in line.split_whitespace() {
            let v =
                tok.parse::<f64>().map_err(|_| anyhow!("{name}: line {}: `{tok}` is not a number", i + 1))?;
            values.push(v);
        }
    }
    if values.len() != cols * rows {
        bail!("{name}: {} values for ncols x nrows = {cols} x {rows} = {}", values.len(), cols * rows);
    }
    let geo = GeoRef {
        west,
        north: south + rows as f64 * cell_y,
        cell_x,
        cell_y,
        geokeys: None,
        geodoubles: None,
        geoascii: None,
    };
    let mut notes = Vec::new();
    let crs = crate::crs::from_prj(&path.with_extension("prj"), &mut notes)?;
    let cell_m = (cell_x, cell_y);
    Ok((Raster { cols, rows, values, nodata, geo, crs, cell_m, row_widths_m: None, notes }, 1.0))
}
