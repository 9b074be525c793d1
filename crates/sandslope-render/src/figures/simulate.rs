//! Figures of `sandslope simulate`: one walk against time (position along the slope, each
//! leg's depth, each leg's force), simulated and closed-form speeds against slope, and the
//! side-view GIF animation (slope, sand surface, body, legs, force arrows).

use std::path::Path;

use anyhow::Result;
use plotters::coord::Shift;
use plotters::prelude::*;

use sandslope::simulate::{BodyPitch, SimSummary, Simulation};
use sandslope::{Robot, SpeedObservation};

use super::palette;
use super::{font, ChartSetup, Figure};
use crate::plot_err;
use sandslope_files::write_output;

/// Tripod colours: tripod 0 blue, tripod 1 orange (legs of one tripod share the colour,
/// front to rear from dark to light).
fn leg_colour(tripod: usize, rank: usize, n: usize) -> RGBColor {
    let RGBColor(r, g, b) = if tripod == 0 { palette::TRIPOD_A } else { palette::TRIPOD_B };
    let f = if n > 1 { 0.45 * rank as f64 / (n - 1) as f64 } else { 0.0 };
    let mix = |c: u8| (c as f64 + (255.0 - c as f64) * f) as u8;
    RGBColor(mix(r), mix(g), mix(b))
}

/// Position along the slope, leg depths and leg forces against time, stacked.
pub struct SimulateFigure<'a> {
    /// The walk.
    pub sim: &'a Simulation,
    /// The robot (for the leg reach).
    pub robot: &'a Robot,
}

type Chart<'a, DB> = super::SlopeChart<'a, DB>;

fn time_chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    title: &str,
    y_label: &str,
    t: (f64, f64),
    y: (f64, f64),
) -> Result<Chart<'a, DB>>
where
    DB::ErrorType: 'static,
{
    let setup = ChartSetup {
        caption: Some((title, 20.0)),
        margin: 10,
        x_label_area: 40,
        label_pt: 14.0,
        desc_pt: 16.0,
        x_ticks: Some(&super::tick),
        y_ticks: Some(&super::tick),
        ..ChartSetup::SLOPE
    };
    let chart = setup.build(area, t.0..t.1, y.0..y.1, "time since the gait started (s)", y_label)?;
    Ok(chart)
}

