//! Synthetic load-cell recordings with known k_n and k_s: the generator of the tests and of
//! the shipped example dataset `examples/measurements/` (regenerate it with
//! `cargo test -p sandslope-cli --test fit -- --ignored regenerate_example_dataset`).
//!
//! The physics is docs/model.md §10 with the paper's protocol (disk radius 1 cm, plate 3 cm
//! wide inserted 2 cm, 5 cm/s), plus what real recordings have:
//! - penetration: the disk starts 2 mm above the surface (force = in-air offset), a 3 mm soft
//!   surface layer where the stiffness ramps up, the linear part `k_n A`, the bed bottom at
//!   37 mm where the bed is 20 times stiffer, and a load cell that clips at 10 N;
//! - shear: a rise `F_p (1 - exp(-x / 3 mm))` to the plateau `F_p = k_s W_p d_p^2`, slowly
//!   varying granular fluctuations (AR(1), 2% of F_p, correlation 0.9 per sample) and white
//!   sensor noise; optionally an impact spike that clips the sensor (full scale 49 N);
//! - in-air offsets that depend on slope (weight of disk or plate and rod along the load axis)
//!   plus a tare error and a small drift with position; in-air runs record the same;
//! - blank cells, NaNs, repeated rows, swapped rows, different sampling rates, units (m, cm,
//!   mm) and raw counts.
//!
//! Noise comes from SplitMix64 + Box-Muller, written here so that the example files are
//! byte-for-byte reproducible whatever version of a random-number crate is in the lock file.

#![allow(dead_code)]

use std::fmt::Write as _;

/// Actuator speed, m/s (paper: 5 cm/s).
pub const SPEED: f64 = 0.05;
/// Disk radius, m (paper: 1 cm).
pub const DISK_RADIUS: f64 = 0.01;
/// Plate width and insertion depth, m (paper: 3 cm, 2 cm).
pub const PLATE_WIDTH: f64 = 0.03;
/// Plate insertion depth, m.
pub const PLATE_DEPTH: f64 = 0.02;
/// Counts per newton of the example load cell (for `force_counts` files).
pub const COUNTS_PER_NEWTON: f64 = 2000.0;
/// Penetration load cell full scale, N.
pub const PEN_CAP: f64 = 10.0;
/// Shear load cell full scale, N.
pub const SHEAR_CAP: f64 = 49.0;

/// Deterministic pseudo-random numbers.
pub struct Noise(u64);

impl Noise {
    /// A stream from a seed.
    pub fn new(seed: u64) -> Noise {
        Noise(seed.wrapping_mul(0x2545_F491_4F6C_DD1D) ^ 0x5DEE_CE66_D1CE_4E5B)
    }
    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Standard normal.
    pub fn normal(&mut self) -> f64 {
        let u = self.uniform().max(1e-300);
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * self.uniform()).cos()
    }
    /// Integer in [0, n).
    pub fn below(&mut self, n: usize) -> usize {
        ((self.uniform() * n as f64) as usize).min(n - 1)
    }
}

/// Length unit of the position column.
#[derive(Debug, Clone, Copy)]
pub enum Unit {
    M,
    Cm,
    Mm,
}

impl Unit {
    fn suffix(self) -> &'static str {
        match self {
            Unit::M => "m",
            Unit::Cm => "cm",
            Unit::Mm => "mm",
        }
    }
    fn per_metre(self) -> f64 {
        match self {
            Unit::M => 1.0,
            Unit::Cm => 100.0,
            Unit::Mm => 1000.0,
        }
    }
    fn decimals(self) -> usize {
        match self {
            Unit::M => 6,
            Unit::Cm => 4,
            Unit::Mm => 3,
        }
    }
}

/// Defects to inject into a recording (each in distinct rows, before any clipping).
#[derive(Debug, Clone, Copy, Default)]
pub struct Defects {
    /// Rows with one blank cell.
    pub blank: usize,
    /// Rows whose force is `NaN`.
    pub nan: usize,
    /// Rows written twice.
    pub duplicate: usize,
    /// Pairs of adjacent rows swapped.
    pub swapped: usize,
}

