//! PDS3 `.IMG` elevation models as HiRISE publishes its DTMs (issue 24): an ODL label
//! attached at the start of the `.IMG` or detached beside it (`.LBL`), one band of
//! `SAMPLE_TYPE`/`SAMPLE_BITS` samples (MSB/LSB integers, signed or unsigned, 8 to 32 bits;
//! IEEE or PC reals, 32 or 64 bits) with `OFFSET`/`SCALING_FACTOR`, `MISSING_CONSTANT` and the
//! ISIS special pixels as nodata, and the `IMAGE_MAP_PROJECTION` (equirectangular or polar
//! stereographic on the body's sphere `A_AXIS_RADIUS`, `MAP_SCALE` metres per pixel).
//!
//! Written from the PDS3 Standards Reference (chapter 5 pointers, chapter 12 ODL, appendix C
//! data types); the projection offsets are read as the standard defines them (and as GDAL's
//! PDS driver and ISIS read them): the centre of the pixel in 0-based column `c` and line `l`
//! is at `x = (c - SAMPLE_PROJECTION_OFFSET) MAP_SCALE`, `y = (LINE_PROJECTION_OFFSET - l)
//! MAP_SCALE`. Every size a label claims is checked against the file before anything is
//! allocated, and every error names the file, the key and its value.
//!
//! [`label`] parses the ODL label, [`image`] reads the IMAGE object, [`projection`] the
//! IMAGE_MAP_PROJECTION.

mod cylindrical;
mod image;
mod label;
mod projection;

use std::fs::File;
use std::io::Read;
use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Context, Result};

use crate::grid::{Raster, SizeCheck};
use label::{parse_label, Item, Label, Value};

/// The largest PDS3 label read, in bytes (a HiRISE DTM's is about 10 KB).
pub const MAX_LABEL_BYTES: u64 = 1 << 20;

/// Whether the file at `path` begins with a PDS3 label (`PDS_VERSION_ID`, or the SFDU line
/// `CCSD3ZF0000100000001NJPL3IF0PDS200000001 = SFDU_LABEL` older products put before it).
pub fn starts_with_label(path: &Path) -> bool {
    let mut head = [0u8; 32];
    File::open(path).and_then(|mut f| f.read(&mut head)).is_ok_and(|n| {
        let text = String::from_utf8_lossy(&head[..n]).trim_start().to_ascii_uppercase();
        text.starts_with("PDS_VERSION_ID") || text.starts_with("CCSD3ZF")
    })
}

/// Reads a PDS3 DTM (`path` the `.IMG` with its label attached or a `.LBL` beside it, or the
/// `.LBL`): heights in metres (NaN where missing or special), the map georeferencing in
/// projected metres, and the ground cell size in metres.
pub fn read_pds3(path: &Path) -> Result<Raster> {
    read_pds3_within(path, &|_, _| Ok(()))
}

/// [`read_pds3`], with `fits(cols, rows)` called once the label gives the size and before the
/// samples are read ([`crate::read_raster_within`]).
pub fn read_pds3_within(path: &Path, fits: SizeCheck) -> Result<Raster> {
    let Described { label, data_path, offset, layout, mut notes } = describe(path)?;
    fits(layout.cols as usize, layout.rows as usize)?;
    let values = image::read_samples(&layout, &label.name, &data_path, offset, &mut notes)?;
    let (geo, cells, crs) = projection::georef(&label, layout.rows, layout.cols, &mut notes)?;
    Ok(Raster {
        cols: layout.cols as usize,
        rows: layout.rows as usize,
        values,
        nodata: None,
        geo,
        crs,
        cell_m: cells.cell_m,
        row_widths_m: cells.row_widths_m,
        notes,
    })
}

/// A DTM opened for window reads (`raster::open_height_windows`): the raster [`read_pds3`]
/// gives without its samples (georeference, CRS, ground cells, notes), and the DTM.
pub(crate) fn open_windows(path: &Path) -> Result<(Raster, Pds3Dtm)> {
    let dtm = Pds3Dtm::open(path)?;
    let Described { label, layout, mut notes, .. } = describe(path)?;
    let (geo, cells, crs) = projection::georef(&label, layout.rows, layout.cols, &mut notes)?;
    let raster = Raster {
        cols: dtm.cols,
        rows: dtm.rows,
        values: Vec::new(),
        nodata: None,
        geo,
        crs,
        cell_m: cells.cell_m,
        row_widths_m: cells.row_widths_m,
        notes,
    };
    Ok((raster, dtm))
}

