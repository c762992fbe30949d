//! Wall-clock timing that beats the shared machine's noise: the median of several runs.

use std::time::Instant;

/// Runs `f` `reps` times (at least once) and returns the median wall time in seconds, or
/// the first error.
pub fn median_seconds<E>(reps: usize, mut f: impl FnMut() -> Result<(), E>) -> Result<f64, E> {
    let mut times = Vec::with_capacity(reps.max(1));
    for _ in 0..reps.max(1) {
        let t = Instant::now();
        f()?;
        times.push(t.elapsed().as_secs_f64());
    }
    Ok(median(&mut times))
}

/// The median (mean of the two middle values for an even count; 0 for none).
pub fn median(xs: &mut [f64]) -> f64 {
    if xs.is_empty() {
        return 0.0;
    }
    xs.sort_by(f64::total_cmp);
    let m = xs.len() / 2;
    if xs.len() % 2 == 1 {
        xs[m]
    } else {
        0.5 * (xs[m - 1] + xs[m])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_of_odd_and_even_counts() {
        assert_eq!(median(&mut [5.0, 1.0, 3.0]), 3.0);
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), 2.5);
        assert_eq!(median(&mut []), 0.0);
    }

    #[test]
    fn median_seconds_runs_reps_times_and_stops_on_error() {
        let mut n = 0;
        let s = median_seconds(5, || {
            n += 1;
            Ok::<(), ()>(())
        })
        .expect("ok");
        assert_eq!(n, 5);
        assert!(s >= 0.0 && s.is_finite());
        let mut m = 0;
        assert!(
            median_seconds(5, || {
                m += 1;
                Err(())
            })
            .is_err()
        );
        assert_eq!(m, 1);
    }
}
