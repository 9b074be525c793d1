//! Steps within a smooth track: touchdown offset, anchoring time t1, backward slip, net step
//! and step speed (docs/model.md §11), their summary across steps, and the
//! stride-averaged speed curve (the paper's Fig. 3b).

use serde::Serialize;

/// Smoothed along-slope position and speed of one segment, sampled at a constant frame rate.
#[derive(Debug, Clone, PartialEq)]
pub struct SmoothTrack {
    /// Time of the first sample, s (in the recording's clock).
    pub start_time_s: f64,
    /// Frames per second.
    pub frame_rate_hz: f64,
    /// Along-slope position, m.
    pub position: Vec<f64>,
    /// Along-slope speed, m/s (positive upslope).
    pub speed: Vec<f64>,
    /// Estimated standard deviation of the speed noise, m/s (see
    /// [`crate::gait::LowPass::speed_noise`]); a speed minimum counts as the anchoring time
    /// only if the speed then rises by more than three times this.
    pub speed_noise_m_s: f64,
    /// A speed within this of zero is rest, m/s (docs/model.md §11): a motion-capture track's
    /// is [`REST_SPEED_FRACTION`] of its noise SD; the stride simulator's is that or its
    /// creep speed, whichever is more, since a resting body creeps (§18).
    pub rest_speed_m_s: f64,
}

impl SmoothTrack {
    /// Time of sample `i`, s.
    pub fn time(&self, i: usize) -> f64 {
        self.start_time_s + i as f64 / self.frame_rate_hz
    }

    /// Time of the last sample, s.
    pub fn end_time(&self) -> f64 {
        self.time(self.position.len().saturating_sub(1))
    }

    /// Linear interpolation of `values` at time `t` (inside the track).
    fn at(&self, values: &[f64], t: f64) -> f64 {
        let x = ((t - self.start_time_s) * self.frame_rate_hz).max(0.0);
        let i = (x.floor() as usize).min(values.len().saturating_sub(2));
        let f = (x - i as f64).clamp(0.0, 1.0);
        values[i] + (values[i + 1] - values[i]) * f
    }

    /// Speed at time `t`, m/s (linear interpolation).
    pub fn speed_at(&self, t: f64) -> f64 {
        self.at(&self.speed, t)
    }

    /// Position at time `t`, m (linear interpolation).
    pub fn position_at(&self, t: f64) -> f64 {
        self.at(&self.position, t)
    }

    /// Whether `[t0, t0 + duration]` lies inside the track.
    pub fn covers(&self, t0: f64, duration: f64) -> bool {
        self.position.len() >= 2 && t0 >= self.start_time_s - 1e-9 && t0 + duration <= self.end_time() + 1e-9
    }
}

/// Where touchdowns fall in the recording's clock (touchdowns every T/2 from an offset),
/// estimated from the speed signal's periodic structure.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TouchdownOffset {
    /// Touchdowns happen at `offset_s + k T/2` in the recording's clock, s, in `[0, T/2)`.
    pub offset_s: f64,
    /// Minimum of the speed averaged over steps (folded at T/2), m/s (negative: the robot
    /// slips back).
    pub min_mean_speed_m_s: f64,
}

