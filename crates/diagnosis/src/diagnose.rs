//! The diagnosis from end to end: the steps of the crate's account, in order.

use crate::context::Context;
use crate::context::Options;
use crate::fit::calibrate::Calibrated;
use crate::input::recording::Recording;
use crate::replay::replay;
use crate::replay::replay_fast;
use crate::replay::Replay;
use crate::verdict::diagnosis::Diagnosis;
use crate::verdict::joint::JointDiagnosis;
use jetpipe_model::physics::actuator::Actuator;
use jetpipe_model::physics::parameters::Parameters;

/// Diagnose a recording (see the module's account). `progress` receives one line per stage.
pub fn diagnose(
    recording: &Recording,
    base: &Parameters,
    calibrate_static: bool,
    progress: &mut dyn FnMut(&str),
) -> Result<Diagnosis, String> {
    let options = Options {
        calibrate: calibrate_static,
        ..Options::default()
    };
    diagnose_with(recording, base, &options, progress)
}

/// Diagnose a recording with the given options: the steps of the module's account, in order.
/// A fault of the diagnosis itself (a panic) comes back as an error that says so, not as the
/// end of the caller's process: a batch goes on with its other recordings.
pub fn diagnose_with(
    recording: &Recording,
    base: &Parameters,
    options: &Options,
    progress: &mut dyn FnMut(&str),
) -> Result<Diagnosis, String> {
    diagnose_owned(recording.clone(), base, options, progress)
}

/// [`diagnose_with`] on a recording the diagnosis may keep and change (its stopper
/// positions smoothed in place): a long recording is held once, not twice (a 600 s
/// recording at 1 kHz is 29 MB).
pub fn diagnose_owned(
    recording: Recording,
    base: &Parameters,
    options: &Options,
    progress: &mut dyn FnMut(&str),
) -> Result<Diagnosis, String> {
    guarded(|| diagnose_unguarded(recording, base, options, progress))
}

/// Diagnose several recordings of one actuator together: one model, with one set of
/// constants and terms, fitted to all of them (`crate::input::joint`), then each recording
/// replayed alone with it (`crate::verdict::joint`). Each recording is named by its `String`
/// in errors and in the report. A fault of the diagnosis itself comes back as an error.
pub fn diagnose_joint(
    recordings: Vec<(String, Recording)>,
    base: &Parameters,
    options: &Options,
    progress: &mut dyn FnMut(&str),
) -> Result<JointDiagnosis, String> {
    guarded(|| diagnose_joint_unguarded(recordings, base, options, progress))
}

fn diagnose_joint_unguarded(
    recordings: Vec<(String, Recording)>,
    base: &Parameters,
    options: &Options,
    progress: &mut dyn FnMut(&str),
) -> Result<JointDiagnosis, String> {
    let start = Actuator::new(base.clone())?;
    let (mut repaired, mut input_checks, mut to_judge, mut settling) = (vec![], vec![], vec![], vec![]);
    for (name, mut recording) in recordings {
        let glitches = crate::input::glitches::find_and_repair(&mut recording);
        let checks = crate::input::checks::check_file(&recording, base).map_err(|e| format!("{name}: {e}"))?;
        input_checks.extend(checks.into_iter().map(|c| format!("{name}: {c}")));
        let spans = crate::input::glitches::set_aside_spans(&glitches);
        // Its own start, as a diagnosis of it alone would measure it.
        let smoothed = recording.with_stopper_smoothed();
        let cx = Context::measure(
            &smoothed,
            &smoothed,
            &start,
            options,
            spans.clone(),
            &mut vec![],
            &mut |_| {},
        )?;
        settling.push(cx.settled_from - smoothed.time[0]);
        to_judge.push(crate::verdict::joint::RecordingToJudge {
            name: name.clone(),
            recording: recording.clone(),
            glitch_spans: spans,
            glitches: glitches.iter().filter(|g| g.sets_aside()).count(),
            resampled: false,
        });
        repaired.push((name, recording, glitches));
    }
    let parts: Vec<(String, Recording)> = repaired.iter().map(|(n, r, _)| (n.clone(), r.clone())).collect();
    let mut joined = crate::input::joint::join(&parts)?;
    drop(parts);
    bridges_read_as_the_model(&mut joined, &start)?;
    let mut glitches = vec![];
    for ((_, _, own), part) in repaired.iter().zip(&joined.parts) {
        glitches.extend(own.iter().cloned().map(|mut g| {
            g.from_s += part.offset_s;
            g.to_s += part.offset_s;
            g
        }));
    }
    drop(repaired);
    // Each bridge and the next recording's own start are set aside together.
    let bridges: Vec<(f64, f64)> = joined
        .bridges
        .iter()
        .zip(joined.parts.iter().skip(1).zip(settling.iter().skip(1)))
        .map(|(&(from, _), (part, &settle))| (from, joined.recording.time[part.rows.start] + settle))
        .collect();
    for (judged, part) in to_judge.iter_mut().zip(&joined.parts) {
        judged.resampled = part.resampled;
    }
    for note in &joined.notes {
        progress(note);
    }
    input_checks.extend(joined.notes.iter().cloned());
    progress(&format!(
        "{} recordings joined: {} samples, {} bridges set aside",
        joined.parts.len(),
        joined.recording.len(),
        bridges.len()
    ));
    let prepared = Prepared {
        recording: joined.recording.clone(),
        glitches,
        bridges: bridges.clone(),
        input_checks,
    };
    let diagnosis = diagnose_prepared(prepared, base, options, progress)?;
    let verdicts = crate::verdict::joint::judge_each(to_judge, base, &diagnosis, options, progress)?;
    let mut notes = joined.notes.clone();
    notes.extend(crate::verdict::joint::sentences(&verdicts));
    joined.bridges = bridges;
    Ok(JointDiagnosis {
        diagnosis,
        recordings: verdicts,
        joined,
        notes,
    })
}