impl Figure for SimulateFigure<'_> {
    fn size(&self) -> (u32, u32) {
        (1000, 1100)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        let tr = &self.sim.trajectory;
        let m = &self.sim.summary;
        let g = &self.sim.geometry;
        let panels = root.split_evenly((3, 1));
        let t = (0.0, tr.time_s.last().copied().unwrap_or(1.0).max(1e-3));
        let legs = g.hip_x_m.len();
        let n = legs / 2;

        // Position along the slope, with touchdowns and anchoring times.
        let x_cm: Vec<f64> = tr.x_m.iter().map(|x| x * 100.0).collect();
        let xr = super::range(x_cm.iter().copied(), (0.0, 1.0));
        let title = format!(
            "{} deg: simulated {:.2} cm/s, closed form {} ({}, {})",
            m.slope_deg,
            m.speed_m_s * 100.0,
            m.closed_form.speed().map_or("-".to_string(), |v| format!("{:.2} cm/s", v * 100.0)),
            m.regime,
            m.cause.name()
        );
        let mut c = time_chart(&panels[0], &title, "position along the slope (cm)", t, xr)?;
        let grey = palette::STEP_MARK_GREY;
        for s in &m.steps {
            c.draw_series([PathElement::new(
                vec![(s.step.touchdown_s, xr.0), (s.step.touchdown_s, xr.1)],
                grey.stroke_width(1),
            )])
            .map_err(plot_err)?;
        }
        c.draw_series(LineSeries::new(
            tr.time_s.iter().copied().zip(x_cm.iter().copied()),
            BLACK.stroke_width(2),
        ))
        .map_err(plot_err)?
        .label("body (centre of mass)")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.stroke_width(2)));
        let marks: Vec<(f64, f64)> = m
            .steps
            .iter()
            .filter_map(|s| s.step.anchoring_time_s.map(|t1| s.step.touchdown_s + t1))
            .filter_map(|ta| {
                let i = tr.time_s.partition_point(|&ts| ts < ta).min(tr.time_s.len().saturating_sub(1));
                x_cm.get(i).map(|&x| (ta, x))
            })
            .collect();
        c.draw_series(marks.iter().map(|&p| Circle::new(p, 4, palette::CLOSED_FORM_RED.filled())))
            .map_err(plot_err)?
            .label("anchoring t1 (speed minimum)")
            .legend(|(x, y)| Circle::new((x + 10, y), 4, palette::CLOSED_FORM_RED.filled()));
        super::legend_box(&mut c, SeriesLabelPosition::UpperLeft, 14.0, super::LegendBox::LIGHT)?;

        // Leg depths.
        let depth_mm: Vec<Vec<f64>> =
            tr.leg_depth_m.iter().map(|d| d.iter().map(|v| v * 1e3).collect()).collect();
        let reach = self.robot.max_depth() * 1e3;
        let dr = super::range(depth_mm.iter().flatten().copied().chain([0.0, reach]), (0.0, reach));
        let mut c = time_chart(&panels[1], "Leg depth below the surface", "depth (mm)", t, dr)?;
        super::reference_line(&mut c, reach, "leg reach 2R - h: deeper means the body sank", t)?;
        for (j, depth) in depth_mm.iter().enumerate() {
            let col = leg_colour(g.tripod[j], j % n.max(1), n);
            let s = c
                .draw_series(LineSeries::new(
                    tr.time_s.iter().copied().zip(depth.iter().copied()),
                    col.stroke_width(2),
                ))
                .map_err(plot_err)?;
            if j % n.max(1) == 0 {
                let label = format!("tripod {} (front to rear: dark to light)", g.tripod[j]);
                s.label(label)
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], col.stroke_width(2)));
            }
        }
        super::legend_box(&mut c, SeriesLabelPosition::UpperRight, 14.0, super::LegendBox::LIGHT)?;

        // Leg forces: normal solid, along the slope dashed.
        let fr = super::range(
            tr.leg_force_z_n.iter().chain(&tr.leg_force_x_n).flatten().copied().chain([0.0]),
            (0.0, 1.0),
        );
        let mut c = time_chart(
            &panels[2],
            "Sand force on each leg",
            "force (N): normal solid, along slope dashed",
            t,
            fr,
        )?;
        for j in 0..legs {
            let col = leg_colour(g.tripod[j], j % n.max(1), n);
            c.draw_series(LineSeries::new(
                tr.time_s.iter().copied().zip(tr.leg_force_z_n[j].iter().copied()),
                col.stroke_width(2),
            ))
            .map_err(plot_err)?;
            c.draw_series(DashedLineSeries::new(
                tr.time_s.iter().copied().zip(tr.leg_force_x_n[j].iter().copied()),
                5,
                4,
                col.stroke_width(1),
            ))
            .map_err(plot_err)?;
        }
        Ok(())
    }
}

/// Simulated speed, the closed form's and the observed speeds against slope.
pub struct SlopesFigure<'a> {
    /// One walk per slope, in slope order.
    pub sims: &'a [SimSummary],
    /// The same walks with the body's pitch locked (drawn dashed; empty: not drawn).
    pub pitch_locked: &'a [SimSummary],
    /// Observed speeds with SDs.
    pub observed: &'a [SpeedObservation],
    /// The terrain's angle of repose.
    pub repose_deg: Option<f64>,
}

