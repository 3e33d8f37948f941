//! Command-line arguments (parsed first; validated into a config by `config`).

use clap::builder::TypedValueParser;
use clap::{Args, Parser, Subcommand, ValueEnum};
use inertia::choice::Choice;
use inertia::constraints::{Consistency, ProductConvention};
use inertia::estimator::momentum_rows::{RhoModel, RotationSource};
use inertia::pipeline::InertialTorque;
use inertia::telemetry::gate::GyroUnit;
use inertia::telemetry::glitch::GlitchPolicy;
use std::path::PathBuf;

/// Estimate a spacecraft's inertia tensor from attitude telemetry.
///
/// Units are SI throughout (s, rad, rad/s, N m s, N m, kg m²); vectors are in body axes;
/// quaternions are [x, y, z, w], scalar last, Hamilton, body → inertial, unless an input
/// option says otherwise.
#[derive(Debug, Parser)]
#[command(name = "inertia", version, about, long_about = None)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// Subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Simulate telemetry of one of the paper's scenarios (§VI) into a CSV file, with the
    /// true inertia beside it (FILE.truth.json).
    Simulate(Box<SimulateArgs>),
    /// Estimate the inertia from a telemetry CSV file.
    Estimate(Box<EstimateArgs>),
    /// Reproduce the paper's numerical examples on built-in simulated data: figures 1-10
    /// (PNG and SVG), their data (CSV) and summary.md.
    Reproduce(ReproduceArgs),
    /// Run a Monte Carlo campaign of a scenario (one seed per run, in parallel) and write
    /// error percentiles (5/50/95 %) over time for each estimator, as CSV and a figure.
    MonteCarlo(MonteCarloArgs),
    /// Plan the calibration manoeuvre: the wheel torque commands that reach a target σ of
    /// J soonest within the spacecraft file's limits, with the σ predicted over time
    /// (CSV) and a figure.
    Plan(PlanArgs),
}

/// `inertia plan`.
#[derive(Debug, Args)]
pub struct PlanArgs {
    /// The spacecraft file (TOML): rotors with max_torque_nm and max_momentum_nms,
    /// [prior], [sensors] and optionally [limits] max_rate_deg_s and max_angle_deg.
    #[arg(long, value_name = "FILE.toml")]
    pub spacecraft: PathBuf,
    /// Target: relative Frobenius error of J at 3σ.
    #[arg(long, value_name = "REL", default_value_t = 0.01)]
    pub target: f64,
    /// Fly this long instead of stopping where the target is met, s.
    #[arg(long, value_name = "S")]
    pub duration: Option<f64>,
    /// Longest plan, s.
    #[arg(long, value_name = "S", default_value_t = 1800.0)]
    pub max_duration: f64,
    /// The estimator's short momentum chain, s (as `estimate --chain`; 0: none), or
    /// `auto`: rehearse the plans for chains of 30, 60 and 120 s and keep the one whose
    /// rehearsal reports the target soonest (the default chain without rehearsals or with
    /// --duration). The plan says which to give `estimate`.
    #[arg(
        long,
        value_name = "S|auto",
        default_value = "auto",
        allow_hyphen_values = true
    )]
    pub chain: String,
    /// Rehearsal flights of the estimator on the prior J (0: the information matrix
    /// alone decides where the plan stops).
    #[arg(long, value_name = "N", default_value_t = 8)]
    pub rehearsals: u64,
    /// Unknown white disturbance torque density of the rehearsals, N m/√Hz.
    #[arg(long, value_name = "NM_RTHZ", default_value_t = 1e-8)]
    pub disturbance: f64,
    /// Output: the wheel torque commands (CSV, units in the header). The predicted σ go
    /// to OUTPUT with `.prediction.csv`, the figure to `.png` and `.svg`.
    #[arg(short = 'o', long, value_name = "FILE.csv")]
    pub output: PathBuf,
}

