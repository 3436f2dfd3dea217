//! `jetpipe`: package the FMU, print its model description, run the standard scenario,
//! sweep parameters over it.
//! It drives the same library as the FMU; there is no second copy of the model.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use clap::{Parser, Subcommand};
use jetpipe_model::physics::actuator::Actuator;
use jetpipe_model::physics::parameters::Parameters;
use jetpipe_model::scenario;
use jetpipe_model::simulation::{Simulation, DEFAULT_RELATIVE_TOLERANCE};

#[derive(Parser)]
#[command(
    name = "jetpipe",
    version,
    about = "Jet-pipe electropneumatic actuator (Henri 1994) as an FMI 2.0 FMU"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Write dist/JetPipeActuator.fmu (FMI 2.0) and dist/JetPipeActuator-fmi3.fmu (FMI 3.0): model
    /// description, linux64 and optionally win64 binaries (the same library in both), documentation.
    Package {
        #[arg(long, default_value = "dist/JetPipeActuator.fmu")]
        out: PathBuf,
        /// Where the FMI 3.0 archive goes.
        #[arg(long, default_value = "dist/JetPipeActuator-fmi3.fmu")]
        out_fmi3: PathBuf,
        /// The compiled linux64 shared library; by default libjetpipe.so next to this executable.
        #[arg(long)]
        library: Option<PathBuf>,
        /// A win64 DLL of the same library, packaged as binaries/win64/JetPipeActuator.dll.
        #[arg(long)]
        win64: Option<PathBuf>,
    },
    /// Print the model description generated from the variable table.
    ModelDescription {
        /// The FMI 3.0 model description instead of the FMI 2.0 one.
        #[arg(long)]
        fmi3: bool,
    },
    /// Print every variable with its unit, start value, limits, thesis reference and meaning
    /// (the Markdown table of docs/model.md, from the variable table).
    Parameters,
    /// Linearise at the equilibrium with the given force (§4.2.2): A, B, C, D, poles, zeros.
    Linearize {
        /// Actuator force of the operating point, N.
        #[arg(long, default_value_t = 45.0)]
        force: f64,
        /// Stopper position of the operating point, m.
        #[arg(long = "x-s", default_value_t = 0.054)]
        x_s: f64,
        /// Print JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
    /// Compare bench recordings with the model, find the effects they lack, report before/after.
    ///
    /// One recording: `diagnose REC.csv` writes REC.json and its page REC.html in the current
    /// directory (`--report r.json` writes r.json and r.html). Many: `diagnose A.csv B.csv DIR --out OUT`
    /// writes OUT/NAME.json and OUT/NAME.html per recording, OUT/summary.csv and OUT/index.html.
    Diagnose {
        /// The recordings (CSV: time_s, v_da_V, x_s_m, force_N[, p1_Pa, p2_Pa]); with --out, also
        /// directories, which stand for the .csv files in them and their subdirectories.
        #[arg(required = true, num_args = 1..)]
        recordings: Vec<PathBuf>,
        /// Where to write the JSON report of the one recording (written only if the diagnosis
        /// succeeds); its page goes beside it with the extension .html. Default: the
        /// recording's name with .json, in the current directory.
        #[arg(long, conflicts_with = "out")]
        report: Option<PathBuf>,
        /// Write no HTML page beside the one recording's report.
        #[arg(long = "no-html", conflicts_with = "out")]
        no_html: bool,
        /// Directory for each recording's JSON report and HTML page, summary.csv and index.html.
        #[arg(long)]
        out: Option<PathBuf>,
        /// JSON object of FMU parameter values to start from instead of the thesis's.
        #[arg(long)]
        params: Option<PathBuf>,
        /// Re-identify jet pipe offset, C_d and leakage (§3.3.1) first.
        #[arg(long)]
        calibrate: bool,
        /// Where the readable terms leave a channel above its bar, try a flexible term (a smooth
        /// function of one or two signals, with memory) in their place or beside them.
        #[arg(long)]
        flexible: bool,
        /// Directory for the SVG figures of the one recording (with --out they are in the pages).
        #[arg(long, conflicts_with = "out")]
        plots: Option<PathBuf>,
        /// Cores to use (default: every core this process may use): with --out, recordings are
        /// diagnosed side by side on them; with one recording, its candidate fits.
        #[arg(long)]
        jobs: Option<usize>,
        /// The recordings are of one actuator: diagnose them together, one model for all
        /// (one report, default NAME_joint.json after the first; with each recording's errors).
        #[arg(long, conflicts_with = "out")]
        joint: bool,
    },
    /// What to record next: from a diagnosis report that ties places or leaves a remainder,
    /// a protocol (time_s, v_da_V, x_s_m) on which its leading explanations differ most,
    /// within what a bench can play (±10 V, the stopper within 35–90 mm at most 200 mm/s).
    /// Writes OUT, and beside it OUT's name with .json and .html: the explanations it
    /// separates and their predicted differences in noise floors.
    Propose {
        /// A report of `jetpipe diagnose` (JSON).
        report: PathBuf,
        /// The protocol's CSV file.
        #[arg(long)]
        out: PathBuf,
        /// Its length, s (5–120).
        #[arg(long, default_value_t = 40.0)]
        seconds: f64,
        /// Its sampling rate, Hz (250–4000).
        #[arg(long, default_value_t = 1000.0)]
        rate: f64,
        /// Seed of the random draws the design picks from (the same seed, the same protocol).
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Cores to use (default: every core this process may use).
        #[arg(long)]
        jobs: Option<usize>,
    },
    /// Write DIR/summary.csv and DIR/index.html from the diagnosis reports in DIR (NAME.json,
    /// with NAME.html beside it; NAME.error.txt for a recording that could not be diagnosed),
    /// e.g. reports written on a cluster by examples/dask_diagnose.py.
    DiagnosisIndex {
        dir: PathBuf,
        /// How long the diagnoses took, for the index page (e.g. "212 s on 4 workers").
        #[arg(long, default_value = "")]
        timing: String,
    },
    /// Run the standard scenario in-process and print a summary.
    Simulate {
        /// Communication step in seconds.
        #[arg(long, default_value_t = 0.01)]
        step: f64,
        /// Relative tolerance of the integrator.
        #[arg(long, default_value_t = DEFAULT_RELATIVE_TOLERANCE)]
        tolerance: f64,
        /// Write time and outputs every 10 ms to this CSV file.
        #[arg(long)]
        csv: Option<PathBuf>,
    },
    /// Run the standard scenario for every point of a parameter grid on all cores; write one
    /// CSV row per run and print the speed-up over one thread.
    Sweep {
        /// NAME=START:STOP:N (N evenly spaced values), NAME=V1,V2,... or NAME=V, with NAME a
        /// parameter of the FMU (e.g. C_d, P_s; `jetpipe parameters` lists them with their
        /// limits, which every value must keep). Several --param give their Cartesian product.
        #[arg(long = "param", value_name = "NAME=VALUES", required = true)]
        params: Vec<String>,
        /// Worker threads (default: every core this process may use).
        #[arg(long)]
        threads: Option<usize>,
        /// The CSV file to write.
        #[arg(long, default_value = "sweep.csv")]
        out: PathBuf,
        /// Simulated seconds of the standard scenario (a multiple of 10 ms; default all 10 s).
        #[arg(long, default_value_t = scenario::DURATION)]
        duration: f64,
        /// Communication step in seconds (divides 10 ms).
        #[arg(long, default_value_t = scenario::SAMPLE_PERIOD)]
        step: f64,
        /// Relative tolerance of the integrator.
        #[arg(long, default_value_t = DEFAULT_RELATIVE_TOLERANCE)]
        tolerance: f64,
        /// JSON object of FMU parameter values the grid starts from instead of the thesis's.
        #[arg(long)]
        base_params: Option<PathBuf>,
        /// Time every run on one thread too (default: an evenly spaced subset of the runs).
        #[arg(long, conflicts_with = "no_serial")]
        compare_serial: bool,
        /// Skip the one-thread reference run (no speed-up is printed).
        #[arg(long)]
        no_serial: bool,
    },
}

