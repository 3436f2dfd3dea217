//! The FMU's outputs are bit-identical to a stored reference on the standard scenario and on
//! the chirp (issue 20: the layout may change, the behaviour may not).
//!
//! Both scenarios run through the exported `fmi2*` functions, as an importer drives the FMU:
//! default parameters and tolerance, start at the equilibrium of the first inputs, inputs set
//! before each `fmi2DoStep`, the six outputs read after it. Every communication point goes
//! into a 64-bit FNV-1a digest of the outputs' bits; every 10 ms point is also stored in full
//! (the bits as hex), so that a failure says where the outputs first differ and by how much.
//! The reference files are `tests/reference/*.csv`; how they were made is in
//! `tests/reference/README.md`. To write them anew (only for a deliberate change of
//! behaviour, said so in the commit):
//!
//!     JETPIPE_WRITE_REFERENCE=1 cargo test --release --test reference_outputs

mod common;

use std::f64::consts::PI;
use std::fmt::Write as _;
use std::path::PathBuf;

use common::*;
use fmi2::types::*;
use jetpipe::fmu_exports::*;
use jetpipe::variables::vr;

/// The outputs compared, in the files' column order.
const COLUMNS: [(&str, u32); 6] = [
    ("F_act", vr::F_ACT),
    ("P1", vr::P1),
    ("P2", vr::P2),
    ("i", vr::I),
    ("x_jp", vr::X_JP),
    ("F_meas", vr::F_MEAS),
];

/// A scenario as the reference defines it (kept here, not shared with the benchmarks, so that
/// editing a benchmark cannot move the reference).
struct Scenario {
    name: &'static str,
    /// Communication step, s.
    step: f64,
    steps: usize,
    /// Inputs (v_DA, x_s) set before the step that starts at communication point `k`.
    inputs: fn(usize) -> (f64, f64),
}

/// The standard scenario of `src/scenario.rs`: 10 s, inputs held every 10 ms.
const STANDARD: Scenario = Scenario {
    name: "standard",
    step: 0.01,
    steps: 1000,
    inputs: jetpipe_model::scenario::standard_inputs,
};

/// The chirp of the benchmarks (`benches/common/scenarios.rs`): v_DA = 2.5 + 1.5 sin φ(t),
/// frequency rising linearly from 0.1 to 20 Hz over 10 s, held every 1 ms; x_s = 54 mm.
const CHIRP: Scenario = Scenario {
    name: "chirp",
    step: 0.001,
    steps: 10_000,
    inputs: chirp_inputs,
};

fn chirp_inputs(k: usize) -> (f64, f64) {
    let t = k as f64 * 0.001;
    let (f0, f1, duration) = (0.1, 20.0, 10.0);
    let phase = 2.0 * PI * (f0 * t + (f1 - f0) * t * t / (2.0 * duration));
    (2.5 + 1.5 * phase.sin(), 0.054)
}

/// What a run produces: the digest over every point and the 10 ms points in full.
struct Run {
    digest: u64,
    /// (communication point index, output bits in [`COLUMNS`] order).
    rows: Vec<(usize, [u64; 6])>,
}

fn fnv1a(mut hash: u64, bits: u64) -> u64 {
    for byte in bits.to_le_bytes() {
        hash ^= u64::from(byte);
        hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
    }
    hash
}

const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;

fn run(scenario: &Scenario) -> Run {
    let sink = Sink::default();
    let every = (0.01 / scenario.step).round() as usize;
    let mut digest = FNV_OFFSET;
    let mut rows = Vec::with_capacity(scenario.steps / every + 1);
    unsafe {
        let c = instantiate(&sink, scenario.name);
        let (v0, x0) = (scenario.inputs)(0);
        initialise(c, None, &[], v0, x0);
        let vrs: Vec<u32> = COLUMNS.iter().map(|&(_, r)| r).collect();
        let mut record = |k: usize, digest: &mut u64| {
            let (status, y) = get_reals(c, &vrs);
            assert_eq!(status, fmi2OK, "{}: fmi2GetReal at point {k}", scenario.name);
            let mut bits = [0u64; 6];
            for (b, v) in bits.iter_mut().zip(&y) {
                *b = v.to_bits();
                *digest = fnv1a(*digest, *b);
            }
            if k % every == 0 {
                rows.push((k, bits));
            }
        };
        record(0, &mut digest);
        for k in 0..scenario.steps {
            let t = k as f64 * scenario.step;
            let (v, x) = (scenario.inputs)(k);
            set_inputs(c, v, x);
            let status = fmi2DoStep(c, t, scenario.step, fmi2True);
            assert_eq!(
                status,
                fmi2OK,
                "{}: fmi2DoStep at t = {t}: {:?}",
                scenario.name,
                sink.since(0)
            );
            record(k + 1, &mut digest);
        }
        fmi2FreeInstance(c);
    }
    Run { digest, rows }
}

