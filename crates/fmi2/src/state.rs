//! The FMI 2.0 state machines of Co-Simulation and Model Exchange, and the explicit table of
//! which function is legal in which state (after the masks of modelica/Reference-FMUs'
//! `fmi2Functions.c`, without `stepInProgress`: this layer only steps synchronously).
//!
//! The two interfaces share `instantiated`, `initializationMode`, `terminated`, `error` and
//! `fatal`; a Co-Simulation instance leaves initialisation for `stepComplete`, a Model
//! Exchange instance for `eventMode`, so that the states an instance can reach tell its
//! interface, and a function of the other interface is illegal in each of them.

/// A state of the FMI 2.0 state machines. `StartAndEnd` is not represented: there is no
/// instance in it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum State {
    Instantiated,
    InitializationMode,
    StepComplete,
    StepFailed,
    StepCanceled,
    Terminated,
    Error,
    Fatal,
    /// Model Exchange: event mode (after initialisation and at each event).
    EventMode,
    /// Model Exchange: continuous-time mode (the importer's solver integrates).
    ContinuousTimeMode,
}

/// Which FMI 2.0 interface an instance was made for (`fmi2Instantiate`'s `fmuType`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interface {
    CoSimulation,
    ModelExchange,
}

/// The FMI version an instance (or an FMU state) belongs to: the layer serves both with the
/// same instances, states and FMU-state bytes, and refuses a call of one version on an
/// instance of the other.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Version {
    Fmi2,
    Fmi3,
}

impl Version {
    /// `"FMI 2.0"` or `"FMI 3.0"`.
    pub const fn name(self) -> &'static str {
        match self {
            Version::Fmi2 => "FMI 2.0",
            Version::Fmi3 => "FMI 3.0",
        }
    }

    /// The prefix of the version's C functions, `"fmi2"` or `"fmi3"`.
    pub const fn prefix(self) -> &'static str {
        match self {
            Version::Fmi2 => "fmi2",
            Version::Fmi3 => "fmi3",
        }
    }
}

impl Interface {
    pub const fn name(self) -> &'static str {
        match self {
            Interface::CoSimulation => "Co-Simulation",
            Interface::ModelExchange => "Model Exchange",
        }
    }
}

impl State {
    pub const ALL: [State; 10] = [
        State::Instantiated,
        State::InitializationMode,
        State::StepComplete,
        State::StepFailed,
        State::StepCanceled,
        State::Terminated,
        State::Error,
        State::Fatal,
        State::EventMode,
        State::ContinuousTimeMode,
    ];

    /// The interface whose state machine alone has this state (`None`: both have it).
    pub const fn interface(self) -> Option<Interface> {
        match self {
            State::StepComplete | State::StepFailed | State::StepCanceled => Some(Interface::CoSimulation),
            State::EventMode | State::ContinuousTimeMode => Some(Interface::ModelExchange),
            _ => None,
        }
    }

    /// The bit of this state in a [`Mask`].
    pub const fn bit(self) -> Mask {
        match self {
            State::Instantiated => INSTANTIATED,
            State::InitializationMode => INITIALIZATION_MODE,
            State::StepComplete => STEP_COMPLETE,
            State::StepFailed => STEP_FAILED,
            State::StepCanceled => STEP_CANCELED,
            State::Terminated => TERMINATED,
            State::Error => ERROR,
            State::Fatal => FATAL,
            State::EventMode => EVENT_MODE,
            State::ContinuousTimeMode => CONTINUOUS_TIME_MODE,
        }
    }

    pub const fn name(self) -> &'static str {
        match self {
            State::Instantiated => "instantiated",
            State::InitializationMode => "initializationMode",
            State::StepComplete => "stepComplete",
            State::StepFailed => "stepFailed",
            State::StepCanceled => "stepCanceled",
            State::Terminated => "terminated",
            State::Error => "error",
            State::Fatal => "fatal",
            State::EventMode => "eventMode",
            State::ContinuousTimeMode => "continuousTimeMode",
        }
    }

    /// The state's name in the state machine of `version`: FMI 3.0 calls Co-Simulation's
    /// `stepComplete` `stepMode` and its `stepFailed` `stepDiscarded`.
    pub const fn name_in(self, version: Version) -> &'static str {
        match (version, self) {
            (Version::Fmi3, State::StepComplete) => "stepMode",
            (Version::Fmi3, State::StepFailed) => "stepDiscarded",
            _ => self.name(),
        }
    }

    /// Stable code used in the serialized FMU state.
    pub const fn code(self) -> u8 {
        match self {
            State::Instantiated => 1,
            State::InitializationMode => 2,
            State::StepComplete => 3,
            State::StepFailed => 4,
            State::StepCanceled => 5,
            State::Terminated => 6,
            State::Error => 7,
            State::Fatal => 8,
            State::EventMode => 9,
            State::ContinuousTimeMode => 10,
        }
    }

    pub fn from_code(code: u8) -> Option<State> {
        State::ALL.into_iter().find(|s| s.code() == code)
    }
}