/// Allocations of 256 KiB and more get pages of their own, returned to the system when freed.
///
/// The diagnosis allocates and frees thousands of series (a replay's outputs, a sensitivity, a
/// Gauss–Newton column) from several threads. glibc's default threshold grows to the largest
/// block freed (up to 32 MiB), after which such series come from the threads' heaps, where
/// freed space stays resident: a 600 s recording at 1 kHz peaked at 287 MB of resident memory,
/// and at 196–215 MB (two runs) with the threshold fixed at 1 MiB. The fits' series of 100,000
/// rows (400 KB in single precision, 800 KB in double) fall below 1 MiB: with it, the shared
/// sensitivities the first pass let go of stayed resident through the final replays, and the
/// 600 s recording peaked there at 251 MB (239 s); at 256 KiB, at 219 MB in two runs (238 and
/// 256 s, within the machine's spread; the system time spent on pages roughly doubles).
fn keep_large_allocations_apart() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt only sets an allocator parameter; it is called before any thread starts.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 1 << 18);
    }
}

/// A reader that closes the output early (`jetpipe diagnose r.csv | head`) ends the program
/// as it ends other Unix tools, without a panic's message: Rust ignores SIGPIPE, and a
/// `println!` to a closed pipe then panics.
fn end_quietly_on_a_closed_pipe() {
    #[cfg(unix)]
    // SAFETY: restores the default disposition of one signal before any thread starts.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

fn main() -> ExitCode {
    keep_large_allocations_apart();
    end_quietly_on_a_closed_pipe();
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("jetpipe: error: {message}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<(), String> {
    match cli.command {
        Command::Package {
            out,
            out_fmi3,
            library,
            win64,
        } => {
            let library = match library {
                Some(path) => path,
                None => build_shared_library()?,
            };
            let mut binaries = vec![("linux64", library.as_path())];
            if let Some(dll) = &win64 {
                binaries.push(("win64", dll.as_path()));
            }
            jetpipe_packaging::write_fmu_platforms(&out, &binaries)?;
            println!("wrote {}", out.display());
            let binaries3: Vec<(&str, &std::path::Path)> = binaries
                .iter()
                .map(|&(platform, path)| {
                    (
                        if platform == "win64" {
                            "x86_64-windows"
                        } else {
                            "x86_64-linux"
                        },
                        path,
                    )
                })
                .collect();
            jetpipe_packaging::write_fmu3_platforms(&out_fmi3, &binaries3)?;
            println!("wrote {}", out_fmi3.display());
            Ok(())
        }
        Command::ModelDescription { fmi3 } => {
            if fmi3 {
                print!("{}", jetpipe_packaging::actuator_model_description_fmi3());
            } else {
                print!("{}", jetpipe_packaging::actuator_model_description());
            }
            Ok(())
        }
        Command::Parameters => {
            print!("{}", jetpipe_model::variables::interface_table());
            Ok(())
        }
        Command::Simulate { step, tolerance, csv } => simulate(step, tolerance, csv),
        Command::Propose {
            report,
            out,
            seconds,
            rate,
            seed,
            jobs,
        } => propose(&report, &out, seconds, rate, seed, jobs),
        Command::DiagnosisIndex { dir, timing } => {
            let rows = jetpipe_cli::batch::index_directory(&dir, &timing)?;
            println!(
                "{} recordings: {} and {}",
                rows.len(),
                dir.join("summary.csv").display(),
                dir.join("index.html").display()
            );
            Ok(())
        }
        Command::Sweep {
            params,
            threads,
            out,
            duration,
            step,
            tolerance,
            base_params,
            compare_serial,
            no_serial,
        } => {
            let options = jetpipe_cli::sweep::SweepOptions {
                params,
                threads,
                out,
                settings: jetpipe_cli::sweep::RunSettings {
                    duration,
                    step,
                    tolerance,
                },
                base: read_parameters(base_params.as_deref())?,
                compare_serial,
                no_serial,
            };
            jetpipe_cli::sweep::run_command(&options, &mut std::io::stdout().lock())
        }
        Command::Linearize { force, x_s, json } => linearize(force, x_s, json),
        Command::Diagnose {
            recordings,
            report,
            out,
            params,
            calibrate,
            flexible,
            plots,
            no_html,
            jobs,
            joint,
        } => match out {
            Some(out) => diagnose_batch(recordings, out, params.as_deref(), (calibrate, flexible), jobs),
            None if joint => {
                if let Some(dir) = recordings.iter().find(|r| r.is_dir()) {
                    return Err(format!(
                        "{} is a directory: --joint takes the recordings' files",
                        dir.display()
                    ));
                }
                let report = match report {
                    Some(report) => report,
                    None => default_report_path(&recordings[0]).map(|r| joint_report_path(&r))?,
                };
                let page = if no_html { None } else { Some(page_path(&report)?) };
                let destination = Destination {
                    report: &report,
                    page: page.as_deref(),
                    plots: plots.as_deref(),
                };
                diagnose_joint(
                    &recordings,
                    &destination,
                    params.as_deref(),
                    (calibrate, flexible),
                    jobs,
                )
            }
            None => {
                let [recording] = recordings.as_slice() else {
                    return Err(match report {
                        Some(_) => format!(
                            "--report takes one recording, got {}: give several with --out DIR",
                            recordings.len()
                        ),
                        None => format!(
                            "{} recordings without --out: give one recording, several with --out DIR, or several of one actuator with --joint",
                            recordings.len()
                        ),
                    });
                };
                if recording.is_dir() {
                    return Err(format!(
                        "{} is a directory: diagnose its recordings with --out DIR",
                        recording.display()
                    ));
                }
                let report = match report {
                    Some(report) => report,
                    None => default_report_path(recording)?,
                };
                let page = if no_html { None } else { Some(page_path(&report)?) };
                let destination = Destination {
                    report: &report,
                    page: page.as_deref(),
                    plots: plots.as_deref(),
                };
                diagnose(recording, &destination, params.as_deref(), (calibrate, flexible), jobs)
            }
        },
    }
}

/// `cargo run --bin jetpipe` builds the FMU crate (the root package) as a dependency only, and does
/// not put its cdylib next to this executable; the FMU needs it, so build it (a no-op when it
/// is up to date) with the same profile as this executable.
fn build_shared_library() -> Result<PathBuf, String> {
    let exe = std::env::current_exe().map_err(|e| format!("cannot locate this executable: {e}"))?;
    let library = exe.with_file_name("libjetpipe.so");
    let manifest = concat!(env!("CARGO_MANIFEST_DIR"), "/../../Cargo.toml");
    if std::path::Path::new(manifest).is_file() {
        let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_string());
        let mut command = std::process::Command::new(&cargo);
        command.args(["build", "--lib", "-p", "jetpipe-fmu", "--manifest-path", manifest]);
        if !cfg!(debug_assertions) {
            command.arg("--release");
        }
        // Put the library next to this executable, wherever the target directory is.
        if let Some(target_dir) = exe.parent().and_then(|p| p.parent()) {
            command.arg("--target-dir").arg(target_dir);
        }
        let status = command.status().map_err(|e| format!("cannot run {cargo}: {e}"))?;
        if !status.success() {
            return Err(format!("`{cargo} build --lib` failed ({status})"));
        }
    }
    Ok(library)
}

/// Parameters from a JSON object of FMU parameter names and values.
fn read_parameters(path: Option<&std::path::Path>) -> Result<Parameters, String> {
    let mut p = Parameters::default();
    let Some(path) = path else { return Ok(p) };
    let text = std::fs::read_to_string(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let value: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| format!("{}: not valid JSON: {e}", path.display()))?;
    let object = value
        .as_object()
        .ok_or_else(|| format!("{}: expected a JSON object of parameter values", path.display()))?;
    let mut start_state = vec![];
    for (name, v) in object {
        let variable = jetpipe_model::variables::VARIABLES
            .iter()
            .find(|var| var.name == name && var.causality == jetpipe_model::variables::Causality::Parameter)
            .ok_or_else(|| format!("{}: '{name}' is not a parameter of the model", path.display()))?;
        if START_STATE.contains(&name.as_str()) {
            // A report's fmu_start_values carry the FMU's start state; the commands that take
            // a parameter file start from their own (the recording's, or an equilibrium).
            let x = v
                .as_f64()
                .or_else(|| v.as_bool().map(f64::from))
                .ok_or_else(|| format!("{}: '{name}' must be a number or a boolean, got {v}", path.display()))?;
            if variable.var_type == jetpipe_model::variables::VarType::Boolean && x != 0.0 && x != 1.0 {
                return Err(format!(
                    "{}: '{name}' = {v} is invalid: must be true or false",
                    path.display()
                ));
            }
            jetpipe_model::variables::check(variable.value_reference, x)
                .map_err(|e| format!("{}: {e}", path.display()))?;
            start_state.push(variable.name);
            continue;
        }
        let x = v
            .as_f64()
            .ok_or_else(|| format!("{}: '{name}' must be a number, got {v}", path.display()))?;
        p.set(variable.value_reference, x)
            .map_err(|e| format!("{}: {e}", path.display()))?;
    }
    p.validate().map_err(|e| format!("{}: {e}", path.display()))?;
    if !start_state.is_empty() {
        eprintln!(
            "{}: {} set the FMU's start state, which this command does not read: a diagnosis starts from the recording's first samples, a sweep at the equilibrium of its first inputs",
            path.display(),
            start_state.join(", ")
        );
    }
    Ok(p)
}

/// `jetpipe propose`: the protocol, its JSON and its page.
fn propose(
    report: &std::path::Path,
    out: &std::path::Path,
    seconds: f64,
    rate: f64,
    seed: u64,
    jobs: Option<usize>,
) -> Result<(), String> {
    let text = std::fs::read_to_string(report).map_err(|e| format!("cannot read {}: {e}", report.display()))?;
    let value: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| format!("{}: not valid JSON: {e}", report.display()))?;
    let mut options = jetpipe_diagnosis::propose::ProposeOptions {
        seconds,
        rate,
        seed,
        ..Default::default()
    };
    if let Some(jobs) = jobs {
        options.jobs = jobs.max(1);
    }
    let started = Instant::now();
    let proposal = jetpipe_diagnosis::propose::propose(&value, &options, &mut |line| eprintln!("{line}"))
        .map_err(|e| format!("{}: {e}", report.display()))?;
    let protocol_file = out
        .file_name()
        .map_or_else(|| out.display().to_string(), |n| n.to_string_lossy().into_owned());
    let report_name = report.display().to_string();
    jetpipe_cli::output::write_atomically(out, &proposal.protocol.to_csv())?;
    let json = jetpipe_cli::proposal::to_json(&proposal, &report_name, &protocol_file, seed);
    let json_path = out.with_extension("json");
    let page_path = out.with_extension("html");
    jetpipe_cli::output::write_atomically(
        &json_path,
        &(serde_json::to_string_pretty(&json).map_err(|e| e.to_string())? + "\n"),
    )?;
    jetpipe_cli::output::write_atomically(
        &page_path,
        &jetpipe_cli::proposal::page(&proposal, &report_name, &protocol_file)?,
    )?;
    let smallest = proposal.smallest();
    println!(
        "{}: {} s at {} Hz; the closest explanations, {} and {}, differ by {:.2} noise floors ({:.1} s); {} and {}",
        out.display(),
        seconds,
        rate,
        proposal.explanations[smallest.first].label,
        proposal.explanations[smallest.second].label,
        smallest.noise_floors,
        started.elapsed().as_secs_f64(),
        json_path.display(),
        page_path.display()
    );
    Ok(())
}

