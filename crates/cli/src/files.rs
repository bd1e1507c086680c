//! Files: read an NC program, patch it through the library, write the output by the
//! output policy ([`crate::outputs`]).

use crate::outputs::{self, Input, Output, PathError, Target};
use polepatch::kinematics::Machine;
use polepatch::{Error, FileReport};
use std::io::Write;
use std::path::Path as FsPath;

/// Errors of a file job.
#[derive(Debug, thiserror::Error)]
pub enum JobError {
    /// The file could not be read.
    #[error("cannot read {path}: {cause}")]
    Read {
        /// File.
        path: String,
        /// Cause (in the message, not a `source()`: error chains would print it twice).
        cause: std::io::Error,
    },
    /// Bad input.
    #[error(transparent)]
    Input(#[from] Error),
    /// The output could not be written.
    #[error("cannot write {path}: {cause}")]
    Write {
        /// Output path.
        path: String,
        /// Cause (in the message, not a `source()`: error chains would print it twice).
        cause: std::io::Error,
    },
    /// The output path is refused by the output policy ([`crate::outputs`]).
    #[error(transparent)]
    Path(#[from] PathError),
}

/// Read a file's bytes; `-` reads standard input to its end.
pub fn read(path: &FsPath) -> Result<Vec<u8>, JobError> {
    let err = |cause| JobError::Read {
        path: shown(path),
        cause,
    };
    if outputs::is_std(path) {
        let mut bytes = Vec::new();
        std::io::Read::read_to_end(&mut std::io::stdin().lock(), &mut bytes).map_err(err)?;
        return Ok(bytes);
    }
    std::fs::read(path).map_err(err)
}

/// An input's name in messages and reports: `<stdin>` for `-`, else the path.
pub fn shown(path: &FsPath) -> String {
    if outputs::is_std(path) {
        "<stdin>".to_string()
    } else {
        path.display().to_string()
    }
}

/// Read, patch and write one file to `output` (checked against the input by the output
/// policy, [`crate::outputs`]).
pub fn patch_file(
    input: &FsPath,
    output: &FsPath,
    machine: &Machine,
    opts: &polepatch::PatchOptions,
) -> Result<FileReport, JobError> {
    let targets = outputs::plan(
        &[Input::new("the input", input)],
        vec![Output::new("-o", output)],
    )?;
    patch_to(input, &targets[0], machine, opts)
}

/// Read one file, patch it through [`polepatch::patch_nc_to`] and write the output to a
/// checked target ([`outputs::plan`]): a temporary file renamed on success (nothing
/// half-written, the input never touched), or a device or FIFO written through.
pub fn patch_to(
    input: &FsPath,
    target: &Target,
    machine: &Machine,
    opts: &polepatch::PatchOptions,
) -> Result<FileReport, JobError> {
    patch_job(input, target, machine, opts, false)
}

/// [`patch_to`], and with `simulate` the simulated times of the input and the output
/// ([`FileReport::simulated`]), from the bytes the job holds: the input it read and the
/// output it wrote (kept in memory beside the write), one simulation when the output is
/// the input. A program that cannot be simulated gets a warning, not an error.
pub fn patch_job(
    input: &FsPath,
    target: &Target,
    machine: &Machine,
    opts: &polepatch::PatchOptions,
    simulate: bool,
) -> Result<FileReport, JobError> {
    let name = shown(input);
    let bytes = read(input)?;
    let write_err = |cause| JobError::Write {
        path: target.path.display().to_string(),
        cause,
    };
    let mut opts = opts.clone();
    opts.read.name = name;
    let like = (!outputs::is_std(input)).then_some(input);
    let mut sink = target.create(like).map_err(write_err)?;
    // With `simulate`, the output is kept as it is written.
    let mut kept: Option<Vec<u8>> = simulate.then(Vec::new);
    let mut report = {
        let w = std::io::BufWriter::with_capacity(1 << 20, &mut sink);
        let mut w = Tee {
            out: w,
            copy: kept.as_mut(),
        };
        let report = match polepatch::patch_nc_to(&bytes, machine, &opts, &mut w) {
            Err(Error::Output(e)) => return Err(write_err(e)),
            r => r?,
        };
        w.out.flush().map_err(write_err)?;
        report
    };
    sink.commit().map_err(write_err)?;
    if let Some(out) = kept {
        simulated(&mut report, &bytes, &out, machine, &opts);
    }
    report.output = Some(if target.is_stdout() {
        "<stdout>".to_string()
    } else {
        target.path.display().to_string()
    });
    Ok(report)
}

/// A writer that also keeps a copy of what it writes.
struct Tee<'a, W: Write> {
    out: W,
    copy: Option<&'a mut Vec<u8>>,
}

impl<W: Write> Write for Tee<'_, W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.out.write(buf)?;
        if let Some(c) = self.copy.as_mut() {
            c.extend_from_slice(&buf[..n]);
        }
        Ok(n)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.out.flush()
    }
}

/// The simulated times of `input` and its patched `output` into `report` (one simulation
/// when no word changed), or a warning naming why they could not be had.
fn simulated(
    report: &mut FileReport,
    input: &[u8],
    output: &[u8],
    machine: &Machine,
    opts: &polepatch::PatchOptions,
) {
    let sim_opts = polepatch::SimulateOptions {
        read: opts.read.clone(),
        sim: polepatch::sim::SimOptions {
            tcy_s: opts.patch.tcy_s,
            ..Default::default()
        },
    };
    let before = polepatch::simulate_nc(input, machine, &sim_opts);
    let after = if report.words_changed == 0 {
        before.as_ref().map(Clone::clone).map_err(|e| e.to_string())
    } else {
        polepatch::simulate_nc(output, machine, &sim_opts).map_err(|e| e.to_string())
    };
    match (before.map_err(|e| e.to_string()), after) {
        (Ok(b), Ok(a)) => report.simulated = Some(polepatch::report::compare(&b, &a)),
        (Err(e), _) | (_, Err(e)) => report
            .warnings
            .push(format!("{}: not simulated: {e}", report.file)),
    }
}
