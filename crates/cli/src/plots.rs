//! The figures of a diagnosis, as SVG text: the force over time, the residual before and
//! after in time and against the signal it follows, the force against the command (the loops
//! of Fig. 3.13), the pressure channels when the recording has them, the static curve of a
//! term that is one, and the shape of each flexible term. `jetpipe diagnose --plots DIR` writes them as files, the HTML page
//! inlines them.
//!
//! What a reader must be able to trust: the measured series is drawn last and semi-transparent,
//! so the model's curves cannot hide it; legends sit in a strip above the plot, off the data;
//! every axis names its unit; dense series are decimated (a min/max envelope per pixel column
//! for traces in time, every k-th sample for curves in a plane, at most `MAX_SCATTER` points
//! for a scatter), so a figure of an 80 000-sample recording stays under about 100 kB.

use jetpipe_diagnosis::vocabulary::{Family, Place};
use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use jetpipe_diagnosis::input::recording::Recording;
use jetpipe_diagnosis::replay::signals::ChainSignals;
use jetpipe_diagnosis::replay::signature::conditional_means;
use jetpipe_diagnosis::replay::{replay, Replay};
use jetpipe_diagnosis::Diagnosis;
use jetpipe_model::physics::actuator::Actuator;
use jetpipe_model::physics::command_stage;
use jetpipe_model::physics::current_driver::static_current;
use jetpipe_model::physics::jet_pipe::{tip_force, StaticCurve, F3};
use jetpipe_model::physics::parameters::Parameters;
use jetpipe_model::physics::sensors::{Channel, SensorLaw};

/// One figure: a file name without extension, a title, a caption saying what to look at.
#[derive(Clone, Debug)]
pub struct Figure {
    pub name: &'static str,
    pub title: String,
    pub caption: String,
    pub svg: String,
}

/// Pixel columns a trace in time is reduced to (two points each: its minimum and maximum).
const ENVELOPE_COLUMNS: usize = 700;
/// Points of a curve in a plane (every k-th sample, in time order).
const MAX_CURVE: usize = 2000;
/// Points of a scatter (before those that fall on the same pixels are dropped).
const MAX_SCATTER: usize = 1000;
/// The replay tolerance of the figures' pressures (the diagnosis's final replays use the same).
const REPLAY_TOLERANCE: f64 = 1e-5;

const MEASURED: RGBColor = RGBColor(0, 0, 0);
const BEFORE: RGBColor = RGBColor(214, 39, 40);
const AFTER: RGBColor = RGBColor(31, 119, 180);
const GLITCH: RGBColor = RGBColor(148, 103, 189);
const MEASURED_OPACITY: f64 = 0.45;
const WIDTH: u32 = 900;
const LEGEND_HEIGHT: u32 = 34;

type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;

fn fail(e: impl std::fmt::Display) -> String {
    format!("plotting failed: {e}")
}

/// The range of `values` with 5 % of margin on each side (1 on each side when flat).
fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
    if !lo.is_finite() {
        return (-1.0, 1.0);
    }
    if hi > lo {
        let pad = 0.05 * (hi - lo);
        (lo - pad, hi + pad)
    } else {
        let pad = (0.05 * lo.abs()).max(1e-9);
        (lo - pad, hi + pad)
    }
}

/// The smallest and largest finite value (a drawn curve spans the data, no more).
fn span(values: impl Iterator<Item = f64>) -> (f64, f64) {
    values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)))
}

/// The minimum and maximum of `y` in each of `columns` equal slices of the samples, in time
/// order: a trace drawn through them covers the same pixels as the full trace.
pub fn envelope(t: &[f64], y: &[f64], columns: usize) -> Vec<(f64, f64)> {
    let n = t.len().min(y.len());
    if n <= 2 * columns {
        return t.iter().zip(y).map(|(&a, &b)| (a, b)).collect();
    }
    let mut out = Vec::with_capacity(2 * columns);
    for c in 0..columns {
        let (a, b) = (c * n / columns, ((c + 1) * n / columns).max(c * n / columns + 1));
        let slice = &y[a..b];
        let (mut lo, mut hi) = (a, a);
        for (k, v) in slice.iter().enumerate() {
            if *v < y[lo] {
                lo = a + k;
            }
            if *v > y[hi] {
                hi = a + k;
            }
        }
        for k in if lo <= hi { [lo, hi] } else { [hi, lo] } {
            out.push((t[k], y[k]));
        }
    }
    out
}

