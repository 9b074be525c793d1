//! A measuring probe, not a test of a value (issue 59 item 1): the sand's force on the belly and
//! on each tripod at every integration step of a walk, written as CSV for the force balance
//! along the slope over a stride (docs/simulate.md, "What cannot hold the body at 24 degrees").
//!
//! `PROBE_SLOPE=24 PROBE_SCALING=motion PROBE_DT=0.0005 PROBE_OUT=/tmp/probe.csv cargo test
//! --release -p sandslope --lib simulate::stride_probe -- --ignored`

use super::tests::builtin_terrain;
use super::*;
use crate::model::tests::paper_robot;

fn env(key: &str, default: &str) -> String {
    std::env::var(key).unwrap_or_else(|_| default.to_string())
}

#[test]
#[ignore = "a probe that writes a CSV; run by hand"]
fn stride_probe() {
    let slope_deg: f64 = env("PROBE_SLOPE", "24").parse().unwrap();
    let dt: f64 = env("PROBE_DT", "0.0005").parse().unwrap();
    let duration: f64 = env("PROBE_DURATION", "4").parse().unwrap();
    let scaling = match env("PROBE_SCALING", "motion").as_str() {
        "components" => RftScaling::Components,
        "li2013" => RftScaling::Li2013,
        _ => RftScaling::Motion,
    };
    let pitch = if env("PROBE_PITCH", "locked") == "free" { BodyPitch::Free } else { BodyPitch::Locked };
    let out = env("PROBE_OUT", "/tmp/probe.csv");
    // PROBE_KS: one k_s at every slope (k_n 7e5), instead of the built-in terrain.
    let terrain = match std::env::var("PROBE_KS") {
        Ok(k) => crate::terrain::Terrain::constant(7e5, k.parse().unwrap()).unwrap(),
        Err(_) => builtin_terrain(),
    };
    let scenario = Scenario::new(paper_robot(), terrain, None, None).unwrap();
    let settings = SimSettings::new(duration)
        .unwrap()
        .with_dt(dt)
        .unwrap()
        .with_rft_scaling(scaling)
        .with_body_pitch(pitch);
    let slope = Slope::from_degrees(slope_deg).unwrap();
    let (ground, _) = scenario.ground_at(slope);
    let robot = scenario.robot();
    let half = robot.stance_duration();
    let n_steps = (duration / dt).round() as usize;
    let mut walker = super::tests::walker(robot, &ground, slope_deg.to_radians(), &settings, dt);
    walker.settle(settings.settle_s);
    // PROBE_RATE: the trajectory's sample rate (PROBE_TRAJ, with the pitch), Hz.
    let rate: f64 = env("PROBE_RATE", "120").parse().unwrap();
    let run = walker.run(n_steps, half, rate);
    if let Ok(path) = std::env::var("PROBE_TRAJ") {
        let tr = &run.trajectory;
        let mut csv = String::from("t_s,x_m,vx_m_s,z_m,vz_m_s,pitch_rad\n");
        for i in 0..tr.time_s.len() {
            csv.push_str(&format!(
                "{:.7},{:.9},{:.9},{:.9},{:.9},{:.9}\n",
                tr.time_s[i], tr.x_m[i], tr.vx_m_s[i], tr.z_m[i], tr.vz_m_s[i], tr.pitch_rad[i]
            ));
        }
        std::fs::write(path, csv).unwrap();
    }
    let mut csv = String::from("t_s,x_m,vx_m_s,belly_x,belly_z,t0_x,t0_z,t1_x,t1_z\n");
    for (i, g) in run.groups.iter().enumerate() {
        csv.push_str(&format!(
            "{:.6},{:.9},{:.9},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6}\n",
            (i + 1) as f64 * dt,
            run.x[i + 1],
            run.vx[i + 1],
            g.belly[0],
            g.belly[1],
            g.tripod[0][0],
            g.tripod[0][1],
            g.tripod[1][0],
            g.tripod[1][1]
        ));
    }
    std::fs::write(&out, csv).unwrap();
}
