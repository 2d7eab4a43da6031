//! One integration-test binary (fast to link); each module tests one part through the
//! public API or the CLI.

// Shared helpers: reference least squares, data generators.
#[path = "integration/common.rs"]
mod common;
// Term language: accept/reject tables, caret texts, parse∘print, compiled = interpreter, fuzz.
#[path = "integration/grammar.rs"]
mod grammar;
// STPRG on the Hald cement data and on synthetic data with a known equation; proptest laws.
#[path = "integration/stepwise.rs"]
mod stepwise;
// The `termid` binary end to end.
#[path = "integration/cli.rs"]
mod cli;
// Model files: the default model against the paper, error locations, round trip.
#[path = "integration/model.rs"]
mod model;
// Simulator and ship plug-in: symmetry, integrator order, steady turning, manoeuvres.
#[path = "integration/ship.rs"]
mod ship;
// Non-ship models (Lorenz, Duffing) through the same library and commands.
#[path = "integration/generic.rs"]
mod generic;
// Inputs held between samples: found, integrated and replayed held.
#[path = "integration/intersample.rs"]
mod intersample;
// Records as loggers write them: a slower sensor's readings repeated between its updates.
#[path = "integration/sensors.rs"]
mod sensors;
// The paper end to end (`termid reproduce`) through the library.
#[path = "integration/reproduce.rs"]
mod reproduce;
// Every back-end through one suite; best subset against brute force.
#[path = "integration/selectors.rs"]
mod selectors;
// No panic on any user input (model files, CSV, manoeuvre strings).
#[path = "integration/robustness.rs"]
mod robustness;
// The discrepancy workflow on data with hidden effects, and a negative control.
#[path = "integration/diagnose.rs"]
mod diagnose;
// Measured runs from a synthetic basin: identify, validate, and the refusals of bad files.
#[path = "integration/basin.rs"]
mod basin;
// Hostile inputs through the CLI: no hang, no half-written file, no silent surprise.
#[path = "integration/hostile.rs"]
mod hostile;
// The second hostile sweep: nothing of the user's lost, no panic, nothing silently ignored.
#[path = "integration/hostile2.rs"]
mod hostile2;
// The library's layers run one way (a table checked against the `crate::` paths).
#[path = "integration/layers.rs"]
mod layers;
// The MMG model of KVLCC2 as a model file, against the shipmmg package's numbers.
#[path = "integration/mmg.rs"]
mod mmg;
// The SIMMAN case study's dataset files, on records laid out as the basins write them.
#[path = "integration/simman.rs"]
mod simman;
// README and the guide as scripts: every shell block runs, in order, on the repository's own files.
#[path = "integration/readme.rs"]
mod readme;
// Every figure kind, read off its SVG as a person would look at it.
#[path = "integration/figures.rs"]
mod figures;
// Grey-box: named parameters of a model file estimated by output error (Lorenz, Nomoto).
#[path = "integration/greybox.rs"]
mod greybox;
// Systems the paper never saw through estimate's defaults: right, or flagged as failed.
#[path = "integration/outside.rs"]
mod outside;
// The reference (docs/reference/) against the code: every key documented, nothing stale.
#[path = "integration/reference.rs"]
mod reference;
// A ship at full scale through defaults set at model scale: bounds, manoeuvre times, checks.
#[path = "integration/full_scale.rs"]
mod full_scale;
