//! The FMU's variable table: one row per variable. The model description, the getters
//! and the setters all come from here (the FMU crate turns the rows into FMI variables), so
//! they cannot drift apart.

pub use crate::variable::{Causality, ChainPlace, ConstantKind, VarType, Variability, Variable};

mod extra_flow;
mod extra_force;
mod flexible;
mod interface_table;
mod modulation;

pub use interface_table::interface_table;

pub mod vr;

/// The D/A converter's range: a command outside it is refused.
pub const V_DA_RANGE: (f64, f64) = (-10.0, 10.0);

/// One row of the table: the FMI variable (name, value reference, unit, start, `min`/`max` as
/// the model description declares them, description) with what the model description cannot
/// say: whether `min` itself is excluded, the thesis reference, and why the limits are where
/// they are. The setters ([`check`]), `jetpipe sweep`, `jetpipe parameters` and the docs
/// table all read these rows.
#[derive(Clone, Copy, Debug)]
pub struct Row {
    pub variable: Variable,
    /// `variable.min` itself is refused ("> 0"); FMI's `min` is closed, so it is declared as is.
    pub min_excluded: bool,
    /// Where the thesis states the row: an equation "(2.18)", a table or a section; "" where
    /// the thesis has nothing (effects and correction terms it lacks).
    pub reference: &'static str,
    /// The physical reason for the limits.
    pub reason: &'static str,
    /// The place of the chain the constant belongs to (for a constant the diagnosis may vary).
    pub place: Option<ChainPlace>,
    /// A difference step for the outputs' sensitivity to the constant where its start value is
    /// 0 and no hundredth of it gives one: a typical size of the quantity.
    pub sensitivity_step: Option<f64>,
    /// What the constant is where its place does not say which kind of departure it makes.
    pub kind: Option<ConstantKind>,
}

// Builders for the rows (const: the table is a constant; no float arithmetic in them, which
// a `const fn` may not do on Rust 1.63).
impl Row {
    const fn of(variable: Variable) -> Row {
        Row {
            variable,
            min_excluded: false,
            reference: "",
            reason: "",
            place: None,
            sensitivity_step: None,
            kind: None,
        }
    }
    /// What the constant is, for the kind of departure it makes.
    const fn is(mut self, kind: ConstantKind) -> Row {
        self.kind = Some(kind);
        self
    }
    /// The place of the chain the constant belongs to.
    const fn at(mut self, place: ChainPlace) -> Row {
        self.place = Some(place);
        self
    }
    /// A typical size of the quantity, for a sensitivity where the value is 0.
    const fn step(mut self, step: f64) -> Row {
        self.sensitivity_step = Some(step);
        self
    }
    /// Values must be > `min`.
    const fn above(mut self, min: f64) -> Row {
        self.variable.min = Some(min);
        self.min_excluded = true;
        self
    }
    /// Values must be >= `min`.
    const fn at_least(mut self, min: f64) -> Row {
        self.variable.min = Some(min);
        self.min_excluded = false;
        self
    }
    /// Values must be <= `max`.
    const fn at_most(mut self, max: f64) -> Row {
        self.variable.max = Some(max);
        self
    }
    const fn cite(mut self, reference: &'static str) -> Row {
        self.reference = reference;
        self
    }
    const fn because(mut self, reason: &'static str) -> Row {
        self.reason = reason;
        self
    }

    /// The limits as a reader writes them: "in (0, 1]", "> 0 Pa", "<= 1e5 N/m"; "" if none.
    pub fn limits_text(&self) -> String {
        let v = &self.variable;
        let unit = match v.unit {
            Some(u) if u != "1" => format!(" {u}"),
            _ => String::new(),
        };
        let open = if self.min_excluded { "(" } else { "[" };
        match (v.min, v.max) {
            (Some(lo), Some(hi)) => format!("in {open}{}, {}]{unit}", number(lo), number(hi)),
            (Some(lo), None) => format!("{} {}{unit}", if self.min_excluded { ">" } else { ">=" }, number(lo)),
            (None, Some(hi)) => format!("<= {}{unit}", number(hi)),
            (None, None) => String::new(),
        }
    }

    /// A value for this row within its limits, or a message naming the variable, the value
    /// and the limit, with the reason for the limit.
    pub fn check(&self, value: f64) -> Result<(), String> {
        let v = &self.variable;
        if !value.is_finite() {
            return Err(format!("{} = {value} is invalid: must be finite", v.name));
        }
        let below = match v.min {
            Some(lo) => value < lo || (self.min_excluded && value == lo),
            None => false,
        };
        let above = v.max.map_or(false, |hi| value > hi);
        if below || above {
            let unit = match v.unit {
                Some(u) if u != "1" => format!(" {u}"),
                _ => String::new(),
            };
            let why = if self.reason.is_empty() {
                String::new()
            } else {
                format!(" ({})", self.reason)
            };
            return Err(format!(
                "{} = {}{unit} is invalid: must be {}{why}",
                v.name,
                number(value),
                self.limits_text()
            ));
        }
        Ok(())
    }
}

/// A number as a message shows it: plain from 1e-4 to 1e6, elsewhere with an exponent where
/// that is much shorter (1e30, not thirty-one digits).
pub fn number(x: f64) -> String {
    let (plain, exponent) = (format!("{x}"), format!("{x:e}"));
    if x != 0.0 && !(1e-4..1e6).contains(&x.abs()) && exponent.len() + 3 <= plain.len() {
        exponent
    } else {
        plain
    }
}

/// The row of a value reference.
pub fn row(value_reference: u32) -> Option<&'static Row> {
    TABLE.iter().find(|r| r.variable.value_reference == value_reference)
}

/// Check a value against its row's limits (see [`Row::check`]).
pub fn check(value_reference: u32, value: f64) -> Result<(), String> {
    row(value_reference)
        .ok_or_else(|| format!("value reference {value_reference} is not in the variable table"))?
        .check(value)
}

const fn input(name: &'static str, vr: u32, unit: &'static str, start: f64, description: &'static str) -> Row {
    Row::of(Variable {
        name,
        value_reference: vr,
        var_type: VarType::Real,
        causality: Causality::Input,
        variability: Variability::Continuous,
        unit: Some(unit),
        start,
        min: None,
        max: None,
        description,
    })
}

const fn output(name: &'static str, vr: u32, unit: &'static str, description: &'static str) -> Row {
    Row::of(Variable {
        name,
        value_reference: vr,
        var_type: VarType::Real,
        causality: Causality::Output,
        variability: Variability::Continuous,
        unit: Some(unit),
        start: 0.0,
        min: None,
        max: None,
        description,
    })
}

const fn parameter(name: &'static str, vr: u32, unit: &'static str, start: f64, description: &'static str) -> Row {
    Row::of(Variable {
        name,
        value_reference: vr,
        var_type: VarType::Real,
        causality: Causality::Parameter,
        variability: Variability::Fixed,
        unit: Some(unit),
        start,
        min: None,
        max: None,
        description,
    })
}

/// Reasons shared by several rows' limits.
const LENGTH: &str =
    "a length of the hand's actuator, whose cylinder is 78 mm long: a metre is beyond any actuator of its kind";
const PRESSURE: &str = "10 MPa: ten times industrial pneumatic supplies; the orifice law treats air as an ideal gas";
const RATE: &str =
    "1e6 rad/s (160 kHz): beyond any current driver or torque motor; Table 3.1's corners are below 7100 rad/s";
const TRAVEL: &str = "10 mm: the receiver's areas stop changing 3 D_jp (3 mm) from its centre (2.8)-(2.17)";
const LEAK_AREA: &str =
    "1e-4 m2: half the bore's cross-section (2e-4 m2 with the thesis's D_cyl); a larger opening is no leak";
const LAMINAR_CONDUCTANCE: &str =
    "1e-6 kg/(s.Pa): 0.1 kg/s at a bar, about a hundred times what the valve's open port passes from the supply";
const RESISTANCE: &str =
    "at the jet pipe's flow of about 1e-3 kg/s, 1e12 Pa.s/kg would drop 1e9 Pa, a thousand times the supply pressure";
const AREA_SCALE: &str = "ten times the drawn area of (2.8)-(2.17); the diagnosis fits at most 3";
const DEAD_VOLUME: &str = "1e-3 m3 (a litre): seventy times the two chambers' 1.4e-5 m3";
const CURVE_COMMAND: &str = "the D/A spans 10 V either way; ten times that is no command";
const CURVE_FORCE: &str = "1000 N: nine times the largest force the actuator gives (109 N)";
const CURVE_PRESSURE: &str = PRESSURE;
const CURVE_RATIO: &str = "a pressure ratio P_down/P_up lies between 0 and 1";
const FILTER_FREQUENCY: &str =
    "100 kHz: a hundred times the bench's sampling rate; a filter that fast reads no dynamics";
const FILTER_DAMPING: &str =
    "a damping ratio above 0 keeps the filter stable; at 10 it is already two lags a hundred times apart";
const CURVE_DISCHARGE: &str = "a discharge coefficient lies between 0 (closed) and 1 (no contraction, no loss)";

/// Every variable of the FMU, one row each: name, value reference, unit, start, limits,
/// description and thesis reference. Defaults: Table 3.1 of the thesis and docs/model.md.
/// Then the modulation slots' rows (`variables/modulation.rs`), the extra force's product
/// slots (`variables/extra_force.rs`), the extra flow slots (`variables/extra_flow.rs`) and the
/// plain constants and flexible slots of `variables/flexible.rs`.
pub const TABLE: &[Row] = &TABLE_ARRAY;
const TABLE_LENGTH: usize = ROWS_BEFORE_THE_SLOTS.len() + modulation::length(&modulation::SLOT_ROWS);
#[allow(clippy::large_const_arrays)]
const TABLE_ARRAY: [Row; TABLE_LENGTH] = modulation::concatenated(ROWS_BEFORE_THE_SLOTS, &modulation::SLOT_ROWS);

