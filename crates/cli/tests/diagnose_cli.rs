//! `jetpipe diagnose` on bad files: a clear error naming row and column, a non-zero exit,
//! and no report written (an existing report is left as it was).

use std::path::Path;
use std::process::Command;

fn diagnose(dir: &Path, csv: &str) -> (bool, String) {
    let recording = dir.join("recording.csv");
    std::fs::write(&recording, csv).unwrap();
    let output = Command::new(env!("CARGO_BIN_EXE_jetpipe"))
        .args([
            "diagnose",
            recording.to_str().unwrap(),
            "--report",
            dir.join("report.json").to_str().unwrap(),
        ])
        .output()
        .expect("jetpipe runs");
    (
        output.status.success(),
        String::from_utf8_lossy(&output.stderr).into_owned(),
    )
}

#[test]
fn bad_recordings_are_refused_and_never_clobber_a_report() {
    let dir = std::env::temp_dir().join(format!("jetpipe-diagnose-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let report = dir.join("report.json");
    std::fs::write(&report, "previous report").unwrap();
    let header = "time_s,v_da_V,x_s_m,force_N\n";
    let cases: Vec<(String, &str)> = vec![
        (String::new(), "empty"),
        (
            "time_s,v_da_V,x_s_m,force\n0,1,0.054,2\n0.001,1,0.054,2\n".into(),
            "unknown column 'force'",
        ),
        (
            "time_s,v_da_V,force_N\n0,1,2\n0.001,1,2\n".into(),
            "missing column 'x_s_m'",
        ),
        (
            format!("{header}0,1,0.054,2\n0.001,one,0.054,2\n"),
            "row 3, column v_da_V",
        ),
        (
            format!("{header}0,1,0.054,2\n0.001,1,0.054,nan\n"),
            "row 3, column force_N",
        ),
        (
            format!("{header}0,1,0.054,2\n0.002,1,0.054,2\n0.001,1,0.054,2\n"),
            "row 4, column time_s",
        ),
        (format!("{header}0,1,0.054,2\n0.001,1,0.2,2\n"), "row 3, column x_s_m"),
        (format!("{header}0,1,54,2\n0.001,1,54,2\n"), "millimetres"),
    ];
    for (csv, expected) in cases {
        let (ok, stderr) = diagnose(&dir, &csv);
        assert!(!ok, "{expected}: exit status was success");
        assert!(stderr.contains(expected), "{expected}: stderr was {stderr}");
        assert_eq!(
            std::fs::read_to_string(&report).unwrap(),
            "previous report",
            "{expected}: report clobbered"
        );
    }
    let missing = Command::new(env!("CARGO_BIN_EXE_jetpipe"))
        .args([
            "diagnose",
            dir.join("nope.csv").to_str().unwrap(),
            "--report",
            report.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(!missing.status.success());
    assert!(String::from_utf8_lossy(&missing.stderr).contains("cannot read"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn fuzzed_csv_text_never_crashes_the_reader() {
    // Random mutations of a good file: every outcome is a recording or a message, never a
    // panic, and messages name a row or the file's shape.
    let good = "time_s,v_da_V,x_s_m,force_N,p1_Pa,p2_Pa\n0.000,1.0,0.054,10.0,300000,200000\n0.001,1.1,0.054,10.1,300100,200050\n0.002,1.2,0.0541,10.3,300300,200100\n";
    let alphabet: Vec<char> = "0123456789.,-+eE\n \tnaNinf\u{feff}x_".chars().collect();
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = |m: usize| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state % m as u64) as usize
    };
    let params = jetpipe_model::physics::parameters::Parameters::default();
    for _ in 0..5000 {
        let mut text: Vec<char> = good.chars().collect();
        for _ in 0..1 + next(6) {
            let at = next(text.len());
            match next(3) {
                0 => text[at] = alphabet[next(alphabet.len())],
                1 => {
                    text.remove(at);
                }
                _ => text.insert(at, alphabet[next(alphabet.len())]),
            }
        }
        let text: String = text.into_iter().collect();
        match std::panic::catch_unwind(|| jetpipe_diagnosis::input::recording::Recording::parse(&text, &params)) {
            Ok(Ok(recording)) => assert!(recording.len() >= 2),
            Ok(Err(message)) => assert!(
                message.contains("row")
                    || message.contains("samples")
                    || message.contains("empty")
                    || message.contains("column"),
                "unhelpful message {message:?} for {text:?}"
            ),
            Err(_) => panic!("the reader panicked on {text:?}"),
        }
    }
}

/// A clean synthetic recording of `seconds`, rows of (t, v, x_s, F, p1, p2).
fn clean_rows(seconds: f64) -> Vec<[f64; 6]> {
    synthetic_bench::generate(&synthetic_bench::BenchEffects::default(), 7, seconds)
}

fn csv(rows: &[[f64; 6]], map: impl Fn([f64; 6]) -> [f64; 6]) -> String {
    let mut text = String::from("time_s,v_da_V,x_s_m,force_N,p1_Pa,p2_Pa\n");
    for r in rows {
        let r = map(*r);
        text.push_str(&format!("{},{},{},{},{},{}\n", r[0], r[1], r[2], r[3], r[4], r[5]));
    }
    text
}

#[test]
fn wrong_units_and_a_too_short_recording_are_refused_naming_the_column_and_the_unit() {
    let dir = std::env::temp_dir().join(format!("jetpipe-diagnose-units-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let rows = clean_rows(20.0);
    let cases: Vec<(String, [&str; 2])> = vec![
        (
            csv(&rows, |r| [r[0], r[1], r[2], r[3] / 1000.0, r[4], r[5]]),
            ["force_N", "kilonewtons"],
        ),
        (
            csv(&rows, |r| [r[0], r[1], r[2], r[3] * 1000.0, r[4], r[5]]),
            ["force_N", "millinewtons"],
        ),
        (
            csv(&rows, |r| [r[0] * 1000.0, r[1], r[2], r[3], r[4], r[5]]),
            ["time_s", "milliseconds"],
        ),
        (
            csv(&rows, |r| [r[0], r[1], r[2], r[3], r[4] / 1000.0, r[5] / 1000.0]),
            ["p1_Pa", "kPa"],
        ),
        (
            csv(&rows, |r| [r[0], r[1], r[2], r[3], r[4] - 101_325.0, r[5] - 101_325.0]),
            ["Pa", "gauge"],
        ),
        (csv(&rows[..10], |r| r), ["at least 8 s", "10 samples"]),
    ];
    for (text, expected) in cases {
        let (ok, stderr) = diagnose(&dir, &text);
        assert!(!ok, "{expected:?}: accepted");
        for word in expected {
            assert!(stderr.contains(word), "{expected:?}: stderr was {stderr}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn irregular_sampling_goes_on_with_a_sentence_in_the_report() {
    let dir = std::env::temp_dir().join(format!("jetpipe-diagnose-irregular-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // Drop every 7th row of a clean recording: steps of 1 and 2 ms.
    let rows: Vec<[f64; 6]> = clean_rows(20.0)
        .into_iter()
        .enumerate()
        .filter(|(k, _)| k % 7 != 3)
        .map(|(_, r)| r)
        .collect();
    let (ok, stderr) = diagnose(&dir, &csv(&rows, |r| r));
    assert!(ok, "{stderr}");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("report.json")).unwrap()).unwrap();
    let checks = report["input_checks"].as_array().unwrap();
    assert!(
        checks.iter().any(|c| c.as_str().unwrap().contains("irregular")),
        "{checks:?}"
    );
    assert!(report["summary"]
        .as_array()
        .unwrap()
        .iter()
        .any(|l| l.as_str().unwrap().contains("irregular")));
    // Nothing was wrong with the actuator: the verdict says so and nothing is named.
    assert_eq!(report["verdict"], "explained", "{}", report["summary"]);
    assert_eq!(report["effects"].as_array().unwrap().len(), 0);
    let _ = std::fs::remove_dir_all(&dir);
}