/// How one trial file is written.
#[derive(Debug, Clone, Copy)]
pub struct Format {
    /// Position unit.
    pub unit: Unit,
    /// Sampling rate, Hz.
    pub rate_hz: f64,
    /// Write a `time_s` column.
    pub time: bool,
    /// Write `force_counts` instead of `force_n`.
    pub counts: bool,
    /// Defects.
    pub defects: Defects,
}

impl Default for Format {
    fn default() -> Format {
        Format { unit: Unit::Mm, rate_hz: 80.0, time: false, counts: false, defects: Defects::default() }
    }
}

/// In-air force of the disk rig at a slope, N (weight along the normal plus a tare error).
pub fn penetration_air_offset(slope_deg: f64) -> f64 {
    0.35 * slope_deg.to_radians().cos() + 0.08
}

/// In-air force of the plate rig at a slope, N (weight along the slope plus a tare error).
pub fn shear_air_offset(slope_deg: f64) -> f64 {
    0.35 * slope_deg.to_radians().sin() + 0.12
}

/// In-air drift with position, N/m (cable drag), the same in air and in sand.
pub const AIR_DRIFT: f64 = 0.4;

/// What a generated file contains, for checking the fit.
#[derive(Debug, Clone, Copy, Default)]
pub struct Truth {
    /// True k of this trial (k_n or k_s), N/m^3; 0 for air runs.
    pub k: f64,
    /// Samples clipped at full scale.
    pub saturated: usize,
    /// Injected defects.
    pub defects: Defects,
    /// Data rows written.
    pub rows: usize,
}

/// Forces (N) against positions (m) to CSV text with the format's defects.
fn to_csv(
    position_name: &str,
    xs: &[f64],
    fs: &[f64],
    first: usize,
    clip_from: usize,
    fmt: Format,
    noise: &mut Noise,
) -> (String, usize) {
    let n = xs.len();
    // Rows: (time, position text, force text)
    let mut rows: Vec<[String; 3]> = (0..n)
        .map(|i| {
            // By sample index (equal to position / speed on a downstroke; still increasing on
            // the way back up).
            let t = 0.25 + (i as f64 * (SPEED / fmt.rate_hz)) / SPEED;
            let force = if fmt.counts {
                format!("{}", (fs[i] * COUNTS_PER_NEWTON).round() as i64)
            } else {
                format!("{:.4}", fs[i])
            };
            [format!("{t:.4}"), format!("{:.*}", fmt.unit.decimals(), xs[i] * fmt.unit.per_metre()), force]
        })
        .collect();
    // Distinct defect rows among first .. min(clip_from, n) - 2, three rows apart at least.
    let limit = clip_from.min(n).saturating_sub(2);
    let d = fmt.defects;
    let wanted = d.blank + d.nan + d.duplicate + d.swapped;
    let mut picked: Vec<usize> = Vec::new();
    while picked.len() < wanted {
        let r = first + noise.below(limit - first);
        if picked.iter().all(|&p| p.abs_diff(r) > 2) {
            picked.push(r);
        }
    }
    let mut it = picked.into_iter();
    for _ in 0..d.blank {
        let r = it.next().unwrap_or(0);
        let col = 1 + noise.below(2);
        rows[r][col] = String::new();
    }
    for _ in 0..d.nan {
        let r = it.next().unwrap_or(0);
        rows[r][2] = "NaN".into();
    }
    let dups: Vec<usize> = (0..d.duplicate).map(|_| it.next().unwrap_or(0)).collect();
    let swaps: Vec<usize> = (0..d.swapped).map(|_| it.next().unwrap_or(0)).collect();
    for &r in &swaps {
        rows.swap(r, r + 1);
    }
    let mut out_rows: Vec<&[String; 3]> = Vec::with_capacity(n + dups.len());
    for (i, row) in rows.iter().enumerate() {
        out_rows.push(row);
        if dups.contains(&i) {
            out_rows.push(row);
        }
    }
    let force_col = if fmt.counts { "force_counts" } else { "force_n" };
    let unit = fmt.unit.suffix();
    let mut s = String::new();
    if fmt.time {
        let _ = writeln!(s, "time_s,{position_name}_{unit},{force_col}");
    } else {
        let _ = writeln!(s, "{position_name}_{unit},{force_col}");
    }
    for r in &out_rows {
        if fmt.time {
            let _ = writeln!(s, "{},{},{}", r[0], r[1], r[2]);
        } else {
            let _ = writeln!(s, "{},{}", r[1], r[2]);
        }
    }
    (s, out_rows.len())
}