impl Figure for SlopesFigure<'_> {
    fn size(&self) -> (u32, u32) {
        (1000, 650)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        // A walk that pitched over has no speed: its step means describe a tumbling body
        // (docs/model.md §18). It is marked on the zero line, not drawn in the curve.
        let sim: Vec<(f64, f64)> = self
            .sims
            .iter()
            .filter(|m| m.pitch_over_s.is_none())
            .map(|m| (m.slope_deg, m.speed_m_s * 100.0))
            .collect();
        let tumbled: Vec<f64> =
            self.sims.iter().filter(|m| m.pitch_over_s.is_some()).map(|m| m.slope_deg).collect();
        let cf: Vec<(f64, f64)> = self
            .sims
            .iter()
            .filter_map(|m| m.closed_form.speed().map(|v| (m.slope_deg, v * 100.0)))
            .collect();
        let obs: Vec<(f64, f64, f64)> =
            self.observed.iter().map(|o| (o.slope.degrees(), o.speed * 100.0, o.speed_sd * 100.0)).collect();
        let locked: Vec<(f64, f64)> =
            self.pitch_locked.iter().map(|m| (m.slope_deg, m.speed_m_s * 100.0)).collect();
        let xr = super::range(
            sim.iter().map(|p| p.0).chain(tumbled.iter().copied()).chain(obs.iter().map(|o| o.0)),
            (0.0, 30.0),
        );
        let yr = super::range(
            sim.iter()
                .chain(&cf)
                .chain(&locked)
                .map(|p| p.1)
                .chain(obs.iter().flat_map(|o| [o.1 - o.2, o.1 + o.2]))
                .chain([0.0]),
            (0.0, 16.0),
        );
        // Headroom above the data for the legend in the upper right (in the lower left it
        // covered the tumble marks on the zero line; over the data, the pitch-locked curve).
        let yr = (yr.0, yr.1 + 0.5 * (yr.1 - yr.0));
        let setup = ChartSetup {
            caption: Some(("Step-averaged speed: simulator, closed form and observations", 22.0)),
            margin: 14,
            x_ticks: Some(&super::tick),
            y_ticks: Some(&super::tick),
            ..ChartSetup::SLOPE
        };
        let mut c = setup.build(root, xr.0..xr.1, yr.0..yr.1, "slope (deg)", "speed (cm/s)")?;
        super::shade_repose(&mut c, self.repose_deg, xr, yr, "at or above the angle of repose: slippage")?;
        if yr.0 < 0.0 {
            c.draw_series([PathElement::new(vec![(xr.0, 0.0), (xr.1, 0.0)], BLACK.stroke_width(1))])
                .map_err(plot_err)?;
        }
        let blue = palette::SIMULATED_BLUE;
        // The curve breaks at a walk that pitched over: no line bridges a tumble.
        let mut runs: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
        for m in self.sims {
            if m.pitch_over_s.is_some() {
                runs.push(Vec::new());
            } else if let Some(run) = runs.last_mut() {
                run.push((m.slope_deg, m.speed_m_s * 100.0));
            }
        }
        c.draw_series(
            runs.iter().filter(|r| !r.is_empty()).map(|r| PathElement::new(r.clone(), blue.stroke_width(3))),
        )
        .map_err(plot_err)?
        .label(if self.sims.first().is_some_and(|m| m.body_pitch == BodyPitch::Locked) {
            "simulated, pitch locked (docs/model.md §15-§18)"
        } else {
            "simulated, pitch free (one draw of a chaotic walk on slopes; docs/simulate.md)"
        })
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], blue.stroke_width(3)));
        c.draw_series(sim.iter().map(|&p| Circle::new(p, 4, blue.filled()))).map_err(plot_err)?;
        if !locked.is_empty() {
            c.draw_series(DashedLineSeries::new(locked.iter().copied(), 8, 5, blue.stroke_width(2)))
                .map_err(plot_err)?
                .label("simulated, body pitch locked (converged; the closed form's assumption)")
                .legend(move |(x, y)| {
                    // Two dashes, as the curve draws them.
                    EmptyElement::at((x, y))
                        + PathElement::new(vec![(0, 0), (8, 0)], blue.stroke_width(2))
                        + PathElement::new(vec![(13, 0), (20, 0)], blue.stroke_width(2))
                });
            c.draw_series(locked.iter().map(|&p| Circle::new(p, 3, blue.stroke_width(1))))
                .map_err(plot_err)?;
        }
        if !tumbled.is_empty() {
            let orange = palette::TUMBLE_ORANGE;
            c.draw_series(tumbled.iter().map(|&x| Cross::new((x, 0.0), 7, orange.stroke_width(3))))
                .map_err(plot_err)?
                .label("simulated body pitched over (tumbled): no speed")
                .legend(move |(x, y)| Cross::new((x + 10, y), 6, orange.stroke_width(3)));
        }
        c.draw_series(LineSeries::new(cf.iter().copied(), palette::CLOSED_FORM_RED.stroke_width(2)))
            .map_err(plot_err)?
            .label("closed form (docs/model.md §3-§6)")
            .legend(|(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], palette::CLOSED_FORM_RED.stroke_width(2))
            });
        if !obs.is_empty() {
            c.draw_series(
                obs.iter().map(|&(x, v, sd)| {
                    ErrorBar::new_vertical(x, v - sd, v, v + sd, BLACK.stroke_width(2), 10)
                }),
            )
            .map_err(plot_err)?
            .label("observed (mean ± SD)")
            .legend(|(x, y)| {
                // The error bar's own mark: an open circle on a vertical bar.
                EmptyElement::at((x + 10, y))
                    + PathElement::new(vec![(0, -7), (0, 7)], BLACK.stroke_width(2))
                    + Circle::new((0, 0), 4, BLACK.stroke_width(2))
            });
        }
        // Upper right, in the headroom: the tumble marks lie on the zero line.
        super::legend_box(&mut c, SeriesLabelPosition::UpperRight, 15.0, super::LegendBox::LIGHT)?;
        Ok(())
    }
}

/// The side-view animation of a walk.
pub struct Animation<'a> {
    /// The walk.
    pub sim: &'a Simulation,
    /// Slope, degrees (the view is rotated so the slope rises to the right).
    pub slope_deg: f64,
}

