//! The windowed reading of the corridor search against the whole grid's (issue 56): the same
//! coarse grid, corridor heights and Horn gradients bit for bit, and the same routes, while
//! reading only the corridor's windows.

use std::ops::{ControlFlow, Range};
use std::sync::atomic::{AtomicUsize, Ordering};

use super::*;
use crate::model::tests::paper_robot;
use crate::plan::corridor::tests::{dunes, terrain};
use crate::plan::{
    plan_corridor, plan_corridor_from, risk_map_from, Cell, CorridorSettings, PlanError, PlanRequest,
    PlanSettings, Planner,
};

/// A grid read through windows, bands of `band` rows, counting the cells read.
struct Windowed {
    grid: ElevationGrid,
    band: usize,
    read: AtomicUsize,
}

impl HeightSource for Windowed {
    fn cols(&self) -> usize {
        self.grid.cols()
    }
    fn rows(&self) -> usize {
        self.grid.rows()
    }
    fn cell_x(&self) -> f64 {
        self.grid.cell_x()
    }
    fn cell_y(&self) -> f64 {
        self.grid.cell_y()
    }
    fn row_widths(&self) -> Option<&[f64]> {
        self.grid.row_widths()
    }
    fn window(&self, rows: Range<usize>, cols: Range<usize>) -> Result<Vec<f32>, String> {
        self.read.fetch_add(rows.len() * cols.len(), Ordering::Relaxed);
        HeightSource::window(&self.grid, rows, cols)
    }
    fn band_rows(&self) -> usize {
        self.band
    }
}

fn windowed(grid: ElevationGrid, band: usize) -> Windowed {
    Windowed { grid, band, read: AtomicUsize::new(0) }
}

/// A bumpy 75 x 61 grid with nodata and rows of different widths (sizes no factor divides).
fn bumpy(widths: bool) -> ElevationGrid {
    let (cols, rows) = (75, 61);
    let z: Vec<f32> = (0..cols * rows)
        .map(|i| {
            let (c, r) = ((i % cols) as f32, (i / cols) as f32);
            (0.37 * c).sin() * 3.0 + (0.21 * r * c).cos() + 0.013 * r * r
        })
        .collect();
    let mask: Vec<bool> = (0..cols * rows).map(|i| i % 31 == 7 || (600..640).contains(&i)).collect();
    let g = ElevationGrid::new(cols, rows, 0.8, 0.9, z, Some(&mask)).unwrap();
    if widths {
        g.with_row_widths((0..rows).map(|r| 0.7 + 0.01 * r as f64).collect()).unwrap()
    } else {
        g
    }
}

#[test]
fn the_streamed_coarse_grid_is_the_whole_grid_s_bit_for_bit() {
    for widths in [false, true] {
        let g = bumpy(widths);
        for (factor, band) in [(2, 1), (4, 5), (8, 256), (3, 7), (64, 3)] {
            let want = g.coarsened(factor);
            let got = coarsened_from(&windowed(g.clone(), band), factor);
            match (want, got) {
                (Ok(w), Ok(s)) => {
                    let bits =
                        |g: &ElevationGrid| g.heights().iter().map(|h| h.to_bits()).collect::<Vec<_>>();
                    assert_eq!(
                        (w.cols(), w.rows(), w.cell_x(), w.cell_y()),
                        (s.cols(), s.rows(), s.cell_x(), s.cell_y())
                    );
                    assert_eq!(w.row_widths(), s.row_widths());
                    assert_eq!(bits(&w), bits(&s), "factor {factor}, band {band}");
                    assert_eq!(
                        (0..w.len()).map(|i| w.is_valid(i)).collect::<Vec<_>>(),
                        (0..s.len()).map(|i| s.is_valid(i)).collect::<Vec<_>>()
                    );
                }
                (Err(_), Err(_)) => {}
                (w, s) => panic!("factor {factor}: {w:?} vs {s:?}"),
            }
        }
    }
}

