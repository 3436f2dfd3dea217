//! Work spread over threads: the candidates of a round, their sensitivities and replays.

use crate::context::ProgressBars;

/// Runs `f` on every item over `jobs` threads, results in the items' order.
pub(crate) fn parallel_map<T: Sync, R: Send>(items: &[T], jobs: usize, f: impl Fn(&T) -> R + Sync) -> Vec<R> {
    let jobs = jobs.clamp(1, items.len().max(1));
    if jobs == 1 {
        return items.iter().map(f).collect();
    }
    let next = std::sync::atomic::AtomicUsize::new(0);
    let mut out: Vec<(usize, R)> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..jobs)
            .map(|_| {
                scope.spawn(|| {
                    let mut mine = vec![];
                    loop {
                        let k = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        if k >= items.len() {
                            break;
                        }
                        mine.push((k, f(&items[k])));
                    }
                    mine
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().expect("a diagnosis worker panicked"))
            .collect()
    });
    out.sort_by_key(|(k, _)| *k);
    out.into_iter().map(|(_, r)| r).collect()
}

/// [`parallel_map`] with a progress bar over the items.
pub(crate) fn parallel_map_shown<T: Sync, R: Send>(
    phase: &str,
    bars: &Option<std::sync::Arc<dyn ProgressBars>>,
    items: &[T],
    jobs: usize,
    f: impl Fn(&T) -> R + Sync,
) -> Vec<R> {
    match bars {
        None => parallel_map(items, jobs, f),
        Some(bars) => {
            bars.start(phase, items.len());
            let out = parallel_map(items, jobs, |item| {
                let r = f(item);
                bars.advance();
                r
            });
            bars.finish();
            out
        }
    }
}
