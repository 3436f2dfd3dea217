//! Writing `JetPipeActuator.fmu` (FMI 2.0) and `JetPipeActuator-fmi3.fmu` (FMI 3.0): model
//! description (from the variable table), the shared library (one library exports both
//! versions' symbols, so both archives carry the same binary), and an HTML page documenting
//! the interface.

use std::io::Write;
use std::path::Path;

use fmi2::model::{Causality, ModelInfo, VarType};
use fmi2::model_description::model_description_xml;
use jetpipe::fmu::MODEL_INFO;

/// The model description of the actuator FMU.
pub fn actuator_model_description() -> String {
    model_description_xml(&MODEL_INFO)
}

/// The FMI 3.0 model description of the actuator FMU.
pub fn actuator_model_description_fmi3() -> String {
    fmi3::model_description::model_description_xml(&MODEL_INFO)
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// `documentation/index.html` of any FMU on the FMI layer: name, description, `notes`
/// (already HTML) and the interface table, from the variable table.
pub fn documentation_page(info: &ModelInfo, notes: &str) -> String {
    documentation_page_for(info, "FMI 2.0 Co-Simulation", notes)
}

/// [`documentation_page`] naming the standard and interfaces (`"FMI 3.0 Co-Simulation and Model Exchange"`).
pub fn documentation_page_for(info: &ModelInfo, standard: &str, notes: &str) -> String {
    let mut rows = String::new();
    for v in info.variables {
        let causality = match v.causality {
            Causality::Parameter => "parameter",
            Causality::Input => "input",
            Causality::Output => "output",
            Causality::Local => "local",
        };
        let start = match (v.causality, v.var_type) {
            (Causality::Output, _) => String::new(),
            (_, VarType::Boolean) => (v.start != 0.0).to_string(),
            _ => format!("{}", v.start),
        };
        let extent = info.extent_of(v);
        let range = match (extent.min, extent.max) {
            (None, None) => String::new(),
            (lo, hi) => format!(
                "[{}, {}]",
                lo.map_or("-inf".to_string(), |x| x.to_string()),
                hi.map_or("inf".to_string(), |x| x.to_string())
            ),
        };
        rows.push_str(&format!(
            "<tr><td><code>{}</code></td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n",
            escape(v.name),
            causality,
            escape(v.unit.unwrap_or("")),
            start,
            range,
            escape(v.description)
        ));
    }
    format!(
        "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>{name}</title></head><body>\n\
<h1>{name}</h1>\n<p>{description}</p>\n<p>{standard}, version {version}.</p>\n{notes}\n\
<table border=\"1\" cellpadding=\"3\"><tr><th>name</th><th>causality</th><th>unit</th><th>start</th>\
<th>valid range</th><th>description</th></tr>\n{rows}</table>\n</body></html>\n",
        name = info.model_identifier,
        description = escape(info.description),
        version = info.version,
    )
}

/// The actuator's `documentation/index.html`: where the equations come from, and the behaviour
/// an importer can rely on.
pub fn documentation_html(info: &ModelInfo) -> String {
    documentation_page_for(info, "FMI 2.0 Co-Simulation and Model Exchange", &actuator_notes(info))
}

/// The FMI 3.0 archive's `documentation/index.html`.
pub fn documentation_html_fmi3(info: &ModelInfo) -> String {
    documentation_page_for(info, "FMI 3.0 Co-Simulation and Model Exchange", &actuator_notes(info))
}

fn actuator_notes(info: &ModelInfo) -> String {
    format!(
        "<p>Equations and numbers follow P.D. Henri, <i>Study of a Jet Pipe \
Electropneumatic Actuator</i> (1994): current driver (2.1)&ndash;(2.3), jet pipe (2.4)&ndash;(2.7), orifice areas \
(2.8)&ndash;(2.17), orifice flow (2.18)&ndash;(2.23), chambers (2.24)&ndash;(2.32), force (2.36)&ndash;(2.38). \
The FMU starts at the equilibrium of its initial inputs. A stopper position set between communication points \
moves the stopper instantly and conserves the air in each chamber (P V<sup>&gamma;</sup> constant); with \
fmi2SetRealInputDerivatives it moves linearly over the step. The tolerance of fmi2SetupExperiment \
(fmi3EnterInitializationMode) is the relative tolerance of the integrator (default {tolerance:e}).</p>",
        tolerance = info.default_tolerance,
    )
}

/// Write the FMU archive to `out`, taking the compiled shared library from `library`.
pub fn write_fmu(out: &Path, library: &Path) -> Result<(), String> {
    write_fmu_platforms(out, &[("linux64", library)])
}

/// Write the FMU archive to `out` with one binary per FMI platform (`linux64`, `win64`).
pub fn write_fmu_platforms(out: &Path, binaries: &[(&str, &Path)]) -> Result<(), String> {
    write_model_fmu_platforms(out, binaries, &MODEL_INFO, &documentation_html(&MODEL_INFO))
}

/// Write the FMU archive of any model on the FMI layer to `out`: `modelDescription.xml`
/// generated from `info`, the shared library `library` as
/// `binaries/linux64/<modelIdentifier>.so`, and `documentation` as
/// `documentation/index.html`. The other FMUs of the workspace (`fmus/`) are written with it.
pub fn write_model_fmu(out: &Path, library: &Path, info: &ModelInfo, documentation: &str) -> Result<(), String> {
    write_model_fmu_platforms(out, &[("linux64", library)], info, documentation)
}

/// Write `JetPipeActuator-fmi3.fmu` to `out` with one binary per FMI 3.0 platform
/// (`x86_64-linux`, `x86_64-windows`).
pub fn write_fmu3_platforms(out: &Path, binaries: &[(&str, &Path)]) -> Result<(), String> {
    let model_description = fmi3::model_description::try_model_description_xml(&MODEL_INFO).map_err(|problems| {
        format!(
            "invalid variable table of {}: {}",
            MODEL_INFO.model_name,
            problems.join("; ")
        )
    })?;
    write_archive(
        out,
        &model_description,
        binaries,
        &MODEL_INFO,
        &documentation_html_fmi3(&MODEL_INFO),
    )
}

/// The file name suffix of a shared library on an FMI 2.0 or FMI 3.0 platform.
fn library_suffix(platform: &str) -> Result<&'static str, String> {
    match platform {
        "linux64" | "linux32" | "x86_64-linux" | "aarch64-linux" => Ok("so"),
        "win64" | "win32" | "x86_64-windows" => Ok("dll"),
        "darwin64" | "x86_64-darwin" | "aarch64-darwin" => Ok("dylib"),
        _ => Err(format!("unknown FMI platform {platform:?}")),
    }
}

