//! The contract between the generic FMI 2.0 Co-Simulation layer and a model.
//!
//! The layer knows nothing about pneumatics: it owns the state machine, the C ABI,
//! logging, FMU-state handling and argument checking against the variable table.
//! A model only provides its variable table, values and a `do_step`.

/// FMI 2.0 causality of a variable.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Causality {
    Parameter,
    Input,
    Output,
    Local,
}

impl Causality {
    /// The attribute's value, e.g. `"parameter"`.
    pub const fn name(self) -> &'static str {
        match self {
            Causality::Parameter => "parameter",
            Causality::Input => "input",
            Causality::Output => "output",
            Causality::Local => "local",
        }
    }
}

/// FMI 2.0 variability of a variable.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variability {
    Fixed,
    Tunable,
    Discrete,
    Continuous,
}

impl Variability {
    /// The attribute's value, e.g. `"tunable"`.
    pub const fn name(self) -> &'static str {
        match self {
            Variability::Fixed => "fixed",
            Variability::Tunable => "tunable",
            Variability::Discrete => "discrete",
            Variability::Continuous => "continuous",
        }
    }
}

/// FMI 2.0 base type of a variable. Boolean and Integer values travel as `f64` in
/// `start` (0/1 for Boolean).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VarType {
    Real,
    Integer,
    Boolean,
}

impl VarType {
    /// The FMI 2.0 type name, e.g. `"Real"`.
    pub const fn name(self) -> &'static str {
        match self {
            VarType::Real => "Real",
            VarType::Integer => "Integer",
            VarType::Boolean => "Boolean",
        }
    }

    /// The type's name in `version`: FMI 3.0 calls Real `Float64` and Integer `Int32`.
    pub const fn name_in(self, version: crate::state::Version) -> &'static str {
        match (version, self) {
            (crate::state::Version::Fmi3, VarType::Real) => "Float64",
            (crate::state::Version::Fmi3, VarType::Integer) => "Int32",
            _ => self.name(),
        }
    }
}

/// One row of the variable table: the single source of the model description and of
/// the getters and setters.
#[derive(Clone, Copy, Debug)]
pub struct Variable {
    pub name: &'static str,
    pub value_reference: u32,
    pub var_type: VarType,
    pub causality: Causality,
    pub variability: Variability,
    /// Unit name; must appear in [`ModelInfo::units`].
    pub unit: Option<&'static str>,
    /// Start value (for parameters and inputs: the default; for outputs: ignored,
    /// outputs are `initial="calculated"`).
    pub start: f64,
    pub min: Option<f64>,
    pub max: Option<f64>,
    pub description: &'static str,
}

/// A unit with its SI base-unit exponents, for `<UnitDefinitions>`.
#[derive(Clone, Copy, Debug)]
pub struct UnitDefinition {
    pub name: &'static str,
    pub kg: i32,
    pub m: i32,
    pub s: i32,
    pub a: i32,
    pub k: i32,
}

/// Bounds and scale of a variable that its table row does not give: `min`, `max` and
/// `nominal` in the model description. A row's own `min`/`max` take precedence.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Extent {
    pub min: Option<f64>,
    pub max: Option<f64>,
    pub nominal: Option<f64>,
}

/// No extent beyond the table row's (the default of [`ModelInfo::extent`]).
pub fn no_extent(_value_reference: u32) -> Extent {
    Extent::default()
}

/// How an output depends on the variables it lists (FMI 2.0 `dependenciesKind`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DependencyKind {
    /// No particular structure (what a nonlinear dependence is).
    Dependent,
    /// Linear with a constant factor.
    Constant,
    /// Linear with a factor that depends on fixed parameters only.
    Fixed,
}

impl DependencyKind {
    pub fn attr(self) -> &'static str {
        match self {
            DependencyKind::Dependent => "dependent",
            DependencyKind::Constant => "constant",
            DependencyKind::Fixed => "fixed",
        }
    }
}

/// The knowns one output depends on (`<ModelStructure>`), by value reference.
#[derive(Clone, Copy, Debug)]
pub struct OutputDependencies {
    pub output: u32,
    /// `<Outputs>`: the inputs whose new value changes the output before the next step
    /// (direct feedthrough), with the kind of each.
    pub step: &'static [(u32, DependencyKind)],
    /// `<InitialUnknowns>`: the inputs and parameters the output's value after
    /// initialisation depends on; `None` means every input and parameter (all `dependent`).
    pub initial: Option<&'static [(u32, DependencyKind)]>,
}

/// The GUID, computed once from the model description (see [`ModelInfo::guid`]). Kept in
/// the `ModelInfo` itself, not on the heap: a shared library that is unloaded leaves no
/// allocation behind.
pub struct GuidCache {
    once: std::sync::Once,
    bytes: std::cell::UnsafeCell<[u8; GUID_LEN]>,
}

