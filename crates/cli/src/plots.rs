//! SVG plots of a diagnosis: residuals over time before and after, and measured vs
//! modelled force against the command (the force/current loops of Fig. 3.13).

use std::path::Path;

use plotters::prelude::*;

use jetpipe_diagnosis::recording::Recording;
use jetpipe_diagnosis::Diagnosis;

fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
    if lo.is_finite() && hi > lo {
        let pad = 0.05 * (hi - lo);
        (lo - pad, hi + pad)
    } else {
        (lo - 1.0, hi + 1.0)
    }
}

/// Every `step`-th point, so an 80 000-sample trace stays a light SVG.
fn thin<T: Copy>(points: &[T], max: usize) -> Vec<T> {
    let step = points.len().div_ceil(max).max(1);
    points.iter().step_by(step).copied().collect()
}

pub fn write_diagnosis_plots(dir: &Path, recording: &Recording, diagnosis: &Diagnosis) -> Result<(), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let fail = |e: &dyn std::fmt::Display| format!("plotting failed: {e}");

    let residual = |model: &[f64]| -> Vec<(f64, f64)> {
        recording
            .time
            .iter()
            .zip(&recording.force)
            .zip(model)
            .map(|((t, m), f)| (*t, m - f))
            .collect()
    };
    let before = thin(&residual(&diagnosis.before_force), 4000);
    let after = thin(&residual(&diagnosis.after_force), 4000);
    let path = dir.join("residual_over_time.svg");
    {
        let root = SVGBackend::new(&path, (1000, 500)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| fail(&e))?;
        let (t0, t1) = range(recording.time.iter().copied());
        let (r0, r1) = range(before.iter().chain(&after).map(|p| p.1));
        let mut chart = ChartBuilder::on(&root)
            .caption("force residual (measured - model)", ("sans-serif", 20))
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(t0..t1, r0..r1)
            .map_err(|e| fail(&e))?;
        chart
            .configure_mesh()
            .x_desc("time (s)")
            .y_desc("residual (N)")
            .draw()
            .map_err(|e| fail(&e))?;
        chart
            .draw_series(LineSeries::new(before, &RED))
            .map_err(|e| fail(&e))?
            .label(format!("thesis model, RMS {:.3} N", diagnosis.before.rms))
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED));
        chart
            .draw_series(LineSeries::new(after, &BLUE))
            .map_err(|e| fail(&e))?
            .label(format!("with the added effects, RMS {:.3} N", diagnosis.after.rms))
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLUE));
        chart
            .configure_series_labels()
            .border_style(BLACK)
            .draw()
            .map_err(|e| fail(&e))?;
        root.present().map_err(|e| fail(&e))?;
    }

    let path = dir.join("force_command_loops.svg");
    {
        let pairs = |force: &[f64]| -> Vec<(f64, f64)> {
            thin(
                &recording
                    .v_da
                    .iter()
                    .copied()
                    .zip(force.iter().copied())
                    .collect::<Vec<_>>(),
                6000,
            )
        };
        let measured = pairs(&recording.force);
        let model_before = pairs(&diagnosis.before_force);
        let model_after = pairs(&diagnosis.after_force);
        let root = SVGBackend::new(&path, (800, 600)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| fail(&e))?;
        let (v0, v1) = range(recording.v_da.iter().copied());
        let (f0, f1) = range(recording.force.iter().chain(&diagnosis.before_force).copied());
        let mut chart = ChartBuilder::on(&root)
            .caption("force against command (the loops of Fig. 3.13)", ("sans-serif", 20))
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(v0..v1, f0..f1)
            .map_err(|e| fail(&e))?;
        chart
            .configure_mesh()
            .x_desc("v_DA (V)")
            .y_desc("force (N)")
            .draw()
            .map_err(|e| fail(&e))?;
        for (points, colour, label) in [
            (measured, BLACK, "measured"),
            (model_before, RED, "thesis model"),
            (model_after, BLUE, "with effects"),
        ] {
            chart
                .draw_series(points.iter().map(|&(v, f)| Circle::new((v, f), 1, colour.filled())))
                .map_err(|e| fail(&e))?
                .label(label)
                .legend(move |(x, y)| Circle::new((x + 10, y), 3, colour.filled()));
        }
        chart
            .configure_series_labels()
            .border_style(BLACK)
            .draw()
            .map_err(|e| fail(&e))?;
        root.present().map_err(|e| fail(&e))?;
    }
    Ok(())
}
