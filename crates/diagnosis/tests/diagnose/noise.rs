//! `jetpipe diagnose` on recordings whose noise is not steady: growing with the force, or
//! wandering in time. A model without error still leaves only noise, so the verdict is
//! `explained`, with nothing added, and the input checks say how the noise varies.

use super::diagnose;
use jetpipe_diagnosis::input::recording::Recording;
use jetpipe_diagnosis::Diagnosis;
use jetpipe_model::physics::parameters::Parameters;
use synthetic_bench::BenchEffects;

use super::names;

/// Deterministic standard normal samples (Box–Muller on an LCG).
fn normals(seed: u64, n: usize) -> Vec<f64> {
    let mut state = seed;
    let mut uniform = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    };
    (0..n)
        .map(|_| {
            let (a, b) = (uniform(), uniform());
            (-2.0 * a.ln()).sqrt() * (2.0 * std::f64::consts::PI * b).cos()
        })
        .collect()
}

/// The bench's recording without effects (0.05 N and 150 Pa of noise), 24 s, with more force
/// noise of `extra(t, force)` N RMS added.
fn recording_with_force_noise(label: &str, extra: impl Fn(f64, f64) -> f64) -> Recording {
    let mut rows = synthetic_bench::generate(&BenchEffects::default(), 307, 24.0);
    let noise = normals(11, rows.len());
    for (row, e) in rows.iter_mut().zip(noise) {
        row[3] += extra(row[0], row[3]) * e;
    }
    let dir = std::env::temp_dir().join(format!("jetpipe-noise-{}-{label}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("recording.csv");
    synthetic_bench::write_csv(&rows, &path).unwrap();
    let recording = Recording::read(&path, &Parameters::default()).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    recording
}

fn run(label: &str, recording: &Recording) -> Diagnosis {
    let d = diagnose(recording, &Parameters::default(), false, &mut |_| {}).unwrap();
    println!(
        "{label}: {}; held-out {:.4} N on a floor of {:.4} N; added {:?} {:?}",
        d.verdict(),
        d.after.heldout_rms,
        d.noise_floor,
        names(&d),
        d.discovered.iter().map(|t| t.location).collect::<Vec<_>>()
    );
    d
}

#[test]
fn force_noise_growing_with_the_force_is_measured_as_such_and_a_right_model_is_explained() {
    // 0.05 N at no force to 0.29 N at 80 N.
    let recording = recording_with_force_noise("level", |_, force| 0.003 * force.abs());
    let d = run("noise growing with the force", &recording);
    let said = d
        .input_checks
        .iter()
        .find(|c| c.starts_with("The force channel's noise is not steady"));
    assert!(
        said.is_some_and(|s| s.contains("growing with the channel's level")),
        "{:?}",
        d.input_checks
    );
    assert!(d.effects.is_empty() && d.discovered.is_empty(), "added {:?}", names(&d));
    assert_eq!(d.verdict(), "explained");
    // The floor is the noise a right model leaves: the held-out RMS is near it.
    assert!(d.after.heldout_rms < 1.2 * d.noise_floor && d.after.heldout_rms > 0.8 * d.noise_floor);
}

#[test]
fn force_noise_wandering_in_time_is_measured_as_such_and_a_right_model_is_explained() {
    // From 0.05 N to 0.25 N and back every 12 s.
    let recording = recording_with_force_noise("time", |t, _| {
        0.2 * (0.5 - 0.5 * (2.0 * std::f64::consts::PI * t / 12.0).cos())
    });
    let d = run("noise wandering in time", &recording);
    let said = d
        .input_checks
        .iter()
        .find(|c| c.starts_with("The force channel's noise is not steady"));
    assert!(
        said.is_some_and(|s| s.contains("wandering in time")),
        "{:?}",
        d.input_checks
    );
    assert!(d.effects.is_empty() && d.discovered.is_empty(), "added {:?}", names(&d));
    assert_eq!(d.verdict(), "explained");
}