/// The bridges' readings replaced by those of `model` replayed on the joined recording: a
/// departure there is then the additions' alone, which is small, and the noise floors, the
/// spectra, the choice of the stopper acceleration's window and the remainder's signature,
/// which read every sample, do not take the bridges' straight lines for the actuator.
fn bridges_read_as_the_model(joined: &mut crate::input::joint::Joined, model: &Actuator) -> Result<(), String> {
    let replayed = replay(
        model,
        &joined.recording.with_stopper_smoothed(),
        1e-5,
        joined.recording.len(),
    )?;
    let r = &mut joined.recording;
    for pair in joined.parts.windows(2) {
        for k in pair[0].rows.end..pair[1].rows.start {
            r.force[k] = replayed.force[k];
            if let (Some(p1), Some(p2)) = (r.p1.as_mut(), r.p2.as_mut()) {
                p1[k] = replayed.p1[k];
                p2[k] = replayed.p2[k];
            }
        }
    }
    Ok(())
}

/// `run`, with a fault of the diagnosis itself (a panic) turned into an error that says so.
fn guarded<T>(run: impl FnOnce() -> Result<T, String>) -> Result<T, String> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(run)).unwrap_or_else(|fault| {
        let message = fault
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| fault.downcast_ref::<&str>().copied())
            .unwrap_or("no message");
        Err(format!(
            "the diagnosis failed on a fault of its own, not of the recording ({message}); please report it with the recording"
        ))
    })
}

pub(crate) fn diagnose_unguarded(
    recording: Recording,
    base: &Parameters,
    options: &Options,
    progress: &mut dyn FnMut(&str),
) -> Result<Diagnosis, String> {
    // 1. The glitches set aside, the file's checks and the noise floors.
    let mut recording = recording;
    let glitches = crate::input::glitches::find_and_repair(&mut recording);
    let input_checks = crate::input::checks::check_file(&recording, base)?;
    let prepared = Prepared {
        recording,
        glitches,
        bridges: vec![],
        input_checks,
    };
    diagnose_prepared(prepared, base, options, progress)
}

/// A recording ready for the diagnosis's steps: its glitches repaired, its file checked.
pub(crate) struct Prepared {
    pub(crate) recording: Recording,
    pub(crate) glitches: Vec<crate::input::glitches::Glitch>,
    /// Spans (s) set aside that are not glitches: the bridges between joined recordings.
    pub(crate) bridges: Vec<(f64, f64)>,
    pub(crate) input_checks: Vec<String>,
}

