//! `antagonistic`: packages the Tendon, FingerJoint and JointController FMUs and the
//! AntagonisticJoint SSP.
//!
//! ```sh
//! cargo run --release -p antagonistic -- package   # dist/{Tendon,FingerJoint,JointController}.fmu + dist/AntagonisticJoint.ssp
//! cargo run --release -p antagonistic -- model-description Tendon
//! cargo run --release -p antagonistic -- ssd       # SystemStructure.ssd to stdout
//! ```
//!
//! `package` needs `dist/JetPipeActuator.fmu` (`cargo run --release --bin jetpipe -- package`).
//!
//! Run it in a cargo invocation of its own (as above): this crate links the three models
//! without their `exports` feature, their FMUs need it on, and cargo would unify the two.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

const USAGE: &str = "usage: antagonistic package [--dist DIR] [--library-dir DIR]
       antagonistic model-description Tendon|FingerJoint|JointController
       antagonistic ssd";

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("antagonistic: {e}");
            ExitCode::FAILURE
        }
    }
}

fn option(args: &[String], name: &str) -> Result<Option<PathBuf>, String> {
    match args.iter().position(|a| a == name) {
        None => Ok(None),
        Some(i) => args
            .get(i + 1)
            .map(|v| Some(PathBuf::from(v)))
            .ok_or_else(|| format!("{name} needs a value\n{USAGE}")),
    }
}

fn run(args: &[String]) -> Result<(), String> {
    match args.first().map(String::as_str) {
        Some("package") => {
            let dist = option(args, "--dist")?.unwrap_or_else(|| PathBuf::from("dist"));
            let library_dir = match option(args, "--library-dir")? {
                Some(dir) => dir,
                None => build_shared_libraries()?,
            };
            for out in antagonistic::package::write_fmus(&dist, &library_dir)? {
                println!("wrote {}", out.display());
            }
            let ssp = dist.join(format!("{}.ssp", antagonistic::system::SYSTEM_NAME));
            antagonistic::package::write_ssp(&ssp, &dist, 3.0)?;
            println!("wrote {}", ssp.display());
            Ok(())
        }
        Some("model-description") => {
            let name = args.get(1).ok_or_else(|| format!("which model?\n{USAGE}"))?;
            let fmu = antagonistic::package::find(name).ok_or_else(|| format!("no model {name}\n{USAGE}"))?;
            print!("{}", fmi2::model_description::model_description_xml(fmu.info));
            Ok(())
        }
        Some("ssd") => {
            antagonistic::system::check().map_err(|p| p.join("\n"))?;
            print!("{}", antagonistic::system::ssd_xml(3.0));
            Ok(())
        }
        _ => Err(USAGE.to_string()),
    }
}

/// `cargo run -p antagonistic` builds the three model crates as rlibs without their exports;
/// the FMUs need their cdylibs with them, so build them (a no-op when up to date) with this
/// executable's profile, into this executable's target directory. This package may not be in
/// the same invocation: cargo would unify features, giving this binary three sets of `fmi2*`
/// symbols next to the actuator's.
fn build_shared_libraries() -> Result<PathBuf, String> {
    let exe = std::env::current_exe().map_err(|e| format!("cannot locate this executable: {e}"))?;
    let dir = exe.parent().map(Path::to_path_buf).unwrap_or_default();
    let manifest = concat!(env!("CARGO_MANIFEST_DIR"), "/../../Cargo.toml");
    if Path::new(manifest).is_file() {
        let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_string());
        let mut command = std::process::Command::new(&cargo);
        command.args(["build", "--lib", "--manifest-path", manifest]);
        for package in ["tendon", "finger_joint", "joint_controller"] {
            command.args(["-p", package]);
        }
        if !cfg!(debug_assertions) {
            command.arg("--release");
        }
        if let Some(target_dir) = dir.parent() {
            command.arg("--target-dir").arg(target_dir);
        }
        let status = command.status().map_err(|e| format!("cannot run {cargo}: {e}"))?;
        if !status.success() {
            return Err(format!(
                "`{cargo} build --lib -p tendon -p finger_joint -p joint_controller` failed ({status})"
            ));
        }
    }
    Ok(dir)
}