/// Corridor planners read window by window hold the heights and Horn gradients the whole
/// grid's planner holds (`Planner::corridor`, cell by cell from the grid), for corridors along
/// the map's borders (where a window has no margin) and across nodata.
#[test]
fn windowed_corridors_hold_the_whole_grid_s_heights_and_gradients() {
    for widths in [false, true] {
        let g = bumpy(widths);
        let routes: [Vec<Cell>; 3] = [
            (0..19).map(|i| Cell { col: i, row: i.min(15) }).collect(),
            (0..19).map(|i| Cell { col: 18 - i, row: 0 }).collect(),
            vec![Cell { col: 18, row: 15 }],
        ];
        for route in &routes {
            for half_width in [1, 2] {
                let settings = CorridorSettings::new(4, half_width, None).unwrap();
                let req = PlanRequest {
                    start: Cell { col: 1, row: 1 },
                    goal: Cell { col: 73, row: 59 },
                    objectives: vec![],
                    risk_map: false,
                };
                let (layout, spans) =
                    super::super::corridor::corridor_layout_for_tests((75, 61), route, &req, &settings);
                let cache = crate::plan::PitchTableCache::new();
                let build = |from: Option<&Windowed>| {
                    let args = (&[terrain()][..], &paper_robot(), PlanSettings::default(), &cache);
                    match from {
                        Some(src) => Planner::corridor_from(
                            src,
                            layout.clone(),
                            &spans,
                            args.0,
                            args.1,
                            args.2,
                            args.3,
                        ),
                        None => Planner::corridor(&g, layout.clone(), &spans, args.0, args.1, args.2, args.3),
                    }
                    .unwrap()
                };
                let want = build(None);
                let src = windowed(g.clone(), 256);
                let got = build(Some(&src));
                let bits = |p: &Planner| p.grid().heights().iter().map(|h| h.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&want), bits(&got));
                let grads = |p: &Planner| p.grad.iter().map(|g| g.map(f32::to_bits)).collect::<Vec<_>>();
                assert_eq!(grads(&want), grads(&got), "{route:?} {half_width}");
                let finite = want.grad.iter().filter(|g| !g[0].is_nan()).count();
                assert!(finite > 20, "{finite}");
            }
        }
    }
}

/// The corridor search on a map read window by window plans the routes the in-memory search
/// plans, and reads only the coarse pass's one sweep and the corridors' windows.
#[test]
fn the_windowed_corridor_search_plans_the_in_memory_routes_reading_only_its_corridor() {
    let grid = dunes(160);
    let (s, t) = (Cell { col: 5, row: 150 }, Cell { col: 150, row: 8 });
    let settings = CorridorSettings::new(8, 2, None).unwrap();
    let req =
        PlanRequest { start: s, goal: t, objectives: vec![crate::plan::Objective::Time], risk_map: false };
    let go = |_: crate::plan::Objective, _: u64, _: u64| ControlFlow::Continue(());
    let robot = paper_robot();
    let want =
        plan_corridor(&grid, &terrain(), &robot, PlanSettings::default(), &req, &settings, &go).unwrap();
    let src = windowed(grid.clone(), 16);
    let got =
        plan_corridor_from(&src, &terrain(), &robot, PlanSettings::default(), &req, &settings, &go).unwrap();
    assert_eq!(format!("{:?}", want.routes), format!("{:?}", got.routes));
    assert_eq!(want.corridors, got.corridors);
    // One sweep of the map for the coarse grid (160 x 160 = 25 600 cells), then each
    // corridor's windows: bands of 64 rows, each the bounding box of its rows' spans with a
    // margin of one cell, so more than the corridors' cells but less than twice as many (a
    // diagonal corridor's band is its width plus the band's rows wide).
    let read = src.read.load(Ordering::Relaxed);
    let corridor_cells: usize = got.corridors.iter().map(|c| c.corridor_cells).sum();
    assert!(got.corridors.iter().all(|c| !c.whole), "{:?}", got.corridors);
    assert!(
        read >= 25_600 + corridor_cells && read - 25_600 < 2 * corridor_cells,
        "{read} cells read, corridors {corridor_cells}"
    );
}

/// The optimality gap each corridor route states (issue 56): its lower bound is at most the
/// full search's optimum on the map (planned here at full resolution, the independent
/// reference), its cost is the route's, and so the stated bound on the gap is at least the
/// route's real excess over the optimum; a corridor that is the whole map states 0.
#[test]
fn every_corridor_route_states_a_gap_bound_that_holds() {
    // Also with rows of different widths, narrowing fivefold to the north as towards a pole
    // (the bound takes the narrowest row a route could reach).
    let widths: Vec<f64> = (0..96).map(|r| 0.1 + 0.4 * r as f64 / 95.0).collect();
    for grid in [dunes(96), dunes(96).with_row_widths(widths).unwrap()] {
        gap_bounds_hold(grid);
    }
}

