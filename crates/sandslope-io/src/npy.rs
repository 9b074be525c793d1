//! NumPy `.npy` files (format version 1.0), so phase and risk maps load directly with
//! `numpy.load` (and from there into xarray).
//!
//! Two element types cover every map: `int8` (regime codes, docs/model.md §6: 0 sinkage,
//! 1 slippage, 2 metastable, 3 success) and `float64` (steps, probabilities, axes; NaN where
//! undefined). Arrays are C-ordered (the last index varies fastest), little-endian.

use std::io::Write;
use std::path::Path;

use anyhow::Result;

/// The data of one array.
#[derive(Debug, Clone, Copy)]
pub enum NpyData<'a> {
    /// `int8` values (`<i1`).
    I8(&'a [i8]),
    /// `float64` values (`<f8`).
    F64(&'a [f64]),
}

impl NpyData<'_> {
    fn len(&self) -> usize {
        match self {
            NpyData::I8(v) => v.len(),
            NpyData::F64(v) => v.len(),
        }
    }
    fn descr(&self) -> &'static str {
        match self {
            NpyData::I8(_) => "|i1",
            NpyData::F64(_) => "<f8",
        }
    }
}

/// The header of a version 1.0 `.npy` file for `data` of `shape`: magic, version, length,
/// and the dictionary padded with spaces to a multiple of 64 bytes, ending in a newline.
pub fn header(shape: &[usize], data: NpyData<'_>) -> Vec<u8> {
    let dims: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
    let shape = match dims.len() {
        1 => format!("({},)", dims[0]),
        _ => format!("({})", dims.join(", ")),
    };
    let mut dict = format!("{{'descr': '{}', 'fortran_order': False, 'shape': {shape}, }}", data.descr());
    // 6 magic + 2 version + 2 length + dict + '\n' must be a multiple of 64.
    let total = (10 + dict.len() + 1).div_ceil(64) * 64;
    while 10 + dict.len() + 1 < total {
        dict.push(' ');
    }
    dict.push('\n');
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend_from_slice(&(dict.len() as u16).to_le_bytes());
    out.extend_from_slice(dict.as_bytes());
    out
}

/// Writes `data` with `shape` (whose product must be the data's length) as `.npy` to `w`.
pub fn write_npy(w: &mut dyn Write, shape: &[usize], data: NpyData<'_>) -> std::io::Result<()> {
    assert_eq!(shape.iter().product::<usize>(), data.len(), "shape does not match the data");
    w.write_all(&header(shape, data))?;
    match data {
        NpyData::I8(v) => {
            let bytes: Vec<u8> = v.iter().map(|&x| x as u8).collect();
            w.write_all(&bytes)
        }
        NpyData::F64(v) => {
            for chunk in v.chunks(1 << 16) {
                let bytes: Vec<u8> = chunk.iter().flat_map(|x| x.to_le_bytes()).collect();
                w.write_all(&bytes)?;
            }
            Ok(())
        }
    }
}

/// Writes one `.npy` file atomically.
pub fn write_npy_file(path: &Path, shape: &[usize], data: NpyData<'_>) -> Result<()> {
    sandslope_files::write_output(path, |file| {
        let mut w = std::io::BufWriter::with_capacity(1 << 20, file);
        write_npy(&mut w, shape, data)
            .and_then(|_| w.flush())
            .map_err(|source| sandslope_files::WriteError { path: path.to_path_buf(), source }.into())
    })
}

/// Writes several arrays `(file name, shape, data)` into the folder `dir` (created if missing),
/// each atomically.
pub fn write_npy_dir(dir: &Path, arrays: &[(&str, Vec<usize>, NpyData<'_>)]) -> Result<()> {
    prepare_npy_dir(dir)?;
    for (name, shape, data) in arrays {
        write_npy_file(&dir.join(name), shape, *data)?;
    }
    Ok(())
}

/// Makes the `--npy` folder `dir` if it is missing, as `mkdir -p` would (a run that fails
/// removes what it made); fails with a clear message if `dir` is a file.
pub fn prepare_npy_dir(dir: &Path) -> Result<()> {
    sandslope_files::create_output_dir(dir).map_err(|e| e.context(format!("--npy {}", dir.display())))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The layout NumPy's documentation gives for version 1.0, byte by byte.
    #[test]
    fn header_and_data_follow_the_format() {
        let mut out = Vec::new();
        write_npy(&mut out, &[2, 3], NpyData::F64(&[1.0, 2.0, 3.0, 4.0, 5.0, f64::NAN])).unwrap();
        assert_eq!(&out[..8], b"\x93NUMPY\x01\x00");
        let len = u16::from_le_bytes([out[8], out[9]]) as usize;
        assert_eq!((10 + len) % 64, 0);
        let dict = std::str::from_utf8(&out[10..10 + len]).unwrap();
        assert!(dict.starts_with("{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }"), "{dict}");
        assert!(dict.ends_with(" \n"));
        let data = &out[10 + len..];
        assert_eq!(data.len(), 48);
        assert_eq!(f64::from_le_bytes(data[8..16].try_into().unwrap()), 2.0);
        assert!(f64::from_le_bytes(data[40..48].try_into().unwrap()).is_nan());
        let mut out = Vec::new();
        write_npy(&mut out, &[3], NpyData::I8(&[0, 3, -1])).unwrap();
        let len = u16::from_le_bytes([out[8], out[9]]) as usize;
        assert!(std::str::from_utf8(&out[10..10 + len])
            .unwrap()
            .contains("'descr': '|i1', 'fortran_order': False, 'shape': (3,)"));
        assert_eq!(&out[10 + len..], &[0, 3, 255]);
    }

    /// A missing folder is made (as `--plot figures/` is); a file in its place is refused.
    #[test]
    fn a_missing_folder_is_made_and_a_file_in_the_way_refused() {
        let dir = tempfile::tempdir().unwrap();
        let missing = dir.path().join("new/maps");
        write_npy_dir(&missing, &[("a.npy", vec![1], NpyData::I8(&[1]))]).unwrap();
        assert_eq!(std::fs::read(missing.join("a.npy")).unwrap().last(), Some(&1));
        let file = dir.path().join("plain");
        std::fs::write(&file, "x").unwrap();
        let err = write_npy_dir(&file, &[("a.npy", vec![1], NpyData::I8(&[1]))]).unwrap_err();
        assert!(format!("{err:#}").contains("--npy"), "{err:#}");
        assert_eq!(std::fs::read(&file).unwrap(), b"x");
    }
}
