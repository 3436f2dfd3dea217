//! `jetpipe sweep` (issue 6): results that do not depend on the thread count, the CSV's
//! shape, and bad parameter names and values refused with a message naming them and a
//! non-zero exit, before any run and without a panic.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use jetpipe_cli::sweep::{parse_axis, run_all, run_indices, RunSettings, Sweep, RESULT_COLUMNS};
use jetpipe_model::physics::parameters::Parameters;

/// Short runs keep the test quick; 2 s of the standard scenario still has both command
/// sines, a stopper move and thousands of integrator steps.
const DURATION: &str = "2";

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("jetpipe-sweep-cli-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn sweep_cli(args: &[&str], out: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_jetpipe"))
        .arg("sweep")
        .args(args)
        .args(["--duration", DURATION, "--out", out.to_str().unwrap()])
        .output()
        .expect("jetpipe runs")
}

/// CSV rows without the timing columns (cpu_s, wall_s), which are the only ones allowed to
/// change with the thread count.
fn physics_columns(csv: &str) -> Vec<Vec<String>> {
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let keep: Vec<usize> = (0..header.len())
        .filter(|&i| header[i] != "cpu_s" && header[i] != "wall_s")
        .collect();
    lines
        .map(|l| {
            let cells: Vec<&str> = l.split(',').collect();
            keep.iter().map(|&i| cells[i].to_string()).collect()
        })
        .collect()
}