/// Estimates the touchdown offset by folding the speed of all `tracks` (one recording, one
/// clock) at the step period `step_s` (= T/2).
///
/// The folded mean has one minimum per step, at the anchoring time t1. The model (docs/model.md
/// section 5) starts each step at rest (the slip `s1 = g sin(theta) t1^2 / 2` assumes zero
/// speed at touchdown), and the paper describes the speed falling "toward zero" after
/// lift-off until the next tripod touches down, then turning negative while the robot slips.
/// So **(choice)** the touchdown is placed where the mean speed crosses zero downward before
/// its minimum. If the mean never goes below zero by more than [`REST_FRACTION`] of its range
/// (no slip: the robot rests until the next tripod pushes, as the stride simulator's walks do
/// and as level sand does; the low pass's ringing can dip below zero), the touchdown is where
/// the speed leaves that rest, rising through the minimum plus that fraction of the range
/// (a placement at the minimum itself was up to 1.4 frames early on the simulator's walks, whose
/// rest lasts about 50 ms); if it never turns positive (the robot only slides down), it is the
/// maximum. `None` when the tracks do not
/// fill every bin of the folded step (less than one step of data).
pub fn estimate_touchdown_offset(tracks: &[SmoothTrack], step_s: f64) -> Option<TouchdownOffset> {
    let rate = tracks.first()?.frame_rate_hz;
    let bins = ((step_s * rate).round() as usize).max(8);
    let width = step_s / bins as f64;
    let mut sum = vec![0.0; bins];
    let mut offset_sum = vec![0.0; bins];
    let mut count = vec![0usize; bins];
    for track in tracks {
        for (i, &v) in track.speed.iter().enumerate() {
            let within = track.time(i).rem_euclid(step_s);
            let b = ((within / width) as usize).min(bins - 1);
            sum[b] += v;
            offset_sum[b] += within;
            count[b] += 1;
        }
    }
    if count.contains(&0) {
        return None;
    }
    let mean: Vec<f64> = sum.iter().zip(&count).map(|(s, &c)| s / c as f64).collect();
    // Mean time-within-step of the samples in each bin (not the bin centre: at an integer number of
    // frames per step every sample sits at the same place in its bin).
    let when: Vec<f64> = offset_sum.iter().zip(&count).map(|(s, &c)| s / c as f64).collect();
    let wrap = |b: isize| b.rem_euclid(bins as isize) as usize;
    let at = |b: isize| mean[wrap(b)];
    let time_of = |b: isize| when[wrap(b)] + b.div_euclid(bins as isize) as f64 * step_s;
    let vertex = |b: usize| {
        // Vertex of the parabola through the three bins around b (uniformly spaced).
        let (l, m, r) = (at(b as isize - 1), mean[b], at(b as isize + 1));
        let denom = l - 2.0 * m + r;
        let off = if denom.abs() > 1e-300 { (0.5 * (l - r) / denom).clamp(-0.5, 0.5) } else { 0.0 };
        when[b] + off * width
    };
    let argmin = (0..bins).min_by(|&a, &b| mean[a].total_cmp(&mean[b]))?;
    let argmax = (0..bins).max_by(|&a, &b| mean[a].total_cmp(&mean[b]))?;
    let min = mean[argmin];
    let range = mean[argmax] - min;
    let offset = if min >= -REST_FRACTION * range && mean[argmax] > 0.0 {
        // At rest before the step (no slip, or only the low pass's ringing below zero): the
        // touchdown is where the speed leaves its rest, REST_FRACTION of the range above the
        // minimum, walking forward from it.
        let level = min + REST_FRACTION * range;
        let mut j = argmin as isize;
        while at(j + 1) < level {
            j += 1;
        }
        let (a, b) = (at(j), at(j + 1));
        let (ta, tb) = (time_of(j), time_of(j + 1));
        ta + (tb - ta) * (level - a) / (b - a)
    } else if mean[argmax] <= 0.0 {
        vertex(argmax)
    } else {
        // Walk back from the minimum to the last non-negative bin; interpolate the crossing.
        let mut j = argmin as isize - 1;
        while at(j) < 0.0 {
            j -= 1;
        }
        let (a, b) = (at(j), at(j + 1));
        let (ta, tb) = (time_of(j), time_of(j + 1));
        ta + (tb - ta) * a / (a - b)
    };
    Some(TouchdownOffset { offset_s: offset.rem_euclid(step_s), min_mean_speed_m_s: min })
}

/// Below this fraction of the folded mean speed's range under zero, the minimum is rest (or
/// the low pass's ringing), not slip.
const REST_FRACTION: f64 = 0.1;

/// A speed within this fraction of the track's noise SD of zero is rest: a body stopped at
/// the minimum, whose anchoring is where it starts to move (docs/model.md §11). Far below a
/// motion-capture track's noise (a minimum that close to zero is rare there); ten times the
/// stride simulator's default creep speed (its noise is set to 1e-4 m/s; a larger creep
/// widens it, [`SmoothTrack::rest_speed_m_s`]).
pub const REST_SPEED_FRACTION: f64 = 0.01;

/// Touchdown times `offset_s + k step_s` whose whole step lies inside `track`.
pub fn touchdowns_in(track: &SmoothTrack, offset_s: f64, step_s: f64) -> Vec<f64> {
    let first = ((track.start_time_s - offset_s) / step_s).ceil() as i64;
    (first..)
        .map(|k| offset_s + k as f64 * step_s)
        .take_while(|&t| t + step_s <= track.end_time() + 1e-9)
        .filter(|&t| track.covers(t, step_s))
        .collect()
}

