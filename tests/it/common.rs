//! Helpers shared by the test modules: the fitbead binary and its output, temporary files, CSV
//! tables, and the reference tables under tests/reference/.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output};

/// The fitbead binary these tests run: the one named by the environment variable
/// `FITBEAD_BIN` (to run the tests against another build, e.g. to check that a regression
/// test fails on the code before its fix), else the one cargo built beside these tests (the
/// package `fitbead-cli`, built by `cargo test` at the root: its own tests need it).
pub fn bin_path() -> PathBuf {
    if let Some(p) = std::env::var_os("FITBEAD_BIN") {
        return PathBuf::from(p);
    }
    // The tests run from target/PROFILE/deps/; the binary is target/PROFILE/fitbead.
    let exe = std::env::current_exe().expect("the test executable's path");
    let built = exe
        .parent()
        .and_then(Path::parent)
        .map(|d| d.join(format!("fitbead{}", std::env::consts::EXE_SUFFIX)))
        .expect("the test executable is in target/PROFILE/deps");
    assert!(
        built.exists(),
        "{} is missing: build it with `cargo build -p fitbead-cli` (same profile), run the \
         tests with `cargo test` at the root (which builds it), or name a binary in FITBEAD_BIN",
        built.display()
    );
    built
}

/// A command that runs the fitbead binary of [`bin_path`].
pub fn bin() -> Command {
    Command::new(bin_path())
}

/// The stdout of a run that must have succeeded; panics with its stderr otherwise.
pub fn stdout_ok(out: &Output) -> String {
    assert!(out.status.success(), "{}", stderr(out));
    String::from_utf8(out.stdout.clone()).unwrap()
}

/// The stderr of a run, lossily decoded.
pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// The crate root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A fresh temporary directory, removed when dropped.
pub fn tmpdir() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

/// Writes `text` to the file `name` in `dir` and returns its path.
pub fn write(dir: impl AsRef<Path>, name: &str, text: &str) -> PathBuf {
    let p = dir.as_ref().join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// A CSV text as its header and its rows of cells.
pub fn table(text: &str) -> (Vec<String>, Vec<Vec<String>>) {
    rows_of(csv::Reader::from_reader(text.as_bytes()))
}

/// A CSV file as its header and its rows of cells.
pub fn read_table(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let r = csv::Reader::from_path(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    rows_of(r)
}

fn rows_of<R: std::io::Read>(mut r: csv::Reader<R>) -> (Vec<String>, Vec<Vec<String>>) {
    let h = r.headers().unwrap().iter().map(String::from).collect();
    let rows = r
        .records()
        .map(|x| x.unwrap().iter().map(String::from).collect())
        .collect();
    (h, rows)
}

/// A CSV text as its header and its rows, each keyed by column name.
pub fn records(text: &str) -> (Vec<String>, Vec<HashMap<String, String>>) {
    let (h, rows) = table(text);
    let rows = rows
        .into_iter()
        .map(|r| h.iter().cloned().zip(r).collect())
        .collect();
    (h, rows)
}

/// The index of column `name` in the header `h`.
pub fn col(h: &[String], name: &str) -> usize {
    h.iter()
        .position(|c| c == name)
        .unwrap_or_else(|| panic!("missing column {name}: {h:?}"))
}

/// Asserts exit code `code` and that stderr holds every one of `must`.
pub fn expect(out: &Output, code: i32, must: &[&str], what: &str) {
    let e = stderr(out);
    assert_eq!(out.status.code(), Some(code), "{what}: {e}");
    assert!(!e.contains("panicked"), "{what}: {e}");
    for m in must {
        assert!(e.contains(m), "{what}: '{m}' not in: {e}");
    }
}

pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Names in `dir` that start with `.fitbead-` (temporary or backup files).
pub fn leftovers(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".fitbead-"))
        .collect()
}

pub fn signal(child: &Child, sig: &str) {
    let ok = Command::new("kill")
        .args([sig, &child.id().to_string()])
        .status()
        .unwrap();
    assert!(ok.success());
}

/// Starts `args` in `dir`, sends `sig` after `after`, and returns the exit status and how
/// long the command took to stop after the signal (panics if it has not ended 30 s after).
pub fn interrupt(
    dir: &Path,
    args: &[&str],
    sig: &str,
    after: std::time::Duration,
) -> (std::process::ExitStatus, std::time::Duration) {
    use std::process::Stdio;
    use std::time::{Duration, Instant};
    let mut child = bin()
        .args(args)
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(after);
    assert!(
        child.try_wait().unwrap().is_none(),
        "{args:?} ended before the signal"
    );
    signal(&child, sig);
    let t0 = Instant::now();
    loop {
        if let Some(st) = child.try_wait().unwrap() {
            return (st, t0.elapsed());
        }
        if t0.elapsed() > Duration::from_secs(30) {
            let _ = child.kill();
            panic!("{args:?} still running 30 s after {sig}");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
}
