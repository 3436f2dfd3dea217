//! `jetpipe diagnose A.csv B.csv DIR --out OUT`: many recordings, spread over `--jobs` cores.
//!
//! For each recording it writes `OUT/NAME.json` (the report of `--report`) and `OUT/NAME.html`
//! (its page, [`crate::html_report`]); then `OUT/summary.csv` (a row per recording) and
//! `OUT/index.html` (the same table, linking the pages). A directory stands for the `.csv` files
//! in it and in its subdirectories; a recording found under a subdirectory is named by its path
//! from the directory, `/` written `-` (`undeclared/u_null4.csv` is `undeclared-u_null4`).
//! A recording that cannot be diagnosed gets a row with its error; the others go on.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

use jetpipe_diagnosis::input::recording::Recording;
use jetpipe_model::physics::parameters::Parameters;

use crate::html_report::{self, SummaryRow};
use crate::output::write_atomically;
use crate::plots::{diagnosis_figures, FigureInputs};

/// A recording of a batch and the name its files take.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Item {
    pub name: String,
    pub path: PathBuf,
}

/// What a batch is asked to do.
pub struct BatchOptions {
    pub inputs: Vec<PathBuf>,
    pub out: PathBuf,
    /// The parameters every diagnosis starts from (the thesis's, or `--params`).
    pub base: Parameters,
    pub calibrate: bool,
    /// Try a flexible term where the readable ones leave a channel above its bar.
    pub flexible: bool,
    /// Cores to use in all: recordings run side by side, and a recording's candidate fits
    /// share what is left over.
    pub jobs: usize,
}

/// The `.csv` files under `dir`, sorted, with their paths relative to it.
fn csv_files_under(dir: &Path, relative: &Path, found: &mut Vec<(PathBuf, PathBuf)>) -> Result<(), String> {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| format!("cannot read the directory {}: {e}", dir.display()))?
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .collect();
    entries.sort();
    for path in entries {
        let Some(file_name) = path.file_name().map(PathBuf::from) else {
            continue;
        };
        if path.is_dir() {
            csv_files_under(&path, &relative.join(&file_name), found)?;
        } else if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("csv")) {
            found.push((path.clone(), relative.join(file_name)));
        }
    }
    Ok(())
}

/// The recordings the inputs stand for, each with a file name of its own.
pub fn collect_recordings(inputs: &[PathBuf]) -> Result<Vec<Item>, String> {
    let mut items: Vec<Item> = vec![];
    for input in inputs {
        let found = if input.is_dir() {
            let mut found = vec![];
            csv_files_under(input, Path::new(""), &mut found)?;
            if found.is_empty() {
                return Err(format!("{}: the directory holds no .csv recording", input.display()));
            }
            found
        } else if input.is_file() {
            let name = input.file_name().map(PathBuf::from).unwrap_or_default();
            vec![(input.clone(), name)]
        } else {
            return Err(format!("cannot read {}: no such file or directory", input.display()));
        };
        for (path, relative) in found {
            let name = relative
                .with_extension("")
                .components()
                .map(|c| c.as_os_str().to_string_lossy().into_owned())
                .collect::<Vec<_>>()
                .join("-");
            if let Some(other) = items.iter().find(|i| i.name == name) {
                return Err(format!(
                    "{} and {} would both be written as {name}.json and {name}.html: diagnose them into \
                     different --out directories",
                    other.path.display(),
                    path.display()
                ));
            }
            items.push(Item { name, path });
        }
    }
    Ok(items)
}

/// Diagnose one recording and write its report and page; its summary row.
fn diagnose_one(item: &Item, options: &BatchOptions, jobs: usize) -> Result<SummaryRow, String> {
    let recording = Recording::read(&item.path, &options.base)?;
    let diagnosis_options = jetpipe_diagnosis::Options {
        calibrate: options.calibrate,
        jobs,
        bars: None,
        flexible: options.flexible,
    };
    // The diagnosis keeps the recording; the figures read it again once the report is written.
    let diagnosis = jetpipe_diagnosis::diagnose_owned(recording, &options.base, &diagnosis_options, &mut |_| {})?;
    let report = diagnosis.to_json(&item.name);
    let (report_file, page_file) = (format!("{}.json", item.name), format!("{}.html", item.name));
    let text = serde_json::to_string_pretty(&report).map_err(|e| e.to_string())? + "\n";
    // The report first: should the figures fail, the diagnosis is not lost with them.
    write_atomically(&options.out.join(&report_file), &text)?;
    let recording = Recording::read(&item.path, &options.base)
        .map_err(|e| format!("{e} (the report {report_file} was written)"))?;
    let figures = diagnosis_figures(&FigureInputs {
        recording: &recording,
        diagnosis: &diagnosis,
        base: &options.base,
    })
    .map_err(|e| format!("{e} (the report {report_file} was written)"))?;
    let page = html_report::page(&item.name, &report, &figures, &report_file, Some("index.html"));
    write_atomically(&options.out.join(&page_file), &page)?;
    Ok(SummaryRow::from_report(&item.name, &report, &page_file, &report_file))
}

