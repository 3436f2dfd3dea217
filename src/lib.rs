//! Jet-pipe electropneumatic actuator of the Utah/MIT Dextrous Hand (P.D. Henri, 1994).

pub mod fmi2;
pub mod variables;