/// Every k-th pair, at most `max` of them.
pub fn every_kth(x: &[f64], y: &[f64], max: usize) -> Vec<(f64, f64)> {
    let n = x.len().min(y.len());
    let step = n.div_ceil(max.max(1)).max(1);
    (0..n).step_by(step).map(|k| (x[k], y[k])).collect()
}

/// A series of a figure: its points, colour, opacity and label, drawn as a line (broken
/// where consecutive points are farther apart in x than `break_at`) or as dots of a radius.
struct Series {
    points: Vec<(f64, f64)>,
    colour: RGBColor,
    opacity: f64,
    label: String,
    /// Dots of this radius (pixels) instead of a line.
    dots: Option<u32>,
    width: u32,
    break_at: f64,
}

impl Series {
    fn line(points: Vec<(f64, f64)>, colour: RGBColor, label: impl Into<String>) -> Self {
        Self {
            points,
            colour,
            opacity: 1.0,
            label: label.into(),
            dots: None,
            width: 1,
            break_at: f64::INFINITY,
        }
    }
    fn measured(points: Vec<(f64, f64)>, label: impl Into<String>) -> Self {
        Self {
            opacity: MEASURED_OPACITY,
            ..Self::line(points, MEASURED, label)
        }
    }
    fn dots(points: Vec<(f64, f64)>, colour: RGBColor, opacity: f64, label: impl Into<String>) -> Self {
        Self {
            opacity,
            dots: Some(1),
            ..Self::line(points, colour, label)
        }
    }
    /// Binned means: large dots, not joined (a line between two distant bins would stand for
    /// samples that are not there).
    fn means(points: Vec<(f64, f64)>, colour: RGBColor, label: impl Into<String>) -> Self {
        Self {
            dots: Some(4),
            ..Self::line(points, colour, label)
        }
    }
    fn wide(self) -> Self {
        Self { width: 2, ..self }
    }
    /// Broken where x jumps by more than `gap` between consecutive points (a command step).
    fn broken_at(self, gap: f64) -> Self {
        Self { break_at: gap, ..self }
    }
}

/// The legend, in its own strip above the plots: a sample of each series' line and its label.
fn legend(area: &Area, series: &[&Series]) -> Result<(), String> {
    let mut x = 70;
    let y = (LEGEND_HEIGHT / 2) as i32;
    for s in series {
        let style = s.colour.mix(s.opacity.max(0.6)).stroke_width(3);
        if s.dots.is_some() {
            area.draw(&Circle::new((x + 12, y), 4, s.colour.mix(s.opacity.max(0.6)).filled()))
                .map_err(fail)?;
        } else {
            area.draw(&PathElement::new(vec![(x, y), (x + 24, y)], style))
                .map_err(fail)?;
        }
        area.draw(&Text::new(s.label.clone(), (x + 30, y - 7), ("sans-serif", 14)))
            .map_err(fail)?;
        x += 30 + 7 * s.label.chars().count() as i32 + 24;
    }
    Ok(())
}

/// A panel with its axes (labels with units) and its series, in the order given (the
/// measured series last, so it lies on top).
fn panel(area: &Area, caption: &str, x_label: &str, y_label: &str, series: &[&Series]) -> Result<(), String> {
    let (x0, x1) = range(series.iter().flat_map(|s| s.points.iter().map(|p| p.0)));
    let (y0, y1) = range(series.iter().flat_map(|s| s.points.iter().map(|p| p.1)));
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 16))
        .margin(8)
        .x_label_area_size(42)
        .y_label_area_size(72)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(fail)?;
    chart
        .configure_mesh()
        .max_light_lines(0)
        .x_desc(x_label)
        .y_desc(y_label)
        .x_labels(8)
        .y_labels(6)
        .draw()
        .map_err(fail)?;
    for s in series {
        if let Some(radius) = s.dots {
            let style = s.colour.mix(s.opacity).filled();
            // One dot per cell of three pixels: more would be drawn over each other.
            let mut seen = std::collections::HashSet::new();
            let distinct: Vec<(f64, f64)> = s
                .points
                .iter()
                .filter(|&&p| {
                    let (x, y) = chart.backend_coord(&p);
                    seen.insert((x / 3, y / 3))
                })
                .copied()
                .collect();
            chart
                .draw_series(distinct.into_iter().map(|p| Circle::new(p, radius, style)))
                .map_err(fail)?;
        } else {
            let style = s.colour.mix(s.opacity).stroke_width(s.width);
            let mut start = 0;
            for k in 1..=s.points.len() {
                if k == s.points.len() || (s.points[k].0 - s.points[k - 1].0).abs() > s.break_at {
                    chart
                        .draw_series(LineSeries::new(s.points[start..k].iter().copied(), style))
                        .map_err(fail)?;
                    start = k;
                }
            }
        }
    }
    Ok(())
}