const ROWS_BEFORE_THE_SLOTS: &[Row] = &[
    input("v_DA", vr::V_DA, "V", 0.0, "D/A command voltage to the current driver").cite("(2.3)"),
    input(
        "x_s",
        vr::X_S,
        "m",
        0.054,
        "rod stopper position (valid while both chamber volumes are positive)",
    ).cite("(2.32)"),
    input(
        "a_s",
        vr::A_S,
        "m/s2",
        0.0,
        "stopper acceleration, read by the extra forces on the piston as far as stopper_acceleration_input_share says (at 0, the default, it is not read)",
    )
        .at_least(-1e4).at_most(1e4)
        .cite("(2.36)")
        .because("1e4 m/s2, a thousand g: the stopper is moved by a finger, not struck"),
    output("F_act", vr::F_ACT, "N", "actuator (tendon) force, (2.36)-(2.38)").cite("(2.36)-(2.38)"),
    output("P1", vr::P1, "Pa", "absolute pressure of chamber 1 (charging side)").cite("(2.26)-(2.29)"),
    output("P2", vr::P2, "Pa", "absolute pressure of chamber 2 (venting side)").cite("(2.26)-(2.29)"),
    output("i", vr::I, "A", "coil current").cite("(2.1)-(2.3)"),
    output("F_meas", vr::F_MEAS, "N", "force as the force sensor reads it: F_act unless the force_sensor_* parameters give it an offset, gain, curve, drift, pick-up, delay, lag, second-order filter or play"),
    output("P1_meas", vr::P1_MEAS, "Pa", "chamber 1 pressure as its transducer reads it: P1 unless the p1_sensor_* parameters give it an offset, gain, curve, drift, delay, lag or second-order filter"),
    output("P2_meas", vr::P2_MEAS, "Pa", "chamber 2 pressure as its transducer reads it: P2 unless the p2_sensor_* parameters give it an offset, gain, curve, drift, delay, lag or second-order filter"),
    output(
        "x_jp",
        vr::X_JP,
        "m",
        "jet pipe tip position relative to rest, before the offset",
    ).cite("(2.6)"),
    parameter(
        "P_s",
        vr::P_S,
        "Pa",
        652_925.0,
        "supply pressure, absolute (551.6 kPa gauge)",
    )
        .above(0.0).at_most(1e7)
        .cite("Table 2.1, (2.18)")
        .because(PRESSURE)
        .at(ChainPlace::Supply),
    parameter("P_r", vr::P_R, "Pa", 101_325.0, "return pressure, absolute")
        .above(0.0).at_most(1e7)
        .cite("(2.18)")
        .because(PRESSURE)
        .at(ChainPlace::Return),
    parameter("T", vr::T_GAS, "K", 293.15, "gas temperature, constant (2.6)")
        .above(0.0).at_most(1000.0)
        .cite("§2.6, (2.18)")
        .because("1000 K: no pneumatic actuator runs hotter; air is still an ideal gas there")
        .at(ChainPlace::Chambers),
    parameter("gamma", vr::GAMMA, "1", 1.4, "isentropic exponent of air")
        .above(1.0).at_most(5.0 / 3.0)
        .cite("(2.19)-(2.22), (2.29)")
        .because("an ideal gas has 1 < gamma <= 5/3, the monatomic value"),
    parameter("R_gas", vr::R_GAS, "J/(kg.K)", 287.0, "gas constant of air")
        .above(0.0).at_most(4200.0)
        .cite("(2.20)-(2.21)")
        .because("hydrogen, the lightest gas, has 4124 J/(kg.K)"),
    parameter("k_cd", vr::K_CD, "A/V", 0.04, "current driver gain (2.3)")
        .at_least(-1.0).at_most(1.0)
        .cite("(2.3)")
        .because("1 A/V gives 10 A at the D/A's 10 V, 25 times the coil's rated 0.4 A")
        .at(ChainPlace::CurrentDriver),
    parameter("i_offset", vr::I_OFFSET, "A", 0.0, "current driver offset (2.3)")
        .at_least(-1.0).at_most(1.0)
        .cite("(2.3)")
        .because("2.5 times the coil's rated 0.4 A")
        .at(ChainPlace::CurrentDriver)
        .step(1e-3),
    parameter(
        "omega_cd",
        vr::OMEGA_CD,
        "rad/s",
        7050.0,
        "current driver corner frequency (2.1)",
    )
        .above(0.0).at_most(1e6)
        .cite("Table 3.1, (2.1)")
        .because(RATE)
        .at(ChainPlace::CurrentDriver),
    parameter("k_m", vr::K_M, "N/A", 1.946, "jet pipe motor constant (2.4)")
        .at_least(-100.0).at_most(100.0)
        .cite("Table 3.1, (2.4)")
        .because("50 times Table 3.1's 1.946 N/A: 40 N on the jet pipe at the rated 0.4 A")
        .at(ChainPlace::JetPipe),
    parameter(
        "omega_1",
        vr::OMEGA_1,
        "rad/s",
        973.9,
        "jet pipe first-order corner (2.6)",
    )
        .above(0.0).at_most(1e6)
        .cite("Table 3.1, (2.6)")
        .because(RATE)
        .at(ChainPlace::JetPipe),
    parameter(
        "omega_2",
        vr::OMEGA_2,
        "rad/s",
        1856.7,
        "jet pipe natural frequency (2.6)",
    )
        .above(0.0).at_most(1e6)
        .cite("Table 3.1, (2.6)")
        .because(RATE)
        .at(ChainPlace::JetPipe),
    parameter("zeta_2", vr::ZETA_2, "1", 0.019, "jet pipe damping ratio (2.6)")
        .at_least(0.0).at_most(100.0)
        .cite("Table 3.1, (2.6)")
        .because("a damping ratio of 100 is already a first-order lag")
        .at(ChainPlace::JetPipe),
    parameter(
        "x_jp_sat",
        vr::X_JP_SAT,
        "m",
        0.5e-3,
        "saturation of the static jet pipe curve f3 (2.5)",
    )
        .above(0.0).at_most(0.01)
        .cite("(2.5), §3.2.1")
        .because(TRAVEL)
        .at(ChainPlace::JetPipe),
    parameter(
        "F_jp_sat",
        vr::F_JP_SAT,
        "N",
        0.45,
        "force scale of the static jet pipe curve f3 (2.5)",
    )
        .above(0.0).at_most(100.0)
        .cite("(2.5), §4.2.1")
        .because("100 N: 100 times the force the motor gives at the rated current (k_m 0.4 A = 0.8 N)")
        .at(ChainPlace::JetPipe),
    parameter(
        "x_jp_offset",
        vr::X_JP_OFFSET,
        "m",
        0.099e-3,
        "jet pipe offset from the receiver centre (2.7)",
    )
        .at_least(-0.01).at_most(0.01)
        .cite("Table 3.1, (2.7)")
        .because(TRAVEL)
        .at(ChainPlace::JetPipe)
        .step(2e-6),
    parameter(
        "D_jp",
        vr::D_JP,
        "m",
        0.9652e-3,
        "jet pipe exit and port diameter (2.5)",
    )
        .above(0.0).at_most(0.01)
        .cite("Table 3.1, (2.8)-(2.17)")
        .because("10 mm: ten times Table 3.1's jet pipe, most of the 15.9 mm bore")
        .at(ChainPlace::Valve),
    parameter("C_d", vr::C_D, "1", 0.696, "orifice discharge coefficient (2.18)")
        .above(0.0).at_most(1.0)
        .cite("Table 3.1, (2.18)")
        .because("a discharge coefficient is the actual flow over the ideal flow")
        .at(ChainPlace::Valve),
    parameter(
        "C_dm_A_lpp",
        vr::C_DM_A_LPP,
        "m2",
        -0.0475e-6,
        "leakage discharge slope times area (2.23)",
    )
        .at_least(-1e-4).at_most(1e-4)
        .cite("Table 3.1, (2.23)")
        .because(LEAK_AREA)
        .at(ChainPlace::Chambers),
    parameter(
        "C_db_A_lpp",
        vr::C_DB_A_LPP,
        "m2",
        0.0971e-6,
        "leakage discharge offset times area (2.23)",
    )
        .at_least(0.0).at_most(1e-4)
        .cite("Table 3.1, (2.23)")
        .because(LEAK_AREA)
        .at(ChainPlace::Chambers),
    parameter("L_cyl", vr::L_CYL, "m", 78.0e-3, "cylinder length")
        .above(0.0).at_most(1.0)
        .cite("Table 3.1, (2.31)")
        .because(LENGTH),
    parameter("L_p", vr::L_P, "m", 8.0e-3, "piston length")
        .above(0.0).at_most(1.0)
        .cite("Table 3.1, (2.31)-(2.32)")
        .because(LENGTH),
    parameter("L_s", vr::L_S, "m", 7.0e-3, "stopper length")
        .at_least(0.0).at_most(1.0)
        .cite("Table 3.1, (2.32)")
        .because(LENGTH),
    parameter("L_sup", vr::L_SUP, "m", 11.0e-3, "support length")
        .at_least(0.0).at_most(1.0)
        .cite("Table 3.1, (2.32)")
        .because(LENGTH)
        .at(ChainPlace::Chambers)
        .is(ConstantKind::LoadBearingLength),
    parameter(
        "L_spring0",
        vr::L_SPRING0,
        "m",
        69.1e-3,
        "unloaded spring length (2.37)",
    )
        .at_least(0.0).at_most(1.0)
        .cite("Table 3.1, (2.37)")
        .because(LENGTH),
    parameter("D_cyl", vr::D_CYL, "m", 15.875e-3, "cylinder bore")
        .above(0.0).at_most(0.5)
        .cite("Table 3.1, (2.30)-(2.31)")
        .because("a bore of 0.5 m, thirty times Table 3.1's, is no hand actuator")
        .at(ChainPlace::Mechanics),
    parameter("k_spring", vr::K_SPRING, "N/m", 88.14, "spring rate (2.37)")
        .at_least(0.0).at_most(1e5)
        .cite("Table 3.1, (2.37)")
        .because("1e5 N/m, a thousand times Table 3.1's: over the 70 mm stroke its force would exceed the piston's largest pneumatic force, A_p (P_s - P_r) = 109 N, sixty times")
        .at(ChainPlace::Mechanics),
    Row::of(Variable {
        name: "start_at_equilibrium",
        value_reference: vr::START_AT_EQUILIBRIUM,
        var_type: VarType::Boolean,
        causality: Causality::Parameter,
        variability: Variability::Fixed,
        unit: None,
        start: 1.0,
        min: None,
        max: None,
        description: "initialise at the equilibrium of the initial inputs; if false, start from P1_start and P2_start",
    }),
    parameter(
        "P1_start",
        vr::P1_START,
        "Pa",
        101_325.0,
        "initial P1 when start_at_equilibrium is false",
    )
        .above(0.0).at_most(1e7)
        .cite("(2.26)-(2.29)")
        .because(PRESSURE),
    parameter(
        "P2_start",
        vr::P2_START,
        "Pa",
        101_325.0,
        "initial P2 when start_at_equilibrium is false")
        .above(0.0).at_most(1e7)
        .cite("(2.26)-(2.29)")
        .because(PRESSURE),
    parameter("hysteresis_width", vr::HYSTERESIS_WIDTH, "m", 0.0, "jet_pipe_hysteresis: separation of the rising and falling branches of the static tip position in large sweeps (an operator after f3 whose law hysteresis_exponent selects; 0 = off)")
        .at_least(0.0).at_most(0.01)
        .cite("§3.2.1-3.2.2")
        .because(TRAVEL),
        parameter("hysteresis_deadband", vr::HYSTERESIS_DEADBAND, "m", 0.0, "jet_pipe_hysteresis: travel of the static tip position after a reversal before the hysteretic output moves (smallest play width, at most hysteresis_width)")
        .at_least(0.0).at_most(0.01)
        .cite("§3.2.1-3.2.2")
        .because(TRAVEL),
    parameter("hysteresis_exponent", vr::HYSTERESIS_EXPONENT, "1", 0.0, "jet_pipe_hysteresis law: 0 = Prandtl-Ishlinskii plays (with hysteresis_deadband); n > 0 = Bouc-Wen law with exponent n, the sharpness of the bend onto a branch (large n approaches a backlash)")
        .at_least(0.0).at_most(50.0)
        .cite("§3.2.2")
        .because("50: beyond it the bend is a corner to within 2 % of the width, the play law's shape"),
    parameter("hysteresis_gain", vr::HYSTERESIS_GAIN, "1", 1.0, "jet_pipe_hysteresis, Bouc-Wen law: gain A of dz/dx = A [1 - (a sgn(dx z) + 1 - a) |z/r|^n] (output x - z; A = 1 with a = 0.5: the output stands still after a reversal)")
        .above(0.0).at_most(2.0)
        .cite("§3.2.2")
        .because("2: with a = 0.5 the output would run backwards after a reversal as fast as the input moves"),
    parameter("hysteresis_beta_share", vr::HYSTERESIS_BETA_SHARE, "1", 0.5, "jet_pipe_hysteresis, Bouc-Wen law: share a of beta in beta + gamma (0.5 = symmetric; with a < 0.5 the output starts to move back right after a reversal)")
        .at_least(0.0).at_most(1.0)
        .cite("§3.2.2")
        .because("a share: beta and gamma are both >= 0"),
    parameter("hysteresis_start", vr::HYSTERESIS_START, "1", 0.0, "jet_pipe_hysteresis: where the loop stands at the start, in half-widths of hysteresis_width: 0 = in its middle (after a long decaying oscillation), +1 = on the rising branch (the command came from below), -1 = on the falling branch")
        .at_least(-1.0).at_most(1.0)
        .cite("§3.2.2")
        .because("the branches are one half-width either side of the middle"),
    parameter("friction_coulomb", vr::FRICTION_COULOMB, "N", 0.0, "piston_friction: Coulomb friction opposing stopper motion, (2.35) (0 = off)")
        .at_least(0.0).at_most(1000.0)
        .cite("(2.35)")
        .because("1000 N: nine times the piston's largest pneumatic force, A_p (P_s - P_r) = 109 N")
        .at(ChainPlace::Mechanics)
        .step(0.1),
    parameter("friction_velocity", vr::FRICTION_VELOCITY, "m/s", 0.0, "piston_friction: the friction reaches the Coulomb level as tanh(v / this) of the stopper velocity v (0 = at once, as (2.35))")
        .at_least(0.0).at_most(1.0)
        .cite("(2.35)")
        .because("1 m/s: ten times the stopper's fastest motion on the bench (94 mm/s)"),
    parameter("friction_stribeck", vr::FRICTION_STRIBECK, "N", 0.0, "piston_friction: the friction level gains this times exp(-(v / friction_stribeck_velocity)^2) at low stopper speed v (stiction; 0 = off)")
        .at_least(0.0).at_most(1000.0)
        .cite("(2.35)")
        .because("1000 N: nine times the piston's largest pneumatic force, A_p (P_s - P_r) = 109 N"),
    parameter("friction_stribeck_velocity", vr::FRICTION_STRIBECK_VELOCITY, "m/s", 0.0, "piston_friction: the speed over which the Stribeck term fades")
        .at_least(0.0).at_most(1.0)
        .cite("(2.35)")
        .because("1 m/s: ten times the stopper's fastest motion on the bench (94 mm/s)"),
    parameter("dead_volume_1", vr::DEAD_VOLUME_1, "m3", 0.0, "dead_volume: port and line volume added to chamber 1 (0 = off)")
        .at_least(0.0).at_most(1e-3)
        .cite("(2.30)")
        .because(DEAD_VOLUME)
        .at(ChainPlace::Chambers)
        .step(1e-7),
    parameter("dead_volume_2", vr::DEAD_VOLUME_2, "m3", 0.0, "dead_volume: port and line volume added to chamber 2 (0 = off)")
        .at_least(0.0).at_most(1e-3)
        .cite("(2.31)")
        .because(DEAD_VOLUME)
        .at(ChainPlace::Chambers)
        .step(1e-7),
    parameter("supply_resistance", vr::SUPPLY_RESISTANCE, "Pa.s/kg", 0.0, "supply_pressure_drop: the supply pressure at the jet pipe falls by this times the supply mass flow (0 = off)")
        .at_least(0.0).at_most(1e12)
        .cite("§2.6")
        .because(RESISTANCE),
    parameter("heat_transfer_fraction", vr::HEAT_TRANSFER_FRACTION, "1", 0.0, "heat_transfer: chambers polytropic with n = gamma - fraction*(gamma - 1): 0 adiabatic as the thesis, 1 isothermal")
        .at_least(0.0).at_most(1.0)
        .cite("(2.29), §2.6")
        .because("0 is adiabatic, 1 isothermal; the process lies between"),
    parameter("command_delay", vr::COMMAND_DELAY, "s", 0.0, "transport_delay: the current driver sees v_DA delayed by this time (0 = off)")
        .at_least(0.0).at_most(1.0)
        .cite("")
        .because("1 s: 500 periods of a 500 Hz force loop; a command that late is no delay any more"),
    parameter("force_sensor_offset", vr::FORCE_SENSOR_OFFSET, "N", 0.0, "sensor_offset_gain: offset of F_meas (0 = off)")
        .at_least(-1000.0).at_most(1000.0)
        .cite("")
        .because("1000 N: nine times the largest force the actuator gives (109 N)")
        .at(ChainPlace::ForceSensor)
        .step(0.1),
    parameter("force_sensor_gain", vr::FORCE_SENSOR_GAIN, "1", 1.0, "sensor_offset_gain: gain of F_meas (1 = off)")
        .above(0.0).at_most(10.0)
        .cite("")
        .because("a gain of 10 is no calibration error of a force sensor")
        .at(ChainPlace::ForceSensor),
    parameter("supply_area_scale_1", vr::SUPPLY_AREA_SCALE_1, "1", 1.0, "valve asymmetry: factor on the supply orifice area of port 1 (1 = the geometry of (2.8)-(2.17))")
        .at_least(0.0).at_most(10.0)
        .cite("(2.8)")
        .because(AREA_SCALE)
        .at(ChainPlace::Valve)
        .is(ConstantKind::PortAreaFactor),
    parameter("supply_area_scale_2", vr::SUPPLY_AREA_SCALE_2, "1", 1.0, "valve asymmetry: factor on the supply orifice area of port 2 (1 = the geometry)")
        .at_least(0.0).at_most(10.0)
        .cite("(2.10)")
        .because(AREA_SCALE)
        .at(ChainPlace::Valve)
        .is(ConstantKind::PortAreaFactor),
    parameter("return_area_scale_1", vr::RETURN_AREA_SCALE_1, "1", 1.0, "valve asymmetry: factor on the return orifice area of port 1 (1 = the geometry)")
        .at_least(0.0).at_most(10.0)
        .cite("(2.9)")
        .because(AREA_SCALE)
        .at(ChainPlace::Valve)
        .is(ConstantKind::PortAreaFactor),
    parameter("return_area_scale_2", vr::RETURN_AREA_SCALE_2, "1", 1.0, "valve asymmetry: factor on the return orifice area of port 2 (1 = the geometry)")
        .at_least(0.0).at_most(10.0)
        .cite("(2.11)")
        .because(AREA_SCALE)
        .at(ChainPlace::Valve)
        .is(ConstantKind::PortAreaFactor),
    parameter("return_resistance", vr::RETURN_RESISTANCE, "Pa.s/kg", 0.0, "return restriction: the pressure the return orifices vent into rises above P_r by this times the return mass flow (0 = off)")
        .at_least(0.0).at_most(1e12)
        .cite("(2.18)")
        .because(RESISTANCE),
    parameter("chamber_vent_1", vr::CHAMBER_VENT_1, "m2", 0.0, "chamber leak: discharge coefficient times area of a leak from chamber 1 to the return pressure (0 = off)")
        .at_least(0.0).at_most(1e-4)
        .cite("(2.24)")
        .because(LEAK_AREA),
    parameter("chamber_vent_2", vr::CHAMBER_VENT_2, "m2", 0.0, "chamber leak: discharge coefficient times area of a leak from chamber 2 to the return pressure (0 = off)")
        .at_least(0.0).at_most(1e-4)
        .cite("(2.25)")
        .because(LEAK_AREA),
    parameter("chamber_supply_leak_1", vr::CHAMBER_SUPPLY_LEAK_1, "m2", 0.0, "chamber leak: discharge coefficient times area of a leak from the supply pressure into chamber 1, by the orifice law (0 = off)")
        .at_least(0.0).at_most(1e-4)
        .cite("(2.18)")
        .because(LEAK_AREA),
    parameter("chamber_supply_leak_2", vr::CHAMBER_SUPPLY_LEAK_2, "m2", 0.0, "chamber leak: discharge coefficient times area of a leak from the supply pressure into chamber 2, by the orifice law (0 = off)")
        .at_least(0.0).at_most(1e-4)
        .cite("(2.18)")
        .because(LEAK_AREA),
    parameter("chamber_laminar_vent_1", vr::CHAMBER_LAMINAR_VENT_1, "kg/(s.Pa)", 0.0, "chamber leak: chamber 1 loses this times (P1 - P_r) to the return pressure through a long, narrow path (laminar: the flow in proportion to the pressure difference; 0 = off)")
        .at_least(0.0).at_most(1e-6)
        .cite("(2.24)")
        .because(LAMINAR_CONDUCTANCE),
    parameter("chamber_laminar_vent_2", vr::CHAMBER_LAMINAR_VENT_2, "kg/(s.Pa)", 0.0, "chamber leak: chamber 2 loses this times (P2 - P_r) to the return pressure through a long, narrow path (laminar: the flow in proportion to the pressure difference; 0 = off)")
        .at_least(0.0).at_most(1e-6)
        .cite("(2.24)")
        .because(LAMINAR_CONDUCTANCE),
    parameter("chamber_laminar_supply_leak_1", vr::CHAMBER_LAMINAR_SUPPLY_LEAK_1, "kg/(s.Pa)", 0.0, "chamber leak: chamber 1 gains this times (P_s - P1) from the supply pressure through a long, narrow path (laminar: the flow in proportion to the pressure difference; 0 = off)")
        .at_least(0.0).at_most(1e-6)
        .cite("(2.24)")
        .because(LAMINAR_CONDUCTANCE),
    parameter("chamber_laminar_supply_leak_2", vr::CHAMBER_LAMINAR_SUPPLY_LEAK_2, "kg/(s.Pa)", 0.0, "chamber leak: chamber 2 gains this times (P_s - P2) from the supply pressure through a long, narrow path (laminar: the flow in proportion to the pressure difference; 0 = off)")
        .at_least(0.0).at_most(1e-6)
        .cite("(2.25)")
        .because(LAMINAR_CONDUCTANCE),
    parameter("chamber_laminar_cross_leak", vr::CHAMBER_LAMINAR_CROSS_LEAK, "kg/(s.Pa)", 0.0, "chamber leak: this times (P1 - P2) flows from chamber 1 into chamber 2 through a long, narrow path, beside the leakage past the piston (2.23) (laminar: the flow in proportion to the pressure difference; 0 = off)")
        .at_least(0.0).at_most(1e-6)
        .cite("(2.24)-(2.25)")
        .because(LAMINAR_CONDUCTANCE),
    parameter("port_resistance_1", vr::PORT_RESISTANCE_1, "Pa.s/kg", 0.0, "port restriction: the orifices of port 1 see a pressure that differs from chamber 1's by this times the net flow through the port (0 = off)")
        .at_least(0.0).at_most(1e12)
        .cite("(2.24)")
        .because(RESISTANCE),
    parameter("port_resistance_2", vr::PORT_RESISTANCE_2, "Pa.s/kg", 0.0, "port restriction: the orifices of port 2 see a pressure that differs from chamber 2's by this times the net flow through the port (0 = off)")
        .at_least(0.0).at_most(1e12)
        .cite("(2.25)")
        .because(RESISTANCE),
    parameter("stopper_compliance", vr::STOPPER_COMPLIANCE, "m/N", 0.0, "compliance between stopper and piston: the piston sits this times the actuator force (A_p (P1 - P2), floored by the spring force) beyond the stopper, which moves the chamber volumes (0 = rigid)")
        .at_least(0.0).at_most(1e-3)
        .cite("(2.32)")
        .because("at the piston's largest force, 109 N, 1e-3 m/N would put it 0.11 m beyond the stopper, more than the 78 mm cylinder"),
    parameter("stopper_mount_lag", vr::STOPPER_MOUNT_LAG, "s", 0.0, "compliant stopper mount: the piston's offset beyond the stopper follows stopper_compliance times the actuator force through a first-order lag of this time constant, the mount's own mass and damping, instead of at once (0 = at once; needs stopper_compliance)")
        .at_least(0.0).at_most(0.1)
        .cite("(2.32)")
        .because("0.1 s: a mount that slow is no stiffness any more but a second actuator"),
    parameter("command_lag", vr::COMMAND_LAG, "s", 0.0, "command dynamics: the current driver sees v_DA through a first-order lag of this time constant, its input the command held over each communication step, its output moving along its exact response within the step (linearly between exact values at most a quarter of the lag apart) (0 = off)")
        .at_least(0.0).at_most(1.0)
        .cite("(2.1)")
        .because("1 s: a lag that long is no D/A stage any more"),
    parameter("command_filter_frequency", vr::COMMAND_FILTER_FREQUENCY, "Hz", 0.0, "command dynamics: the current driver sees v_DA, after the lag, through a second-order low-pass filter of this natural frequency, exact for its input held over each communication step, its output moving linearly between its exact values at the step's end, or at up to 16 nodes a quarter of its period apart where it is that fast (0 = off)")
        .at_least(0.0).at_most(1e5)
        .cite("(2.1)")
        .because(FILTER_FREQUENCY),
    parameter("command_filter_damping", vr::COMMAND_FILTER_DAMPING, "1", std::f64::consts::FRAC_1_SQRT_2, "command dynamics: the damping ratio of its second-order filter (1/sqrt(2): Butterworth; 1: two equal lags)")
        .above(0.0).at_most(10.0)
        .cite("(2.1)")
        .because(FILTER_DAMPING),
    parameter("command_limit", vr::COMMAND_LIMIT, "V", 0.0, "command limit: the command the current driver sees saturates at plus or minus this (0 = off)")
        .at_least(0.0).at_most(100.0)
        .cite("(2.3)")
        .because("the D/A spans 10 V either way; ten times that clips nothing"),
    parameter("command_upper_limit", vr::COMMAND_UPPER_LIMIT, "V", 100.0, "command limit on one side: the command the current driver sees saturates above this (100 or more = off)")
        .at_least(-1000.0).at_most(1000.0)
        .cite("(2.3)")
        .because("off from 100 V, ten times the D/A's span; the range leaves room either side of it"),
    parameter("command_lower_limit", vr::COMMAND_LOWER_LIMIT, "V", -100.0, "command limit on one side: the command the current driver sees saturates below this (-100 or less = off)")
        .at_least(-1000.0).at_most(1000.0)
        .cite("(2.3)")
        .because("off from 100 V, ten times the D/A's span; the range leaves room either side of it"),
    parameter("command_quantum", vr::COMMAND_QUANTUM, "V", 0.0, "command quantiser: the command the current driver sees takes only the levels command_quantum_origin + k times this, a D/A of fewer bits than the logged command (0 = off)")
        .at_least(0.0).at_most(10.0)
        .cite("(2.3)")
        .because("10 V: two levels over the D/A's 20 V, a 1-bit converter"),
    parameter("command_quantum_origin", vr::COMMAND_QUANTUM_ORIGIN, "V", 0.0, "command quantiser: a level its grid passes through (needs command_quantum)")
        .at_least(-10.0).at_most(10.0)
        .cite("(2.3)")
        .because("the grid repeats every step, so one within the D/A's span places it"),
    parameter("command_quantum_threshold", vr::COMMAND_QUANTUM_THRESHOLD, "1", 0.5, "command quantiser: the share of the way from one level to the next at which the command takes the next (0.5: the nearest level; 1: the level below, as truncation gives; needs command_quantum)")
        .at_least(0.0).at_most(1.0)
        .cite("(2.3)")
        .because("a share of one step"),
    parameter("current_limit", vr::CURRENT_LIMIT, "A", 0.0, "current limit: the coil current saturates at plus or minus this, applied to the command through k_cd and i_offset (0 = off)")
        .at_least(0.0).at_most(10.0)
        .cite("(2.1)-(2.3)")
        .because("10 A: 25 times the coil's rated 0.4 A"),
    parameter("current_slew_limit", vr::CURRENT_SLEW_LIMIT, "A/s", 0.0, "current slew limit: the command the driver sees moves towards the applied one at most this over k_cd per second, continuously (0 = off)")
        .at_least(0.0).at_most(1e6)
        .cite("(2.1)-(2.3)")
        .because("1e6 A/s: far beyond what the driver's 7050 rad/s corner slews (about 3000 A/s on a full step)"),
    parameter("f3_input_cubic", vr::F3_INPUT_CUBIC, "V", 0.0, "jet pipe static curve: the command reaching f3 is bent by this times (v_DA / 10 V)^3 (0 = off)")
        .at_least(-100.0).at_most(100.0)
        .cite("(2.5)")
        .because("100 V at full command: ten times the D/A range"),
    parameter("f3_algebraic_share", vr::F3_ALGEBRAIC_SHARE, "1", 0.0, "jet pipe static curve: f3 blends tanh u with the algebraic sigmoid u/sqrt(1 + u^2) in this share, u = F_jp/F_jp_sat: the same slope at 0 and saturation, a softer knee (0 = off: the tanh)")
        .at_least(0.0).at_most(1.0)
        .cite("(2.5)")
        .because("0 is the tanh alone and 1 the algebraic sigmoid alone; outside, the blend is no longer between two saturations"),
    parameter("force_sensor_quadratic", vr::FORCE_SENSOR_QUADRATIC, "1/N", 0.0, "force sensor curve: F_meas gains this times F_act^2 (0 = off)")
        .at_least(-1.0).at_most(1.0)
        .cite("")
        .because("1/N: at 109 N the term would be a hundred times the force"),
    parameter("force_sensor_cubic", vr::FORCE_SENSOR_CUBIC, "1/N2", 0.0, "force sensor curve: F_meas gains this times F_act^3 (0 = off)")
        .at_least(-1.0).at_most(1.0)
        .cite("")
        .because("1/N2: at 109 N the term would be ten thousand times the force"),
    parameter("force_sensor_drift", vr::FORCE_SENSOR_DRIFT, "N/s", 0.0, "force sensor drift: F_meas gains this times the time (0 = off)")
        .at_least(-1000.0).at_most(1000.0)
        .cite("")
        .because("1000 N/s: nine times the largest force every second"),
    parameter("force_sensor_lag", vr::FORCE_SENSOR_LAG, "s", 0.0, "force sensor dynamics: F_meas follows the reading through a first-order lag of this time constant, the reading taken as linear between the points it is recorded at: each communication point and, parts of the step no longer than its time constant (lag, or 1/(2 pi f)) nor than 1 ms (at most 16) (0 = off)")
        .at_least(0.0).at_most(1.0)
        .cite("")
        .because("1 s: a sensor that slow reads no dynamics at all"),
    parameter("force_sensor_delay", vr::FORCE_SENSOR_DELAY, "s", 0.0, "force sensor delay: F_meas is the reading this long ago, interpolated between communication points (0 = off)")
        .at_least(0.0).at_most(1.0)
        .cite("")
        .because("1 s: as the command delay"),
    parameter("force_sensor_play", vr::FORCE_SENSOR_PLAY, "N", 0.0, "force sensor hysteresis: F_meas stays within half this of the reading, moving only when pushed (a play operator; 0 = off)")
        .at_least(0.0).at_most(1000.0)
        .cite("")
        .because("1000 N: nine times the largest force"),
    parameter("force_sensor_ripple_sine", vr::FORCE_SENSOR_RIPPLE_SINE, "N", 0.0, "force sensor pick-up: F_meas gains this times sin(2 pi f t) (0 = off)")
        .at_least(-1000.0).at_most(1000.0)
        .cite("")
        .because("1000 N: nine times the largest force"),
    parameter("force_sensor_ripple_frequency", vr::FORCE_SENSOR_RIPPLE_FREQUENCY, "Hz", 0.0, "force sensor pick-up: its frequency f")
        .at_least(0.0).at_most(1e4)
        .cite("")
        .because("10 kHz: ten times the bench's sampling rate"),
    parameter("force_sensor_ripple_cosine", vr::FORCE_SENSOR_RIPPLE_COSINE, "N", 0.0, "force sensor pick-up: F_meas gains this times cos(2 pi f t) (0 = off)")
        .at_least(-1000.0).at_most(1000.0)
        .cite("")
        .because("1000 N: nine times the largest force"),
    parameter("force_sensor_filter_frequency", vr::FORCE_SENSOR_FILTER_FREQUENCY, "Hz", 0.0, "force sensor dynamics: F_meas follows the reading through a second-order low-pass filter of this natural frequency, the reading taken as linear between the points it is recorded at: each communication point and, parts of the step no longer than its time constant (lag, or 1/(2 pi f)) nor than 1 ms (at most 16) (0 = off)")
        .at_least(0.0).at_most(1e5)
        .cite("")
        .because(FILTER_FREQUENCY),
    parameter("force_sensor_filter_damping", vr::FORCE_SENSOR_FILTER_DAMPING, "1", std::f64::consts::FRAC_1_SQRT_2, "force sensor dynamics: the damping ratio of its second-order filter (1/sqrt(2): Butterworth; 1: two equal lags)")
        .above(0.0).at_most(10.0)
        .cite("")
        .because(FILTER_DAMPING),
    parameter("viscous_friction", vr::VISCOUS_FRICTION, "N.s/m", 0.0, "viscous friction: a force of this times the stopper velocity opposes the motion where the pressures set the force (0 = off)")
        .at_least(0.0).at_most(1e5)
        .cite("(2.33)-(2.35)")
        .because("1e5 N.s/m: 1000 N at 1 cm/s")
        .at(ChainPlace::Mechanics)
        .step(1.0),
    parameter("position_force_rate", vr::POSITION_FORCE_RATE, "N/m", 0.0, "a force of this times (x_s - position_force_reference) opposes the stopper position where the pressures set the force (0 = off)")
        .at_least(-1e5).at_most(1e5)
        .cite("(2.37)")
        .because("1e5 N/m: as the spring rate's limit"),
    parameter("position_force_reference", vr::POSITION_FORCE_REFERENCE, "m", 0.054, "where the position_force vanishes")
        .at_least(0.0).at_most(1.0)
        .cite("(2.32)")
        .because("1 m: as the lengths"),
    parameter("extra_force_acceleration", vr::EXTRA_FORCE_ACCELERATION, "kg", 0.0, "extra force on the piston: the force the sensor reads gains this times the stopper acceleration (the change of the stopper's mean velocity between the last two communication steps, over their mean length) where the pressures set the force; a moving mass m is -m (0 = off)")
        .at_least(-100.0).at_most(100.0)
        .cite("(2.36)")
        .because("100 kg: a thousand times the piston's mass"),
    parameter("extra_force_velocity_squared", vr::EXTRA_FORCE_VELOCITY_SQUARED, "N.s2/m2", 0.0, "extra force on the piston: the force the sensor reads gains this times v |v|, v the stopper velocity, where the pressures set the force; quadratic damping is negative (0 = off)")
        .at_least(-1e7).at_most(1e7)
        .cite("(2.36)")
        .because("1e7 N.s2/m2: 1000 N at 1 cm/s"),
    parameter("extra_force_sign_pressure", vr::EXTRA_FORCE_SIGN_PRESSURE, "m2", 0.0, "extra force on the piston: the force the sensor reads gains this times tanh(v / extra_force_sign_velocity) (P1 + P2 - 2 P_r) where the pressures set the force; a seal friction that grows with the pressure is negative (0 = off)")
        .at_least(-1e-3).at_most(1e-3)
        .cite("(2.36)")
        .because("1e-3 m2: about four times the piston area"),
    parameter("extra_force_pressure_difference", vr::EXTRA_FORCE_PRESSURE_DIFFERENCE, "m2", 0.0, "extra force on the piston: the force the sensor reads gains this times (P1 - P2) where the pressures set the force: an error of the effective piston area (0 = off)")
        .at_least(-1e-3).at_most(1e-3)
        .cite("(2.36)")
        .because("1e-3 m2: about four times the piston area")
        .at(ChainPlace::Mechanics)
        .step(1e-6),
    parameter("extra_force_sign_velocity", vr::EXTRA_FORCE_SIGN_VELOCITY, "m/s", 1e-3, "the speed over which the smooth sign tanh(v / this) of extra_force_sign_pressure turns")
        .at_least(1e-6).at_most(1.0)
        .cite("")
        .because("1 m/s: far beyond the stopper's speeds; 1 um/s: a sharp sign"),
    parameter("stopper_acceleration_input_share", vr::STOPPER_ACCELERATION_INPUT_SHARE, "1", 0.0, "the stopper acceleration the extra forces read is this share of the input a_s plus the rest of the acceleration formed from the stopper positions: 1 for a master that knows the stopper's acceleration (a finger model, or a smoothed estimate from a recording), 0 to form it from x_s alone")
        .at_least(0.0).at_most(1.0)
        .cite("(2.36)")
        .because("a share of one of two estimates of the same acceleration"),
    parameter("return_vent_area", vr::RETURN_VENT_AREA, "m2", 0.0, "return restriction: the return orifices vent into a plenum that empties to P_r through an orifice of this discharge coefficient times area, (2.18) (0 = off: the return orifices see P_r)")
        .at_least(0.0).at_most(1e-4)
        .cite("(2.18)")
        .because(LEAK_AREA),
    parameter("supply_drift", vr::SUPPLY_DRIFT, "Pa/s", 0.0, "supply drift: the supply pressure is P_s plus this times the time, held over each communication step at its mid-step value (0 = off)")
        .at_least(-1e6).at_most(1e6)
        .cite("§2.6")
        .because("1e6 Pa/s: the whole supply in about half a second"),
    parameter("supply_ripple_sine", vr::SUPPLY_RIPPLE_SINE, "Pa", 0.0, "supply ripple: the supply pressure gains this times sin(2 pi f t), held over each communication step at its mid-step value (0 = off)")
        .at_least(-1e7).at_most(1e7)
        .cite("§2.6")
        .because(PRESSURE),
    parameter("supply_ripple_frequency", vr::SUPPLY_RIPPLE_FREQUENCY, "Hz", 0.0, "supply ripple: its frequency f")
        .at_least(0.0).at_most(1e4)
        .cite("§2.6")
        .because("10 kHz: ten times the bench's sampling rate"),
    parameter("supply_ripple_cosine", vr::SUPPLY_RIPPLE_COSINE, "Pa", 0.0, "supply ripple: the supply pressure gains this times cos(2 pi f t), held likewise (0 = off)")
        .at_least(-1e7).at_most(1e7)
        .cite("§2.6")
        .because(PRESSURE),
    parameter("x_jp_offset_drift", vr::X_JP_OFFSET_DRIFT, "m/s", 0.0, "jet pipe null drift: x_jp_offset gains this times the time, held over each communication step at its mid-step value (0 = off)")
        .at_least(-0.01).at_most(0.01)
        .cite("(2.7)")
        .because("10 mm/s: the whole receiver travel in a third of a second"),
    parameter("T_drift", vr::T_DRIFT, "K/s", 0.0, "gas temperature drift: the gas temperature T of (2.6) is T plus this times the time, in the chambers and the orifice flows, held over each communication step at its mid-step value (0 = off)")
        .at_least(-10.0).at_most(10.0)
        .cite("§2.6, (2.20)-(2.21), (2.29)")
        .because("10 K/s: the gas warms by its own absolute temperature in half a minute"),
    parameter("p1_sensor_offset", vr::P1_SENSOR_OFFSET, "Pa", 0.0, "pressure transducer 1: offset of P1_meas (0 = off)")
        .at_least(-1e6).at_most(1e6)
        .cite("")
        .because("1 MPa: more than the supply's gauge pressure (551.6 kPa)")
        .at(ChainPlace::PressureSensors)
        .step(100.0),
    parameter("p1_sensor_gain", vr::P1_SENSOR_GAIN, "1", 1.0, "pressure transducer 1: gain of P1_meas (1 = off)")
        .above(0.0).at_most(10.0)
        .cite("")
        .because("a transducer reads a rise as a rise (gain > 0); ten times is no longer a calibration error")
        .at(ChainPlace::PressureSensors),
    parameter("p1_sensor_drift", vr::P1_SENSOR_DRIFT, "Pa/s", 0.0, "pressure transducer 1: P1_meas gains this times the time (0 = off)")
        .at_least(-1e5).at_most(1e5)
        .cite("")
        .because("1e5 Pa/s: the supply's gauge pressure in under six seconds"),
    parameter("p1_sensor_lag", vr::P1_SENSOR_LAG, "s", 0.0, "pressure transducer 1: P1_meas follows the reading through a first-order lag of this time constant, the reading taken as linear between the points it is recorded at: each communication point and, parts of the step no longer than its time constant (lag, or 1/(2 pi f)) nor than 1 ms (at most 16) (0 = off)")
        .at_least(0.0).at_most(1.0)
        .cite("")
        .because("1 s: a transducer that slow reads no dynamics at all"),
    parameter("p1_sensor_delay", vr::P1_SENSOR_DELAY, "s", 0.0, "pressure transducer 1: P1_meas is the reading this long ago, interpolated between communication points (0 = off)")
        .at_least(0.0).at_most(1.0)
        .cite("")
        .because("1 s: as the command delay"),
    parameter("p1_sensor_filter_frequency", vr::P1_SENSOR_FILTER_FREQUENCY, "Hz", 0.0, "pressure transducer 1: P1_meas follows the reading through a second-order low-pass filter of this natural frequency, the reading taken as linear between the points it is recorded at: each communication point and, parts of the step no longer than its time constant (lag, or 1/(2 pi f)) nor than 1 ms (at most 16) (0 = off)")
        .at_least(0.0).at_most(1e5)
        .cite("")
        .because(FILTER_FREQUENCY),
    parameter("p1_sensor_filter_damping", vr::P1_SENSOR_FILTER_DAMPING, "1", std::f64::consts::FRAC_1_SQRT_2, "pressure transducer 1: the damping ratio of its second-order filter (1/sqrt(2): Butterworth; 1: two equal lags)")
        .above(0.0).at_most(10.0)
        .cite("")
        .because(FILTER_DAMPING),
    parameter("p2_sensor_offset", vr::P2_SENSOR_OFFSET, "Pa", 0.0, "pressure transducer 2: offset of P2_meas (0 = off)")
        .at_least(-1e6).at_most(1e6)
        .cite("")
        .because("1 MPa: more than the supply's gauge pressure (551.6 kPa)")
        .at(ChainPlace::PressureSensors)
        .step(100.0),
    parameter("p2_sensor_gain", vr::P2_SENSOR_GAIN, "1", 1.0, "pressure transducer 2: gain of P2_meas (1 = off)")
        .above(0.0).at_most(10.0)
        .cite("")
        .because("a transducer reads a rise as a rise (gain > 0); ten times is no longer a calibration error")
        .at(ChainPlace::PressureSensors),
    parameter("p2_sensor_drift", vr::P2_SENSOR_DRIFT, "Pa/s", 0.0, "pressure transducer 2: P2_meas gains this times the time (0 = off)")
        .at_least(-1e5).at_most(1e5)
        .cite("")
        .because("1e5 Pa/s: the supply's gauge pressure in under six seconds"),
    parameter("p2_sensor_lag", vr::P2_SENSOR_LAG, "s", 0.0, "pressure transducer 2: P2_meas follows the reading through a first-order lag of this time constant, the reading taken as linear between the points it is recorded at: each communication point and, parts of the step no longer than its time constant (lag, or 1/(2 pi f)) nor than 1 ms (at most 16) (0 = off)")
        .at_least(0.0).at_most(1.0)
        .cite("")
        .because("1 s: a transducer that slow reads no dynamics at all"),
    parameter("p2_sensor_delay", vr::P2_SENSOR_DELAY, "s", 0.0, "pressure transducer 2: P2_meas is the reading this long ago, interpolated between communication points (0 = off)")
        .at_least(0.0).at_most(1.0)
        .cite("")
        .because("1 s: as the command delay"),
    parameter("p2_sensor_filter_frequency", vr::P2_SENSOR_FILTER_FREQUENCY, "Hz", 0.0, "pressure transducer 2: P2_meas follows the reading through a second-order low-pass filter of this natural frequency, the reading taken as linear between the points it is recorded at: each communication point and, parts of the step no longer than its time constant (lag, or 1/(2 pi f)) nor than 1 ms (at most 16) (0 = off)")
        .at_least(0.0).at_most(1e5)
        .cite("")
        .because(FILTER_FREQUENCY),
    parameter("p2_sensor_filter_damping", vr::P2_SENSOR_FILTER_DAMPING, "1", std::f64::consts::FRAC_1_SQRT_2, "pressure transducer 2: the damping ratio of its second-order filter (1/sqrt(2): Butterworth; 1: two equal lags)")
        .above(0.0).at_most(10.0)
        .cite("")
        .because(FILTER_DAMPING),
    parameter("supply_restriction_area", vr::SUPPLY_RESTRICTION_AREA, "m2", 0.0, "supply restriction: the jet pipe draws its supply through an orifice of this discharge coefficient times area, (2.18), instead of from P_s directly (0 = off; not with supply_resistance)")
        .at_least(0.0).at_most(1e-4)
        .cite("(2.18), §2.6")
        .because(LEAK_AREA),
    parameter("supply_plenum_volume", vr::SUPPLY_PLENUM_VOLUME, "m3", 0.0, "supply plenum: a gas volume between the supply restriction and the jet pipe, whose pressure follows (2.29) (0 = the restriction alone; needs supply_resistance or supply_restriction_area)")
        .at_least(0.0).at_most(1e-3)
        .cite("(2.29)")
        .because(DEAD_VOLUME),
    parameter("return_plenum_volume", vr::RETURN_PLENUM_VOLUME, "m3", 0.0, "return plenum: a gas volume between the return orifices and the return restriction, whose pressure follows (2.29) (0 = the restriction alone; needs return_resistance or return_vent_area)")
        .at_least(0.0).at_most(1e-3)
        .cite("(2.29)")
        .because(DEAD_VOLUME),
    parameter("port_restriction_area_1", vr::PORT_RESTRICTION_AREA_1, "m2", 0.0, "port restriction: receiver port 1 reaches chamber 1 through an orifice of this discharge coefficient times area, (2.18) (0 = off; not with port_resistance_1)")
        .at_least(0.0).at_most(1e-4)
        .cite("(2.18), (2.24)")
        .because(LEAK_AREA),
    parameter("port_restriction_area_2", vr::PORT_RESTRICTION_AREA_2, "m2", 0.0, "port restriction: receiver port 2 reaches chamber 2 through an orifice of this discharge coefficient times area, (2.18) (0 = off; not with port_resistance_2)")
        .at_least(0.0).at_most(1e-4)
        .cite("(2.18), (2.25)")
        .because(LEAK_AREA),
    parameter("port_line_volume_1", vr::PORT_LINE_VOLUME_1, "m3", 0.0, "port line: a gas volume between receiver port 1 and its restriction, whose pressure follows (2.29) (0 = the restriction alone; needs port_resistance_1 or port_restriction_area_1)")
        .at_least(0.0).at_most(1e-3)
        .cite("(2.29)")
        .because(DEAD_VOLUME),
    parameter("port_line_volume_2", vr::PORT_LINE_VOLUME_2, "m3", 0.0, "port line: a gas volume between receiver port 2 and its restriction, whose pressure follows (2.29) (0 = the restriction alone; needs port_resistance_2 or port_restriction_area_2)")
        .at_least(0.0).at_most(1e-3)
        .cite("(2.29)")
        .because(DEAD_VOLUME),
    parameter("command_curve_knots", vr::COMMAND_CURVE_KNOTS, "1", 0.0, "command static curve: the number of knots in use, piecewise linear between them and along the end segments beyond (0 = off; else 2 to 8, abscissae increasing)").at_least(0.0).at_most(8.0).because("at most 8 knots"),
    parameter("command_curve_x_1", vr::COMMAND_CURVE_X, "V", 0.0, "command static curve: knot 1, the logged command v_DA").at_least(-100.0).at_most(100.0).because(CURVE_COMMAND),
    parameter("command_curve_x_2", vr::COMMAND_CURVE_X + 1, "V", 0.0, "command static curve: knot 2, the logged command v_DA").at_least(-100.0).at_most(100.0).because(CURVE_COMMAND),
    parameter("command_curve_x_3", vr::COMMAND_CURVE_X + 2, "V", 0.0, "command static curve: knot 3, the logged command v_DA").at_least(-100.0).at_most(100.0).because(CURVE_COMMAND),
    parameter("command_curve_x_4", vr::COMMAND_CURVE_X + 3, "V", 0.0, "command static curve: knot 4, the logged command v_DA").at_least(-100.0).at_most(100.0).because(CURVE_COMMAND),
    parameter("command_curve_x_5", vr::COMMAND_CURVE_X + 4, "V", 0.0, "command static curve: knot 5, the logged command v_DA").at_least(-100.0).at_most(100.0).because(CURVE_COMMAND),
    parameter("command_curve_x_6", vr::COMMAND_CURVE_X + 5, "V", 0.0, "command static curve: knot 6, the logged command v_DA").at_least(-100.0).at_most(100.0).because(CURVE_COMMAND),
    parameter("command_curve_x_7", vr::COMMAND_CURVE_X + 6, "V", 0.0, "command static curve: knot 7, the logged command v_DA").at_least(-100.0).at_most(100.0).because(CURVE_COMMAND),
    parameter("command_curve_x_8", vr::COMMAND_CURVE_X + 7, "V", 0.0, "command static curve: knot 8, the logged command v_DA").at_least(-100.0).at_most(100.0).because(CURVE_COMMAND),
    parameter("command_curve_y_1", vr::COMMAND_CURVE_Y, "V", 0.0, "command static curve: knot 1, the command the current driver sees there").at_least(-100.0).at_most(100.0).because(CURVE_COMMAND),
    parameter("command_curve_y_2", vr::COMMAND_CURVE_Y + 1, "V", 0.0, "command static curve: knot 2, the command the current driver sees there").at_least(-100.0).at_most(100.0).because(CURVE_COMMAND),
    parameter("command_curve_y_3", vr::COMMAND_CURVE_Y + 2, "V", 0.0, "command static curve: knot 3, the command the current driver sees there").at_least(-100.0).at_most(100.0).because(CURVE_COMMAND),
    parameter("command_curve_y_4", vr::COMMAND_CURVE_Y + 3, "V", 0.0, "command static curve: knot 4, the command the current driver sees there").at_least(-100.0).at_most(100.0).because(CURVE_COMMAND),
    parameter("command_curve_y_5", vr::COMMAND_CURVE_Y + 4, "V", 0.0, "command static curve: knot 5, the command the current driver sees there").at_least(-100.0).at_most(100.0).because(CURVE_COMMAND),
    parameter("command_curve_y_6", vr::COMMAND_CURVE_Y + 5, "V", 0.0, "command static curve: knot 6, the command the current driver sees there").at_least(-100.0).at_most(100.0).because(CURVE_COMMAND),
    parameter("command_curve_y_7", vr::COMMAND_CURVE_Y + 6, "V", 0.0, "command static curve: knot 7, the command the current driver sees there").at_least(-100.0).at_most(100.0).because(CURVE_COMMAND),
    parameter("command_curve_y_8", vr::COMMAND_CURVE_Y + 7, "V", 0.0, "command static curve: knot 8, the command the current driver sees there").at_least(-100.0).at_most(100.0).because(CURVE_COMMAND),
    parameter("force_sensor_curve_knots", vr::FORCE_SENSOR_CURVE_KNOTS, "1", 0.0, "force sensor static curve: the number of knots in use, piecewise linear between them and along the end segments beyond (0 = off; else 2 to 8, abscissae increasing)").at_least(0.0).at_most(8.0).because("at most 8 knots"),
    parameter("force_sensor_curve_x_1", vr::FORCE_SENSOR_CURVE_X, "N", 0.0, "force sensor static curve: knot 1, the force F_act").at_least(-1000.0).at_most(1000.0).because(CURVE_FORCE),
    parameter("force_sensor_curve_x_2", vr::FORCE_SENSOR_CURVE_X + 1, "N", 0.0, "force sensor static curve: knot 2, the force F_act").at_least(-1000.0).at_most(1000.0).because(CURVE_FORCE),
    parameter("force_sensor_curve_x_3", vr::FORCE_SENSOR_CURVE_X + 2, "N", 0.0, "force sensor static curve: knot 3, the force F_act").at_least(-1000.0).at_most(1000.0).because(CURVE_FORCE),
    parameter("force_sensor_curve_x_4", vr::FORCE_SENSOR_CURVE_X + 3, "N", 0.0, "force sensor static curve: knot 4, the force F_act").at_least(-1000.0).at_most(1000.0).because(CURVE_FORCE),
    parameter("force_sensor_curve_x_5", vr::FORCE_SENSOR_CURVE_X + 4, "N", 0.0, "force sensor static curve: knot 5, the force F_act").at_least(-1000.0).at_most(1000.0).because(CURVE_FORCE),
    parameter("force_sensor_curve_x_6", vr::FORCE_SENSOR_CURVE_X + 5, "N", 0.0, "force sensor static curve: knot 6, the force F_act").at_least(-1000.0).at_most(1000.0).because(CURVE_FORCE),
    parameter("force_sensor_curve_x_7", vr::FORCE_SENSOR_CURVE_X + 6, "N", 0.0, "force sensor static curve: knot 7, the force F_act").at_least(-1000.0).at_most(1000.0).because(CURVE_FORCE),
    parameter("force_sensor_curve_x_8", vr::FORCE_SENSOR_CURVE_X + 7, "N", 0.0, "force sensor static curve: knot 8, the force F_act").at_least(-1000.0).at_most(1000.0).because(CURVE_FORCE),
    parameter("force_sensor_curve_y_1", vr::FORCE_SENSOR_CURVE_Y, "N", 0.0, "force sensor static curve: knot 1, its reading there").at_least(-1000.0).at_most(1000.0).because(CURVE_FORCE),
    parameter("force_sensor_curve_y_2", vr::FORCE_SENSOR_CURVE_Y + 1, "N", 0.0, "force sensor static curve: knot 2, its reading there").at_least(-1000.0).at_most(1000.0).because(CURVE_FORCE),
    parameter("force_sensor_curve_y_3", vr::FORCE_SENSOR_CURVE_Y + 2, "N", 0.0, "force sensor static curve: knot 3, its reading there").at_least(-1000.0).at_most(1000.0).because(CURVE_FORCE),
    parameter("force_sensor_curve_y_4", vr::FORCE_SENSOR_CURVE_Y + 3, "N", 0.0, "force sensor static curve: knot 4, its reading there").at_least(-1000.0).at_most(1000.0).because(CURVE_FORCE),
    parameter("force_sensor_curve_y_5", vr::FORCE_SENSOR_CURVE_Y + 4, "N", 0.0, "force sensor static curve: knot 5, its reading there").at_least(-1000.0).at_most(1000.0).because(CURVE_FORCE),
    parameter("force_sensor_curve_y_6", vr::FORCE_SENSOR_CURVE_Y + 5, "N", 0.0, "force sensor static curve: knot 6, its reading there").at_least(-1000.0).at_most(1000.0).because(CURVE_FORCE),
    parameter("force_sensor_curve_y_7", vr::FORCE_SENSOR_CURVE_Y + 6, "N", 0.0, "force sensor static curve: knot 7, its reading there").at_least(-1000.0).at_most(1000.0).because(CURVE_FORCE),
    parameter("force_sensor_curve_y_8", vr::FORCE_SENSOR_CURVE_Y + 7, "N", 0.0, "force sensor static curve: knot 8, its reading there").at_least(-1000.0).at_most(1000.0).because(CURVE_FORCE),
    parameter("p1_sensor_curve_knots", vr::P1_SENSOR_CURVE_KNOTS, "1", 0.0, "pressure transducer 1 static curve: the number of knots in use, piecewise linear between them and along the end segments beyond (0 = off; else 2 to 8, abscissae increasing)").at_least(0.0).at_most(8.0).because("at most 8 knots"),
    parameter("p1_sensor_curve_x_1", vr::P1_SENSOR_CURVE_X, "Pa", 0.0, "pressure transducer 1 static curve: knot 1, the pressure P1").at_least(-1e7).at_most(1e7).because(CURVE_PRESSURE),
    parameter("p1_sensor_curve_x_2", vr::P1_SENSOR_CURVE_X + 1, "Pa", 0.0, "pressure transducer 1 static curve: knot 2, the pressure P1").at_least(-1e7).at_most(1e7).because(CURVE_PRESSURE),
    parameter("p1_sensor_curve_x_3", vr::P1_SENSOR_CURVE_X + 2, "Pa", 0.0, "pressure transducer 1 static curve: knot 3, the pressure P1").at_least(-1e7).at_most(1e7).because(CURVE_PRESSURE),
    parameter("p1_sensor_curve_x_4", vr::P1_SENSOR_CURVE_X + 3, "Pa", 0.0, "pressure transducer 1 static curve: knot 4, the pressure P1").at_least(-1e7).at_most(1e7).because(CURVE_PRESSURE),
    parameter("p1_sensor_curve_x_5", vr::P1_SENSOR_CURVE_X + 4, "Pa", 0.0, "pressure transducer 1 static curve: knot 5, the pressure P1").at_least(-1e7).at_most(1e7).because(CURVE_PRESSURE),
    parameter("p1_sensor_curve_x_6", vr::P1_SENSOR_CURVE_X + 5, "Pa", 0.0, "pressure transducer 1 static curve: knot 6, the pressure P1").at_least(-1e7).at_most(1e7).because(CURVE_PRESSURE),
    parameter("p1_sensor_curve_x_7", vr::P1_SENSOR_CURVE_X + 6, "Pa", 0.0, "pressure transducer 1 static curve: knot 7, the pressure P1").at_least(-1e7).at_most(1e7).because(CURVE_PRESSURE),
    parameter("p1_sensor_curve_x_8", vr::P1_SENSOR_CURVE_X + 7, "Pa", 0.0, "pressure transducer 1 static curve: knot 8, the pressure P1").at_least(-1e7).at_most(1e7).because(CURVE_PRESSURE),
    parameter("p1_sensor_curve_y_1", vr::P1_SENSOR_CURVE_Y, "Pa", 0.0, "pressure transducer 1 static curve: knot 1, its reading there").at_least(-1e7).at_most(1e7).because(CURVE_PRESSURE),
    parameter("p1_sensor_curve_y_2", vr::P1_SENSOR_CURVE_Y + 1, "Pa", 0.0, "pressure transducer 1 static curve: knot 2, its reading there").at_least(-1e7).at_most(1e7).because(CURVE_PRESSURE),
    parameter("p1_sensor_curve_y_3", vr::P1_SENSOR_CURVE_Y + 2, "Pa", 0.0, "pressure transducer 1 static curve: knot 3, its reading there").at_least(-1e7).at_most(1e7).because(CURVE_PRESSURE),
    parameter("p1_sensor_curve_y_4", vr::P1_SENSOR_CURVE_Y + 3, "Pa", 0.0, "pressure transducer 1 static curve: knot 4, its reading there").at_least(-1e7).at_most(1e7).because(CURVE_PRESSURE),
    parameter("p1_sensor_curve_y_5", vr::P1_SENSOR_CURVE_Y + 4, "Pa", 0.0, "pressure transducer 1 static curve: knot 5, its reading there").at_least(-1e7).at_most(1e7).because(CURVE_PRESSURE),
    parameter("p1_sensor_curve_y_6", vr::P1_SENSOR_CURVE_Y + 5, "Pa", 0.0, "pressure transducer 1 static curve: knot 6, its reading there").at_least(-1e7).at_most(1e7).because(CURVE_PRESSURE),
    parameter("p1_sensor_curve_y_7", vr::P1_SENSOR_CURVE_Y + 6, "Pa", 0.0, "pressure transducer 1 static curve: knot 7, its reading there").at_least(-1e7).at_most(1e7).because(CURVE_PRESSURE),
    parameter("p1_sensor_curve_y_8", vr::P1_SENSOR_CURVE_Y + 7, "Pa", 0.0, "pressure transducer 1 static curve: knot 8, its reading there").at_least(-1e7).at_most(1e7).because(CURVE_PRESSURE),
    parameter("p2_sensor_curve_knots", vr::P2_SENSOR_CURVE_KNOTS, "1", 0.0, "pressure transducer 2 static curve: the number of knots in use, piecewise linear between them and along the end segments beyond (0 = off; else 2 to 8, abscissae increasing)").at_least(0.0).at_most(8.0).because("at most 8 knots"),
    parameter("p2_sensor_curve_x_1", vr::P2_SENSOR_CURVE_X, "Pa", 0.0, "pressure transducer 2 static curve: knot 1, the pressure P2").at_least(-1e7).at_most(1e7).because(CURVE_PRESSURE),
    parameter("p2_sensor_curve_x_2", vr::P2_SENSOR_CURVE_X + 1, "Pa", 0.0, "pressure transducer 2 static curve: knot 2, the pressure P2").at_least(-1e7).at_most(1e7).because(CURVE_PRESSURE),
    parameter("p2_sensor_curve_x_3", vr::P2_SENSOR_CURVE_X + 2, "Pa", 0.0, "pressure transducer 2 static curve: knot 3, the pressure P2").at_least(-1e7).at_most(1e7).because(CURVE_PRESSURE),
    parameter("p2_sensor_curve_x_4", vr::P2_SENSOR_CURVE_X + 3, "Pa", 0.0, "pressure transducer 2 static curve: knot 4, the pressure P2").at_least(-1e7).at_most(1e7).because(CURVE_PRESSURE),
    parameter("p2_sensor_curve_x_5", vr::P2_SENSOR_CURVE_X + 4, "Pa", 0.0, "pressure transducer 2 static curve: knot 5, the pressure P2").at_least(-1e7).at_most(1e7).because(CURVE_PRESSURE),
    parameter("p2_sensor_curve_x_6", vr::P2_SENSOR_CURVE_X + 5, "Pa", 0.0, "pressure transducer 2 static curve: knot 6, the pressure P2").at_least(-1e7).at_most(1e7).because(CURVE_PRESSURE),
    parameter("p2_sensor_curve_x_7", vr::P2_SENSOR_CURVE_X + 6, "Pa", 0.0, "pressure transducer 2 static curve: knot 7, the pressure P2").at_least(-1e7).at_most(1e7).because(CURVE_PRESSURE),
    parameter("p2_sensor_curve_x_8", vr::P2_SENSOR_CURVE_X + 7, "Pa", 0.0, "pressure transducer 2 static curve: knot 8, the pressure P2").at_least(-1e7).at_most(1e7).because(CURVE_PRESSURE),
    parameter("p2_sensor_curve_y_1", vr::P2_SENSOR_CURVE_Y, "Pa", 0.0, "pressure transducer 2 static curve: knot 1, its reading there").at_least(-1e7).at_most(1e7).because(CURVE_PRESSURE),
    parameter("p2_sensor_curve_y_2", vr::P2_SENSOR_CURVE_Y + 1, "Pa", 0.0, "pressure transducer 2 static curve: knot 2, its reading there").at_least(-1e7).at_most(1e7).because(CURVE_PRESSURE),
    parameter("p2_sensor_curve_y_3", vr::P2_SENSOR_CURVE_Y + 2, "Pa", 0.0, "pressure transducer 2 static curve: knot 3, its reading there").at_least(-1e7).at_most(1e7).because(CURVE_PRESSURE),
    parameter("p2_sensor_curve_y_4", vr::P2_SENSOR_CURVE_Y + 3, "Pa", 0.0, "pressure transducer 2 static curve: knot 4, its reading there").at_least(-1e7).at_most(1e7).because(CURVE_PRESSURE),
    parameter("p2_sensor_curve_y_5", vr::P2_SENSOR_CURVE_Y + 4, "Pa", 0.0, "pressure transducer 2 static curve: knot 5, its reading there").at_least(-1e7).at_most(1e7).because(CURVE_PRESSURE),
    parameter("p2_sensor_curve_y_6", vr::P2_SENSOR_CURVE_Y + 5, "Pa", 0.0, "pressure transducer 2 static curve: knot 6, its reading there").at_least(-1e7).at_most(1e7).because(CURVE_PRESSURE),
    parameter("p2_sensor_curve_y_7", vr::P2_SENSOR_CURVE_Y + 6, "Pa", 0.0, "pressure transducer 2 static curve: knot 7, its reading there").at_least(-1e7).at_most(1e7).because(CURVE_PRESSURE),
    parameter("p2_sensor_curve_y_8", vr::P2_SENSOR_CURVE_Y + 7, "Pa", 0.0, "pressure transducer 2 static curve: knot 8, its reading there").at_least(-1e7).at_most(1e7).because(CURVE_PRESSURE),
    parameter("discharge_curve_knots", vr::DISCHARGE_CURVE_KNOTS, "1", 0.0, "discharge curve: the valve orifices' C_d as a function of the pressure ratio P_down/P_up across each, in place of C_d (area factors still apply): the number of knots in use, piecewise linear between them and along the end segments beyond, not below 0 (0 = off, C_d constant; else 2 to 8, abscissae increasing)").at_least(0.0).at_most(8.0).because("at most 8 knots"),
    parameter("discharge_curve_x_1", vr::DISCHARGE_CURVE_X, "1", 0.0, "discharge curve: knot 1, the pressure ratio P_down/P_up").at_least(0.0).at_most(1.0).because(CURVE_RATIO),
    parameter("discharge_curve_x_2", vr::DISCHARGE_CURVE_X + 1, "1", 0.0, "discharge curve: knot 2, the pressure ratio P_down/P_up").at_least(0.0).at_most(1.0).because(CURVE_RATIO),
    parameter("discharge_curve_x_3", vr::DISCHARGE_CURVE_X + 2, "1", 0.0, "discharge curve: knot 3, the pressure ratio P_down/P_up").at_least(0.0).at_most(1.0).because(CURVE_RATIO),
    parameter("discharge_curve_x_4", vr::DISCHARGE_CURVE_X + 3, "1", 0.0, "discharge curve: knot 4, the pressure ratio P_down/P_up").at_least(0.0).at_most(1.0).because(CURVE_RATIO),
    parameter("discharge_curve_x_5", vr::DISCHARGE_CURVE_X + 4, "1", 0.0, "discharge curve: knot 5, the pressure ratio P_down/P_up").at_least(0.0).at_most(1.0).because(CURVE_RATIO),
    parameter("discharge_curve_x_6", vr::DISCHARGE_CURVE_X + 5, "1", 0.0, "discharge curve: knot 6, the pressure ratio P_down/P_up").at_least(0.0).at_most(1.0).because(CURVE_RATIO),
    parameter("discharge_curve_x_7", vr::DISCHARGE_CURVE_X + 6, "1", 0.0, "discharge curve: knot 7, the pressure ratio P_down/P_up").at_least(0.0).at_most(1.0).because(CURVE_RATIO),
    parameter("discharge_curve_x_8", vr::DISCHARGE_CURVE_X + 7, "1", 0.0, "discharge curve: knot 8, the pressure ratio P_down/P_up").at_least(0.0).at_most(1.0).because(CURVE_RATIO),
    parameter("discharge_curve_y_1", vr::DISCHARGE_CURVE_Y, "1", 0.0, "discharge curve: knot 1, C_d at that ratio").at_least(0.0).at_most(1.0).because(CURVE_DISCHARGE),
    parameter("discharge_curve_y_2", vr::DISCHARGE_CURVE_Y + 1, "1", 0.0, "discharge curve: knot 2, C_d at that ratio").at_least(0.0).at_most(1.0).because(CURVE_DISCHARGE),
    parameter("discharge_curve_y_3", vr::DISCHARGE_CURVE_Y + 2, "1", 0.0, "discharge curve: knot 3, C_d at that ratio").at_least(0.0).at_most(1.0).because(CURVE_DISCHARGE),
    parameter("discharge_curve_y_4", vr::DISCHARGE_CURVE_Y + 3, "1", 0.0, "discharge curve: knot 4, C_d at that ratio").at_least(0.0).at_most(1.0).because(CURVE_DISCHARGE),
    parameter("discharge_curve_y_5", vr::DISCHARGE_CURVE_Y + 4, "1", 0.0, "discharge curve: knot 5, C_d at that ratio").at_least(0.0).at_most(1.0).because(CURVE_DISCHARGE),
    parameter("discharge_curve_y_6", vr::DISCHARGE_CURVE_Y + 5, "1", 0.0, "discharge curve: knot 6, C_d at that ratio").at_least(0.0).at_most(1.0).because(CURVE_DISCHARGE),
    parameter("discharge_curve_y_7", vr::DISCHARGE_CURVE_Y + 6, "1", 0.0, "discharge curve: knot 7, C_d at that ratio").at_least(0.0).at_most(1.0).because(CURVE_DISCHARGE),
    parameter("discharge_curve_y_8", vr::DISCHARGE_CURVE_Y + 7, "1", 0.0, "discharge curve: knot 8, C_d at that ratio").at_least(0.0).at_most(1.0).because(CURVE_DISCHARGE),
];