/// `summary.csv`: a row per recording.
pub fn summary_csv(rows: &[SummaryRow]) -> Result<String, String> {
    let mut writer = csv::Writer::from_writer(vec![]);
    let fail = |e: csv::Error| format!("cannot write summary.csv: {e}");
    writer
        .write_record([
            "recording",
            "verdict",
            "noise_floor_N",
            "heldout_before_rms_N",
            "heldout_after_rms_N",
            "whole_before_rms_N",
            "whole_after_rms_N",
            "added",
            "remainder_location",
            "page",
            "report",
            "error",
        ])
        .map_err(fail)?;
    let number = |x: Option<f64>| x.map_or_else(String::new, |v| format!("{v:.6}"));
    for r in rows {
        writer
            .write_record([
                r.name.clone(),
                r.verdict.clone(),
                number(r.noise_floor_n),
                number(r.heldout_before_n),
                number(r.heldout_after_n),
                number(r.whole_before_n),
                number(r.whole_after_n),
                r.added.clone(),
                r.remainder_location.clone(),
                r.page.clone(),
                r.report.clone(),
                r.error.clone(),
            ])
            .map_err(fail)?;
    }
    let bytes = writer
        .into_inner()
        .map_err(|e| format!("cannot write summary.csv: {e}"))?;
    String::from_utf8(bytes).map_err(|e| format!("cannot write summary.csv: {e}"))
}

/// Run the batch: every recording's report and page, then `summary.csv` and `index.html`.
/// `log` gets a line as each recording finishes (from the worker threads). The rows come back
/// in the order of the inputs; a recording that failed has verdict `error`.
pub fn run(options: &BatchOptions, log: &(dyn Fn(&str) + Sync)) -> Result<Vec<SummaryRow>, String> {
    if options.jobs == 0 {
        return Err("--jobs 0 is invalid: must be at least 1".to_string());
    }
    let items = collect_recordings(&options.inputs)?;
    if items.is_empty() {
        return Err("no recording to diagnose".to_string());
    }
    std::fs::create_dir_all(&options.out).map_err(|e| format!("cannot create {}: {e}", options.out.display()))?;
    let started = Instant::now();
    let workers = options.jobs.min(items.len());
    let inner_jobs = (options.jobs / workers).max(1);
    let next = AtomicUsize::new(0);
    let rows: Mutex<Vec<Option<SummaryRow>>> = Mutex::new(vec![None; items.len()]);
    std::thread::scope(|scope| {
        for _ in 0..workers {
            scope.spawn(|| loop {
                let k = next.fetch_add(1, Ordering::SeqCst);
                let Some(item) = items.get(k) else { break };
                let began = Instant::now();
                // A panic in one diagnosis is that recording's error, not the batch's end.
                let outcome =
                    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| diagnose_one(item, options, inner_jobs)))
                        .unwrap_or_else(|_| Err("the diagnosis panicked".to_string()));
                let row = match outcome {
                    Ok(row) => {
                        log(&format!(
                            "[{:6.1} s] {}: {}, held-out force error {:.4} N → {:.4} N ({:.1} s)",
                            started.elapsed().as_secs_f64(),
                            item.name,
                            row.verdict,
                            row.heldout_before_n.unwrap_or(f64::NAN),
                            row.heldout_after_n.unwrap_or(f64::NAN),
                            began.elapsed().as_secs_f64()
                        ));
                        row
                    }
                    Err(e) => {
                        log(&format!(
                            "[{:6.1} s] {}: error: {e}",
                            started.elapsed().as_secs_f64(),
                            item.name
                        ));
                        SummaryRow::failed(&item.name, &e)
                    }
                };
                if let Ok(mut rows) = rows.lock() {
                    rows[k] = Some(row);
                }
            });
        }
    });
    let rows: Vec<SummaryRow> = rows
        .into_inner()
        .map_err(|_| "a worker thread failed".to_string())?
        .into_iter()
        .zip(&items)
        .map(|(row, item)| row.unwrap_or_else(|| SummaryRow::failed(&item.name, "not diagnosed")))
        .collect();
    let timing = format!(
        "{:.1} s wall with {} jobs",
        started.elapsed().as_secs_f64(),
        options.jobs
    );
    write_summary_and_index(&options.out, &rows, &timing)?;
    Ok(rows)
}