/// An SVG of `height` pixels: the legend strip, then `panels` drawn into equal rows.
fn svg(
    height: u32,
    legend_series: &[&Series],
    rows: usize,
    draw: impl FnOnce(Vec<Area>) -> Result<(), String>,
) -> Result<String, String> {
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, (WIDTH, height)).into_drawing_area();
        root.fill(&WHITE).map_err(fail)?;
        let (top, body) = root.split_vertically(LEGEND_HEIGHT);
        legend(&top, legend_series)?;
        draw(body.split_evenly((rows, 1)))?;
        root.present().map_err(fail)?;
    }
    // plotters spells out SVG's defaults on every dot: a third of a scatter's bytes.
    Ok(text.replace(" stroke=\"none\" stroke-width=\"1\"/>", "/>"))
}

/// Units and scale of the chain's signals (the diagnosis names them; the figures print SI
/// values in the units an engineer reads them in).
fn signal_axis(name: &str) -> (String, f64) {
    let (unit, scale) = match name {
        n if n.starts_with("command level") => ("V", 1.0),
        n if n.starts_with("command rate") => ("V/s", 1.0),
        n if n.starts_with("command direction") => ("−1 falling, +1 rising", 1.0),
        n if n.starts_with("coil current") => ("mA", 1e3),
        n if n.starts_with("jet pipe position") => ("mm", 1e3),
        n if n.ends_with("mass flow") => ("g/s", 1e3),
        n if n.ends_with("pressure") => ("kPa", 1e-3),
        n if n.ends_with("volume") => ("cm³", 1e6),
        n if n.starts_with("stopper position") => ("mm", 1e3),
        n if n.starts_with("stopper velocity") => ("mm/s", 1e3),
        n if n.starts_with("modelled force rate") => ("N/s", 1.0),
        n if n.starts_with("modelled force") => ("N", 1.0),
        "time" => ("s", 1.0),
        _ => ("SI units", 1.0),
    };
    (format!("{name} ({unit})"), scale)
}

/// What the figures need beyond the diagnosis: the model's replays before and after, for the
/// pressures and the signals the residual follows.
pub struct FigureInputs<'a> {
    pub recording: &'a Recording,
    pub diagnosis: &'a Diagnosis,
    /// The parameters the diagnosis started from (the thesis's, or `--params`).
    pub base: &'a Parameters,
}

/// Every figure of a diagnosis.
pub fn diagnosis_figures(inputs: &FigureInputs) -> Result<Vec<Figure>, String> {
    let recording = inputs.recording;
    let diagnosis = inputs.diagnosis;
    // The diagnosis drives the model with the smoothed stopper positions; so do the figures.
    let driven = recording.with_stopper_smoothed();
    let before_model = Actuator::new(inputs.base.clone())?;
    let after_model = Actuator::new(diagnosis.parameters.clone())?;
    let n = recording.len();
    let (before, after) = std::thread::scope(|scope| {
        let b = scope.spawn(|| replay(&before_model, &driven, REPLAY_TOLERANCE, n));
        let a = replay(&after_model, &driven, REPLAY_TOLERANCE, n);
        (b.join().unwrap_or_else(|_| Err("the replay panicked".into())), a)
    });
    let (before, after) = (before?, after?);
    let mut figures = vec![
        force_over_time(recording, diagnosis)?,
        residual_over_time(recording, diagnosis)?,
        residual_against_signal(recording, diagnosis, &before_model, &driven, &before)?,
        force_against_command(recording, diagnosis)?,
    ];
    if let Some(figure) = pressures_over_time(recording, &before, &after)? {
        figures.push(figure);
    }
    figures.extend(static_curves(recording, diagnosis, inputs.base)?);
    figures.extend(flexible_shapes(diagnosis)?);
    Ok(figures)
}

