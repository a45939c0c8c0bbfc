//! Output files that appear whole or not at all.
//!
//! A regular file (new or existing) is written under a temporary name in its directory and
//! renamed over the target at the end; dropped before that, the temporary file is removed and
//! the target is untouched. What the target is decides the rest:
//!
//! - a **symbolic link** is followed (links to links too): its final target is replaced, the
//!   link stays;
//! - a **device, FIFO or socket** cannot be replaced: it is opened and written in place (so
//!   `/dev/null` stays a device and a FIFO's reader gets the bytes);
//! - a **directory** is an error before anything is written;
//! - a **new file** gets mode 0666 less the process umask (0644 under umask 022), as a file
//!   made by `>` in a shell would; an **existing file** keeps its mode.
//!
//! A group of files ([`write_atomic_all`]) is checked whole before the first rename (every
//! target resolved, none a directory, no two the same file), then renamed one after the other;
//! if a rename fails, the files already renamed are put back as they were (the previous
//! contents of a replaced file are kept under a hard link until the group succeeds).

use super::{setting_error, InputError};
use std::fs::{File, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};

/// How many symbolic links are followed before giving up (as Linux's `ELOOP` limit).
const MAX_LINKS: usize = 40;

/// What a path names, once symbolic links are followed.
#[derive(Debug)]
enum Target {
    /// Nothing yet: a new regular file at this path.
    New(PathBuf),
    /// An existing regular file, with its permission bits.
    Regular(PathBuf, std::fs::Permissions),
    /// A device, FIFO or socket: written in place.
    Special(PathBuf),
}

impl Target {
    fn path(&self) -> &Path {
        match self {
            Target::New(p) | Target::Regular(p, _) | Target::Special(p) => p,
        }
    }
}

fn with_path(path: &Path, e: std::io::Error) -> std::io::Error {
    std::io::Error::new(e.kind(), format!("{}: {e}", path.display()))
}

fn is_a_directory(path: &Path) -> std::io::Error {
    std::io::Error::new(
        std::io::ErrorKind::IsADirectory,
        format!("{}: is a directory", path.display()),
    )
}

/// Follows the symbolic links of `path` (the last component only, repeatedly) and says what
/// the final target is.
fn resolve(path: &Path) -> std::io::Result<Target> {
    let mut p = path.to_path_buf();
    for _ in 0..MAX_LINKS {
        let meta = match std::fs::symlink_metadata(&p) {
            Ok(m) => m,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Target::New(p)),
            Err(e) => return Err(with_path(path, e)),
        };
        let ft = meta.file_type();
        if ft.is_symlink() {
            let next = std::fs::read_link(&p).map_err(|e| with_path(path, e))?;
            p = match p.parent() {
                Some(dir) if next.is_relative() => dir.join(next),
                _ => next,
            };
            continue;
        }
        if ft.is_dir() {
            return Err(is_a_directory(path));
        }
        if ft.is_file() {
            return Ok(Target::Regular(p, meta.permissions()));
        }
        return Ok(Target::Special(p));
    }
    Err(std::io::Error::other(format!(
        "{}: too many levels of symbolic links",
        path.display()
    )))
}

/// The directory a temporary file for `target` goes in.
fn dir_of(target: &Path) -> PathBuf {
    match target.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// Whether `a` and `b` name the same file once symbolic links are followed: the same device
/// and inode when both exist, else the same path (its directory made absolute). A path that
/// cannot be resolved is not the same as any other.
pub fn same_file(a: &Path, b: &Path) -> bool {
    let (Ok(ta), Ok(tb)) = (resolve_any(a), resolve_any(b)) else {
        return false;
    };
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if let (Ok(ma), Ok(mb)) = (std::fs::metadata(&ta), std::fs::metadata(&tb)) {
            return ma.dev() == mb.dev() && ma.ino() == mb.ino();
        }
    }
    absolute(&ta) == absolute(&tb)
}

/// The final target of `path`'s symbolic links, directories included.
fn resolve_any(path: &Path) -> std::io::Result<PathBuf> {
    match resolve(path) {
        Ok(t) => Ok(t.path().to_path_buf()),
        Err(e) if e.kind() == std::io::ErrorKind::IsADirectory => Ok(path.to_path_buf()),
        Err(e) => Err(e),
    }
}

fn absolute(p: &Path) -> PathBuf {
    let dir = dir_of(p);
    let dir = std::fs::canonicalize(&dir).unwrap_or(dir);
    match p.file_name() {
        Some(n) => dir.join(n),
        None => dir,
    }
}

/// Where the bytes go until [`AtomicFile::commit`].
enum Sink {
    /// A temporary file renamed over `target` at the end.
    Temp {
        tmp: tempfile::NamedTempFile,
        target: PathBuf,
    },
    /// A device, FIFO or socket, written in place.
    Direct(File),
}

/// A file written under a temporary name in the target's directory and renamed over the
/// target only by [`AtomicFile::commit`]; dropped uncommitted, the temporary file is removed
/// and the target is untouched. A symbolic link is followed to its target; a device, FIFO or
/// socket is written in place (module docs).
pub struct AtomicFile {
    sink: Sink,
    /// The path as given, for messages.
    path: PathBuf,
}