/// `inertia monte-carlo`.
#[derive(Debug, Args)]
pub struct MonteCarloArgs {
    /// Scenario.
    #[arg(long, value_enum)]
    pub scenario: ScenarioArg,
    /// Number of runs (run i uses seed SEED + i).
    #[arg(long, value_name = "N", default_value_t = 200)]
    pub runs: u64,
    /// First seed.
    #[arg(long, value_name = "S", default_value_t = 1)]
    pub seed: u64,
    /// Gyro rate noise spectral density, deg/s/√Hz.
    #[arg(
        long,
        visible_alias = "gyro-noise-deg-s-rthz",
        value_name = "DEG_S_RTHZ",
        default_value_t = 1e-5
    )]
    pub gyro_noise: f64,
    /// Unknown disturbance torque spectral density, N m/√Hz.
    #[arg(
        long,
        visible_alias = "disturbance-nm-rthz",
        value_name = "NM_RTHZ",
        default_value_t = 1e-8
    )]
    pub disturbance: f64,
    /// Duration, s [default: the scenario's].
    #[arg(long, visible_alias = "duration-s", value_name = "S")]
    pub duration: Option<f64>,
    /// Output directory.
    #[arg(long, value_name = "DIR", default_value = "monte-carlo")]
    pub out: PathBuf,
}

/// The paper's scenarios.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ScenarioArg {
    /// Three-axis stabilised slews on reaction wheels (300 s).
    Slew,
    /// Major-axis spin with one wheel pulse at 30 s (180 s).
    Spin,
}

/// Spacecraft presets (inertia, sensors, wheels and manoeuvre; see the library's
/// `sim::presets`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum PresetArg {
    /// 12U-class small satellite: MEMS gyro (ARW 0.15 deg/√h, bias, bias instability),
    /// star tracker 5″/5″/40″ at 5 Hz, MEKF attitude, slews on wheels with 10 Hz commands
    /// and 1e-5 N m s speed quantisation (600 s).
    SmallSat,
    /// Three-axis microsatellite: FOG (ARW 0.02 deg/√h), star tracker 3″/3″/25″ at 10 Hz,
    /// MEKF attitude, 5 Hz wheel commands (900 s).
    Microsat,
    /// A hand-thrown lab device (0.5 s free tumble, one flywheel spun up to 600 rad/s on
    /// body z): MEMS gyro at 4 kHz vibrating at the rotor frequency, attitude integrated
    /// from it, speed telemetry in 10 rpm steps held at 100 Hz, an aerodynamic torque
    /// fixed in the inertial frame and air drag.
    Throw,
}

/// Where the telemetered attitude comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum AttitudeArg {
    /// The true attitude.
    Truth,
    /// Propagated from the gyro's delta angles (the paper's model).
    Gyro,
    /// A star tracker sampled at every telemetry node.
    StarTracker,
    /// A multiplicative EKF fusing gyro and star tracker (flight-software style).
    Mekf,
}

