//! The output-path policy: every file a command writes (NC programs, reports, CSV, JSON,
//! SVG plots, and any later trajectory file) is planned and written through this module.
//! The rules, in `docs/output-paths.md`:
//!
//! 1. **Never an input.** An output that is the same file as anything the command reads
//!    (the NC or CL inputs, every file of an input folder, a machine file) is refused. The
//!    same file means the same device and inode (Unix) or the same canonical path: any
//!    spelling, `..`, a symbolic or hard link, a case-insensitive file system's other case.
//!    All inputs exist before the command writes anything, so this also covers a file
//!    that a batch would read after writing it.
//! 2. **Never two outputs on one path**, by the same identity (`-o X --report X`, two
//!    inputs of one file name in a batch).
//! 3. **Never outside `--out-dir`**: a batch output's path under it is built from names
//!    only (no `..`), and one that would leave it through a symbolic link is refused.
//! 4. **Refused before anything is written**: [`plan`] checks every output of a command
//!    together; only then is anything created.
//! 5. **Regular files are replaced atomically**: written to a temporary file in the same
//!    folder, named `.<name>.polepatch-tmp-XXXXXX`, synced, given the permissions of the
//!    file it replaces (else of the input it derives from, else rw-r--r--), and renamed
//!    over the output on success. A failed job deletes it; so does SIGINT, SIGTERM or
//!    SIGHUP ([`remove_temporaries_on_signal`]). A run killed outright leaves it; the next
//!    run that writes the same output removes it ([`remove_stale`]: not locked, older than
//!    [`STALE_AFTER`]).
//! 6. **Anything else that exists is written through**: a character device (`/dev/null`,
//!    a terminal), a FIFO or a socket is opened and written, never replaced by a rename.
//!    A character device is a stream, not a file: it may take several outputs and may
//!    also be an input (`/dev/stdin` and `/dev/stdout` on one terminal).
//! 7. **A symbolic link at an output path is followed**: the file it points to is
//!    replaced (through a temporary file in that file's folder) and the link stays; a link
//!    to an input is refused by rule 1; a dangling link is refused (its target is not
//!    created).
//! 8. **`-` is standard output** (and, as an input, standard input): written through,
//!    never a file named `-`; at most one output may be `-`.

use std::fs;
use std::io::{self, Write};
use std::path::{Component, Path, PathBuf};
use std::sync::Mutex;

/// Why an output path is refused. Every message names both paths involved.
#[derive(Debug, thiserror::Error)]
pub enum PathError {
    /// The output is a file the command reads.
    #[error(
        "{what} {path} is {input_what} {input} (the same file); polepatch never writes over a file it reads"
    )]
    Input {
        /// The output's role (`-o`, `--report`, `the output of a/x.nc`).
        what: String,
        /// The output path as given.
        path: String,
        /// The input's role (`the input`, `the machine file`).
        input_what: String,
        /// The input path as given.
        input: String,
    },
    /// Two outputs on one file.
    #[error(
        "{what} {path} and {other_what} {other} are the same file; each output needs its own path"
    )]
    Clash {
        /// The first output's role.
        what: String,
        /// Its path.
        path: String,
        /// The second output's role.
        other_what: String,
        /// Its path.
        other: String,
    },
    /// A batch output that would not be under `--out-dir`.
    #[error("{what} {path} would be outside --out-dir {dir} ({why}); outputs stay under it")]
    Outside {
        /// The output's role.
        what: String,
        /// Its path.
        path: String,
        /// The folder.
        dir: String,
        /// How it would leave it.
        why: String,
    },
    /// A symbolic link whose target does not exist.
    #[error(
        "{what} {path} is a symbolic link to {target}, which does not exist; polepatch follows a link at an output path but does not create its target"
    )]
    Dangling {
        /// The output's role.
        what: String,
        /// Its path.
        path: String,
        /// Where the link points.
        target: String,
    },
    /// The output path is a folder.
    #[error("{what} {path} is a folder; give a file path")]
    Folder {
        /// The output's role.
        what: String,
        /// Its path.
        path: String,
    },
    /// `--out-dir` names something that is not a folder.
    #[error("--out-dir {dir} exists and is not a folder")]
    OutDirNotFolder {
        /// The path.
        dir: String,
    },
    /// The file system could not be asked.
    #[error("{what} {path}: {cause}")]
    Io {
        /// The output's role.
        what: String,
        /// Its path.
        path: String,
        /// Cause (in the message, not a `source()`: error chains would print it twice).
        cause: io::Error,
    },
}

