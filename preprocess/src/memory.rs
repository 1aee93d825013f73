//! How much memory a bake holds: the process's peak, and each stage's own peak, sampled.
//!
//! A stage's peak is the largest resident set seen while it ran, read from the OS every few
//! milliseconds by a thread of its own (Linux: `/proc/self/status`); elsewhere there is none.
//! Resetting the kernel's high-water mark instead (`/proc/self/clear_refs`) would give exact
//! peaks but also reset what `getrusage` and GNU time report for the whole process.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::thread::JoinHandle;
use std::time::Duration;

/// How often a stage's resident set is read.
const SAMPLE_EVERY: Duration = Duration::from_millis(4);

/// A field of `/proc/self/status` in bytes (its value is in kB).
fn status_bytes(field: &str) -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with(field))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// Peak resident set size of this process (Linux `VmHWM`), bytes.
pub fn peak_memory_bytes() -> Option<u64> {
    status_bytes("VmHWM:")
}

/// Samples the resident set while a stage runs.
pub(crate) struct StagePeak {
    stop: Arc<AtomicBool>,
    peak: Arc<AtomicU64>,
    sampler: Option<JoinHandle<()>>,
}

impl StagePeak {
    /// Starts sampling (nothing where the OS does not tell the resident set).
    pub fn start() -> StagePeak {
        let stop = Arc::new(AtomicBool::new(false));
        let peak = Arc::new(AtomicU64::new(status_bytes("VmRSS:").unwrap_or(0)));
        let sampler = (peak.load(Ordering::Relaxed) > 0).then(|| {
            let (stop, peak) = (stop.clone(), peak.clone());
            std::thread::spawn(move || {
                while !stop.load(Ordering::Relaxed) {
                    if let Some(rss) = status_bytes("VmRSS:") {
                        peak.fetch_max(rss, Ordering::Relaxed);
                    }
                    // Woken early when the stage ends, so that a short stage does not wait.
                    std::thread::park_timeout(SAMPLE_EVERY);
                }
            })
        });
        StagePeak {
            stop,
            peak,
            sampler,
        }
    }

    /// Stops sampling: the largest resident set seen, bytes.
    pub fn finish(mut self) -> Option<u64> {
        self.stop.store(true, Ordering::Relaxed);
        let sampler = self.sampler.take()?;
        sampler.thread().unpark();
        sampler.join().ok()?;
        let end = status_bytes("VmRSS:").unwrap_or(0);
        Some(self.peak.load(Ordering::Relaxed).max(end))
    }
}

#[cfg(all(test, target_os = "linux"))]
mod tests {
    use super::*;

    #[test]
    fn a_stage_that_holds_64_mib_has_a_peak_of_64_mib_at_least() {
        let stage = StagePeak::start();
        // Touched, so that it is resident (a zeroed allocation would map pages lazily).
        let held: Vec<u8> = (0..64usize << 20).map(|i| i as u8).collect();
        // Kept alive past the sample, or an optimised build drops the allocation.
        std::hint::black_box(&held);
        let peak = stage.finish().expect("Linux tells the resident set");
        assert!(peak >= 64 << 20, "{peak} bytes");
        assert!(peak_memory_bytes().is_some_and(|p| p >= peak), "{peak}");
        drop(held);
    }
}
