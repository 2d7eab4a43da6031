//! Command-line arguments (clap derive): one struct per subcommand.

use std::path::PathBuf;

use clap::{ArgGroup, Args, Parser, Subcommand, ValueEnum};
use termid::select::BackendName;
use termid::sim::Integrator;

/// termid: identify equations of motion from time series.
#[derive(Debug, Parser)]
#[command(name = "termid", version, about, long_about = None)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Select terms and fit coefficients of one equation, or of every equation of a --model,
    /// from one or several runs.
    Identify(Box<IdentifyCommand>),
    /// Simulate a model file (the default ship model if none) under a manoeuvre or inputs.
    Simulate(SimulateCommand),
    /// Reproduce Oltmann (1973) end to end: tables, figures and a report beside the paper's.
    Reproduce(ReproduceCommand),
    /// Run every back-end on the same data and equations and show them side by side.
    Compare(CompareCommand),
    /// Find where model and measurements disagree, name the missing effect, add it.
    Diagnose(DiagnoseCommand),
    /// Check a model against held-out runs: errors per run, manoeuvre metrics side by side.
    Validate(ValidateCommand),
    /// Rescale a model by Froude's law (a basin's model to its ship, or back).
    Scale(ScaleCommand),
    /// Write an equation's sufficient statistics over a shard of runs (merged and identified
    /// by `identify --moments`).
    Moments(MomentsCommand),
    /// Estimate a model file's free parameters (`free = true`) by output error: grey-box
    /// identification, alone or with the term coefficients.
    Estimate(EstimateCommand),
    /// Write a grey-box MMG model file for a ship from its main particulars: every parameter
    /// estimated by a cited formula and free with that estimate as its prior (then `estimate`).
    NewShip(NewShipCommand),
}

/// `termid new-ship`.
#[derive(Debug, Args)]
#[command(
    after_help = "A particulars file (TOML; SI, degrees):\n  name = \"KVLCC2\"\n  lpp = 7.0\n  beam = 1.27\n  draught = 0.46\n  block_coefficient = 0.81\n  x_g = 0.25                # from midship, forward positive (default 0)\n  rudder_area = 0.0539\n  rudder_span = 0.345\n  propeller_diameter = 0.216\n  u0 = 1.17248\n  rudder_rate = 15.8\n  # optional: rudder_limit = 35, density = 1025, kt = [k0, k1, k2] (the propeller's K_T(J))\n\nExample (then `termid estimate --model ship_greybox.toml --dataset YOUR_RUNS.toml`):\n  termid new-ship --particulars examples/kvlcc2_particulars.toml --out ship_greybox.toml\n  termid simulate --model ship_greybox.toml -m turning:35"
)]
pub struct NewShipCommand {
    /// The particulars file.
    #[arg(long)]
    pub particulars: PathBuf,
    /// Where the grey-box model file goes.
    #[arg(long)]
    pub out: PathBuf,
}

/// `termid estimate`.
#[derive(Debug, Args)]
#[command(
    after_help = "A parameter is free when its table says so, with an optional prior and bounds:\n  [parameters.K]\n  value = 0.2          # where the estimate starts\n  free = true\n  prior = { value = 0.2, sd = 0.05 }\n  bounds = [0.0, 5.0]\n\nExample (a step response of a ship with K = 0.15, T = 8; the file starts at 0.1 and 10):\n  termid simulate --model models/nomoto.toml --param K=0.15 T=8 --input δ=0.1 --duration 60 --sample 0.1 --out step.csv\n  termid estimate --model models/nomoto.toml --data step.csv --states ψ,r --out nomoto_estimated.toml\n\nSeveral basins, each with its own rudder indicator zero `δ_0` (a free parameter of the model): give\n`--dataset` once per basin and `--per-source δ_0`."
)]
pub struct EstimateCommand {
    /// The model file with free parameters.
    #[arg(long)]
    pub model: PathBuf,
    /// Runs (CSV with the time, the inputs and measured states in the model's names, SI):
    /// one source.
    #[arg(long = "data", short = 'd', num_args = 1.., required_unless_present = "dataset")]
    pub data: Vec<PathBuf>,
    /// A dataset file (TOML): runs with their own column names and units. Repeatable: each
    /// is a source (a basin, a campaign) with its own columns, units and scale.
    #[arg(long, action = clap::ArgAction::Append)]
    pub dataset: Vec<PathBuf>,
    /// A column of the --data files that names each row's run, where a file holds several
    /// (a long table: runs one after another or interleaved row by row): each of its values
    /// read as a run of its own.
    #[arg(long, value_name = "COLUMN", requires = "data")]
    pub by: Option<String>,
    /// Free parameters estimated once per source (nuisances, e.g. each basin's rudder
    /// indicator zero; not written to the model); the others once for all unless the model
    /// file declares them a nuisance (`nuisance = "run"`).
    #[arg(long, num_args = 1.., value_delimiter = ',')]
    pub per_source: Vec<String>,
    /// Held parameters of the model file to estimate too, from their values (with the file's
    /// prior and bounds where it gives them; per run or source as its `nuisance` says): a sea
    /// trial's current `c_N,c_E` in a model `new-ship` wrote.
    #[arg(long, num_args = 1.., value_delimiter = ',')]
    pub free: Vec<String>,
    /// Free parameters of the model file to hold at their values in this estimate; among them
    /// a velocity of the medium (`medium = true`: a current), which runs tracked over ground
    /// (satellite fixes) otherwise estimate.
    #[arg(long, num_args = 1.., value_delimiter = ',')]
    pub hold: Vec<String>,
    /// Free parameters estimated once per run (nuisances that change from run to run, such
    /// as the rudder's zero `δ_0` as a basin's indicator drifts; the model keeps the runs'
    /// mean). A model file declares its own with `nuisance = "run"`.
    #[arg(long, num_args = 1.., value_delimiter = ',')]
    pub per_run: Vec<String>,
    /// Another model of the same ship (a polynomial one `identify` wrote): both models'
    /// checks side by side, flagged where they disagree by more than 10 % on a manoeuvre the
    /// runs did not cover (a turning circle): the runs cannot tell them apart there.
    #[arg(long)]
    pub against: Option<PathBuf>,
    /// Write the model with the estimates, their standard errors and covariance.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Also estimate every term coefficient of the identified equations (each held to its
    /// stored value by its standard error).
    #[arg(long)]
    pub coefficients: bool,
    /// Most Levenberg-Marquardt iterations per round (two rounds).
    #[arg(long, default_value_t = 50)]
    pub iterations: usize,
    /// Each run's initial values of the compared states: `auto` (free; where the fit leans on
    /// them, fitted again held as `measured` holds them, and that fit kept where it predicts
    /// the runs from their recorded first samples better), `measured` (estimated, held to the
    /// recorded first sample by the record's noise), `free` (estimated without a prior: they
    /// may absorb what the model does not explain) or `recorded` (the first sample, not
    /// estimated).
    #[arg(long = "initial-values", default_value = "auto", value_parser = termid::diagnose::InitialValues::parse)]
    pub initial_values: termid::diagnose::InitialValues,
    /// Compare only these states (default: every state the runs have), and these derived
    /// variables of the model (`[[derived]]`: a propeller's thrust), each with the runs' column
    /// of its name, evaluated along the re-simulation.
    #[arg(long, num_args = 1.., value_delimiter = ',')]
    pub states: Option<Vec<String>>,
    /// The RK4 step, s (default: the runs' sample interval; the recorded inputs are known only at
    /// the samples).
    #[arg(allow_negative_numbers = true, long)]
    pub dt: Option<f64>,
    /// Fit at the coarsest step (up to 8 samples) at which the model file's values re-simulate
    /// the runs as at every sample (each compared state within 0.1 % of its spread), as
    /// `identify --parameters` does: about half the time on records sampled finely (20 Hz);
    /// the costs, the initial values' moves and the residuals' correlation time are still
    /// reported at every sample.
    #[arg(long, conflicts_with = "dt")]
    pub coarse: bool,
    /// Fit each run cut into this many segments, each from its own initial values (multiple
    /// shooting; none shorter than 20 samples): where a motion's errors grow over a run (a
    /// chaotic or unstable system) no whole-run re-simulation follows its record, while
    /// segments short against that growth do. Each segment is reported as a run.
    #[arg(long, value_parser = clap::value_parser!(u32).range(2..))]
    pub segments: Option<u32>,
    /// One figure per run (SVG) into this folder: each compared state measured, simulated with
    /// the model's values and with the estimates (each from the run's first sample, each
    /// source with its own values), and the residuals
    #[arg(long)]
    pub svg: Option<PathBuf>,
    /// Output format.
    #[arg(long, value_enum, default_value = "text")]
    pub format: Format,
}