/// A file the command reads, with its role for messages.
#[derive(Debug, Clone)]
pub struct Input {
    /// Role: `the input`, `the machine file`, `the CL input`.
    pub what: String,
    /// Path as given.
    pub path: PathBuf,
}

impl Input {
    /// An input with its role.
    pub fn new(what: impl Into<String>, path: impl Into<PathBuf>) -> Self {
        Input {
            what: what.into(),
            path: path.into(),
        }
    }
}

/// A file the command will write, with its role for messages.
#[derive(Debug, Clone)]
pub struct Output {
    /// Role: `-o`, `--report`, `--csv`, `--plot`, `the output`.
    pub what: String,
    /// Path as given (or built under `--out-dir`).
    pub path: PathBuf,
    /// The path in messages (with the input it comes from, for a batch output).
    shown: String,
    /// For a batch output: the `--out-dir` it must stay under.
    under: Option<PathBuf>,
}

impl Output {
    /// An output with its role.
    pub fn new(what: impl Into<String>, path: impl Into<PathBuf>) -> Self {
        let path = path.into();
        Output {
            what: what.into(),
            shown: path.display().to_string(),
            path,
            under: None,
        }
    }

    /// The batch output of `input`: `rel` (names only: no root, no `..`) under `dir`.
    pub fn under(input: &Path, dir: &Path, rel: &Path) -> Result<Self, PathError> {
        let path = dir.join(rel);
        let shown = format!("{} (from {})", path.display(), input.display());
        if let Some(c) = rel
            .components()
            .find(|c| !matches!(c, Component::Normal(_) | Component::CurDir))
        {
            return Err(PathError::Outside {
                what: "the output".into(),
                path: shown,
                dir: dir.display().to_string(),
                why: format!("its relative path {} has {c:?}", rel.display()),
            });
        }
        Ok(Output {
            what: "the output".into(),
            shown,
            path,
            under: Some(dir.to_path_buf()),
        })
    }
}

/// A checked output: where to write and how.
#[derive(Debug, Clone)]
pub struct Target {
    /// Role, for messages.
    pub what: String,
    /// The path as given (reports).
    pub path: PathBuf,
    /// The path in messages.
    shown: String,
    /// The file that is replaced: `path` with symbolic links resolved.
    file: PathBuf,
    /// An existing non-regular file (device, FIFO, socket): opened and written.
    through: bool,
    /// `-`: standard output (written through).
    stdout: bool,
}

/// `-`: standard input as an input, standard output as an output (rule 8).
pub fn is_std(path: &Path) -> bool {
    path.as_os_str() == "-"
}

/// Identity of an existing file: device and inode on Unix.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Id(u64, u64);

#[cfg(unix)]
fn id_of(m: &fs::Metadata) -> Option<Id> {
    use std::os::unix::fs::MetadataExt;
    Some(Id(m.dev(), m.ino()))
}

#[cfg(not(unix))]
fn id_of(_: &fs::Metadata) -> Option<Id> {
    None
}

#[cfg(unix)]
fn is_char_device(m: &fs::Metadata) -> bool {
    use std::os::unix::fs::FileTypeExt;
    m.file_type().is_char_device()
}

#[cfg(not(unix))]
fn is_char_device(_: &fs::Metadata) -> bool {
    false
}

/// What is at a path, links followed.
struct Found {
    /// The path made absolute, symbolic links of the existing part resolved, the rest
    /// (not yet created) appended with `.` and `..` applied.
    key: PathBuf,
    /// Metadata of the existing file (links followed).
    meta: Option<fs::Metadata>,
}

fn absolute(path: &Path) -> io::Result<PathBuf> {
    if path.is_absolute() {
        Ok(path.to_path_buf())
    } else {
        Ok(std::env::current_dir()?.join(path))
    }
}