/// The FMU parameters that set the start state rather than the model's constants.
const START_STATE: [&str; 3] = ["start_at_equilibrium", "P1_start", "P2_start"];

/// Progress of the diagnosis's long phases on stderr: on a terminal a bar with the time left
/// (indicatif); in a log, where the bar is hidden, a plain line when a phase starts and when it
/// ends, with its duration.
#[derive(Default)]
struct TerminalBars {
    bar: std::sync::Mutex<Option<(indicatif::ProgressBar, String, Instant)>>,
}

impl TerminalBars {
    fn println(&self, line: &str) {
        match self
            .bar
            .lock()
            .ok()
            .as_deref()
            .and_then(|b| b.as_ref().map(|(bar, ..)| bar.clone()))
        {
            Some(bar) if !bar.is_hidden() => bar.suspend(|| eprintln!("{line}")),
            _ => eprintln!("{line}"),
        }
    }
}

impl jetpipe_diagnosis::ProgressBars for TerminalBars {
    fn start(&self, phase: &str, total: usize) {
        let bar = indicatif::ProgressBar::new(total as u64);
        if let Ok(style) =
            indicatif::ProgressStyle::with_template("{prefix:>13} [{bar:30}] {pos}/{len} {elapsed}, about {eta} left")
        {
            bar.set_style(style.progress_chars("=> "));
        }
        bar.set_prefix(phase.to_string());
        if bar.is_hidden() {
            eprintln!("{phase}: {total} to do");
        }
        if let Ok(mut slot) = self.bar.lock() {
            *slot = Some((bar, phase.to_string(), Instant::now()));
        }
    }
    fn advance(&self) {
        if let Ok(slot) = self.bar.lock() {
            if let Some((bar, ..)) = slot.as_ref() {
                bar.inc(1);
            }
        }
    }
    fn finish(&self) {
        if let Ok(mut slot) = self.bar.lock() {
            if let Some((bar, phase, started)) = slot.take() {
                if bar.is_hidden() {
                    eprintln!("{phase}: done in {:.1} s", started.elapsed().as_secs_f64());
                }
                bar.finish_and_clear();
            }
        }
    }
}