/// Frames per second of simulated time in the animation, played in real time (every sample
/// at 120 Hz would make huge files).
pub const GIF_FPS: f64 = 20.0;
/// Longest animation, s of simulated time: a longer walk is animated over its first
/// `GIF_MAX_S` seconds (`GIF_MAX_S * GIF_FPS` = 1200 frames, about 60 MB of GIF); `simulate
/// --help` and docs/simulate.md name the cap.
pub const GIF_MAX_S: f64 = 60.0;
/// Spacing of the marks on the sand, m along the slope (as the explorer's page draws them).
pub const GROUND_MARK_M: f64 = 0.05;

impl Animation<'_> {
    /// The trajectory samples drawn as frames: one per 1/[`GIF_FPS`] s of the whole walk, up
    /// to [`GIF_MAX_S`].
    pub fn frames(&self) -> Vec<usize> {
        let tr = &self.sim.trajectory;
        let rate = if tr.time_s.len() > 1 { 1.0 / (tr.time_s[1] - tr.time_s[0]) } else { GIF_FPS };
        let every = ((rate / GIF_FPS).round() as usize).max(1);
        (0..tr.time_s.len()).step_by(every).take_while(|&i| tr.time_s[i] <= GIF_MAX_S + 1e-9).collect()
    }
}

/// Writes `anim` as an animated GIF to `path`, atomically, calling `on_frame` after each frame
/// (of [`Animation::frames`]) is encoded, for a progress bar.
pub fn save_gif(path: &Path, anim: &Animation<'_>, on_frame: &mut dyn FnMut()) -> Result<()> {
    super::register_fonts();
    let frames = anim.frames();
    let delay = (1000.0 / GIF_FPS) as u32;
    write_output(path, |file| {
        let mut gif = GifWriter::new(file, GIF_SIZE, delay)?;
        let mut rgb = vec![0u8; GIF_SIZE.0 as usize * GIF_SIZE.1 as usize * 3];
        for &i in &frames {
            {
                let root = BitMapBackend::with_buffer(&mut rgb, GIF_SIZE).into_drawing_area();
                root.fill(&WHITE).map_err(plot_err)?;
                draw_frame(&root, anim, i)?;
                root.present().map_err(plot_err)?;
            }
            gif.frame(&rgb)?;
            on_frame();
        }
        Ok(())
    })
}

/// Frame size of the animation, pixels.
const GIF_SIZE: (u32, u32) = (800, 450);

/// An animated GIF written frame by frame into any writer (the `gif` crate, looping forever),
/// without a file path of its own, so that it goes through the one output writer. Each frame's
/// palette is learned by NeuQuant at sampling factor 30 (every 30th pixel), not plotters' 10:
/// learning spent 55% of `simulate --animate` (perf, 2026-12-07); at 30 a 3 s walk's GIF took
/// 1.35 s of CPU against 2.1 s (debug build, the docs test's), and its frames look the same
/// (flat fills, a few antialiased lines; frame 40 compared by eye).
struct GifWriter<W: std::io::Write> {
    encoder: gif::Encoder<W>,
    size: (u16, u16),
    /// Frame delay, hundredths of a second.
    delay: u16,
}

impl<W: std::io::Write> GifWriter<W> {
    fn new(out: W, (w, h): (u32, u32), delay_ms: u32) -> Result<Self> {
        let size = (u16::try_from(w)?, u16::try_from(h)?);
        let mut encoder = gif::Encoder::new(out, size.0, size.1, &[]).map_err(gif_err)?;
        encoder.set_repeat(gif::Repeat::Infinite).map_err(gif_err)?;
        Ok(GifWriter { encoder, size, delay: u16::try_from((delay_ms + 5) / 10).unwrap_or(u16::MAX) })
    }

    /// Appends one frame (RGB, the writer's size).
    fn frame(&mut self, rgb: &[u8]) -> Result<()> {
        let mut frame = gif::Frame::from_rgb_speed(self.size.0, self.size.1, rgb, 30);
        frame.delay = self.delay;
        self.encoder.write_frame(&frame).map_err(gif_err)
    }
}

fn gif_err(e: gif::EncodingError) -> anyhow::Error {
    anyhow::anyhow!("encoding the GIF: {e}")
}

