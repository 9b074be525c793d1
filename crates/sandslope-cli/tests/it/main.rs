//! The CLI's end-to-end tests that only compute, one module per command or document, in one
//! test binary: one link instead of nineteen (each test file under tests/ is a binary of its
//! own, linked against the whole dependency tree), and their tests share the test harness's
//! threads, so that a file whose one slow test would leave a core idle runs beside the others.
//! The tests that time a bus or a server in real time stay binaries of their own, run alone
//! (tests/drive.rs, tests/serve.rs, tests/serve_drive.rs, tests/foxglove_live.rs).

#[path = "../common/mod.rs"]
mod common;

mod animate;
mod calibrate;
mod cli;
mod design_infer;
mod docs_examples;
mod docs_numbers;
mod exit_codes;
mod fit;
mod fit_noisy;
mod hostile_input;
mod phase_risk;
mod plan;
mod plan_risk_streamed;
mod plan_seam;
mod report;
mod report_page;
mod simulate;
mod surroundings;
/// The synthetic load-cell campaigns `fit` and `fit_noisy` test on.
#[path = "fit/synth.rs"]
mod synth;
mod track;
