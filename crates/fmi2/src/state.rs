//! The FMI 2.0 Co-Simulation state machine and the explicit table of which function is
//! legal in which state (after the masks of modelica/Reference-FMUs' `fmi2Functions.c`,
//! without the Model-Exchange states and without `stepInProgress`: this layer only steps
//! synchronously).

/// A state of the FMI 2.0 Co-Simulation state machine. `StartAndEnd` is not represented:
/// there is no instance in it.
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
}

impl State {
    pub const ALL: [State; 8] = [
        State::Instantiated,
        State::InitializationMode,
        State::StepComplete,
        State::StepFailed,
        State::StepCanceled,
        State::Terminated,
        State::Error,
        State::Fatal,
    ];

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

/// Every state except `fatal`.
const ALL_BUT_FATAL: Mask =
    INSTANTIATED | INITIALIZATION_MODE | STEP_COMPLETE | STEP_FAILED | STEP_CANCELED | TERMINATED | ERROR;
/// States in which values can be read.
const READABLE: Mask = INITIALIZATION_MODE | STEP_COMPLETE | STEP_FAILED | STEP_CANCELED | TERMINATED | ERROR;

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
}

/// The table: function, C name, states in which it may be called.
///
/// Deviations from Reference-FMUs, on purpose:
/// * getters are also legal in `instantiated`, but there only for parameters and inputs
///   (checked per variable in the API);
/// * `fmi2FreeInstance` is also legal in `fatal`, so an importer can release memory;
/// * `fmi2CancelStep` is legal nowhere (no asynchronous stepping: `stepInProgress` is
///   never entered). It returns fmi2Error with the illegal-call message.
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
    (Function::Terminate, "fmi2Terminate", STEP_COMPLETE | STEP_FAILED),
    (Function::Reset, "fmi2Reset", ALL_BUT_FATAL),
    (Function::GetReal, "fmi2GetReal", INSTANTIATED | READABLE),
    (Function::GetInteger, "fmi2GetInteger", INSTANTIATED | READABLE),
    (Function::GetBoolean, "fmi2GetBoolean", INSTANTIATED | READABLE),
    (Function::GetString, "fmi2GetString", INSTANTIATED | READABLE),
    (
        Function::SetReal,
        "fmi2SetReal",
        INSTANTIATED | INITIALIZATION_MODE | STEP_COMPLETE,
    ),
    (
        Function::SetInteger,
        "fmi2SetInteger",
        INSTANTIATED | INITIALIZATION_MODE | STEP_COMPLETE,
    ),
    (
        Function::SetBoolean,
        "fmi2SetBoolean",
        INSTANTIATED | INITIALIZATION_MODE | STEP_COMPLETE,
    ),
    (
        Function::SetString,
        "fmi2SetString",
        INSTANTIATED | INITIALIZATION_MODE | STEP_COMPLETE,
    ),
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
];

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

    pub fn all() -> impl Iterator<Item = Function> {
        TABLE.iter().map(|row| row.0)
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
        assert_eq!(TABLE.len(), 31);
        for s in State::ALL {
            assert_eq!(State::from_code(s.code()), Some(s));
        }
        assert_eq!(State::from_code(0), None);
        assert!(Function::DoStep.allowed_in(State::StepComplete));
        assert!(!Function::DoStep.allowed_in(State::StepFailed));
        assert!(Function::all().all(|f| !f.allowed_in(State::Fatal) || f == Function::FreeInstance));
    }
}
