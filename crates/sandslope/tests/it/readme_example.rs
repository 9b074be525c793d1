//! The README's "Using the library" example, compiled and run as written: `EXAMPLE` is the
//! block's text, which the README must contain verbatim, and `readme_example_runs` is that text
//! inside a function (a changed API breaks the build here, a changed README fails the check).

const EXAMPLE: &str = r#"use sandslope::{predict, Ground, Robot, RobotSpec, Slope};
// the paper's robot (RobotSpec::paper_hexapod, docs/model.md) with a 1 kg payload
let robot = Robot::new(RobotSpec { mass_kg: 1.0, ..RobotSpec::paper_hexapod() })?;
let p = predict(&robot, Slope::from_degrees(20.0)?, &Ground::new(7e5, 1.4e6)?);
println!("{} at {:?} m/s", p.regime, p.speed);
"#;

#[test]
fn the_readme_shows_this_example() {
    let readme = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../README.md")).unwrap();
    assert!(
        readme.contains(&format!("```rust\n{EXAMPLE}```")),
        "README's library example differs from EXAMPLE"
    );
}

#[test]
fn readme_example_runs() -> Result<(), Box<dyn std::error::Error>> {
    use sandslope::{predict, Ground, Robot, RobotSpec, Slope};
    // the paper's robot (RobotSpec::paper_hexapod, docs/model.md) with a 1 kg payload
    let robot = Robot::new(RobotSpec { mass_kg: 1.0, ..RobotSpec::paper_hexapod() })?;
    let p = predict(&robot, Slope::from_degrees(20.0)?, &Ground::new(7e5, 1.4e6)?);
    println!("{} at {:?} m/s", p.regime, p.speed);
    Ok(())
}