/// [`Found`] for `path`.
fn find(path: &Path) -> io::Result<Found> {
    let abs = absolute(path)?;
    let meta = match fs::metadata(&abs) {
        Ok(m) => Some(m),
        Err(e) if e.kind() == io::ErrorKind::NotFound => None,
        Err(e) => return Err(e),
    };
    let comps: Vec<Component> = abs.components().collect();
    for k in (1..=comps.len()).rev() {
        let prefix: PathBuf = comps[..k].iter().collect();
        if let Ok(mut key) = fs::canonicalize(&prefix) {
            for c in &comps[k..] {
                match c {
                    Component::ParentDir => {
                        key.pop();
                    }
                    Component::CurDir => {}
                    c => key.push(c),
                }
            }
            return Ok(Found { key, meta });
        }
    }
    Ok(Found { key: abs, meta })
}

/// Check every output of a command against its inputs and each other (module docs), before
/// anything is written. Inputs that do not exist are skipped (reading them fails later).
pub fn plan(inputs: &[Input], outputs: Vec<Output>) -> Result<Vec<Target>, PathError> {
    let mut input_ids: Vec<(Option<Id>, PathBuf, &Input)> = Vec::new();
    for input in inputs {
        if is_std(&input.path) {
            continue;
        }
        if let Ok(found) = find(&input.path)
            && let Some(m) = &found.meta
            && !m.is_dir()
            && !is_char_device(m)
        {
            input_ids.push((id_of(m), found.key, input));
        }
    }
    let mut targets: Vec<(Target, Found)> = Vec::with_capacity(outputs.len());
    for out in outputs {
        if out.under.is_none() && is_std(&out.path) {
            if let Some((other, _)) = targets.iter().find(|(t, _)| t.stdout) {
                return Err(PathError::Clash {
                    what: other.what.clone(),
                    path: "- (standard output)".into(),
                    other_what: out.what,
                    other: "- (standard output)".into(),
                });
            }
            let target = Target {
                what: out.what,
                shown: "standard output".into(),
                path: out.path,
                file: PathBuf::new(),
                through: true,
                stdout: true,
            };
            targets.push((
                target,
                Found {
                    key: PathBuf::new(),
                    meta: None,
                },
            ));
            continue;
        }
        let shown = out.shown.clone();
        let io_err = |cause| PathError::Io {
            what: out.what.clone(),
            path: shown.clone(),
            cause,
        };
        let found = find(&out.path).map_err(io_err)?;
        if found.meta.is_none()
            && let Ok(link) = fs::read_link(&out.path)
        {
            return Err(PathError::Dangling {
                what: out.what,
                path: shown,
                target: link.display().to_string(),
            });
        }
        let through = match &found.meta {
            Some(m) if m.is_dir() => {
                return Err(PathError::Folder {
                    what: out.what,
                    path: shown,
                });
            }
            Some(m) => !m.is_file(),
            None => false,
        };
        if let Some(dir) = &out.under {
            let dir_found = find(dir).map_err(io_err)?;
            if dir_found.meta.as_ref().is_some_and(|m| !m.is_dir()) {
                return Err(PathError::OutDirNotFolder {
                    dir: dir.display().to_string(),
                });
            }
            if !found.key.starts_with(&dir_found.key) {
                return Err(PathError::Outside {
                    what: out.what,
                    path: shown,
                    dir: dir.display().to_string(),
                    why: format!("it resolves to {}", found.key.display()),
                });
            }
        }
        let stream = found.meta.as_ref().is_some_and(is_char_device);
        if !stream {
            let id = found.meta.as_ref().and_then(id_of);
            for (input_id, input_key, input) in &input_ids {
                if *input_key == found.key || (id.is_some() && id == *input_id) {
                    return Err(PathError::Input {
                        what: out.what,
                        path: shown,
                        input_what: input.what.clone(),
                        input: input.path.display().to_string(),
                    });
                }
            }
            for (other, other_found) in &targets {
                let same_id = match (&found.meta, &other_found.meta) {
                    (Some(a), Some(b)) => id_of(a).is_some() && id_of(a) == id_of(b),
                    _ => false,
                };
                if other_found.key == found.key || same_id {
                    return Err(PathError::Clash {
                        what: other.what.clone(),
                        path: other.shown.clone(),
                        other_what: out.what,
                        other: shown,
                    });
                }
            }
        }
        let target = Target {
            what: out.what,
            shown,
            path: out.path,
            file: found.key.clone(),
            through,
            stdout: false,
        };
        targets.push((target, found));
    }
    Ok(targets.into_iter().map(|(t, _)| t).collect())
}