/// `inertia simulate`.
#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// Scenario (one of --scenario and --preset is required).
    #[arg(
        long,
        value_enum,
        required_unless_present_any = ["preset", "commands"],
        conflicts_with = "preset"
    )]
    pub scenario: Option<ScenarioArg>,
    /// A spacecraft preset instead of the paper's scenarios; the options below override
    /// its settings.
    #[arg(long, value_enum)]
    pub preset: Option<PresetArg>,
    /// Duration, s [default: 300 for slew, 180 for spin, the preset's].
    #[arg(long, visible_alias = "duration-s", value_name = "S")]
    pub duration: Option<f64>,
    /// Integration node period h, s: the telemetry period unless --telemetry-dt is given
    /// [default: 0.1, or the preset's].
    #[arg(long, visible_alias = "dt-s", value_name = "S")]
    pub dt: Option<f64>,
    /// Telemetry period, s: a whole multiple of --dt (write every n-th node; the gyro's
    /// delta angle covers the whole period), e.g. `--dt 0.1 --telemetry-dt 1`.
    #[arg(long, visible_alias = "telemetry-dt-s", value_name = "S")]
    pub telemetry_dt: Option<f64>,
    /// Noise seed.
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub seed: u64,
    /// The wheels' stored momentum at rest, N m s, body axes, e.g. `0:0:0.05` (a
    /// momentum-biased spacecraft; slews only) [default: none].
    #[arg(long, value_name = "X:Y:Z", allow_hyphen_values = true)]
    pub momentum_bias: Option<String>,
    /// Gyro rate noise spectral density, deg/s/√Hz [default: 1e-5, or the preset's].
    #[arg(
        long,
        visible_alias = "gyro-noise-deg-s-rthz",
        value_name = "DEG_S_RTHZ",
        conflicts_with = "gyro_arw_deg_rthr"
    )]
    pub gyro_noise: Option<f64>,
    /// Gyro angle random walk, deg/√h (= 60 × the density in deg/s/√Hz).
    #[arg(long, value_name = "DEG_RTHR")]
    pub gyro_arw_deg_rthr: Option<f64>,
    /// Constant gyro bias per body axis, deg/h, e.g. `2:-1.5:1`.
    #[arg(long, value_name = "X:Y:Z", allow_hyphen_values = true)]
    pub gyro_bias_deg_h: Option<String>,
    /// Gyro bias instability, deg/h: stationary 1σ of a first-order Gauss–Markov bias
    /// starting at 0.
    #[arg(long, value_name = "DEG_H")]
    pub gyro_bias_instability_deg_h: Option<f64>,
    /// Correlation time of the bias instability, s [default: 3600, or the preset's].
    #[arg(long, value_name = "S")]
    pub gyro_bias_correlation_s: Option<f64>,
    /// Unknown disturbance torque spectral density, N m/√Hz [default: 1e-8, or the
    /// preset's].
    #[arg(long, visible_alias = "disturbance-nm-rthz", value_name = "NM_RTHZ")]
    pub disturbance: Option<f64>,
    /// Source of the telemetered attitude [default: gyro, or the preset's (mekf)].
    #[arg(long, value_enum)]
    pub attitude: Option<AttitudeArg>,
    /// Star-tracker 1σ noise, arcsec: cross-boresight x, cross-boresight y and roll about
    /// the boresight [default: 5:5:40, or the preset's].
    #[arg(long, value_name = "X:Y:ROLL")]
    pub star_tracker_arcsec: Option<String>,
    /// Star-tracker boresight, body axes [default: 0:0:1].
    #[arg(long, value_name = "X:Y:Z", allow_hyphen_values = true)]
    pub star_tracker_boresight: Option<String>,
    /// Star-tracker update rate of the MEKF, Hz (1/(rate·dt) a whole number)
    /// [default: the telemetry rate, or the preset's].
    #[arg(long, value_name = "HZ")]
    pub star_tracker_hz: Option<f64>,
    /// Telemeter the MEKF's raw gyro rates instead of bias-corrected ones.
    #[arg(long)]
    pub mekf_raw_rates: bool,
    /// Hold the wheel torque commands at this controller rate, Hz (zero-order hold)
    /// [default: continuous, or the preset's].
    #[arg(long, value_name = "HZ")]
    pub controller_hz: Option<f64>,
    /// Time of the first command tick after t = 0, s, in [0, 1/controller-hz): 0 puts
    /// ticks on the telemetry nodes, dt/2 half-way between them.
    #[arg(
        long,
        visible_alias = "command-phase-s",
        value_name = "S",
        default_value_t = 0.0
    )]
    pub command_phase: f64,
    /// Wheel-momentum telemetry LSB, N m s (rounding) [default: 0, or the preset's].
    #[arg(long, value_name = "NMS")]
    pub wheel_quantization_nms: Option<f64>,
    /// Wheel-momentum telemetry white noise 1σ per axis, N m s.
    #[arg(long, value_name = "NMS")]
    pub wheel_noise_nms: Option<f64>,
    /// Wheel time-tag skew, s: ρ at node t is the true ρ at t + SKEW (|SKEW| ≤ the
    /// telemetry period).
    #[arg(long, value_name = "S", allow_hyphen_values = true)]
    pub wheel_skew_s: Option<f64>,
    /// Wheel spin-inertia scale error per body axis (telemetered = (1 + e) true),
    /// e.g. `0.01:0:-0.01`.
    #[arg(long, value_name = "X:Y:Z", allow_hyphen_values = true)]
    pub wheel_scale_error: Option<String>,
    /// Misalignment of the telemetered wheel momentum: a rotation vector, deg, body axes.
    #[arg(long, value_name = "X:Y:Z", allow_hyphen_values = true)]
    pub wheel_misalignment_deg: Option<String>,
    /// Gravity-gradient torque (unknown: not in tau_*) on a circular orbit at this
    /// altitude, km. The inertial position is written as extra columns r_x,r_y,r_z (m).
    #[arg(long, value_name = "KM")]
    pub gravity_gradient_altitude_km: Option<f64>,
    /// Orbit inclination, deg (with --gravity-gradient-altitude-km). RAAN 0 and argument
    /// of latitude 0 at t = 0: the orbit starts on the inertial x axis, so with
    /// inclination 0 the initial body axes are radial, along-track and orbit normal.
    #[arg(
        long,
        value_name = "DEG",
        default_value_t = 0.0,
        allow_hyphen_values = true,
        requires = "gravity_gradient_altitude_km"
    )]
    pub orbit_inclination_deg: f64,
    /// Constant unknown body-frame torque, N m, e.g. `1e-5:0:0` (not in tau_*).
    #[arg(long, value_name = "X:Y:Z", allow_hyphen_values = true)]
    pub constant_torque_nm: Option<String>,
    /// Constant unknown torque fixed in the inertial frame, N m (an aerodynamic force off
    /// the centre of mass; not in tau_*) [default: 0, or the preset's].
    #[arg(long, value_name = "X:Y:Z", allow_hyphen_values = true)]
    pub inertial_torque_nm: Option<String>,
    /// Air drag: an unknown torque −D·ω with this D, N m s [default: 0, or the preset's].
    #[arg(long, value_name = "NMS")]
    pub drag_nms: Option<f64>,
    /// A constant magnetic field fixed in the inertial frame, T, e.g. `2e-5:0:-3e-5`: the
    /// field of the magnetic options (without it they need --gravity-gradient-altitude-km
    /// and use Earth's centred dipole along the inertial z axis, B0 = 3.12e-5 T). With a
    /// field the magnetometer's reading is written as extra columns b_x,b_y,b_z (T, body
    /// axes).
    #[arg(long, value_name = "X:Y:Z", allow_hyphen_values = true)]
    pub magnetic_field_t: Option<String>,
    /// Residual magnetic dipole, A m², body axes: an unknown torque m × B (not in tau_*).
    #[arg(long, value_name = "X:Y:Z", allow_hyphen_values = true)]
    pub residual_dipole_am2: Option<String>,
    /// Magnetorquers: a commanded dipole of this amplitude, A m², on each body axis (sine
    /// waves of periods 50, 70 and 90 s); its torque m × B with the measured field is added
    /// to tau_*.
    #[arg(long, value_name = "AM2", allow_hyphen_values = true)]
    pub magnetorquer_am2: Option<f64>,
    /// Magnetometer white noise, T per axis and sample [default: 1e-7].
    #[arg(long, value_name = "T")]
    pub magnetometer_noise_t: Option<f64>,
    /// Magnetometer bias, T, body axes [default: 0].
    #[arg(long, value_name = "X:Y:Z", allow_hyphen_values = true)]
    pub magnetometer_bias_t: Option<String>,
    /// Thrusters of this thrust, N: six in pairs at --thruster-arm-m from the origin
    /// (torques ±arm·thrust about x, y, z in turn; forces along +z, +x, +y), firing one at
    /// a time a smooth 4 s pulse every 10 s from 5 s. Their torque about the origin is
    /// added to tau_*, the force written as extra columns f_x,f_y,f_z (N, body axes).
    #[arg(long, value_name = "N")]
    pub thrusters: Option<f64>,
    /// The thrusters' distance from the origin, m.
    #[arg(long, value_name = "M", default_value_t = 0.3, requires = "thrusters")]
    pub thruster_arm_m: f64,
    /// The true centre of mass, m, body axes, from the origin tau_* is taken about: the
    /// thrusters' unknown torque −c × F [default: 0].
    #[arg(
        long,
        value_name = "X:Y:Z",
        allow_hyphen_values = true,
        requires = "thrusters"
    )]
    pub centre_of_mass_m: Option<String>,
    /// White noise of the written force, N per axis and sample [default: 0].
    #[arg(long, value_name = "N", requires = "thrusters")]
    pub force_noise_n: Option<f64>,
    /// Gyro vibration at the rotor frequency (rotor speed |ρ|/rotor spin inertia):
    /// amplitude per body axis, rad/s [default: 0, or the preset's].
    #[arg(long, value_name = "X:Y:Z", allow_hyphen_values = true)]
    pub gyro_vibration_rad_s: Option<String>,
    /// Spin inertia of the rotor that carries ρ, kg m² (sets the vibration's frequency)
    /// [default: 1, or the preset's].
    #[arg(long, value_name = "KG_M2")]
    pub rotor_spin_inertia_kg_m2: Option<f64>,
    /// Wheel-speed telemetry rate, Hz, held between updates (a whole fraction of the
    /// telemetry rate) [default: every sample, or the preset's].
    #[arg(long, value_name = "HZ")]
    pub wheel_hold_hz: Option<f64>,
    /// Fly these wheel torque commands (an `inertia plan` CSV) from rest instead of the
    /// scenario's manoeuvres; the duration defaults to the profile's.
    #[arg(long, value_name = "PLAN.csv", conflicts_with = "scenario")]
    pub commands: Option<PathBuf>,
    /// The true inertia of the run, kg m²: J11:J22:J33:J12:J13:J23 (default: the
    /// scenario's or the preset's).
    #[arg(
        long,
        value_name = "J11:J22:J33:J12:J13:J23",
        allow_hyphen_values = true
    )]
    pub inertia: Option<String>,
    /// A spacecraft file (TOML) whose rotors carry the simulated rotor momentum: the CSV
    /// holds their speed columns instead of rho_*, split among them as a pseudo-inverse
    /// allocator does, with the file's spin inertias as the truth.
    #[arg(long, value_name = "FILE.toml")]
    pub spacecraft: Option<PathBuf>,
    /// Output CSV file (the truth goes to the same name with `.truth.json`).
    #[arg(short = 'o', long, value_name = "FILE.csv")]
    pub output: PathBuf,
    /// The paper's J as the truth, exactly (it breaks the triangle inequality J1 + J2 ≥
    /// J3 by 4.9e-5 kg m²). By default the scenarios' truth is the paper's J + 1e-4 I,
    /// the nearest physical inertia of that form.
    #[arg(long, conflicts_with = "preset")]
    pub paper_inertia: bool,
    /// Step change of the inertia: at T seconds J becomes SCALE·J (angular momentum
    /// conserved), e.g. `300:1.1`.
    #[arg(long, value_name = "T:SCALE", conflicts_with = "inertia_ramp")]
    pub inertia_step: Option<String>,
    /// Linear change of the inertia from T0 to T1 seconds, to SCALE·J, e.g. `300:360:0.9`.
    #[arg(long, value_name = "T0:T1:SCALE")]
    pub inertia_ramp: Option<String>,
}

