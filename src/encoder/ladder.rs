//! The k-means ladder's stop: with `--segmentation auto` tdct tries k-means at K, 1.5 K and 2 K
//! ([`super::options::kmeans_ladder`]; a picture codec ranks the same rungs by tdct's estimates,
//! then tries the first with pictures, and the one above when close: `encoder/auto/rungs.rs`); a
//! rung is tried only when the one below it beat the one below that. More clusters fit the motion
//! more closely for more side information, and where 1.5 K did not pay, 2 K did not either on any of 75 default encodes (15 clips, quality 10 … 90),
//! while skipping it spared its segmentation and trials in 41 of them (docs/design.md, "First-frame
//! bits trials and k-means ladder").
//!
//! The rule reads the two rungs' smallest costs (tdct's estimates, a picture codec's sampled costs
//! at equal error), so those must not depend on timing: their
//! trials never stop early (a stopped estimate's bytes are how far it got, which depends on which
//! trials ended first). The gated rung is run by whichever thread ends the later of its two rungs:
//! the same rungs are tried on any number of threads, hence the same stream.

use crate::encoder::Segmentation;
use crate::error::{Error, Result};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;

/// For each job (one per segmentation, in the choice's order), the two jobs whose smallest costs
/// decide whether it runs: the k-means rungs two and one below it.
pub(super) fn gates(segmentations: &[(Segmentation, usize)]) -> Vec<Option<(usize, usize)>> {
    let mut rungs: Vec<usize> = Vec::new();
    segmentations
        .iter()
        .enumerate()
        .map(|(i, (segmentation, _))| {
            if *segmentation != Segmentation::KMeans {
                return None;
            }
            rungs.push(i);
            match rungs.as_slice() {
                [.., two_below, one_below, _] => Some((*two_below, *one_below)),
                _ => None,
            }
        })
        .collect()
}

/// Whether a job's trials may stop early: not when a gate reads its costs.
pub(super) fn may_stop(gates: &[Option<(usize, usize)>], job: usize) -> bool {
    !gates
        .iter()
        .flatten()
        .any(|&(a, b)| a == job || b == job)
}

/// Whether the rung above two finished rungs runs: only if the one below cost strictly less
/// than the one two below (`None`: a rung that failed or had no candidate, which runs it: the
/// choice reports the failure itself; a skipped rung costs +∞).
pub(super) fn climbs(two_below: Option<f64>, one_below: Option<f64>) -> bool {
    match (two_below, one_below) {
        (Some(low), Some(high)) => high < low,
        _ => true,
    }
}