/// Positions every `SPEED / rate` from 0 to `travel`.
fn positions(travel: f64, rate_hz: f64) -> Vec<f64> {
    let step = SPEED / rate_hz;
    let n = (travel / step).floor() as usize;
    (0..=n).map(|i| i as f64 * step).collect()
}

/// A penetration recording of true `k_n` at `slope_deg` (or an in-air run when `k_n` is 0).
pub fn penetration(k_n: f64, slope_deg: f64, fmt: Format, seed: u64) -> (String, Truth) {
    let mut noise = Noise::new(seed);
    let area = std::f64::consts::PI * DISK_RADIUS * DISK_RADIUS;
    let b = k_n * area;
    let (contact, soft, bottom, sigma) = (0.002, 0.003, 0.037, 0.02);
    let xs = positions(0.045, fmt.rate_hz);
    let mut clip_from = xs.len();
    let mut saturated = 0;
    let fs: Vec<f64> = xs
        .iter()
        .enumerate()
        .map(|(i, &d)| {
            let e = (d - contact).max(0.0);
            let mut f = if e < soft { b * e * e / (2.0 * soft) } else { b * (e - soft / 2.0) };
            if d > bottom {
                f += 20.0 * b * (d - bottom);
            }
            let f = penetration_air_offset(slope_deg) + AIR_DRIFT * d + f + sigma * noise.normal();
            if f >= PEN_CAP {
                clip_from = clip_from.min(i);
                saturated += 1;
                PEN_CAP
            } else {
                f
            }
        })
        .collect();
    let (csv, rows) = to_csv("depth", &xs, &fs, 2, clip_from, fmt, &mut noise);
    (csv, Truth { k: k_n, saturated, defects: fmt.defects, rows })
}

/// A shear recording of true `k_s` at `slope_deg` (an in-air run when `k_s` is 0); `spike`
/// adds an impact that clips the sensor for three samples early in the drag.
pub fn shear(k_s: f64, slope_deg: f64, fmt: Format, spike: bool, seed: u64) -> (String, Truth) {
    let mut noise = Noise::new(seed);
    let fp = k_s * PLATE_WIDTH * PLATE_DEPTH * PLATE_DEPTH;
    let (x0, sigma) = (0.003, 0.03);
    let xs = positions(0.10, fmt.rate_hz);
    let (rho, amp) = (0.9f64, 0.02 * fp);
    let mut ar = 0.0;
    let mut saturated = 0;
    let fs: Vec<f64> = xs
        .iter()
        .enumerate()
        .map(|(i, &x)| {
            ar = rho * ar + (1.0 - rho * rho).sqrt() * amp * noise.normal();
            let rise = 1.0 - (-x / x0).exp();
            let f =
                shear_air_offset(slope_deg) + AIR_DRIFT * x + fp * rise + rise * ar + sigma * noise.normal();
            if spike && (4..7).contains(&i) {
                saturated += 1;
                SHEAR_CAP
            } else {
                f
            }
        })
        .collect();
    // Defects go after the spike (rows 4-6).
    let (csv, rows) = to_csv("displacement", &xs, &fs, 9, xs.len(), fmt, &mut noise);
    (csv, Truth { k: k_s, saturated, defects: fmt.defects, rows })
}

/// True k_n at a slope of the example terrain, N/m^3: nearly constant (the paper's finding).
pub fn example_k_n(slope_deg: f64) -> f64 {
    7.0e5 * (1.0 - 0.002 * slope_deg)
}