impl AtomicFile {
    /// Creates the temporary file next to `path`'s final target (or opens a device or FIFO
    /// for writing). Fails when the target is a directory or its directory is not writable.
    pub fn create(path: &Path) -> std::io::Result<AtomicFile> {
        let target = resolve(path)?;
        Self::create_for(path, target)
    }

    fn create_for(path: &Path, target: Target) -> std::io::Result<AtomicFile> {
        let sink = match target {
            Target::Special(p) => Sink::Direct(
                OpenOptions::new()
                    .write(true)
                    .open(&p)
                    .map_err(|e| with_path(path, e))?,
            ),
            Target::New(p) => Sink::Temp {
                tmp: temp_in(&p, None).map_err(|e| with_path(path, e))?,
                target: p,
            },
            Target::Regular(p, perm) => Sink::Temp {
                tmp: temp_in(&p, Some(perm)).map_err(|e| with_path(path, e))?,
                target: p,
            },
        };
        Ok(AtomicFile {
            sink,
            path: path.to_path_buf(),
        })
    }

    /// Flushes the data to disk and renames the file over its target (a device or FIFO is
    /// only flushed).
    pub fn commit(mut self) -> std::io::Result<()> {
        self.sync()?;
        self.persist().map(|_| ())
    }

    fn sync(&mut self) -> std::io::Result<()> {
        match &mut self.sink {
            Sink::Temp { tmp, .. } => tmp.as_file().sync_all(),
            Sink::Direct(f) => f.flush(),
        }
        .map_err(|e| with_path(&self.path, e))
    }

    fn is_direct(&self) -> bool {
        matches!(self.sink, Sink::Direct(_))
    }

    /// Renames the temporary file over the target; returns what [`undo`] needs.
    fn persist(self) -> std::io::Result<Done> {
        let path = self.path;
        match self.sink {
            Sink::Direct(_) => Ok(Done {
                target: PathBuf::new(),
                backup: None,
                existed: true,
            }),
            Sink::Temp { tmp, target } => {
                let backup = backup_of(&target);
                let existed = backup.is_some() || target.exists();
                match tmp.persist(&target) {
                    Ok(_) => Ok(Done {
                        target,
                        backup,
                        existed,
                    }),
                    Err(e) => {
                        if let Some(b) = backup {
                            let _ = std::fs::remove_file(b);
                        }
                        Err(with_path(&path, e.error))
                    }
                }
            }
        }
    }
}

/// A rename done within a group, and how to undo it.
struct Done {
    target: PathBuf,
    /// A hard link to the target's previous contents.
    backup: Option<PathBuf>,
    /// Whether the target existed before (an existing file without a backup cannot be put
    /// back and is left as written).
    existed: bool,
}

impl Done {
    /// Puts the previous contents back (or removes a file that did not exist).
    fn undo(&self) {
        match &self.backup {
            Some(b) => {
                let _ = std::fs::rename(b, &self.target);
            }
            None if !self.existed && !self.target.as_os_str().is_empty() => {
                let _ = std::fs::remove_file(&self.target);
            }
            None => {}
        }
    }

    /// Drops the backup once the whole group succeeded.
    fn forget(&self) {
        if let Some(b) = &self.backup {
            let _ = std::fs::remove_file(b);
        }
    }
}

/// A hard link to `target` under a fresh name in its directory, or `None` when the target
/// does not exist or cannot be linked.
fn backup_of(target: &Path) -> Option<PathBuf> {
    if !target.is_file() {
        return None;
    }
    let dir = dir_of(target);
    for _ in 0..16 {
        // A fresh unique name: create and remove an empty temporary file, then link to it.
        let name = tempfile::Builder::new()
            .prefix(".fitbead-")
            .suffix(".bak")
            .tempfile_in(&dir)
            .ok()?
            .into_temp_path();
        let p = name.to_path_buf();
        name.close().ok()?;
        match std::fs::hard_link(target, &p) {
            Ok(()) => return Some(p),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            // A file system without hard links: a copy keeps the contents as well.
            Err(_) => return std::fs::copy(target, &p).ok().map(|_| p),
        }
    }
    None
}

/// A temporary file in `target`'s directory: mode `perm` (an existing target's), or 0666 less
/// the umask for a new file.
fn temp_in(
    target: &Path,
    perm: Option<std::fs::Permissions>,
) -> std::io::Result<tempfile::NamedTempFile> {
    let mut b = tempfile::Builder::new();
    b.prefix(".fitbead-").suffix(".tmp");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        // Given at creation, the mode is masked by the umask.
        b.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let tmp = b.tempfile_in(dir_of(target))?;
    if let Some(perm) = perm {
        // Set explicitly, the mode is not masked: the replaced file's mode is kept.
        tmp.as_file().set_permissions(perm)?;
    }
    Ok(tmp)
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        match &mut self.sink {
            Sink::Temp { tmp, .. } => tmp.write(buf),
            Sink::Direct(f) => f.write(buf),
        }
    }

    fn write_all(&mut self, buf: &[u8]) -> std::io::Result<()> {
        match &mut self.sink {
            Sink::Temp { tmp, .. } => tmp.write_all(buf),
            Sink::Direct(f) => f.write_all(buf),
        }
    }

    fn flush(&mut self) -> std::io::Result<()> {
        match &mut self.sink {
            Sink::Temp { tmp, .. } => tmp.flush(),
            Sink::Direct(f) => f.flush(),
        }
    }
}