fn force_over_time(recording: &Recording, diagnosis: &Diagnosis) -> Result<Figure, String> {
    let t = &recording.time;
    let before = Series::line(
        envelope(t, &diagnosis.before_force, ENVELOPE_COLUMNS),
        BEFORE,
        "model before",
    );
    let after = Series::line(
        envelope(t, &diagnosis.after_force, ENVELOPE_COLUMNS),
        AFTER,
        "model after",
    );
    let measured = Series::measured(envelope(t, &recording.force, ENVELOPE_COLUMNS), "measured (on top)");
    let order = [&before, &after, &measured];
    let svg = svg(420, &order, 1, |areas| {
        panel(&areas[0], "force over time", "time (s)", "force (N)", &order)
    })?;
    Ok(Figure {
        name: "force_over_time",
        title: "Force over time".into(),
        caption: "The measured force (black, semi-transparent, drawn last) against the model before (red) and \
                  after (blue) the additions. Each trace is reduced to its minimum and maximum per pixel column."
            .into(),
        svg,
    })
}

fn residual_over_time(recording: &Recording, diagnosis: &Diagnosis) -> Result<Figure, String> {
    let t = &recording.time;
    let residual = |model: &[f64]| -> Vec<f64> { recording.force.iter().zip(model).map(|(m, f)| m - f).collect() };
    let before = Series::line(
        envelope(t, &residual(&diagnosis.before_force), ENVELOPE_COLUMNS),
        BEFORE,
        format!("before: RMS {:.4} N", diagnosis.before.rms),
    );
    let after = Series::line(
        envelope(t, &residual(&diagnosis.after_force), ENVELOPE_COLUMNS),
        AFTER,
        format!("after: RMS {:.4} N", diagnosis.after.rms),
    );
    let noise = diagnosis.noise_floor;
    // The glitches set aside, marked where they are on each residual.
    let marks = |model: &[f64]| -> Series {
        let r = residual(model);
        let points = diagnosis
            .glitches
            .iter()
            .filter(|g| g.sets_aside())
            .filter_map(|g| {
                let k = t.partition_point(|&x| x < g.from_s);
                r.get(k).map(|&y| (g.from_s, y))
            })
            .collect();
        Series::means(points, GLITCH, "glitches set aside (not fitted, not scored)")
    };
    let (before_marks, after_marks) = (marks(&diagnosis.before_force), marks(&diagnosis.after_force));
    let legend: Vec<&Series> = if diagnosis.glitches.iter().any(|g| g.sets_aside()) {
        vec![&before, &after, &after_marks]
    } else {
        vec![&before, &after]
    };
    let svg = svg(560, &legend, 2, |areas| {
        panel(
            &areas[0],
            "residual before (measured − model)",
            "time (s)",
            "residual (N)",
            &[&before, &before_marks],
        )?;
        panel(
            &areas[1],
            &format!("residual after (noise floor {noise:.4} N)"),
            "time (s)",
            "residual (N)",
            &[&after, &after_marks],
        )
    })?;
    Ok(Figure {
        name: "residual_over_time",
        title: "Residual over time, before and after".into(),
        caption: "Measured minus modelled force, each panel on its own scale: an explained recording's residual \
                  after is noise of the size of the noise floor, with no shape in time."
            .into(),
        svg,
    })
}

/// The binned means of `residual` over ten quantile bins of `signal`, as a line.
fn binned_means(signal: &[f64], residual: &[f64], scale: f64) -> Vec<(f64, f64)> {
    let (_, bins) = conditional_means(residual, signal);
    bins.into_iter()
        .map(|(centre, mean, _)| (centre * scale, mean))
        .collect()
}