/// True k_s at a slope of the example terrain, N/m^3: at 20 deg 40% of level (the paper).
pub fn example_k_s(slope_deg: f64) -> f64 {
    2.0e6 * (1.0 - 0.03 * slope_deg)
}

/// One generated trial.
#[derive(Debug, Clone)]
pub struct GeneratedTrial {
    /// File name.
    pub file: String,
    /// `penetration` or `shear`.
    pub kind: &'static str,
    /// Slope, degrees.
    pub slope_deg: f64,
    /// In-air run.
    pub air: bool,
    /// The CSV text.
    pub csv: String,
    /// What it contains.
    pub truth: Truth,
}

/// A dataset: trials and the manifest text.
#[derive(Debug, Clone)]
pub struct Dataset {
    /// Trials in manifest order.
    pub trials: Vec<GeneratedTrial>,
    /// Comment lines at the top of the manifest (`None`: the example dataset's).
    pub header: Option<String>,
}

impl Dataset {
    /// The manifest TOML.
    pub fn manifest(&self) -> String {
        let header = self.header.clone().unwrap_or_else(|| {
            "# Example load-cell measurements (synthetic; generated by crates/sandslope-cli/tests/it/fit/synth.rs).\n\
             # True values: k_n = 7.0e5 (1 - 0.002 slope_deg), k_s = 2.0e6 (1 - 0.03 slope_deg) N/m^3,\n\
             # each trial drawn with 5% trial-to-trial scatter. No shear trials at 15 deg (interpolated).\n"
                .to_string()
        });
        let mut s = header
            + "name = \"example-glass-beads\"\nrepose_deg = 25.0\n\n[penetration]\ndisk_radius_m = 0.01\n\n[shear]\n\
             plate_width_m = 0.03\nplate_depth_m = 0.02\n";
        for t in &self.trials {
            let _ = write!(
                s,
                "\n[[trial]]\nkind = \"{}\"\nslope_deg = {:?}\nfile = \"{}\"\nair = {}\n",
                t.kind, t.slope_deg, t.file, t.air
            );
        }
        s
    }

    /// Writes the manifest (as `manifest.toml`) and every trial into `dir`.
    pub fn write(&self, dir: &std::path::Path) -> std::io::Result<()> {
        std::fs::create_dir_all(dir)?;
        std::fs::write(dir.join("manifest.toml"), self.manifest())?;
        for t in &self.trials {
            std::fs::write(dir.join(&t.file), &t.csv)?;
        }
        Ok(())
    }
}

/// The example dataset: slopes 0, 5, 10, 15, 20, 24 deg; three penetration and three shear
/// trials per slope (no shear at 15 deg) and one in-air run per kind and slope; a mix of
/// units, rates, counts and defects.
pub fn example_dataset() -> Dataset {
    let mut trials = Vec::new();
    let mut seed = 1000u64;
    let mut scatter = Noise::new(7);
    for (si, &slope) in [0.0, 5.0, 10.0, 15.0, 20.0, 24.0].iter().enumerate() {
        let tag = slope as u32;
        // In-air runs.
        seed += 1;
        let fmt = Format { rate_hz: 80.0, ..Format::default() };
        let (csv, truth) = penetration(0.0, slope, fmt, seed);
        trials.push(GeneratedTrial {
            file: format!("pen-{tag:02}-air.csv"),
            kind: "penetration",
            slope_deg: slope,
            air: true,
            csv,
            truth,
        });
        seed += 1;
        let (csv, truth) = shear(0.0, slope, fmt, false, seed);
        trials.push(GeneratedTrial {
            file: format!("shear-{tag:02}-air.csv"),
            kind: "shear",
            slope_deg: slope,
            air: true,
            csv,
            truth,
        });
        for rep in 1..=3usize {
            let k_n = example_k_n(slope) * (1.0 + 0.05 * scatter.normal());
            let k_s = example_k_s(slope) * (1.0 + 0.05 * scatter.normal());
            let variant = (si + rep) % 4;
            let fmt = match variant {
                0 => Format { unit: Unit::Mm, rate_hz: 80.0, ..Format::default() },
                1 => Format {
                    unit: Unit::M,
                    rate_hz: 40.0,
                    time: true,
                    defects: Defects { blank: 1, nan: 1, duplicate: 2, swapped: 1 },
                    ..Format::default()
                },
                2 => Format { unit: Unit::Cm, rate_hz: 200.0, counts: true, ..Format::default() },
                _ => Format {
                    unit: Unit::Mm,
                    rate_hz: 80.0,
                    time: true,
                    counts: true,
                    defects: Defects { blank: 2, nan: 0, duplicate: 1, swapped: 2 },
                },
            };
            seed += 1;
            let (csv, truth) = penetration(k_n, slope, fmt, seed);
            trials.push(GeneratedTrial {
                file: format!("pen-{tag:02}-{rep}.csv"),
                kind: "penetration",
                slope_deg: slope,
                air: false,
                csv,
                truth,
            });
            if slope != 15.0 {
                seed += 1;
                let (csv, truth) = shear(k_s, slope, fmt, variant == 3, seed);
                trials.push(GeneratedTrial {
                    file: format!("shear-{tag:02}-{rep}.csv"),
                    kind: "shear",
                    slope_deg: slope,
                    air: false,
                    csv,
                    truth,
                });
            }
        }
    }
    Dataset { trials, header: None }
}