/// `termid moments`.
#[derive(Debug, Args)]
#[command(
    after_help = "Example, two shards identified together as their rows would be:\n  termid simulate --model models/lorenz.toml --duration 10 --sample 0.01 --out a.csv\n  termid simulate --model models/lorenz.toml --duration 10 --sample 0.01 --initial x=1 y=1 z=20 --out b.csv\n  termid moments --model models/lorenz.toml --equation z_dot --data a.csv --out a.moments\n  termid moments --model models/lorenz.toml --equation z_dot --data b.csv --out b.moments\n  termid identify --model models/lorenz.toml --moments a.moments b.moments --out lorenz_id.toml"
)]
pub struct MomentsCommand {
    /// The model file whose equation's candidates are accumulated.
    #[arg(long)]
    pub model: PathBuf,
    /// The equation (e.g. `r_dot`).
    #[arg(long)]
    pub equation: String,
    /// CSV files of runs (model names, SI).
    #[arg(long = "data", short = 'd', num_args = 1.., required_unless_present = "dataset")]
    pub data: Vec<PathBuf>,
    /// A dataset file (TOML): runs with their own column names and units. Repeatable: the
    /// runs of every one together (each with its own columns, units and scale).
    #[arg(long, action = clap::ArgAction::Append)]
    pub dataset: Vec<PathBuf>,
    /// A column of the --data files that names each row's run, where a file holds several
    /// (a long table: runs one after another or interleaved row by row): each of its values
    /// read as a run of its own.
    #[arg(long, value_name = "COLUMN", requires = "data")]
    pub by: Option<String>,
    /// Derivative method where the target is a state's derivative (the runs have no
    /// `<state>_dot` column): central, five-point, savitzky-golay[:W:Q], spline[:ALPHA], kalman,
    /// or integral[:W] (no rate: changes over windows of W samples against integrals).
    #[arg(long, default_value = "central")]
    pub derivative: String,
    /// Write the statistics here (JSON; numbers round-trip exactly).
    #[arg(long)]
    pub out: PathBuf,
    /// Rows per piece when `--data` files are read in pieces (one pass, memory bounded by
    /// a few pieces, whatever the file's size): with a derivative of fixed reach (central,
    /// five-point, savitzky-golay, integral) or measured `<state>_dot` columns. 0 reads each
    /// file whole.
    #[arg(allow_negative_numbers = true, long, default_value_t = 262_144)]
    pub chunk_rows: usize,
}

/// `termid scale`.
#[derive(Debug, Args)]
#[command(
    after_help = "Example:\n  termid scale --model models/mmg_kvlcc2.toml --factor 45.714 --out kvlcc2_full.toml\n(KVLCC2 from L = 7 m to 320 m: lengths × λ, speeds × √λ, times × √λ, masses × λ³; every coefficient by its dimension)"
)]
pub struct ScaleCommand {
    /// The model file.
    #[arg(long)]
    pub model: PathBuf,
    /// Length factor λ (new length / old length; < 1 from ship to model).
    #[arg(allow_negative_numbers = true, long)]
    pub factor: f64,
    /// Write the rescaled model here.
    #[arg(long)]
    pub out: PathBuf,
}