/// What one step (one tripod's stance, `T/2` from touchdown) did: the one step type of
/// `track`'s result ([`super::StepRow`] adds its recording's index), serialised with the
/// anchoring time as `t1_s`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct StepMeasure {
    /// Touchdown time t0, s (recording clock).
    pub touchdown_s: f64,
    /// Anchoring time after touchdown, t1 - t0, s; `None` if the speed never turned from
    /// falling to rising within the step (no anchoring).
    #[serde(rename = "t1_s")]
    pub anchoring_time_s: Option<f64>,
    /// Backward slip: distance travelled downslope between t0 and t1, m (0 if none);
    /// `None` without anchoring.
    pub slip_m: Option<f64>,
    /// Net displacement upslope over the step, m.
    pub step_m: f64,
    /// Step-averaged speed, `step / (T/2)`, m/s.
    pub speed_m_s: f64,
}

/// Measures the step starting at touchdown `t0` (which must satisfy `track.covers(t0, step_s)`).
///
/// t1 is the first speed minimum at or after t0 (the acceleration turning from negative to
/// positive): walking from the first frame at or after t0, the lowest speed seen before the
/// speed first rises more than three noise SDs above it (so noise wiggles on the way down do
/// not count), refined to a fraction of a frame by the parabola through its neighbours. If
/// the speed rises right after touchdown, t1 = 0; if it never rises within the step, there
/// is no anchoring. Where that minimum is a backward speed and the slide it belongs to speeds
/// up again before it ends within the step, t1 is the slide's lowest instant (docs/model.md
/// §11). The slip integrates the negative part of the speed from t0 to t1.
pub fn measure_step(track: &SmoothTrack, t0: f64, step_s: f64) -> StepMeasure {
    let rate = track.frame_rate_hz;
    let v = &track.speed;
    let first = (((t0 - track.start_time_s) * rate).ceil().max(0.0) as usize).min(v.len() - 1);
    let last = (((t0 + step_s - track.start_time_s) * rate).floor() as usize).min(v.len() - 1);
    // Walk while the speed has not risen more than `rise` above its running minimum.
    let rise = 3.0 * track.speed_noise_m_s;
    let mut i = first;
    let mut lowest = first;
    let mut anchored = false;
    while i < last {
        i += 1;
        if v[i] < v[lowest] {
            lowest = i;
        } else if v[i] > v[lowest] + rise {
            anchored = true;
            break;
        }
    }
    // At rest at the minimum (the stride simulator's walks on level and gentle slopes stop
    // before touchdown and stay stopped until the legs push): the minimum is the whole rest,
    // and the acceleration turns positive where the speed leaves it. Within the rest the
    // lowest frame is a rounding error's choice.
    let rest = track.rest_speed_m_s;
    let at_rest = anchored && v[lowest].abs() <= rest;
    let t1_abs = if !anchored {
        None
    } else if at_rest {
        let mut j = lowest;
        while j + 1 < i && v[j + 1] <= rest {
            j += 1;
        }
        // Where the speed rises through `rest` between frames j and j + 1.
        let (a, b) = (v[j], v[j + 1]);
        let off = if b > a { ((rest - a) / (b - a)).clamp(0.0, 1.0) } else { 0.0 };
        Some(track.time(j) + off / rate)
    } else if lowest == first {
        // Rising from the first frame after touchdown: anchored at once (or at that frame,
        // if the speed was still falling between touchdown and it).
        Some(if track.speed_at(t0) <= v[first] { t0 } else { track.time(first) })
    } else {
        let (l, m, r) = (v[lowest - 1], v[lowest], v[lowest + 1]);
        let denom = l - 2.0 * m + r;
        let off = if denom > 0.0 { (0.5 * (l - r) / denom).clamp(-0.5, 0.5) } else { 0.0 };
        Some(track.time(lowest) + off / rate)
    };
    let t1_abs = t1_abs.map(|t| t.max(t0));
    let t1_abs = match deepest_in_the_slide(track, t0, step_s, t1_abs.map(|t| t - t0)) {
        Some(t1) => Some(t0 + t1),
        None => t1_abs,
    };
    let step_m = track.position_at(t0 + step_s) - track.position_at(t0);
    StepMeasure {
        touchdown_s: t0,
        anchoring_time_s: t1_abs.map(|t| t - t0),
        slip_m: t1_abs.map(|t| downslope_travel(track, t0, t)),
        step_m,
        speed_m_s: step_m / step_s,
    }
}

