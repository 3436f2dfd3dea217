//! The `benchgen` binary writes what the library generates. (Also why `cargo test --release`
//! builds `target/release/benchgen`, which fmu_tests/test_diagnose_fmu.py runs.)

use std::process::Command;

use synthetic_bench::{generate, write_csv, BenchEffects, UNDECLARED};

#[test]
fn benchgen_lists_the_undeclared_mechanisms() {
    let output = Command::new(env!("CARGO_BIN_EXE_benchgen"))
        .args(["--out", "unused.csv", "--list-undeclared"])
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let text = String::from_utf8(output.stdout).unwrap();
    let names: Vec<&str> = text.lines().map(|l| l.split('\t').next().unwrap()).collect();
    let expected: Vec<&str> = UNDECLARED.iter().map(|m| m.name).collect();
    assert_eq!(names, expected);
}

#[test]
fn benchgen_writes_the_recording_of_the_library() {
    let dir = std::env::temp_dir().join(format!("benchgen-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (cli, library) = (dir.join("cli.csv"), dir.join("library.csv"));
    let output = Command::new(env!("CARGO_BIN_EXE_benchgen"))
        .args(["--out", cli.to_str().unwrap(), "--seed", "3", "--duration", "1"])
        .args(["--friction-coulomb", "2"])
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let effects = BenchEffects {
        friction_coulomb: 2.0,
        ..BenchEffects::default()
    };
    write_csv(&generate(&effects, 3, 1.0), &library).unwrap();
    assert_eq!(std::fs::read(&cli).unwrap(), std::fs::read(&library).unwrap());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn benchgen_writes_the_recording_of_the_library_with_the_two_extra_piston_forces() {
    let dir = std::env::temp_dir().join(format!("benchgen-forces-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (cli, library, without) = (dir.join("cli.csv"), dir.join("library.csv"), dir.join("without.csv"));
    let output = Command::new(env!("CARGO_BIN_EXE_benchgen"))
        .args(["--out", cli.to_str().unwrap(), "--seed", "3", "--duration", "3"])
        .args(["--position-sign-force", "-75", "--position-sign-origin", "0.054"])
        .args(["--chamber-1-pressure-force", "1e-6"])
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let mut effects = BenchEffects::default();
    effects.undeclared.position_sign_force = -75.0;
    effects.undeclared.position_sign_origin = 0.054;
    effects.undeclared.chamber_1_pressure_force = 1e-6;
    write_csv(&generate(&effects, 3, 3.0), &library).unwrap();
    write_csv(&generate(&BenchEffects::default(), 3, 3.0), &without).unwrap();
    let read = |path: &std::path::Path| std::fs::read(path).unwrap();
    assert!(
        read(&cli) == read(&library),
        "the command line gives the library's recording"
    );
    // Once the pressures lift the force above the spring's floor (the first second holds it
    // there), 1e-6 m² on chamber 1's pressure above the return moves it by tenths of a newton.
    assert!(read(&cli) != read(&without), "the forces change the recording");
    let refused = Command::new(env!("CARGO_BIN_EXE_benchgen"))
        .args(["--out", "unused.csv", "--chamber-1-pressure-force", "nan"])
        .output()
        .unwrap();
    assert_eq!(refused.status.code(), Some(2));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn benchgen_refuses_an_unknown_mechanism() {
    let output = Command::new(env!("CARGO_BIN_EXE_benchgen"))
        .args(["--out", "unused.csv", "--undeclared", "no_such_mechanism"])
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&output.stderr).contains("unknown undeclared mechanism"));
}

#[test]
fn benchgen_writes_a_protocol_recording_without_pressures_at_the_asked_rate() {
    let dir = std::env::temp_dir().join(format!("benchgen-protocol-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("multisine.csv");
    let output = Command::new(env!("CARGO_BIN_EXE_benchgen"))
        .args([
            "--out",
            out.to_str().unwrap(),
            "--protocol",
            "multisine",
            "--duration",
            "20",
        ])
        .args([
            "--sample-rate",
            "2000",
            "--no-pressures",
            "--stopper",
            "sine:0.054:0.005:2.5",
        ])
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let text = std::fs::read_to_string(&out).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "time_s,v_da_V,x_s_m,force_N");
    assert_eq!(lines.len(), 1 + 40_000);
    let time = |line: &str| line.split(',').next().unwrap().parse::<f64>().unwrap();
    assert!((time(lines[2]) - time(lines[1]) - 0.0005).abs() < 1e-9);
}

#[test]
fn benchgen_refuses_a_sampling_rate_off_the_integration_step_naming_it() {
    let output = Command::new(env!("CARGO_BIN_EXE_benchgen"))
        .args([
            "--out",
            "unused.csv",
            "--protocol",
            "prbs",
            "--duration",
            "20",
            "--sample-rate",
            "300",
        ])
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(2));
    let err = String::from_utf8_lossy(&output.stderr);
    assert!(err.contains("sample_rate = 300 Hz"), "{err}");
}