// ---------------------------------------------------------------- realistic noisy campaigns

/// How a noisy campaign is made (issue 11: a rig nobody tuned the tool for).
#[derive(Debug, Clone, Copy)]
pub struct Realism {
    /// Sensor noise as a fraction of full scale (0.005 to 0.03).
    pub noise_fs: f64,
    /// Penetration load cell full scale, N.
    pub pen_full_scale: f64,
    /// Shear load cell full scale, N.
    pub shear_full_scale: f64,
    /// In-air drift with position, N/m (cable drag), in air and in sand alike.
    pub drift: f64,
    /// Seed.
    pub seed: u64,
}

impl Default for Realism {
    fn default() -> Realism {
        Realism { noise_fs: 0.02, pen_full_scale: 10.0, shear_full_scale: 30.0, drift: 0.5, seed: 1 }
    }
}

/// Stroke of the noisy penetration trials, m.
pub const NOISY_STROKE: f64 = 0.05;

/// What makes one noisy penetration trial different.
#[derive(Debug, Clone, Copy)]
pub struct PenetrationShape {
    /// Depth of the bed bottom (20 times stiffer below), m.
    pub bottom: f64,
    /// The clipped amplifier reads exactly full scale (true) or full scale plus noise (false:
    /// the ADC noise comes after the clip, so the cleaning cannot see it).
    pub exact_clip: bool,
    /// The recording goes back up after the deepest point.
    pub retraction: bool,
}

/// The true end of the linear part of a noisy penetration trial, m: the bed bottom or the
/// depth where the force reaches full scale, whichever comes first.
pub fn linear_end(k_n: f64, slope_deg: f64, r: &Realism, shape: &PenetrationShape) -> f64 {
    let b = k_n * std::f64::consts::PI * DISK_RADIUS * DISK_RADIUS;
    // F = offset + drift d + b (d - contact - soft / 2) = full scale.
    let (contact, soft) = (0.002, 0.002);
    let offset = noisy_pen_offset(slope_deg);
    let clip = (r.pen_full_scale - offset + b * (contact + soft / 2.0)) / (b + r.drift);
    clip.min(shape.bottom).min(NOISY_STROKE)
}

/// In-air force of the noisy penetration rig, N (about 0.3 N).
pub fn noisy_pen_offset(slope_deg: f64) -> f64 {
    0.25 * slope_deg.to_radians().cos() + 0.06
}

/// In-air force of the noisy shear rig, N.
pub fn noisy_shear_offset(slope_deg: f64) -> f64 {
    0.3 * slope_deg.to_radians().sin() + 0.25
}

