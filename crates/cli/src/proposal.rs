//! `jetpipe propose`'s files: the protocol (`time_s, v_da_V, x_s_m`, nothing else, so that
//! every CSV reader and bench takes it), and beside it a JSON and a page that say which
//! explanations it separates and by how much.

use crate::html_report::escape;
use crate::plots::proposal_figure;
use jetpipe_diagnosis::propose::Proposal;
use serde_json::{json, Value};

/// What the proposal's figures compare with: stated on the page and in the JSON.
pub const CAVEAT: &str = "Each explanation is simulated as the report fitted it, not refitted to the others' \
predictions on this protocol: a difference that a refit would absorb counts here, so the figures bound what a \
diagnosis of the new recording can see from above.";

/// The proposal as JSON: its explanations, their predicted differences and its segments.
pub fn to_json(p: &Proposal, report: &str, protocol_file: &str, seed: u64) -> Value {
    let label = |k: usize| p.explanations[k].label.clone();
    let smallest = p.smallest();
    json!({
        "report": report,
        "protocol": protocol_file,
        "seconds": p.protocol.time.last().copied().unwrap_or(0.0),
        "rate_Hz": p.protocol.rate,
        "seed": seed,
        "report_verdict_explained": p.explained,
        "tied_locations": p.tied,
        "channels": p.channels.iter().zip(&p.noise).map(|(c, n)| json!({"name": c, "noise_floor": n})).collect::<Vec<_>>(),
        "explanations": p.explanations.iter().map(|e| json!({"label": e.label, "locations": e.places})).collect::<Vec<_>>(),
        "predicted_differences": p.differences.iter().map(|d| json!({
            "between": [label(d.first), label(d.second)],
            "noise_floors": d.noise_floors,
            "by_channel_noise_floors": p.channels.iter().zip(&d.by_channel).map(|(c, v)| (c.to_string(), json!(v))).collect::<serde_json::Map<_, _>>(),
        })).collect::<Vec<_>>(),
        "smallest_noise_floors": smallest.noise_floors,
        "closest_pair": [label(smallest.first), label(smallest.second)],
        "segments": p.segments.iter().map(|(t, what)| json!({"from_s": t, "what": what})).collect::<Vec<_>>(),
        "note": CAVEAT,
    })
}

/// The proposal's page: what it separates, by how much, and the protocol in a figure.
pub fn page(p: &Proposal, report: &str, protocol_file: &str) -> Result<String, String> {
    let forces: Vec<(String, &[f64])> = p
        .explanations
        .iter()
        .zip(&p.predicted)
        .map(|(e, readings)| (e.label.clone(), readings[0].as_slice()))
        .collect();
    let figure = proposal_figure(&p.protocol.time, &p.protocol.v_da, &p.protocol.x_s, &forces)?;
    let smallest = p.smallest();
    let rows_explanations: String = p
        .explanations
        .iter()
        .enumerate()
        .map(|(k, e)| {
            format!(
                "<tr><td>{}</td><td>{}</td><td>{}</td></tr>",
                k + 1,
                escape(&e.label),
                escape(&e.places.join(", "))
            )
        })
        .collect();
    let rows_differences: String = p
        .differences
        .iter()
        .map(|d| {
            let by: Vec<String> = p
                .channels
                .iter()
                .zip(&d.by_channel)
                .map(|(c, v)| format!("{c}: {v:.2}"))
                .collect();
            format!(
                "<tr><td>{} and {}</td><td>{:.2}</td><td>{}</td></tr>",
                d.first + 1,
                d.second + 1,
                d.noise_floors,
                escape(&by.join(", "))
            )
        })
        .collect();
    let rows_segments: String = p
        .segments
        .iter()
        .map(|(t, what)| format!("<tr><td>{t:.1} s</td><td>{}</td></tr>", escape(what)))
        .collect();
    let why = match (p.tied.is_empty(), p.explained) {
        (false, _) => format!("The report ties places ({}).", escape(&p.tied.join(", "))),
        (true, false) => "The report leaves a remainder.".to_string(),
        (true, true) => "The report explains the recording with no tie: this protocol checks its model against the next places of its ranking.".to_string(),
    };
    Ok(format!(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>What to record next: {protocol}</title>\
<style>body{{font-family:sans-serif;max-width:960px;margin:2em auto;line-height:1.4}}table{{border-collapse:collapse}}\
td,th{{border:1px solid #ccc;padding:4px 8px;text-align:left}}</style></head><body>\
<h1>What to record next</h1>\
<p>From <code>{report}</code>. {why} Play <code>{protocol}</code> ({seconds:.0} s at {rate:.0} Hz, open loop): \
the closest two explanations, {a} and {b}, are predicted to differ there by <b>{floors:.2} noise floors</b>.</p>\
<h2>The explanations</h2><table><tr><th></th><th>explanation</th><th>places</th></tr>{rows_explanations}</table>\
<h2>Predicted differences</h2><p>RMS over the protocol, in the noise floors the report measured \
(channels summed in quadrature).</p><table><tr><th>between</th><th>noise floors</th><th>by channel</th></tr>{rows_differences}</table>\
<p>{caveat}</p>\
<h2>{title}</h2><figure>{svg}<figcaption>{caption}</figcaption></figure>\
<h2>Segments</h2><table><tr><th>from</th><th>what</th></tr>{rows_segments}</table>\
</body></html>\n",
        protocol = escape(protocol_file),
        report = escape(report),
        seconds = p.protocol.time.last().copied().unwrap_or(0.0),
        rate = p.protocol.rate,
        a = smallest.first + 1,
        b = smallest.second + 1,
        floors = smallest.noise_floors,
        caveat = escape(CAVEAT),
        title = escape(&figure.title),
        svg = figure.svg,
        caption = escape(&figure.caption),
    ))
}
