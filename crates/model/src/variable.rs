//! What one variable of the table ([`crate::variables`]) is: name, value reference, type,
//! causality, variability, unit, start, limits, description. Plain data: the FMU crate
//! (the root package, `src/variables.rs`) turns each into the FMI layer's variable for the model description, the
//! getters and the setters; the model itself, the command-line tool and the diagnosis read
//! them as they are. The names follow FMI 2.0's, whose concepts these are.

/// Who sets the variable: before the run ([`Causality::Parameter`]), at each communication
/// point ([`Causality::Input`]), or nobody: the model computes it ([`Causality::Output`],
/// [`Causality::Local`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Causality {
    Parameter,
    Input,
    Output,
    Local,
}

/// When the value may change: fixed after initialisation, tunable between steps, at events
/// only, or continuously.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variability {
    Fixed,
    Tunable,
    Discrete,
    Continuous,
}

/// The type of the value. Boolean and Integer values travel as `f64` in `start` (0/1 for
/// Boolean).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VarType {
    Real,
    Integer,
    Boolean,
}

/// One variable of the table.
#[derive(Clone, Copy, Debug)]
pub struct Variable {
    pub name: &'static str,
    pub value_reference: u32,
    pub var_type: VarType,
    pub causality: Causality,
    pub variability: Variability,
    /// Unit name, as the model description writes it ("Pa", "N/m", "1").
    pub unit: Option<&'static str>,
    /// Start value (for parameters and inputs: the default; for outputs: ignored, they are
    /// computed).
    pub start: f64,
    /// Limits: the setters refuse values outside them (see `variables::Row`).
    pub min: Option<f64>,
    pub max: Option<f64>,
    pub description: &'static str,
}

/// What a constant is, where that says more about a departure of it than its place does:
/// the kind of departure it makes when it follows a state of the chain.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ConstantKind {
    /// A factor on one port's orifice area: following any state, port 1 departs from port 2,
    /// an asymmetry.
    PortAreaFactor,
    /// A length the load bears on: following the force or a chamber pressure, it gives under
    /// the load, a compliance.
    LoadBearingLength,
}

/// The place of the chain a constant of the table belongs to, from the command to the
/// transducers: where a departure of it would be, for the diagnosis that locates one.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ChainPlace {
    Command,
    CurrentDriver,
    JetPipe,
    Valve,
    Supply,
    Return,
    Chambers,
    Mechanics,
    ForceSensor,
    PressureSensors,
}
