//! The FMI 3.0 state machines of Co-Simulation and Model Exchange as a table of which
//! function is legal in which state, over the layer's states ([`fmi2::state::State`], named
//! as FMI 3.0 names them: `stepMode`, `stepDiscarded`).
//!
//! What this FMU offers decides which parts of the FMI 3.0 machines exist: Co-Simulation
//! without event mode (`hasEventMode="false"`: an instance goes from `initializationMode` to
//! `stepMode`, so `fmi3EnterStepMode` is never legal), no intermediate update, no clocks, no
//! structural parameters (no configuration modes), no Scheduled Execution. A call the FMU
//! does not support answers fmi3Error with a message that says so; a call in the wrong state
//! logs "fmi3Xxx: illegal call in state yyy".

use fmi2::state::{
    Call, Interface, Mask, State, Version, CONTINUOUS_TIME_MODE, ERROR, EVENT_MODE, FATAL, INITIALIZATION_MODE,
    INSTANTIATED, STEP_COMPLETE, STEP_FAILED, TERMINATED,
};

/// The two states of Model Exchange after initialisation.
const ME_RUNNING: Mask = EVENT_MODE | CONTINUOUS_TIME_MODE;
/// Every state except `fatal`.
const ALL_BUT_FATAL: Mask =
    INSTANTIATED | INITIALIZATION_MODE | STEP_COMPLETE | STEP_FAILED | TERMINATED | ERROR | ME_RUNNING;
/// States in which values can be read (in `instantiated` only parameters and inputs: checked
/// per variable).
const READABLE: Mask =
    INSTANTIATED | INITIALIZATION_MODE | STEP_COMPLETE | STEP_FAILED | TERMINATED | ERROR | ME_RUNNING;
/// States in which values can be set (per variable: `fmi2::api::check_set_in`).
const SETTABLE: Mask = INSTANTIATED | INITIALIZATION_MODE | STEP_COMPLETE | ME_RUNNING;
/// States after initialisation in which values exist.
const EVALUATED: Mask = INITIALIZATION_MODE | STEP_COMPLETE | STEP_FAILED | TERMINATED | ERROR | ME_RUNNING;
/// Where Model Exchange's states, derivatives and indicators can be read.
const ME_VALUES: Mask = INITIALIZATION_MODE | ME_RUNNING | TERMINATED | ERROR;

macro_rules! functions {
    ($($variant:ident = $name:literal, $mask:expr;)*) => {
        /// An FMI 3.0 function that takes an instance.
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        pub enum Function {
            $($variant,)*
        }

        /// The table: function, C name, states in which it may be called.
        pub const TABLE: &[(Function, &str, Mask)] = &[
            $((Function::$variant, $name, $mask),)*
        ];
    };
}