fn residual_against_signal(
    recording: &Recording,
    diagnosis: &Diagnosis,
    before_model: &Actuator,
    driven: &Recording,
    before: &Replay,
) -> Result<Figure, String> {
    let residual = |model: &[f64]| -> Vec<f64> { recording.force.iter().zip(model).map(|(m, f)| m - f).collect() };
    let (before_residual, after_residual) = (residual(&diagnosis.before_force), residual(&diagnosis.after_force));
    let signals = ChainSignals::new(before_model, driven, before);
    // The signal the residual before follows most (η², the binned means' share of its variance).
    let (name, values, eta) = signals
        .names
        .iter()
        .zip(&signals.values)
        .filter(|(name, _)| **name != "time")
        .map(|(name, values)| (*name, values, conditional_means(&before_residual, values).0))
        .max_by(|a, b| a.2.total_cmp(&b.2))
        .ok_or("no signal to plot the residual against")?;
    let (axis, scale) = signal_axis(name);
    let scaled: Vec<f64> = values.iter().map(|v| v * scale).collect();
    let dots_before = Series::dots(
        every_kth(&scaled, &before_residual, MAX_SCATTER),
        BEFORE,
        0.35,
        "samples before",
    );
    let means_before = Series::means(
        binned_means(values, &before_residual, scale),
        BEFORE,
        format!("binned means before (η² = {eta:.2})"),
    );
    let eta_after = conditional_means(&after_residual, values).0;
    let dots_after = Series::dots(
        every_kth(&scaled, &after_residual, MAX_SCATTER),
        AFTER,
        0.35,
        "samples after",
    );
    let means_after = Series::means(
        binned_means(values, &after_residual, scale),
        AFTER,
        format!("binned means after (η² = {eta_after:.2})"),
    );
    let svg = svg(
        600,
        &[&dots_before, &means_before, &dots_after, &means_after],
        2,
        |areas| {
            panel(
                &areas[0],
                "residual before",
                &axis,
                "residual (N)",
                &[&dots_before, &means_before],
            )?;
            panel(
                &areas[1],
                "residual after",
                &axis,
                "residual (N)",
                &[&dots_after, &means_after],
            )
        },
    )?;
    Ok(Figure {
        name: "residual_against_signal",
        title: format!("Residual against the {name}"),
        caption: format!(
            "The residual before and after against the signal along the chain that its binned means follow \
             most before the additions: the {name} (η² = {eta:.2} before, {eta_after:.2} after; η² is the share \
             of the residual's variance that its means over ten quantile bins of the signal explain). \
             {} of the samples are shown.",
            dots_before.points.len()
        ),
        svg,
    })
}

fn force_against_command(recording: &Recording, diagnosis: &Diagnosis) -> Result<Figure, String> {
    let v = &recording.v_da;
    // A command step is not a path the force travels: the curves break there.
    let (v0, v1) = range(v.iter().copied());
    let step = 0.05 * (v1 - v0);
    let before = Series::line(every_kth(v, &diagnosis.before_force, MAX_CURVE), BEFORE, "model before").broken_at(step);
    let after = Series::line(every_kth(v, &diagnosis.after_force, MAX_CURVE), AFTER, "model after").broken_at(step);
    let measured = Series::measured(every_kth(v, &recording.force, MAX_CURVE), "measured (on top)").broken_at(step);
    let order = [&before, &after, &measured];
    let svg = svg(560, &order, 1, |areas| {
        panel(
            &areas[0],
            "force against command",
            "command v_DA (V)",
            "force (N)",
            &order,
        )
    })?;
    Ok(Figure {
        name: "force_against_command",
        title: "Force against command (the loops of Fig. 3.13)".into(),
        caption: format!(
            "Each series in time order through every {}-th sample, broken where the command steps; the measured \
             force is drawn last.",
            recording.len().div_ceil(MAX_CURVE).max(1)
        ),
        svg,
    })
}

fn pressures_over_time(recording: &Recording, before: &Replay, after: &Replay) -> Result<Option<Figure>, String> {
    let (Some(p1), Some(p2)) = (&recording.p1, &recording.p2) else {
        return Ok(None);
    };
    let t = &recording.time;
    let kpa = |p: &[f64]| -> Vec<f64> { p.iter().map(|x| x * 1e-3).collect() };
    let channel = |measured: &[f64], before: &[f64], after: &[f64]| {
        [
            Series::line(envelope(t, &kpa(before), ENVELOPE_COLUMNS), BEFORE, "model before"),
            Series::line(envelope(t, &kpa(after), ENVELOPE_COLUMNS), AFTER, "model after"),
            Series::measured(envelope(t, &kpa(measured), ENVELOPE_COLUMNS), "measured (on top)"),
        ]
    };
    let one = channel(p1, &before.p1, &after.p1);
    let two = channel(p2, &before.p2, &after.p2);
    let svg = svg(640, &[&one[0], &one[1], &one[2]], 2, |areas| {
        panel(
            &areas[0],
            "chamber 1 pressure P1 (absolute)",
            "time (s)",
            "P1 (kPa)",
            &[&one[0], &one[1], &one[2]],
        )?;
        panel(
            &areas[1],
            "chamber 2 pressure P2 (absolute)",
            "time (s)",
            "P2 (kPa)",
            &[&two[0], &two[1], &two[2]],
        )
    })?;
    Ok(Some(Figure {
        name: "pressures_over_time",
        title: "Chamber pressures over time".into(),
        caption: "The recorded pressure channels against the transducer readings of the model before and after \
                  (P1_meas, P2_meas), minimum and maximum per pixel column."
            .into(),
        svg,
    }))
}

