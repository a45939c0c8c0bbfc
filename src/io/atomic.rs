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
//! - a **standard stream or open descriptor** of this process (`-`, which is standard output,
//!   `/dev/stdout`, `/dev/stderr`, `/dev/fd/N`, `/proc/self/fd/N`, or a link to one) is written
//!   through the descriptor itself, at its offset and in append mode when it was opened so: a
//!   file redirected with `>>` keeps its earlier content, and a pipe gets the bytes; a
//!   descriptor of another process (`/proc/PID/fd/N`) is opened in place, in append mode when
//!   that descriptor is;
//! - a **directory** is an error before anything is written;
//! - a **new file** gets mode 0666 less the process umask (0644 under umask 022), as a file
//!   made by `>` in a shell would; an **existing file** keeps its mode, and is replaced only
//!   if this user may write it (a read-only file, or another user's, in a directory anyone
//!   may write is refused).
//!
//! A group of files ([`AtomicFile::write_files`]) is checked whole before the first rename (every
//! target resolved, none a directory, no two the same file), then renamed one after the other;
//! if a rename fails, the files already renamed are put back as they were (the previous
//! contents of a replaced file are kept under a hard link until the group succeeds).
//!
//! A target that became a symbolic link after it was resolved (swapped in during the run) is
//! resolved again just before the rename: the link stays a link and its final target is
//! replaced.
//!
//! Temporary files and backups are named `.fitbead-PID-XXXXXX.tmp` and `.fitbead-PID-XXXXXX.bak`
//! (PID the writing process): [`remove_stale_temporaries`] removes those of a process that is
//! gone (a run killed by SIGKILL leaves them behind).

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
    /// An open descriptor of this process (a standard stream): written through it.
    Descriptor(i32),
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
    if path == Path::new("-") {
        return Ok(Target::Descriptor(1));
    }
    let mut p = path.to_path_buf();
    for _ in 0..MAX_LINKS {
        match descriptor_of(&p) {
            Some(Fd::Own(fd)) => return Ok(Target::Descriptor(fd)),
            Some(Fd::Foreign) => return Ok(Target::Special(p)),
            None => {}
        }
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

/// A path in a directory of open descriptors.
enum Fd {
    /// Descriptor N of this process.
    Own(i32),
    /// A descriptor of another process.
    Foreign,
}

/// Whether `p` names an open descriptor: `N` in this process's descriptor directory
/// (`/proc/self/fd`, `/dev/fd`, `/proc/thread-self/fd`, `/proc/PID/fd` with this PID), or in
/// another process's (`/proc/PID/fd`). Only on Linux; elsewhere `/dev/fd/N` is a device.
fn descriptor_of(p: &Path) -> Option<Fd> {
    if !cfg!(target_os = "linux") {
        return None;
    }
    let n: i32 = p.file_name()?.to_str()?.parse().ok()?;
    let dir = std::fs::canonicalize(p.parent()?).ok()?;
    let parts: Vec<&str> = dir.iter().filter_map(|c| c.to_str()).collect();
    let pid = match parts.as_slice() {
        ["/", "proc", pid, "fd"] | ["/", "proc", pid, "task", _, "fd"] => {
            pid.parse::<u32>().ok()?
        }
        _ => return None,
    };
    Some(if pid == std::process::id() {
        Fd::Own(n)
    } else {
        Fd::Foreign
    })
}

/// Whether descriptor `fd` of this process is open in append mode (Linux, from /proc; false
/// elsewhere or when unknown).
fn descriptor_appends(path: &Path) -> bool {
    // /proc/PID/fdinfo/N beside /proc/PID/fd/N; O_APPEND is 0o2000.
    let (Some(dir), Some(n)) = (path.parent().and_then(Path::parent), path.file_name()) else {
        return false;
    };
    std::fs::read_to_string(dir.join("fdinfo").join(n))
        .ok()
        .and_then(|info| {
            info.lines()
                .find_map(|l| l.strip_prefix("flags:"))
                .and_then(|f| u32::from_str_radix(f.trim(), 8).ok())
        })
        .is_some_and(|f| f & 0o2000 != 0)
}

/// A new handle on descriptor `fd` of this process (a duplicate: same offset, same flags).
#[cfg(unix)]
fn duplicate(fd: i32, path: &Path) -> std::io::Result<File> {
    use std::os::fd::BorrowedFd;
    if fd < 0 {
        return Err(bad_descriptor(fd, path));
    }
    // SAFETY: the descriptor is only duplicated (F_DUPFD_CLOEXEC), never closed; one that is
    // not open makes the duplication fail with EBADF.
    let b = unsafe { BorrowedFd::borrow_raw(fd) };
    b.try_clone_to_owned()
        .map(File::from)
        .map_err(|_| bad_descriptor(fd, path))
}

#[cfg(not(unix))]
fn duplicate(fd: i32, path: &Path) -> std::io::Result<File> {
    Err(bad_descriptor(fd, path))
}

fn bad_descriptor(fd: i32, path: &Path) -> std::io::Error {
    std::io::Error::new(
        std::io::ErrorKind::NotFound,
        format!("{}: descriptor {fd} is not open", path.display()),
    )
}

/// The directory a temporary file for `target` goes in.
fn dir_of(target: &Path) -> PathBuf {
    match target.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// Refuses to replace an existing regular file `p` that this user could not write in place
/// (opened for writing, nothing written): renaming a file over it needs only the directory's
/// permission, and would let anyone who may write in a shared directory (`/tmp`) replace
/// another user's read-only file.
fn writable(p: &Path) -> std::io::Result<()> {
    match OpenOptions::new().write(true).open(p) {
        Ok(_) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::PermissionDenied => Err(std::io::Error::new(
            e.kind(),
            "the file exists and this user may not write it: fitbead does not replace a \
                 file it could not write in place",
        )),
        Err(_) => Ok(()),
    }
}

/// Refuses an output path (named by `flag`) whose directory does not exist or is not a
/// directory, or that is an existing file this user may not write ([`writable`]): the run
/// would fail only when it writes, after all its work.
fn ready_output(flag: &str, p: &Path) -> Result<(), InputError> {
    if let Ok(Target::Regular(target, _)) = resolve(p) {
        if let Err(e) = writable(&target) {
            return Err(setting_error(
                flag.trim_start_matches("--"),
                &p.display().to_string(),
                e.to_string(),
            ));
        }
    }
    let dir = dir_of(p);
    match std::fs::metadata(&dir) {
        Ok(m) if m.is_dir() => Ok(()),
        Ok(_) => Err(setting_error(
            flag.trim_start_matches("--"),
            &p.display().to_string(),
            format!("cannot be created: {} is not a directory", dir.display()),
        )),
        Err(e) => Err(setting_error(
            flag.trim_start_matches("--"),
            &p.display().to_string(),
            format!("cannot be created in {}: {e}", dir.display()),
        )),
    }
}

/// Whether `a` and `b` name the same file once symbolic links are followed: the same device
/// and inode when both exist, else the same path (its directory made absolute). A path that
/// cannot be resolved is not the same as any other. Two standard streams (`-`,
/// `/dev/stdout`, `/proc/self/fd/N`) are the same when they are the same descriptor; a stream
/// is the same as a path only when it is redirected to that regular file.
pub fn same_file(a: &Path, b: &Path) -> bool {
    let (Ok(ta), Ok(tb)) = (resolve_any(a), resolve_any(b)) else {
        return false;
    };
    let meta = |t: &Resolved| match t {
        Resolved::Path(p) => std::fs::metadata(p),
        Resolved::Fd(fd) => duplicate(*fd, Path::new("-"))
            .and_then(|f| f.metadata())
            .and_then(|m| {
                if m.is_file() {
                    Ok(m)
                } else {
                    Err(std::io::Error::other("not a regular file"))
                }
            }),
    };
    match (&ta, &tb) {
        (Resolved::Fd(x), Resolved::Fd(y)) => return x == y,
        (Resolved::Path(x), Resolved::Path(y)) if !x.exists() || !y.exists() => {
            return absolute(x) == absolute(y)
        }
        _ => {}
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if let (Ok(ma), Ok(mb)) = (meta(&ta), meta(&tb)) {
            return ma.dev() == mb.dev() && ma.ino() == mb.ino();
        }
    }
    match (&ta, &tb) {
        (Resolved::Path(x), Resolved::Path(y)) => absolute(x) == absolute(y),
        _ => false,
    }
}

/// What a path names, directories included.
enum Resolved {
    Path(PathBuf),
    Fd(i32),
}

/// The final target of `path`'s symbolic links, directories included.
fn resolve_any(path: &Path) -> std::io::Result<Resolved> {
    match resolve(path) {
        Ok(Target::Descriptor(fd)) => Ok(Resolved::Fd(fd)),
        Ok(Target::New(p) | Target::Regular(p, _) | Target::Special(p)) => Ok(Resolved::Path(p)),
        Err(e) if e.kind() == std::io::ErrorKind::IsADirectory => {
            Ok(Resolved::Path(path.to_path_buf()))
        }
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
    /// The temporary file's data synced to disk in the background while it is written.
    early: EarlySync,
}

/// Bytes written to a temporary file between two background syncs of its data (64 KiB in the
/// unit tests, so that a small file goes through several); the size was chosen by
/// whole-process timings against 2 and 64 MiB (docs/PERFORMANCE.md, "Thread scaling").
const EARLY_SYNC_BYTES: u64 = if cfg!(test) { 64 << 10 } else { 8 << 20 };

/// Syncs a temporary file's data to disk on a thread of its own each [`EARLY_SYNC_BYTES`]
/// written, so that [`AtomicFile::commit`]'s final sync has only the last of them to wait for
/// (the final sync of `forward`'s 200 MB output took 0.159 s without them against 0.069 s with
/// them, in runs of 1.53 s against 1.37 s; docs/PERFORMANCE.md, "Thread scaling"). One sync at a time; the first error is kept for the commit,
/// since a failed sync may not fail again on the next.
#[derive(Default)]
struct EarlySync {
    /// Bytes written since the last sync started.
    since: u64,
    /// The sync in flight.
    running: Option<std::thread::JoinHandle<std::io::Result<()>>>,
    /// The first error of a finished sync.
    failed: Option<std::io::Error>,
    /// Syncs started.
    started: u32,
}

impl EarlySync {
    /// Counts `n` bytes written to `file`, and starts a sync of its data when enough have
    /// been since the last one and that one has finished.
    fn wrote(&mut self, file: &File, n: usize) {
        self.since += n as u64;
        if self.since < EARLY_SYNC_BYTES || self.running.as_ref().is_some_and(|h| !h.is_finished())
        {
            return;
        }
        self.join();
        self.since = 0;
        // Without a second descriptor the final sync does it all.
        if let Ok(f) = file.try_clone() {
            self.running = Some(std::thread::spawn(move || f.sync_data()));
            self.started += 1;
        }
    }

    /// Waits for the sync in flight, keeping its error.
    fn join(&mut self) {
        if let Some(h) = self.running.take() {
            let r = h
                .join()
                .unwrap_or_else(|_| Err(std::io::Error::other("background sync panicked")));
            if let Err(e) = r {
                self.failed.get_or_insert(e);
            }
        }
    }

    /// Waits for the sync in flight; the first error of any.
    fn finish(&mut self) -> std::io::Result<()> {
        self.join();
        self.failed.take().map_or(Ok(()), Err)
    }
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
            Target::Descriptor(fd) => Sink::Direct(duplicate(fd, path)?),
            Target::Special(p) => {
                // A descriptor of another process: in append mode when it is; a regular file
                // behind it is rewritten from the start.
                let foreign = matches!(descriptor_of(&p), Some(Fd::Foreign));
                let append = foreign && descriptor_appends(&p);
                let truncate =
                    foreign && !append && std::fs::metadata(&p).is_ok_and(|m| m.is_file());
                Sink::Direct(
                    OpenOptions::new()
                        .write(true)
                        .append(append)
                        .truncate(truncate)
                        .open(&p)
                        .map_err(|e| with_path(path, e))?,
                )
            }
            Target::New(p) => Sink::Temp {
                tmp: temp_in(&p, None).map_err(|e| with_path(path, e))?,
                target: p,
            },
            Target::Regular(p, perm) => {
                writable(&p).map_err(|e| with_path(path, e))?;
                Sink::Temp {
                    tmp: temp_in(&p, Some(perm)).map_err(|e| with_path(path, e))?,
                    target: p,
                }
            }
        };
        Ok(AtomicFile {
            sink,
            path: path.to_path_buf(),
            early: EarlySync::default(),
        })
    }

    /// Flushes the data to disk and renames the file over its target (a device or FIFO is
    /// only flushed).
    pub fn commit(mut self) -> std::io::Result<()> {
        self.sync()?;
        self.persist(false).map(|_| ())
    }

    fn sync(&mut self) -> std::io::Result<()> {
        match &mut self.sink {
            Sink::Temp { tmp, .. } => self.early.finish().and_then(|()| tmp.as_file().sync_all()),
            Sink::Direct(f) => f.flush(),
        }
        .map_err(|e| with_path(&self.path, e))
    }

    /// Whether the bytes go straight to the target (a device or FIFO), seen as they are
    /// written, rather than to a temporary file that replaces the target on commit.
    pub fn is_direct(&self) -> bool {
        matches!(self.sink, Sink::Direct(_))
    }

    /// Renames the temporary file over the target; returns what [`Done::undo`] needs (with
    /// `keep_backup`, a hard link to the previous contents, for a group's roll-back). A target
    /// that became a symbolic link since it was resolved is resolved again: the link stays
    /// and its final target is replaced.
    fn persist(self, keep_backup: bool) -> std::io::Result<Done> {
        let path = self.path;
        match self.sink {
            Sink::Direct(_) => Ok(Done {
                target: PathBuf::new(),
                backup: None,
                existed: true,
            }),
            Sink::Temp { tmp, target } => {
                let (tmp, target) = retarget(tmp, target).map_err(|e| with_path(&path, e))?;
                let backup = if keep_backup {
                    backup_of(&target)
                } else {
                    None
                };
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

/// The temporary file and the target it is renamed over, once `target` is resolved again: a
/// symbolic link put there since is followed (the bytes are moved to a temporary file in the
/// link's final directory when that differs); a directory, device or stream put there is an
/// error.
fn retarget(
    tmp: tempfile::NamedTempFile,
    target: PathBuf,
) -> std::io::Result<(tempfile::NamedTempFile, PathBuf)> {
    let is_link = std::fs::symlink_metadata(&target).is_ok_and(|m| m.file_type().is_symlink());
    if !is_link {
        return Ok((tmp, target));
    }
    let (p, perm) = match resolve(&target)? {
        Target::New(p) => (p, None),
        Target::Regular(p, perm) => (p, Some(perm)),
        Target::Special(_) | Target::Descriptor(_) => {
            return Err(std::io::Error::other(format!(
                "{}: became a link to a device or stream during the run",
                target.display()
            )))
        }
    };
    let same_dir =
        std::fs::canonicalize(dir_of(&p)).ok() == std::fs::canonicalize(dir_of(tmp.path())).ok();
    if same_dir {
        if let Some(perm) = perm {
            tmp.as_file().set_permissions(perm)?;
        }
        return Ok((tmp, p));
    }
    let mut moved = temp_in(&p, perm)?;
    let mut from = tmp.reopen()?;
    std::io::copy(&mut from, &mut moved)?;
    moved.as_file().sync_all()?;
    Ok((moved, p))
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
            .prefix(&temp_prefix())
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

/// The prefix of this process's temporary files and backups: `.fitbead-PID-`.
fn temp_prefix() -> String {
    format!(".fitbead-{}-", std::process::id())
}

/// How old a temporary file or backup named without a process id (`.fitbead-XXXXXX.tmp`, as
/// fitbead named them before) must be for [`remove_stale_temporaries`] to take it as stale.
pub const STALE_UNOWNED_SECS: u64 = 3600;

/// Removes the stale temporary files and backups of fitbead's own naming in `dir`: a regular
/// file named `.fitbead-PID-XXXXXX.tmp` or `.fitbead-PID-XXXXXX.bak` whose process PID is no
/// longer running (on Linux; elsewhere only the age rule applies), or one named
/// `.fitbead-XXXXXX.tmp` / `.bak` without a process id that was last modified more than
/// [`STALE_UNOWNED_SECS`] ago. A live run's files, other names, links and directories are
/// never touched. Returns the names removed.
pub fn remove_stale_temporaries(dir: &Path) -> std::io::Result<Vec<String>> {
    let mut removed = Vec::new();
    for e in std::fs::read_dir(dir)? {
        let Ok(e) = e else { continue };
        let name = e.file_name();
        let Some(name) = name.to_str() else { continue };
        let Some(stem) = name
            .strip_prefix(".fitbead-")
            .and_then(|n| n.strip_suffix(".tmp").or_else(|| n.strip_suffix(".bak")))
        else {
            continue;
        };
        let Ok(meta) = std::fs::symlink_metadata(e.path()) else {
            continue;
        };
        if !meta.file_type().is_file() {
            continue;
        }
        let stale = match stem.split_once('-') {
            Some((pid, rest))
                if !pid.is_empty()
                    && !rest.is_empty()
                    && pid.bytes().all(|b| b.is_ascii_digit()) =>
            {
                let pid: u64 = pid.parse().unwrap_or(0);
                pid != u64::from(std::process::id()) && process_gone(pid, &meta)
            }
            _ => meta
                .modified()
                .ok()
                .and_then(|m| m.elapsed().ok())
                .is_some_and(|age| age.as_secs() > STALE_UNOWNED_SECS),
        };
        if stale && std::fs::remove_file(e.path()).is_ok() {
            removed.push(name.to_string());
        }
    }
    removed.sort();
    Ok(removed)
}

/// Whether process `pid`, which wrote a file whose metadata is `meta`, is gone: on Linux, no
/// /proc/PID; elsewhere, when the file is older than [`STALE_UNOWNED_SECS`].
fn process_gone(pid: u64, meta: &std::fs::Metadata) -> bool {
    if cfg!(target_os = "linux") && Path::new("/proc/self").exists() {
        return !Path::new("/proc").join(pid.to_string()).exists();
    }
    meta.modified()
        .ok()
        .and_then(|m| m.elapsed().ok())
        .is_some_and(|age| age.as_secs() > STALE_UNOWNED_SECS)
}

/// A temporary file in `target`'s directory: mode `perm` (an existing target's), or 0666 less
/// the umask for a new file.
fn temp_in(
    target: &Path,
    perm: Option<std::fs::Permissions>,
) -> std::io::Result<tempfile::NamedTempFile> {
    let mut b = tempfile::Builder::new();
    let prefix = temp_prefix();
    b.prefix(&prefix).suffix(".tmp");
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
            Sink::Temp { tmp, .. } => {
                let n = tmp.write(buf)?;
                self.early.wrote(tmp.as_file(), n);
                Ok(n)
            }
            Sink::Direct(f) => f.write(buf),
        }
    }

    fn write_all(&mut self, buf: &[u8]) -> std::io::Result<()> {
        match &mut self.sink {
            Sink::Temp { tmp, .. } => {
                tmp.write_all(buf)?;
                self.early.wrote(tmp.as_file(), buf.len());
                Ok(())
            }
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

/// [`AtomicFile::write_files`] with `before_rename` called once every temporary file is written,
/// just before the first rename: a hook for tests of the roll-back (a target can be made to
/// fail there).
pub(crate) fn write_atomic_all_then(
    files: &[(&Path, &[u8])],
    before_rename: impl FnOnce(),
) -> std::io::Result<()> {
    let mut targets = Vec::with_capacity(files.len());
    for (path, _) in files {
        targets.push(resolve(path)?);
    }
    for i in 0..files.len() {
        for j in 0..i {
            let streams = matches!(targets[i], Target::Special(_) | Target::Descriptor(_));
            if !streams && same_file(files[i].0, files[j].0) {
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
        if matches!(target, Target::Special(_) | Target::Descriptor(_)) {
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
        match f.persist(true) {
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

/// Whole files and sets of files written atomically, and the checks of output paths that
/// come before any work.
impl AtomicFile {
    /// Writes `bytes` to `path` atomically: a temporary file in the same directory, flushed and
    /// synced, then renamed over the target. On any error the target is untouched. Symbolic
    /// links, devices and FIFOs: module docs.
    pub fn write_file(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
        Self::write_files(&[(path, bytes)])
    }

    /// Writes several files atomically as a group. Every target is resolved and checked first
    /// (none a directory, no two the same file), every temporary file is written and synced, and
    /// only then are they renamed into place; a rename that fails puts back the files already
    /// renamed. Devices and FIFOs among the targets are written last, once every rename
    /// succeeded. On any error no regular target has changed.
    pub fn write_files(files: &[(&Path, &[u8])]) -> std::io::Result<()> {
        write_atomic_all_then(files, || {})
    }

    /// Refuses, before any work, an output that is a directory, whose directory does not exist,
    /// that is one of the `inputs` (after following symbolic links; `-`, standard input, when it
    /// is redirected from that file) or that is another of the `outputs` (a character device such
    /// as `/dev/null` excepted). An output `-` is standard
    /// output; two outputs to the same standard stream or descriptor (`-` and `/dev/stdout`, say)
    /// are refused as well: their bytes would be mixed. Paths are named by the flag that gives
    /// them (absent ones skipped); the error names the flag.
    pub fn distinct_paths(
        inputs: &[(&str, Option<&Path>)],
        outputs: &[(&str, Option<&Path>)],
    ) -> Result<(), InputError> {
        let outs: Vec<(&str, &Path)> = outputs
            .iter()
            .filter_map(|(n, p)| p.map(|p| (*n, p)))
            .collect();
        for (i, (flag, p)) in outs.iter().enumerate() {
            let stream = Self::stream_of(p);
            if stream.is_none() && p.is_dir() {
                return Err(setting_error(
                    flag.trim_start_matches("--"),
                    &p.display().to_string(),
                    "is a directory",
                ));
            }
            if stream.is_none() {
                ready_output(flag, p)?;
            }
            for (iflag, q) in inputs.iter().filter_map(|(n, q)| q.map(|q| (*n, q))) {
                // `-` is standard input: the same file as the output when it is redirected from it.
                let q = if q == Path::new("-") {
                    Path::new("/dev/stdin")
                } else {
                    q
                };
                if same_file(p, q) {
                    return Err(setting_error(
                        flag.trim_start_matches("--"),
                        &p.display().to_string(),
                        format!("is the same file as {iflag}: the input would be overwritten"),
                    ));
                }
            }
            for (oflag, q) in &outs[..i] {
                if let Some(fd) = stream.filter(|fd| Self::stream_of(q) == Some(*fd)) {
                    let name = match fd {
                        1 => "standard output".to_string(),
                        2 => "standard error".to_string(),
                        n => format!("descriptor {n}"),
                    };
                    return Err(setting_error(
                        flag.trim_start_matches("--"),
                        &p.display().to_string(),
                        format!(
                            "goes to {name}, as {oflag} does: only one output may go to a stream \
                             (give one of them a file)"
                        ),
                    ));
                }
                // A character device (/dev/null, a terminal) takes any number of writers.
                if same_file(p, q) && !Self::is_char_device(p) {
                    return Err(setting_error(
                        flag.trim_start_matches("--"),
                        &p.display().to_string(),
                        format!(
                            "is the same file as {oflag}: one output would overwrite the other"
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Whether `path` resolves to an open descriptor of this process (`-` is standard output):
    /// descriptor N, or `None` for a path.
    pub fn stream_of(path: &Path) -> Option<i32> {
        match resolve(path) {
            Ok(Target::Descriptor(fd)) => Some(fd),
            _ => None,
        }
    }

    /// Whether `p` is a character device (`/dev/null`, a terminal), after following links.
    pub fn is_char_device(p: &Path) -> bool {
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
}

#[cfg(test)]
mod tests {
    use std::io::Write;
    use std::path::{Path, PathBuf};

    #[test]
    fn a_file_synced_in_the_background_while_written_commits_whole() {
        let d = tmpdir();
        let p = write(&d, "out.csv", "old\n");
        let mut f = super::AtomicFile::create(&p).unwrap();
        let mut want = Vec::new();
        for i in 0..3000u32 {
            let line = format!("{i},{}\n", "x".repeat((i % 97) as usize));
            f.write_all(line.as_bytes()).unwrap();
            want.extend_from_slice(line.as_bytes());
        }
        // A background sync started along the way (one at a time, each 64 KiB in the tests),
        // and the target is untouched until the commit.
        assert!(f.early.started >= 1, "{} syncs", f.early.started);
        assert_eq!(std::fs::read(&p).unwrap(), b"old\n");
        f.commit().unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), want);
        assert!(leftovers(d.path()).is_empty());
    }

    fn tmpdir() -> tempfile::TempDir {
        tempfile::tempdir().unwrap()
    }

    fn write(dir: impl AsRef<Path>, name: &str, text: &str) -> PathBuf {
        let p = dir.as_ref().join(name);
        std::fs::write(&p, text).unwrap();
        p
    }

    /// Names in `dir` that start with `.fitbead-` (temporary or backup files).
    fn leftovers(dir: &Path) -> Vec<String> {
        std::fs::read_dir(dir)
            .unwrap()
            .filter_map(|e| e.ok())
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .filter(|n| n.starts_with(".fitbead-"))
            .collect()
    }

    #[test]
    fn a_failed_group_of_renames_is_rolled_back() {
        // A target that turns into a directory after the group was checked (a
        // race) fails its rename; the file renamed before it is put back.
        let dir = tmpdir();
        let a = write(&dir, "a.csv", "old a\n");
        let b = dir.path().join("b.csv");
        let r = super::write_atomic_all_then(&[(&a, b"new a\n"), (&b, b"new b\n")], || {
            std::fs::create_dir(&b).unwrap()
        });
        assert!(r.is_err());
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "old a\n");
        assert!(b.is_dir());
        assert!(
            leftovers(dir.path()).is_empty(),
            "{:?}",
            leftovers(dir.path())
        );
    }

    #[cfg(unix)]
    #[test]
    fn a_symlink_swapped_in_before_the_rename_stays_a_link() {
        use std::io::Write;
        let dir = tmpdir();
        let out = write(&dir, "out.csv", "old\n");
        let elsewhere = dir.path().join("sub");
        std::fs::create_dir(&elsewhere).unwrap();
        let real = write(&elsewhere, "real.csv", "real old\n");
        let mut f = super::AtomicFile::create(&out).unwrap();
        f.write_all(b"new\n").unwrap();
        // During the run, out.csv becomes a link to a file in another directory.
        std::fs::remove_file(&out).unwrap();
        std::os::unix::fs::symlink(&real, &out).unwrap();
        f.commit().unwrap();
        assert!(std::fs::symlink_metadata(&out)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(std::fs::read_to_string(&real).unwrap(), "new\n");
        assert!(
            leftovers(dir.path()).is_empty(),
            "{:?}",
            leftovers(dir.path())
        );
        assert!(
            leftovers(&elsewhere).is_empty(),
            "{:?}",
            leftovers(&elsewhere)
        );
    }
}
