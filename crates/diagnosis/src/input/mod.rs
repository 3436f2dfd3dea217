//! Stage 1, the input: the recording, its checks, its glitches, the channels' noise floors, spectral lines,
//! the training and held-out blocks, and the stopper's acceleration formed from its positions.

pub mod acceleration;
pub mod blocks;
pub mod checks;
pub mod glitches;
pub mod joint;
pub mod lines;
pub mod noise;
pub mod recording;
pub mod stopper_motion;