/// What a DTM's label says before any sample is read: the label, where the image's bytes are
/// (file and offset), its layout, and the notes so far.
struct Described {
    label: Label,
    data_path: PathBuf,
    offset: u64,
    layout: image::Layout,
    notes: Vec<String>,
}

/// Finds and parses the label of the DTM at `path`, and where and how its image is stored.
fn describe(path: &Path) -> Result<Described> {
    let (label_path, text, attached) = find_label(path)?;
    let label = parse_label(&label_path.display().to_string(), &text)?;
    let (data_path, offset) = image_location(&label, &label_path, attached)?;
    let mut notes = Vec::new();
    let layout = image::layout(&label, &mut notes)?;
    Ok(Described { label, data_path, offset, layout, notes })
}

/// A PDS3 DTM opened for reading windows of it: the size and ground cell size from its label,
/// the samples only when a window is read. The Dask raster reads a DTM larger than memory tile
/// by tile this way (`sandslope.dask.risk_raster` on a `.img` path); every window holds
/// exactly the heights [`read_pds3`] gives there.
#[derive(Debug, Clone)]
pub struct Pds3Dtm {
    name: String,
    data_path: PathBuf,
    offset: u64,
    layout: image::Layout,
    /// LINES.
    pub rows: usize,
    /// LINE_SAMPLES.
    pub cols: usize,
    /// Ground size of a cell, metres (east, north), as [`read_pds3`] gives it.
    pub cell_m: (f64, f64),
    /// East-west ground size of each row's cells (equirectangular), as [`read_pds3`] gives it.
    pub row_widths_m: Option<Vec<f64>>,
    /// What was assumed (the projection, a unit converted), as [`read_pds3`] notes it.
    pub notes: Vec<String>,
}

impl Pds3Dtm {
    /// Reads the label of the DTM at `path` (the `.IMG` with its label attached or a `.LBL`
    /// beside it, or the `.LBL`) and checks that the data file holds the image it describes.
    pub fn open(path: &Path) -> Result<Pds3Dtm> {
        let Described { label, data_path, offset, layout, mut notes } = describe(path)?;
        // The size checks of a read, on an empty window: nothing is allocated.
        image::read_window(
            &layout,
            &label.name,
            &data_path,
            offset,
            &image::Window { rows: 0..0, cols: 0..0 },
        )?;
        let (_, cells, _) = projection::georef(&label, layout.rows, layout.cols, &mut notes)?;
        Ok(Pds3Dtm {
            name: label.name.clone(),
            data_path,
            offset,
            rows: layout.rows as usize,
            cols: layout.cols as usize,
            layout,
            cell_m: cells.cell_m,
            row_widths_m: cells.row_widths_m,
            notes,
        })
    }

    /// Heights in metres of rows `rows` and columns `cols` (row-major, NaN where missing or
    /// special); only those samples' bytes are read. An error names the DTM when the window
    /// is not inside the image.
    pub fn read_window(
        &self,
        rows: std::ops::Range<usize>,
        cols: std::ops::Range<usize>,
    ) -> Result<Vec<f64>> {
        let window = image::Window {
            rows: rows.start as u64..rows.end as u64,
            cols: cols.start as u64..cols.end as u64,
        };
        let (values, _, _) =
            image::read_window(&self.layout, &self.name, &self.data_path, self.offset, &window)?;
        Ok(values)
    }
}

