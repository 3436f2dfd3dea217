//! `jetpipe diagnose A.csv B.csv --joint`: one report and one page for the recordings of one
//! actuator, with each recording's errors; refusals that name what is wrong.

use std::path::{Path, PathBuf};
use std::process::Command;

use synthetic_bench::{generate_protocol, BenchEffects, CommandProtocol, ProtocolSpec};

fn recording(dir: &Path, name: &str, spec: &ProtocolSpec) -> PathBuf {
    let path = dir.join(name);
    generate_protocol(spec, &BenchEffects::default())
        .unwrap()
        .write_csv(&path)
        .unwrap();
    path
}

fn jetpipe(args: &[&str], dir: &Path) -> (bool, String, String) {
    let output = Command::new(env!("CARGO_BIN_EXE_jetpipe"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("jetpipe runs");
    (
        output.status.success(),
        String::from_utf8_lossy(&output.stdout).into_owned(),
        String::from_utf8_lossy(&output.stderr).into_owned(),
    )
}

#[test]
fn two_recordings_of_one_actuator_give_one_report_and_page_with_each_recording_s_errors() {
    let dir = std::env::temp_dir().join(format!("jetpipe-joint-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let short = |command, sample_rate, pressures, seed| ProtocolSpec {
        command,
        sample_rate,
        duration: 20.0,
        pressures,
        seed,
        ..ProtocolSpec::default()
    };
    recording(&dir, "steps.csv", &short(CommandProtocol::Staircase, 1000.0, true, 1));
    recording(&dir, "sines.csv", &short(CommandProtocol::Multisine, 500.0, false, 2));
    let (ok, stdout, stderr) = jetpipe(&["diagnose", "steps.csv", "sines.csv", "--joint"], &dir);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("steps.csv: held-out force error"), "{stdout}");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("steps_joint.json")).unwrap()).unwrap();
    // A single report's fields, for the tools that read one…
    for field in [
        "verdict",
        "effects",
        "discovered",
        "heldout",
        "noise_floor_N",
        "fmu_start_values",
    ] {
        assert!(!report[field].is_null(), "no {field}");
    }
    assert_eq!(report["recording"], "steps.csv + sines.csv");
    // …and each recording's, at its own rate and with its own channels.
    let recordings = report["recordings"].as_array().unwrap();
    assert_eq!(recordings.len(), 2);
    assert_eq!(recordings[0]["recording"], "steps.csv");
    assert_eq!(recordings[0]["samples"], 20_000);
    assert_eq!(recordings[1]["samples"], 10_000);
    assert!((recordings[1]["rate_Hz"].as_f64().unwrap() - 500.0).abs() < 1e-6);
    assert_eq!(recordings[0]["fitted_at_a_lower_rate"], true);
    assert!(recordings[0]["after"]["pressure_rms_Pa"].is_array());
    assert!(recordings[1]["after"]["pressure_rms_Pa"].is_null());
    let notes: Vec<&str> = report["joint"]["notes"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|n| n.as_str())
        .collect();
    assert!(notes.iter().any(|n| n.contains("sines.csv has none")), "{notes:?}");
    assert!(
        notes
            .iter()
            .any(|n| n.contains("steps.csv (1000 Hz) is fitted at 500 Hz")),
        "{notes:?}"
    );
    let page = std::fs::read_to_string(dir.join("steps_joint.html")).unwrap();
    assert!(page.contains("<table id=recordings>"), "no recordings table");
    assert!(page.contains("<td>sines.csv</td>"), "sines.csv not on the page");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_joint_diagnosis_of_one_recording_or_a_directory_or_a_bad_file_is_refused_by_name() {
    let dir = std::env::temp_dir().join(format!("jetpipe-joint-cli-refusals-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("folder")).unwrap();
    let spec = ProtocolSpec {
        duration: 20.0,
        ..ProtocolSpec::default()
    };
    recording(&dir, "good.csv", &spec);
    std::fs::write(
        dir.join("bad.csv"),
        "time_s,v_da_V,x_s_m,force_N\n0,1,0.054,2\n0.001,one,0.054,2\n",
    )
    .unwrap();
    let cases: [(&[&str], &str); 3] = [
        (
            &["diagnose", "good.csv", "--joint"],
            "--joint needs two or more recordings of one actuator, got 1",
        ),
        (&["diagnose", "good.csv", "folder", "--joint"], "folder is a directory"),
        (&["diagnose", "good.csv", "bad.csv", "--joint"], "row 3, column v_da_V"),
    ];
    for (args, expected) in cases {
        let (ok, _, stderr) = jetpipe(args, &dir);
        assert!(!ok, "{args:?} succeeded");
        assert!(stderr.contains(expected), "{args:?}: {stderr}");
    }
    assert!(!dir.join("good_joint.json").exists());
    let _ = std::fs::remove_dir_all(&dir);
}
