//! `jetpipe diagnose` end to end, in one test binary:
//!
//! * `shared`: the project's shared bench recordings (`../shared/bench/`);
//! * `synthetic`: the synthetic bench's recordings of the named effects;
//! * `undeclared`: the synthetic bench's undeclared mechanisms;
//! * `protocols`: the general discovery pieces on recordings under other protocols;
//! * `balance`: an extra force in the piston's balance picked from a library of local signals;
//! * `beside`: a named friction beside another effect;
//! * `flows`: an extra mass flow into one chamber alone, from the generated class;
//! * `curves`: the static-curve class at the command and the transducers;
//! * `search`: compounds and mechanisms that a search locking in on its first choice missed;
//! * `constants`: a thesis constant of the plant other than the model's, re-identified;
//! * `modulations`: a constant of the model varying with a signal of the chain;
//! * `intervals`: the intervals and margins of a report;
//! * `joint`: several recordings of one actuator diagnosed together;
//! * `flexible`: a departure no readable class holds, closed by a flexible term.
//!
//! The test command runs a representative subset: every module but `flexible` (an opt-in
//! option whose one case takes two minutes), each place of the chain and each function class
//! at least once. The other cases are `#[ignore]`d with the reason
//! "a broad case", and `scripts/bench_cases.sh` runs every case, each on its own, with its
//! time (docs/results/diagnosis_cases.md has the table).
//!
//! Why one binary and not three: cargo runs test binaries one after another and each
//! harness runs its tests two at a time, so a binary's last, long test left a core idle
//! until it ended, three times over. Here the harness takes the next of all the
//! diagnoses whenever one ends, and both cores stay busy until the last few.

mod balance;
mod beside;
mod compound;
mod constants;
mod curves;
mod flexible;
mod flows;
mod glitches;
mod intervals;
mod joint;
mod modulations;
mod noise;
mod protocols;
mod search;
mod shared;
mod synthetic;
mod undeclared;

use jetpipe_diagnosis::input::recording::Recording;
use jetpipe_diagnosis::Diagnosis;
use jetpipe_model::physics::parameters::Parameters;

/// The library's `diagnose`, which also writes the case's report when
/// `JETPIPE_CASE_REPORTS` names a folder: `scripts/compare_reports.py` holds two such sets
/// against each other, so that a change meant to move code and not behaviour is shown to
/// give the same reports. A case's report is named after its test (the harness names each
/// test's thread after it), with a count when one test diagnoses more than once.
fn diagnose(
    recording: &Recording,
    base: &Parameters,
    calibrate: bool,
    progress: &mut dyn FnMut(&str),
) -> Result<Diagnosis, String> {
    let diagnosis = jetpipe_diagnosis::diagnose(recording, base, calibrate, progress)?;
    if let Some(dir) = std::env::var_os("JETPIPE_CASE_REPORTS") {
        thread_local!(static COUNT: std::cell::Cell<usize> = const { std::cell::Cell::new(0) });
        let count = COUNT.with(|c| {
            c.set(c.get() + 1);
            c.get()
        });
        let thread = std::thread::current();
        let case = thread.name().unwrap_or("main").replace("::", ".");
        let name = format!("{case}.{count}");
        let path = std::path::Path::new(&dir).join(format!("{name}.json"));
        std::fs::create_dir_all(&dir).unwrap();
        let report = serde_json::to_string_pretty(&diagnosis.to_json(&name)).unwrap();
        std::fs::write(&path, report).unwrap();
    }
    Ok(diagnosis)
}

/// The names of the named effects a diagnosis added.
fn names(d: &Diagnosis) -> Vec<&'static str> {
    d.effects.iter().map(|e| e.name).collect()
}

/// The FMU value reference of a model variable.
fn value_reference(name: &str) -> u32 {
    jetpipe_model::variables::VARIABLES
        .iter()
        .find(|v| v.name == name)
        .unwrap()
        .value_reference
}

/// Rows of the synthetic bench read back as a recording, through the CSV file the bench
/// writes (its formatting and quantisation are part of what is tested), with `base` as the
/// model the recording is read against. `label` names the file's folder, unique in the
/// binary: the tests run in parallel in one process.
fn generated(label: &str, rows: &[[f64; 6]], base: &Parameters) -> Recording {
    let dir = std::env::temp_dir().join(format!("jetpipe-diagnose-{}-{label}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("recording.csv");
    synthetic_bench::write_csv(rows, &path).unwrap();
    let recording = Recording::read(&path, base).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    recording
}
