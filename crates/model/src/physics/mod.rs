//! The actuator's physics, one module per physical part, in plain Rust (no FFI types).
//! Equation numbers are those of P.D. Henri's 1994 thesis; docs/model.md ("Choices the thesis leaves open") corrects its slips.
//! Each equation is stated once, here: the exact propagator (`crate::electromechanics`)
//! takes the current driver, f3 and the jet pipe's linear dynamics from `current_driver`
//! and `jet_pipe` rather than deriving them again.
//!
//! | part | module | equations |
//! |---|---|---|
//! | parameters and their defaults | [`parameters`] | Table 3.1, docs/model.md |
//! | current driver | [`current_driver`] | (2.1)–(2.3) |
//! | jet pipe | [`jet_pipe`] | (2.4)–(2.7) |
//! | orifice areas (supply/return area of each port) | [`orifice_geometry`] | (2.8)–(2.17) |
//! | orifice and leakage flow | [`orifice_flow`] | (2.18)–(2.23) |
//! | chambers | [`chambers`] | (2.24)–(2.32) |
//! | piston force and spring | [`piston`] | (2.36)–(2.38) |
//! | effects the thesis model lacks (off by default) | [`effects`] | docs/model.md |
//! | an extra force in the piston's balance, from a library of local signals (off by default) | [`extra_force`] | (2.36) |
//! | an extra mass flow into one chamber alone, from a library of pressure signals (off by default) | [`extra_flow`] | (2.24)–(2.25) |
//! | restrictions and gas volumes between the valve and the air (off by default) | [`restrictions`] | (2.18), (2.29) |
//! | the command as the current driver sees it (off by default) | [`command_stage`] | (2.1) |
//! | what the force and pressure transducers read | [`sensors`] | docs/model.md |
//! | static curves at the command and the transducers (off by default) | [`static_curve`] | docs/model.md |
//! | constants that vary in time (off by default) | [`time_varying`] | docs/model.md |
//! | a constant that varies with a signal of the chain: the modulation slots (off by default) | [`modulation`] | docs/model.md |
//! | a constant plus a function of one or two signals, each optionally low-passed: the flexible slots (off by default) | [`flexible`] | docs/model.md |
//! | the assembled six-state model | [`actuator`] | (4.1) |

pub mod actuator;
pub mod chambers;
pub mod command_stage;
pub mod current_driver;
pub mod effects;
pub mod extra_flow;
pub mod extra_force;
pub mod flexible;
pub mod jet_pipe;
pub mod modulation;
pub mod orifice_flow;
pub mod orifice_geometry;
pub mod parameters;
pub mod piston;
pub mod restrictions;
pub mod sensors;
pub mod static_curve;
pub mod time_varying;
