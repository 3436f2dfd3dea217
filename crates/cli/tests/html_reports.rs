//! `jetpipe diagnose DIR --out OUT`, its pages rendered in a real browser.
//!
//! The recordings come from the synthetic bench (the independent simulator): one with a force
//! sensor offset and gain, the same without its pressure channels, one with the jet pipe's
//! static curve bent (a mechanism outside the named effects), and one file whose force is in
//! kN, which must be refused without stopping the others. Each page is rendered by headless Chromium (Debian's `chromium`, which
//! `scripts/install_chromium.sh` installs; `JETPIPE_CHROMIUM` may name another binary): the
//! rendered DOM must show the report's verdict and every figure, and a screenshot must show
//! the figures' series painted in their colours.

use std::path::{Path, PathBuf};
use std::process::Command;

use synthetic_bench::{generate, undeclared_mechanism, BenchEffects};

/// Seconds of the bench protocol each recording holds (segments A and B: the major loop and
/// the nested reversals).
const DURATION: f64 = 24.0;

fn chromium() -> PathBuf {
    if let Some(path) = std::env::var_os("JETPIPE_CHROMIUM") {
        return PathBuf::from(path);
    }
    let found = std::env::var_os("PATH").and_then(|paths| {
        std::env::split_paths(&paths)
            .map(|dir| dir.join("chromium"))
            .find(|candidate| candidate.is_file())
    });
    found.unwrap_or_else(|| {
        panic!(
            "these tests render the diagnosis pages in Chromium, and no `chromium` is on PATH: \
             run `bash scripts/install_chromium.sh` (Debian's package), or set JETPIPE_CHROMIUM"
        )
    })
}