/// `{xxxxxxxx-xxxx-xxxx-xxxx-xxxxxxxxxxxx}`.
const GUID_LEN: usize = 38;

// The bytes are written once, inside `once`, before any reader can see them.
unsafe impl Sync for GuidCache {}

impl GuidCache {
    pub const fn new() -> Self {
        GuidCache {
            once: std::sync::Once::new(),
            bytes: std::cell::UnsafeCell::new([0; GUID_LEN]),
        }
    }
}

impl Default for GuidCache {
    fn default() -> Self {
        Self::new()
    }
}

impl std::fmt::Debug for GuidCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("GuidCache")
    }
}

/// Static description of a model: everything the model description needs.
#[derive(Debug)]
pub struct ModelInfo {
    pub model_name: &'static str,
    pub model_identifier: &'static str,
    pub description: &'static str,
    pub author: &'static str,
    pub version: &'static str,
    pub generation_tool: &'static str,
    pub default_start_time: f64,
    pub default_stop_time: f64,
    pub default_tolerance: f64,
    pub default_step_size: f64,
    pub log_categories: &'static [(&'static str, &'static str)],
    pub units: &'static [UnitDefinition],
    pub variables: &'static [Variable],
    /// `canInterpolateInputs`: the model accepts first-order input derivatives.
    pub can_interpolate_inputs: bool,
    /// `min`, `max` and `nominal` beyond the table rows', by value reference.
    pub extent: fn(u32) -> Extent,
    /// Every output's dependencies; an empty list leaves `dependencies` out of the model
    /// description (an importer then assumes that each output depends on every known).
    pub dependencies: &'static [OutputDependencies],
    /// The Model Exchange interface, when the model has one (`None`: Co-Simulation only).
    pub model_exchange: Option<&'static ModelExchangeInfo>,
    /// Holds the GUID once computed.
    pub guid_cache: GuidCache,
}

/// A continuous state of Model Exchange: the value references of the state and of its
/// derivative (both variables of the table, Real and continuous).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ContinuousState {
    pub state: u32,
    pub derivative: u32,
}

/// What the model description says of a model's Model Exchange interface: `<ModelExchange>`,
/// the `derivative` attributes, `<Derivatives>` and `numberOfEventIndicators`.
#[derive(Debug)]
pub struct ModelExchangeInfo {
    /// In the order of the state vector of `fmi2GetContinuousStates`.
    pub states: &'static [ContinuousState],
    pub event_indicators: usize,
    /// Whether the model updates a memory in `fmi2CompletedIntegratorStep` (FMI 2.0's
    /// `completedIntegratorStepNotNeeded` is its negation, FMI 3.0's
    /// `needsCompletedIntegratorStep` the same); the call never asks for an event either way.
    pub needs_completed_integrator_step: bool,
}

impl ModelInfo {
    /// The GUID: a name-based UUID (version 5, SHA-1) of the model description with an
    /// empty `guid` attribute, so that it changes whenever anything in the description does.
    pub fn guid(&self) -> &str {
        let cache = &self.guid_cache;
        cache.once.call_once(|| {
            let guid = super::model_description::content_guid(self);
            let mut bytes = [0u8; GUID_LEN];
            bytes.copy_from_slice(&guid.as_bytes()[..GUID_LEN]);
            // SAFETY: written only here, once, before `call_once` returns to any caller.
            unsafe { *cache.bytes.get() = bytes };
        });
        // SAFETY: never written again after `call_once`.
        let bytes = unsafe { &*cache.bytes.get() };
        std::str::from_utf8(bytes).unwrap_or("")
    }

    /// The effective extent of a variable: its row's `min`/`max`, else [`ModelInfo::extent`]'s.
    pub fn extent_of(&self, v: &Variable) -> Extent {
        let e = (self.extent)(v.value_reference);
        Extent {
            min: v.min.or(e.min),
            max: v.max.or(e.max),
            nominal: e.nominal,
        }
    }
}

/// Why a step did not complete.
#[derive(Clone, Debug, PartialEq)]
pub enum StepError {
    /// The step could not be completed but the state up to `last_successful_time`
    /// is valid (`fmi2Discard`).
    Discard { message: String, last_successful_time: f64 },
    /// Invalid request; nothing was changed (`fmi2Error`).
    Error(String),
}