/// One frame: world view (slope rising to the right), sand, body, legs and force arrows.
fn draw_frame<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, anim: &Animation<'_>, i: usize) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let tr = &anim.sim.trajectory;
    let g = &anim.sim.geometry;
    let (s, c) = anim.slope_deg.to_radians().sin_cos();
    let world = |p: [f64; 2]| (p[0] * c - p[1] * s, p[0] * s + p[1] * c);
    let (x, z, phi) = (tr.x_m[i], tr.z_m[i], tr.pitch_rad[i]);
    let centre = world([x, z]);
    let half_w = 0.25;
    let half_h = half_w * 450.0 / 800.0;
    let mut chart = ChartBuilder::on(root)
        .caption(
            format!(
                "t = {:.2} s, {} deg, speed {:.2} cm/s (simulated)",
                tr.time_s[i],
                anim.slope_deg,
                anim.sim.summary.speed_m_s * 100.0
            ),
            font(18.0),
        )
        .margin(8)
        .build_cartesian_2d(centre.0 - half_w..centre.0 + half_w, centre.1 - half_h..centre.1 + half_h)
        .map_err(plot_err)?;
    // Sand: the view box clipped to the half-plane below the surface line (points must stay
    // inside the view: plotters clamps points outside it, which would tilt the line).
    let view = [
        (centre.0 - half_w, centre.1 - half_h),
        (centre.0 + half_w, centre.1 - half_h),
        (centre.0 + half_w, centre.1 + half_h),
        (centre.0 - half_w, centre.1 + half_h),
    ];
    let (sand_poly, surface) = below_line(&view, (-s, c));
    let sand = palette::SAND;
    if sand_poly.len() >= 3 {
        chart.draw_series([Polygon::new(sand_poly, sand.filled())]).map_err(plot_err)?;
    }
    if surface.len() == 2 {
        chart
            .draw_series([PathElement::new(surface, palette::SAND_SURFACE.stroke_width(2))])
            .map_err(plot_err)?;
    }
    // Marks on the sand every GROUND_MARK_M along the slope, fixed to the sand (the camera
    // follows the body, so the marks are what shows it move, and slip as marks standing still
    // under an anchored leg); only marks wholly in view (plotters clamps points outside it).
    let inside = |p: Point| (p.0 - centre.0).abs() <= half_w && (p.1 - centre.1).abs() <= half_h;
    let reach = 2.0 * half_w;
    let first = ((x - reach) / GROUND_MARK_M).floor() as i64;
    let last = ((x + reach) / GROUND_MARK_M).ceil() as i64;
    let marks: Vec<Vec<Point>> = (first..=last)
        .map(|k| vec![world([k as f64 * GROUND_MARK_M, 0.0]), world([k as f64 * GROUND_MARK_M, -0.012])])
        .filter(|m| m.iter().all(|&p| inside(p)))
        .collect();
    chart
        .draw_series(marks.into_iter().map(|m| PathElement::new(m, palette::SAND_SURFACE.stroke_width(1))))
        .map_err(plot_err)?;
    // The body's path so far: its centre's trace, the part in view.
    let trace: Vec<Point> = (0..=i).map(|k| world([tr.x_m[k], tr.z_m[k]])).filter(|&p| inside(p)).collect();
    let (trace_colour, trace) = (palette::BODY_TRACE, if trace.len() >= 2 { trace } else { Vec::new() });
    chart
        .draw_series([PathElement::new(trace, trace_colour.stroke_width(2))])
        .map_err(plot_err)?
        .label("path of the body's centre (black dot)")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], trace_colour.stroke_width(2)));
    // Body: belly (h below the axle) to 0.3 h above it, pitched, drawn above the sand only: at
    // a touchdown the belly presses a few mm into the yielding sand (docs/model.md §16), which
    // drawn whole looked like the body sinking into the ground.
    let (sp, cp) = phi.sin_cos();
    let above = body_above_sand(anim, i);
    let grey = palette::DATA_GREY.mix(0.8);
    chart
        .draw_series([Polygon::new(above, grey.filled())])
        .map_err(plot_err)?
        .label("body (drawn above the sand surface)")
        .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 20, y + 5)], grey.filled()));
    let legs = g.hip_x_m.len();
    let n = (legs / 2).max(1);
    let scale = 0.02; // m of arrow per N
    legs_legend(&mut chart, n, scale)?;
    for j in 0..legs {
        let psi = tr.leg_angle_rad[j][i];
        let (sa, ca) = (phi - psi).sin_cos();
        let hip = [g.hip_x_m[j], 0.0];
        let pts: Vec<(f64, f64)> = g
            .leg_nodes_m
            .iter()
            .map(|p| {
                let r = [ca * p[0] - sa * p[1], sa * p[0] + ca * p[1]];
                let hp = [cp * hip[0] - sp * hip[1], sp * hip[0] + cp * hip[1]];
                world([x + hp[0] + r[0], z + hp[1] + r[1]])
            })
            .collect();
        let col = leg_colour(g.tripod[j], j % n, n);
        let width = if g.tripod[j] == 0 { 4 } else { 3 };
        chart.draw_series([PathElement::new(pts.clone(), col.stroke_width(width))]).map_err(plot_err)?;
        let (fx, fz) = (tr.leg_force_x_n[j][i], tr.leg_force_z_n[j][i]);
        if fx.hypot(fz) > 0.05 {
            // Arrow from the leg's lowest point, in the slope frame turned into the world.
            let lowest = pts
                .iter()
                .copied()
                .min_by(|p, q| (-p.0 * s + p.1 * c).total_cmp(&(-q.0 * s + q.1 * c)))
                .unwrap_or(centre);
            let tip = (lowest.0 + scale * (fx * c - fz * s), lowest.1 + scale * (fx * s + fz * c));
            chart
                .draw_series([PathElement::new(vec![lowest, tip], palette::CLOSED_FORM_RED.stroke_width(2))])
                .map_err(plot_err)?;
            chart.draw_series([Circle::new(tip, 3, palette::CLOSED_FORM_RED.filled())]).map_err(plot_err)?;
        }
    }
    chart.draw_series([Circle::new(world([x, z]), 4, BLACK.filled())]).map_err(plot_err)?;
    super::legend_box(&mut chart, SeriesLabelPosition::UpperLeft, 12.0, super::LegendBox::LIGHT)?;
    Ok(())
}