/// Where one recording's diagnosis goes: its JSON report, its HTML page (none with
/// `--no-html`) and the directory of its SVG figures (`--plots`).
struct Destination<'a> {
    report: &'a std::path::Path,
    page: Option<&'a std::path::Path>,
    plots: Option<&'a std::path::Path>,
}

/// `NAME.json` in the current directory for the recording `.../NAME.csv`.
fn default_report_path(recording: &std::path::Path) -> Result<PathBuf, String> {
    let stem = recording.file_stem().filter(|s| !s.is_empty()).ok_or_else(|| {
        format!(
            "{}: cannot name a report after this path: give --report FILE",
            recording.display()
        )
    })?;
    Ok(PathBuf::from(stem).with_extension("json"))
}

/// The page beside the report: the report's path with the extension `.html`.
fn page_path(report: &std::path::Path) -> Result<PathBuf, String> {
    let page = report.with_extension("html");
    if page == report {
        return Err(format!(
            "--report {}: the HTML page would overwrite the report; name the report .json (or give --no-html)",
            report.display()
        ));
    }
    Ok(page)
}

fn diagnose(
    recording_path: &std::path::Path,
    destination: &Destination,
    params: Option<&std::path::Path>,
    (calibrate, flexible): (bool, bool),
    jobs: Option<usize>,
) -> Result<(), String> {
    let report = destination.report;
    let (options, bars) = diagnosis_options((calibrate, flexible), jobs)?;
    let started = Instant::now();
    let base = read_parameters(params)?;
    let recording = jetpipe_diagnosis::input::recording::Recording::read(recording_path, &base)?;
    let mut progress = |line: &str| bars.println(&format!("[{:6.1} s] {line}", started.elapsed().as_secs_f64()));
    // The diagnosis keeps the recording; the figures read it again once the report is
    // written, so a long recording is not held twice meanwhile.
    let diagnosis = jetpipe_diagnosis::diagnose_owned(recording, &base, &options, &mut progress)?;
    let name = recording_path.display().to_string();
    let json = diagnosis.to_json(&name);
    write_report(destination, &json)?;
    let recording = jetpipe_diagnosis::input::recording::Recording::read(recording_path, &base)
        .map_err(|e| format!("{e} (the report {} was written)", report.display()))?;
    write_figures_and_page(destination, &name, &json, (&recording, &diagnosis, &base))?;
    print_summary(&name, &diagnosis, destination);
    println!("  ({:.1} s)", started.elapsed().as_secs_f64());
    Ok(())
}