pub type Mask = u16;
pub const INSTANTIATED: Mask = 1 << 0;
pub const INITIALIZATION_MODE: Mask = 1 << 1;
pub const STEP_COMPLETE: Mask = 1 << 2;
pub const STEP_FAILED: Mask = 1 << 3;
pub const STEP_CANCELED: Mask = 1 << 4;
pub const TERMINATED: Mask = 1 << 5;
pub const ERROR: Mask = 1 << 6;
pub const FATAL: Mask = 1 << 7;
pub const EVENT_MODE: Mask = 1 << 8;
pub const CONTINUOUS_TIME_MODE: Mask = 1 << 9;

/// The two states of Model Exchange after initialisation.
const ME_RUNNING: Mask = EVENT_MODE | CONTINUOUS_TIME_MODE;
/// Every state except `fatal`.
const ALL_BUT_FATAL: Mask =
    INSTANTIATED | INITIALIZATION_MODE | STEP_COMPLETE | STEP_FAILED | STEP_CANCELED | TERMINATED | ERROR | ME_RUNNING;
/// States in which values can be read.
const READABLE: Mask =
    INITIALIZATION_MODE | STEP_COMPLETE | STEP_FAILED | STEP_CANCELED | TERMINATED | ERROR | ME_RUNNING;
/// States in which inputs can be set (per variable: see `api::check_set`).
const SETTABLE: Mask = INSTANTIATED | INITIALIZATION_MODE | STEP_COMPLETE | ME_RUNNING;

/// An FMI 2.0 function that takes an instance.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Function {
    SetDebugLogging,
    FreeInstance,
    SetupExperiment,
    EnterInitializationMode,
    ExitInitializationMode,
    Terminate,
    Reset,
    GetReal,
    GetInteger,
    GetBoolean,
    GetString,
    SetReal,
    SetInteger,
    SetBoolean,
    SetString,
    GetFMUstate,
    SetFMUstate,
    FreeFMUstate,
    SerializedFMUstateSize,
    SerializeFMUstate,
    DeSerializeFMUstate,
    GetDirectionalDerivative,
    SetRealInputDerivatives,
    GetRealOutputDerivatives,
    DoStep,
    CancelStep,
    GetStatus,
    GetRealStatus,
    GetIntegerStatus,
    GetBooleanStatus,
    GetStringStatus,
    // Model Exchange
    EnterEventMode,
    NewDiscreteStates,
    EnterContinuousTimeMode,
    CompletedIntegratorStep,
    SetTime,
    SetContinuousStates,
    GetDerivatives,
    GetEventIndicators,
    GetContinuousStates,
    GetNominalsOfContinuousStates,
}