fn reference_path(scenario: &Scenario) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/reference")
        .join(format!("fmu_outputs_{}.csv", scenario.name))
}

fn to_text(scenario: &Scenario, run: &Run) -> String {
    let mut text = String::new();
    writeln!(
        text,
        "# {} scenario: {} communication steps of {} s; FNV-1a 64 of the output bits at every point: {:016x}",
        scenario.name, scenario.steps, scenario.step, run.digest
    )
    .unwrap();
    let names: Vec<&str> = COLUMNS.iter().map(|&(n, _)| n).collect();
    writeln!(text, "point,{}", names.join(",")).unwrap();
    for (k, bits) in &run.rows {
        let hex: Vec<String> = bits.iter().map(|b| format!("{b:016x}")).collect();
        writeln!(text, "{k},{}", hex.join(",")).unwrap();
    }
    text
}

/// (digest, rows) of a reference file.
fn parse(text: &str) -> (u64, Vec<(usize, [u64; 6])>) {
    let mut lines = text.lines();
    let header = lines.next().expect("a digest line");
    let digest = u64::from_str_radix(header.rsplit(' ').next().unwrap(), 16).expect("a hex digest");
    lines.next().expect("a column line");
    let rows = lines
        .map(|line| {
            let mut fields = line.split(',');
            let k = fields.next().unwrap().parse().unwrap();
            let mut bits = [0u64; 6];
            for b in bits.iter_mut() {
                *b = u64::from_str_radix(fields.next().unwrap(), 16).unwrap();
            }
            (k, bits)
        })
        .collect();
    (digest, rows)
}

fn check(scenario: &Scenario) {
    let path = reference_path(scenario);
    let run = run(scenario);
    if std::env::var("JETPIPE_WRITE_REFERENCE").map_or(false, |v| v == "1") {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, to_text(scenario, &run)).unwrap();
        return;
    }
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let (digest, rows) = parse(&text);
    assert_eq!(rows.len(), run.rows.len(), "{}: number of stored points", scenario.name);
    for ((k, want), (k_got, got)) in rows.iter().zip(&run.rows) {
        assert_eq!(k, k_got);
        for (j, (w, g)) in want.iter().zip(got).enumerate() {
            assert!(
                w == g,
                "{}: {} at point {k} (t = {} s) is {:e}, the reference {:e} (bits {g:016x} vs {w:016x})",
                scenario.name,
                COLUMNS[j].0,
                *k as f64 * scenario.step,
                f64::from_bits(*g),
                f64::from_bits(*w)
            );
        }
    }
    assert_eq!(
        run.digest, digest,
        "{}: the 10 ms points agree, but an output between them differs (digest {:016x}, reference {digest:016x})",
        scenario.name, run.digest
    );
}

#[test]
fn the_standard_scenario_gives_the_reference_outputs_bit_for_bit() {
    check(&STANDARD);
}

#[test]
fn the_chirp_gives_the_reference_outputs_bit_for_bit() {
    check(&CHIRP);
}

#[test]
fn a_change_in_the_last_bit_of_one_output_is_caught() {
    let run = run(&STANDARD);
    let (digest, rows) = parse(&to_text(&STANDARD, &run));
    assert_eq!((digest, rows.len()), (run.digest, run.rows.len()));
    let mut changed = run.rows[500].1;
    changed[0] ^= 1;
    assert_ne!(changed, rows[500].1);
    let rehashed = run.rows.iter().fold(FNV_OFFSET, |h, (k, bits)| {
        let b = if *k == 500 { &changed } else { bits };
        b.iter().fold(h, |h, &x| fnv1a(h, x))
    });
    let original = run
        .rows
        .iter()
        .fold(FNV_OFFSET, |h, (_, bits)| bits.iter().fold(h, |h, &x| fnv1a(h, x)));
    assert_ne!(rehashed, original, "one flipped bit changes the digest");
}