/// The diagnosis's steps from the noise floors on.
pub(crate) fn diagnose_prepared(
    prepared: Prepared,
    base: &Parameters,
    options: &Options,
    progress: &mut dyn FnMut(&str),
) -> Result<Diagnosis, String> {
    let Prepared {
        recording,
        glitches,
        bridges,
        mut input_checks,
    } = prepared;
    if let Some(sentence) = crate::input::glitches::sentence(&glitches) {
        progress(&sentence);
        input_checks.push(sentence);
    }
    let stopper_positions = recording.stopper_positions();
    if let crate::input::recording::StopperPositions::AnsweringTheirRounding { correlation } = stopper_positions {
        let sentence = format!(
            "The force answers the rounding of the stopper positions (correlation {correlation:.2} between the change of slope a smoothing would take out of each interval and the force's content at the sampling rate): the stopper moved as it was logged, in steps, and the model is driven with the positions as recorded."
        );
        progress(&sentence);
        input_checks.push(sentence);
    }
    let mut smoothed = recording.into_driven_by(stopper_positions);
    let before_model = Actuator::new(base.clone())?;
    // The fits' fixed-step replay, checked against the error-controlled one of the starting
    // model, which the verdict compares the final model with.
    progress("the starting model replayed with the error-controlled integrator");
    let before_accurate = replay(&before_model, &smoothed, 1e-5, smoothed.len())?;
    let fast_replay = crate::replay::agreement::fast_step_that_agrees(&before_model, &smoothed, &before_accurate)?;
    smoothed.fast_replay = fast_replay.method();
    if let Some(sentence) = fast_replay.sentence() {
        progress(&sentence);
        input_checks.push(sentence);
    }
    smoothed.acceleration_window = crate::input::stopper_motion::choose_window(
        &smoothed,
        &crate::replay::signals::difference(&smoothed.force, &before_accurate.force),
    );
    let departures = before_departures(&smoothed, &before_accurate);
    let departures: Vec<&[f64]> = departures.iter().map(Vec::as_slice).collect();
    let fitted = smoothed.rows_for_fits_where_departing(crate::input::recording::MAX_FIT_ROWS, &departures);
    let mut set_aside = crate::input::glitches::set_aside_spans(&glitches);
    set_aside.extend(bridges);
    let cx = Context::measure(
        &smoothed,
        &fitted,
        &before_model,
        options,
        set_aside,
        &mut input_checks,
        progress,
    )?;
    let before_fast = replay_fast(&before_model, cx.recording, cx.n)?;
    input_checks.extend(crate::input::checks::check_against_model(
        cx.recording,
        &before_fast.force,
        Some((&before_fast.p1, &before_fast.p2)),
        base,
    )?);
    // 2. The static identification, when asked for.
    let (mut params, calibrated) = if options.calibrate {
        calibrate_static(&cx, base, progress)
    } else {
        (base.clone(), vec![])
    };
    // The forces on the stopper's motion read the acceleration smoothed from the recording
    // (a model without such a force reads none: the share goes back to 0 at the end).
    params.stopper_acceleration_input_share = 1.0;
    let mut cx = cx.with_piston_area(before_model.piston_area);
    cx.stopper_positions = stopper_positions;
    // 3–5. Replay, localize, add what earns its place; then refit the additions together.
    let mut replays = 1;
    let mut found = crate::decide::decision::run_rounds(&mut cx, params, &mut replays, progress)?;
    // Where no readable term closed the departure: a flexible one, when asked for.
    if options.flexible {
        crate::decide::flexible::close_with_flexible(&cx, &mut found, &mut replays, progress)?;
    }
    let joint_refit = found.joint_refit;
    // 6. The verdict, from the accurate replays.
    crate::verdict::conclude::conclude(
        &cx,
        (before_model, before_accurate, fast_replay),
        found,
        joint_refit,
        input_checks,
        calibrated,
        glitches,
        replays,
        progress,
    )
}

/// The starting model's error on each measured channel at every sample.
pub(crate) fn before_departures(recording: &Recording, before: &Replay) -> Vec<Vec<f64>> {
    let mut departures = vec![crate::replay::signals::difference(&recording.force, &before.force)];
    if let (Some(p1), Some(p2)) = (&recording.p1, &recording.p2) {
        departures.push(crate::replay::signals::difference(p1, &before.p1));
        departures.push(crate::replay::signals::difference(p2, &before.p2));
    }
    departures
}

/// Re-identify what the thesis identified from static loops (§3.3.1).
pub(crate) fn calibrate_static(
    cx: &Context,
    base: &Parameters,
    progress: &mut dyn FnMut(&str),
) -> (Parameters, Vec<Calibrated>) {
    progress("calibration: x_jp_offset, C_d and the leakage (§3.3.1), on the whole and on halves");
    let (params, calibrated) = crate::fit::calibrate::calibrate(cx.recording, base, &cx.blocks);
    for c in &calibrated {
        progress(&format!(
            "  {} = {:.4e} (thesis {:.4e}){}",
            c.name,
            c.value,
            c.thesis,
            if c.flags.is_empty() { "" } else { "  FLAGGED" }
        ));
    }
    (params, calibrated)
}