/// Output format.
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum Format {
    /// Human-readable tables.
    Text,
    /// JSON on standard output.
    Json,
}

/// Step rule names on the command line.
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum RuleName {
    /// First step after which F no longer rises (by more than --step-tolerance).
    FMax,
    /// First step after which the standard error no longer falls by more than --step-tolerance.
    SePlateau,
    /// The last step.
    Last,
}

/// `termid identify`.
#[derive(Clone, Debug, Args)]
#[command(group(ArgGroup::new("system").args(["model", "states"]).multiple(true)))]
#[command(
    after_help = "Examples:\n  termid identify --data tests/data/hald.csv --no-time --target y --terms x1 x2 x3 x4\n  termid simulate --model models/lorenz.toml --duration 20 --sample 0.01 --out lorenz.csv\n  termid identify --model models/lorenz.toml --data lorenz.csv --out lorenz_id.toml\n  termid identify --data lorenz.csv --states x,y,z --out lorenz_whole.toml\n  termid identify --model examples/data/ship.toml --dataset examples/data/runs.toml --derivative kinematic,kalman \\\n      --smooth --no-intercept --choose sparse,best-subset --compare u,v,r,ψ --refine u,v,r,ψ --out ship_id.toml\nBack-ends: stepwise (the paper's STPRG), efroymson, best-subset, sparse, stlsq.\nDerivatives: weak[:W[:P]], integral[:W] and ito (no rate; ito for a record moved by a random force), central, five-point, savitzky-golay[:W:Q], spline[:ALPHA], kalman[:RATIO]; kinematic (ship models).\nRuns: CSV (model names, SI; aliases, semicolons, tabs and aligned blanks read), Parquet, Arrow IPC, or a dataset file (README)."
)]
pub struct IdentifyCommand {
    /// CSV files with a header row; several are combined (the paper's "Komb. Daten").
    #[arg(long = "data", short = 'd', num_args = 1.., required_unless_present_any = ["dataset", "moments"])]
    pub data: Vec<PathBuf>,
    /// A dataset file (TOML): runs with their own column names and units. Repeatable: the
    /// runs of every one together (each with its own columns, units and scale).
    #[arg(long, action = clap::ArgAction::Append)]
    pub dataset: Vec<PathBuf>,
    /// A column of the --data files that names each row's run, where a file holds several
    /// (a long table: runs one after another or interleaved row by row): each of its values
    /// read as a run of its own.
    #[arg(long, value_name = "COLUMN", requires = "data")]
    pub by: Option<String>,
    /// With --model: identify from statistics written by `termid moments` instead of runs
    /// (several files are merged; each names its equation).
    #[arg(long, num_args = 1.., requires = "model")]
    pub moments: Vec<PathBuf>,
    /// Name of the time column.
    #[arg(long, default_value = "t")]
    pub time: String,
    /// The rows are not a time series (no time column; derivative targets are refused).
    #[arg(long, conflicts_with = "time")]
    pub no_time: bool,
    /// What to explain: a column (`y`) or the derivative of one (`dr/dt`). A rate (`dX/dt`, or
    /// a column `X_dot` beside `X`) is an equation of motion: stlsq, the constant a candidate
    /// term. With --model the default is each equation's `<state>_dot` column, else the
    /// state's derivative.
    #[arg(long, required_unless_present_any = ["model", "states"])]
    pub target: Option<String>,
    /// Candidate terms, e.g. --terms "u*v" "u*r" "u^2*δ", or comma-separated: --terms u*v,u*r
    /// (a comma inside a call's parentheses stays: "atan2(v, u)").
    #[arg(long, num_args = 1.., required_unless_present_any = ["terms_file", "model", "states"])]
    pub terms: Vec<String>,
    /// Take vocabulary, candidates, forced terms and back-end from a model file.
    #[arg(long)]
    pub model: Option<PathBuf>,
    /// Every state's rate at once without a model file: these columns are the states
    /// (comma-separated), each rate over the same candidates (--terms, --terms-file, or every
    /// monomial of the states and inputs to --degree), the rest as with --model: --out writes
    /// the model file (each state starting where the first run starts), which `termid
    /// simulate --model` runs. A state the runs do not record, the rate of one they do, is
    /// written `v=dx/dt` (a position recorded alone: --states x,v=dx/dt): estimated from x's
    /// record by the Kalman smoother, ẋ = v kinematics, v's equation identified.
    #[arg(long, num_args = 1.., value_delimiter = ',')]
    pub states: Vec<String>,
    /// With --states: the columns that drive the states, known from the records
    /// (comma-separated; given without names, or as "": none). Default: every other column of
    /// the runs.
    #[arg(long, num_args = 0.., value_delimiter = ',', requires = "states")]
    pub inputs: Option<Vec<String>>,
    /// With --states and no candidates named: the degree of the polynomial library (every
    /// monomial of the states and inputs, the constant among them; a variable the runs hold
    /// more than 10 spreads from 0 written about a round reference value, ΔT = T - T0, said).
    /// Default 3, the ODE benchmark's (benches/odes).
    #[arg(long, requires = "states")]
    pub degree: Option<u32>,
    /// With --model or --states: the equation(s) to identify (default: all that are
    /// identifiable).
    #[arg(long, num_args = 1.., requires = "system")]
    pub equation: Vec<String>,
    /// With --model or --states: write the model with the identified coefficients to this file.
    #[arg(long, requires = "system")]
    pub out: Option<PathBuf>,
    /// A file of candidate terms, one per line (`#` starts a comment).
    #[arg(long)]
    pub terms_file: Option<PathBuf>,
    /// Terms that always enter first (with --model or --states: in every identified equation
    /// that has them among its candidates). Comma-separated as --terms.
    #[arg(long, num_args = 1..)]
    pub forced: Vec<String>,
    /// Terms that never enter (with --model or --states: in every identified equation that
    /// has them among its candidates). Comma-separated as --terms.
    #[arg(long, num_args = 1..)]
    pub exclude: Vec<String>,
    /// Per-run parameters: `u0=2.01`, `u0=first:u` (first value of u in each run) or `u0=mean:u`.
    #[arg(long = "param", num_args = 1..)]
    pub params: Vec<String>,
    /// Columns that act later than they are recorded (a dead time): `F=0.2` reads F 0.2 s
    /// earlier against the rest, the runs' first 0.2 s left out (with --states, the input's
    /// `delay` in the model written). Without it, a rate's fit whose residuals show such a
    /// delay says so (with --states, the system is identified again with it: --no-dead-times).
    #[arg(long = "delay", num_args = 1.., value_name = "NAME=SECONDS")]
    pub delays: Vec<String>,
    /// Columns that act through a first-order lag (an actuator that follows its command as
    /// ẏ = (u − y)/T): `u=0.5` reads u through a lag of 0.5 s, at rest at its first value
    /// (with --states, the input's `lag` in the model written). After --delay where both are
    /// given.
    #[arg(long = "lag", num_args = 1.., value_name = "NAME=SECONDS")]
    pub lags: Vec<String>,
    /// Derived variables: `Δu=u-u0`.
    #[arg(long = "derive", num_args = 1..)]
    pub derived: Vec<String>,
    /// Aliases: `du=Δu`.
    #[arg(long = "alias", num_args = 1..)]
    pub aliases: Vec<String>,
    /// Regression back-end (settings beyond the defaults: a model file's `backend` table).
    /// Default: stlsq for a rate (`dX/dt`, `X_dot`), else stepwise; with --model each
    /// equation's own, which this replaces when given.
    #[arg(long, value_enum)]
    pub backend: Option<BackendName>,
    /// Derivative method for `dX/dt` targets: central, five-point, savitzky-golay[:WINDOW:ORDER],
    /// spline[:ALPHA] (GCV by default), kalman[:RATIO] (maximum likelihood by default), or for
    /// ship models `kinematic`: the tracking filter fusing track, heading, log and gyro.
    /// Several, comma-separated, with --model and --refine: one start each (prepared,
    /// identified, refined, checked), a table of them, and the one whose refined model
    /// re-simulates the runs best (the --refine-validation runs where given) is kept.
    /// `weak[:W[:P]]` and `integral[:W]` estimate no derivative: the weak form weighs the
    /// equation over windows of W samples (default 32) by a smooth bump of power P (8), the
    /// integral form takes changes over windows against the candidates' integrals (Simpson).
    /// `ito` takes each interval's change against the candidates as the intervals before
    /// predict them: for a record moved by a random force (process noise), whose terms every
    /// other method biases. Default `auto`: the weak form for any system (the integral form's
    /// windows of 8 on runs of at most 128 samples), central for a model with a plug-in's
    /// table (a ship, as the paper differentiated).
    #[arg(long, default_value = "auto")]
    pub derivative: String,
    /// Resample every run to this interval [s] before differentiating (low-pass filtered
    /// first when coarser than the data, so noise does not alias).
    #[arg(allow_negative_numbers = true, long)]
    pub resample: Option<f64>,
    /// Replace each differentiated signal by the derivative method's smoothed estimate
    /// (spline, kalman), so the regressors are smoothed as well as the targets.
    #[arg(long)]
    pub smooth: bool,
    /// Keep the runs' spikes as recorded. By default a sample or three that leap away from
    /// their neighbours and straight back, far beyond the record's own steps and noise (a
    /// glitch, not a motion), are replaced by the line through their neighbours, and said.
    /// With --model as the file's `keep_spikes = true` (which the model written keeps).
    #[arg(long)]
    pub keep_spikes: bool,
    /// How the runs' inputs behave between samples. `auto`: an input that stays put between
    /// samples and jumps at isolated ones (a digital controller's command, a force stepped by
    /// a rig) is taken as held from each sample to the next, and said; one that does so off
    /// any clock (a relay) switches somewhere between two samples: the integral form leaves
    /// out the windows that hold a jump, said; else a line, unless a state's rate fits
    /// clearly better with it held (a random telegraph, an APRBS, a smooth command put out
    /// through a DAC: held, said). The integral form integrates a
    /// held input piece by piece between its jumps, and a replay into a simulation holds it
    /// over each step. Any column (the state too) that changes only
    /// every few rows on a clock, at most of its ticks, repeats a slower sensor's readings: it
    /// is read at its readings and interpolated between them by cubics, and said; an input so
    /// where a state's rate steps at its changes, or fits clearly better with it held, is a
    /// controller's command, held (`linear`: neither; `held`: every input that changes).
    /// With --model as the file's `intersample` (which the model written keeps).
    #[arg(long, value_enum)]
    pub intersample: Option<termid::data::Intersample>,
    /// Write a figure of the raw and prepared signals of every run into this folder.
    #[arg(long)]
    pub prepared_svg: Option<PathBuf>,
    /// After the regression, refine all identified coefficients together by output error:
    /// re-simulate the (prepared) runs from their initial states with their recorded inputs
    /// and fit these states, comma-separated model names (e.g. `u,v,r,ψ`), or `all`. Compare
    /// velocities and heading; positions integrate every earlier error and dominate the fit.
    /// A derived variable of the model among them is compared with the runs' column of its
    /// name (a propeller's thrust).
    #[arg(long, value_name = "STATES")]
    pub refine: Option<String>,
    /// With --refine: weight of the regression's estimates as a prior (each coefficient held
    /// to its regression value within its standard error); 0 lets the refinement wander.
    #[arg(
        allow_negative_numbers = true,
        long,
        value_name = "WEIGHT",
        default_value_t = 1e-4,
        requires = "refine"
    )]
    pub refine_prior: f64,
    /// With --refine: most Levenberg-Marquardt iterations (it stops earlier once converged; with
    /// the model file's free parameters, in each of the estimate's two rounds).
    #[arg(allow_negative_numbers = true, long, value_name = "N", default_value_t = 30, requires = "refine")]
    pub refine_iterations: usize,
    /// With --refine: re-simulate and compare the runs at this step, s (resampled,
    /// anti-aliased). Default: the coarsest whole number of samples, up to 8, at which the
    /// regression's model and the refined one re-simulate the runs as at their samples (every
    /// compared state within 0.1 % of its spread), or finer steps between the samples where
    /// those do not resolve the motion; the costs reported are at every sample.
    #[arg(long, value_name = "SECONDS", requires = "refine")]
    pub refine_step: Option<f64>,
    /// With --refine: a dataset file of runs the refinement does not fit but is stopped by
    /// (of its iterates, the one that predicts these runs best is kept).
    #[arg(long, value_name = "DATASET", requires = "refine")]
    pub refine_validation: Option<PathBuf>,
    /// With --model: estimate the model file's free parameters (`free = true`, e.g. the
    /// new-ship template's rudder zero `δ_0`, its own in every run) by output error together
    /// with every coefficient of each start and each run's initial state, at the refinement's
    /// step; kept where the checks the start passed still pass (else the start is refined
    /// without them). A regression cannot estimate a parameter inside its terms. The default
    /// with --refine where the model file declares free parameters, in place of the
    /// refinement (not with --refine-validation runs, which stop the refinement and which the
    /// estimate cannot heed); this flag asks for it without --refine too, and after a
    /// refinement that --refine-validation runs stop.
    #[arg(long, requires = "model", conflicts_with = "no_parameters")]
    pub parameters: bool,
    /// With --refine: refine the coefficients alone, the model file's free parameters kept at
    /// their values (a rudder zero of 0).
    #[arg(long, requires = "model", conflicts_with_all = ["per_source", "per_run"])]
    pub no_parameters: bool,
    /// With --parameters (implied): these free parameters estimated once per source (each
    /// --dataset a source, the --data files another), e.g. each basin's rudder indicator zero.
    #[arg(long, num_args = 1.., value_delimiter = ',', requires = "model")]
    pub per_source: Vec<String>,
    /// With --parameters (implied): these free parameters estimated once per run (a rudder
    /// zero that drifts from run to run; the model keeps the runs' mean). A model file
    /// declares its own with `nuisance = "run"`.
    #[arg(long, num_args = 1.., value_delimiter = ',', requires = "model")]
    pub per_run: Vec<String>,
    /// With --model or --states: choose among these back-ends and model files (comma-separated, or `all`
    /// back-ends; a model file is another candidate library for the same equations) by what
    /// they predict: each run is re-simulated by the model identified on the other runs; of
    /// those within one standard error of the smallest error, the first listed is identified
    /// on all runs. The table it chose from is printed.
    #[arg(long, value_name = "BACKENDS", requires = "system")]
    pub choose: Option<String>,
    /// With --choose: the states compared in the held-out runs (default: the states of the
    /// identified equations), e.g. `u,v,r,ψ`.
    #[arg(long, value_name = "STATES", requires = "choose")]
    pub compare: Option<String>,
    /// With --states and the polynomial library (no --terms): keep the polynomials even where
    /// their terms fail the checks a stand-in fails (the halves, the re-simulation) or hold a
    /// state's or an input's power alone (v³, n³); without it the system is identified again
    /// with each state's and input's laws among the candidates (sign, x·|x|, √|x|, sin x), and those kept where they pass every
    /// check in no more terms (and fit the rows clearly better where the polynomials passed
    /// too), said either way.
    #[arg(long, requires = "states")]
    pub no_laws: bool,
    /// Keep the derivative method even where the records show a state moved by a random force
    /// (process noise: another state's record holds its roughness, so it is motion, not a
    /// sensor's noise); without it such a system (one start, not refined) is identified again by
    /// Itô's steps (`--derivative ito`), whose terms the force does not bias, and that is said.
    #[arg(long)]
    pub no_random_force: bool,
    /// Keep the inputs as recorded even where the regression finds one acting later (a dead
    /// time: its note says by how much); without it a system of no plug-in's is identified
    /// again with that input read so (its `delay` under [[inputs]] in the model written), and
    /// that is kept where it fails no check the inputs as recorded pass, said either way.
    #[arg(long)]
    pub no_dead_times: bool,
    /// Write the model even when it fails a check: a physical check of its plug-in (a ship's:
    /// damping signs, turning circles that complete, plausible speed loss and drift), or, for
    /// a system of no plug-in's, that its equations retrace the runs without running away.
    #[arg(long, requires = "system")]
    pub keep_unphysical: bool,
    /// With --model or --states and plain --data files: read them in pieces of this many rows, one pass
    /// and bounded memory whatever their size (statistics merged as `termid moments` and
    /// `identify --moments` would). Needs a derivative of fixed reach (central, five-point,
    /// savitzky-golay, integral) and none of --dataset, --resample, --smooth, --prepared-svg, --refine,
    /// --choose, --target. Default: in pieces of 262144 rows when the files together exceed
    /// 256 MiB and these hold; 0 reads them whole.
    #[arg(allow_negative_numbers = true, long, value_name = "ROWS", requires = "system")]
    pub chunk_rows: Option<usize>,
    /// Fit without an intercept b0.
    #[arg(long, conflicts_with = "intercept")]
    pub no_intercept: bool,
    /// Fit a forced intercept b0 where the default would not: for a rate target (`dX/dt`,
    /// `X_dot`) without --model, and for a model file with `intercept = false` (there the
    /// constant `1` is a candidate like any other).
    #[arg(long)]
    pub intercept: bool,
    /// Weighted least squares with the row weights in this column.
    #[arg(long)]
    pub weight: Option<String>,
    /// Stepwise: stop when the next term's share of the total sum of squares is below this.
    #[arg(allow_negative_numbers = true, long, default_value_t = 0.0)]
    pub min_proportion: f64,
    /// Stepwise: how the reported step is chosen.
    #[arg(long, value_enum, default_value = "f-max")]
    pub step_rule: RuleName,
    /// Stepwise: tolerance of the step rule (relative).
    #[arg(allow_negative_numbers = true, long, default_value_t = 0.0)]
    pub step_tolerance: f64,
    /// Output format.
    #[arg(long, value_enum, default_value = "text")]
    pub format: Format,
}

