//! The antagonistic finger joint of the Utah/MIT Dextrous Hand as an SSP (System Structure
//! and Parameterization 1.0) of FMUs: two jet-pipe actuators, two tendons, one joint and a
//! joint controller, wired as in the hand's 2N drive (thesis §1.1.1, §1.4):
//!
//! ```text
//!  theta_ref ─► controller ─v_DA─► actuator_flexor ──F_act──► tendon_flexor ──T──► joint
//!                 ▲  ▲  ▲           ▲      │ F_meas             │ ▲ x_s           │
//!                 │  │  └───────────┼──────┘                    │ └──x_flexor, v──┤
//!                 │  │              └──────────── x_s ──────────┘                 │
//!                 │  └──F_meas── actuator_extensor ◄─x_s─ tendon_extensor ◄──x,v──┤
//!                 └─────────────────────── theta, omega ──────────────────────────┘
//! ```
//!
//! Each tendon's displacement at the rod is its actuator's stopper position `x_s`; each
//! actuator's force `F_act` pulls its tendon; the tendons' joint-end tensions turn the joint,
//! whose excursions r·θ and −r·θ are the tendons' joint ends. The connector names are checked
//! against the models' variable tables here, so a renamed variable fails the packaging, not
//! the simulation.
//!
//! [`system`] holds the structure and the parameter set; [`package`] writes the FMUs and the
//! `.ssp` archive.

pub mod package;
pub mod system;
