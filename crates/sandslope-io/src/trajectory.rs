//! A simulated walk as motion capture (docs/model.md §18): the body's centre in the world
//! frame in the plain CSV format (`time_s,x_m,y_m,z_m`) that `track` reads, so a simulated
//! walk is measured exactly as a lab recording.

use std::fmt::Write as _;

use sandslope::simulate::Trajectory;

/// The plain motion-capture CSV of `trajectory` on a slope of `slope_deg`: world x horizontal
/// (upslope), z vertical, y = 0, from the slope frame by `X = x cos theta - z sin theta`,
/// `Z = x sin theta + z cos theta`. Numbers are printed with ryu's shortest round-trip form.
pub fn plain_mocap_csv(trajectory: &Trajectory, slope_deg: f64) -> String {
    let (s, c) = slope_deg.to_radians().sin_cos();
    let mut out = String::with_capacity(48 * (trajectory.time_s.len() + 1));
    out.push_str("time_s,x_m,y_m,z_m\n");
    let mut buf = ryu::Buffer::new();
    for ((t, x), z) in trajectory.time_s.iter().zip(&trajectory.x_m).zip(&trajectory.z_m) {
        let (wx, wz) = (x * c - z * s, x * s + z * c);
        let _ = write!(out, "{},", buf.format(*t));
        let _ = write!(out, "{},0,", buf.format(wx));
        let _ = writeln!(out, "{}", buf.format(wz));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotates_the_slope_frame_into_the_world() {
        let tr = Trajectory {
            time_s: vec![0.0, 0.5],
            x_m: vec![0.0, 1.0],
            z_m: vec![0.0, 0.0],
            pitch_rad: vec![0.0; 2],
            vx_m_s: vec![0.0; 2],
            vz_m_s: vec![0.0; 2],
            leg_angle_rad: vec![],
            leg_depth_m: vec![],
            leg_force_x_n: vec![],
            leg_force_z_n: vec![],
            leg_torque_n_m: vec![],
        };
        // 30 degrees: 1 m along the slope is (cos 30, sin 30) = (0.8660..., 0.5) in the world.
        let text = plain_mocap_csv(&tr, 30.0);
        let last: Vec<f64> = text.lines().nth(2).unwrap().split(',').map(|v| v.parse().unwrap()).collect();
        assert_eq!(text.lines().next().unwrap(), "time_s,x_m,y_m,z_m");
        assert!((last[1] - 0.866_025_403_784_438_6).abs() < 1e-15 && (last[3] - 0.5).abs() < 1e-15);
        assert_eq!((last[0], last[2]), (0.5, 0.0));
    }
}