/// Writes `bytes` to `path` atomically: a temporary file in the same directory, flushed and
/// synced, then renamed over the target. On any error the target is untouched. Symbolic
/// links, devices and FIFOs: module docs.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    write_atomic_all(&[(path, bytes)])
}

/// Writes several files atomically as a group. Every target is resolved and checked first
/// (none a directory, no two the same file), every temporary file is written and synced, and
/// only then are they renamed into place; a rename that fails puts back the files already
/// renamed. Devices and FIFOs among the targets are written last, once every rename
/// succeeded. On any error no regular target has changed.
pub fn write_atomic_all(files: &[(&Path, &[u8])]) -> std::io::Result<()> {
    write_atomic_all_then(files, || {})
}

/// [`write_atomic_all`] with `before_rename` called once every temporary file is written,
/// just before the first rename: a hook for tests of the roll-back (a target can be made to
/// fail there).
#[doc(hidden)]
pub fn write_atomic_all_then(
    files: &[(&Path, &[u8])],
    before_rename: impl FnOnce(),
) -> std::io::Result<()> {
    let mut targets = Vec::with_capacity(files.len());
    for (path, _) in files {
        targets.push(resolve(path)?);
    }
    for i in 0..files.len() {
        for j in 0..i {
            if !matches!(targets[i], Target::Special(_)) && same_file(files[i].0, files[j].0) {
                return Err(std::io::Error::new(
                    std::io::ErrorKind::InvalidInput,
                    format!(
                        "{} and {} are the same file",
                        files[j].0.display(),
                        files[i].0.display()
                    ),
                ));
            }
        }
    }
    let mut staged = Vec::with_capacity(files.len());
    let mut direct = Vec::new();
    for ((path, bytes), target) in files.iter().zip(targets) {
        if matches!(target, Target::Special(_)) {
            direct.push((*path, *bytes));
            continue;
        }
        let mut f = AtomicFile::create_for(path, target)?;
        f.write_all(bytes).map_err(|e| with_path(path, e))?;
        f.sync()?;
        staged.push(f);
    }
    before_rename();
    let mut done: Vec<Done> = Vec::with_capacity(staged.len());
    let rollback = |done: &[Done]| {
        for d in done.iter().rev() {
            d.undo();
        }
    };
    for f in staged {
        debug_assert!(!f.is_direct());
        match f.persist() {
            Ok(d) => done.push(d),
            Err(e) => {
                rollback(&done);
                return Err(e);
            }
        }
    }
    for (path, bytes) in direct {
        let r = AtomicFile::create(path).and_then(|mut f| {
            f.write_all(bytes).map_err(|e| with_path(path, e))?;
            f.commit()
        });
        if let Err(e) = r {
            rollback(&done);
            return Err(e);
        }
    }
    for d in &done {
        d.forget();
    }
    Ok(())
}

/// Whether `p` is a character device (`/dev/null`, a terminal), after following links.
fn is_char_device(p: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        std::fs::metadata(p).is_ok_and(|m| m.file_type().is_char_device())
    }
    #[cfg(not(unix))]
    {
        p == Path::new("NUL")
    }
}

/// Refuses, before any work, an output that is a directory, that is one of the `inputs`
/// (after following symbolic links; `-`, standard input, is none) or that is another of the
/// `outputs` (a character device such as `/dev/null` excepted). Paths are named by the flag that gives them (absent ones skipped); the error
/// names the flag.
pub fn distinct_paths(
    inputs: &[(&str, Option<&Path>)],
    outputs: &[(&str, Option<&Path>)],
) -> Result<(), InputError> {
    let outs: Vec<(&str, &Path)> = outputs
        .iter()
        .filter_map(|(n, p)| p.map(|p| (*n, p)))
        .collect();
    for (i, (flag, p)) in outs.iter().enumerate() {
        if p.is_dir() {
            return Err(setting_error(
                flag.trim_start_matches("--"),
                &p.display().to_string(),
                "is a directory",
            ));
        }
        for (iflag, q) in inputs.iter().filter_map(|(n, q)| q.map(|q| (*n, q))) {
            if q != Path::new("-") && same_file(p, q) {
                return Err(setting_error(
                    flag.trim_start_matches("--"),
                    &p.display().to_string(),
                    format!("is the same file as {iflag}: the input would be overwritten"),
                ));
            }
        }
        for (oflag, q) in &outs[..i] {
            // A character device (/dev/null, a terminal) takes any number of writers.
            if same_file(p, q) && !is_char_device(p) {
                return Err(setting_error(
                    flag.trim_start_matches("--"),
                    &p.display().to_string(),
                    format!("is the same file as {oflag}: one output would overwrite the other"),
                ));
            }
        }
    }
    Ok(())
}