/// `DIR/summary.csv` and `DIR/index.html` of these rows; `timing` says how long they took.
fn write_summary_and_index(dir: &Path, rows: &[SummaryRow], timing: &str) -> Result<(), String> {
    write_atomically(&dir.join("summary.csv"), &summary_csv(rows)?)?;
    write_atomically(&dir.join("index.html"), &html_report::index(rows, timing))
}

/// The file a recording's error is written to when it was diagnosed elsewhere (the Dask
/// example writes it, [`index_directory`] reads it).
pub const ERROR_SUFFIX: &str = ".error.txt";

/// `summary.csv` and `index.html` of the reports already in `dir`: every `NAME.json` that is a
/// diagnosis report (with `NAME.html` beside it, linked when present) and every
/// `NAME.error.txt` (a recording that could not be diagnosed, the file holding why). For
/// reports written elsewhere, e.g. by the workers of `examples/dask_diagnose.py`.
pub fn index_directory(dir: &Path, timing: &str) -> Result<Vec<SummaryRow>, String> {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| format!("cannot read the directory {}: {e}", dir.display()))?
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .collect();
    paths.sort();
    let mut rows = vec![];
    for path in paths {
        let file_name = path
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
        if let Some(name) = file_name.strip_suffix(ERROR_SUFFIX) {
            let error = std::fs::read_to_string(&path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
            rows.push(SummaryRow::failed(name, error.trim()));
        } else if let Some(name) = file_name.strip_suffix(".json") {
            let text = std::fs::read_to_string(&path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
            let report: serde_json::Value =
                serde_json::from_str(&text).map_err(|e| format!("{}: not valid JSON: {e}", path.display()))?;
            if report.get("verdict").is_none() || report.get("heldout").is_none() {
                continue;
            }
            let page = format!("{name}.html");
            let page = if dir.join(&page).is_file() { page } else { String::new() };
            rows.push(SummaryRow::from_report(name, &report, &page, &file_name));
        }
    }
    if rows.is_empty() {
        return Err(format!("{}: no diagnosis report (NAME.json) in it", dir.display()));
    }
    write_summary_and_index(dir, &rows, timing)?;
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_directory_stands_for_its_csv_files_named_by_their_relative_paths() {
        let dir = std::env::temp_dir().join(format!("jetpipe-batch-collect-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("undeclared")).unwrap();
        for file in ["rec_02.csv", "rec_01.csv", "README.md", "undeclared/u_null4.csv"] {
            std::fs::write(dir.join(file), "").unwrap();
        }
        let items = collect_recordings(std::slice::from_ref(&dir)).unwrap();
        let names: Vec<&str> = items.iter().map(|i| i.name.as_str()).collect();
        assert_eq!(names, ["rec_01", "rec_02", "undeclared-u_null4"]);
        let twice = collect_recordings(&[dir.clone(), dir.join("rec_01.csv")]).unwrap_err();
        assert!(twice.contains("rec_01.json"), "{twice}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn the_summary_quotes_a_field_holding_a_comma() {
        let row = SummaryRow {
            name: "a".into(),
            verdict: "error".into(),
            error: "row 3, column force_N: not a number".into(),
            ..SummaryRow::default()
        };
        let text = summary_csv(&[row]).unwrap();
        let mut reader = csv::Reader::from_reader(text.as_bytes());
        let record = reader.records().next().unwrap().unwrap();
        assert_eq!(&record[11], "row 3, column force_N: not a number");
        assert_eq!(reader.headers().unwrap().len(), 12);
    }
}