/// Where the image's bytes are: the file and the byte offset of its first line.
fn image_location(label: &Label, label_path: &Path, attached: bool) -> Result<(PathBuf, u64)> {
    let name = &label.name;
    let record_bytes = || -> Result<u64> {
        label
            .count("RECORD_BYTES", 1, 1 << 32, None)
            .context("a ^IMAGE pointer in records needs RECORD_BYTES")
    };
    // A pointer `n` (records, 1-based) or `n <BYTES>` (bytes, 1-based).
    let offset_of = |item: &Item, shown: &str| -> Result<u64> {
        let n =
            item.text.trim().parse::<u64>().ok().filter(|&n| n >= 1).ok_or_else(|| {
                anyhow!("{name}: ^IMAGE = {shown}: the pointer must be a whole number from 1")
            })?;
        match item.unit.as_deref().map(str::to_ascii_uppercase).as_deref() {
            Some("BYTES" | "BYTE") => Ok(n - 1),
            None => Ok((n - 1).saturating_mul(record_bytes()?)),
            Some(u) => bail!("{name}: ^IMAGE = {shown}: unknown pointer unit <{u}> (records, or <BYTES>)"),
        }
    };
    let dir = label_path.parent().unwrap_or(Path::new("."));
    let Some((value, _)) = label.get("^IMAGE") else {
        if !attached {
            bail!("{name}: the label has no ^IMAGE pointer to the image's file");
        }
        // No pointer: the image follows the label records.
        let records = label.count("LABEL_RECORDS", 1, 1 << 32, None).context("no ^IMAGE pointer")?;
        return Ok((label_path.to_path_buf(), records.saturating_mul(record_bytes()?)));
    };
    let shown = value.shown();
    match value {
        Value::One(item) if item.quoted => Ok((data_file(name, dir, &item.text, &shown)?, 0)),
        Value::One(item) => Ok((label_path.to_path_buf(), offset_of(item, &shown)?)),
        Value::List(items) => match items.as_slice() {
            [file, at] if file.quoted => {
                Ok((data_file(name, dir, &file.text, &shown)?, offset_of(at, &shown)?))
            }
            [file] if file.quoted => Ok((data_file(name, dir, &file.text, &shown)?, 0)),
            _ => bail!("{name}: ^IMAGE = {shown}: expected n, n <BYTES>, \"FILE\" or (\"FILE\", n)"),
        },
    }
}

/// The file a detached pointer names, beside the label (its name's case as given, lower or
/// upper: labels name `FILE.IMG` for a `file.img` often enough).
fn data_file(name: &str, dir: &Path, file: &str, shown: &str) -> Result<PathBuf> {
    if file.contains('/') || file.contains('\\') {
        bail!("{name}: ^IMAGE = {shown}: the file must lie beside the label (no folders)");
    }
    let ext = Path::new(file).extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    if matches!(ext.as_str(), "tif" | "tiff") {
        bail!("{name}: ^IMAGE = {shown} is a GeoTIFF: give sandslope the .tif itself");
    }
    if matches!(ext.as_str(), "jp2" | "jpg" | "png") {
        bail!("{name}: ^IMAGE = {shown}: a .{ext} image is not an elevation model sandslope reads");
    }
    for candidate in [file.to_owned(), file.to_ascii_lowercase(), file.to_ascii_uppercase()] {
        let p = dir.join(&candidate);
        if p.is_file() {
            return Ok(p);
        }
    }
    bail!("{name}: ^IMAGE = {shown}: no such file beside the label in {}", dir.display())
}

/// The label's file and text: the file itself when it begins with `PDS_VERSION_ID` (an
/// attached label, or a detached `.lbl`), else the `.lbl` beside it.
fn find_label(path: &Path) -> Result<(PathBuf, Vec<u8>, bool)> {
    let name = path.display();
    let label_path = if starts_with_label(path) {
        path.to_path_buf()
    } else if !path.is_file() {
        bail!("cannot read {name}: no such file");
    } else {
        let mut head = [0u8; 15];
        if File::open(path).and_then(|mut f| f.read_exact(&mut head)).is_ok() && &head == b"EHFA_HEADER_TAG" {
            bail!(
                "{name}: an ERDAS IMAGINE .img, not a PDS3 DTM; convert it to a GeoTIFF first (gdal_translate -of GTiff)"
            );
        }
        let found = ["lbl", "LBL"].iter().map(|e| path.with_extension(e)).find(|p| p.is_file() && p != path);
        found.ok_or_else(|| {
            anyhow!(
                "{name}: not a PDS3 file: it does not begin with a label (PDS_VERSION_ID) and there is no {} beside it",
                path.with_extension("lbl").file_name().map_or_else(String::new, |f| f.to_string_lossy().into_owned())
            )
        })?
    };
    let mut text = Vec::new();
    File::open(&label_path)
        .with_context(|| format!("cannot read {}", label_path.display()))?
        .take(MAX_LABEL_BYTES)
        .read_to_end(&mut text)
        .with_context(|| format!("cannot read {}", label_path.display()))?;
    let attached = label_path == path && !path.extension().is_some_and(|e| e.eq_ignore_ascii_case("lbl"));
    Ok((label_path, text, attached))
}