/// A noisy penetration recording (an in-air run when `k_n` is 0): 2 mm in air, an impact bump
/// and a 2 mm soft layer at the surface, the linear part, the bed bottom, a clipping load cell,
/// optionally a return stroke.
pub fn noisy_penetration(
    k_n: f64,
    slope_deg: f64,
    r: &Realism,
    shape: &PenetrationShape,
    fmt: Format,
    seed: u64,
) -> (String, Truth) {
    let mut noise = Noise::new(seed);
    let b = k_n * std::f64::consts::PI * DISK_RADIUS * DISK_RADIUS;
    let (contact, soft, sigma) = (0.002, 0.002, r.noise_fs * r.pen_full_scale);
    let mut xs = positions(NOISY_STROKE, fmt.rate_hz);
    let down = xs.len();
    if shape.retraction {
        // Back up to the surface at the same speed.
        let back: Vec<f64> = xs[..down - 1].iter().rev().copied().collect();
        xs.extend(back);
    }
    let cap = r.pen_full_scale;
    let mut clip_from = xs.len();
    let mut saturated = 0;
    let fs: Vec<f64> = xs
        .iter()
        .enumerate()
        .map(|(i, &d)| {
            let e = (d - contact).max(0.0);
            let mut f = if k_n == 0.0 {
                0.0
            } else if e < soft {
                b * e * e / (2.0 * soft)
            } else {
                b * (e - soft / 2.0)
            };
            if k_n > 0.0 && d > shape.bottom {
                f += 20.0 * b * (d - shape.bottom);
            }
            if k_n > 0.0 && e > 0.0 {
                // Impact of the disk on the surface: a bump of 0.4 N peaking 0.6 mm in.
                let u = e / 0.0006;
                f += 0.4 * u * (1.0 - u).exp();
            }
            if i >= down {
                // Unloading on the way back: the sand does not push the disk back up.
                f *= 0.1;
            }
            let f = noisy_pen_offset(slope_deg) + r.drift * d + f;
            if f >= cap {
                clip_from = clip_from.min(i);
                if shape.exact_clip {
                    if i < down {
                        saturated += 1;
                    }
                    return cap;
                }
                return cap + sigma * noise.normal();
            }
            f + sigma * noise.normal()
        })
        .collect();
    let (csv, rows) = to_csv("depth", &xs, &fs, 2, clip_from.min(down), fmt, &mut noise);
    (csv, Truth { k: k_n, saturated, defects: fmt.defects, rows })
}

/// A noisy shear recording (an in-air run when `k_s` is 0), optionally with the return.
pub fn noisy_shear(
    k_s: f64,
    slope_deg: f64,
    r: &Realism,
    fmt: Format,
    retraction: bool,
    seed: u64,
) -> (String, Truth) {
    let mut noise = Noise::new(seed);
    let fp = k_s * PLATE_WIDTH * PLATE_DEPTH * PLATE_DEPTH;
    let (x0, sigma) = (0.003, r.noise_fs * r.shear_full_scale);
    let mut xs = positions(0.10, fmt.rate_hz);
    let fwd = xs.len();
    if retraction {
        let back: Vec<f64> = xs[..fwd - 1].iter().rev().copied().collect();
        xs.extend(back);
    }
    let (rho, amp) = (0.9f64, 0.02 * fp);
    let mut ar = 0.0;
    let fs: Vec<f64> = xs
        .iter()
        .enumerate()
        .map(|(i, &x)| {
            ar = rho * ar + (1.0 - rho * rho).sqrt() * amp * noise.normal();
            let rise = if i < fwd { 1.0 - (-x / x0).exp() } else { -0.5 };
            noisy_shear_offset(slope_deg) + r.drift * x + fp * rise + rise.abs() * ar + sigma * noise.normal()
        })
        .collect();
    let (csv, rows) = to_csv("displacement", &xs, &fs, 9, fwd, fmt, &mut noise);
    (csv, Truth { k: k_s, saturated: 0, defects: fmt.defects, rows })
}