/// What the generic layer needs from a model. All methods are plain Rust: no FFI types.
///
/// Values arrive already checked by the layer for value reference, type, causality and
/// the legality of the call in the current state; the model checks physical validity
/// (finite, in range) and returns a message that names the variable and the value.
pub trait CoSimModel: Send + Sized + 'static {
    /// The static description (identifier, variable table; the GUID is derived from it).
    fn info() -> &'static ModelInfo;

    /// A fresh instance with every variable at its start value.
    fn instantiate() -> Self;

    /// Back to the state right after `instantiate` (all start values).
    fn reset(&mut self) {
        *self = Self::instantiate();
    }

    fn get_real(&self, vr: u32) -> Result<f64, String>;
    fn set_real(&mut self, vr: u32, value: f64) -> Result<(), String>;
    fn get_integer(&self, vr: u32) -> Result<i32, String> {
        Err(format!("no Integer variable with value reference {vr}"))
    }
    fn set_integer(&mut self, vr: u32, _value: i32) -> Result<(), String> {
        Err(format!("no Integer variable with value reference {vr}"))
    }
    fn get_boolean(&self, vr: u32) -> Result<bool, String> {
        Err(format!("no Boolean variable with value reference {vr}"))
    }
    fn set_boolean(&mut self, vr: u32, _value: bool) -> Result<(), String> {
        Err(format!("no Boolean variable with value reference {vr}"))
    }

    /// `fmi2SetupExperiment`. `tolerance` is `None` when `toleranceDefined` is false.
    fn setup_experiment(
        &mut self,
        tolerance: Option<f64>,
        start_time: f64,
        stop_time: Option<f64>,
    ) -> Result<(), String>;

    /// `fmi2EnterInitializationMode`.
    fn enter_initialization(&mut self) -> Result<(), String> {
        Ok(())
    }

    /// `fmi2ExitInitializationMode`: compute the initial state (e.g. an equilibrium).
    fn exit_initialization(&mut self) -> Result<(), String>;

    /// `fmi2SetRealInputDerivatives` for one variable; `order` is at least 1.
    fn set_real_input_derivative(&mut self, vr: u32, order: i32, value: f64) -> Result<(), String> {
        let _ = value;
        Err(format!(
            "input derivatives of order {order} for value reference {vr} are not supported"
        ))
    }

    /// Advance from `current_time` by `step_size` (> 0, already checked).
    fn do_step(&mut self, current_time: f64, step_size: f64) -> Result<(), StepError>;

    /// The model's current time (`fmi2LastSuccessfulTime`).
    fn time(&self) -> f64;

    /// A self-contained, versioned byte image of the whole model state (no pointers).
    fn serialize(&self) -> Vec<u8>;

    /// Restore from `serialize`'s output; reject foreign or corrupted bytes with a
    /// message and leave `self` unchanged.
    fn deserialize(&mut self, bytes: &[u8]) -> Result<(), String>;

    /// Called right after `instantiate` (and after `reset`) for an instance made for Model
    /// Exchange; only models whose [`ModelInfo::model_exchange`] is set get such instances.
    fn use_model_exchange(&mut self) {}
}

/// What `fmi2NewDiscreteStates` reports (`fmi2EventInfo`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EventUpdate {
    pub values_of_continuous_states_changed: bool,
    pub nominals_of_continuous_states_changed: bool,
    pub terminate_simulation: bool,
    pub next_event_time: Option<f64>,
}

/// What the Model Exchange layer ([`crate::model_exchange`]) needs beyond [`CoSimModel`]. The
/// slices have exactly as many elements as [`ModelExchangeInfo`] declares (checked by the
/// layer); the model is called only in the states the legality table allows.
pub trait ModelExchangeModel: CoSimModel {
    /// `fmi2SetTime` (finite, checked by the layer).
    fn set_time(&mut self, time: f64) -> Result<(), String>;
    /// `fmi2GetContinuousStates`.
    fn continuous_states(&self, x: &mut [f64]) -> Result<(), String>;
    /// `fmi2SetContinuousStates`: refuse values that are not states (NaN, ...) with a message
    /// and leave the states unchanged.
    fn set_continuous_states(&mut self, x: &[f64]) -> Result<(), String>;
    /// `fmi2GetDerivatives` at the current time, inputs and states.
    fn derivatives(&self, dx: &mut [f64]) -> Result<(), String>;
    /// `fmi2GetEventIndicators` at the current time, inputs and states.
    fn event_indicators(&self, z: &mut [f64]) -> Result<(), String>;
    /// `fmi2GetNominalsOfContinuousStates`.
    fn nominals(&self, nominals: &mut [f64]);
    /// `fmi2EnterEventMode`.
    fn enter_event_mode(&mut self) -> Result<(), String> {
        Ok(())
    }
    /// `fmi2NewDiscreteStates`: one event iteration.
    fn new_discrete_states(&mut self) -> Result<EventUpdate, String>;
    /// `fmi2CompletedIntegratorStep`: whether to terminate the simulation.
    fn completed_integrator_step(&mut self) -> Result<bool, String> {
        Ok(false)
    }
}