#[cfg(test)]
mod tests {
    //! The DTMs of `tests/fixtures/pds3/make_pds3.py`, written byte by byte from the PDS3
    //! standard and read back by GDAL 3.10.3's PDS driver with the transforms and heights
    //! below. Expected values come from the script's formulas, worked here by hand.
    use super::label::*;
    use super::*;
    use crate::crs::Crs;

    fn fixture_path(name: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../sandslope-io/tests/fixtures/pds3").join(name)
    }

    fn fixture(name: &str) -> Raster {
        crate::read_raster(&fixture_path(name)).unwrap_or_else(|e| panic!("{name}: {e:#}"))
    }

    /// The script's hill: `height exp(-(((c - cx) / sx)^2 + ((r - cy) / sy)^2))`.
    fn hill(c: f64, r: f64, height: f64, cx: f64, cy: f64, sx: f64, sy: f64) -> f64 {
        height * (-(((c - cx) / sx).powi(2) + ((r - cy) / sy).powi(2))).exp()
    }

    /// HiRISE layout: attached label, record pointer, PC_REAL, ISIS NULL as MISSING_CONSTANT and
    /// the four other special pixels. Corner: SAMPLE_PROJECTION_OFFSET 4399.5 and
    /// LINE_PROJECTION_OFFSET 59299.5 at 20 m give x = -(4399.5 + 0.5) 20 = -88 000 m and
    /// y = (59299.5 + 0.5) 20 = 1 186 000 m (GDAL: the same). Ground cell: rows at y = R lat,
    /// latitudes 59 252 x 20 / 3 396 190 rad = 19.99234 deg to 59 300 x 20 / R = 20.00854 deg,
    /// mid 20.00044 deg; east-west 20 cos(20.00044) / cos(15) = 20 x 0.939687 / 0.965926 =
    /// 19.4568 m; north-south 20 m.
    #[test]
    fn a_hirise_layout_dtm_reads_with_heights_nodata_and_ground_cells() {
        let r = fixture("dtm-attached.img");
        assert_eq!((r.cols, r.rows), (60, 48));
        assert_eq!(
            (r.geo.west, r.geo.north, r.geo.cell_x, r.geo.cell_y),
            (-88_000.0, 1_186_000.0, 20.0, 20.0)
        );
        let special = [(0, 0), (59, 0), (0, 47), (59, 47), (10, 20)];
        for row in 0..48 {
            for col in 0..60 {
                let i = row * 60 + col;
                if special.contains(&(col, row)) {
                    assert!(r.is_nodata(i), "({col}, {row}) is a special pixel");
                } else {
                    let want = f64::from(
                        (-2500.0 + hill(col as f64, row as f64, 12.0, 30.0, 24.0, 14.0, 11.0)) as f32,
                    );
                    assert_eq!(r.values[i], want, "({col}, {row})");
                }
            }
        }
        assert!((r.cell_m.0 - 19.4568).abs() < 1e-3 && r.cell_m.1 == 20.0, "{:?}", r.cell_m);
        // Each row its own width: row 0's centre at y = 59 299.5 x 20 = 1 185 990 m, latitude
        // 1 185 990 / 3 396 190 rad = 20.00837 deg, 20 cos(20.00837) / cos(15) = 19.45579 m;
        // row 47's at 1 185 050 m, 19.99251 deg, 19.45775 m.
        let w = r.row_widths_m.as_ref().unwrap();
        assert!(w.len() == 48 && (w[0] - 19.45579).abs() < 1e-5 && (w[47] - 19.45775).abs() < 1e-5, "{w:?}");
        assert_eq!(r.crs, Crs::Projected { metres_per_unit: 1.0, unit: "metre" });
        let notes = r.notes.join("\n");
        assert!(notes.contains("equirectangular map on Mars (sphere of radius 3396190 m)"), "{notes}");
        assert!(
            notes.contains("5 cells without a height (MISSING_CONSTANT: 1, other ISIS special pixels: 4)"),
            "{notes}"
        );
    }