impl Target {
    /// Whether the output is written through (an existing device, FIFO or socket) rather
    /// than replaced.
    pub fn is_written_through(&self) -> bool {
        self.through
    }

    /// Whether the output is standard output (`-`).
    pub fn is_stdout(&self) -> bool {
        self.stdout
    }

    /// Start writing the output: a temporary file beside the file it replaces (its folders
    /// created), or the device or FIFO opened for writing. `like` is the input whose
    /// permissions a new file takes.
    pub fn create(&self, like: Option<&Path>) -> io::Result<Sink> {
        if self.stdout {
            return Ok(Sink {
                inner: SinkInner::Stdout(io::stdout()),
                file: PathBuf::new(),
                like: None,
            });
        }
        if self.through {
            let file = fs::OpenOptions::new().write(true).open(&self.path)?;
            return Ok(Sink {
                inner: SinkInner::Through(file),
                file: self.file.clone(),
                like: None,
            });
        }
        let dir = match self.file.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        fs::create_dir_all(dir)?;
        let name = self
            .file
            .file_name()
            .map_or("output".into(), |n| n.to_string_lossy().into_owned());
        Ok(Sink {
            inner: SinkInner::Temp(Staged::new(dir, &name)?),
            file: self.file.clone(),
            like: like.map(Path::to_path_buf),
        })
    }

    /// Write `bytes` as the whole output ([`Target::create`], write, [`Sink::commit`]).
    pub fn write(&self, bytes: &[u8], like: Option<&Path>) -> io::Result<()> {
        let mut sink = self.create(like)?;
        sink.write_all(bytes)?;
        sink.commit()
    }
}

/// An output being written ([`Target::create`]): commit it to put it in place; dropped
/// uncommitted, its temporary file is deleted.
pub struct Sink {
    inner: SinkInner,
    file: PathBuf,
    like: Option<PathBuf>,
}

enum SinkInner {
    Temp(Staged),
    Through(fs::File),
    Stdout(io::Stdout),
}

impl Sink {
    /// Finish: a temporary file is synced, given its permissions and renamed over the
    /// output; a written-through output is flushed.
    pub fn commit(self) -> io::Result<()> {
        match self.inner {
            SinkInner::Through(mut f) => f.flush(),
            SinkInner::Stdout(mut f) => f.flush(),
            SinkInner::Temp(mut staged) => {
                let perms = fs::metadata(&self.file)
                    .or_else(|e| self.like.as_deref().map_or(Err(e), fs::metadata))
                    .map(|m| m.permissions())
                    .ok()
                    .or_else(default_permissions);
                let f = staged.file();
                f.sync_all()?;
                if let Some(perms) = perms {
                    f.set_permissions(perms)?;
                }
                staged.persist(&self.file)
            }
        }
    }

    fn writer(&mut self) -> &mut dyn Write {
        match &mut self.inner {
            SinkInner::Through(f) => f,
            SinkInner::Stdout(f) => f,
            SinkInner::Temp(s) => s.file(),
        }
    }
}

impl Write for Sink {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.writer().write(buf)
    }
    fn write_all(&mut self, buf: &[u8]) -> io::Result<()> {
        self.writer().write_all(buf)
    }
    fn flush(&mut self) -> io::Result<()> {
        self.writer().flush()
    }
}

#[cfg(unix)]
fn default_permissions() -> Option<fs::Permissions> {
    use std::os::unix::fs::PermissionsExt;
    Some(fs::Permissions::from_mode(0o644))
}

#[cfg(not(unix))]
fn default_permissions() -> Option<fs::Permissions> {
    None
}

/// Temporary files that exist now, for the signal handler.
static LIVE: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn live() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    LIVE.lock().unwrap_or_else(|p| p.into_inner())
}

/// Marker in the name of every temporary file: `.<name>.polepatch-tmp-XXXXXX`.
pub const TEMP_MARKER: &str = ".polepatch-tmp-";

/// A temporary file older than this whose writer is gone is removed by the next run that
/// writes the same output ([`remove_stale`]).
pub const STALE_AFTER: std::time::Duration = std::time::Duration::from_secs(10);

