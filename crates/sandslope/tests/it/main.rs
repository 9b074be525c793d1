//! The library's integration tests in one test binary (one link, not three): calibration,
//! properties of the model, and the README's library example.

mod calibrate;
mod properties;
mod readme_example;