    /// Detached label, MSB_INTEGER with OFFSET and SCALING_FACTOR, polar stereographic about the
    /// south pole; the .lbl and the .img name the same DTM. Corner x = -(99.5 + 0.5) 5 = -500 m,
    /// y = (59 999.5 + 0.5) 5 = 300 000 m. Ground cell at the centre (x, y) = (-400, 299 925) m:
    /// the sphere's polar stereographic scale factor is k = 1 + rho^2 / (4 R^2) = 1 +
    /// 8.99550e10 / 4.61363e13 = 1.0019498, so 5 / k = 4.99027 m.
    #[test]
    fn a_detached_label_integer_polar_stereographic_dtm_reads_by_either_file() {
        for name in ["dtm-detached.lbl", "dtm-detached.img"] {
            let r = fixture(name);
            assert_eq!((r.cols, r.rows), (40, 30), "{name}");
            assert_eq!((r.geo.west, r.geo.north, r.geo.cell_x), (-500.0, 300_000.0, 5.0), "{name}");
            for row in 0..30 {
                for col in 0..40 {
                    let i = row * 40 + col;
                    if (col, row) == (0, 0) || (col, row) == (39, 29) {
                        assert!(r.is_nodata(i), "{name} ({col}, {row})");
                    } else {
                        let dn = ((hill(col as f64, row as f64, 30.0, 20.0, 15.0, 9.0, 7.0) + 500.0) * 4.0)
                            .round();
                        assert_eq!(r.values[i], -4000.0 + 0.25 * dn, "{name} ({col}, {row})");
                    }
                }
            }
            let rho2 = 400.0f64.powi(2) + 299_925.0f64.powi(2);
            let k = 1.0 + rho2 / (4.0 * 3_396_190.0f64.powi(2));
            assert!((r.cell_m.0 - 5.0 / k).abs() < 1e-9 && r.cell_m.0 == r.cell_m.1, "{:?}", r.cell_m);
            assert!((r.cell_m.0 - 4.99027).abs() < 1e-5);
            assert!(r.notes.iter().any(|n| n.contains("south pole of Mars")), "{:?}", r.notes);
        }
    }

    /// Byte pointer, IEEE_REAL 64-bit, and MAP_SCALE and A_AXIS_RADIUS without units (the
    /// standard's km): 0.01 km = 10 m cells; corner x = -(-199.5 + 0.5) 10 = 1990 m,
    /// y = (100.5 + 0.5) 10 = 1010 m. At latitude 0.03 deg on the Moon the cells are square.
    #[test]
    fn ieee_doubles_by_byte_pointer_with_the_standards_km_units() {
        let r = fixture("moon-bytes.img");
        assert_eq!((r.cols, r.rows), (20, 16));
        assert_eq!((r.geo.west, r.geo.north, r.geo.cell_x), (1990.0, 1010.0, 10.0));
        for (i, v) in r.values.iter().enumerate() {
            let (c, w) = ((i % 20) as f64, (i / 20) as f64);
            assert_eq!(*v, 1000.0 + 0.5 * c - 0.25 * w + 1.0 / 3.0, "cell {i}");
        }
        // Mid-latitude (1010 + 850) / 2 / 1 737 400 rad: 10 cos(that) = 10 (1 - 1.43e-7) m.
        assert!((r.cell_m.0 - 9.999_998_57).abs() < 1e-8 && r.cell_m.1 == 10.0, "{:?}", r.cell_m);
        let notes = r.notes.join("\n");
        assert!(
            notes.contains("MAP_SCALE = 0.01 has no unit")
                && notes.contains("on Moon (sphere of radius 1737400 m)"),
            "{notes}"
        );
    }