/// The options of one diagnosis (single or joint), with the terminal's progress bars.
fn diagnosis_options(
    (calibrate, flexible): (bool, bool),
    jobs: Option<usize>,
) -> Result<(jetpipe_diagnosis::Options, std::sync::Arc<TerminalBars>), String> {
    if jobs == Some(0) {
        return Err("--jobs 0 is invalid: must be at least 1".to_string());
    }
    let bars = std::sync::Arc::new(TerminalBars::default());
    let mut options = jetpipe_diagnosis::Options {
        calibrate,
        flexible,
        bars: Some(bars.clone()),
        ..Default::default()
    };
    if let Some(jobs) = jobs {
        options.jobs = jobs;
    }
    Ok((options, bars))
}

/// `NAME_joint.json` beside `NAME.json`: the joint report named after the first recording.
fn joint_report_path(report: &std::path::Path) -> PathBuf {
    let stem = report
        .file_stem()
        .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
    report.with_file_name(format!("{stem}_joint.json"))
}

/// Several recordings of one actuator, one model for all (`diagnose --joint`).
fn diagnose_joint(
    paths: &[PathBuf],
    destination: &Destination,
    params: Option<&std::path::Path>,
    (calibrate, flexible): (bool, bool),
    jobs: Option<usize>,
) -> Result<(), String> {
    let (options, bars) = diagnosis_options((calibrate, flexible), jobs)?;
    let started = Instant::now();
    let base = read_parameters(params)?;
    let mut recordings = vec![];
    for path in paths {
        let recording = jetpipe_diagnosis::input::recording::Recording::read(path, &base)?;
        recordings.push((path.display().to_string(), recording));
    }
    let mut progress = |line: &str| bars.println(&format!("[{:6.1} s] {line}", started.elapsed().as_secs_f64()));
    let joint = jetpipe_diagnosis::diagnose_joint(recordings, &base, &options, &mut progress)?;
    let json = joint.to_json();
    let name = json["recording"].as_str().unwrap_or("joint").to_string();
    write_report(destination, &json)?;
    write_figures_and_page(
        destination,
        &name,
        &json,
        (&joint.joined.recording, &joint.diagnosis, &base),
    )?;
    print_summary(&name, &joint.diagnosis, destination);
    for r in &joint.recordings {
        println!(
            "  {}: held-out force error {:.4} → {:.4} N ({:.2} noise floors){}",
            r.name,
            r.before.heldout_rms,
            r.after.heldout_rms,
            r.after.heldout_rms / r.noise_floor,
            if r.explained() { ", within its noise" } else { "" }
        );
    }
    for note in &joint.notes {
        println!("  {note}");
    }
    println!("  ({:.1} s)", started.elapsed().as_secs_f64());
    Ok(())
}