/// [`write_model_fmu`] with one shared library per platform: `binaries/<platform>/<modelIdentifier>.<so|dll>`.
pub fn write_model_fmu_platforms(
    out: &Path,
    libraries: &[(&str, &Path)],
    info: &ModelInfo,
    documentation: &str,
) -> Result<(), String> {
    let model_description = fmi2::model_description::try_model_description_xml(info)
        .map_err(|problems| format!("invalid variable table of {}: {}", info.model_name, problems.join("; ")))?;
    write_archive(out, &model_description, libraries, info, documentation)
}

/// An FMU archive: `model_description`, `binaries/<platform>/<modelIdentifier>.<so|dll>`,
/// `documentation/index.html`; written to a temporary file first.
fn write_archive(
    out: &Path,
    model_description: &str,
    libraries: &[(&str, &Path)],
    info: &ModelInfo,
    documentation: &str,
) -> Result<(), String> {
    let mut binaries = Vec::new();
    for &(platform, library) in libraries {
        let suffix = library_suffix(platform)?;
        let bytes = std::fs::read(library).map_err(|e| {
            format!(
                "cannot read the shared library {}: {e} (build it with `cargo build --release`)",
                library.display()
            )
        })?;
        binaries.push((platform, suffix, bytes));
    }
    if let Some(parent) = out.parent() {
        std::fs::create_dir_all(parent).map_err(|e| format!("cannot create {}: {e}", parent.display()))?;
    }
    // Write to a temporary file first so a failure never leaves half an FMU behind.
    let temporary = out.with_extension("fmu.partial");
    let result = (|| -> Result<(), Box<dyn std::error::Error>> {
        let file = std::fs::File::create(&temporary)?;
        let mut zip = zip::ZipWriter::new(file);
        let options = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
        zip.start_file("modelDescription.xml", options)?;
        zip.write_all(model_description.as_bytes())?;
        zip.add_directory("binaries/", options)?;
        for (platform, suffix, bytes) in &binaries {
            zip.add_directory(format!("binaries/{platform}/"), options)?;
            zip.start_file(
                format!("binaries/{platform}/{}.{suffix}", info.model_identifier),
                options,
            )?;
            zip.write_all(bytes)?;
        }
        zip.add_directory("documentation/", options)?;
        zip.start_file("documentation/index.html", options)?;
        zip.write_all(documentation.as_bytes())?;
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checked_in_model_description_is_the_generated_one() {
        let checked = include_str!("../../../modelDescription.xml");
        assert_eq!(
            checked,
            actuator_model_description(),
            "modelDescription.xml is stale: regenerate it with `cargo run --release --bin jetpipe -- model-description > modelDescription.xml`"
        );
    }

    #[test]
    fn checked_in_fmi3_model_description_is_the_generated_one() {
        let checked = include_str!("../../../modelDescription-fmi3.xml");
        assert_eq!(
            checked,
            actuator_model_description_fmi3(),
            "modelDescription-fmi3.xml is stale: regenerate it with `cargo run --release --bin jetpipe -- model-description --fmi3 > modelDescription-fmi3.xml`"
        );
    }
}