/// The body's box in frame `i` as drawn, in the world view (m): belly (h below the axle) to
/// 0.3 h above it, pitched, clipped to the half-plane above the sand surface.
fn body_above_sand(anim: &Animation<'_>, i: usize) -> Vec<Point> {
    let (tr, g) = (&anim.sim.trajectory, &anim.sim.geometry);
    let (s, c) = anim.slope_deg.to_radians().sin_cos();
    let (x, z, (sp, cp)) = (tr.x_m[i], tr.z_m[i], tr.pitch_rad[i].sin_cos());
    let body = |p: [f64; 2]| {
        let q = [x + cp * p[0] - sp * p[1], z + sp * p[0] + cp * p[1]];
        (q[0] * c - q[1] * s, q[0] * s + q[1] * c)
    };
    let (l, h) = (g.body_length_m, g.hip_height_m);
    let corners = [[-l / 2.0, -h], [l / 2.0, -h], [l / 2.0, 0.3 * h], [-l / 2.0, 0.3 * h]];
    let outline: Vec<Point> = corners.iter().map(|&p| body(p)).collect();
    below_line(&outline, (s, -c)).0
}

/// The animation legend's entries for the legs of each tripod and the sand's force on a leg
/// (`scale` m of arrow per N), as empty series: the marks themselves are drawn per leg.
fn legs_legend<'a, DB: DrawingBackend + 'a>(
    chart: &mut super::SlopeChart<'a, DB>,
    n: usize,
    scale: f64,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    for (tripod, name) in [(0, "tripod A legs"), (1, "tripod B legs")] {
        let col = leg_colour(tripod, 0, n);
        chart
            .draw_series(std::iter::empty::<PathElement<Point>>())
            .map_err(plot_err)?
            .label(name)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], col.stroke_width(3)));
    }
    chart
        .draw_series(std::iter::empty::<PathElement<Point>>())
        .map_err(plot_err)?
        .label(format!("sand's force on a leg ({:.0} mm per N)", scale * 1e3))
        .legend(|(x, y)| {
            EmptyElement::at((x, y))
                + PathElement::new(vec![(0, 0), (16, 0)], palette::CLOSED_FORM_RED.stroke_width(2))
                + Circle::new((17, 0), 3, palette::CLOSED_FORM_RED.filled())
        });
    Ok(())
}

/// A point of the animation's world view, m.
type Point = (f64, f64);

/// The part of polygon `poly` where `n . p <= 0` (Sutherland-Hodgman against one half-plane
/// through the origin), and the points where its boundary crosses the line `n . p = 0`.
fn below_line(poly: &[Point], n: Point) -> (Vec<Point>, Vec<Point>) {
    let side = |p: (f64, f64)| n.0 * p.0 + n.1 * p.1;
    let mut out = Vec::new();
    let mut crossings = Vec::new();
    for (k, &a) in poly.iter().enumerate() {
        let b = poly[(k + 1) % poly.len()];
        let (sa, sb) = (side(a), side(b));
        if sa <= 0.0 {
            out.push(a);
        }
        if (sa < 0.0) != (sb < 0.0) && sa != sb {
            let t = sa / (sa - sb);
            let p = (a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1));
            out.push(p);
            crossings.push(p);
        }
    }
    (out, crossings)
}