/// Names from the library's registry as clap's possible values, with their help.
fn registered(
    entries: impl Iterator<Item = (&'static str, &'static str)>,
) -> clap::builder::PossibleValuesParser {
    clap::builder::PossibleValuesParser::new(
        entries.map(|(name, help)| clap::builder::PossibleValue::new(name).help(help)),
    )
}

/// A choice-valued option: the library's names ([`Choice::NAMES`]) as clap's possible
/// values, parsed into the library's value.
fn choice<T: Choice + Clone + Send + Sync>() -> impl clap::builder::TypedValueParser<Value = T> {
    clap::builder::PossibleValuesParser::new(T::NAMES.iter().copied())
        .map(|s| T::parse(&s).expect("clap passes one of the possible values"))
}

/// Input-format options shared by commands that read telemetry.
#[derive(Debug, Args)]
pub struct InputArgs {
    /// The quaternion columns hold [w, x, y, z] (scalar first) instead of [x, y, z, w].
    #[arg(long, conflicts_with_all = ["jpl", "conjugate"])]
    pub scalar_first: bool,
    /// The quaternion follows the JPL/Shuster convention (inertial → body, scalar last).
    #[arg(long, conflicts_with = "conjugate")]
    pub jpl: bool,
    /// The quaternion is a Hamilton quaternion that maps inertial → body (the conjugate
    /// of this tool's body → inertial), scalar last: conjugate it as it is read.
    #[arg(long)]
    pub conjugate: bool,
    /// The unit of the gyro rate columns w_*: `rad/s` (default) or `deg/s`.
    #[arg(long, value_name = "UNIT", value_parser = choice::<GyroUnit>())]
    pub gyro_unit: Option<GyroUnit>,
    /// The rho columns hold the rotor momentum with the opposite sign (e.g. the wheels'
    /// reaction on the body): negate them as they are read.
    #[arg(long)]
    pub negate_rho: bool,
    /// A spacecraft file (TOML): the rotors' axes, spin inertias ± σ and speed columns.
    /// The rotor momentum is computed from the wheel speeds (the file then has no rho_*
    /// columns), and the spin inertias' σ widen the answer's σ.
    #[arg(long, value_name = "FILE.toml")]
    pub spacecraft: Option<std::path::PathBuf>,
    /// Rename a column, e.g. `--column t=time --column rho_x=h_wheel_x`.
    #[arg(long = "column", value_name = "DEFAULT=NAME")]
    pub columns: Vec<String>,
    /// Largest | |q| − 1 | that is renormalised (beyond it, an error) [default: 0.001].
    #[arg(long, value_name = "TOL")]
    pub unit_tolerance: Option<f64>,
    /// Strict mode: reject any step that differs from the first by more than TOL
    /// (relative). By default irregular sampling is accepted and gaps are counted.
    #[arg(long, value_name = "TOL")]
    pub period_tolerance: Option<f64>,
}

