//! The HTML page of a diagnosis, and the index of a batch's pages.
//!
//! A page is self-contained: its style and its figures (SVG) are inline, and it loads nothing,
//! from the network or from disk, so it can be mailed or archived alone. It is written from
//! the JSON report (the fields of docs/diagnosis.md, "The report"), so the page and the report
//! cannot say different things.

use serde_json::Value;

use crate::plots::Figure;

/// `text` with the characters HTML gives a meaning escaped.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

const STYLE: &str = "body{font-family:system-ui,sans-serif;max-width:960px;margin:2em auto;padding:0 1em;color:#222;line-height:1.45}
h1{font-size:1.5em;margin-bottom:.2em}h2{font-size:1.2em;margin-top:1.6em;border-bottom:1px solid #ccc}
table{border-collapse:collapse;margin:.5em 0}td,th{border:1px solid #ccc;padding:.25em .6em;text-align:left;vertical-align:top}
th{background:#f3f3f3}td.n{text-align:right;font-variant-numeric:tabular-nums}
.verdict{display:inline-block;padding:.2em .7em;border-radius:.3em;font-weight:bold;color:#fff}
.explained{background:#2b7a2b}.unexplained_remainder{background:#b3541e}.error{background:#a11}
pre{background:#f6f6f6;padding:.7em;overflow-x:auto}figure{margin:1.2em 0}figure svg{max-width:100%;height:auto}
figcaption{font-size:.9em;color:#444}body.wide{max-width:1400px}#summary td{font-size:.9em}";

fn number(v: &Value) -> Option<f64> {
    v.as_f64()
}

/// A value in N with four decimals, or a dash.
fn newtons(v: &Value) -> String {
    number(v).map_or_else(|| "—".into(), |x| format!("{x:.4} N"))
}

fn percent(v: &Value) -> String {
    number(v).map_or_else(|| "—".into(), |x| format!("{:.1} %", 100.0 * x))
}

/// The unit of an FMU parameter, from the variable table.
fn unit_of(name: &str) -> &'static str {
    jetpipe_model::variables::VARIABLES
        .iter()
        .find(|v| v.name == name)
        .and_then(|v| v.unit)
        .unwrap_or("")
}

fn parameters_table(parameters: &Value, units: Option<&Value>) -> String {
    let Some(object) = parameters.as_object() else {
        return String::new();
    };
    let mut rows = String::new();
    for (name, value) in object {
        let unit = units
            .and_then(|u| u.get(name))
            .and_then(Value::as_str)
            .map(str::to_string)
            .unwrap_or_else(|| unit_of(name).to_string());
        rows.push_str(&format!(
            "<tr><td><code>{}</code></td><td class=n>{}</td><td>{}</td></tr>",
            escape(name),
            number(value).map_or_else(|| escape(&value.to_string()), |x| format!("{x:.6e}")),
            escape(&unit)
        ));
    }
    format!("<table><tr><th>parameter</th><th>value</th><th>unit</th></tr>{rows}</table>")
}

fn errors_section(report: &Value) -> String {
    let heldout = &report["heldout"];
    let noise = number(&report["noise_floor_N"]).unwrap_or(f64::NAN);
    let ratio = |v: &Value| number(v).map_or_else(|| "—".into(), |x| format!("{:.1}×", x / noise));
    let mut html = format!(
        "<h2>Errors before and after</h2><table><tr><th>force RMS error</th><th>before</th><th>after</th><th>after / noise floor</th></tr>\
         <tr><td>held-out blocks (odd 2 s blocks, not fitted)</td><td class=n>{}</td><td class=n>{}</td><td class=n>{}</td></tr>\
         <tr><td>whole recording</td><td class=n>{}</td><td class=n>{}</td><td class=n>{}</td></tr></table>\
         <p>Noise floor of the force: {}.",
        newtons(&heldout["before_rms_N"]),
        newtons(&heldout["after_rms_N"]),
        ratio(&heldout["after_rms_N"]),
        newtons(&report["before"]["force_rms_N"]),
        newtons(&report["after"]["force_rms_N"]),
        ratio(&report["after"]["force_rms_N"]),
        newtons(&report["noise_floor_N"]),
    );
    if let (Some(p1), Some(p2)) = (
        number(&report["noise_floor_Pa"]["p1"]),
        number(&report["noise_floor_Pa"]["p2"]),
    ) {
        html.push_str(&format!(
            " Noise floors of the pressures: P1 {p1:.0} Pa, P2 {p2:.0} Pa."
        ));
    }
    html.push_str("</p>");
    let pressures = |v: &Value| -> Option<String> {
        let a = v.as_array()?;
        Some(format!(
            "P1 {:.0} Pa, P2 {:.0} Pa",
            a.first()?.as_f64()?,
            a.get(1)?.as_f64()?
        ))
    };
    if let (Some(b), Some(a)) = (
        pressures(&report["before"]["pressure_rms_Pa"]),
        pressures(&report["after"]["pressure_rms_Pa"]),
    ) {
        html.push_str(&format!(
            "<p>Pressure RMS errors over the whole recording: {b} before, {a} after.</p>"
        ));
    }
    html
}

fn additions_section(report: &Value) -> String {
    let effects = report["effects"].as_array().cloned().unwrap_or_default();
    let discovered = report["discovered"].as_array().cloned().unwrap_or_default();
    let mut html = String::from("<h2>What was added</h2>");
    if effects.is_empty() && discovered.is_empty() {
        html.push_str("<p>Nothing: no effect or term was added to the thesis model.</p>");
    }
    if let Some(names) = report["withdrawn"]["names"].as_array() {
        let listed = |v: &Value| -> Vec<String> {
            v.as_array()
                .map(|a| a.iter().filter_map(Value::as_str).map(escape).collect())
                .unwrap_or_default()
        };
        let names: Vec<String> = names.iter().filter_map(Value::as_str).map(escape).collect();
        let kept = listed(&report["withdrawn"]["kept"]);
        html.push_str(&format!(
            "<p id=withdrawn>Withdrawn: {}. Replayed accurately, the model with every addition had a force error of {} held out and {} over the whole recording, worse than the starting model's {} and {}; {}.</p>",
            names.join(" and "),
            newtons(&report["withdrawn"]["heldout_with_rms_N"]),
            newtons(&report["withdrawn"]["whole_with_rms_N"]),
            newtons(&report["heldout"]["before_rms_N"]),
            newtons(&report["before"]["force_rms_N"]),
            if kept.is_empty() {
                "the model reported is the starting model".to_string()
            } else {
                format!("the model reported keeps {} as an earlier round fitted them", kept.join(" and "))
            }
        ));
    }
    for e in &effects {
        html.push_str(&format!(
            "<h3>Named effect <code>{}</code> at the {}</h3><p>{}</p>",
            escape(e["name"].as_str().unwrap_or("?")),
            escape(e["location"].as_str().unwrap_or("?")),
            escape(e["evidence"].as_str().unwrap_or("")),
        ));
        html.push_str(&parameters_table(&e["parameters"], None));
        html.push_str(&format!(
            "<p>Held-out force error {} → {}: it removes {} of the held-out mean square.{}</p>",
            newtons(&e["heldout_before_rms_N"]),
            newtons(&e["heldout_after_rms_N"]),
            percent(&e["share_of_heldout_explained"]),
            match e["remainder_follows"].as_str() {
                Some(s) if !s.is_empty() => format!(" What it leaves follows {}.", escape(s)),
                _ => String::new(),
            }
        ));
    }
    for d in &discovered {
        html.push_str(&format!(
            "<h3>Discovered term: {} at the {} ({})</h3><p>{}</p>",
            escape(d["candidate"].as_str().unwrap_or("?")),
            escape(d["location"].as_str().unwrap_or("?")),
            escape(d["family"].as_str().unwrap_or("?")),
            escape(d["reading"].as_str().unwrap_or("")),
        ));
        html.push_str(&parameters_table(&d["parameters"], Some(&d["units"])));
        html.push_str(&format!(
            "<p>Held-out force error {} → {}: it removes {} of the held-out mean square.</p>",
            newtons(&d["heldout_before_rms_N"]),
            newtons(&d["heldout_after_rms_N"]),
            percent(&d["share_of_heldout_explained"]),
        ));
    }
    if let (Some(a), Some(b)) = (
        number(&report["joint_refit"]["heldout_before_rms_N"]),
        number(&report["joint_refit"]["heldout_after_rms_N"]),
    ) {
        html.push_str(&format!(
            "<p>Refitted together, the added parameters lower the held-out force error from {a:.4} N to {b:.4} N \
             (the values above are the refitted ones).</p>"
        ));
    }
    html
}

fn remainder_section(report: &Value) -> String {
    let u = &report["unexplained"];
    if u.is_null() {
        return String::new();
    }
    let alternatives: Vec<String> = u["alternatives"]
        .as_array()
        .map(|a| a.iter().filter_map(Value::as_str).map(escape).collect())
        .unwrap_or_default();
    format!(
        "<h2>What stays unexplained ({})</h2><p>{}</p><table><tr><th>location</th><td>{}</td></tr>\
         <tr><th>family</th><td>{}</td></tr><tr><th>alternatives</th><td>{}</td></tr>\
         <tr><th>RMS</th><td>{} ({:.1}× the noise floor)</td></tr></table>",
        escape(u["channel"].as_str().unwrap_or("force")),
        escape(u["sentence"].as_str().unwrap_or("")),
        escape(u["location"].as_str().unwrap_or("?")),
        escape(u["family"].as_str().unwrap_or("?")),
        if alternatives.is_empty() {
            "none".into()
        } else {
            alternatives.join(", ")
        },
        newtons(&u["rms_N"]),
        number(&u["ratio_to_noise"]).unwrap_or(f64::NAN),
    )
}

fn start_values_section(report: &Value) -> String {
    let values = &report["fmu_start_values"];
    let empty = values.as_object().map_or(true, |o| o.is_empty());
    let text = serde_json::to_string_pretty(values).unwrap_or_else(|_| "{}".into());
    format!(
        "<h2>FMU start values</h2><p>{}</p><pre id=fmu_start_values>{}</pre><p>With FMPy: \
         <code>fmpy.simulate_fmu(\"JetPipeActuator.fmu\", start_values=…)</code> with this dictionary. {}</p>",
        if empty {
            "Every parameter keeps the thesis's value."
        } else {
            "Every FMU parameter of the final model that differs from the thesis's; with these the FMU is the \
             model whose errors this page gives."
        },
        escape(&text),
        escape(report["stopper_positions"].as_str().map_or("", |s| s)),
    )
}

fn split_and_checks_section(report: &Value) -> String {
    let split = &report["pressure_split"];
    let mut html = format!(
        "<h2>Pressure split</h2><p>{}</p>",
        escape(split["sentence"].as_str().unwrap_or(""))
    );
    if split["available"].as_bool() == Some(true) {
        let pair = |v: &Value, k: usize, digits: usize| {
            v.get(k)
                .and_then(Value::as_f64)
                .map_or_else(|| "—".into(), |x| format!("{x:.digits$}"))
        };
        html.push_str(&format!(
            "<table><tr><th></th><th>RMS</th><th>in noise floors</th></tr>\
             <tr><td>measured force − force of the measured pressures</td><td class=n>{}</td><td class=n>{}</td></tr>\
             <tr><td>measured − modelled P1</td><td class=n>{} Pa</td><td class=n>{}</td></tr>\
             <tr><td>measured − modelled P2</td><td class=n>{} Pa</td><td class=n>{}</td></tr></table>",
            newtons(&split["force_vs_pressures_rms_N"]),
            number(&split["force_vs_pressures_ratio_to_noise"]).map_or_else(|| "—".into(), |x| format!("{x:.2}")),
            pair(&split["pressures_vs_model_rms_Pa"], 0, 0),
            pair(&split["pressures_vs_model_ratio_to_noise"], 0, 2),
            pair(&split["pressures_vs_model_rms_Pa"], 1, 0),
            pair(&split["pressures_vs_model_ratio_to_noise"], 1, 2),
        ));
    }
    html.push_str("<h2>Input checks</h2>");
    let checks: Vec<&str> = report["input_checks"]
        .as_array()
        .map(|a| a.iter().filter_map(Value::as_str).collect())
        .unwrap_or_default();
    if checks.is_empty() {
        html.push_str("<p>The file raised no doubt.</p>");
    } else {
        html.push_str("<ul>");
        for c in checks {
            html.push_str(&format!("<li>{}</li>", escape(c)));
        }
        html.push_str("</ul>");
    }
    html
}

fn localization_section(report: &Value) -> String {
    let Some(rows) = report["localization"]["by_location"].as_array() else {
        return String::new();
    };
    let mut html = String::from(
        "<h2>Where the last round placed the misfit</h2><table><tr><th>place</th><th>share of the held-out misfit its best candidate removes</th><th>that candidate</th></tr>",
    );
    for r in rows {
        html.push_str(&format!(
            "<tr><td>{}</td><td class=n>{}</td><td>{}</td></tr>",
            escape(r["location"].as_str().unwrap_or("?")),
            percent(&r["explained_share_heldout"]),
            escape(r["best_candidate"].as_str().unwrap_or("")),
        ));
    }
    html.push_str("</table>");
    html
}

fn figures_section(figures: &[Figure]) -> String {
    let mut html = String::from("<h2>Figures</h2>");
    for f in figures {
        // The SVG is inlined as an element of the page: its XML declaration, if any, goes.
        let svg = f.svg.trim_start_matches(|c| c != '<');
        let svg = if svg.starts_with("<?xml") {
            svg.split_once("?>").map_or(svg, |(_, rest)| rest)
        } else {
            svg
        };
        html.push_str(&format!(
            "<figure id=\"figure-{}\"><h3>{}</h3>{}<figcaption>{}</figcaption></figure>",
            f.name,
            escape(&f.title),
            svg.trim(),
            escape(&f.caption)
        ));
    }
    html
}

/// A verdict in words, for a title or a table.
pub fn verdict_words(verdict: &str) -> &'static str {
    match verdict {
        "explained" => "explained",
        "unexplained_remainder" => "not explained: a remainder stays",
        _ => "failed",
    }
}

/// The page of one recording's diagnosis, from its JSON report; `report_file` is the report's
/// file name beside the page, `index` the index's relative path (when there is one).
pub fn page(name: &str, report: &Value, figures: &[Figure], report_file: &str, index: Option<&str>) -> String {
    let verdict = report["verdict"].as_str().unwrap_or("");
    let summary: Vec<&str> = report["summary"]
        .as_array()
        .map(|a| a.iter().filter_map(Value::as_str).collect())
        .unwrap_or_default();
    let mut html = format!(
        "<!DOCTYPE html><html lang=en><head><meta charset=utf-8><title>{name}: {words}</title>\
         <meta name=viewport content=\"width=device-width, initial-scale=1\"><style>{STYLE}</style></head><body>\
         <h1>Diagnosis of {name}</h1><p id=verdict><span class=\"verdict {verdict}\">{words}</span> \
         {samples} samples.</p><p id=verdict-sentence>{sentence}</p>",
        name = escape(name),
        words = verdict_words(verdict),
        verdict = escape(verdict),
        samples = report["samples"].as_u64().unwrap_or(0),
        sentence = escape(summary.first().copied().unwrap_or("")),
    );
    html.push_str(&errors_section(report));
    html.push_str(&additions_section(report));
    html.push_str(&remainder_section(report));
    html.push_str(&figures_section(figures));
    html.push_str(&start_values_section(report));
    html.push_str(&split_and_checks_section(report));
    html.push_str(&localization_section(report));
    html.push_str(&format!(
        "<h2>The report</h2><p>Every number of this page is in <a href=\"{r}\">{r}</a>; the fields are described \
         in the project's docs/diagnosis.md.{}</p></body></html>\n",
        index.map_or_else(String::new, |i| format!(
            " <a href=\"{}\">All recordings</a>.",
            escape(i)
        )),
        r = escape(report_file),
    ));
    html
}

/// One recording's line of a batch: its summary row and where its page is.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SummaryRow {
    pub name: String,
    /// `explained`, `unexplained_remainder`, or `error`.
    pub verdict: String,
    pub noise_floor_n: Option<f64>,
    pub heldout_before_n: Option<f64>,
    pub heldout_after_n: Option<f64>,
    pub whole_before_n: Option<f64>,
    pub whole_after_n: Option<f64>,
    /// What was added, `; `-separated: named effects by name, discovered terms as
    /// `location/family: parameters`.
    pub added: String,
    /// Where the remainder was placed (`location/family`, with `channel`), empty when none.
    pub remainder_location: String,
    /// The page and the report, relative to the batch directory (empty on error).
    pub page: String,
    pub report: String,
    /// Why the recording could not be diagnosed.
    pub error: String,
}

impl SummaryRow {
    /// The row of a diagnosed recording, from its JSON report.
    pub fn from_report(name: &str, report: &Value, page: &str, report_file: &str) -> Self {
        let mut added: Vec<String> = report["effects"]
            .as_array()
            .map(|a| {
                a.iter()
                    .filter_map(|e| e["name"].as_str().map(str::to_string))
                    .collect()
            })
            .unwrap_or_default();
        if let Some(terms) = report["discovered"].as_array() {
            for d in terms {
                let names: Vec<&str> = d["parameters"]
                    .as_object()
                    .map(|o| o.keys().map(String::as_str).collect())
                    .unwrap_or_default();
                added.push(format!(
                    "{}/{}: {}",
                    d["location"].as_str().unwrap_or("?"),
                    d["family"].as_str().unwrap_or("?"),
                    names.join(" ")
                ));
            }
        }
        let u = &report["unexplained"];
        Self {
            name: name.to_string(),
            verdict: report["verdict"].as_str().unwrap_or("").to_string(),
            noise_floor_n: number(&report["noise_floor_N"]),
            heldout_before_n: number(&report["heldout"]["before_rms_N"]),
            heldout_after_n: number(&report["heldout"]["after_rms_N"]),
            whole_before_n: number(&report["before"]["force_rms_N"]),
            whole_after_n: number(&report["after"]["force_rms_N"]),
            added: added.join("; "),
            remainder_location: if u.is_null() {
                String::new()
            } else {
                format!(
                    "{}/{} ({})",
                    u["location"].as_str().unwrap_or("?"),
                    u["family"].as_str().unwrap_or("?"),
                    u["channel"].as_str().unwrap_or("force")
                )
            },
            page: page.to_string(),
            report: report_file.to_string(),
            error: String::new(),
        }
    }

    /// The row of a recording that could not be diagnosed.
    pub fn failed(name: &str, error: &str) -> Self {
        Self {
            name: name.to_string(),
            verdict: "error".into(),
            error: error.to_string(),
            ..Self::default()
        }
    }
}

/// The index page of a batch: a table of the rows, linking each page; `timing` says how long
/// the batch took (empty when unknown).
pub fn index(rows: &[SummaryRow], timing: &str) -> String {
    let cell = |x: Option<f64>| x.map_or_else(|| "—".into(), |v| format!("{v:.4}"));
    let mut html = format!(
        "<!DOCTYPE html><html lang=en><head><meta charset=utf-8><title>Diagnoses of {n} recordings</title>\
         <meta name=viewport content=\"width=device-width, initial-scale=1\"><style>{STYLE}</style></head><body class=wide>\
         <h1>Diagnoses of {n} recordings</h1><p>{explained} explained, {remainder} with a remainder, {failed} \
         failed{timing}. The same table is in <a href=\"summary.csv\">summary.csv</a>.</p>\
         <table id=summary><tr><th>recording</th><th>verdict</th><th>noise floor (N)</th><th>held-out before (N)</th>\
         <th>held-out after (N)</th><th>whole before (N)</th><th>whole after (N)</th><th>added</th><th>remainder at</th></tr>",
        n = rows.len(),
        explained = rows.iter().filter(|r| r.verdict == "explained").count(),
        remainder = rows.iter().filter(|r| r.verdict == "unexplained_remainder").count(),
        failed = rows.iter().filter(|r| r.verdict == "error").count(),
        timing = if timing.is_empty() {
            String::new()
        } else {
            format!("; {}", escape(timing))
        },
    );
    for r in rows {
        let name = if r.page.is_empty() {
            escape(&r.name)
        } else {
            format!("<a href=\"{}\">{}</a>", escape(&r.page), escape(&r.name))
        };
        html.push_str(&format!(
            "<tr><td>{name}</td><td><span class=\"verdict {v}\">{words}</span></td><td class=n>{}</td><td class=n>{}</td>\
             <td class=n>{}</td><td class=n>{}</td><td class=n>{}</td><td>{}</td><td>{}</td></tr>",
            cell(r.noise_floor_n),
            cell(r.heldout_before_n),
            cell(r.heldout_after_n),
            cell(r.whole_before_n),
            cell(r.whole_after_n),
            escape(if r.error.is_empty() { &r.added } else { &r.error }),
            escape(&r.remainder_location),
            v = escape(&r.verdict),
            words = verdict_words(&r.verdict),
        ));
    }
    html.push_str("</table></body></html>\n");
    html
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escaping_leaves_no_markup_of_the_text() {
        assert_eq!(escape("a<b & \"c\" 'd'>"), "a&lt;b &amp; &quot;c&quot; &#39;d&#39;&gt;");
    }

    #[test]
    fn a_report_with_a_discovered_term_gives_a_row_naming_its_place_and_parameters() {
        let report = serde_json::json!({
            "verdict": "explained", "noise_floor_N": 0.05,
            "heldout": {"before_rms_N": 3.4, "after_rms_N": 0.05},
            "before": {"force_rms_N": 3.5}, "after": {"force_rms_N": 0.051},
            "effects": [{"name": "piston_friction"}],
            "discovered": [{"location": "current_driver", "family": "parameter_offset",
                            "parameters": {"k_cd": 0.036, "i_offset": 0.0}}],
        });
        let row = SummaryRow::from_report("u_kcd_gain", &report, "u_kcd_gain.html", "u_kcd_gain.json");
        assert_eq!(
            row.added,
            "piston_friction; current_driver/parameter_offset: i_offset k_cd"
        );
        assert_eq!(row.heldout_after_n, Some(0.05));
        assert!(row.remainder_location.is_empty());
    }

    #[test]
    fn a_withdrawal_that_keeps_an_earlier_round_names_what_went_and_what_stayed() {
        let mut report = serde_json::json!({
            "heldout": {"before_rms_N": 1.1441}, "before": {"force_rms_N": 1.0067},
            "effects": [], "discovered": [{"location": "command", "family": "nonlinearity", "parameters": {}}],
            "withdrawn": {"names": ["x_jp_offset varying with v_DA"], "heldout_with_rms_N": 0.9566,
                          "whole_with_rms_N": 1.168, "kept": ["command static curve"]},
        });
        let html = additions_section(&report);
        assert!(html.contains("Withdrawn: x_jp_offset varying with v_DA."), "{html}");
        assert!(
            html.contains("1.1680 N over the whole recording, worse than the starting model's 1.1441 N and 1.0067 N"),
            "{html}"
        );
        assert!(
            html.contains("the model reported keeps command static curve as an earlier round fitted them"),
            "{html}"
        );
        report["withdrawn"]["kept"] = serde_json::json!([]);
        let html = additions_section(&report);
        assert!(html.contains("the model reported is the starting model"), "{html}");
    }
}