#[cfg(test)]
mod tests {
    use super::*;
    use sandslope::simulate::{simulate, SimSettings};
    use sandslope::{Robot, RobotSpec, Scenario, Terrain};

    /// Frames of the animation draw (written as PNG to the temp folder, for looking at), and
    /// the GIF holds every 6th sample of 120 Hz (20 frames/s) up to 6 s.
    #[test]
    fn the_sand_is_the_view_below_the_surface_line() {
        // A unit box centred on the origin cut by a 45 degree line: the lower-right triangle.
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let (poly, line) = below_line(&[(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)], (-h, h));
        assert_eq!(line.len(), 2);
        assert!(poly.iter().all(|p| p.1 <= p.0 + 1e-12), "{poly:?}");
        assert!(poly.contains(&(1.0, -1.0)) && !poly.contains(&(-1.0, 1.0)));
    }

    fn walk(slope_deg: f64, duration_s: f64) -> Simulation {
        let robot = Robot::new(RobotSpec::paper_hexapod()).unwrap();
        let s = Scenario::new(robot, Terrain::constant(7e5, 2e6).unwrap(), None, None).unwrap();
        simulate(
            &s,
            sandslope::SignedSlope::from_degrees(slope_deg).unwrap(),
            &SimSettings::new(duration_s).unwrap(),
        )
        .unwrap()
    }

    /// One frame as RGB pixels, 800 x 450.
    fn frame_rgb(anim: &Animation<'_>, i: usize) -> Vec<u8> {
        super::super::register_fonts();
        let mut rgb = vec![0u8; 800 * 450 * 3];
        {
            let root = BitMapBackend::with_buffer(&mut rgb, GIF_SIZE).into_drawing_area();
            root.fill(&WHITE).unwrap();
            draw_frame(&root, anim, i).unwrap();
            root.present().unwrap();
        }
        rgb
    }

    fn is(rgb: &[u8], col: usize, row: usize, c: RGBColor) -> bool {
        let k = 3 * (row * 800 + col);
        rgb[k..k + 3] == [c.0, c.1, c.2]
    }

    /// The whole walk is animated (a 7 s walk at 120 Hz: 7 s x 20 frames/s + the frame at
    /// t = 0 = 141 frames, every 6th sample, the last at 7.00 s), not its first 6 s.
    #[test]
    fn the_whole_walk_is_animated() {
        let sim = walk(10.0, 7.0);
        let anim = Animation { sim: &sim, slope_deg: 10.0 };
        let frames = anim.frames();
        assert_eq!(frames.len(), 141);
        assert!(frames.windows(2).all(|w| w[1] - w[0] == 6), "{frames:?}");
        assert!((sim.trajectory.time_s[*frames.last().unwrap()] - 7.0).abs() < 1e-9);
    }

    /// On level sand the marks stand vertical below the surface, one every 5 cm: at 800 px
    /// less two 8 px margins for a 0.5 m wide view, 784 px / 0.5 m x 0.05 m = 78.4 px apart.
    /// They are fixed to the sand: a mark's pixel plus the body's advance in pixels is the
    /// same, modulo 78.4 px, in every frame. The body's trace shows once the body has moved.
    #[test]
    fn ground_marks_every_5_cm_fixed_to_the_sand_and_the_trace() {
        let sim = walk(0.0, 1.5);
        let anim = Animation { sim: &sim, slope_deg: 0.0 };
        let px_per_m = 784.0 / 0.5;
        let spacing = GROUND_MARK_M * px_per_m;
        let mut phases = Vec::new();
        for i in [0usize, 90, 174] {
            let rgb = frame_rgb(&anim, i);
            // The surface: the first sand-surface pixel down the left edge's column 20.
            let top = (0..450).find(|&r| is(&rgb, 20, r, palette::SAND_SURFACE)).expect("surface line");
            let row = top + 6;
            let cols: Vec<usize> = (0..800).filter(|&c| is(&rgb, c, row, palette::SAND_SURFACE)).collect();
            // Runs of mark pixels, by their centres.
            let mut centres: Vec<f64> = Vec::new();
            let mut run: Vec<usize> = Vec::new();
            for &c in &cols {
                if run.last().is_some_and(|&l| c != l + 1) {
                    centres.push(run.iter().sum::<usize>() as f64 / run.len() as f64);
                    run.clear();
                }
                run.push(c);
            }
            if !run.is_empty() {
                centres.push(run.iter().sum::<usize>() as f64 / run.len() as f64);
            }
            assert!(centres.len() >= 6, "frame {i}: marks at {centres:?}");
            for w in centres.windows(2) {
                let n = (w[1] - w[0]) / spacing;
                assert!((n - n.round()).abs() < 0.03 && n.round() >= 1.0, "frame {i}: {centres:?}");
            }
            let shift = sim.trajectory.x_m[i] * px_per_m;
            phases.push((centres[0] + shift).rem_euclid(spacing));
            // (Outside the legend in the upper left, whose swatch has the trace's colour.)
            let legend = |k: usize| k % 800 < 320 && k / 800 < 160;
            let traced =
                (0..800 * 450).any(|k| !legend(k) && is(&rgb, k % 800, k / 800, palette::BODY_TRACE));
            assert_eq!(traced, i > 0, "frame {i}: trace drawn {traced}");
        }
        assert!(sim.trajectory.x_m[174] - sim.trajectory.x_m[0] > 0.1, "the walk must move");
        for p in &phases {
            let d = (p - phases[0]).abs();
            assert!(d.min(spacing - d) < 1.5, "marks move with the camera, not the sand: {phases:?}");
        }
    }