fn gap_bounds_hold(grid: ElevationGrid) {
    let (s, t) = (Cell { col: 4, row: 90 }, Cell { col: 90, row: 40 });
    let robot = paper_robot();
    let full = Planner::new(grid.clone(), None, &[terrain()], &robot, PlanSettings::default()).unwrap();
    let go = |_: crate::plan::Objective, _: u64, _: u64| ControlFlow::Continue(());
    for (half_width, whole) in [(1, false), (64, true)] {
        let settings = CorridorSettings::new(4, half_width, None).unwrap();
        let objectives = vec![crate::plan::Objective::Time, crate::plan::Objective::Risk];
        let req = PlanRequest { start: s, goal: t, objectives, risk_map: false };
        let plan =
            plan_corridor(&grid, &terrain(), &robot, PlanSettings::default(), &req, &settings, &go).unwrap();
        for (stats, (obj, route)) in plan.corridors.iter().zip(&plan.routes) {
            let best = full.route(*obj, s, t, &|_| ControlFlow::Continue(())).unwrap().unwrap();
            let optimum = full.cost_of_route_for_tests(*obj, &best.cells);
            let cost = full.cost_of_route_for_tests(*obj, &route.as_ref().unwrap().cells);
            assert_eq!(stats.whole, whole);
            assert!((stats.cost.unwrap() - cost).abs() <= 1e-9 * cost, "{obj:?}: {:?} vs {cost}", stats.cost);
            assert!(
                stats.lower_bound > 0.0 && stats.lower_bound <= optimum,
                "{obj:?}: {} vs {optimum}",
                stats.lower_bound
            );
            let gap = stats.gap_at_most.unwrap();
            assert!(gap >= cost / optimum - 1.0 - 1e-12, "{obj:?}: {gap} vs {}", cost / optimum - 1.0);
            if whole {
                assert_eq!(gap, 0.0);
            }
        }
    }
}

/// The risk raster computed band by band from a windowed source is the whole grid's
/// [`Planner::risk_map`] bit for bit, for uniform grids and grids of per-row widths, with
/// nodata, for steep and gentle maps and for bands of 1 row to more than the map.
#[test]
fn the_streamed_risk_map_is_the_in_memory_one_bit_for_bit() {
    let (robot, t) = (paper_robot(), terrain());
    for widths in [false, true] {
        for scale in [1.0_f32, 0.15] {
            let g = bumpy(widths);
            let z: Vec<f32> = g.heights().iter().map(|h| h * scale).collect();
            let mask: Vec<bool> = (0..g.len()).map(|i| !g.is_valid(i)).collect();
            let mut grid =
                ElevationGrid::new(g.cols(), g.rows(), g.cell_x(), g.cell_y(), z, Some(&mask)).unwrap();
            if let Some(w) = g.row_widths() {
                grid = grid.with_row_widths(w.to_vec()).unwrap();
            }
            let settings = PlanSettings::default();
            let whole = Planner::new(grid.clone(), None, std::slice::from_ref(&t), &robot, settings).unwrap();
            let (want_p, want_a) = whole.risk_map();
            // Some cells are passable and some are not: the test compares values, not NaNs alone.
            let finite = want_p.iter().filter(|p| p.is_finite()).count();
            assert!(finite > 100 && finite < want_p.len(), "{finite} finite cells");
            for band in [1, 2, 5, 16, 61, 500] {
                let source = windowed(grid.clone(), band);
                let (mut got_p, mut got_a, mut next) = (Vec::new(), Vec::new(), 0);
                risk_map_from::<PlanError>(&source, &t, &robot, settings, band, |rows, p, a| {
                    assert_eq!(rows.start, next);
                    assert_eq!(p.len(), rows.len() * grid.cols());
                    next = rows.end;
                    got_p.extend_from_slice(p);
                    got_a.extend_from_slice(a);
                    Ok(())
                })
                .unwrap();
                let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(
                    bits(&got_p),
                    bits(&want_p),
                    "p_fail, widths {widths}, scale {scale}, band {band}"
                );
                assert_eq!(
                    bits(&got_a),
                    bits(&want_a),
                    "azimuth, widths {widths}, scale {scale}, band {band}"
                );
                // Each band reads its rows and at most two rows of margin.
                let read = source.read.load(Ordering::Relaxed);
                assert!(read <= grid.len() + 2 * grid.cols() * grid.rows().div_ceil(band) + 2 * grid.cols());
            }
        }
    }
}

#[test]
fn a_failing_read_stops_the_streamed_risk_map_with_its_error() {
    struct Broken(ElevationGrid);
    impl HeightSource for Broken {
        fn cols(&self) -> usize {
            self.0.cols()
        }
        fn rows(&self) -> usize {
            self.0.rows()
        }
        fn cell_x(&self) -> f64 {
            self.0.cell_x()
        }
        fn cell_y(&self) -> f64 {
            self.0.cell_y()
        }
        fn row_widths(&self) -> Option<&[f64]> {
            None
        }
        fn window(&self, rows: Range<usize>, _: Range<usize>) -> Result<Vec<f32>, String> {
            Err(format!("rows {rows:?}: tile 3 at byte 4096 is past the end of the file"))
        }
    }
    let mut bands = 0;
    let err = risk_map_from::<PlanError>(
        &Broken(bumpy(false)),
        &terrain(),
        &paper_robot(),
        PlanSettings::default(),
        8,
        |_, _, _| {
            bands += 1;
            Ok(())
        },
    )
    .unwrap_err();
    assert_eq!(bands, 0);
    assert!(err.to_string().contains("at byte 4096"), "{err}");
}
