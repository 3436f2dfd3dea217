//! The modulation class: a constant of the model that varies with a signal of the chain,
//! generated from the model's list of constants times the list of signals, not written for
//! one mechanism. The synthetic bench writes the mechanism with its own integrator and its
//! own form (a friction present over a band of the bore, with tanh edges the diagnosis's
//! piecewise-linear shape can only approach), so nothing of the candidate is copied into the
//! recording.

use jetpipe_diagnosis::diagnose;
use jetpipe_diagnosis::recording::Recording;
use jetpipe_model::physics::modulation::ModulationSignal;
use jetpipe_model::physics::parameters::Parameters;
use jetpipe_model::variables::vr;
use synthetic_bench::{
    generate_protocol, BenchEffects, CommandProtocol, ProtocolSpec, StopperMotion, UndeclaredEffects,
};

use super::names;

#[test]
fn a_friction_over_a_band_of_the_bore_is_the_coulomb_friction_varying_with_the_stopper_position() {
    let spec = ProtocolSpec {
        command: CommandProtocol::Multisine,
        stopper: StopperMotion::Sine {
            centre: 0.062,
            amplitude: 0.010,
            frequency: 0.4,
        },
        sample_rate: 1000.0,
        duration: 30.0,
        force_noise: 0.05,
        pressures: true,
        seed: 5,
        ..ProtocolSpec::default()
    };
    let effects = BenchEffects {
        undeclared: UndeclaredEffects {
            friction_band: 2.5,
            ..UndeclaredEffects::default()
        },
        ..BenchEffects::default()
    };
    let dir = std::env::temp_dir().join(format!("jetpipe-diagnose-{}-friction-band", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("recording.csv");
    generate_protocol(&spec, &effects).unwrap().write_csv(&path).unwrap();
    let recording = Recording::read(&path, &Parameters::default()).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    let d = diagnose(&recording, &Parameters::default(), false, &mut |_| {}).unwrap();
    println!("friction band: {}", d.summary().join(" | "));
    assert!(names(&d).is_empty(), "named {:?}", names(&d));
    assert_eq!(d.discovered.len(), 1, "{}", d.summary().join(" | "));
    let found = &d.discovered[0];
    assert_eq!(
        (found.location, found.family),
        ("mechanics", "extra_force"),
        "{}",
        found.reading
    );
    assert_eq!(d.verdict(), "explained", "{}", d.summary()[0]);
    // In the model: slot 1 carries the Coulomb friction against the stopper position.
    let slot = &d.parameters.modulation[0];
    assert_eq!(slot.constant(), vr::FRICTION_COULOMB, "{}", found.reading);
    assert_eq!(slot.signal(), ModulationSignal::StopperPosition, "{}", found.reading);
    // Inside the band the friction is the bench's 2.5 N within 10 %, outside it within 0.25 N
    // of none.
    for (x, level) in [(0.0625, 2.5), (0.064, 2.5), (0.055, 0.0), (0.070, 0.0)] {
        let fitted = d.parameters.friction_coulomb + slot.increment(x);
        assert!(
            (fitted - level).abs() <= 0.1 * 2.5,
            "at {x} m: {fitted} N, the bench's {level} N ({})",
            found.reading
        );
    }
    assert!(
        found.reading.contains("friction_coulomb changes by") && found.reading.contains("mm of x_s"),
        "{}",
        found.reading
    );
}
