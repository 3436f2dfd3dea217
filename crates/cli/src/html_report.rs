//! The HTML page of a diagnosis, and the index of a batch's pages.
//!
//! A page is self-contained: its style and its figures (SVG) are inline, and it loads nothing,
//! from the network or from disk, so it can be mailed or archived alone. It is written from
//! the JSON report (the fields of docs/diagnosis.md, "The report"), so the page and the report
//! cannot say different things.

use serde_json::Value;

use jetpipe_model::physics::modulation::ModulationSignal;

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
th{background:#f3f3f3}td.n{text-align:right;font-variant-numeric:tabular-nums;white-space:nowrap}
summary{cursor:pointer;color:#444}details{margin:.5em 0}
.verdict{display:inline-block;padding:.2em .7em;border-radius:.3em;font-weight:bold;color:#fff}
.explained{background:#2b7a2b}.unexplained_remainder{background:#b3541e}.error{background:#a11}
pre{background:#f6f6f6;padding:.7em;overflow-x:auto}figure{margin:1.2em 0}figure svg{max-width:100%;height:auto}
figcaption{font-size:.9em;color:#444}body.wide{max-width:1400px}#summary td{font-size:.9em}";

fn number(v: &Value) -> Option<f64> {
    v.as_f64()
}

/// The prefixed forms of an SI unit a person reads, largest first, each with its factor; the
/// unit itself (factor 1) is among them. Units without a sensible prefix have none.
fn prefixes(unit: &str) -> &'static [(f64, &'static str)] {
    match unit {
        "Pa" => &[(1e6, "MPa"), (1e3, "kPa"), (1.0, "Pa")],
        "Pa/s" => &[(1e6, "MPa/s"), (1e3, "kPa/s"), (1.0, "Pa/s")],
        "m" => &[(1.0, "m"), (1e-3, "mm"), (1e-6, "µm"), (1e-9, "nm")],
        "m/s" => &[(1.0, "m/s"), (1e-3, "mm/s"), (1e-6, "µm/s")],
        "m2" => &[(1.0, "m²"), (1e-6, "mm²")],
        "m3" => &[(1.0, "m³"), (1e-6, "cm³"), (1e-9, "mm³")],
        "s" => &[(1.0, "s"), (1e-3, "ms"), (1e-6, "µs"), (1e-9, "ns")],
        "N" => &[(1.0, "N"), (1e-3, "mN")],
        "N/m" => &[(1e3, "kN/m"), (1.0, "N/m")],
        "m/N" => &[(1.0, "m/N"), (1e-3, "mm/N"), (1e-6, "µm/N")],
        "A" => &[(1.0, "A"), (1e-3, "mA"), (1e-6, "µA")],
        "V" => &[(1.0, "V"), (1e-3, "mV"), (1e-6, "µV")],
        "kg" => &[(1.0, "kg"), (1e-3, "g"), (1e-6, "mg")],
        "kg/s" => &[(1.0, "kg/s"), (1e-3, "g/s"), (1e-6, "mg/s")],
        "Hz" => &[(1e3, "kHz"), (1.0, "Hz")],
        _ => &[],
    }
}

/// A unit as the model writes it (`m3`, `N.s2/m2`, `kg/(s.Pa)`) as it is printed: powers as
/// superscripts, products with a middle dot (`m³`, `N·s²/m²`, `kg/(s·Pa)`).
fn unit_for_people(unit: &str) -> String {
    let mut out = String::with_capacity(unit.len());
    let mut after_letter = false;
    for c in unit.chars() {
        match c {
            '0'..='9' if after_letter => out.push(superscript(c)),
            '.' => out.push('·'),
            c => {
                out.push(c);
                after_letter = c.is_alphabetic();
            }
        }
    }
    out
}

fn superscript(c: char) -> char {
    match c {
        '0' => '⁰',
        '1' => '¹',
        '2' => '²',
        '3' => '³',
        '4' => '⁴',
        '5' => '⁵',
        '6' => '⁶',
        '7' => '⁷',
        '8' => '⁸',
        '9' => '⁹',
        '-' => '⁻',
        c => c,
    }
}

/// `x` (≥ 0) rounded to `digits` significant figures, and the decimal exponent of the result.
fn rounded(x: f64, digits: usize) -> (f64, i32) {
    let text = format!("{:.*e}", digits.saturating_sub(1), x);
    let (_, exponent) = text.split_once('e').unwrap_or((&text, "0"));
    (text.parse().unwrap_or(x), exponent.parse().unwrap_or(0))
}

/// A non-negative number in fixed notation with `decimals`, its whole part grouped by
/// thousands with a narrow no-break space (`652 925`).
fn grouped(x: f64, decimals: usize) -> String {
    let text = format!("{x:.decimals$}");
    let (whole, fraction) = text
        .split_once('.')
        .map_or((text.as_str(), None), |(w, f)| (w, Some(f)));
    let mut out = String::new();
    for (k, c) in whole.chars().enumerate() {
        if k > 0 && (whole.len() - k) % 3 == 0 {
            out.push('\u{202f}');
        }
        out.push(c);
    }
    if let Some(fraction) = fraction {
        out.push('.');
        out.push_str(fraction);
    }
    out
}

/// An amount with its unit (the model's SI unit: `"Pa"`, `"m3"`, `"1"` or `""` for a number),
/// as a person reads it, with `digits` significant figures: a true minus sign, an SI prefix
/// where the unit takes one (`652.9 kPa`, `44.00 mm`, `25.00 µs`, `1.500 cm³`), fixed notation
/// grouped by thousands from 0.001 to a million of the unit printed, and beyond that only,
/// `3.200 × 10⁻⁹ kg/(s·Pa)`. Zero is `0`; a whole number without a unit (a count, a code) is
/// written whole.
pub fn amount_to(value: f64, unit: &str, digits: usize) -> String {
    let digits = digits.max(1);
    let dimensionless = unit.is_empty() || unit == "1";
    let printed_unit = unit_for_people(unit);
    let with_unit = |number: String, unit: &str| {
        if dimensionless {
            number
        } else {
            format!("{number} {unit}")
        }
    };
    let sign = if value < 0.0 { "−" } else { "" };
    if value.is_nan() {
        return with_unit("NaN".into(), &printed_unit);
    }
    if value.is_infinite() {
        return with_unit(format!("{sign}∞"), &printed_unit);
    }
    if value == 0.0 {
        return with_unit("0".into(), &printed_unit);
    }
    let magnitude = value.abs();
    if dimensionless && magnitude.fract() == 0.0 && magnitude < 1e6 {
        return format!("{sign}{}", grouped(magnitude, 0));
    }
    let (rounded_magnitude, _) = rounded(magnitude, digits);
    let scales = prefixes(unit);
    // The largest prefix under which the rounded amount is at least one.
    let (factor, prefixed) = scales
        .iter()
        .find(|(factor, _)| rounded_magnitude >= factor * (1.0 - 1e-12))
        .or(scales.last())
        .map_or((1.0, printed_unit.as_str()), |&(factor, name)| (factor, name));
    let mantissa = magnitude / factor;
    let (rounded_mantissa, exponent) = rounded(mantissa, digits);
    if (1e-3..1e6).contains(&rounded_mantissa) {
        let decimals = (digits as i32 - 1 - exponent).max(0) as usize;
        // Above a thousand, the whole number: rounding 652 925 to 653 000 would only hide digits.
        let shown = if decimals == 0 { mantissa } else { rounded_mantissa };
        return with_unit(format!("{sign}{}", grouped(shown, decimals)), prefixed);
    }
    let (rounded_magnitude, exponent) = rounded(magnitude, digits);
    let significand = rounded_magnitude / 10f64.powi(exponent);
    let power: String = exponent.to_string().chars().map(superscript).collect();
    with_unit(format!("{sign}{significand:.*} × 10{power}", digits - 1), &printed_unit)
}

/// [`amount_to`] with four significant figures: `−10.00 V`, `652.9 kPa`, `0.8500`.
pub fn amount(value: f64, unit: &str) -> String {
    amount_to(value, unit, 4)
}

/// The exact value of an amount, as the JSON report holds it, in its SI unit: a cell's title.
fn exact(value: f64, unit: &str) -> String {
    if unit.is_empty() || unit == "1" {
        format!("{value:?}")
    } else {
        format!("{value:?} {unit}")
    }
}

/// A value in N with four decimals, or a dash; below 0.01 N or from 10 000 N on, as
/// [`amount`] writes it (`4.900 mN` rather than `0.0049 N`).
fn newtons(v: &Value) -> String {
    number(v).map_or_else(
        || "—".into(),
        |x| {
            if x == 0.0 || (0.01..1e4).contains(&x.abs()) {
                format!("{x:.4} N").replace('-', "−")
            } else {
                amount(x, "N")
            }
        },
    )
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

/// The variable of the table with value reference `code` (a modulation slot's constant).
fn variable_of_code(code: f64) -> Option<&'static jetpipe_model::variable::Variable> {
    jetpipe_model::variables::VARIABLES
        .iter()
        .find(|v| code.fract() == 0.0 && f64::from(v.value_reference) == code)
}

/// What a modulation or flexible slot's setting `name` is in, from the slot's other settings
/// in `parameters`: a knot's abscissa in the unit of the slot's signal (a flexible slot's
/// `x1_j` of its first signal, `x2_j` of its second), its increment in the unit of the
/// constant it modulates (the variable table writes "1" for all).
fn slot_unit(name: &str, parameters: &serde_json::Map<String, Value>) -> Option<&'static str> {
    let (kind, rest) = if let Some(rest) = name.strip_prefix("modulation_") {
        ("modulation", rest)
    } else {
        ("flexible", name.strip_prefix("flexible_")?)
    };
    let (slot, setting) = rest.split_once('_')?;
    let code = |what: &str| number(parameters.get(&format!("{kind}_{slot}_{what}"))?);
    let signal = match setting {
        s if kind == "modulation" && s.starts_with("x_") => Some("signal"),
        s if s.starts_with("x1_") => Some("signal_1"),
        s if s.starts_with("x2_") => Some("signal_2"),
        _ => None,
    };
    if let Some(signal) = signal {
        ModulationSignal::from_code(code(signal)?).map(ModulationSignal::unit)
    } else if setting.starts_with("y_") {
        variable_of_code(code("parameter")?)?.unit
    } else if setting.starts_with("lag_") {
        Some("s")
    } else {
        None
    }
}

/// What a modulation or flexible slot's code names: its signal, or the constant it modulates.
fn slot_code_name(name: &str, value: f64) -> Option<&'static str> {
    let rest = name
        .strip_prefix("modulation_")
        .or_else(|| name.strip_prefix("flexible_"))?;
    let (_, setting) = rest.split_once('_')?;
    match setting {
        "signal" | "signal_1" | "signal_2" => ModulationSignal::from_code(value).map(ModulationSignal::name),
        "parameter" => variable_of_code(value).map(|v| v.name),
        _ => None,
    }
}

/// Tables of more rows than this fold under the sentence that states them.
const FOLD_ROWS: usize = 8;

/// An addition's parameters with, where the report has them (`intervals_95`,
/// `interval_method`), their 95 % intervals: a column that reports written before intervals
/// do not get.
fn parameters_table(addition: &Value, units: Option<&Value>) -> String {
    let Some(object) = addition["parameters"].as_object() else {
        return String::new();
    };
    let intervals = addition["intervals_95"].as_object();
    let mut rows = String::new();
    for (name, value) in object {
        let unit = slot_unit(name, object)
            .or_else(|| units.and_then(|u| u.get(name)).and_then(Value::as_str))
            .unwrap_or_else(|| unit_of(name));
        let cell = match number(value) {
            Some(x) => format!(
                "<td class=n title=\"{}\">{}{}</td>",
                escape(&exact(x, unit)),
                escape(&amount(x, unit)),
                slot_code_name(name, x).map_or_else(String::new, |n| format!(" ({})", escape(n)))
            ),
            None => format!("<td class=n>{}</td>", escape(&value.to_string())),
        };
        let interval = intervals.map(|i| {
            let bounds = i.get(name).and_then(Value::as_array);
            match bounds.and_then(|b| Some((number(b.first()?)?, number(b.get(1)?)?))) {
                Some((low, high)) => format!(
                    "<td class=n title=\"{} to {}, from the {}\">{} to {}</td>",
                    escape(&exact(low, unit)),
                    escape(&exact(high, unit)),
                    match addition["interval_method"][name].as_str() {
                        Some("heldout_blocks") => "spread over the held-out blocks",
                        _ => "curvature of the fit",
                    },
                    escape(&amount(low, unit)),
                    escape(&amount(high, unit)),
                ),
                None => "<td class=n>—</td>".to_string(),
            }
        });
        rows.push_str(&format!(
            "<tr><td><code>{}</code></td>{cell}{}</tr>",
            escape(name),
            interval.unwrap_or_default()
        ));
    }
    let table = format!(
        "<table><tr><th>parameter</th><th>value</th>{}</tr>{rows}</table>",
        if intervals.is_some() {
            "<th>95 % interval</th>"
        } else {
            ""
        }
    );
    if object.len() > FOLD_ROWS {
        format!(
            "<details><summary>the {} parameters that carry it</summary>{table}</details>",
            object.len()
        )
    } else {
        table
    }
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
            " Noise floors of the pressures: P1 {}, P2 {}.",
            amount(p1, "Pa"),
            amount(p2, "Pa")
        ));
    }
    html.push_str("</p>");
    let pressures = |v: &Value| -> Option<String> {
        let a = v.as_array()?;
        Some(format!(
            "P1 {}, P2 {}",
            amount(a.first()?.as_f64()?, "Pa"),
            amount(a.get(1)?.as_f64()?, "Pa")
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

/// A joint diagnosis's recordings, each replayed alone with the starting and the joint
/// model, and what the joining says (none for a diagnosis of one recording).
fn recordings_section(report: &Value) -> String {
    let Some(recordings) = report["recordings"].as_array() else {
        return String::new();
    };
    let mut html = String::from(
        "<h2>Each recording under the joint model</h2><table id=recordings><tr><th>recording</th><th>rate</th>\
         <th>noise floor</th><th>held-out force error before</th><th>after</th><th>after / noise floor</th>\
         <th>within its noise</th><th>holds</th></tr>",
    );
    for r in recordings {
        let holds: Vec<String> = r["holds"]
            .as_array()
            .map(|a| a.iter().filter_map(Value::as_str).map(escape).collect())
            .unwrap_or_default();
        html.push_str(&format!(
            "<tr><td>{}</td><td class=n>{}</td><td class=n>{}</td><td class=n>{}</td><td class=n>{}</td>\
             <td class=n>{}</td><td>{}</td><td>{}</td></tr>",
            escape(r["recording"].as_str().unwrap_or("")),
            number(&r["rate_Hz"]).map_or_else(|| "—".into(), |x| amount(x, "Hz")),
            newtons(&r["noise_floor_N"]),
            newtons(&r["before"]["heldout_force_rms_N"]),
            newtons(&r["after"]["heldout_force_rms_N"]),
            number(&r["heldout_noise_floors"]["after"]).map_or_else(|| "—".into(), |x| format!("{x:.1}×")),
            if r["explained"].as_bool() == Some(true) {
                "yes"
            } else {
                "no"
            },
            if holds.is_empty() {
                "—".to_string()
            } else {
                holds.join(", ")
            },
        ));
    }
    html.push_str("</table>");
    let notes: Vec<String> = report["joint"]["notes"]
        .as_array()
        .map(|a| a.iter().filter_map(Value::as_str).map(escape).collect())
        .unwrap_or_default();
    if !notes.is_empty() {
        html.push_str(&format!("<ul id=joint-notes><li>{}</li></ul>", notes.join("</li><li>")));
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
        html.push_str(&parameters_table(e, None));
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
        html.push_str(&margin_sentence(e));
    }
    for d in &discovered {
        html.push_str(&format!(
            "<h3>Discovered term: {} at the {} ({})</h3><p>{}</p>",
            escape(d["candidate"].as_str().unwrap_or("?")),
            escape(d["location"].as_str().unwrap_or("?")),
            escape(d["family"].as_str().unwrap_or("?")),
            escape(d["reading"].as_str().unwrap_or("")),
        ));
        html.push_str(&parameters_table(d, Some(&d["units"])));
        html.push_str(&format!(
            "<p>Held-out force error {} → {}: it removes {} of the held-out mean square.</p>",
            newtons(&d["heldout_before_rms_N"]),
            newtons(&d["heldout_after_rms_N"]),
            percent(&d["share_of_heldout_explained"]),
        ));
        html.push_str(&margin_sentence(d));
    }
    let joint = &report["joint_refit"];
    if let (Some(_), Some(_)) = (
        number(&joint["heldout_before_rms_N"]),
        number(&joint["heldout_after_rms_N"]),
    ) {
        html.push_str(&format!(
            "<p>Refitted together, the added parameters lower the held-out force error from {} to {} \
             (the values above are the refitted ones).</p>",
            newtons(&joint["heldout_before_rms_N"]),
            newtons(&joint["heldout_after_rms_N"]),
        ));
    }
    html
}

/// How clearly an addition's place won, from its `margin_noise_floors`; nothing without one.
fn margin_sentence(addition: &Value) -> String {
    match number(&addition["margin_noise_floors"]) {
        Some(m) if m >= 0.0 => format!(
            "<p class=margin>Its place won by a margin of {m:.2} noise floors: the next-best place's best candidate left that much more of the held-out error.</p>"
        ),
        Some(m) => format!(
            "<p class=margin>Its place was not the best of its round: another place's best candidate left {:.2} noise floors less of the held-out error.</p>",
            -m
        ),
        None => String::new(),
    }
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
         <tr><th>RMS</th><td>{} ({:.1}× the noise floor)</td></tr>{}</table>",
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
        number(&u["margin_noise_floors"]).map_or_else(String::new, |m| format!(
            "<tr><th>margin</th><td>{m:.2} noise floors of held-out error over the next-best place</td></tr>"
        )),
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
        let ratio = |v: &Value, k: usize| {
            v.get(k)
                .and_then(Value::as_f64)
                .map_or_else(|| "—".into(), |x| format!("{x:.2}"))
        };
        let pascals = |v: &Value, k: usize| {
            v.get(k)
                .and_then(Value::as_f64)
                .map_or_else(|| "—".into(), |x| amount(x, "Pa"))
        };
        html.push_str(&format!(
            "<table><tr><th></th><th>RMS</th><th>in noise floors</th></tr>\
             <tr><td>measured force − force of the measured pressures</td><td class=n>{}</td><td class=n>{}</td></tr>\
             <tr><td>measured − modelled P1</td><td class=n>{}</td><td class=n>{}</td></tr>\
             <tr><td>measured − modelled P2</td><td class=n>{}</td><td class=n>{}</td></tr></table>",
            newtons(&split["force_vs_pressures_rms_N"]),
            number(&split["force_vs_pressures_ratio_to_noise"]).map_or_else(|| "—".into(), |x| format!("{x:.2}")),
            pascals(&split["pressures_vs_model_rms_Pa"], 0),
            ratio(&split["pressures_vs_model_ratio_to_noise"], 0),
            pascals(&split["pressures_vs_model_rms_Pa"], 1),
            ratio(&split["pressures_vs_model_ratio_to_noise"], 1),
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
    html.push_str(&glitches_table(report));
    html
}

/// The glitches of the recording, each where it is (marked on the residual figure too).
fn glitches_table(report: &Value) -> String {
    let Some(rows) = report["glitches"].as_array().filter(|a| !a.is_empty()) else {
        return String::new();
    };
    let mut html = String::from(
        "<h3>Glitches in the data</h3><table><tr><th>kind</th><th>column</th><th>from (s)</th><th>to (s)</th><th>samples</th><th>set aside</th></tr>",
    );
    for g in rows {
        html.push_str(&format!(
            "<tr><td>{}</td><td>{}</td><td class=n>{}</td><td class=n>{}</td><td class=n>{}</td><td>{}</td></tr>",
            escape(g["kind"].as_str().unwrap_or("?")),
            escape(g["column"].as_str().unwrap_or("?")),
            number(&g["from_s"]).map_or_else(|| "—".into(), |x| format!("{x:.4}")),
            number(&g["to_s"]).map_or_else(|| "—".into(), |x| format!("{x:.4}")),
            g["samples"].as_u64().map_or_else(|| "—".into(), |x| x.to_string()),
            if g["set_aside"].as_bool() == Some(true) {
                "yes"
            } else {
                "no"
            },
        ));
    }
    html.push_str("</table>");
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
    html.push_str(&recordings_section(report));
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
    fn amounts_read_with_a_true_minus_an_si_prefix_and_four_significant_figures() {
        assert_eq!(amount(-10.0, "V"), "−10.00 V");
        assert_eq!(amount(652_925.0, "Pa"), "652.9 kPa");
        assert_eq!(amount(-1.2e7, "Pa"), "−12.00 MPa");
        assert_eq!(
            amount(999.96, "Pa"),
            "1.000 kPa",
            "the rounding carries into the prefix"
        );
        assert_eq!(amount(2.5e-5, "s"), "25.00 µs");
        assert_eq!(amount(0.044, "m"), "44.00 mm");
        assert_eq!(amount(1.5e-6, "m3"), "1.500 cm³");
        assert_eq!(amount(3.2e-8, "m3"), "32.00 mm³");
        assert_eq!(amount(3.14e-4, "m2"), "314.0 mm²");
        assert_eq!(amount(0.0123, "N"), "12.30 mN");
        assert_eq!(amount(-0.0042, "A"), "−4.200 mA");
        assert_eq!(amount(2.1e-3, "kg/s"), "2.100 g/s");
        assert_eq!(amount(2.1e-4, "kg/s"), "210.0 mg/s");
        assert_eq!(amount(5.0e4, "N/m"), "50.00 kN/m");
        assert_eq!(amount(4.998e-5, "m/N"), "49.98 µm/N");
    }

    #[test]
    fn zero_and_plain_numbers_and_whole_counts_read_plainly() {
        assert_eq!(amount(0.0, "Pa"), "0 Pa");
        assert_eq!(amount(-0.0, "V"), "0 V");
        assert_eq!(amount(0.0, "1"), "0");
        assert_eq!(amount(0.85, "1"), "0.8500");
        assert_eq!(amount(1.234, ""), "1.234");
        assert_eq!(amount(-0.001234, "1"), "−0.001234");
        assert_eq!(amount(125.0, "1"), "125", "a code is written whole");
        assert_eq!(amount(12_345.6, "1"), "12\u{202f}346");
        assert_eq!(amount(1500.0, "N"), "1\u{202f}500 N", "newtons take no kilo");
        assert_eq!(amount(293.15, "K"), "293.1 K");
    }

    #[test]
    fn compound_units_and_amounts_beyond_every_prefix_fall_back_to_powers_of_ten() {
        assert_eq!(amount(3.2e-9, "kg/(s.Pa)"), "3.200 × 10⁻⁹ kg/(s·Pa)");
        assert_eq!(amount(-4.5e-7, "1/N2"), "−4.500 × 10⁻⁷ 1/N²");
        assert_eq!(amount(120.5, "N.s/m"), "120.5 N·s/m");
        assert_eq!(amount(1e-15, "m"), "1.000 × 10⁻¹⁵ m");
        assert_eq!(amount(1.5e12, "Pa"), "1.500 × 10¹² Pa");
        assert_eq!(amount(6.02214e23, "1"), "6.022 × 10²³");
        assert_eq!(amount(9.0e-4, ""), "9.000 × 10⁻⁴");
        assert_eq!(amount_to(-10.0, "V", 2), "−10 V");
        assert_eq!(amount(f64::NAN, "N"), "NaN N");
    }

    #[test]
    fn a_parameters_cell_shows_the_amount_and_keeps_the_exact_value_in_its_title() {
        let table = parameters_table(
            &serde_json::json!({"parameters": {"P_s": 652_925.123_456_789, "C_d": 0.85}}),
            None,
        );
        assert!(
            table.contains("<td class=n title=\"652925.123456789 Pa\">652.9 kPa</td>"),
            "{table}"
        );
        assert!(table.contains("<td class=n title=\"0.85\">0.8500</td>"), "{table}");
        assert!(!table.contains("e5"), "{table}");
    }

    #[test]
    fn the_parameters_table_gives_each_interval_in_the_amounts_unit_and_a_dash_where_there_is_none() {
        let addition = serde_json::json!({
            "parameters": {"force_sensor_lag": 0.009982, "command_curve_knots": 3},
            "intervals_95": {"force_sensor_lag": [0.00995, 0.01001], "command_curve_knots": null},
            "interval_method": {"force_sensor_lag": "heldout_blocks", "command_curve_knots": null},
            "margin_noise_floors": 1.234,
        });
        let table = parameters_table(&addition, None);
        assert!(table.contains("<th>95 % interval</th>"), "{table}");
        assert!(table.contains(">9.950 ms to 10.01 ms</td>"), "{table}");
        assert!(table.contains("from the spread over the held-out blocks"), "{table}");
        assert!(table.contains("<td class=n>—</td></tr>"), "{table}");
        assert!(margin_sentence(&addition).contains("a margin of 1.23 noise floors"));
        let older = parameters_table(&serde_json::json!({"parameters": {"k_cd": 0.036}}), None);
        assert!(!older.contains("interval"), "a report without intervals: {older}");
        assert_eq!(margin_sentence(&serde_json::json!({"margin_noise_floors": null})), "");
    }

    #[test]
    fn a_modulation_slots_knots_read_in_the_units_of_its_signal_and_of_its_constant() {
        let constant = jetpipe_model::variables::vr::F_JP_SAT;
        let table = parameters_table(
            &serde_json::json!({"parameters": {
                "modulation_1_parameter": constant, "modulation_1_signal": 5, "modulation_1_knots": 2,
                "modulation_1_x_1": 0.044, "modulation_1_y_1": -0.0235,
            }}),
            Some(&serde_json::json!({"modulation_1_x_1": "1", "modulation_1_y_1": "1"})),
        );
        assert_eq!(unit_of("F_jp_sat"), "N");
        assert!(table.contains("title=\"0.044 m\">44.00 mm</td>"), "{table}");
        assert!(table.contains("title=\"-0.0235 N\">−23.50 mN</td>"), "{table}");
        assert!(table.contains(&format!(">{constant} (F_jp_sat)</td>")), "{table}");
        assert!(table.contains(">5 (x_s)</td>"), "{table}");
    }

    #[test]
    fn a_long_knot_table_folds_under_its_reading_and_a_short_table_stays_open() {
        let mut knots = serde_json::Map::new();
        knots.insert("command_curve_knots".into(), 20.into());
        for k in 1..=20 {
            knots.insert(format!("command_curve_x_{k}"), (-10.0 + f64::from(k)).into());
            knots.insert(format!("command_curve_y_{k}"), (-9.5 + f64::from(k)).into());
        }
        let report = serde_json::json!({
            "verdict": "explained", "samples": 1000, "noise_floor_N": 0.05,
            "summary": ["The model explains the recording."],
            "heldout": {"before_rms_N": 3.4, "after_rms_N": 0.05},
            "before": {"force_rms_N": 3.5}, "after": {"force_rms_N": 0.051},
            "effects": [{"name": "sensor_offset_gain", "location": "force_sensor",
                         "evidence": "The force sensor reads 1.5 N high.",
                         "parameters": {"force_sensor_offset": 1.5, "force_sensor_gain": 1.04}}],
            "discovered": [{"location": "command", "family": "nonlinearity", "candidate": "command static curve",
                            "reading": "At the command (nonlinearity): the curve bends.",
                            "parameters": knots, "units": {}}],
        });
        let html = page("curve", &report, &[], "curve.json", None);
        let (open, close) = (html.find("<details>").unwrap(), html.find("</details>").unwrap());
        assert_eq!(html.matches("<details>").count(), 1, "only the knot table folds");
        let folded = &html[open..close];
        assert!(
            folded.contains("<summary>the 41 parameters that carry it</summary>"),
            "{folded}"
        );
        assert!(
            folded.contains("<code>command_curve_x_20</code>") && folded.contains("−9.000 V"),
            "{folded}"
        );
        let reading = html.find("the curve bends.").unwrap();
        assert!(reading < open, "the reading comes before its folded table");
        let effect = html.find("<code>force_sensor_offset</code>").unwrap();
        assert!(effect < open && html.find("<code>force_sensor_gain</code>").unwrap() < open);
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

    #[test]
    fn the_page_lists_each_glitch_and_says_nothing_of_glitches_when_there_are_none() {
        let report = serde_json::json!({
            "input_checks": [],
            "glitches": [
                {"kind": "spike", "column": "force_N", "from_s": 3.1234, "to_s": 3.1234, "samples": 1, "set_aside": true},
                {"kind": "gap", "column": "time_s", "from_s": 8.499, "to_s": 8.501, "samples": 1, "set_aside": false}
            ]
        });
        let html = split_and_checks_section(&report);
        assert!(html.contains("<h3>Glitches in the data</h3>"), "{html}");
        assert!(
            html.contains("<td>spike</td><td>force_N</td><td class=n>3.1234</td>"),
            "{html}"
        );
        assert!(html.contains("<td>gap</td><td>time_s</td><td class=n>8.4990</td><td class=n>8.5010</td><td class=n>1</td><td>no</td>"), "{html}");
        let clean = serde_json::json!({"input_checks": [], "glitches": []});
        assert!(!split_and_checks_section(&clean).contains("Glitches"));
    }
}