const N_VARIABLES: usize = TABLE.len();

const fn variables_of(rows: &[Row]) -> [Variable; N_VARIABLES] {
    let mut out = [rows[0].variable; N_VARIABLES];
    let mut k = 1;
    while k < N_VARIABLES {
        out[k] = rows[k].variable;
        k += 1;
    }
    out
}

// A const, not a static, so that `VARIABLES` below stays a const slice; it is built at compile
// time once.
#[allow(clippy::large_const_arrays)]
const VARIABLE_ARRAY: [Variable; N_VARIABLES] = variables_of(TABLE);

/// The variables of [`TABLE`], in its order (the FMU crate's `variables::VARIABLES` are these
/// as the FMI layer's variables: what the model description, the getters and the setters see).
pub const VARIABLES: &[Variable] = &VARIABLE_ARRAY;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_start_value_is_inside_its_own_limits() {
        for row in TABLE {
            if row.variable.causality != Causality::Output {
                row.check(row.variable.start)
                    .unwrap_or_else(|e| panic!("the start value of {}: {e}", row.variable.name));
            }
        }
    }

    #[test]
    fn every_parameter_has_finite_limits_a_reason_and_the_variables_follow_the_table() {
        assert_eq!(VARIABLES.len(), TABLE.len());
        for (v, row) in VARIABLES.iter().zip(TABLE) {
            assert_eq!(v.value_reference, row.variable.value_reference);
            assert_eq!((v.min, v.max), (row.variable.min, row.variable.max));
        }
        for &r in crate::physics::parameters::Parameters::VALUE_REFERENCES {
            let row = row(r).unwrap();
            let v = &row.variable;
            assert!(
                v.min.map_or(false, f64::is_finite) && v.max.map_or(false, f64::is_finite),
                "{}: limits {:?}",
                v.name,
                (v.min, v.max)
            );
            assert!(!row.reason.is_empty(), "{}: no reason for the limits", v.name);
        }
    }

    #[test]
    fn a_value_outside_the_limits_is_refused_naming_the_variable_the_value_and_the_limit() {
        let e = check(vr::K_SPRING, 1e30).unwrap_err();
        assert!(
            e.starts_with("k_spring = 1e30 N/m is invalid: must be in [0, 100000] N/m"),
            "{e}"
        );
        let e = check(vr::C_D, 1.5).unwrap_err();
        assert!(e.starts_with("C_d = 1.5 is invalid: must be in (0, 1]"), "{e}");
        let e = check(vr::C_D, 0.0).unwrap_err();
        assert!(e.starts_with("C_d = 0 is invalid: must be in (0, 1]"), "{e}");
        assert!(check(vr::C_D, 1.0).is_ok());
        let e = check(vr::P_S, f64::NAN).unwrap_err();
        assert!(e.contains("P_s = NaN") && e.contains("finite"), "{e}");
    }

    #[test]
    fn every_constant_a_slot_may_vary_names_its_place_in_the_chain_and_no_other_row_does() {
        use crate::physics::flexible::FLEXIBLE_TARGETS;
        for row in TABLE {
            let target = FLEXIBLE_TARGETS.contains(&row.variable.value_reference);
            assert_eq!(row.place.is_some(), target, "{}", row.variable.name);
            assert!(row.sensitivity_step.is_none() || target, "{}", row.variable.name);
            assert!(row.kind.is_none() || target, "{}", row.variable.name);
        }
    }

    #[test]
    fn the_four_port_area_factors_and_the_support_length_alone_say_what_kind_of_constant_they_are() {
        let kinds: Vec<(&str, ConstantKind)> = TABLE
            .iter()
            .filter_map(|r| r.kind.map(|k| (r.variable.name, k)))
            .collect();
        assert_eq!(
            kinds,
            [
                ("L_sup", ConstantKind::LoadBearingLength),
                ("supply_area_scale_1", ConstantKind::PortAreaFactor),
                ("supply_area_scale_2", ConstantKind::PortAreaFactor),
                ("return_area_scale_1", ConstantKind::PortAreaFactor),
                ("return_area_scale_2", ConstantKind::PortAreaFactor),
            ]
        );
    }

    #[test]
    fn the_docs_carry_the_interface_table() {
        let docs = include_str!("../../../docs/model.md");
        assert!(
            docs.contains(&interface_table()),
            "docs/model.md's interface table is stale: replace it with the output of `cargo run --release --bin jetpipe -- parameters`"
        );
    }
}