    /// Line prefix and suffix bytes are skipped; LSB_INTEGER 16-bit with MISSING_CONSTANT 7 and
    /// the ISIS LRS -32767, and 8-bit unsigned samples, decode to the values written.
    #[test]
    fn line_prefixes_and_suffixes_are_skipped_and_integers_decode() {
        let label = |t: &str, bits: u32| {
            format!(
                "PDS_VERSION_ID = PDS3\r\nRECORD_TYPE = UNDEFINED\r\n^IMAGE = 1025 <BYTES>\r\nOBJECT = IMAGE\r\n\
                 LINES = 2\r\nLINE_SAMPLES = 3\r\nSAMPLE_TYPE = {t}\r\nSAMPLE_BITS = {bits}\r\n\
                 LINE_PREFIX_BYTES = 4\r\nLINE_SUFFIX_BYTES = 2\r\nMISSING_CONSTANT = 7\r\nEND_OBJECT = IMAGE\r\n\
                 OBJECT = IMAGE_MAP_PROJECTION\r\nMAP_PROJECTION_TYPE = EQUIRECTANGULAR\r\nA_AXIS_RADIUS = 3396.19\r\n\
                 CENTER_LATITUDE = 0\r\nMAP_SCALE = 2 <METERS/PIXEL>\r\nLINE_PROJECTION_OFFSET = 0.5\r\n\
                 SAMPLE_PROJECTION_OFFSET = -0.5\r\nEND_OBJECT = IMAGE_MAP_PROJECTION\r\nEND\r\n"
            )
        };
        let dir = tempfile::tempdir().unwrap();
        let write = |name: &str, label: String, lines: [&[u8]; 2]| {
            let mut bytes = label.into_bytes();
            assert!(bytes.len() <= 1024, "the label fits before byte 1025");
            bytes.resize(1024, b' ');
            for l in lines {
                bytes.extend_from_slice(&[0xEE; 4]);
                bytes.extend_from_slice(l);
                bytes.extend_from_slice(&[0xDD; 2]);
            }
            let path = dir.path().join(name);
            std::fs::write(&path, bytes).unwrap();
            crate::read_raster(&path).unwrap()
        };
        // -2, 300, 7 (missing) / -32767 (LRS), 0, 1000 as little-endian 16-bit.
        let r = write(
            "i16.img",
            label("LSB_INTEGER", 16),
            [&[0xFE, 0xFF, 0x2C, 0x01, 0x07, 0x00], &[0x01, 0x80, 0x00, 0x00, 0xE8, 0x03]],
        );
        let v: Vec<String> = r.values.iter().map(|v| format!("{v}")).collect();
        assert_eq!(v, ["-2", "300", "NaN", "NaN", "0", "1000"]);
        // Corner x = -(-0.5 + 0.5) 2 = 0, y = (0.5 + 0.5) 2 = 2.
        assert_eq!((r.geo.west, r.geo.north), (0.0, 2.0));
        // Behind an SFDU line, under a name that is not .img: found by its first bytes.
        let sfdu = format!(
            "CCSD3ZF0000100000001NJPL3IF0PDS200000001 = SFDU_LABEL\r\n{}",
            label("MSB_UNSIGNED_INTEGER", 8)
        );
        let r = write("u8.dat", sfdu, [&[0, 255, 7], &[1, 2, 3]]);
        let v: Vec<String> = r.values.iter().map(|v| format!("{v}")).collect();
        assert_eq!(v, ["0", "255", "NaN", "1", "2", "3"]);
    }

    /// A copy of the attached fixture with `from` replaced by `to` in its label, read.
    fn edited(from: &str, to: &str) -> String {
        let mut bytes = std::fs::read(fixture_path("dtm-attached.img")).unwrap();
        let at = bytes.windows(from.len()).position(|w| w == from.as_bytes()).expect(from);
        bytes.splice(at..at + from.len(), to.bytes());
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("edited.img");
        std::fs::write(&path, &bytes).unwrap();
        let started = std::time::Instant::now();
        let err = crate::read_raster(&path).expect_err("must be refused");
        assert!(started.elapsed().as_secs() < 5);
        let err = format!("{err:#}");
        assert!(err.contains("edited.img"), "{err}");
        err
    }