/// Chromium run headless on `page`, with no network service it would start on its own, in a
/// profile of its own; `mode` is `--dump-dom` or `--screenshot=FILE`.
fn render(page: &Path, profile: &Path, mode: &str) -> String {
    let output = Command::new(chromium())
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--window-size=1000,7000",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg(mode)
        .arg(format!("file://{}", page.display()))
        .output()
        .expect("chromium runs");
    assert!(
        output.status.success(),
        "chromium failed on {}: {}",
        page.display(),
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8_lossy(&output.stdout).into_owned()
}

/// Pixels of a PNG (RGBA or RGB, 8 bits) whose colour is within 40 of `colour` in every channel.
fn pixels_near(png_path: &Path, colour: [u8; 3]) -> usize {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(png_path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buffer = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buffer).unwrap();
    let channels = info.color_type.samples();
    assert_eq!(info.bit_depth, png::BitDepth::Eight);
    buffer[..info.buffer_size()]
        .chunks(channels)
        .filter(|p| (0..3).all(|c| (p[c] as i32 - colour[c] as i32).abs() <= 40))
        .count()
}

fn write_recording(dir: &Path, name: &str, effects: &BenchEffects, seed: u64) {
    synthetic_bench::write_csv(&generate(effects, seed, DURATION), dir.join(name)).unwrap();
}

#[test]
fn a_directory_of_recordings_becomes_pages_that_chromium_renders_with_their_verdicts_and_figures() {
    let root = std::env::temp_dir().join(format!("jetpipe-html-reports-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    let (recordings, out) = (root.join("recordings"), root.join("out"));
    std::fs::create_dir_all(recordings.join("hand")).unwrap();
    let sensor = BenchEffects {
        force_sensor_offset: 1.5,
        force_sensor_gain: 1.04,
        ..BenchEffects::default()
    };
    write_recording(&recordings, "sensor.csv", &sensor, 1);
    let curve = (undeclared_mechanism("jet_pipe_curve").unwrap().effects)();
    write_recording(&recordings.join("hand"), "curve.csv", &curve, 2);
    // The sensor recording with its force written in kN: refused, the others go on.
    let text = std::fs::read_to_string(recordings.join("sensor.csv")).unwrap();
    let kilonewtons: String = text
        .lines()
        .enumerate()
        .map(|(k, line)| {
            if k == 0 {
                return format!("{line}\n");
            }
            let mut fields: Vec<String> = line.split(',').map(str::to_string).collect();
            fields[3] = format!("{:.7}", fields[3].parse::<f64>().unwrap() / 1000.0);
            fields.join(",") + "\n"
        })
        .collect();
    std::fs::write(recordings.join("kilonewtons.csv"), kilonewtons).unwrap();
    // The sensor recording without its pressure channels: a page without the pressures' figure.
    let force_only: String = text
        .lines()
        .map(|line| line.split(',').take(4).collect::<Vec<_>>().join(",") + "\n")
        .collect();
    std::fs::write(recordings.join("hand").join("force_only.csv"), force_only).unwrap();

    let run = Command::new(env!("CARGO_BIN_EXE_jetpipe"))
        .args(["diagnose", recordings.to_str().unwrap(), "--out", out.to_str().unwrap()])
        .args(["--jobs", "2"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success(), "a refused recording makes the batch fail");
    assert!(
        stderr.contains("1 of 4 recordings could not be diagnosed (kilonewtons)"),
        "{stderr}"
    );

    let mut summary = csv::Reader::from_path(out.join("summary.csv")).unwrap();
    let headers = summary.headers().unwrap().clone();
    let column = |name: &str| headers.iter().position(|h| h == name).unwrap();
    let rows: Vec<csv::StringRecord> = summary.records().map(Result::unwrap).collect();
    let names: Vec<&str> = rows.iter().map(|r| &r[column("recording")]).collect();
    assert_eq!(names, ["hand-curve", "hand-force_only", "kilonewtons", "sensor"]);
    assert_eq!(&rows[2][column("verdict")], "error");
    assert!(rows[2][column("error")].contains("force_N"), "{:?}", rows[2]);

    let profile = root.join("chromium-profile");
    for row in [&rows[0], &rows[1], &rows[3]] {
        let name = &row[column("recording")];
        let report: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join(&row[column("report")])).unwrap()).unwrap();
        assert_eq!(report["verdict"].as_str().unwrap(), &row[column("verdict")]);
        let page = out.join(&row[column("page")]);
        let html = std::fs::read_to_string(&page).unwrap();
        for loader in [
            "<script",
            "<link",
            "<img",
            "<iframe",
            "@import",
            "url(",
            "src=",
            "href=\"http",
        ] {
            assert!(!html.contains(loader), "{name}: the page loads something ({loader})");
        }

        let dom = render(&page, &profile, "--dump-dom");
        let words = match report["verdict"].as_str().unwrap() {
            "explained" => "explained</span>",
            _ => "not explained: a remainder stays</span>",
        };
        assert!(
            dom.contains(words),
            "{name}: the rendered page does not show its verdict"
        );
        let first_summary = report["summary"][0].as_str().unwrap().replace('&', "&amp;");
        assert!(dom.contains(&first_summary[..40]), "{name}: no verdict sentence");
        // Figures: force, residual in time, residual against a signal, loops, the pressures when
        // the recording has them, and the static curve of the term added at the force sensor or
        // on the command path.
        let has_pressures = report["pressure_split"]["available"] == true;
        let added_static_curve = report["effects"]
            .as_array()
            .unwrap()
            .iter()
            .any(|e| e["location"] == "force_sensor")
            || report["discovered"].as_array().unwrap().iter().any(|d| {
                d["family"] == "nonlinearity" && matches!(d["location"].as_str(), Some("force_sensor" | "jet_pipe"))
            });
        let figures = dom.matches("<figure").count();
        assert_eq!(dom.matches("<svg").count(), figures, "{name}: a figure without its SVG");
        assert_eq!(
            figures,
            4 + usize::from(has_pressures) + usize::from(added_static_curve),
            "{name}: {figures} figures"
        );
        for figure in [
            "figure-force_over_time",
            "figure-residual_over_time",
            "figure-residual_against_signal",
            "figure-force_against_command",
        ] {
            assert!(dom.contains(figure), "{name}: no {figure}");
        }
        assert_eq!(dom.contains("figure-pressures_over_time"), has_pressures, "{name}");

        let screenshot = root.join(format!("{name}.png"));
        render(&page, &profile, &format!("--screenshot={}", screenshot.display()));
        // The series' colours, as painted: the model before (red), after (blue).
        let red = pixels_near(&screenshot, [214, 39, 40]);
        let blue = pixels_near(&screenshot, [31, 119, 180]);
        assert!(red > 5000 && blue > 5000, "{name}: red {red}, blue {blue} pixels");
    }
    // Each recording the test made was given its term: the sensor's named, the curve's found.
    let sensor: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("sensor.json")).unwrap()).unwrap();
    assert_eq!(
        sensor["effects"][0]["name"], "sensor_offset_gain",
        "{}",
        sensor["summary"]
    );
    let curve: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("hand-curve.json")).unwrap()).unwrap();
    assert_eq!(curve["discovered"][0]["location"], "jet_pipe", "{}", curve["summary"]);

    let index = render(&out.join("index.html"), &profile, "--dump-dom");
    assert_eq!(sensor["pressure_split"]["available"], true);
    let force_only: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("hand-force_only.json")).unwrap()).unwrap();
    assert_eq!(force_only["pressure_split"]["available"], false);
    for page in ["hand-curve.html", "hand-force_only.html", "sensor.html"] {
        assert!(
            index.contains(&format!("href=\"{page}\"")),
            "the index does not link {page}"
        );
    }
    let explained = rows.iter().filter(|r| &r[column("verdict")] == "explained").count();
    assert!(
        index.contains(&format!("{explained} explained")) && index.contains("1 failed"),
        "{index}"
    );
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn one_recording_with_report_and_out_together_is_refused_by_name() {
    let output = Command::new(env!("CARGO_BIN_EXE_jetpipe"))
        .args(["diagnose", "a.csv", "--report", "r.json", "--out", "dir"])
        .output()
        .unwrap();
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("--report") && stderr.contains("--out"), "{stderr}");
    let two = Command::new(env!("CARGO_BIN_EXE_jetpipe"))
        .args(["diagnose", "a.csv", "b.csv", "--report", "r.json"])
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&two.stderr).contains("--report takes one recording, got 2"));
    let without_out = Command::new(env!("CARGO_BIN_EXE_jetpipe"))
        .args(["diagnose", "a.csv", "b.csv"])
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&without_out.stderr).contains("2 recordings without --out"));
}

