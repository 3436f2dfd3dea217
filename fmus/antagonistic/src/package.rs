//! Writing the three FMUs (through jetpipe's `packaging::write_model_fmu`) and the `.ssp`.

use std::io::Write;
use std::path::{Path, PathBuf};

use fmi2::model::ModelInfo;

use crate::system::{check, components, ssd_xml};

/// One FMU of this workspace: its model info, the cdylib's file name, and its notes.
pub struct Fmu {
    pub info: &'static ModelInfo,
    pub library: &'static str,
    pub notes: &'static str,
}

pub const FMUS: &[Fmu] = &[
    Fmu {
        info: &tendon::fmu::MODEL_INFO,
        library: "libtendon.so",
        notes: "<p>Rod node m_rod dv/dt = F_act - T_rod - c_rod v; joint-end tension T = max(0, k s + c ds/dt) for \
stretch s &gt; 0, else 0 (slack); pulley friction by the capstan law T_rod = T exp(capstan tanh(v/v_friction)). \
Implicit Euler on substeps of at most max_substep; the joint end moves linearly over each step with v_joint. \
Starts at the static equilibrium of its inputs (stretch F_act/k).</p>",
    },
    Fmu {
        info: &finger_joint::fmu::MODEL_INFO,
        library: "libfinger_joint.so",
        notes: "<p>J d(omega)/dt = r (T_flexor - T_extensor) + tau_ext - b omega + tau_limit, with one-sided \
spring-damper stops at theta_min and theta_max. Outputs the tendon excursions x_flexor = r theta and \
x_extensor = -r theta. Implicit Euler on substeps of at most max_substep.</p>",
    },
    Fmu {
        info: &joint_controller::fmu::MODEL_INFO,
        library: "libjoint_controller.so",
        notes: "<p>tau = Kp e + Ki int(e) - Kd omega; T_flexor/extensor = T_co +/- tau/(2r), both raised to at \
least T_min and lowered to at most T_max (Jacobsen et al.'s co-contraction); v_DA = v_static(T_ref) + K_F (T_ref \
- F_meas), clamped to [v_min, v_max]. Sampled: reads its inputs at the start of each step and holds its outputs \
over the next.</p>",
    },
];

/// Look a model up by its identifier (for `model-description NAME`).
pub fn find(identifier: &str) -> Option<&'static Fmu> {
    FMUS.iter().find(|f| f.info.model_identifier == identifier)
}

/// Write `<dist>/<modelIdentifier>.fmu` for each model, with the libraries from `library_dir`.
pub fn write_fmus(dist: &Path, library_dir: &Path) -> Result<Vec<PathBuf>, String> {
    let mut written = Vec::new();
    for f in FMUS {
        let library = library_dir.join(f.library);
        check_exports(&library)?;
        let out = dist.join(format!("{}.fmu", f.info.model_identifier));
        let documentation = jetpipe_packaging::documentation_page(f.info, f.notes);
        jetpipe_packaging::write_model_fmu(&out, &library, f.info, &documentation)?;
        written.push(out);
    }
    Ok(written)
}

/// A library built without its model's `exports` feature (the variant cargo builds when the
/// crate is only a dependency) has no `fmi2*` symbols, and the FMU would fail to load. Its
/// dynamic string table holds each exported name NUL-terminated; without the exports the
/// generic layer is not even instantiated, so the names appear nowhere.
fn check_exports(library: &Path) -> Result<(), String> {
    let bytes = std::fs::read(library).map_err(|e| format!("cannot read {}: {e}", library.display()))?;
    for name in ["fmi2Instantiate", "fmi2DoStep", "fmi2GetReal"] {
        let needle = format!("\0{name}\0");
        if !bytes.windows(needle.len()).any(|w| w == needle.as_bytes()) {
            return Err(format!(
                "{} does not export {name}: it was built without its `exports` feature \
                 (build it with `cargo build --release --lib -p tendon -p finger_joint -p joint_controller`)",
                library.display()
            ));
        }
    }
    Ok(())
}

/// Write the `.ssp`: `SystemStructure.ssd`, the parameter set, and every component's FMU
/// from `dist` (the actuator's `JetPipeActuator.fmu` included).
pub fn write_ssp(out: &Path, dist: &Path, stop_time: f64) -> Result<(), String> {
    check().map_err(|problems| format!("the system does not match the models:\n{}", problems.join("\n")))?;
    let mut sources: Vec<(String, PathBuf)> = Vec::new();
    for c in components() {
        let source = c.source();
        if sources.iter().all(|(s, _)| *s != source) {
            let file = dist.join(format!("{}.fmu", c.info.model_identifier));
            if !file.is_file() {
                return Err(format!(
                    "{} is missing: build it first ({})",
                    file.display(),
                    if c.info.model_identifier == "JetPipeActuator" {
                        "cargo run --release --bin jetpipe -- package"
                    } else {
                        "cargo run --release -p antagonistic -- package"
                    }
                ));
            }
            sources.push((source, file));
        }
    }
    let temporary = out.with_extension("ssp.partial");
    let result = (|| -> Result<(), Box<dyn std::error::Error>> {
        let mut zip = zip::ZipWriter::new(std::fs::File::create(&temporary)?);
        let deflated = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
        // FMUs are zip files already: stored, not compressed twice.
        let stored = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Stored);
        zip.start_file("SystemStructure.ssd", deflated)?;
        zip.write_all(ssd_xml(stop_time).as_bytes())?;
        zip.add_directory("resources/", deflated)?;
        for (source, file) in &sources {
            zip.start_file(source.as_str(), stored)?;
            zip.write_all(&std::fs::read(file)?)?;
        }
        zip.finish()?;
        Ok(())
    })();
    match result {
        Ok(()) => std::fs::rename(&temporary, out).map_err(|e| format!("cannot write {}: {e}", out.display())),
        Err(e) => {
            let _ = std::fs::remove_file(&temporary);
            Err(format!("cannot write {}: {e}", out.display()))
        }
    }
}