    #[test]
    fn a_label_lying_about_its_size_is_refused_naming_the_key_before_allocating() {
        let err = edited("LINES = 48\r", "LINES = 4800\r");
        // By hand: 7 label records of 240 bytes, then 4800 x 240: 1680 + 1 152 000 bytes.
        assert!(
            err.contains("LINES = 4800 lines of 240 bytes")
                && err.contains("from byte 1680 need 1153680 bytes"),
            "{err}"
        );
        let err = edited("LINES = 48\r", "LINES = 2000000000\r");
        assert!(err.contains("LINES = 2000000000 lines of 240 bytes"), "{err}");
        let err = edited("LINE_SAMPLES = 60", "LINE_SAMPLES = 60.5");
        assert!(err.contains("IMAGE.LINE_SAMPLES = 60.5 must be a whole number"), "{err}");
    }

    #[test]
    fn unsupported_layouts_are_refused_naming_the_key_and_value() {
        let err = edited("SAMPLE_TYPE = PC_REAL", "SAMPLE_TYPE = VAX_REAL");
        assert!(err.contains("SAMPLE_TYPE = VAX_REAL is not supported"), "{err}");
        let err = edited("SAMPLE_BITS = 32", "SAMPLE_BITS = 16");
        assert!(err.contains("SAMPLE_BITS = 16 with SAMPLE_TYPE = PC_REAL"), "{err}");
        let err = edited("MAP_PROJECTION_ROTATION = 0.0", "MAP_PROJECTION_ROTATION = 9.0");
        assert!(err.contains("MAP_PROJECTION_ROTATION = 9"), "{err}");
        let err = edited("\"EQUIRECTANGULAR\"", "\"MERCATOR\"       ");
        assert!(err.contains("MAP_PROJECTION_TYPE = MERCATOR is not supported"), "{err}");
        let err = edited("MAP_SCALE = 20.0", "MAP_SKALE = 20.0");
        assert!(err.contains("no IMAGE_MAP_PROJECTION.MAP_SCALE"), "{err}");
        let err = edited("BANDS = 1", "BANDS = 3");
        assert!(err.contains("IMAGE.BANDS = 3"), "{err}");
        // Without END the label runs into the samples.
        let err = edited("\r\nEND\r\n", "\r\nXND\r\n");
        assert!(err.contains("line 49: keyword `XND` is not followed by `=`"), "{err}");
        let err = edited("^IMAGE = 8", "^IMAGE = 0");
        assert!(err.contains("^IMAGE = 0"), "{err}");
        // Another format's .img: ERDAS IMAGINE begins with its own header tag.
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("erdas.img");
        std::fs::write(&path, b"EHFA_HEADER_TAG\0\0\0\0").unwrap();
        let err = format!("{:#}", crate::read_raster(&path).unwrap_err());
        assert!(err.contains("erdas.img: an ERDAS IMAGINE .img, not a PDS3 DTM"), "{err}");
    }

    #[test]
    fn odl_values_parse_as_the_standard_writes_them() {
        let text =
            b"PDS_VERSION_ID = PDS3\r\n/* a comment */ A = 16#FF7FFFFB#\nB = (\"x.img\",\n 3 <BYTES>)\n\
            W = (450, 550) <NM>\nOBJECT = IMAGE\n C = \"two\n lines\" D = -1.5E+02 <M>\nEND_OBJECT\nEND\n";
        let l = parse_label("t.lbl", text).unwrap();
        assert_eq!(parse_based("16#FF7FFFFB#"), Some(0xFF7F_FFFB));
        assert_eq!(parse_based("2#101#"), Some(5));
        assert!(
            matches!(l.get("B"), Some((Value::List(v), 3)) if v.len() == 2 && v[1].unit.as_deref() == Some("BYTES"))
        );
        assert_eq!(l.word("IMAGE.C").unwrap().0, "TWO LINES");
        assert!(matches!(l.get("W"), Some((Value::List(v), 5)) if v[1].unit.as_deref() == Some("NM")));
        assert_eq!(l.number("IMAGE.D").unwrap(), Some((-150.0, Some("M".into()))));
        assert!(parse_label("t.lbl", b"A = (((((((((((((((((((((1)))))))))))))))))))))\nEND").is_err());
    }

