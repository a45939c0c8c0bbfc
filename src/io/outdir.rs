//! A directory of output files written as one unit (`fitbead report --out-dir`).
//!
//! The directory may hold files that are not the run's (a user's notes): it is never replaced
//! or emptied. Instead, [`write_dir`]
//!
//! 1. locks the directory (an exclusive `flock` on the directory itself, so no lock file is
//!    left behind): a second run writing the same directory waits until the first is done,
//!    and the files of two runs are never mixed;
//! 2. removes the stale temporary files and backups of fitbead's own naming
//!    ([`super::remove_stale_temporaries`]: those of runs that are gone, never a live run's);
//! 3. records in the manifest `MANIFEST` that this run is writing (naming the run, and
//!    every file of the previous run and of this one);
//! 4. writes every file as one group ([`super::AtomicFile::write_files`]: all of them or, on an
//!    error, none changed);
//! 5. removes the files the previous run listed in the manifest that this run did not write
//!    (a corner plot of a series no longer in the data, say) — and no other file;
//! 6. records in the manifest that the run is complete, with its files.
//!
//! A run killed during step 4 can leave a mix of old and new files: the manifest then says
//! `state writing` and names the run, and the next run replaces and removes them all.

use super::{remove_stale_temporaries, AtomicFile};
use std::path::Path;

/// Whether `dir` can take the output files before any work is done: an existing directory,
/// or a path whose nearest existing ancestor is a directory (the missing ones are made when
/// the files are written). The error says what stands in the way (without naming `dir`).
pub(crate) fn check_dir(dir: &Path) -> std::io::Result<()> {
    let mut p = Some(dir);
    while let Some(d) = p {
        let d = if d.as_os_str().is_empty() {
            Path::new(".")
        } else {
            d
        };
        match std::fs::metadata(d) {
            Ok(m) if m.is_dir() => return Ok(()),
            Ok(_) if d == dir => return Err(std::io::Error::other("is not a directory")),
            Ok(_) => {
                return Err(std::io::Error::other(format!(
                    "cannot be created: {} is not a directory",
                    d.display()
                )))
            }
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => p = d.parent(),
            Err(e) => {
                return Err(std::io::Error::other(format!(
                    "cannot be created: {}: {e}",
                    d.display()
                )))
            }
        }
    }
    Ok(())
}

/// The manifest's name in the directory. It does not start with `.fitbead-`, the prefix of
/// temporary files.
pub(crate) const MANIFEST: &str = ".fitbead.manifest";

/// What a manifest says: the run's state and its files.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Manifest {
    /// `writing` while a run writes (or when it was killed doing so), `complete` after.
    pub state: String,
    /// Who wrote the directory: fitbead's version, the process id and the time.
    pub run: String,
    /// The files of the run, by name in the directory.
    pub files: Vec<String>,
}

impl Manifest {
    /// The manifest of `dir`, or `None` when there is none (or it cannot be read).
    pub fn read(dir: &Path) -> Option<Manifest> {
        let text = std::fs::read_to_string(dir.join(MANIFEST)).ok()?;
        let mut m = Manifest::default();
        for line in text.lines() {
            if let Some(f) = line.strip_prefix("file ") {
                m.files.push(f.to_string());
            } else if let Some(s) = line.strip_prefix("state ") {
                m.state = s.to_string();
            } else if let Some(r) = line.strip_prefix("run ") {
                m.run = r.to_string();
            }
        }
        Some(m)
    }

    fn text(&self) -> String {
        let mut t = String::from(
            "# fitbead: the files of the last run that wrote this directory. The next run \
             removes those it does not write again;\n# no other file here is ever touched.\n",
        );
        t.push_str(&format!("run {}\nstate {}\n", self.run, self.state));
        for f in &self.files {
            t.push_str(&format!("file {f}\n"));
        }
        t
    }
}

/// A file name the manifest may list: one plain component (no separator, not `.` or `..`),
/// without a line break, and not the manifest itself.
fn plain_name(name: &str) -> bool {
    !name.is_empty()
        && name != "."
        && name != ".."
        && name != MANIFEST
        && !name.contains(['/', '\\', '\n', '\r'])
}

/// Writes `files` (name in `dir`, bytes) into the existing directory `dir` as one unit (module
/// docs): locked, stale temporaries removed, all files or none, the previous run's files that
/// are not written again removed, the run recorded in `MANIFEST`. A name that is not a plain
/// file name is an error before anything is written.
pub fn write_dir(dir: &Path, files: &[(String, Vec<u8>)]) -> std::io::Result<()> {
    if let Some((bad, _)) = files.iter().find(|(n, _)| !plain_name(n)) {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!("{bad:?}: not a plain file name"),
        ));
    }
    let _lock = lock(dir)?;
    remove_stale_temporaries(dir)?;
    let previous = Manifest::read(dir);
    let old_files: Vec<String> = previous
        .as_ref()
        .map(|m| m.files.iter().filter(|f| plain_name(f)).cloned().collect())
        .unwrap_or_default();
    let run = format!(
        "fitbead {}, process {}, at {} (unix time)",
        env!("CARGO_PKG_VERSION"),
        std::process::id(),
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_secs())
            .unwrap_or(0)
    );
    let mut all: Vec<String> = files.iter().map(|(n, _)| n.clone()).collect();
    for f in &old_files {
        if !all.contains(f) {
            all.push(f.clone());
        }
    }
    let manifest = dir.join(MANIFEST);
    let writing = Manifest {
        state: "writing".into(),
        run: run.clone(),
        files: all,
    };
    AtomicFile::write_file(&manifest, writing.text().as_bytes())?;
    let paths: Vec<std::path::PathBuf> = files.iter().map(|(n, _)| dir.join(n)).collect();
    let group: Vec<(&Path, &[u8])> = paths
        .iter()
        .zip(files)
        .map(|(p, (_, b))| (p.as_path(), b.as_slice()))
        .collect();
    if let Err(e) = AtomicFile::write_files(&group) {
        // Nothing was written: the manifest goes back to what it was.
        let _ = match &previous {
            Some(m) => AtomicFile::write_file(&manifest, m.text().as_bytes()),
            None => std::fs::remove_file(&manifest),
        };
        return Err(e);
    }
    for f in old_files
        .iter()
        .filter(|f| !files.iter().any(|(n, _)| n == *f))
    {
        let p = dir.join(f);
        // Only a file or a link of the listed name, never a directory.
        if std::fs::symlink_metadata(&p).is_ok_and(|m| !m.is_dir()) {
            let _ = std::fs::remove_file(&p);
        }
    }
    let complete = Manifest {
        state: "complete".into(),
        run,
        files: files.iter().map(|(n, _)| n.clone()).collect(),
    };
    AtomicFile::write_file(&manifest, complete.text().as_bytes())
}

/// An exclusive lock on the directory itself, held until the returned handle is dropped
/// (blocking while another run holds it).
#[cfg(unix)]
fn lock(dir: &Path) -> std::io::Result<Option<std::fs::File>> {
    let f = std::fs::File::open(dir)
        .map_err(|e| std::io::Error::new(e.kind(), format!("{}: {e}", dir.display())))?;
    match f.lock() {
        Ok(()) => Ok(Some(f)),
        // A file system without locks: the run goes on unlocked.
        Err(e) if e.kind() == std::io::ErrorKind::Unsupported => Ok(None),
        Err(e) => Err(std::io::Error::new(
            e.kind(),
            format!("{}: cannot lock: {e}", dir.display()),
        )),
    }
}

#[cfg(not(unix))]
fn lock(_dir: &Path) -> std::io::Result<Option<std::fs::File>> {
    Ok(None)
}