/// Runs every job on rayon's threads and returns their outcomes in the jobs' order (the first
/// job's error in that order if any fails). Each thread takes the next ungated job not yet
/// started, in the jobs' order (a split work list would start the last half's first job beside
/// the first one: the default candidates' estimates are known soonest, and the later jobs' stop
/// sooner). A gated job is claimed by the thread that finishes the second of its two rungs, which
/// runs it at once, or `skip`s it, as [`climbs`] says on their `cost`s.
///
/// No thread ever waits for another job: a rayon thread blocked on a job that its own stack
/// holds (work stealing runs queued tasks inside a wait) would never wake.
pub(super) fn run_jobs<T: Send>(
    gates: &[Option<(usize, usize)>],
    run: impl Fn(usize) -> Result<T> + Sync,
    skip: impl Fn(usize) -> T + Sync,
    cost: impl Fn(&T) -> Option<f64> + Sync,
) -> Result<Vec<T>> {
    let open: Vec<usize> = (0..gates.len()).filter(|&i| gates[i].is_none()).collect();
    let next = AtomicUsize::new(0);
    let claimed: Vec<AtomicBool> = gates.iter().map(|_| AtomicBool::new(false)).collect();
    // Per job: its outcome once ended, and its cost (`Some(None)`: ended without one).
    let done: Vec<Mutex<Option<Result<T>>>> = gates.iter().map(|_| Mutex::new(None)).collect();
    let costs: Mutex<Vec<Option<Option<f64>>>> = Mutex::new(vec![None; gates.len()]);
    // A skipped rung counts as costing more than any: the rungs above it are skipped too.
    let finish = |i: usize, outcome: Result<T>, skipped: bool| {
        let c = match skipped {
            true => Some(f64::INFINITY),
            false => outcome.as_ref().ok().and_then(&cost),
        };
        if let Ok(mut costs) = costs.lock() {
            costs[i] = Some(c);
        }
        if let Ok(mut slot) = done[i].lock() {
            *slot = Some(outcome);
        }
    };
    // The gated jobs whose two rungs have ended, not claimed yet: claimed now, with whether to run.
    let ready = || -> Vec<(usize, bool)> {
        let Ok(costs) = costs.lock() else {
            return Vec::new();
        };
        let mut ready = Vec::new();
        for (g, gate) in gates.iter().enumerate() {
            let Some((a, b)) = *gate else { continue };
            if let (Some(low), Some(high)) = (costs[a], costs[b]) {
                if !claimed[g].swap(true, Ordering::Relaxed) {
                    ready.push((g, climbs(low, high)));
                }
            }
        }
        ready
    };
    let workers = rayon::current_num_threads().clamp(1, open.len().max(1));
    rayon::scope(|scope| {
        for _ in 0..workers {
            scope.spawn(|_| {
                while let Some(&i) = open.get(next.fetch_add(1, Ordering::Relaxed)) {
                    finish(i, run(i), false);
                    // A gated job's outcome may make the next rung ready: until none is.
                    let mut pending = ready();
                    while let Some((g, runs)) = pending.pop() {
                        match runs {
                            true => finish(g, run(g), false),
                            false => finish(g, Ok(skip(g)), true),
                        }
                        pending.extend(ready());
                    }
                }
            });
        }
    });
    done.into_iter()
        .map(|slot| {
            let outcome = slot.into_inner().ok().flatten();
            outcome.unwrap_or_else(|| Err(Error::Codec("a trial of the choice did not end".into())))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    const DECIMATION: Segmentation = Segmentation::Decimation { e0: 0.1 };

    #[test]
    fn the_third_rung_is_gated_by_the_two_below() {
        let ladder = [
            (Segmentation::KMeans, 20),
            (Segmentation::KMeans, 30),
            (Segmentation::KMeans, 40),
            (DECIMATION, 20),
        ];
        let gated = gates(&ladder);
        assert_eq!(gated, vec![None, None, Some((0, 1)), None]);
        assert!(!may_stop(&gated, 0) && !may_stop(&gated, 1));
        assert!(may_stop(&gated, 2) && may_stop(&gated, 3));
        // One K (the user's) or two: nothing gated.
        assert_eq!(gates(&ladder[..2]), vec![None, None]);
        assert_eq!(gates(&[(Segmentation::KMeans, 20), (DECIMATION, 20)]), vec![None, None]);
    }

    #[test]
    fn a_rung_runs_only_when_the_one_below_paid() {
        assert!(climbs(Some(10.0), Some(9.0)));
        assert!(!climbs(Some(10.0), Some(10.0)));
        assert!(!climbs(Some(10.0), Some(11.0)));
        assert!(climbs(None, Some(11.0)) && climbs(Some(10.0), None));
    }

    /// Runs a ladder of five rungs (each gated by the two below) and one other job, whose
    /// costs are `costs`, on `threads` threads: which jobs ran.
    fn ran(costs: [f64; 6], threads: usize) -> Vec<bool> {
        let ladder: Vec<(Segmentation, usize)> = (0..5)
            .map(|k| (Segmentation::KMeans, 10 + k))
            .chain([(DECIMATION, 0)])
            .collect();
        let gated = gates(&ladder);
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build();
        let pool = pool.unwrap_or_else(|e| panic!("{e}"));
        let outcomes = pool.install(|| {
            run_jobs(
                &gated,
                |i| {
                    // Jobs of uneven length, so that they end in varied orders.
                    std::thread::sleep(std::time::Duration::from_millis(1 + (7 * i as u64) % 5));
                    Ok(Some(costs[i]))
                },
                |_| None,
                |c| *c,
            )
        });
        let outcomes = outcomes.unwrap_or_else(|e| panic!("{e}"));
        outcomes.iter().map(Option::is_some).collect()
    }

    #[test]
    fn the_same_rungs_run_on_any_number_of_threads() {
        // 9 → 8 paid, so the third rung runs; 8 → 8.5 did not, so the fourth is skipped, and
        // the fifth with it (a ladder stops at the first rung that does not pay).
        let costs = [9.0, 8.0, 8.5, 7.0, 1.0, 3.0];
        for threads in [1, 2, 3, 8] {
            assert_eq!(ran(costs, threads), [true, true, true, false, false, true], "{threads}");
        }
        // A steadily paying ladder climbs to the top.
        let costs = [9.0, 8.0, 7.0, 6.0, 5.0, 3.0];
        for threads in [1, 2, 8] {
            assert_eq!(ran(costs, threads), [true; 6], "{threads}");
        }
    }
}