/// The report, written whole or not at all: an existing report is never left half-written,
/// and it is written before the figures, so that should they fail the diagnosis is not lost.
fn write_report(destination: &Destination, json: &serde_json::Value) -> Result<(), String> {
    let text = serde_json::to_string_pretty(json).map_err(|e| e.to_string())? + "\n";
    jetpipe_cli::output::write_atomically(destination.report, &text)
}

/// The figures (with --plots) and the page beside the report.
fn write_figures_and_page(
    destination: &Destination,
    name: &str,
    json: &serde_json::Value,
    (recording, diagnosis, base): (
        &jetpipe_diagnosis::input::recording::Recording,
        &jetpipe_diagnosis::Diagnosis,
        &Parameters,
    ),
) -> Result<(), String> {
    let report = destination.report;
    let figures_failed = |e: String| format!("{e} (the report {} was written)", report.display());
    let inputs = jetpipe_cli::plots::FigureInputs {
        recording,
        diagnosis,
        base,
    };
    let figures = match destination.plots {
        Some(dir) => {
            let figures = jetpipe_cli::plots::write_diagnosis_plots(dir, &inputs).map_err(figures_failed)?;
            eprintln!("plots written to {}", dir.display());
            Some(figures)
        }
        None => None,
    };
    if let Some(page) = destination.page {
        let figures = match figures {
            Some(figures) => figures,
            None => jetpipe_cli::plots::diagnosis_figures(&inputs).map_err(figures_failed)?,
        };
        // The page links the report by its file name: the two sit side by side.
        let report_file = report
            .file_name()
            .map_or_else(|| report.display().to_string(), |f| f.to_string_lossy().into_owned());
        let html = jetpipe_cli::html_report::page(name, json, &figures, &report_file, None);
        jetpipe_cli::output::write_atomically(page, &html)?;
    }
    Ok(())
}

