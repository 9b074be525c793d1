//! The report's inputs table: what the report was made from, each with its provenance.

use sandslope::report::{Evidence, ForceTests, Input, Provenance, ProvenanceKind};

use super::sci;

fn row(name: &str, value: impl Into<String>, kind: ProvenanceKind, detail: impl Into<String>) -> Input {
    Input { name: name.into(), value: value.into(), provenance: Provenance { kind, detail: detail.into() } }
}

use ProvenanceKind::{Assumed, Derived, Measured, Tuned};

/// The robot's rows: on the built-in robot one per group of keys, else the user's file.
fn robot_rows(e: &Evidence) -> Vec<Input> {
    let r = &e.robot;
    if !e.builtin_robot {
        return vec![row(
            "robot",
            e.robot_source.clone(),
            Assumed,
            "your robot file: sandslope cannot tell which of its values were measured",
        )];
    }
    vec![
        row(
            "robot: m, R, W, ω, n",
            format!(
                "{} ({} kg, R = {} cm, W = {} cm, ω = {} rad/s, n = {} legs in stance)",
                e.robot_source,
                r.mass(),
                r.leg_radius() * 100.0,
                r.leg_width() * 100.0,
                if (r.leg_speed() - std::f64::consts::TAU).abs() < 1e-12 { "2π".to_string() } else { format!("{:.4}", r.leg_speed()) },
                r.stance_legs()
            ),
            Measured,
            "the paper, Sec. II-A (robot) and Sec. III-D (alternating tripod, n = 3)",
        ),
        row(
            "robot: response time Δt",
            format!("{} s", r.response_time()),
            Measured,
            "the paper, Sec. III-D (\"characteristic elastic response time\", after Li et al. 2009)",
        ),
        row(
            "robot: hip height h",
            format!("{} m", r.hip_height()),
            Tuned,
            "not reported by the paper; chosen so that the level-sand speed ceiling s*/(T/2) sits just above the observed 15.7 cm/s at 0°",
        ),
        row(
            "robot: leg contact area A_c",
            format!("{} m² (W R)", sci(r.contact_area(), 1)),
            Assumed,
            "not reported by the paper; docs/model.md §2 takes W R",
        ),
        row(
            "robot: stride period T",
            format!("{} s (T/2 = {} s)", r.stride_period(), r.stance_duration()),
            Derived,
            "T = 2π/ω from the paper's leg speed",
        ),
    ]
}

/// The terrain's rows.
fn terrain_rows(e: &Evidence) -> Vec<Input> {
    if !e.builtin_terrain {
        return vec![row(
            "terrain",
            e.terrain_source.clone(),
            Assumed,
            "your terrain file: sandslope cannot tell which of its values were measured",
        )];
    }
    // With the user's observations the page's model is calibrated on them, not on the paper's
    // speeds (one calibration drives the page, issue 28).
    let k_s = if e.has_own_observations() {
        let forces = match e.forces {
            ForceTests::Given { .. } => "your force tests",
            ForceTests::Paper(_) => "the paper's force-test ratio",
            ForceTests::None => "the terrain's own k_s shape",
        };
        row(
            "terrain: leg k_s(θ)",
            format!("{}, recalibrated", e.terrain_source),
            Tuned,
            format!("the joint calibration on your observations (below) and {forces} (docs/calibration.md): plate_scale and a model-error floor fitted"),
        )
    } else {
        row(
            "terrain: leg k_s(θ)",
            e.terrain_source.clone(),
            Tuned,
            "the joint calibration on the paper's five speeds and its force-test ratio (docs/calibration.md): plate_scale and a model-error floor fitted",
        )
    };
    vec![
        k_s,
        row(
            "terrain: k_n",
            "7 × 10⁵ N/m³ at every slope",
            Assumed,
            "the paper prints no k_n; its constancy with slope is the paper's (Sec. III-B), its level an order-of-magnitude value",
        ),
        row("terrain: angle of repose", "25°", Measured, "the paper, Sec. II-C footnote (\"25° approaches the angle of repose\")"),
    ]
}

/// The evidence's rows: speeds, force tests, anchoring times, tracks.
fn evidence_rows(e: &Evidence, tracks_give_t1: bool) -> Vec<Input> {
    let tracks = &e.tracks;
    let mut out = vec![match (&e.observed, tracks.is_empty()) {
        (Some((p, _)), _) => row("observed speeds", p.clone(), Measured, "your measurements"),
        (None, false) => row(
            "observed speeds",
            "the motion-capture tracks' (mean ± SD per slope, --tracks)",
            Measured,
            "your recordings, analysed as sandslope track does (docs/model.md §11)",
        ),
        (None, true) if !sandslope::paper::is_papers_robot(&e.robot) => row(
            "observed speeds",
            "none (the paper's five are of its 0.35 kg robot, not yours)",
            Assumed,
            "give your robot's measured speeds with --observed to test the model on it",
        ),
        (None, true) => row(
            "observed speeds",
            "the paper's five (docs/model.md §12)",
            Measured,
            "the paper, Sec. III-A and Fig. 3a (means and SDs as printed)",
        ),
    }];
    out.extend(match &e.forces {
        ForceTests::Given { source, .. } => vec![row("force tests", source.clone(), Measured, "your measurements")],
        ForceTests::Paper(_) => vec![
            row(
                "force tests: k_s(20°)/k_s(0)",
                "0.40 (data/example-force-tests.toml)",
                Measured,
                "the paper, Sec. III-C (\"approximately 40%\"); its Fig. 4d/h values are not printed",
            ),
            row(
                "force tests: levels and SDs",
                "plate k_s(0) = 1 × 10⁵ N/m³, k_n = 7 × 10⁵ N/m³; SDs 15% (k_s), 10% (k_n)",
                Assumed,
                "not in the paper: order-of-magnitude values for loose glass beads; with plate_scale free only the ratio and its SD matter",
            ),
        ],
        ForceTests::None => vec![row(
            "force tests",
            "the terrain's own table",
            Derived,
            "none given: the terrain's k_s shape is the one calibrated",
        )],
    });
    let mut t1_sources: Vec<String> = e.anchoring.iter().map(|(p, _)| p.clone()).collect();
    if tracks_give_t1 {
        t1_sources.push("the motion-capture tracks (--tracks)".into());
    }
    if !t1_sources.is_empty() {
        out.push(row("anchoring times", t1_sources.join(" and "), Measured, "your measurements"));
    }
    for t in tracks {
        out.push(row(
            &format!("motion capture at {}°", t.slope_deg),
            t.files.join(", "),
            Measured,
            "your recordings",
        ));
    }
    if !tracks.is_empty() {
        let r = &e.track_reading;
        out.push(row(
            "motion-capture reading",
            format!(
                "format {}; body {}; upslope {}; stride period T = {} s (the robot's)",
                r.format.as_deref().unwrap_or("detected per file"),
                r.body.as_deref().unwrap_or("chosen per file (no --tracks-body)"),
                r.upslope.map_or("estimated per slope from the travel".to_string(), |v| {
                    format!("[{:.3}, {:.3}, {:.3}]", v[0], v[1], v[2])
                }),
                e.robot.stride_period()
            ),
            Derived,
            "the flags given and the robot's leg speed",
        ));
    }
    out
}

/// The inputs table: what the report was made from, each with its provenance.
pub(super) fn inputs(e: &Evidence, tracks_give_t1: bool) -> Vec<Input> {
    let mut out = robot_rows(e);
    out.extend(terrain_rows(e));
    out.extend(evidence_rows(e, tracks_give_t1));
    out
}