functions! {
    SetDebugLogging = "fmi3SetDebugLogging", ALL_BUT_FATAL;
    FreeInstance = "fmi3FreeInstance", ALL_BUT_FATAL | FATAL;
    EnterInitializationMode = "fmi3EnterInitializationMode", INSTANTIATED;
    ExitInitializationMode = "fmi3ExitInitializationMode", INITIALIZATION_MODE;
    EnterEventMode = "fmi3EnterEventMode", ME_RUNNING;
    Terminate = "fmi3Terminate", STEP_COMPLETE | STEP_FAILED | ME_RUNNING;
    Reset = "fmi3Reset", ALL_BUT_FATAL;
    GetFloat32 = "fmi3GetFloat32", READABLE;
    GetFloat64 = "fmi3GetFloat64", READABLE;
    GetInt8 = "fmi3GetInt8", READABLE;
    GetUInt8 = "fmi3GetUInt8", READABLE;
    GetInt16 = "fmi3GetInt16", READABLE;
    GetUInt16 = "fmi3GetUInt16", READABLE;
    GetInt32 = "fmi3GetInt32", READABLE;
    GetUInt32 = "fmi3GetUInt32", READABLE;
    GetInt64 = "fmi3GetInt64", READABLE;
    GetUInt64 = "fmi3GetUInt64", READABLE;
    GetBoolean = "fmi3GetBoolean", READABLE;
    GetString = "fmi3GetString", READABLE;
    GetBinary = "fmi3GetBinary", READABLE;
    GetClock = "fmi3GetClock", EVALUATED;
    SetFloat32 = "fmi3SetFloat32", SETTABLE;
    SetFloat64 = "fmi3SetFloat64", SETTABLE;
    SetInt8 = "fmi3SetInt8", SETTABLE;
    SetUInt8 = "fmi3SetUInt8", SETTABLE;
    SetInt16 = "fmi3SetInt16", SETTABLE;
    SetUInt16 = "fmi3SetUInt16", SETTABLE;
    SetInt32 = "fmi3SetInt32", SETTABLE;
    SetUInt32 = "fmi3SetUInt32", SETTABLE;
    SetInt64 = "fmi3SetInt64", SETTABLE;
    SetUInt64 = "fmi3SetUInt64", SETTABLE;
    SetBoolean = "fmi3SetBoolean", SETTABLE;
    SetString = "fmi3SetString", SETTABLE;
    SetBinary = "fmi3SetBinary", SETTABLE;
    SetClock = "fmi3SetClock", SETTABLE;
    GetNumberOfVariableDependencies = "fmi3GetNumberOfVariableDependencies", EVALUATED;
    GetVariableDependencies = "fmi3GetVariableDependencies", EVALUATED;
    GetFMUState = "fmi3GetFMUState", ALL_BUT_FATAL;
    SetFMUState = "fmi3SetFMUState", ALL_BUT_FATAL;
    FreeFMUState = "fmi3FreeFMUState", ALL_BUT_FATAL;
    SerializedFMUStateSize = "fmi3SerializedFMUStateSize", ALL_BUT_FATAL;
    SerializeFMUState = "fmi3SerializeFMUState", ALL_BUT_FATAL;
    DeserializeFMUState = "fmi3DeserializeFMUState", ALL_BUT_FATAL;
    GetDirectionalDerivative = "fmi3GetDirectionalDerivative", EVALUATED;
    GetAdjointDerivative = "fmi3GetAdjointDerivative", EVALUATED;
    EnterConfigurationMode = "fmi3EnterConfigurationMode", INSTANTIATED | STEP_COMPLETE | EVENT_MODE;
    ExitConfigurationMode = "fmi3ExitConfigurationMode", 0;
    GetIntervalDecimal = "fmi3GetIntervalDecimal", EVALUATED;
    GetIntervalFraction = "fmi3GetIntervalFraction", EVALUATED;
    GetShiftDecimal = "fmi3GetShiftDecimal", EVALUATED;
    GetShiftFraction = "fmi3GetShiftFraction", EVALUATED;
    SetIntervalDecimal = "fmi3SetIntervalDecimal", EVALUATED;
    SetIntervalFraction = "fmi3SetIntervalFraction", EVALUATED;
    SetShiftDecimal = "fmi3SetShiftDecimal", EVALUATED;
    SetShiftFraction = "fmi3SetShiftFraction", EVALUATED;
    EvaluateDiscreteStates = "fmi3EvaluateDiscreteStates", INITIALIZATION_MODE | STEP_COMPLETE | ME_RUNNING;
    UpdateDiscreteStates = "fmi3UpdateDiscreteStates", EVENT_MODE;
    // Model Exchange
    EnterContinuousTimeMode = "fmi3EnterContinuousTimeMode", EVENT_MODE;
    CompletedIntegratorStep = "fmi3CompletedIntegratorStep", CONTINUOUS_TIME_MODE;
    SetTime = "fmi3SetTime", ME_RUNNING;
    SetContinuousStates = "fmi3SetContinuousStates", CONTINUOUS_TIME_MODE;
    GetContinuousStateDerivatives = "fmi3GetContinuousStateDerivatives", ME_VALUES;
    GetEventIndicators = "fmi3GetEventIndicators", ME_VALUES;
    GetContinuousStates = "fmi3GetContinuousStates", ME_VALUES;
    GetNominalsOfContinuousStates = "fmi3GetNominalsOfContinuousStates", INSTANTIATED | ME_VALUES;
    GetNumberOfEventIndicators = "fmi3GetNumberOfEventIndicators", ALL_BUT_FATAL;
    GetNumberOfContinuousStates = "fmi3GetNumberOfContinuousStates", ALL_BUT_FATAL;
    // Co-Simulation
    EnterStepMode = "fmi3EnterStepMode", EVENT_MODE;
    GetOutputDerivatives = "fmi3GetOutputDerivatives", STEP_COMPLETE | STEP_FAILED | TERMINATED | ERROR;
    DoStep = "fmi3DoStep", STEP_COMPLETE;
    // Scheduled Execution
    ActivateModelPartition = "fmi3ActivateModelPartition", 0;
}