/// The end of a backward slide that a brief check interrupts (docs/model.md §11). Where §11's
/// first speed minimum after touchdown (`t1`, s after `t0`) is a backward speed (below minus
/// the track's rest speed), the slide it belongs to runs on until the speed rises back through
/// minus the rest speed. If the slide speeds up again after that minimum and ends within the
/// step, t1 is its deepest instant, where the backward slippage stopped accelerating for good
/// (the paper's "the instant when backward slippage stopped accelerating"): the new tripod's
/// first contact can slow a body already sliding back for a few ms, by more than the
/// measure's rise, before it slides on faster until the legs anchor (the free body at 20
/// degrees: -1.7 mm/s 5 ms after touchdown, -12.5 mm/s at 15 ms; docs/simulate.md, "The free
/// body's t1 at 20 degrees"). `None` where §11's minimum stands: no backward speed there, no
/// deeper instant after it, or a slide that outlasts the step (a body sliding back through its
/// stance, whose slide has no end to time).
fn deepest_in_the_slide(track: &SmoothTrack, t0: f64, half: f64, t1: Option<f64>) -> Option<f64> {
    let t1 = t1?;
    let v = &track.speed;
    let rate = track.frame_rate_hz;
    let index = |t: f64| ((((t - track.start_time_s) * rate).round()).max(0.0) as usize).min(v.len() - 1);
    let (first, last) = (index(t0 + t1), index(t0 + half));
    let rest = track.rest_speed_m_s;
    if v[first] >= -rest {
        return None;
    }
    let mut lowest = first;
    let mut i = first;
    while i < last && v[i + 1] < -rest {
        i += 1;
        if v[i] < v[lowest] {
            lowest = i;
        }
    }
    // A slide that outlasts the step (a body sliding back through its stance) is no phase 1
    // with an end, and §11's minimum stands.
    if i >= last || lowest == first {
        return None;
    }
    let (l, m, r) = (v[lowest - 1], v[lowest], v[lowest + 1]);
    let denom = l - 2.0 * m + r;
    let off = if denom > 0.0 { (0.5 * (l - r) / denom).clamp(-0.5, 0.5) } else { 0.0 };
    Some(track.time(lowest) + off / rate - t0)
}

/// Integral of `max(0, -v)` from `ta` to `tb` with `v` linear between frames, m.
fn downslope_travel(track: &SmoothTrack, ta: f64, tb: f64) -> f64 {
    if tb <= ta {
        return 0.0;
    }
    let dt = 1.0 / track.frame_rate_hz;
    let mut knots = vec![ta];
    let mut i = ((ta - track.start_time_s) * track.frame_rate_hz).floor() as i64 + 1;
    loop {
        let t = track.start_time_s + i as f64 * dt;
        if t >= tb {
            break;
        }
        knots.push(t);
        i += 1;
    }
    knots.push(tb);
    knots
        .windows(2)
        .map(|w| {
            let (a, b) = (-track.speed_at(w[0]), -track.speed_at(w[1]));
            let h = w[1] - w[0];
            match (a > 0.0, b > 0.0) {
                (true, true) => 0.5 * (a + b) * h,
                (false, false) => 0.0,
                (true, false) => 0.5 * a * h * a / (a - b),
                (false, true) => 0.5 * b * h * b / (b - a),
            }
        })
        .sum()
}

/// Mean and sample standard deviation of a quantity across steps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stats {
    /// Mean.
    pub mean: f64,
    /// Sample standard deviation (n - 1 in the denominator); `None` for fewer than 2 values.
    pub sd: Option<f64>,
    /// Number of values.
    pub n: usize,
}

