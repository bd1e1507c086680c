//! What a caller may ask of a long patch while it runs: progress and cancellation.
//!
//! [`crate::patch_nc_hooked`] (and [`crate::patch_nc_to`] on it) calls them
//! between stretches — a stretch is a run near the pole, with the runs that share a
//! block with it ([`crate::stream`]) — never inside one: a stretch is patched whole or not
//! at all. The CLI's `filter` prints the progress as LinuxCNC's `FILTER_PROGRESS=N`; the
//! Python package cancels on Ctrl-C.

/// Callbacks of a patch. Both may be called from several worker threads at once.
#[derive(Clone, Copy)]
pub struct Hooks<'a> {
    /// Called with (bytes of the input done, bytes in all) as the output is written, in
    /// file order, ending with (n, n) on success.
    pub progress: &'a (dyn Fn(usize, usize) + Sync),
    /// Returns `true` when the caller wants the patch stopped: checked before each
    /// stretch is patched and before each batch of them is written. The patch then ends
    /// with [`crate::Error::Cancelled`]; what was written to the output must be discarded.
    pub cancelled: &'a (dyn Fn() -> bool + Sync),
}

impl Hooks<'static> {
    /// No progress, never cancelled.
    pub const NONE: Hooks<'static> = Hooks {
        progress: &|_, _| {},
        cancelled: &|| false,
    };
}

impl std::fmt::Debug for Hooks<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Hooks")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinematics::Machine;
    use std::sync::Mutex;
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// `copies` passes near the pole, each its own run and stretch.
    fn many_zones(copies: usize) -> Vec<u8> {
        let body = include_str!("../../../fixtures/generated/fanuc-ac-swing-d1.nc");
        let moves: Vec<&str> = body
            .lines()
            .filter(|l| l.starts_with('X') || l.starts_with("G1 "))
            .collect();
        let mut out = String::from("%\nO1000\nG90 G21 G94\nG43.4 H1\n");
        for _ in 0..copies {
            out.push_str("G0 Z50\n");
            for m in &moves {
                out.push_str(m);
                out.push('\n');
            }
        }
        out.push_str("G49\nM30\n%\n");
        out.into_bytes()
    }

    #[test]
    fn progress_rises_to_the_whole_file_and_the_output_is_patch_nc_s() {
        let machine = Machine::builtin("mikron-ucp710").unwrap();
        let bytes = many_zones(40);
        let seen = Mutex::new(Vec::new());
        let progress = |done: usize, total: usize| seen.lock().unwrap().push((done, total));
        let hooks = Hooks {
            progress: &progress,
            cancelled: &|| false,
        };
        let mut out = Vec::new();
        let opts = crate::PatchOptions::default();
        let report = crate::patch_nc_hooked(&bytes, &machine, &opts, &mut out, hooks).unwrap();
        let (plain, plain_report) = crate::patch_nc(&bytes, &machine, &opts).unwrap();
        assert_eq!(out, plain);
        assert_eq!(report.zones.len(), plain_report.zones.len());
        assert!(report.zones.len() >= 40);
        let seen = seen.into_inner().unwrap();
        assert!(seen.len() >= 2, "{seen:?}");
        assert!(seen.windows(2).all(|w| w[0].0 <= w[1].0), "{seen:?}");
        assert_eq!(seen.last(), Some(&(bytes.len(), bytes.len())));
    }

    #[test]
    fn a_cancelled_patch_stops_between_stretches_with_cancelled() {
        let machine = Machine::builtin("mikron-ucp710").unwrap();
        let bytes = many_zones(40);
        // Cancelled from the 3rd check on: some stretches are patched, not all.
        let checks = AtomicUsize::new(0);
        let cancelled = || checks.fetch_add(1, Ordering::Relaxed) >= 3;
        let hooks = Hooks {
            progress: &|_, _| {},
            cancelled: &cancelled,
        };
        let mut out = Vec::new();
        let r = crate::patch_nc_hooked(
            &bytes,
            &machine,
            &crate::PatchOptions::default(),
            &mut out,
            hooks,
        );
        assert!(matches!(r, Err(crate::Error::Cancelled)), "{r:?}");
        assert!(out.len() < bytes.len(), "stopped before the end");
        // Cancelled before it starts: nothing is done.
        let r = crate::patch_nc_hooked(
            &bytes,
            &machine,
            &crate::PatchOptions::default(),
            &mut Vec::new(),
            Hooks {
                progress: &|_, _| {},
                cancelled: &|| true,
            },
        );
        assert!(matches!(r, Err(crate::Error::Cancelled)));
    }
}