impl IdentifyCommand {
    /// Options given together that cannot be: checked here, not declared to clap, since a
    /// conflict declared on an option that another `requires` makes clap pass that
    /// requirement unchecked (its issue 4520: `identify --terms x --out m.toml` ran without
    /// `--model` and wrote nothing, without a word).
    pub fn refuse_conflicts(&self) -> Result<(), String> {
        let with_model = [
            (
                "--terms",
                !self.terms.is_empty(),
                "the candidates are each equation's `candidates` in the model file",
            ),
            (
                "--terms-file",
                self.terms_file.is_some(),
                "the candidates are each equation's `candidates` in the model file",
            ),
            (
                "--param",
                !self.params.is_empty(),
                "declare parameters in the model file (`[parameters.NAME]`, `per_run = \"mean:u\"`)",
            ),
            (
                "--derive",
                !self.derived.is_empty(),
                "declare derived variables in the model file (`[[derived]]`)",
            ),
            ("--alias", !self.aliases.is_empty(), "declare aliases in the model file (`[aliases]`)"),
            ("--weight", self.weight.is_some(), "row weights apply to one equation without a model file"),
        ];
        if self.model.is_some() {
            refuse_given("--model", &with_model)?;
            if !self.states.is_empty() {
                return Err("--states cannot be used with --model: the model file declares its states".into());
            }
        }
        if !self.states.is_empty() {
            let single = [
                ("--target", self.target.is_some(), "--states identifies the rate of every state named"),
                ("--no-time", self.no_time, "the rates of states need the time"),
                ("--weight", self.weight.is_some(), "row weights apply to one equation without a model file"),
                (
                    "--param",
                    !self.params.is_empty(),
                    "a model made from columns has no parameters; write a model file",
                ),
                (
                    "--derive",
                    !self.derived.is_empty(),
                    "a model made from columns has no derived variables; write a model file",
                ),
                (
                    "--alias",
                    !self.aliases.is_empty(),
                    "a model made from columns has no aliases; write a model file",
                ),
                (
                    "--moments",
                    !self.moments.is_empty(),
                    "statistics files are written for a model file's equations",
                ),
            ];
            refuse_given("--states", &single)?;
            if self.degree.is_some() && (!self.terms.is_empty() || self.terms_file.is_some()) {
                return Err(
                    "--degree cannot be used with --terms or --terms-file: the candidates are named".into()
                );
            }
        }
        if !self.moments.is_empty() {
            let why = "the statistics stand for the runs, and re-simulating or leaving runs out needs the runs themselves";
            refuse_given(
                "--moments",
                &[
                    ("--data", !self.data.is_empty(), why),
                    ("--dataset", !self.dataset.is_empty(), why),
                    ("--refine", self.refine.is_some(), why),
                    ("--choose", self.choose.is_some(), why),
                ],
            )?;
        }
        Ok(())
    }
}

