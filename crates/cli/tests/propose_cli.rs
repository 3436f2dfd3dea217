//! `jetpipe propose` from the command line: from a report that ties two places, a protocol a
//! bench can play and, beside it, the JSON and the page that say what it separates; a file
//! that is no report is refused with its name, and nothing is written.

use std::path::Path;
use std::process::Command;

fn propose(dir: &Path, report: &str, extra: &[&str]) -> (bool, String, String) {
    let path = dir.join("report.json");
    std::fs::write(&path, report).unwrap();
    let out = dir.join("next.csv");
    let mut args = vec!["propose", path.to_str().unwrap(), "--out", out.to_str().unwrap()];
    args.extend_from_slice(extra);
    let output = Command::new(env!("CARGO_BIN_EXE_jetpipe"))
        .args(&args)
        .output()
        .expect("jetpipe runs");
    (
        output.status.success(),
        String::from_utf8_lossy(&output.stdout).into_owned(),
        String::from_utf8_lossy(&output.stderr).into_owned(),
    )
}

const TIED: &str = r#"{
  "verdict": "explained", "noise_floor_N": 0.05,
  "noise_floor_Pa": {"p1": 150.0, "p2": 150.0},
  "fmu_start_values": {"omega_1": 62.4},
  "discovered": [{"candidate": "jet pipe lag", "location": "jet_pipe", "parameters": {"omega_1": 62.4},
                  "tied_locations": ["jet_pipe", "command"]}],
  "candidates": [{"candidate": "command delay", "location": "command", "parameters": {"command_delay": 0.015},
                  "settings": {}, "explained_share_heldout": 0.9}]
}"#;

#[test]
fn a_tied_report_gets_a_playable_protocol_with_its_json_and_page_beside_it() {
    let dir = std::env::temp_dir().join(format!("jetpipe-propose-cli-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let (ok, stdout, stderr) = propose(&dir, TIED, &["--seconds", "10", "--rate", "500", "--seed", "2"]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("noise floors"), "{stdout}");
    let csv = std::fs::read_to_string(dir.join("next.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("time_s,v_da_V,x_s_m"));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 5001);
    for pair in rows.windows(2) {
        assert!(
            (pair[1][0] - pair[0][0] - 2e-3).abs() < 1e-9,
            "evenly sampled at 500 Hz"
        );
        assert!(
            (pair[1][2] - pair[0][2]).abs() * 500.0 <= 0.2 + 1e-6,
            "the stopper within 200 mm/s"
        );
    }
    assert!(rows
        .iter()
        .all(|r| r[1].abs() <= 10.0 && (0.035..=0.09).contains(&r[2])));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("next.json")).unwrap()).unwrap();
    assert_eq!(json["protocol"], "next.csv");
    assert_eq!(json["closest_pair"][1], "command delay");
    assert_eq!(
        json["channels"].as_array().unwrap().len(),
        3,
        "force and both pressures"
    );
    assert!(json["smallest_noise_floors"].as_f64().unwrap() > 1.0, "{json}");
    let page = std::fs::read_to_string(dir.join("next.html")).unwrap();
    assert!(page.contains("What to record next") && page.contains("<svg") && page.contains("command delay"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_file_that_is_no_report_is_refused_by_name_and_nothing_is_written() {
    let dir = std::env::temp_dir().join(format!("jetpipe-propose-bad-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for (text, words) in [
        ("not json", "not valid JSON"),
        (r#"{"noise_floor_N": 0.05}"#, "fmu_start_values"),
    ] {
        let (ok, _, stderr) = propose(&dir, text, &[]);
        assert!(!ok);
        assert!(stderr.contains("report.json") && stderr.contains(words), "{stderr}");
        assert!(!dir.join("next.csv").exists());
    }
    let (ok, _, stderr) = propose(&dir, TIED, &["--rate", "100"]);
    assert!(
        !ok && stderr.contains("--rate 100") && stderr.contains("250"),
        "{stderr}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