/// A noisy campaign: slopes 0, 5, 10, 15, 20, 24 deg, three trials of each kind and one in-air
/// run per kind and slope, 80 to 100 Hz, depth in m, cm or mm, some files in counts, some with
/// a return stroke, exact or noisy clipping. At the slopes in `short_at` the third penetration
/// trial meets the bed bottom at 12 mm (a window forced short).
pub fn noisy_campaign(r: &Realism, short_at: &[f64]) -> (Dataset, Vec<PenetrationShape>) {
    let mut trials = Vec::new();
    let mut shapes = Vec::new();
    let mut seed = r.seed * 10_000;
    let mut scatter = Noise::new(r.seed + 77);
    for (si, &slope) in [0.0, 5.0, 10.0, 15.0, 20.0, 24.0].iter().enumerate() {
        let tag = slope as u32;
        let air_shape = PenetrationShape { bottom: 1.0, exact_clip: true, retraction: false };
        let fmt = Format { rate_hz: 100.0, ..Format::default() };
        seed += 1;
        let (csv, truth) = noisy_penetration(0.0, slope, r, &air_shape, fmt, seed);
        trials.push(GeneratedTrial {
            file: format!("pen-{tag:02}-air.csv"),
            kind: "penetration",
            slope_deg: slope,
            air: true,
            csv,
            truth,
        });
        shapes.push(air_shape);
        seed += 1;
        let (csv, truth) = noisy_shear(0.0, slope, r, fmt, false, seed);
        trials.push(GeneratedTrial {
            file: format!("shear-{tag:02}-air.csv"),
            kind: "shear",
            slope_deg: slope,
            air: true,
            csv,
            truth,
        });
        shapes.push(air_shape);
        for rep in 1..=3usize {
            let k_n = example_k_n(slope) * (1.0 + 0.05 * scatter.normal());
            let k_s = example_k_s(slope) * (1.0 + 0.05 * scatter.normal());
            let variant = (si + rep) % 4;
            let fmt = match variant {
                0 => Format { unit: Unit::Mm, rate_hz: 100.0, ..Format::default() },
                1 => Format { unit: Unit::M, rate_hz: 80.0, time: true, ..Format::default() },
                2 => Format { unit: Unit::Cm, rate_hz: 100.0, counts: true, ..Format::default() },
                _ => Format { unit: Unit::Mm, rate_hz: 90.0, time: true, counts: true, ..Format::default() },
            };
            let shape = PenetrationShape {
                bottom: if short_at.contains(&slope) && rep == 3 { 0.012 } else { 0.08 },
                exact_clip: variant % 2 == 0,
                retraction: variant == 1 || variant == 3,
            };
            seed += 1;
            let (csv, truth) = noisy_penetration(k_n, slope, r, &shape, fmt, seed);
            trials.push(GeneratedTrial {
                file: format!("pen-{tag:02}-{rep}.csv"),
                kind: "penetration",
                slope_deg: slope,
                air: false,
                csv,
                truth,
            });
            shapes.push(shape);
            seed += 1;
            let (csv, truth) = noisy_shear(k_s, slope, r, fmt, variant == 2, seed);
            trials.push(GeneratedTrial {
                file: format!("shear-{tag:02}-{rep}.csv"),
                kind: "shear",
                slope_deg: slope,
                air: false,
                csv,
                truth,
            });
            shapes.push(shape);
        }
    }
    let header = format!(
        "# Noisy load-cell campaign (synthetic; generated by crates/sandslope-cli/tests/it/fit/synth.rs, noisy_campaign).\n\
         # A {:.0} N penetration and a {:.0} N shear load cell with {:.1}% full-scale noise, offsets near 0.3 N, an impact\n\
         # bump and a soft layer at the surface, clipping at full scale, in-air drift {} N/m, return strokes,\n\
         # depth in m, cm or mm at 80 to 100 Hz. True values: k_n = 7.0e5 (1 - 0.002 slope_deg),\n\
         # k_s = 2.0e6 (1 - 0.03 slope_deg) N/m^3, each trial drawn with 5% trial-to-trial scatter.\n",
        r.pen_full_scale,
        r.shear_full_scale,
        100.0 * r.noise_fs,
        r.drift
    );
    (Dataset { trials, header: Some(header) }, shapes)
}