/// The first of `options` (flag, given, why) that is given, refused as one that cannot go
/// with the option `with`.
fn refuse_given(with: &str, options: &[(&str, bool, &str)]) -> Result<(), String> {
    match options.iter().find(|(_, given, _)| *given) {
        Some((flag, _, why)) => Err(format!("{flag} cannot be used with {with}: {why}")),
        None => Ok(()),
    }
}

/// `termid simulate`.
#[derive(Debug, Args)]
#[command(
    after_help = "Examples:\n  termid simulate -m zigzag:20/20 --svg z.svg --out z.csv\n  termid simulate --model models/mmg_kvlcc2.toml -m turning:-35 --param u0=1.18\n  termid simulate --model models/lorenz.toml --integrator rk4 --dt 0.001 --duration 20\nManoeuvres: zigzag:RUDDER/HEADING[:port], turning:RUDDER, spiral[:MAX/STEP/HOLD], pullout:RUDDER, replay:FILE.\nRudder sign: the model's own (Oltmann's: positive δ turns to port; the MMG and new-ship models: to starboard);\n`port`/`starboard` are read off the heading."
)]
pub struct SimulateCommand {
    /// Model file (default: the embedded Oltmann 1973 ship model).
    #[arg(long)]
    pub model: Option<PathBuf>,
    /// Ship models: zigzag:20/20[:port][:absolute] (the rudder about the straight run's δ0,
    /// or about 0 as basins lay it), turning:35, spiral[:MAX/STEP/HOLD], pullout:20,
    /// initial-turning[:10/10], replay:FILE.csv (IMO MSC.137(76) criteria are judged where
    /// they apply). Any model: replay:FILE.csv.
    #[arg(long, short = 'm')]
    pub manoeuvre: Option<String>,
    /// Integrator: dopri5 (adaptive Dormand-Prince 5(4) with error control; where it finds the
    /// model stiff it goes on with rosenbrock's steps, and says so), rosenbrock (adaptive,
    /// linearly implicit: stiff models), rk4 or b8 (Oltmann's modified Euler, eq. B8). Default:
    /// the model file's `[simulation]`, else dopri5.
    #[arg(long, value_enum)]
    pub integrator: Option<Integrator>,
    /// Control step, s (or the unit the model's time is named by: `day`): inputs are taken
    /// on its grid; the fixed step of rk4 and b8. Default: the model file's `[simulation]
    /// dt`, else 0.04.
    #[arg(allow_negative_numbers = true, long)]
    pub dt: Option<f64>,
    /// Relative tolerance of dopri5. Default: the model file's `[simulation] rtol`, else 1e-6.
    #[arg(allow_negative_numbers = true, long)]
    pub rtol: Option<f64>,
    /// Absolute tolerance of dopri5, in each state's unit. Default: the model file's
    /// `[simulation] atol`, else 1e-7.
    #[arg(allow_negative_numbers = true, long)]
    pub atol: Option<f64>,
    /// Output interval, s or the model's unit of time (a multiple of the step).
    #[arg(allow_negative_numbers = true, long, default_value_t = 0.2)]
    pub sample: f64,
    /// Duration, s or the model's unit of time (`day`: days, as the run's column is
    /// written). Default: the manoeuvre's own.
    #[arg(allow_negative_numbers = true, long)]
    pub duration: Option<f64>,
    /// Write the run as CSV (SI units, angles in rad).
    #[arg(long, short = 'o')]
    pub out: Option<PathBuf>,
    /// Write a figure (SVG).
    #[arg(long)]
    pub svg: Option<PathBuf>,
    /// Models without a manoeuvre: constant inputs NAME=VALUE.
    #[arg(long = "input", num_args = 1..)]
    pub inputs: Vec<String>,
    /// Initial states NAME=VALUE (default: the model file's).
    #[arg(long = "initial", num_args = 1..)]
    pub initial: Vec<String>,
    /// Parameters NAME=VALUE (default: the model file's).
    #[arg(long = "param", num_args = 1..)]
    pub params: Vec<String>,
    /// Include each equation's stored intercept b0 in the right-hand side.
    #[arg(long)]
    pub with_intercept: bool,
    #[command(flatten)]
    pub monte_carlo: MonteCarloArgs,
    /// Output format of the summary.
    #[arg(long, value_enum, default_value = "text")]
    pub format: Format,
}