fn print_summary(name: &str, diagnosis: &jetpipe_diagnosis::Diagnosis, destination: &Destination) {
    println!(
        "{name}: {} samples, noise floor {:.4} N",
        diagnosis.samples, diagnosis.noise_floor
    );
    println!("  verdict: {}", diagnosis.verdict());
    for line in diagnosis.summary() {
        println!("  {line}");
    }
    println!("  report: {}", destination.report.display());
    if let Some(page) = destination.page {
        println!("  page: {}", page.display());
    }
}

fn diagnose_batch(
    inputs: Vec<PathBuf>,
    out: PathBuf,
    params: Option<&std::path::Path>,
    (calibrate, flexible): (bool, bool),
    jobs: Option<usize>,
) -> Result<(), String> {
    let jobs = jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(2, |n| n.get()));
    let options = jetpipe_cli::batch::BatchOptions {
        inputs,
        out,
        base: read_parameters(params)?,
        calibrate,
        flexible,
        jobs,
    };
    let started = Instant::now();
    let rows = jetpipe_cli::batch::run(&options, &|line: &str| eprintln!("{line}"))?;
    let failed: Vec<&str> = rows
        .iter()
        .filter(|r| r.verdict == "error")
        .map(|r| r.name.as_str())
        .collect();
    println!(
        "{} recordings in {:.1} s with {jobs} jobs: {} explained, {} with a remainder, {} failed",
        rows.len(),
        started.elapsed().as_secs_f64(),
        rows.iter().filter(|r| r.verdict == "explained").count(),
        rows.iter().filter(|r| r.verdict == "unexplained_remainder").count(),
        failed.len()
    );
    println!("  pages: {}", options.out.join("index.html").display());
    println!("  table: {}", options.out.join("summary.csv").display());
    if failed.is_empty() {
        Ok(())
    } else {
        Err(format!(
            "{} of {} recordings could not be diagnosed ({}); their errors are in summary.csv",
            failed.len(),
            rows.len(),
            failed.join(", ")
        ))
    }
}

fn linearize(force: f64, x_s: f64, json: bool) -> Result<(), String> {
    if !force.is_finite() {
        return Err(format!("--force {force} is invalid: must be finite"));
    }
    let model = Actuator::new(Parameters::default())?;
    model.params.check_stopper(x_s)?;
    let v = jetpipe_model::linearization::command_for_force(&model, force, x_s)?;
    let lin = jetpipe_model::linearization::linearize(&model, v, x_s)?;
    if json {
        println!(
            "{}",
            serde_json::to_string_pretty(&linear_model_json(&lin)).map_err(|e| e.to_string())?
        );
        return Ok(());
    }
    let op = &lin.operating_point;
    println!(
        "operating point: F_act = {:.4} N, x_s = {} m, v_DA = {:.6} V, i = {:.6} A, P1 = {:.0} Pa, P2 = {:.0} Pa",
        op.f_act, op.x_s, op.v_da, op.current, op.p1, op.p2
    );
    println!("poles (rad/s):");
    for p in &lin.poles {
        println!("  {:12.4} {:+12.4}j", p.re, p.im);
    }
    println!("zeros (rad/s):");
    for z in &lin.zeros {
        println!("  {:12.4} {:+12.4}j", z.re, z.im);
    }
    if let Some(bw) = lin.bandwidth_hz() {
        println!("open-loop -3 dB bandwidth of F_act/v_DA: {bw:.3} Hz");
    }
    Ok(())
}

