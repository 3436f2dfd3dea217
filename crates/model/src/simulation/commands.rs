//! The command the current driver sees over a step: v_DA through the command stage
//! ([`crate::physics::command_stage`]) and, with the transport_delay effect, as it was
//! `command_delay` earlier, in pieces of held or ramping command.

use super::Simulation;
use crate::physics::command_stage;

/// From `time` on, the command was `v_da` + `rate`·(t − `time`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CommandChange {
    pub time: f64,
    pub v_da: f64,
    pub rate: f64,
}

impl Simulation {
    /// The command the current driver sees over the next `step`, through the command stage
    /// and the delay line, as [`Self::command_segments`] pieces; shared by the
    /// error-controlled and the fixed steps.
    pub(super) fn seen_command_segments(&mut self, step: f64) -> smallvec::SmallVec<[(f64, f64, f64); 2]> {
        if !self.plan.command_path {
            return smallvec::smallvec![(step, self.v_da, self.v_da_rate)];
        }
        // The command stage holds what the driver sees over the step, or ramps it to the
        // filter's output at the step's end (a command ramp reaches it at the next
        // communication point).
        let applied = self.v_da;
        let staged = command_stage::is_active(&self.model.params);
        if staged {
            let before = self.command_stage.current(&self.model.params);
            let seen = self.command_stage.next(&self.model.params, self.time, applied);
            self.input_changed |= seen != before;
            self.v_da = seen;
        }
        let rate = self.v_da_rate;
        if staged && self.model.params.command_delay == 0.0 {
            if let Some(pieces) = self.command_stage.pieces_over(&self.model.params, step) {
                self.v_da = applied;
                return pieces;
            }
        }
        if staged {
            self.v_da_rate = self.command_stage.rate_over(&self.model.params, step);
        }
        let segments = self.command_segments(step);
        self.v_da = applied;
        self.v_da_rate = rate;
        segments
    }

    /// The command the current driver sees over the next `step`: v_DA itself, or (with the
    /// transport_delay effect) v_DA as it was `command_delay` earlier, as (duration,
    /// value at the segment's start, rate) pieces.
    fn command_segments(&mut self, step: f64) -> smallvec::SmallVec<[(f64, f64, f64); 2]> {
        let delay = self.model.params.command_delay;
        if delay == 0.0 {
            return smallvec::smallvec![(step, self.v_da, self.v_da_rate)];
        }
        self.command_history.push(CommandChange {
            time: self.time,
            v_da: self.v_da,
            rate: self.v_da_rate,
        });
        let (from, to) = (self.time - delay, self.time + step - delay);
        // Forget what no later step can see.
        while self.command_history.len() > 1 && self.command_history[1].time <= from {
            self.command_history.remove(0);
        }
        let mut segments: smallvec::SmallVec<[(f64, f64, f64); 2]> = smallvec::SmallVec::new();
        let mut start = from;
        for (k, change) in self.command_history.iter().enumerate() {
            let end = self.command_history.get(k + 1).map_or(to, |next| next.time.min(to));
            if end <= start {
                continue;
            }
            let value = if change.rate == 0.0 {
                change.v_da
            } else {
                change.v_da + change.rate * (start - change.time)
            };
            segments.push((end - start, value, change.rate));
            start = end;
            if start >= to {
                break;
            }
        }
        // Rounding can leave the pieces a hair short of the step: give it to the last.
        let covered: f64 = segments.iter().map(|s| s.0).sum();
        if let Some(last) = segments.last_mut() {
            last.0 += step - covered;
        }
        segments
    }
}