/// `inertia estimate`.
#[derive(Debug, Args)]
pub struct EstimateArgs {
    /// Telemetry CSV file (see README: t, q_x..q_w, rho_x..rho_z, optional tau_*, w_*).
    /// Several files are several records of one spacecraft, estimated together with
    /// `--batch`: one J, each record its own initial momenta and torques.
    #[arg(required = true, num_args = 1.., value_name = "FILE")]
    pub files: Vec<PathBuf>,
    /// A run file (TOML, or JSON for a name ending in `.json`) that gives any of the
    /// options below (and the input options) by their long names in snake case
    /// (`memory = 120`, `rho_model = "held"`, `bounds = ["J33=2.7:3.3"]`,
    /// `torque_bias = false`, `columns = { t = "time" }`); the options given on the command
    /// line override it. Relative file names in it are relative to its folder.
    #[arg(long, value_name = "RUN.toml")]
    pub settings: Option<PathBuf>,
    /// Estimator (default: the discrete momentum estimator, the most accurate in the
    /// README's Monte Carlo matrix; `variational` is the paper's).
    #[arg(long, value_parser = registered(inertia::pipeline::registry::ESTIMATORS.iter().map(|e| (e.name, e.summary))))]
    pub estimator: Option<String>,
    /// One batch solve over all samples instead of the recursive estimator.
    #[arg(long)]
    pub batch: bool,
    /// Constraint set: `physical` (J ⪰ εI and Σ = ½ tr(J) I − J ⪰ 0, exact physical
    /// consistency; default), `paper` (J ⪰ εI and the paper's diagonal triangle
    /// inequalities, eq. 9) or `positive-definite` (J ⪰ εI only).
    #[arg(long, value_parser = choice::<Consistency>())]
    pub constraints: Option<Consistency>,
    /// Bound an element, kg m²: `J33=2.7:3.3`, `J12=:0.05`, `J11=0.9:` (repeatable).
    #[arg(long = "bound", value_name = "Jij=LO:HI")]
    pub bounds: Vec<String>,
    /// Nominal inertia (JSON, as written by `simulate`), bounding every element with
    /// `--tolerance`: moments within ±p·|J_ii|, products within ±p·√(J_ii J_jj).
    #[arg(long, value_name = "J.json", requires = "tolerance")]
    pub nominal: Option<PathBuf>,
    /// Tolerance for `--nominal`, e.g. `10%` or `0.1`.
    #[arg(long, value_name = "P", requires = "nominal")]
    pub tolerance: Option<String>,
    /// Fix every product of inertia at zero (J diagonal in the telemetry's body axes): an
    /// equality the solver eliminates, as `--bound J12=0:0` etc.
    #[arg(long)]
    pub diagonal: bool,
    /// Gaussian prior on J, e.g. from CAD (JSON as written by `simulate`, optionally with
    /// `sigma_kg_m2` per element and `products_of_inertia`: "tensor" or "cad"). It is
    /// weighed against the data; the report says how much of each element the data
    /// determine.
    #[arg(long, value_name = "J.json")]
    pub prior: Option<PathBuf>,
    /// Standard deviation of the prior: relative (`5%`: moments ±5 %·|J_ii|, products
    /// ±5 %·√(J_ii J_jj)) or absolute in kg m² for every element (`0.02`). Overrides the
    /// file's `sigma_kg_m2`.
    #[arg(long, value_name = "P", requires = "prior")]
    pub prior_sigma: Option<String>,
    /// Relative standard deviation of the wheel momentum's scale, common to every wheel
    /// (their spin inertia known to ±P): `2%` or `0.02`. It widens σ by P·|Ĵ| per element
    /// (the data fix J's scale only as well as the wheels'), and an answer whose relative
    /// σ then exceeds the threshold is not determined.
    #[arg(long, value_name = "P")]
    pub rotor_scale_sigma: Option<String>,
    /// Relative standard deviation of the known torque's scale (`tau_*`, the spacecraft
    /// file's thrusters, commanded magnetorquer dipoles: a thrust or a dipole known to ±P):
    /// `2%` or `0.02`. The final answer's σ grows by P times the part of Ĵ the known torque
    /// sets (all of it where no wheel moves), and an answer whose relative σ then exceeds
    /// the threshold is not determined.
    #[arg(long, value_name = "P")]
    pub torque_scale_sigma: Option<String>,
    /// Low-pass cutoff, Hz, of the equation-error baseline's differentiating filter
    /// (default: a twentieth of the sample rate).
    #[arg(long, value_name = "HZ")]
    pub filter_cutoff_hz: Option<f64>,
    /// How products of inertia are written in `--prior`, `--nominal` and `--bound Jij`
    /// (i ≠ j): `tensor` (J12 = −Σ m x y, this tool's convention) or `cad` (I_xy = +Σ m x y,
    /// what CAD tools report). Default tensor; a `--prior`/`--nominal` file's own
    /// `products_of_inertia` applies to that file (and must agree with this option).
    #[arg(long, value_name = "CONVENTION", value_parser = choice::<ProductConvention>())]
    pub products: Option<ProductConvention>,
    /// Solve every N samples (recursive estimators) [default: 1]; the discrete momentum
    /// estimator also answers at the end of the input.
    #[arg(long, value_name = "N")]
    pub every: Option<usize>,
    /// Forget old data with this time constant, s (exponential weighting, for an inertia
    /// that changes). Shorter memory tracks faster and is noisier (README).
    #[arg(long, value_name = "S")]
    pub memory: Option<f64>,
    /// Resample irregular telemetry to this period, s, by 4-point Lagrange interpolation
    /// before estimating (keeps the rows' O(h⁴) accuracy on jittered time stamps; README).
    #[arg(long, value_name = "S")]
    pub resample: Option<f64>,
    /// The gyro's rate-noise density, deg/s/√Hz: compensates the errors-in-variables
    /// shrinkage of J (book, "Estimators"). Without it the discrete momentum estimator
    /// estimates the density from the rates where their differences are noise (and says
    /// so); the other estimators compensate nothing. 0: no compensation.
    #[arg(
        long,
        visible_alias = "gyro-noise-deg-s-rthz",
        value_name = "DEG_S_RTHZ"
    )]
    pub gyro_noise: Option<f64>,
    /// Angle random walk of the attitude solution, deg/√h (discrete-momentum estimator,
    /// with --gyro-noise): for an attitude propagated from a gyro, that gyro's ARW. The
    /// momentum rows are then weighted for the attitude's drift (generalised least
    /// squares; README, "Weighting"). Not for a star tracker or an MEKF, whose attitude
    /// error is bounded.
    #[arg(long, value_name = "DEG_RTH")]
    pub attitude_drift: Option<f64>,
    /// Where the incremental rotations come from (discrete-momentum estimator): the
    /// attitude quaternions or the gyro's angle increments. Default: both are tried when
    /// the telemetry has gyro rates, and the rows that fit better are used (the report
    /// says which).
    #[arg(long, value_name = "SOURCE", value_parser = choice::<RotationSource>())]
    pub rotation_source: Option<RotationSource>,
    /// What the wheel momentum does between samples (discrete-momentum estimator):
    /// `auto` (estimated with J: smooth laws, commands held over each step, or commands
    /// that change between samples), `smooth`, `held` (torque commands held over each
    /// telemetry step, changing at the samples), or `plain` (O(h²) one-step rows).
    #[arg(long, value_parser = choice::<RhoModel>())]
    pub rho_model: Option<RhoModel>,
    /// A step where the attitude jumps against the gyro (a glitch in the quaternions or
    /// the rates; telemetry with `w_*` columns): `stop` with an error naming the line
    /// (default), or `keep` it and estimate anyway, the steps counted and listed in the
    /// report.
    #[arg(long, value_parser = choice::<GlitchPolicy>())]
    pub glitches: Option<GlitchPolicy>,
    /// Do not estimate an unknown constant disturbance torque (discrete-momentum
    /// estimator; by default it is estimated, at no cost when it is absent).
    #[arg(long)]
    pub no_torque_bias: bool,
    /// A disturbance torque constant in the inertial frame (discrete-momentum estimator;
    /// aerodynamic or solar force fixed in space, or the momentum's drift over a short
    /// record), one per chain: `short` (default: `auto` on a record shorter than 30 s,
    /// `off` on a longer one), `off`, `on`, or `auto` (both models folded; it is taken
    /// where a nested chi-squared test at 1e-3 and the BIC both say the data need it, and
    /// the report's `rows:` line says so).
    #[arg(long, value_name = "MODE", value_parser = choice::<InertialTorque>())]
    pub inertial_torque: Option<InertialTorque>,
    /// Estimate a linear damping torque −D·ω (air drag on a tumbling body; one more
    /// unknown D, N m s, reported; discrete-momentum estimator).
    #[arg(long)]
    pub damping: bool,
    /// Estimate the spacecraft file's rotor parameters with J (each wheel's spin-inertia
    /// error, the two tilts of its axis and its own time tag, wherever the file gives them
    /// a σ, which is their prior; with --batch). The overall scale of the wheels stays the
    /// file's σ, and a record with a known torque is not calibrated. Unless every
    /// parameter is a time tag, the record needs a total angular momentum (a momentum
    /// bias), else the file's σ is a consider term and the report says why.
    #[arg(long)]
    pub calibrate_rotors: bool,
    /// Do not model the gravity-gradient torque from the telemetry's positions
    /// (r_x,r_y,r_z; modelled by default where given): for a known torque that already
    /// holds it.
    #[arg(long)]
    pub no_gravity_gradient: bool,
    /// The gravitational parameter μ of the gravity gradient, m³/s² [default: Earth's,
    /// 3.986004418e14].
    #[arg(long, value_name = "M3_S2")]
    pub gravity_mu: Option<f64>,
    /// Do not estimate a residual magnetic dipole from the telemetry's magnetic field
    /// (b_x,b_y,b_z; estimated by default where given, reported with σ).
    #[arg(long)]
    pub no_residual_dipole: bool,
    /// Do not estimate the centre of mass from the telemetry's force (f_x,f_y,f_z;
    /// estimated by default where given, reported with σ, from the origin the known
    /// torque is taken about).
    #[arg(long)]
    pub no_centre_of_mass: bool,
    /// The wheel-speed telemetry's time tag: the speeds are read δ later than their time
    /// stamps. `off` (default), the delay in seconds (e.g. `0.05`; negative: early), or
    /// `estimate` (the residuals' minimum over ±min(0.25 s, a tenth of the record), with
    /// σ; its σ widens each element's). Any estimator; the run then keeps every sample
    /// and gives its estimates (and the history) at the end of the input. Speeds held
    /// between updates lag by about half the update period.
    #[arg(long, value_name = "S|estimate", allow_hyphen_values = true)]
    pub wheel_delay: Option<String>,
    /// Short momentum chain, s (discrete-momentum estimator): the conserved momentum is
    /// re-anchored after this long, which bounds the effect of a drifting attitude
    /// (gyro-propagated attitude); chains a quarter and 4x as long and one chain over the
    /// whole record are folded too, and the data choose (the report's `rows:` line says
    /// which). `0` for chains that end only at gaps [default: 30].
    #[arg(long, value_name = "S")]
    pub chain: Option<f64>,
    /// True inertia (JSON) to report the relative Frobenius error against.
    #[arg(long, value_name = "J.json")]
    pub truth: Option<PathBuf>,
    /// Write the estimate history to this CSV file.
    #[arg(short = 'o', long, value_name = "FILE.csv")]
    pub output: Option<PathBuf>,
    /// Print one JSON object instead of the readable report.
    #[arg(long)]
    pub json: bool,
    /// Solver backend [default: native].
    #[arg(long, value_parser = registered(inertia::pipeline::registry::BACKENDS.iter().map(|e| (e.name, e.summary))))]
    pub solver: Option<String>,
    /// Input format.
    #[command(flatten)]
    pub input: InputArgs,
}

/// `inertia reproduce`.
#[derive(Debug, Args)]
pub struct ReproduceArgs {
    /// Output directory.
    #[arg(long, value_name = "DIR", default_value = "results")]
    pub out: PathBuf,
    /// Noise seed of the simulated telemetry.
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub seed: u64,
}