    /// Every window of each fixture (edges, one cell, whole lines, the empty window) holds the
    /// same heights as the whole read there, NaN where it has NaN; a window outside the image
    /// is an error naming LINES x LINE_SAMPLES, and opening reads no sample.
    #[test]
    fn windows_are_the_whole_reads_heights() {
        for name in ["dtm-attached.img", "dtm-detached.lbl", "dtm-detached.img", "moon-bytes.img"] {
            let whole = fixture(name);
            let dtm = Pds3Dtm::open(&fixture_path(name)).unwrap_or_else(|e| panic!("{name}: {e:#}"));
            assert_eq!((dtm.rows, dtm.cols), (whole.rows, whole.cols), "{name}");
            assert_eq!((&dtm.cell_m, &dtm.row_widths_m), (&whole.cell_m, &whole.row_widths_m), "{name}");
            assert_eq!(dtm.notes.iter().filter(|n| !n.contains("without a height")).count(), dtm.notes.len());
            let (r, c) = (whole.rows, whole.cols);
            for (rows, cols) in [
                (0..r, 0..c),
                (0..1, 0..1),
                (r - 1..r, c - 1..c),
                (1..r / 2, c / 3..c),
                (r / 2..r, 0..c / 2 + 1),
                (3..3, 0..c),
            ] {
                let got = dtm.read_window(rows.clone(), cols.clone()).unwrap();
                assert_eq!(got.len(), rows.len() * cols.len(), "{name} {rows:?} {cols:?}");
                for (k, g) in got.iter().enumerate() {
                    let (i, j) = (rows.start + k / cols.len(), cols.start + k % cols.len());
                    let want = whole.values[i * c + j];
                    assert!(
                        g.to_bits() == want.to_bits() || (g.is_nan() && want.is_nan()),
                        "{name} ({i}, {j}): {g} vs {want}"
                    );
                }
            }
            let err = format!("{:#}", dtm.read_window(0..r + 1, 0..c).unwrap_err());
            assert!(err.contains(&format!("the {r} x {c} image (LINES x LINE_SAMPLES)")), "{err}");
        }
    }
}

#[cfg(test)]
mod mutated {
    //! Mutated labels and truncated files are refused or read, never a panic or an abort.
    use super::*;

    #[test]
    fn mutated_and_truncated_pds3_files_never_panic() {
        let dir = tempfile::tempdir().unwrap();
        let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("../sandslope-io/tests/fixtures/pds3");
        std::fs::copy(fixtures.join("dtm-detached.img"), dir.path().join("dtm-detached.img")).unwrap();
        let mut seed = 0x2545_F491_4F6C_DD1Du64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        let tokens: [&[u8]; 8] = [b"=", b"(", b"\"", b"<", b"#", b"-", b"9999999999", b"END"];
        for (file, label_len) in
            [("dtm-attached.img", 1680usize), ("dtm-detached.lbl", 682), ("moon-bytes.img", 2048)]
        {
            let original = std::fs::read(fixtures.join(file)).unwrap();
            let path = dir.path().join(file);
            for _ in 0..300 {
                let mut bytes = original.clone();
                match next() % 3 {
                    0 => bytes.truncate((next() % original.len() as u64) as usize),
                    1 => {
                        for _ in 0..1 + next() % 4 {
                            let at = (next() % label_len as u64) as usize;
                            bytes[at] = next() as u8;
                        }
                    }
                    _ => {
                        let at = (next() % label_len as u64) as usize;
                        let t = tokens[(next() % tokens.len() as u64) as usize];
                        bytes.splice(at..at, t.iter().copied());
                    }
                }
                std::fs::write(&path, &bytes).unwrap();
                if let Ok(r) = crate::read_raster(&path) {
                    assert_eq!(r.values.len(), r.cols * r.rows);
                }
            }
        }
    }
}

#[cfg(test)]
mod megdr_tests;

#[cfg(test)]
mod archive_tests;