/// Whether an added term is a static curve of the command path (command → jet pipe position).
fn bends_command_path(location: Place, family: Family) -> bool {
    matches!(location, Place::Command | Place::CurrentDriver | Place::JetPipe)
        && matches!(family, Family::Nonlinearity | Family::Limit)
}

/// The drawn static curves of the terms that are static curves: the force sensor's map, and
/// the command path's map from v_DA to the jet pipe's static position x̄ = f3(k_m i) (2.4),
/// (2.5), with i the current driver's static current and the command stage's static map.
fn static_curves(recording: &Recording, diagnosis: &Diagnosis, base: &Parameters) -> Result<Vec<Figure>, String> {
    let after = &diagnosis.parameters;
    let mut figures = vec![];
    let sensor_term = diagnosis.discovered.iter().any(|d| {
        d.location == Place::ForceSensor && matches!(d.family, Family::Nonlinearity | Family::ParameterOffset)
    }) || diagnosis.effects.iter().any(|e| e.location == Place::ForceSensor);
    if sensor_term {
        figures.push(force_sensor_curve(recording, diagnosis, base, after)?);
    }
    if diagnosis
        .discovered
        .iter()
        .any(|d| bends_command_path(d.location, d.family))
    {
        figures.push(command_path_curve(recording, base, after)?);
    }
    Ok(figures)
}

fn force_sensor_curve(
    recording: &Recording,
    diagnosis: &Diagnosis,
    base: &Parameters,
    after: &Parameters,
) -> Result<Figure, String> {
    let (law_before, law_after) = (
        SensorLaw::of(base, Channel::Force),
        SensorLaw::of(after, Channel::Force),
    );
    let (f0, f1) = span(diagnosis.before_force.iter().copied());
    let curve: Vec<(f64, f64)> = (0..=200)
        .map(|k| {
            let f = f0 + (f1 - f0) * k as f64 / 200.0;
            (f, law_after.static_reading(f, 0.0) - law_before.static_reading(f, 0.0))
        })
        .collect();
    let residual: Vec<f64> = recording
        .force
        .iter()
        .zip(&diagnosis.before_force)
        .map(|(m, f)| m - f)
        .collect();
    let dots = Series::dots(
        every_kth(&diagnosis.before_force, &residual, MAX_SCATTER),
        BEFORE,
        0.35,
        "residual before (measured − model)",
    );
    let fitted = Series::line(curve, AFTER, "fitted sensor curve (reading after − before)").wide();
    let svg = svg(480, &[&dots, &fitted], 1, |areas| {
        panel(
            &areas[0],
            "force sensor: fitted static curve",
            "modelled force before (N)",
            "reading change (N)",
            &[&dots, &fitted],
        )
    })?;
    Ok(Figure {
        name: "force_sensor_curve",
        title: "The force sensor's fitted static curve".into(),
        caption: "What the added sensor law changes in the reading of a force, against that force (blue, at \
                  t = 0, without drift or pick-up), over the residual before against the modelled force (red): \
                  the curve should run through the residual's middle."
            .into(),
        svg,
    })
}