/// `termid reproduce`.
#[derive(Debug, Args)]
#[command(
    after_help = "Example (the paper's Tables 1-5 and Figures 2-11 beside termid's, into oltmann1973/):\n  termid reproduce --out oltmann1973"
)]
pub struct ReproduceCommand {
    /// Output folder (report.md, figures/, tables/, data/, summary.json).
    #[arg(long, short = 'o', default_value = "termid-out")]
    pub out: PathBuf,
    /// Model file with the true coefficients (default: the embedded Oltmann model).
    #[arg(long)]
    pub model: Option<PathBuf>,
    /// Take the "exact" accelerations as the B8 step used them, with δ(t+Δt).
    #[arg(long)]
    pub rudder_at_end_of_step: bool,
    /// Round r and ṙ in rad/s (default: °/s, as the paper printed them).
    #[arg(long)]
    pub round_rates_in_radians: bool,
}

/// `termid compare`.
#[derive(Debug, Args)]
#[command(
    after_help = "Example (two runs of the default ship, every back-end on them):\n  termid simulate -m zigzag:20/20 --out run1.csv\n  termid simulate -m zigzag:10/10:port --out run2.csv\n  termid compare --model models/oltmann1973.toml --data run1.csv run2.csv"
)]
pub struct CompareCommand {
    /// Model file with the candidates (default: the embedded Oltmann model).
    #[arg(long)]
    pub model: Option<PathBuf>,
    /// Runs (CSV), combined.
    #[arg(long = "data", short = 'd', num_args = 1.., required_unless_present = "dataset")]
    pub data: Vec<PathBuf>,
    /// A dataset file (TOML): runs with their own column names and units. Repeatable: the
    /// runs of every one together (each with its own columns, units and scale).
    #[arg(long, action = clap::ArgAction::Append)]
    pub dataset: Vec<PathBuf>,
    /// A column of the --data files that names each row's run, where a file holds several
    /// (a long table: runs one after another or interleaved row by row): each of its values
    /// read as a run of its own.
    #[arg(long, value_name = "COLUMN", requires = "data")]
    pub by: Option<String>,
    /// Equations to compare (default: all identifiable ones).
    #[arg(long, num_args = 1..)]
    pub equation: Vec<String>,
    /// A recorded run to re-simulate with each back-end's model (its inputs replayed).
    #[arg(long)]
    pub replay: Option<PathBuf>,
    /// Control step of the re-simulation, s or the model's unit of time (default: the model
    /// file's, else the record's sample interval for the adaptive methods).
    #[arg(allow_negative_numbers = true, long)]
    pub dt: Option<f64>,
    /// Time each fit as the median of this many repetitions after the warm-up.
    #[arg(allow_negative_numbers = true, long, default_value_t = 5)]
    pub repeat: usize,
    /// Warm up by fitting for at least this long (s; at least one fit) before timing: a core
    /// that was idle runs slowly for the first ~0.1 s of work.
    #[arg(allow_negative_numbers = true, long, default_value_t = 0.3)]
    pub warm_up: f64,
    /// Derivative method where a state's derivative is the target.
    #[arg(long, default_value = "central")]
    pub derivative: String,
    /// Fit without an intercept.
    #[arg(long)]
    pub no_intercept: bool,
    /// Output format.
    #[arg(long, value_enum, default_value = "text")]
    pub format: Format,
}

