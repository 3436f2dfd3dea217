//! Small statistics every stage uses: stated once here.

/// Correlation coefficient of two series (over the shorter one's length); 0 where either is
/// constant or shorter than two samples.
pub fn correlation(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    if n < 2 {
        return 0.0;
    }
    let (a, b) = (&a[..n], &b[..n]);
    let (ma, mb) = (a.iter().sum::<f64>() / n as f64, b.iter().sum::<f64>() / n as f64);
    let (mut ab, mut aa, mut bb) = (0.0, 0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        ab += (x - ma) * (y - mb);
        aa += (x - ma) * (x - ma);
        bb += (y - mb) * (y - mb);
    }
    if aa > 0.0 && bb > 0.0 {
        ab / (aa * bb).sqrt()
    } else {
        0.0
    }
}

/// The value at `time[0]` of the least-squares line through `(time, values)`: where the
/// values move steadily, their mean is the value at the span's middle, not at its start
/// (four readings of a pressure rising at 0.9 MPa/s, read at 250 Hz, average 5.6 kPa above
/// the first). One value is itself; equal times give the mean.
pub fn line_value_at_start(time: &[f64], values: &[f64]) -> f64 {
    let n = time.len().min(values.len());
    if n == 0 {
        return f64::NAN;
    }
    let (time, values) = (&time[..n], &values[..n]);
    let mean_t = time.iter().sum::<f64>() / n as f64;
    let mean_v = values.iter().sum::<f64>() / n as f64;
    let (mut tv, mut tt) = (0.0, 0.0);
    for (t, v) in time.iter().zip(values) {
        tv += (t - mean_t) * (v - mean_v);
        tt += (t - mean_t) * (t - mean_t);
    }
    let slope = if tt > 0.0 { tv / tt } else { 0.0 };
    mean_v + slope * (time[0] - mean_t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_series_correlates_fully_with_itself_scaled_and_not_at_all_with_its_quadrature() {
        let a: Vec<f64> = (0..1000).map(|k| (k as f64 * 0.0628).sin()).collect();
        let b: Vec<f64> = a.iter().map(|v| -3.0 * v + 2.0).collect();
        let c: Vec<f64> = (0..1000).map(|k| (k as f64 * 0.0628).cos()).collect();
        assert!((correlation(&a, &b) + 1.0).abs() < 1e-12);
        assert!(correlation(&a, &c).abs() < 0.01);
        assert_eq!(correlation(&a, &[1.0; 1000]), 0.0);
    }

    #[test]
    fn the_value_at_the_start_of_steadily_moving_readings_is_the_first_not_their_mean() {
        let time = [0.0, 0.004, 0.008, 0.012];
        let rising: Vec<f64> = time.iter().map(|t| 5.0e5 + 9.0e5 * t).collect();
        assert!((line_value_at_start(&time, &rising) - 5.0e5).abs() < 1e-6);
        let mean = rising.iter().sum::<f64>() / 4.0;
        assert!(mean - 5.0e5 > 5.0e3);
        assert_eq!(line_value_at_start(&time[..1], &rising[..1]), 5.0e5);
        let held = [4.0e5, 4.1e5, 3.9e5, 4.0e5];
        assert!((line_value_at_start(&[0.0; 4], &held) - 4.0e5).abs() < 1e-9);
    }
}