/// Remove the temporary files that a run killed outright (SIGKILL, a power cut: no
/// clean-up could run) left for the output `name` in `dir`: those named
/// `.<name>.polepatch-tmp-*`, last written more than [`STALE_AFTER`] ago, and not locked.
/// Every run holds an exclusive `flock` on its temporary file while it writes, which the
/// system releases when the process ends however it ends: a lock that can be taken means
/// no process is writing the file. Returns the paths removed. Without Unix file locks it
/// removes nothing.
pub fn remove_stale(dir: &Path, name: &str) -> Vec<PathBuf> {
    let mut removed = Vec::new();
    #[cfg(unix)]
    {
        let prefix = format!(".{name}{TEMP_MARKER}");
        let Ok(entries) = fs::read_dir(dir) else {
            return removed;
        };
        for e in entries.flatten() {
            if !e.file_name().to_string_lossy().starts_with(&prefix) {
                continue;
            }
            let path = e.path();
            let old = fs::symlink_metadata(&path).is_ok_and(|m| {
                m.is_file()
                    && m.modified()
                        .ok()
                        .and_then(|t| t.elapsed().ok())
                        .is_some_and(|age| age > STALE_AFTER)
            });
            if !old {
                continue;
            }
            let Ok(file) = fs::File::open(&path) else {
                continue;
            };
            if rustix::fs::flock(&file, rustix::fs::FlockOperation::NonBlockingLockExclusive)
                .is_ok()
                && fs::remove_file(&path).is_ok()
            {
                removed.push(path);
            }
        }
    }
    #[cfg(not(unix))]
    let _ = (dir, name);
    removed
}

/// A temporary file registered for removal on a signal; deleted when dropped.
struct Staged {
    tmp: Option<tempfile::NamedTempFile>,
}

impl Staged {
    fn new(dir: &Path, name: &str) -> io::Result<Staged> {
        for p in remove_stale(dir, name) {
            eprintln!(
                "polepatch: removed {}, the temporary file of a run that was killed before it finished",
                p.display()
            );
        }
        let mut registry = live();
        let tmp = tempfile::Builder::new()
            .prefix(&format!(".{name}{TEMP_MARKER}"))
            .rand_bytes(6)
            .tempfile_in(dir)?;
        // Held until the file is renamed or removed, and released by the system if the
        // process dies: how the next run tells a live temporary file from a stale one.
        #[cfg(unix)]
        rustix::fs::flock(
            tmp.as_file(),
            rustix::fs::FlockOperation::NonBlockingLockExclusive,
        )?;
        registry.push(tmp.path().to_path_buf());
        Ok(Staged { tmp: Some(tmp) })
    }

    fn file(&mut self) -> &mut fs::File {
        self.tmp
            .as_mut()
            .expect("a staged file is present until persisted or dropped")
            .as_file_mut()
    }

    /// Rename over `to`. Under the registry's lock: a signal either removes the temporary
    /// file before the rename or finds it gone.
    fn persist(&mut self, to: &Path) -> io::Result<()> {
        let mut registry = live();
        let tmp = self
            .tmp
            .take()
            .expect("a staged file is present until persisted or dropped");
        let path = tmp.path().to_path_buf();
        registry.retain(|p| *p != path);
        tmp.persist(to).map(drop).map_err(|e| e.error)
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        if let Some(tmp) = self.tmp.take() {
            let mut registry = live();
            registry.retain(|p| p != tmp.path());
            drop(tmp);
        }
    }
}

