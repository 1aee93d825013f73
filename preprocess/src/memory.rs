//! How much memory a bake holds: the process's peak, and each stage's own peak, sampled; and
//! how much CPU time the process has used (each stage's share of the cores).
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

/// Clock ticks a second of `/proc/self/stat`'s CPU times: Linux's USER_HZ, 100 on every
/// architecture visgate builds for.
const USER_HZ: f64 = 100.0;

/// CPU time this process has used, every thread's, user and system (Linux
/// `/proc/self/stat`; to 10 ms). [Units: s]
pub fn process_cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    Some(stat_cpu_ticks(&stat)? as f64 / USER_HZ)
}

/// User plus system ticks of a `/proc/PID/stat` line: its 14th and 15th fields, counted after
/// the command's name in parentheses (which may hold spaces and parentheses itself).
fn stat_cpu_ticks(stat: &str) -> Option<u64> {
    let after_name = &stat[stat.rfind(')')? + 1..];
    let mut fields = after_name.split_whitespace().skip(11);
    let user: u64 = fields.next()?.parse().ok()?;
    let system: u64 = fields.next()?.parse().ok()?;
    Some(user + system)
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
    fn cpu_ticks_are_read_after_a_name_with_spaces_and_parentheses() {
        // pid (comm) state ppid pgrp session tty tpgid flags minflt cminflt majflt cmajflt
        // utime stime ...
        let line = "4242 (vis gate) (x)) R 1 4242 4242 0 -1 4194304 950 0 0 0 377 23 0 0 20 0";
        assert_eq!(stat_cpu_ticks(line), Some(400));
        assert_eq!(stat_cpu_ticks("4242 (visgate) R 1 2"), None);
        // This process's own line reads.
        assert!(process_cpu_seconds().is_some_and(|s| s >= 0.0));
    }

    #[test]
    fn a_stage_that_holds_64_mib_has_a_peak_of_64_mib_at_least() {
        let stage = StagePeak::start();
        // Touched, so that it is resident (a zeroed allocation would map pages lazily).
        let held: Vec<u8> = (0..64usize << 20).map(|i| i as u8).collect();
        // Kept alive past the sample, or an optimised build drops the allocation.
        std::hint::black_box(&held);
        let peak = stage.finish().expect("Linux tells the resident set");
        assert!(peak >= 64 << 20, "{peak} bytes");
        // The process's peak holds what is resident now. Not compared with the stage's sampled
        // peak: the tests beside this one allocate and free too, and the kernel's high-water
        // mark is kept lazily (a CI rehearsal sampled 87 MB, then read a lower VmHWM).
        let process = peak_memory_bytes();
        assert!(process.is_some_and(|p| p >= 64 << 20), "{process:?}");
        drop(held);
    }
}
