//! `infer --servo-log` on logs as messy as a real bus writes them (issue 42, docs/drive.md
//! "Messy logs"): each of the ten emulated logs (k_s = 2.5e5 N/m^3 at 20 degrees, 10 mA of
//! noise) with one defect injected. Each defect must either be refused with an error naming
//! the file, line and servo (exit 2, nothing printed on stdout) or give an answer whose 90%
//! interval still holds the emulator's k_s in at least 9 of the 10 runs.

use std::path::Path;

use sandslope::infer::servo::{infer_from_currents, model_grid, CurrentInferenceSettings, ModelGrid};
use sandslope::infer::LogUniformPrior;
use sandslope::robot::{Robot, RobotSpec};

use super::{bin, emulated_logs, text};

const TRUTH: f64 = 2.5e5;
/// K_t of the XL330-M288 from its datasheet: 0.52 N m stall torque at 1.47 A.
const K_T: f64 = 0.52 / 1.47;
/// The default servos' directions (docs/drive.md): legs 0-2 +1, legs 3-5 -1.
const DIRECTION: [f64; 6] = [1.0, 1.0, 1.0, -1.0, -1.0, -1.0];

/// splitmix64, uniform in [0, 1).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn within(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
}

/// A log split into its `#` header, its column line and its rows' fields.
struct Log {
    header: String,
    columns: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Log {
    fn read(path: &Path) -> Log {
        let text = std::fs::read_to_string(path).unwrap();
        let header: String = text.lines().filter(|l| l.starts_with('#')).map(|l| format!("{l}\n")).collect();
        let mut body = text.lines().filter(|l| !l.starts_with('#'));
        let columns = body.next().unwrap().split(',').map(String::from).collect();
        let rows = body.map(|l| l.split(',').map(String::from).collect()).collect();
        Log { header, columns, rows }
    }
    fn col(&self, name: &str) -> usize {
        self.columns.iter().position(|c| c == name).unwrap()
    }
    fn text(&self) -> String {
        let mut s = format!("{}{}\n", self.header, self.columns.join(","));
        for r in &self.rows {
            s.push_str(&r.join(","));
            s.push('\n');
        }
        s
    }
    /// The file line of row `i` (header lines, then the column line, then the rows).
    fn line_of(&self, i: usize) -> usize {
        self.header.lines().count() + 2 + i
    }
    /// Adds `ma` mA to a row's Present Current, and its torque `direction K_t I` to the drive
    /// torque, as a biased current sensor would.
    fn add_current(&mut self, i: usize, ma: f64) {
        let (cur, tau, leg) = (self.col("present_current_ma"), self.col("drive_torque_n_m"), self.col("leg"));
        let ma = ma.round();
        let r = &mut self.rows[i];
        let leg: usize = r[leg].parse().unwrap();
        r[cur] = (r[cur].parse::<f64>().unwrap() + ma).to_string();
        r[tau] = (r[tau].parse::<f64>().unwrap() + DIRECTION[leg] * K_T * ma / 1000.0).to_string();
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Defect {
    /// A constant zero-current offset per servo, -40 to 40 mA.
    Bias,
    /// An offset that drifts: -40 to 40 mA at the start, changing by -8 to 8 mA/s.
    Drift,
    /// Bus timeouts: 3% of the cycles start a gap of 1 to 3 cycles with no rows.
    Gaps,
    /// One servo's rows missing for a second.
    Missing,
    /// 5% of the rows written twice, and rows a cycle out of time order.
    Repeats,
    /// 2% of the rows with an empty or NaN measurement.
    Nan,
    /// The last row cut short (the logger killed mid-write).
    Cut,
}

/// The log with the defect; for Bias and Drift, each leg's injected offset as the swings see
/// it, mA: the mean over the leg's swings (from its first touchdown on, three rows or more) of
/// the offset's mean in the swing. A swing is where the leg's angle is half a turn to a turn
/// past touchdown, phi0 = asin((0.03 - 0.04) / 0.04) (the paper's robot, docs/model.md §15).
fn inject(defect: Defect, log: &mut Log, rng: &mut Rng) -> Option<Vec<f64>> {
    let (t, leg) = (log.col("time_s"), log.col("leg"));
    let time = |r: &Vec<String>| r[t].parse::<f64>().unwrap();
    let leg_of = |r: &Vec<String>| r[leg].parse::<usize>().unwrap();
    match defect {
        Defect::Bias | Defect::Drift => {
            let start: Vec<f64> = (0..6).map(|_| rng.within(-40.0, 40.0)).collect();
            let rate: Vec<f64> =
                (0..6).map(|_| if defect == Defect::Drift { rng.within(-8.0, 8.0) } else { 0.0 }).collect();
            let (phi0, a) = ((-0.25f64).asin(), log.col("leg_angle_rad"));
            let mut swings: [std::collections::BTreeMap<i64, Vec<f64>>; 6] = Default::default();
            for i in 0..log.rows.len() {
                let (l, ti) = (leg_of(&log.rows[i]), time(&log.rows[i]));
                let ma = (start[l] + rate[l] * (ti + 1.0)).round();
                log.add_current(i, ma);
                let turns = (log.rows[i][a].parse::<f64>().unwrap() - phi0) / (2.0 * std::f64::consts::PI);
                if turns >= 0.0 && turns.fract() >= 0.5 {
                    swings[l].entry(turns.floor() as i64).or_default().push(ma);
                }
            }
            let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
            return Some(
                swings
                    .iter()
                    .map(|m| mean(&m.values().filter(|v| v.len() >= 3).map(|v| mean(v)).collect::<Vec<_>>()))
                    .collect(),
            );
        }
        Defect::Gaps => {
            let mut times: Vec<String> = log.rows.iter().map(|r| r[t].clone()).collect();
            times.dedup();
            let mut drop = std::collections::HashSet::new();
            let mut i = 0;
            while i < times.len() {
                if rng.next() < 0.03 {
                    let len = 1 + (rng.next() * 3.0) as usize;
                    drop.extend(times.iter().skip(i).take(len).cloned());
                    i += 3;
                }
                i += 1;
            }
            log.rows.retain(|r| !drop.contains(&r[t]));
        }
        Defect::Missing => {
            let (l, t0) = ((rng.next() * 6.0) as usize, rng.within(0.5, 3.5));
            log.rows.retain(|r| !(leg_of(r) == l && (t0..t0 + 1.0).contains(&time(r))));
        }
        Defect::Repeats => {
            let mut rows = vec![];
            for r in log.rows.drain(..) {
                if rng.next() < 0.05 {
                    rows.push(r.clone());
                }
                rows.push(r);
            }
            for _ in 0..rows.len() / 30 {
                let i = (rng.next() * (rows.len() - 7) as f64) as usize;
                rows.swap(i, i + 6);
            }
            log.rows = rows;
        }
        Defect::Nan => {
            let cols = ["present_current_ma", "drive_torque_n_m", "leg_angle_rad", "present_velocity"];
            for i in 0..log.rows.len() {
                if rng.next() < 0.02 {
                    let c = log.col(cols[(rng.next() * 4.0) as usize]);
                    log.rows[i][c] = if rng.next() < 0.5 { String::new() } else { "NaN".into() };
                }
            }
        }
        Defect::Cut => {}
    }
    None
}

/// The longest step between successive row times of `log`, in median steps (bus cycles).
fn longest_gap_cycles(log: &Log) -> f64 {
    let t = log.col("time_s");
    let mut times: Vec<f64> = log.rows.iter().map(|r| r[t].parse::<f64>().unwrap()).collect();
    times.dedup();
    let mut steps: Vec<f64> = times.windows(2).map(|w| w[1] - w[0]).collect();
    steps.sort_by(f64::total_cmp);
    steps.last().unwrap() / steps[steps.len() / 2]
}

fn write_defect(defect: Defect, log: &Log, dir: &Path, seed: usize, rng: &mut Rng) -> std::path::PathBuf {
    let mut text = log.text();
    if defect == Defect::Cut {
        // Cut 3 to 30 bytes off the end: the last row loses its line end and part of a field.
        text.truncate(text.len() - 3 - (rng.next() * 27.0) as usize);
    }
    let path = dir.join(format!("{defect:?}-{seed}.csv"));
    std::fs::write(&path, text).unwrap();
    path
}

fn grid(swing_offset: bool) -> ModelGrid {
    let robot = Robot::new(RobotSpec::paper_hexapod()).unwrap();
    let settings = CurrentInferenceSettings {
        prior: LogUniformPrior::new(3e4, 3e7).unwrap(),
        grid_points: 25,
        swing_offset,
        ..Default::default()
    };
    // k_n of the built-in terrain (glass beads) as the logs' header records it.
    model_grid(&robot, 7e5, sandslope::SignedSlope::from_degrees(20.0).unwrap(), &settings).unwrap()
}

/// Per defect, the 90% interval must hold the emulator's k_s in 9 of the 10 runs, and the
/// reader must say what it repaired. For a biased sensor (offsets, drift) the offsets must be
/// read back within 3 mA (the swing median's noise with 10 mA per sample and ~25 samples a
/// swing is ~2.5 mA per swing, less averaged over four), and the estimate must stay within 5%
/// of the clean log's: without the swing correction, the same offsets moved the median by up
/// to 18% (offsets) and 2.9 times (drift), yet the wide intervals still covered the truth in
/// 10 of 10 (2026-11-28), so coverage alone cannot tell a correction from none.
#[test]
fn messy_logs_still_cover_the_emulated_k_s() {
    emulated_logs();
    let _cpu = super::cpu_bound();
    let robot = Robot::new(RobotSpec::paper_hexapod()).unwrap();
    let grid = grid(true);
    let dir = tempfile::tempdir().unwrap();
    let defects = [
        Defect::Bias,
        Defect::Drift,
        Defect::Gaps,
        Defect::Missing,
        Defect::Repeats,
        Defect::Nan,
        Defect::Cut,
    ];
    // The clean logs' answers: k_s, and the offsets read from them, mA. A clean log's reading
    // is the median of its swings' noise (10 mA a sample, ~25 samples a swing, a few swings:
    // about 1.3 mA, but 4 mA seen once in CI, 2026-11-28, as the real-time emulator's sampling
    // varies with load), so the check is on what an injected offset adds to the clean log's
    // reading: for a constant offset the median moves by exactly that much.
    let clean: Vec<(f64, Vec<f64>)> = emulated_logs()
        .iter()
        .map(|p| {
            let read = sandslope_io::servo_log::read_servo_log(p).unwrap();
            let answer = infer_from_currents(&robot, &grid, &read.leg_traces(6, p).unwrap()).unwrap();
            let ma =
                answer.swing_offset_n_m.iter().enumerate().map(|(leg, &o)| 1000.0 * o / K_T * DIRECTION[leg]);
            (answer.k_s, ma.collect())
        })
        .collect();
    for defect in defects {
        let (mut inside, mut checked_notes) = (0, 0);
        for (seed, path) in emulated_logs().iter().enumerate() {
            let mut rng = Rng(1000 * seed as u64 + defect as u64);
            let mut log = Log::read(path);
            let injected = inject(defect, &mut log, &mut rng);
            let file = write_defect(defect, &log, dir.path(), seed, &mut rng);
            let read = sandslope_io::servo_log::read_servo_log(&file).unwrap();
            let notes = read.notes.join(" | ");
            let expect = match defect {
                Defect::Nan => Some("with an empty or NaN value left out"),
                Defect::Cut => Some("the log ends mid-row"),
                Defect::Repeats => Some("repeated row(s) read once"),
                // Only where a gap of 3 or more dropped cycles was drawn (4 cycles between
                // rows, clear of the 3-cycle threshold; a 2-cycle drop sits on it, to the
                // emulator's real-time jitter).
                Defect::Gaps if longest_gap_cycles(&log) > 3.5 => {
                    Some("gap(s) in time longer than 3 bus cycles")
                }
                _ => None,
            };
            if let Some(e) = expect {
                assert!(notes.contains(e), "{defect:?} seed {seed}: notes {notes}");
                checked_notes += 1;
            }
            if defect == Defect::Repeats {
                assert!(notes.contains("out of time order"), "{notes}");
            }
            let traces = read.leg_traces(6, &file).unwrap();
            let answer = infer_from_currents(&robot, &grid, &traces).unwrap();
            if answer.k_s_lo <= TRUTH && TRUTH <= answer.k_s_hi {
                inside += 1;
            }
            if let Some(ma) = injected {
                let (clean_k_s, clean_ma) = &clean[seed];
                let moved = answer.k_s / clean_k_s - 1.0;
                assert!(
                    moved.abs() < 0.05,
                    "{defect:?} seed {seed}: k_s {} against {} clean",
                    answer.k_s,
                    clean_k_s
                );
                for (leg, (&got, want)) in answer.swing_offset_n_m.iter().zip(ma).enumerate() {
                    let got_ma = 1000.0 * got / K_T * DIRECTION[leg] - clean_ma[leg];
                    assert!(
                        (got_ma - want).abs() < 3.0,
                        "{defect:?} seed {seed} leg {leg}: offset read {got_ma} mA over the clean log's {} mA, injected {want} mA",
                        clean_ma[leg]
                    );
                }
            }
        }
        assert!(inside >= 9, "{defect:?}: the true k_s inside the 90% interval in {inside} of 10 runs");
        if defect == Defect::Gaps {
            assert!(checked_notes >= 5, "a gap of 3 cycles or more drawn in only {checked_notes} of 10 logs");
        }
    }
}

/// The same through the binary: a log with a drifting offset, NaNs, repeats and a cut last
/// row gives an answer (exit 0), the notes on stderr, and the offsets in `--json`.
#[test]
fn a_messy_log_through_the_cli_says_what_it_repaired() {
    let dir = tempfile::tempdir().unwrap();
    let mut log = Log::read(&emulated_logs()[0]);
    let mut rng = Rng(7);
    inject(Defect::Drift, &mut log, &mut rng);
    inject(Defect::Nan, &mut log, &mut rng);
    inject(Defect::Repeats, &mut log, &mut rng);
    let path = write_defect(Defect::Cut, &log, dir.path(), 0, &mut rng);
    let out = bin()
        .args(["infer", "--servo-log"])
        .arg(&path)
        .args(["--grid-points", "25", "--k-s-prior", "3e4:3e7", "--json"])
        .output()
        .unwrap();
    let all = text(&out);
    assert!(out.status.success(), "{all}");
    for note in ["ends mid-row", "empty or NaN", "repeated row", "out of time order"] {
        assert!(all.contains(note), "{note}: {all}");
    }
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["swing_offset_n_m"].as_array().unwrap().len(), 6, "{v}");
    // The same repairs in `--json`'s `notes`, one each (a gap may be noted beside them).
    let notes: Vec<&str> = v["notes"].as_array().unwrap().iter().map(|n| n.as_str().unwrap()).collect();
    for note in ["ends mid-row", "empty or NaN", "repeated row", "out of time order"] {
        assert_eq!(notes.iter().filter(|n| n.contains(note)).count(), 1, "{note}: {notes:?}");
        assert!(all.contains(&format!(
            "note: {}: {}",
            path.display(),
            notes.iter().find(|n| n.contains(note)).unwrap()
        )));
    }
}

/// What cannot be repaired is refused: exit 2, the file, line and servo named, nothing on
/// stdout. Line numbers counted here from the text written.
#[test]
fn broken_logs_are_refused_naming_the_line_and_servo() {
    let dir = tempfile::tempdir().unwrap();
    let base = Log::read(&emulated_logs()[1]);
    let (id, tau, time, leg) =
        (base.col("id"), base.col("drive_torque_n_m"), base.col("time_s"), base.col("leg"));
    type Break = Box<dyn Fn(&mut Log) -> String>;
    let cases: Vec<(&str, Break)> = vec![
        (
            "two rows",
            Box::new(move |l: &mut Log| {
                let mut r = l.rows[100].clone();
                r[tau] = "0.5".into();
                l.rows.insert(101, r);
                let sid = &l.rows[100][id];
                format!(
                    "lines {} and {} (servo ID {sid}): two different rows at time_s",
                    l.line_of(100),
                    l.line_of(101)
                )
            }),
        ),
        (
            "garbage",
            Box::new(move |l: &mut Log| {
                l.rows[200][tau] = "0.1x".into();
                format!(
                    "line {} (servo ID {}): `drive_torque_n_m` = `0.1x` is not a finite number",
                    l.line_of(200),
                    l.rows[200][id]
                )
            }),
        ),
        (
            "short row",
            Box::new(move |l: &mut Log| {
                l.rows[300].pop();
                format!(
                    "line {} (servo ID {}): 13 fields, the header has 14",
                    l.line_of(300),
                    l.rows[300][id]
                )
            }),
        ),
        (
            "no time",
            Box::new(move |l: &mut Log| {
                l.rows[50][time] = String::new();
                format!("line {} (servo ID {}): `time_s` is empty", l.line_of(50), l.rows[50][id])
            }),
        ),
        (
            "two legs",
            Box::new(move |l: &mut Log| {
                let other = if l.rows[400][leg] == "0" { "1" } else { "0" };
                l.rows[400][leg] = other.into();
                format!("(servo ID {}): leg {other}, but line", l.rows[400][id])
            }),
        ),
    ];
    for (name, break_it) in cases {
        let mut log =
            Log { header: base.header.clone(), columns: base.columns.clone(), rows: base.rows.clone() };
        let want = break_it(&mut log);
        let path = dir.path().join(format!("{}.csv", name.replace(' ', "-")));
        std::fs::write(&path, log.text()).unwrap();
        let out = bin().args(["infer", "--servo-log"]).arg(&path).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{name}: {}", text(&out));
        assert!(
            err.contains(&path.display().to_string()) && err.contains(&want),
            "{name}: want {want}: {err}"
        );
        assert!(out.stdout.is_empty(), "{name}: {}", text(&out));
    }
}