/// `termid diagnose`.
#[derive(Debug, Args)]
#[command(
    after_help = "Example (a model identified from the sample records, checked against them):\n  termid identify --model examples/data/ship.toml --dataset examples/data/runs.toml --derivative kalman \\\n      --smooth --no-intercept --out identified.toml\n  termid diagnose --model identified.toml --dataset examples/data/runs.toml --svg figs/\n(`--out repaired.toml` writes the model with the effect that explains the gap, where one does)"
)]
pub struct DiagnoseCommand {
    /// The model to check (default: the embedded Oltmann model).
    #[arg(long)]
    pub model: Option<PathBuf>,
    /// Measured runs.
    #[command(flatten)]
    pub runs: RunsArgs,
    /// Write the model with the winning effect added (the original stays as it is).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Re-simulation settings.
    #[command(flatten)]
    pub resim: ResimArgs,
    /// Output format.
    #[arg(long, value_enum, default_value = "text")]
    pub format: Format,
}

/// `termid validate`.
#[derive(Debug, Args)]
#[command(
    after_help = "Example (identified from four sample records, checked on the fifth):\n  termid identify --model examples/data/ship.toml --dataset examples/data/runs.toml --derivative kalman \\\n      --smooth --no-intercept --out identified.toml\n  termid validate --model identified.toml --dataset examples/data/held_out.toml --monte-carlo 100 --svg figs/"
)]
pub struct ValidateCommand {
    /// The model (default: the embedded Oltmann model).
    #[arg(long)]
    pub model: Option<PathBuf>,
    /// Held-out runs.
    #[command(flatten)]
    pub runs: RunsArgs,
    /// Re-simulation settings.
    #[command(flatten)]
    pub resim: ResimArgs,
    #[command(flatten)]
    pub monte_carlo: MonteCarloArgs,
    /// Output format.
    #[arg(long, value_enum, default_value = "text")]
    pub format: Format,
}