#[test]
fn one_and_two_threads_give_bit_identical_results() {
    let axes = vec![
        parse_axis("C_d=0.6:0.75:3").unwrap(),
        parse_axis("P_s=600000,652925").unwrap(),
    ];
    let settings = RunSettings {
        duration: 2.0,
        ..RunSettings::default()
    };
    let sweep = Sweep::new(&Parameters::default(), axes, settings).unwrap();
    let (one, _) = run_all(&sweep, 1);
    let (two, _) = run_all(&sweep, 2);
    // More threads than runs, and the points in another order: still the same per point.
    let reversed: Vec<usize> = (0..sweep.len()).rev().collect();
    let (many, _) = run_indices(&sweep, &reversed, 8);
    assert_eq!(one.len(), 6);
    for i in 0..sweep.len() {
        assert!(one[i].error.is_none(), "run {i}: {:?}", one[i].error);
        assert_eq!(one[i].physics_bits(), two[i].physics_bits(), "run {i}: 1 vs 2 threads");
        assert_eq!(
            one[i].physics_bits(),
            many[sweep.len() - 1 - i].physics_bits(),
            "run {i}: 1 vs 8 threads, reversed"
        );
    }
    // The parameters were applied: a larger C_d charges chamber 1 faster, more force.
    assert!(one[0].rms_force < one[2].rms_force && one[2].rms_force < one[4].rms_force);
    assert!(
        one[0].rms_force < one[1].rms_force,
        "higher supply pressure, more force"
    );

    // The same through the command line, CSV against CSV.
    let dir = scratch("threads");
    let (a, b) = (dir.join("one.csv"), dir.join("two.csv"));
    let spec = ["--param", "C_d=0.6:0.75:3", "--param", "P_s=600000,652925"];
    let run = |threads: &str, out: &Path| {
        let mut args = spec.to_vec();
        args.extend(["--threads", threads, "--no-serial"]);
        let o = sweep_cli(&args, out);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        std::fs::read_to_string(out).unwrap()
    };
    let (csv1, csv2) = (run("1", &a), run("2", &b));
    assert_eq!(physics_columns(&csv1), physics_columns(&csv2));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn csv_has_one_row_per_run_and_the_speedup_is_printed() {
    let dir = scratch("shape");
    let out = dir.join("sweep.csv");
    let o = sweep_cli(
        &[
            "--param",
            "C_d=0.65,0.7",
            "--param",
            "k_spring=80:100:2",
            "--threads",
            "2",
        ],
        &out,
    );
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{stdout}\n{}", String::from_utf8_lossy(&o.stderr));
    for expected in [
        "4 runs",
        "runs/s",
        "speed-up",
        "parallel efficiency",
        "bit-identical to the 2-thread results: yes",
    ] {
        assert!(stdout.contains(expected), "no {expected:?} in:\n{stdout}");
    }
    let csv = std::fs::read_to_string(&out).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let mut expected_header = vec!["run", "C_d", "k_spring"];
    expected_header.extend(RESULT_COLUMNS);
    assert_eq!(header, expected_header);
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 4);
    let grid = [("0.65", "80"), ("0.65", "100"), ("0.7", "80"), ("0.7", "100")];
    for (k, row) in rows.iter().enumerate() {
        assert_eq!(row.len(), header.len(), "row {k}: {row:?}");
        assert_eq!(row[0], k.to_string());
        assert_eq!((row[1], row[2]), grid[k], "row {k}: grid order, last parameter fastest");
        assert_eq!(*row.last().unwrap(), "ok");
        // Every figure parses; forces are physical; the run did integrate.
        let value = |name: &str| -> f64 {
            let i = header.iter().position(|h| *h == name).unwrap();
            row[i]
                .parse()
                .unwrap_or_else(|_| panic!("row {k}, {name} = {:?}", row[i]))
        };
        assert!(value("rms_F_act_N") > 1.0 && value("max_F_act_N") < 120.0);
        assert!(value("min_F_act_N") <= value("rms_F_act_N") && value("rms_F_act_N") <= value("max_F_act_N"));
        assert!(value("final_P1_Pa") > 101_325.0 * 0.99 && value("final_P2_Pa") < 660_000.0);
        assert!(value("steps") > 100.0 && value("cpu_s") > 0.0 && value("wall_s") > 0.0);
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_names_and_values_are_refused_before_any_run() {
    let dir = scratch("bad");
    let out = dir.join("sweep.csv");
    std::fs::write(&out, "previous").unwrap();
    let cases: &[(&[&str], &[&str])] = &[
        (&["--param", "Cd=0.6:0.75:4"], &["Cd", "unknown parameter", "C_d"]),
        (&["--param", "c_d=0.6"], &["did you mean C_d"]),
        (&["--param", "F_act=3"], &["F_act cannot be swept"]),
        (
            &["--param", "P1_start=2e5"],
            &["P1_start cannot be swept", "equilibrium"],
        ),
        (&["--param", "C_d=0.6:x:4"], &["C_d", "\"x\"", "not a number"]),
        (&["--param", "C_d=-0.5"], &["C_d = -0.5", "(0, 1]"]),
        (&["--param", "P_s=0,652925"], &["P_s = 0 Pa", "(0, 1e7] Pa"]),
        (&["--param", "C_d=0.6:0.7:-2"], &["C_d", "\"-2\""]),
        (&["--param", "gamma=1.4,0.9"], &["gamma = 0.9", "(1, "]),
        (&["--param", "C_d=1.5"], &["C_d = 1.5", "must be in (0, 1]"]),
        (
            &["--param", "P_s=90000"],
            &["P_s = 90000 Pa", "must be >= P_r = 101325 Pa"],
        ),
        (
            &["--param", "k_spring=1e30"],
            &["k_spring = 1e30 N/m", "must be in [0, 100000] N/m"],
        ),
        (
            &["--param", "L_cyl=0.035"],
            &["L_cyl = 0.035", "x_s", "outside the cylinder"],
        ),
        (&["--param", "C_d=0.6", "--param", "C_d=0.7"], &["C_d", "twice"]),
        (&["--param", "C_d=0.6", "--threads", "0"], &["--threads 0"]),
        (&["--param", "C_d=0.6", "--step", "0.003"], &["--step 0.003"]),
    ];
    for (args, expected) in cases {
        let o = sweep_cli(args, &out);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{args:?}: exit status was success");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        for e in *expected {
            assert!(stderr.contains(e), "{args:?}: no {e:?} in stderr: {stderr}");
        }
        assert_eq!(
            std::fs::read_to_string(&out).unwrap(),
            "previous",
            "{args:?} touched the CSV"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn the_thesis_measured_preset_is_a_base_the_sweep_accepts_and_it_changes_the_force() {
    let preset = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../presets/thesis_measured.json");
    let dir = scratch("preset");
    let final_force = |base: Option<&Path>, name: &str| -> f64 {
        let out = dir.join(name);
        let mut args = vec!["--param", "k_spring=88.14", "--no-serial"];
        if let Some(base) = base {
            args.extend(["--base-params", base.to_str().unwrap()]);
        }
        let o = sweep_cli(&args, &out);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let csv = std::fs::read_to_string(&out).unwrap();
        let mut lines = csv.lines();
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        let row: Vec<&str> = lines.next().unwrap().split(',').collect();
        assert_eq!(*row.last().unwrap(), "ok");
        let i = header.iter().position(|h| *h == "final_F_act_N").unwrap();
        row[i].parse().unwrap()
    };
    let thesis = final_force(None, "thesis.csv");
    let measured = final_force(Some(&preset), "measured.csv");
    // The hysteresis and the vent move the force of the standard scenario by newtons, not bits.
    assert!(
        (measured - thesis).abs() > 0.5,
        "thesis {thesis} N, with the preset {measured} N"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_reports_start_values_are_a_base_the_sweep_accepts_naming_the_start_state_it_does_not_read() {
    // fmu_start_values as a diagnosis writes them: constants, and the start state the FMU
    // reproduces the recording from.
    let dir = scratch("start_values");
    let base = dir.join("start_values.json");
    let run = |text: &str, name: &str| -> Output {
        std::fs::write(&base, text).unwrap();
        sweep_cli(
            &[
                "--param",
                "k_spring=88.14",
                "--no-serial",
                "--base-params",
                base.to_str().unwrap(),
            ],
            &dir.join(name),
        )
    };
    let o = run(
        r#"{"P1_start": 351745.6, "P2_start": 510402.7, "start_at_equilibrium": false, "friction_coulomb": 2.08}"#,
        "accepted.csv",
    );
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    assert!(
        stderr.contains("start_at_equilibrium") && stderr.contains("P1_start") && stderr.contains("does not read"),
        "{stderr}"
    );
    for (text, expected) in [
        (r#"{"P1_start": -5}"#, "P1_start = -5 Pa is invalid"),
        (
            r#"{"start_at_equilibrium": 2}"#,
            "'start_at_equilibrium' = 2 is invalid",
        ),
        (r#"{"start_at_equilibrium": "yes"}"#, "must be a number or a boolean"),
    ] {
        let o = run(text, "refused.csv");
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && stderr.contains(expected), "{text}: {stderr}");
    }
    std::fs::remove_dir_all(&dir).ok();
}