impl Stats {
    /// Statistics of `values`; `None` when empty.
    pub fn of(values: impl IntoIterator<Item = f64>) -> Option<Stats> {
        let v: Vec<f64> = values.into_iter().collect();
        if v.is_empty() {
            return None;
        }
        let n = v.len();
        let mean = v.iter().sum::<f64>() / n as f64;
        let sd = (n > 1).then(|| (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt());
        Some(Stats { mean, sd, n })
    }
}

/// Means and sample SDs across steps (docs/model.md §11; an SD is `None` with fewer than two
/// values): the one summary of recordings at one slope, what `track` reports (flattened into
/// [`super::TrackResult`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct GaitSummary {
    /// Mean step-averaged speed, m/s.
    pub speed_m_s: f64,
    /// Its SD across steps, m/s.
    pub speed_sd_m_s: Option<f64>,
    /// Mean anchoring time t1 over anchored steps, s; `None` if no step anchored.
    pub t1_s: Option<f64>,
    /// Its SD, s.
    pub t1_sd_s: Option<f64>,
    /// Mean backward slip over anchored steps, m.
    pub slip_m: Option<f64>,
    /// Its SD, m.
    pub slip_sd_m: Option<f64>,
    /// Mean net step, m.
    pub step_m: f64,
    /// Its SD, m.
    pub step_sd_m: Option<f64>,
    /// Steps measured.
    pub steps: usize,
    /// Steps in which the speed never turned upward (no anchoring).
    pub unanchored_steps: usize,
}

/// Summarises `steps`; `None` when there are none.
pub fn summarize(steps: &[StepMeasure]) -> Option<GaitSummary> {
    let speed = Stats::of(steps.iter().map(|s| s.speed_m_s))?;
    let step = Stats::of(steps.iter().map(|s| s.step_m))?;
    let t1 = Stats::of(steps.iter().filter_map(|s| s.anchoring_time_s));
    let slip = Stats::of(steps.iter().filter_map(|s| s.slip_m));
    Some(GaitSummary {
        speed_m_s: speed.mean,
        speed_sd_m_s: speed.sd,
        t1_s: t1.map(|t| t.mean),
        t1_sd_s: t1.and_then(|t| t.sd),
        slip_m: slip.map(|s| s.mean),
        slip_sd_m: slip.and_then(|s| s.sd),
        step_m: step.mean,
        step_sd_m: step.sd,
        steps: speed.n,
        unanchored_steps: steps.iter().filter(|s| s.anchoring_time_s.is_none()).count(),
    })
}

/// Speed against time within a stride, averaged over strides (the paper's Fig. 3b).
#[derive(Debug, Clone, PartialEq)]
pub struct StrideCurve {
    /// Time since touchdown of the first tripod, s, from 0 to T.
    pub time_s: Vec<f64>,
    /// Mean speed, m/s.
    pub mean: Vec<f64>,
    /// Standard deviation across strides, m/s (0 with a single stride).
    pub sd: Vec<f64>,
    /// Strides averaged.
    pub strides: usize,
}

/// Averages the speed over strides of period `stride_s` starting at every other touchdown
/// of each track (`tracks[i].1` are its touchdowns in time order), sampled at `points`
/// evenly spaced times from 0 to T inclusive. `None` when no whole stride exists.
pub fn stride_curve(tracks: &[(&SmoothTrack, &[f64])], stride_s: f64, points: usize) -> Option<StrideCurve> {
    let points = points.max(2);
    let time_s: Vec<f64> = (0..points).map(|j| stride_s * j as f64 / (points - 1) as f64).collect();
    let mut sum = vec![0.0; points];
    let mut sum_sq = vec![0.0; points];
    let mut strides = 0usize;
    for (track, touchdowns) in tracks {
        for &t0 in touchdowns.iter().step_by(2).filter(|&&t0| track.covers(t0, stride_s)) {
            for (j, tau) in time_s.iter().enumerate() {
                let v = track.speed_at(t0 + tau);
                sum[j] += v;
                sum_sq[j] += v * v;
            }
            strides += 1;
        }
    }
    if strides == 0 {
        return None;
    }
    let n = strides as f64;
    let mean: Vec<f64> = sum.iter().map(|s| s / n).collect();
    let sd = sum_sq
        .iter()
        .zip(&mean)
        .map(|(sq, m)| if strides > 1 { ((sq - n * m * m) / (n - 1.0)).max(0.0).sqrt() } else { 0.0 })
        .collect();
    Some(StrideCurve { time_s, mean, sd, strides })
}