/// Prediction uncertainty from the coefficients' covariance.
#[derive(Debug, Args)]
pub struct MonteCarloArgs {
    /// Also simulate this many models drawn from the identified coefficients' covariance
    /// (stored by `identify --out`): a 90 % band in the figure and the spread of each metric.
    #[arg(allow_negative_numbers = true, long, default_value_t = 0)]
    pub monte_carlo: usize,
    /// Seed of the draws.
    #[arg(allow_negative_numbers = true, long, default_value_t = 1)]
    pub seed: u64,
}

/// Measured runs: CSV files with the model's names in SI, and/or a dataset file.
#[derive(Debug, Args)]
pub struct RunsArgs {
    /// Runs (CSV with the time, the inputs and measured states).
    #[arg(long = "data", short = 'd', num_args = 1.., required_unless_present = "dataset")]
    pub data: Vec<PathBuf>,
    /// A dataset file (TOML): runs with their own column names and units. Repeatable: the
    /// runs of every one together (each with its own columns, units and scale).
    #[arg(long, action = clap::ArgAction::Append)]
    pub dataset: Vec<PathBuf>,
    /// A column of the --data files that names each row's run, where a file holds several
    /// (a long table: runs one after another or interleaved row by row): each of its values
    /// read as a run of its own.
    #[arg(long, value_name = "COLUMN", requires = "data")]
    pub by: Option<String>,
    /// A velocity of the medium the model declares (`medium = true`: a current) to keep at its
    /// file's value: runs a dataset file tracks by satellite fixes otherwise have it estimated
    /// first, alone, the model held.
    #[arg(long, num_args = 1.., value_delimiter = ',')]
    pub hold: Vec<String>,
}

/// How measured runs are re-simulated, and where the figures go.
#[derive(Debug, Args)]
pub struct ResimArgs {
    /// Integrator: dopri5 (adaptive; linearly implicit where the model is stiff), rosenbrock,
    /// rk4 or b8 (the paper's modified Euler). Default: the model file's `[simulation]`, else
    /// dopri5.
    #[arg(long, value_enum)]
    pub integrator: Option<Integrator>,
    /// Control step, s or the model's unit of time (default: the model file's, else the
    /// records' sample interval for dopri5 and rosenbrock, 0.04 of the model's unit for rk4 and b8).
    #[arg(allow_negative_numbers = true, long)]
    pub dt: Option<f64>,
    /// Relative tolerance of dopri5 (default: the model file's, else 1e-6).
    #[arg(allow_negative_numbers = true, long)]
    pub rtol: Option<f64>,
    /// Absolute tolerance of dopri5, in each state's unit (default: the model file's, else 1e-7).
    #[arg(allow_negative_numbers = true, long)]
    pub atol: Option<f64>,
    /// One figure per run (measured, simulated, residual) into this folder.
    #[arg(long)]
    pub svg: Option<PathBuf>,
    /// Include each equation's stored intercept b0 in the simulation.
    #[arg(long)]
    pub with_intercept: bool,
}

#[cfg(test)]
mod tests {
    use clap::CommandFactory;

    /// clap skips an option's `requires` where the required option conflicts with one given
    /// (its issue 4520), so no option another requires may declare or be named in a conflict:
    /// such pairs are refused after parsing instead ([`super::IdentifyCommand::refuse_conflicts`]).
    #[test]
    fn no_option_another_requires_is_in_a_conflict() {
        let source = include_str!("args.rs");
        let required: Vec<&str> =
            source.split("requires = \"").skip(1).filter_map(|rest| rest.split('"').next()).collect();
        assert!(required.contains(&"model") && required.contains(&"data"), "{required:?}");
        let cli = super::Cli::command();
        for sub in cli.get_subcommands() {
            for arg in sub.get_arguments() {
                let conflicts: Vec<String> =
                    sub.get_arg_conflicts_with(arg).iter().map(|a| a.get_id().to_string()).collect();
                let named = |id: &str| required.contains(&id);
                assert!(
                    conflicts.is_empty()
                        || !(named(arg.get_id().as_str()) || conflicts.iter().any(|c| named(c))),
                    "{} --{} conflicts with {conflicts:?}, and others require one of them",
                    sub.get_name(),
                    arg.get_id()
                );
            }
        }
    }

    /// What clap would have refused is refused after parsing, with the reason.
    #[test]
    fn identify_refuses_options_that_do_not_go_together() {
        let parse = |line: &str| match super::Cli::try_parse_from(line.split_whitespace()) {
            Ok(super::Cli { command: super::Command::Identify(cmd) }) => cmd.refuse_conflicts(),
            other => panic!("{line}: {other:?}"),
        };
        use clap::Parser;
        assert!(parse("termid identify --data d.csv --target dx/dt --terms x").is_ok());
        let e = parse("termid identify --data d.csv --model m.toml --terms x").unwrap_err();
        assert!(e.contains("--terms cannot be used with --model"), "{e}");
        let e = parse("termid identify --data d.csv --model m.toml --weight w").unwrap_err();
        assert!(e.starts_with("--weight"), "{e}");
        let e = parse("termid identify --model m.toml --moments a.json --data d.csv").unwrap_err();
        assert!(e.starts_with("--data cannot be used with --moments"), "{e}");
    }
}