    /// The frame's legend names what is drawn, and the body is drawn above the sand only: in a
    /// 1.5 s walk at 10 degrees whose belly reaches into the sand (checked from the trajectory),
    /// every corner of the drawn body lies on or above the surface line in every frame; and
    /// the legend's box in the upper left holds the swatch of every mark: the trace's purple,
    /// the tripods' blue and orange and the force's red.
    #[test]
    fn the_legend_names_every_mark_and_the_body_stays_above_the_sand() {
        let sim = walk(10.0, 1.5);
        let anim = Animation { sim: &sim, slope_deg: 10.0 };
        // How far the belly's lowest corner lies below the surface in each frame, m, from the
        // trajectory alone (slope frame): z - h cos(phi) - (L/2) |sin(phi)|.
        let (tr, g) = (&sim.trajectory, &sim.geometry);
        let dip = |i: usize| {
            let phi = tr.pitch_rad[i];
            -(tr.z_m[i] - g.hip_height_m * phi.cos() - 0.5 * g.body_length_m * phi.sin().abs())
        };
        let deepest = anim.frames().into_iter().max_by(|&a, &b| dip(a).total_cmp(&dip(b))).unwrap();
        assert!(dip(deepest) > 0.0, "the walk's belly never reaches into the sand: nothing to test");
        // Drawn, every corner of the body lies on or above the surface line (n . p >= 0 with
        // n = (-sin, cos) of the slope in the world view).
        let (s, c) = 10f64.to_radians().sin_cos();
        for i in anim.frames() {
            let body = body_above_sand(&anim, i);
            assert!(body.len() >= 3, "frame {i}");
            assert!(body.iter().all(|p| -s * p.0 + c * p.1 >= -1e-12), "frame {i}: {body:?}");
        }
        let rgb = frame_rgb(&anim, 0);
        let in_legend = |c: RGBColor| (0..160).any(|r| (0..320).any(|col| is(&rgb, col, r, c)));
        for c in [palette::BODY_TRACE, palette::TRIPOD_A, palette::TRIPOD_B, palette::CLOSED_FORM_RED] {
            assert!(in_legend(c), "{c:?} missing from the legend");
        }
    }

    #[test]
    fn animation_frames_draw_and_the_gif_is_written() {
        let robot = Robot::new(RobotSpec::paper_hexapod()).unwrap();
        let s = Scenario::new(robot, Terrain::constant(7e5, 2e6).unwrap(), None, None).unwrap();
        let fifteen = sandslope::SignedSlope::from_degrees(15.0).unwrap();
        let sim = simulate(&s, fifteen, &SimSettings::new(2.0).unwrap()).unwrap();
        let anim = Animation { sim: &sim, slope_deg: 15.0 };
        // A directory of its own: concurrent test runs (two checkouts) shared fixed names in
        // /tmp and removed each other's files.
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path();
        for i in [30usize, 54] {
            let rgb = frame_rgb(&anim, i);
            assert!(rgb.chunks(3).filter(|p| p != &[255, 255, 255]).count() > 800 * 450 / 10, "frame {i}");
        }
        let gif = dir.join("sandslope-sim-test.gif");
        let mut frames = 0;
        save_gif(&gif, &anim, &mut || frames += 1).unwrap();
        assert_eq!(frames, anim.frames().len());
        let bytes = std::fs::read(&gif).unwrap();
        assert_eq!(&bytes[..6], b"GIF89a");
    }
}
