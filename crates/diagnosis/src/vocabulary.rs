//! The words a diagnosis speaks in: where along the chain the model departs (a [`Place`]),
//! what kind of departure it is (a [`Family`]) and how the term was formed (an [`Origin`]). Each is an enum whose JSON word is its serde
//! name ([`Place::as_str`]).

/// One vocabulary: an enum, its words in order, and their serde form.
macro_rules! vocabulary {
    ($(#[$doc:meta])* $name:ident { $($(#[$vdoc:meta])* $variant:ident => $word:literal,)* }) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub enum $name {
            $($(#[$vdoc])* $variant,)*
        }

        impl $name {
            /// Every word, in the vocabulary's order.
            pub const ALL: &'static [$name] = &[$($name::$variant,)*];

            /// The word reports use.
            pub fn as_str(self) -> &'static str {
                match self {
                    $($name::$variant => $word,)*
                }
            }

            /// The value whose word is `word`, if any.
            pub fn from_word(word: &str) -> Option<$name> {
                $name::ALL.iter().copied().find(|v| v.as_str() == word)
            }
        }

        impl std::fmt::Display for $name {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(self.as_str())
            }
        }

        impl serde::Serialize for $name {
            fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
                serializer.serialize_str(self.as_str())
            }
        }
    };
}

vocabulary! {
    /// A place along the actuator's chain, in the order a command travels.
    Place {
        /// The D/A command and what the current driver sees of it.
        Command => "command",
        CurrentDriver => "current_driver",
        JetPipe => "jet_pipe",
        /// The orifice geometry and flows.
        Valve => "valve",
        Supply => "supply",
        Return => "return",
        /// Volumes, leaks, thermodynamics.
        Chambers => "chambers",
        /// Piston, stopper, spring, friction.
        Mechanics => "mechanics",
        ForceSensor => "force_sensor",
        PressureSensors => "pressure_sensors",
        /// No place explains enough of the misfit.
        Unknown => "unknown",
        /// A candidate that stands for no place (the joint refit of everything added).
        Unplaced => "",
    }
}

impl From<jetpipe_model::variables::ChainPlace> for Place {
    fn from(place: jetpipe_model::variables::ChainPlace) -> Place {
        use jetpipe_model::variables::ChainPlace as C;
        match place {
            C::Command => Place::Command,
            C::CurrentDriver => Place::CurrentDriver,
            C::JetPipe => Place::JetPipe,
            C::Valve => Place::Valve,
            C::Supply => Place::Supply,
            C::Return => Place::Return,
            C::Chambers => Place::Chambers,
            C::Mechanics => Place::Mechanics,
            C::ForceSensor => Place::ForceSensor,
            C::PressureSensors => Place::PressureSensors,
        }
    }
}

vocabulary! {
    /// What kind of departure a term is.
    Family {
        /// A thesis constant has another value.
        ParameterOffset => "parameter_offset",
        /// Something changes slowly with time.
        Drift => "drift",
        /// A disturbance at a frequency.
        Periodic => "periodic",
        /// A signal saturates.
        Limit => "limit",
        /// An added lag or filter.
        Dynamics => "dynamics",
        Delay => "delay",
        /// A mass flow to or from somewhere the model has none.
        ExtraFlow => "extra_flow",
        /// A force that is a function of a signal.
        ExtraForce => "extra_force",
        Compliance => "compliance",
        /// A static curve on a signal.
        Nonlinearity => "nonlinearity",
        /// Supply against return, or port 1 against port 2.
        Asymmetry => "asymmetry",
        /// A flow resistance, with or without a volume.
        Restriction => "restriction",
        Hysteresis => "hysteresis",
        /// No place explains enough of the misfit to tell its kind.
        Unknown => "unknown",
        /// No family (the joint refit of everything added).
        Unclassified => "",
    }
}

vocabulary! {
    /// How the diagnosis formed a term: which of its classes it comes from.
    Origin {
        /// One of the seven named effects.
        Named => "named",
        /// A candidate written for its place (a constant, a transform, a law).
        Written => "written",
        /// A constant varying with a signal, in a modulation slot.
        Modulation => "modulation",
        /// A static curve through knots: a channel's, the command's, the discharge
        /// coefficient's.
        Curve => "curve",
        /// A generated term of a balance: an extra force product or an extra flow slot.
        BalanceTerm => "balance_term",
        /// A smooth surface of one or two signals, in a flexible slot.
        Flexible => "flexible",
    }
}

impl Origin {
    /// The origin the FMU parameters a term sets or fills show: each generated class has its
    /// own slots or curves; anything else was written.
    pub fn of_parameters<'a>(names: impl IntoIterator<Item = &'a str>) -> Origin {
        let names: Vec<&str> = names.into_iter().collect();
        let fills = |prefixes: &[&str]| names.iter().any(|n| prefixes.iter().any(|p| n.starts_with(p)));
        // A slot outranks a curve or a constant it targets.
        if fills(&["flexible_"]) {
            Origin::Flexible
        } else if fills(&["modulation_"]) {
            Origin::Modulation
        } else if fills(&["extra_force_product_", "extra_flow_"]) {
            Origin::BalanceTerm
        } else if names.iter().any(|n| n.contains("_curve_")) {
            Origin::Curve
        } else {
            Origin::Written
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_word_reads_back_as_its_value_and_serialises_as_itself() {
        for &place in Place::ALL {
            assert_eq!(Place::from_word(place.as_str()), Some(place));
            assert_eq!(serde_json::to_string(&place).unwrap(), format!("\"{place}\""));
        }
        for &family in Family::ALL {
            assert_eq!(Family::from_word(family.as_str()), Some(family));
        }
        assert_eq!(Place::from_word("piston"), None);
        assert_eq!(Place::PressureSensors.as_str(), "pressure_sensors");
        assert!(Place::Command < Place::PressureSensors, "the chain's order");
        for &origin in Origin::ALL {
            assert_eq!(Origin::from_word(origin.as_str()), Some(origin));
        }
    }

    #[test]
    fn a_terms_origin_is_read_from_the_slots_and_curves_it_fills() {
        assert_eq!(Origin::of_parameters(["force_sensor_lag"]), Origin::Written);
        assert_eq!(
            Origin::of_parameters(["command_curve_knots", "command_curve_x_1"]),
            Origin::Curve
        );
        assert_eq!(Origin::of_parameters(["discharge_curve_knots"]), Origin::Curve);
        assert_eq!(
            Origin::of_parameters(["extra_force_product_2_first"]),
            Origin::BalanceTerm
        );
        assert_eq!(Origin::of_parameters(["extra_flow_1_chamber"]), Origin::BalanceTerm);
        assert_eq!(Origin::of_parameters(["extra_inflow_1"]), Origin::Written);
        assert_eq!(
            Origin::of_parameters(["P_s", "modulation_1_parameter", "modulation_1_y_2"]),
            Origin::Modulation
        );
        assert_eq!(
            Origin::of_parameters(["extra_force_product_1_first", "flexible_1_y_1_1"]),
            Origin::Flexible
        );
    }
}