/// Remove the temporary files of unfinished outputs on SIGINT, SIGTERM or SIGHUP, then exit
/// with 128 + the signal's number (as a shell reports a process killed by it). Call once,
/// first thing in `main`. Without Unix signals it does nothing.
pub fn remove_temporaries_on_signal() {
    #[cfg(unix)]
    {
        use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
        let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) else {
            return;
        };
        std::thread::spawn(move || {
            if let Some(sig) = signals.forever().next() {
                // Held until exit: no rename can follow the removal.
                let registry = live();
                for p in registry.iter() {
                    let _ = fs::remove_file(p);
                }
                eprintln!(
                    "polepatch: stopped by signal {sig}; {} temporary file(s) removed, outputs not finished are not written",
                    registry.len()
                );
                std::process::exit(128 + sig);
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d =
            std::env::temp_dir().join(format!("polepatch-outputs-{name}-{}", std::process::id()));
        let _ = fs::remove_dir_all(&d);
        fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn a_new_path_is_resolved_through_its_existing_folders() {
        let d = dir("resolve");
        fs::create_dir_all(d.join("a")).unwrap();
        let found = find(&d.join("a/../a/./new/x.nc")).unwrap();
        assert!(found.meta.is_none());
        assert_eq!(found.key, d.canonicalize().unwrap().join("a/new/x.nc"));
        fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn an_escaping_relative_path_is_refused_under_out_dir() {
        for rel in ["../x.nc", "/abs/x.nc", "a/../../x.nc"] {
            let e = Output::under(Path::new("x"), Path::new("o"), Path::new(rel)).unwrap_err();
            assert!(matches!(e, PathError::Outside { .. }), "{rel}: {e}");
        }
        assert!(Output::under(Path::new("x"), Path::new("o"), Path::new("a/./x.nc")).is_ok());
    }

    #[test]
    fn a_temporary_file_is_named_for_its_output_and_registered_until_persisted() {
        let d = dir("staged");
        let target = &plan(&[], vec![Output::new("-o", d.join("SING.patched.I"))]).unwrap()[0];
        let mut sink = target.create(None).unwrap();
        sink.write_all(b"x").unwrap();
        let names: Vec<String> = fs::read_dir(&d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names.len(), 1);
        assert!(
            names[0].starts_with(".SING.patched.I.polepatch-tmp-"),
            "{names:?}"
        );
        assert!(live().iter().any(|p| p.starts_with(&d)));
        sink.commit().unwrap();
        assert!(!live().iter().any(|p| p.starts_with(&d)));
        assert_eq!(fs::read(d.join("SING.patched.I")).unwrap(), b"x");
        // Dropped without commit: deleted and unregistered.
        let sink = target.create(None).unwrap();
        drop(sink);
        assert!(!live().iter().any(|p| p.starts_with(&d)));
        assert_eq!(fs::read_dir(&d).unwrap().count(), 1);
        fs::remove_dir_all(&d).unwrap();
    }

    /// Issue 26 item 4: a patch killed outright (SIGKILL) leaves its temporary file; the
    /// next run writing the same output removes it, but never one that a live run holds.
    #[cfg(unix)]
    #[test]
    fn a_stale_temporary_file_is_removed_by_the_next_run_and_a_live_one_kept() {
        let d = dir("stale");
        let old = std::time::SystemTime::now() - 2 * STALE_AFTER;
        let stale = d.join(".x.I.polepatch-tmp-AAAAAA");
        fs::File::create(&stale).unwrap().set_modified(old).unwrap();
        let held = d.join(".x.I.polepatch-tmp-BBBBBB");
        let holder = fs::File::create(&held).unwrap();
        holder.set_modified(old).unwrap();
        rustix::fs::flock(
            &holder,
            rustix::fs::FlockOperation::NonBlockingLockExclusive,
        )
        .unwrap();
        let young = d.join(".x.I.polepatch-tmp-CCCCCC");
        fs::File::create(&young).unwrap();
        let other = d.join(".y.I.polepatch-tmp-DDDDDD");
        fs::File::create(&other).unwrap().set_modified(old).unwrap();
        let target = &plan(&[], vec![Output::new("-o", d.join("x.I"))]).unwrap()[0];
        target.write(b"x", None).unwrap();
        assert!(!stale.exists(), "the stale temporary file is removed");
        assert!(
            held.exists(),
            "a locked temporary file belongs to a live run"
        );
        assert!(
            young.exists(),
            "a recent one may be a run that has not locked it yet"
        );
        assert!(
            other.exists(),
            "another output's temporary file is not this run's business"
        );
        assert_eq!(fs::read(d.join("x.I")).unwrap(), b"x");
        drop(holder);
        fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn dash_is_standard_output_and_only_once() {
        let t = plan(
            &[Input::new("the input", "-")],
            vec![Output::new("-o", "-")],
        )
        .unwrap();
        assert!(t[0].is_stdout() && t[0].is_written_through());
        let e = plan(
            &[],
            vec![Output::new("-o", "-"), Output::new("--report", "-")],
        )
        .unwrap_err();
        assert!(matches!(e, PathError::Clash { .. }), "{e}");
    }
}
