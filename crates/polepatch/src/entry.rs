//! The entry points for NC programs held in memory: bytes in, bytes (or a report) out.
//! Each checks its options, then hands the bytes to the one reader ([`crate::stream`]).

use crate::error::Error;
use crate::hooks::Hooks;
use crate::options::{AnalyzeOptions, PatchOptions};
use crate::report::{AnalyzeReport, FileReport};
use crate::{program, stream};
use polepatch_kinematics::Machine;

/// Patch an NC program held in memory: the rewritten bytes (identical to `bytes` except
/// the rotary words that had to change) and the report. [`patch_nc_to`] into a `Vec`.
///
/// Programs of up to 4 GiB are read (the reader's byte offsets are 32-bit); memory is about
/// twice the input for a program far from the pole, plus about ten times each run near it
/// (docs/performance-nc.md). Where memory cannot be had the call returns
/// [`Error::OutOfMemory`] (or a parse error naming it) instead of aborting the process.
///
/// Bad input (syntax errors with line and column, an empty program, no G1 motion, no
/// rotary words) is an [`Error`]; a zone that cannot reach feed is a status in the report.
pub fn patch_nc(
    bytes: &[u8],
    machine: &Machine,
    opts: &PatchOptions,
) -> Result<(Vec<u8>, FileReport), Error> {
    // The output is about the input's size: a host that cannot give it gets an error,
    // not an abort (the reader reserves its own tables the same way).
    let mut out = Vec::new();
    out.try_reserve(bytes.len())
        .map_err(|_| Error::OutOfMemory {
            what: "the output",
            bytes: bytes.len(),
        })?;
    let report = patch_nc_to(bytes, machine, opts, &mut out)?;
    Ok((out, report))
}

/// Patch an NC program held in memory, writing the output to `out`: the one entry every
/// caller goes through (the CLI's file jobs, [`patch_nc`], hence the C ABI and `post`).
///
/// The one reader: a first read finds the runs and which come near the pole; a program with
/// none has no zone, and its output is its input, written in one piece. Otherwise a second
/// read parses the stretches near the pole; they are patched and written in file order,
/// everything between them copied.
///
/// On an error nothing more is written; what was written before it must be discarded by
/// the caller (the CLI writes to a temporary file). A failed write is [`Error::Output`].
pub fn patch_nc_to(
    bytes: &[u8],
    machine: &Machine,
    opts: &PatchOptions,
    out: &mut dyn std::io::Write,
) -> Result<FileReport, Error> {
    patch_nc_hooked(bytes, machine, opts, out, Hooks::NONE)
}

/// [`patch_nc_to`] with [`Hooks`]: progress as the output is written, and a cancellation
/// check between stretches (a cancelled patch ends with [`Error::Cancelled`]).
pub fn patch_nc_hooked(
    bytes: &[u8],
    machine: &Machine,
    opts: &PatchOptions,
    out: &mut dyn std::io::Write,
    hooks: Hooks<'_>,
) -> Result<FileReport, Error> {
    if (hooks.cancelled)() {
        return Err(Error::Cancelled);
    }
    stream::patch_nc_hooked(bytes, machine, opts, out, hooks)
        .map_err(|e| program::or_cl_file(e, bytes, &opts.read.name))
}

/// Equation 6 along every run of an NC program held in memory (what `polepatch analyze`
/// prints).
pub fn analyze_nc(
    bytes: &[u8],
    machine: &Machine,
    opts: &AnalyzeOptions,
) -> Result<AnalyzeReport, Error> {
    stream::analyze_nc_stretches(bytes, machine, opts)
}
