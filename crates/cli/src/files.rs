//! Files: read an NC program, patch it through the library, write the output safely.

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
    /// Output and input are the same file.
    #[error("{path}: the output would overwrite the input; polepatch never modifies its input")]
    Overwrite {
        /// Path.
        path: String,
    },
}

/// Read a file's bytes.
pub fn read(path: &FsPath) -> Result<Vec<u8>, JobError> {
    std::fs::read(path).map_err(|cause| JobError::Read {
        path: path.display().to_string(),
        cause,
    })
}

/// Read, patch and write one file. The output is written to a temporary file beside it and
/// renamed on success: nothing half-written, the input never touched.
pub fn patch_file(
    input: &FsPath,
    output: &FsPath,
    machine: &Machine,
    opts: &polepatch::PatchOptions,
) -> Result<FileReport, JobError> {
    let name = input.display().to_string();
    if same_file(input, output) {
        return Err(JobError::Overwrite { path: name });
    }
    let bytes = read(input)?;
    let write_err = |cause| JobError::Write {
        path: output.display().to_string(),
        cause,
    };
    // No run point within the cone: the output is the input, proven by a streaming read
    // (memory: the file once).
    let whole = polepatch::PatchOptions {
        name: name.clone(),
        ..opts.clone()
    };
    // The copy is written while the scan runs (it is the output when the scan proves the
    // program far from the pole; otherwise it is deleted).
    let (far, staged) = std::thread::scope(|sc| {
        let copy = sc.spawn(|| stage(output, &bytes, Some(input)));
        let far = polepatch::far::far_from_pole(&bytes, machine, &whole);
        (far, copy.join())
    });
    if let Some(mut report) = far? {
        let staged = staged.unwrap_or_else(|p| std::panic::resume_unwind(p));
        staged
            .map_err(write_err)?
            .persist(output)
            .map_err(|e| write_err(e.error))?;
        report.output = Some(output.display().to_string());
        return Ok(report);
    }
    drop(staged);
    // Near the pole: the output is written as the stretches near the pole are patched
    // (memory: the input and those stretches), to a temporary file renamed on success.
    let mut tmp = temp_beside(output).map_err(write_err)?;
    let mut report = {
        let mut w = std::io::BufWriter::with_capacity(1 << 20, tmp.as_file_mut());
        let report = polepatch::stream::patch_nc_to(&bytes, machine, &whole, &mut w);
        let report = match report {
            Err(Error::Output(e)) => return Err(write_err(e)),
            r => r?,
        };
        w.flush().map_err(write_err)?;
        report
    };
    finish_staged(&mut tmp, output, Some(input)).map_err(write_err)?;
    tmp.persist(output).map_err(|e| write_err(e.error))?;
    report.output = Some(output.display().to_string());
    Ok(report)
}

/// Whether two paths name the same existing file: the same path once `.`, `..` and
/// symbolic links are resolved, or (on Unix) the same device and inode, which also
/// catches a case-insensitive file system's other spelling.
pub fn same_file(a: &FsPath, b: &FsPath) -> bool {
    if let (Ok(x), Ok(y)) = (a.canonicalize(), b.canonicalize())
        && x == y
    {
        return true;
    }
    same_inode(a, b)
}

#[cfg(unix)]
fn same_inode(a: &FsPath, b: &FsPath) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (std::fs::metadata(a), std::fs::metadata(b)) {
        (Ok(x), Ok(y)) => x.dev() == y.dev() && x.ino() == y.ino(),
        _ => false,
    }
}

#[cfg(not(unix))]
fn same_inode(_: &FsPath, _: &FsPath) -> bool {
    false
}

/// Write `bytes` to `path` through a temporary file in the same folder and a rename.
/// The file gets the permissions of the file it replaces, else those of `like` (the
/// input), else rw-r--r-- — not the temporary file's owner-only mode.
pub fn write_atomic_like(
    path: &FsPath,
    bytes: &[u8],
    like: Option<&FsPath>,
) -> std::io::Result<()> {
    stage(path, bytes, like)?
        .persist(path)
        .map_err(|e| e.error)?;
    Ok(())
}

/// The first half of [`write_atomic_like`]: `bytes` written and synced to a temporary
/// file beside `path`, with the permissions it will have. `persist(path)` puts it in
/// place; dropping it deletes it.
pub fn stage(
    path: &FsPath,
    bytes: &[u8],
    like: Option<&FsPath>,
) -> std::io::Result<tempfile::NamedTempFile> {
    let mut tmp = temp_beside(path)?;
    tmp.write_all(bytes)?;
    finish_staged(&mut tmp, path, like)?;
    Ok(tmp)
}

/// [`stage`] for output written as it is made (a trajectory): `write` gets a buffered
/// writer on the temporary file beside `path`; `persist(path)` puts it in place.
pub fn stage_streamed(
    path: &FsPath,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> std::io::Result<tempfile::NamedTempFile> {
    let mut tmp = temp_beside(path)?;
    {
        let mut w = std::io::BufWriter::with_capacity(1 << 16, tmp.as_file_mut());
        write(&mut w)?;
        w.flush()?;
    }
    finish_staged(&mut tmp, path, None)?;
    Ok(tmp)
}

/// An empty temporary file in `path`'s folder (deleted when dropped).
fn temp_beside(path: &FsPath) -> std::io::Result<tempfile::NamedTempFile> {
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => FsPath::new("."),
    };
    tempfile::NamedTempFile::new_in(dir)
}

/// Sync a written temporary file and give it the permissions the file at `path` has,
/// else those of `like`, else rw-r--r--.
fn finish_staged(
    tmp: &mut tempfile::NamedTempFile,
    path: &FsPath,
    like: Option<&FsPath>,
) -> std::io::Result<()> {
    let perms = std::fs::metadata(path)
        .or_else(|e| like.map_or(Err(e), std::fs::metadata))
        .map(|m| m.permissions())
        .ok();
    tmp.as_file().sync_all()?;
    if let Some(perms) = perms.or_else(default_permissions) {
        tmp.as_file().set_permissions(perms)?;
    }
    Ok(())
}

/// [`write_atomic_like`] without a model file (reports, CSV).
pub fn write_atomic(path: &FsPath, bytes: &[u8]) -> std::io::Result<()> {
    write_atomic_like(path, bytes, None)
}

#[cfg(unix)]
fn default_permissions() -> Option<std::fs::Permissions> {
    use std::os::unix::fs::PermissionsExt;
    Some(std::fs::Permissions::from_mode(0o644))
}

#[cfg(not(unix))]
fn default_permissions() -> Option<std::fs::Permissions> {
    None
}