fn command_path_curve(recording: &Recording, base: &Parameters, after: &Parameters) -> Result<Figure, String> {
    let position = |p: &Parameters, v: f64| -> f64 {
        let command = command_stage::static_map(p, v);
        let current = static_current(p.k_cd, p.i_offset, command);
        F3::from_parameters(p).value(tip_force(p.k_m, current)) * 1e3
    };
    let (v0, v1) = span(recording.v_da.iter().copied());
    let curve = |p: &Parameters| -> Vec<(f64, f64)> {
        (0..=300)
            .map(|k| {
                let v = v0 + (v1 - v0) * k as f64 / 300.0;
                (v, position(p, v))
            })
            .collect()
    };
    let before = Series::line(curve(base), BEFORE, "before").wide();
    let after_curve = Series::line(curve(after), AFTER, "fitted (after)").wide();
    let difference: Vec<(f64, f64)> = before
        .points
        .iter()
        .zip(&after_curve.points)
        .map(|(b, a)| (b.0, 1e3 * (a.1 - b.1)))
        .collect();
    let change = Series::line(difference, AFTER, "after − before").wide();
    let svg = svg(600, &[&before, &after_curve], 2, |areas| {
        panel(
            &areas[0],
            "static jet pipe position against command",
            "command v_DA (V)",
            "static position x̄ (mm)",
            &[&before, &after_curve],
        )?;
        panel(
            &areas[1],
            "the fitted curve's change",
            "command v_DA (V)",
            "change of x̄ (µm)",
            &[&change],
        )
    })?;
    Ok(Figure {
        name: "command_path_curve",
        title: "The command path's fitted static curve".into(),
        caption: "The jet pipe's static position x̄ = f3(k_m i) (2.4), (2.5) against the command, with i the \
                  current driver's static current of the command after the command stage's static map, under \
                  the parameters before and after; below, their difference."
            .into(),
        svg,
    })
}

/// Write every figure as `DIR/NAME.svg` (`jetpipe diagnose --plots DIR`).
pub fn write_diagnosis_plots(dir: &Path, inputs: &FigureInputs) -> Result<Vec<Figure>, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let figures = diagnosis_figures(inputs)?;
    for figure in &figures {
        let path = dir.join(format!("{}.svg", figure.name));
        std::fs::write(&path, &figure.svg).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    }
    Ok(figures)
}

/// Colours of a flexible term's lines, one per knot of its second signal.
const SHAPE_COLOURS: [RGBColor; 5] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
];

/// Each flexible term's surface: what it adds to its constant along its first signal, one
/// line at each knot of its second (a single line for a term of one signal).
fn flexible_shapes(diagnosis: &Diagnosis) -> Result<Vec<Figure>, String> {
    use jetpipe_diagnosis::candidates::flexible;
    let mut figures = vec![];
    for (k, term) in diagnosis
        .discovered
        .iter()
        .filter(|d| d.flexible.is_some())
        .take(2)
        .enumerate()
    {
        let Some(shape) = flexible::shape(&term.parameters) else {
            continue;
        };
        let value = |name: String| term.parameters.iter().find(|(n, _)| *n == name).map(|(_, v)| *v);
        let Some(slot) = (1..=flexible::SLOTS).find(|&s| value(format!("flexible_{s}_parameter")).is_some()) else {
            continue;
        };
        let knots = |axis: usize| -> Vec<f64> {
            let n = value(format!("flexible_{slot}_knots_{axis}")).unwrap_or(0.0) as usize;
            (1..=n)
                .filter_map(|j| value(format!("flexible_{slot}_x{axis}_{j}")))
                .collect()
        };
        let (first, second) = (knots(1), knots(2));
        let Some((axis, _)) = shape.axes.first() else {
            continue;
        };
        let (x_label, x_scale) = signal_unit_scale(axis.signal.unit());
        let columns = second.len().max(1);
        let series: Vec<Series> = (0..columns)
            .map(|j| {
                let points = first
                    .iter()
                    .enumerate()
                    .map(|(i, x)| {
                        (
                            x * x_scale,
                            value(format!("flexible_{slot}_y_{}_{}", i + 1, j + 1)).unwrap_or(0.0),
                        )
                    })
                    .collect();
                let label = match (shape.axes.get(1), second.get(j)) {
                    (Some((other, _)), Some(x2)) => {
                        let (unit, scale) = signal_unit_scale(other.signal.unit());
                        format!("{} = {:.3} {unit}", other.signal.name(), x2 * scale)
                    }
                    _ => "the term".to_string(),
                };
                Series::line(points, SHAPE_COLOURS[j % SHAPE_COLOURS.len()], label).wide()
            })
            .collect();
        let refs: Vec<&Series> = series.iter().collect();
        let caption = format!("flexible term {}: added to {}", k + 1, shape.constant);
        let x_desc = format!("{} ({x_label})", axis.name());
        let y_desc = format!("added to {} ({})", shape.constant, shape.unit);
        let svg = svg(420, &refs, 1, |areas| {
            panel(&areas[0], &caption, &x_desc, &y_desc, &refs)
        })?;
        figures.push(Figure {
            name: if k == 0 { "flexible_term_1" } else { "flexible_term_2" },
            title: format!("The shape of flexible term {}", k + 1),
            caption: format!(
                "What the flexible term adds to {} at its knots, joined by straight lines as the model interpolates \
                 them, along {}{}: a departure no readable form at any place closed. Held beyond the end knots.",
                shape.constant,
                axis.name(),
                match shape.axes.get(1) {
                    Some((other, _)) => format!(", one line at each knot of {}", other.name()),
                    None => String::new(),
                }
            ),
            svg,
        });
    }
    Ok(figures)
}