/// The shipped example recording the demo diagnoses first (examples/recordings/README.md).
fn example_recording(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/recordings")
        .join(name)
}

#[test]
fn one_recording_with_a_report_path_gets_its_page_beside_the_report_and_chromium_renders_it() {
    let root = std::env::temp_dir().join(format!("jetpipe-one-page-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    std::fs::create_dir_all(root.join("reports")).unwrap();
    let recording = example_recording("hysteresis.csv");
    let report_path = root.join("reports").join("r.json");
    let run = Command::new(env!("CARGO_BIN_EXE_jetpipe"))
        .args(["diagnose", recording.to_str().unwrap(), "--jobs", "2"])
        .args(["--report", report_path.to_str().unwrap()])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let page = root.join("reports").join("r.html");
    assert!(stdout.contains(&format!("page: {}", page.display())), "{stdout}");
    let report: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report_path).unwrap()).unwrap();
    // What examples/recordings/README.md says the demo finds in this recording.
    assert_eq!(report["verdict"], "explained", "{}", report["summary"]);
    assert_eq!(
        report["effects"][0]["name"], "jet_pipe_hysteresis",
        "{}",
        report["summary"]
    );

    let html = std::fs::read_to_string(&page).unwrap();
    assert!(html.contains("href=\"r.json\""), "the page does not link its report");
    assert!(
        !html.contains("index.html"),
        "a page of one recording links an index that does not exist"
    );
    let dom = render(&page, &root.join("chromium-profile"), "--dump-dom");
    assert!(
        dom.contains("explained</span>"),
        "the rendered page does not show its verdict"
    );
    assert!(
        dom.contains("jet_pipe_hysteresis"),
        "the rendered page does not name the effect added"
    );
    for figure in [
        "figure-force_over_time",
        "figure-force_against_command",
        "figure-pressures_over_time",
    ] {
        assert!(dom.contains(figure), "no {figure}");
    }
    // How sure: the hysteresis width's 95 % interval holds its value, the rendered table has
    // the interval column, and the page says by how much the jet pipe won its place.
    let effect = &report["effects"][0];
    let width = effect["parameters"]["hysteresis_width"].as_f64().unwrap();
    let interval = &effect["intervals_95"]["hysteresis_width"];
    assert!(
        interval[0].as_f64().unwrap() < width && width < interval[1].as_f64().unwrap(),
        "{width} outside {interval}"
    );
    assert!(
        dom.contains("<th>95 % interval</th>"),
        "the rendered page has no interval column"
    );
    assert!(
        effect["margin_noise_floors"].as_f64().unwrap() > 0.0 && dom.contains("Its place won by a margin of"),
        "margin {} not shown as a win",
        effect["margin_noise_floors"]
    );
    let screenshot = root.join("r.png");
    render(
        &page,
        &root.join("chromium-profile"),
        &format!("--screenshot={}", screenshot.display()),
    );
    let blue = pixels_near(&screenshot, [31, 119, 180]);
    assert!(
        blue > 5000,
        "the model with the hysteresis is not painted: {blue} blue pixels"
    );
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn a_report_named_html_is_refused_before_any_work_since_its_page_would_overwrite_it() {
    let output = Command::new(env!("CARGO_BIN_EXE_jetpipe"))
        .args(["diagnose", example_recording("hysteresis.csv").to_str().unwrap()])
        .args(["--report", "r.html"])
        .output()
        .unwrap();
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("--report r.html") && stderr.contains("--no-html"),
        "{stderr}"
    );
    assert!(!Path::new("r.html").exists());
}

#[test]
fn without_a_report_path_the_report_is_named_after_the_recording_in_the_current_directory_and_no_html_leaves_the_page_out(
) {
    let root = std::env::temp_dir().join(format!("jetpipe-no-html-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    std::fs::create_dir_all(root.join("work")).unwrap();
    // A clean recording: the thesis model explains it at once.
    write_recording(&root, "clean.csv", &BenchEffects::default(), 3);
    let run = Command::new(env!("CARGO_BIN_EXE_jetpipe"))
        .current_dir(root.join("work"))
        .args(["diagnose", root.join("clean.csv").to_str().unwrap(), "--no-html"])
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    assert!(String::from_utf8_lossy(&run.stdout).contains("report: clean.json"));
    assert!(root.join("work").join("clean.json").is_file());
    assert!(!root.join("work").join("clean.html").exists(), "--no-html wrote a page");
    let _ = std::fs::remove_dir_all(&root);
}