/// The table: function, C name, states in which it may be called.
///
/// Deviations from Reference-FMUs, on purpose:
/// * getters are also legal in `instantiated`, but there only for parameters and inputs
///   (checked per variable in the API);
/// * `fmi2FreeInstance` is also legal in `fatal`, so an importer can release memory;
/// * `fmi2CancelStep` is legal nowhere (no asynchronous stepping: `stepInProgress` is
///   never entered). It returns fmi2Error with the illegal-call message;
/// * `fmi2GetDerivatives` is also legal in `initializationMode` (FMI 2.0's state machine
///   allows it there; Reference-FMUs' mask does not).
///
/// The Model Exchange rows are Reference-FMUs' masks: `fmi2SetTime` and `fmi2EnterEventMode`
/// in `eventMode` and `continuousTimeMode`, `fmi2NewDiscreteStates` and
/// `fmi2EnterContinuousTimeMode` in `eventMode`, `fmi2SetContinuousStates` and
/// `fmi2CompletedIntegratorStep` in `continuousTimeMode`, the getters of states, derivatives
/// and event indicators wherever values exist.
pub const TABLE: &[(Function, &str, Mask)] = &[
    (Function::SetDebugLogging, "fmi2SetDebugLogging", ALL_BUT_FATAL),
    (Function::FreeInstance, "fmi2FreeInstance", ALL_BUT_FATAL | FATAL),
    (Function::SetupExperiment, "fmi2SetupExperiment", INSTANTIATED),
    (
        Function::EnterInitializationMode,
        "fmi2EnterInitializationMode",
        INSTANTIATED,
    ),
    (
        Function::ExitInitializationMode,
        "fmi2ExitInitializationMode",
        INITIALIZATION_MODE,
    ),
    (
        Function::Terminate,
        "fmi2Terminate",
        STEP_COMPLETE | STEP_FAILED | ME_RUNNING,
    ),
    (Function::Reset, "fmi2Reset", ALL_BUT_FATAL),
    (Function::GetReal, "fmi2GetReal", INSTANTIATED | READABLE),
    (Function::GetInteger, "fmi2GetInteger", INSTANTIATED | READABLE),
    (Function::GetBoolean, "fmi2GetBoolean", INSTANTIATED | READABLE),
    (Function::GetString, "fmi2GetString", INSTANTIATED | READABLE),
    (Function::SetReal, "fmi2SetReal", SETTABLE),
    (Function::SetInteger, "fmi2SetInteger", SETTABLE),
    (Function::SetBoolean, "fmi2SetBoolean", SETTABLE),
    (Function::SetString, "fmi2SetString", SETTABLE),
    (Function::GetFMUstate, "fmi2GetFMUstate", ALL_BUT_FATAL),
    (Function::SetFMUstate, "fmi2SetFMUstate", ALL_BUT_FATAL),
    (Function::FreeFMUstate, "fmi2FreeFMUstate", ALL_BUT_FATAL),
    (
        Function::SerializedFMUstateSize,
        "fmi2SerializedFMUstateSize",
        ALL_BUT_FATAL,
    ),
    (Function::SerializeFMUstate, "fmi2SerializeFMUstate", ALL_BUT_FATAL),
    (Function::DeSerializeFMUstate, "fmi2DeSerializeFMUstate", ALL_BUT_FATAL),
    (
        Function::GetDirectionalDerivative,
        "fmi2GetDirectionalDerivative",
        READABLE,
    ),
    (
        Function::SetRealInputDerivatives,
        "fmi2SetRealInputDerivatives",
        INSTANTIATED | INITIALIZATION_MODE | STEP_COMPLETE,
    ),
    (
        Function::GetRealOutputDerivatives,
        "fmi2GetRealOutputDerivatives",
        STEP_COMPLETE | STEP_FAILED | STEP_CANCELED | TERMINATED | ERROR,
    ),
    (Function::DoStep, "fmi2DoStep", STEP_COMPLETE),
    (Function::CancelStep, "fmi2CancelStep", 0),
    (
        Function::GetStatus,
        "fmi2GetStatus",
        STEP_COMPLETE | STEP_FAILED | TERMINATED,
    ),
    (
        Function::GetRealStatus,
        "fmi2GetRealStatus",
        STEP_COMPLETE | STEP_FAILED | TERMINATED,
    ),
    (
        Function::GetIntegerStatus,
        "fmi2GetIntegerStatus",
        STEP_COMPLETE | STEP_FAILED | TERMINATED,
    ),
    (
        Function::GetBooleanStatus,
        "fmi2GetBooleanStatus",
        STEP_COMPLETE | STEP_FAILED | TERMINATED,
    ),
    (
        Function::GetStringStatus,
        "fmi2GetStringStatus",
        STEP_COMPLETE | STEP_FAILED | TERMINATED,
    ),
    (Function::EnterEventMode, "fmi2EnterEventMode", ME_RUNNING),
    (Function::NewDiscreteStates, "fmi2NewDiscreteStates", EVENT_MODE),
    (
        Function::EnterContinuousTimeMode,
        "fmi2EnterContinuousTimeMode",
        EVENT_MODE,
    ),
    (
        Function::CompletedIntegratorStep,
        "fmi2CompletedIntegratorStep",
        CONTINUOUS_TIME_MODE,
    ),
    (Function::SetTime, "fmi2SetTime", ME_RUNNING),
    (
        Function::SetContinuousStates,
        "fmi2SetContinuousStates",
        CONTINUOUS_TIME_MODE,
    ),
    (
        Function::GetDerivatives,
        "fmi2GetDerivatives",
        INITIALIZATION_MODE | ME_RUNNING | TERMINATED | ERROR,
    ),
    (
        Function::GetEventIndicators,
        "fmi2GetEventIndicators",
        INITIALIZATION_MODE | ME_RUNNING | TERMINATED | ERROR,
    ),
    (
        Function::GetContinuousStates,
        "fmi2GetContinuousStates",
        INITIALIZATION_MODE | ME_RUNNING | TERMINATED | ERROR,
    ),
    (
        Function::GetNominalsOfContinuousStates,
        "fmi2GetNominalsOfContinuousStates",
        INSTANTIATED | ME_RUNNING | TERMINATED | ERROR,
    ),
];