impl Function {
    #[inline]
    fn row(self) -> &'static (Function, &'static str, Mask) {
        // the macro lists the rows in the declaration order
        &TABLE[self as usize]
    }

    /// The C name, e.g. `"fmi3DoStep"`.
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

    /// The interface this function belongs to alone (`None`: both have it). Scheduled
    /// Execution's function belongs to neither of the two this FMU offers.
    pub fn interface(self) -> Option<Interface> {
        use Function::*;
        match self {
            EnterContinuousTimeMode
            | CompletedIntegratorStep
            | SetTime
            | SetContinuousStates
            | GetContinuousStateDerivatives
            | GetEventIndicators
            | GetContinuousStates
            | GetNominalsOfContinuousStates
            | GetNumberOfEventIndicators
            | GetNumberOfContinuousStates
            | EnterEventMode => Some(Interface::ModelExchange),
            EnterStepMode | GetOutputDerivatives | DoStep => Some(Interface::CoSimulation),
            _ => None,
        }
    }
}

impl Call for Function {
    #[inline]
    fn name(self) -> &'static str {
        Function::name(self)
    }

    #[inline]
    fn version(self) -> Version {
        Version::Fmi3
    }

    #[inline]
    fn legal(self, state: State, interface: Interface) -> bool {
        self.allowed_in(state) && self.interface().map_or(true, |i| i == interface)
    }

    fn illegal_call_message(self, state: State, interface: Interface) -> String {
        let mut m = format!(
            "{}: illegal call in state {}",
            self.name(),
            state.name_in(Version::Fmi3)
        );
        let why = match self {
            Function::EnterStepMode | Function::EnterEventMode if interface == Interface::CoSimulation => {
                Some("this FMU's Co-Simulation has no event mode (hasEventMode=\"false\"): an instance is in stepMode from fmi3ExitInitializationMode on".to_owned())
            }
            Function::ExitConfigurationMode => {
                Some("this FMU has no structural parameters and so no configuration mode".to_owned())
            }
            Function::ActivateModelPartition => {
                Some("this FMU offers Co-Simulation and Model Exchange, not Scheduled Execution".to_owned())
            }
            _ => match self.interface() {
                Some(wanted) if wanted != interface => Some(format!(
                    "{} is a {} function; this instance was instantiated for {}",
                    self.name(),
                    wanted.name(),
                    interface.name()
                )),
                _ => None,
            },
        };
        if let Some(why) = why {
            m.push_str(" (");
            m.push_str(&why);
            m.push(')');
        }
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_lists_each_function_once_in_declaration_order() {
        for (i, row) in TABLE.iter().enumerate() {
            assert_eq!(row.0 as usize, i, "{}", row.1);
            assert!(row.1.starts_with("fmi3"), "{}", row.1);
            assert!(TABLE[i + 1..].iter().all(|r| r.1 != row.1), "{}", row.1);
        }
        assert!(Function::all().all(|f| !f.allowed_in(State::Fatal) || f == Function::FreeInstance));
    }

    #[test]
    fn a_co_simulation_instance_steps_only_in_step_mode_and_never_enters_it_by_call() {
        let cs = Interface::CoSimulation;
        assert!(Call::legal(Function::DoStep, State::StepComplete, cs));
        assert!(!Call::legal(Function::DoStep, State::StepFailed, cs));
        assert!(!Call::legal(
            Function::DoStep,
            State::EventMode,
            Interface::ModelExchange
        ));
        for s in State::ALL {
            assert!(!Call::legal(Function::EnterStepMode, s, cs) || s == State::EventMode);
        }
        let m = Call::illegal_call_message(Function::EnterStepMode, State::StepComplete, cs);
        assert!(
            m.starts_with("fmi3EnterStepMode: illegal call in state stepMode"),
            "{m}"
        );
        assert!(m.contains("hasEventMode"), "{m}");
    }

    #[test]
    fn a_model_exchange_function_is_illegal_for_a_co_simulation_instance_in_every_state() {
        let me_functions: Vec<Function> = Function::all()
            .filter(|f| f.interface() == Some(Interface::ModelExchange))
            .collect();
        assert!(me_functions.len() >= 10);
        for f in me_functions {
            for s in State::ALL {
                assert!(!Call::legal(f, s, Interface::CoSimulation), "{} in {:?}", f.name(), s);
            }
        }
        let m = Call::illegal_call_message(
            Function::GetContinuousStateDerivatives,
            State::InitializationMode,
            Interface::CoSimulation,
        );
        assert!(m.contains("is a Model Exchange function"), "{m}");
    }
}
