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
    let params = jetpipe::physics::parameters::Parameters::default();
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
        match std::panic::catch_unwind(|| jetpipe::recording::Recording::parse(&text, &params)) {
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