/// A function of one version's legality table, as [`crate::api::guarded`] checks it.
pub trait Call: Copy {
    /// The C name, e.g. `"fmi2DoStep"`.
    fn name(self) -> &'static str;
    /// The version whose instances the function takes.
    fn version(self) -> Version;
    /// Whether the call is legal for an instance of `interface` in `state`.
    fn legal(self, state: State, interface: Interface) -> bool;
    /// The message of an illegal call: the function, the state and, when that is the reason,
    /// the interface.
    fn illegal_call_message(self, state: State, interface: Interface) -> String;
}

impl Call for Function {
    #[inline]
    fn name(self) -> &'static str {
        Function::name(self)
    }
    #[inline]
    fn version(self) -> Version {
        Version::Fmi2
    }
    #[inline]
    fn legal(self, state: State, interface: Interface) -> bool {
        Function::legal(self, state, interface)
    }
    fn illegal_call_message(self, state: State, interface: Interface) -> String {
        crate::api::illegal_call_message_for(self, state, interface)
    }
}

impl Function {
    #[inline]
    fn row(self) -> &'static (Function, &'static str, Mask) {
        // The table lists the functions in their declaration order (tested); the search is
        // for a table that does not.
        match TABLE.get(self as usize) {
            Some(row) if row.0 == self => row,
            _ => TABLE
                .iter()
                .find(|row| row.0 == self)
                .expect("every Function has a row in TABLE"),
        }
    }

    /// The C name, e.g. `"fmi2DoStep"`.
    #[inline]
    pub fn name(self) -> &'static str {
        self.row().1
    }

    #[inline]
    pub fn mask(self) -> Mask {
        self.row().2
    }

    #[inline]
    pub fn allowed_in(self, state: State) -> bool {
        self.mask() & state.bit() != 0
    }

    /// Whether the call is legal for an instance of `interface` in `state`: the table's row,
    /// and a function of one interface only is illegal for an instance of the other (also in
    /// the states the two share, e.g. `fmi2GetDerivatives` in `initializationMode`).
    #[inline]
    pub fn legal(self, state: State, interface: Interface) -> bool {
        self.allowed_in(state) && self.interface().map_or(true, |i| i == interface)
    }

    pub fn all() -> impl Iterator<Item = Function> {
        TABLE.iter().map(|row| row.0)
    }

    /// The interface this function belongs to alone (`None`: both have it).
    pub fn interface(self) -> Option<Interface> {
        use Function::*;
        match self {
            EnterEventMode
            | NewDiscreteStates
            | EnterContinuousTimeMode
            | CompletedIntegratorStep
            | SetTime
            | SetContinuousStates
            | GetDerivatives
            | GetEventIndicators
            | GetContinuousStates
            | GetNominalsOfContinuousStates => Some(Interface::ModelExchange),
            SetRealInputDerivatives
            | GetRealOutputDerivatives
            | DoStep
            | CancelStep
            | GetStatus
            | GetRealStatus
            | GetIntegerStatus
            | GetBooleanStatus
            | GetStringStatus => Some(Interface::CoSimulation),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_has_each_function_once_and_codes_round_trip() {
        for (i, row) in TABLE.iter().enumerate() {
            assert!(
                TABLE[i + 1..].iter().all(|r| r.0 != row.0 && r.1 != row.1),
                "{:?}",
                row.0
            );
        }
        assert_eq!(TABLE.len(), 41);
        for s in State::ALL {
            assert_eq!(State::from_code(s.code()), Some(s));
        }
        assert_eq!(State::from_code(0), None);
        assert!(Function::DoStep.allowed_in(State::StepComplete));
        assert!(!Function::DoStep.allowed_in(State::StepFailed));
        assert!(Function::all().all(|f| !f.allowed_in(State::Fatal) || f == Function::FreeInstance));
    }
}
