//! The servo crate's integration tests in one test binary (one link, not three): the
//! emulator against the e-Manual's packets and dynamixel2, the goals' range, and a wrong model.

mod conformance;
mod range;
mod wrong_model;