/// The unit an engineer reads an SI unit of the chain's signals in, with its scale.
fn signal_unit_scale(unit: &str) -> (&'static str, f64) {
    match unit {
        "m" => ("mm", 1e3),
        "m/s" => ("mm/s", 1e3),
        "Pa" => ("kPa", 1e-3),
        "A" => ("mA", 1e3),
        "V" => ("V", 1.0),
        "N" => ("N", 1.0),
        "s" => ("s", 1.0),
        _ => ("1", 1.0),
    }
}

/// Colours of a proposal's explanations, the report's model first.
const EXPLANATION_COLOURS: [RGBColor; 4] = [AFTER, BEFORE, RGBColor(44, 160, 44), RGBColor(255, 127, 14)];

/// A proposed protocol: the command and the stopper over time, and the force each
/// explanation predicts, less the report's model's (the differences the protocol is for).
pub fn proposal_figure(
    time: &[f64],
    v_da: &[f64],
    x_s: &[f64],
    predicted_force: &[(String, &[f64])],
) -> Result<Figure, String> {
    let command = Series::line(envelope(time, v_da, ENVELOPE_COLUMNS), MEASURED, "command (V)");
    let stopper_mm: Vec<f64> = x_s.iter().map(|x| x * 1e3).collect();
    let stopper = Series::line(envelope(time, &stopper_mm, ENVELOPE_COLUMNS), MEASURED, "stopper (mm)");
    let reference = predicted_force.first().map(|(_, f)| *f).unwrap_or(&[]);
    let differences: Vec<Series> = predicted_force
        .iter()
        .enumerate()
        .map(|(k, (label, force))| {
            let less: Vec<f64> = force.iter().zip(reference).map(|(f, r)| f - r).collect();
            Series::line(
                envelope(time, &less, ENVELOPE_COLUMNS),
                EXPLANATION_COLOURS[k % EXPLANATION_COLOURS.len()],
                label.clone(),
            )
        })
        .collect();
    let legend_series: Vec<&Series> = differences.iter().collect();
    let svg = svg(760, &legend_series, 3, |areas| {
        panel(&areas[0], "command", "time (s)", "v_DA (V)", &[&command])?;
        panel(&areas[1], "stopper position", "time (s)", "x_s (mm)", &[&stopper])?;
        panel(
            &areas[2],
            "force each explanation predicts, less the report's model's",
            "time (s)",
            "force (N)",
            &legend_series,
        )
    })?;
    Ok(Figure {
        name: "proposal",
        title: "The proposed protocol".into(),
        caption: "The command and the stopper position to play, and the force each explanation predicts on them, \
                  less what the report's model predicts (each trace reduced to its minimum and maximum per pixel \
                  column)."
            .into(),
        svg,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_envelope_keeps_every_column_extreme_in_time_order() {
        let t: Vec<f64> = (0..10_000).map(|k| k as f64 * 1e-3).collect();
        let y: Vec<f64> = t
            .iter()
            .map(|t| (37.0 * t).sin() + if *t == 5.0 { 9.0 } else { 0.0 })
            .collect();
        let e = envelope(&t, &y, 100);
        assert!(e.len() <= 200);
        assert!(e.windows(2).all(|w| w[0].0 <= w[1].0));
        assert!(e.iter().any(|p| p.1 > 9.0), "the single spike survives");
        let lowest = y.iter().copied().fold(f64::INFINITY, f64::min);
        assert!(e.iter().any(|p| p.1 == lowest));
    }

    #[test]
    fn every_kth_takes_at_most_the_asked_number_of_points() {
        let x: Vec<f64> = (0..80_001).map(f64::from).collect();
        let points = every_kth(&x, &x, 3000);
        assert!(points.len() <= 3000 && points.len() > 2900, "{}", points.len());
        assert_eq!(points[0], (0.0, 0.0));
    }
}