fn simulate(step: f64, tolerance: f64, csv: Option<PathBuf>) -> Result<(), String> {
    if !(step.is_finite() && step > 0.0 && step <= scenario::SAMPLE_PERIOD) {
        return Err(format!(
            "--step {step} is invalid: must be in (0, {}] s",
            scenario::SAMPLE_PERIOD
        ));
    }
    let substeps = (scenario::SAMPLE_PERIOD / step).round().max(1.0) as usize;
    let model = Actuator::new(Parameters::default())?;
    let (v0, x0) = scenario::standard_inputs(0);
    let started = Instant::now();
    let mut sim = Simulation::at_equilibrium(model, v0, x0, 0.0, tolerance)?;
    let mut rows = vec![(0.0, sim.outputs())];
    for k in 0..scenario::standard_samples() {
        let (v, x) = scenario::standard_inputs(k);
        sim.set_command(v)?;
        sim.set_stopper(x)?;
        for _ in 0..substeps {
            sim.step(scenario::SAMPLE_PERIOD / substeps as f64)
                .map_err(|e| format!("{e:?}"))?;
        }
        rows.push((sim.time(), sim.outputs()));
    }
    let elapsed = started.elapsed().as_secs_f64();
    let force = rows.iter().map(|r| r.1.f_act);
    let (f_min, f_max) = force.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), f| (a.min(f), b.max(f)));
    let last = rows.last().expect("at least the initial row").1;
    let st = sim.statistics();
    println!(
        "standard scenario: {} s, communication step {step} s, relative tolerance {tolerance:e}",
        scenario::DURATION
    );
    println!("  F_act  min {f_min:.4} N  max {f_max:.4} N  final {:.6} N", last.f_act);
    println!("  P1 final {:.1} Pa   P2 final {:.1} Pa", last.p1, last.p2);
    println!(
        "  work: {} steps ({} rejected), {} right-hand sides, {} Jacobians; {:.1} ms CPU ({:.0}x real time)",
        st.steps,
        st.rejected,
        st.rhs_evaluations,
        st.jacobians,
        elapsed * 1e3,
        scenario::DURATION / elapsed
    );
    if let Some(path) = csv {
        let mut text = String::from("time_s,F_act_N,P1_Pa,P2_Pa,i_A,x_jp_m\n");
        for (t, y) in &rows {
            text.push_str(&format!("{t},{},{},{},{},{}\n", y.f_act, y.p1, y.p2, y.current, y.x_jp));
        }
        std::fs::write(&path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        println!("  wrote {}", path.display());
    }
    Ok(())
}

/// The report `jetpipe linearize --json` prints.
fn linear_model_json(lin: &jetpipe_model::LinearModel) -> serde_json::Value {
    use jetpipe_model::physics::actuator::N_STATES;
    let matrix = |m: &jetpipe_model::physics::actuator::Jacobian| -> Vec<Vec<f64>> {
        (0..N_STATES)
            .map(|r| (0..N_STATES).map(|c| m[(r, c)]).collect())
            .collect()
    };
    let pairs = |v: &[nalgebra::Complex<f64>]| -> Vec<[f64; 2]> { v.iter().map(|z| [z.re, z.im]).collect() };
    let op = &lin.operating_point;
    serde_json::json!({
        "states": ["i", "x_jp", "der(x_jp)", "der(x_jp,2)", "P1", "P2"],
        "input": "v_DA",
        "output": "F_act",
        "A": matrix(&lin.a),
        "B": lin.b.iter().map(|v| vec![*v]).collect::<Vec<_>>(),
        "C": [lin.c.iter().copied().collect::<Vec<_>>()],
        "D": [[lin.d]],
        "poles": pairs(&lin.poles),
        "zeros": pairs(&lin.zeros),
        "bandwidth_Hz": lin.bandwidth_hz(),
        "operating_point": {
            "v_DA": op.v_da, "x_s": op.x_s, "F_act": op.f_act, "i": op.current,
            "x_jp": op.x_jp, "P1": op.p1, "P2": op.p2
        }
    })
}
