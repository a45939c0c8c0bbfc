//! Outputs at their edges: standard streams and descriptors written through in place, `-` for
//! standard output on every output flag, report directories written as one unit (locked, the
//! previous run's files and stale temporaries removed, foreign files kept), series labels that
//! are data and not paths or markup, and recipes whose values are blamed on the recipe.

use crate::common::bin_path;
use crate::common::{bin, expect, leftovers, s, stderr, tmpdir, write};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// Runs fitbead with `args` in `dir` (stdin closed) and returns its output.
fn fb_in(dir: &Path, args: &[&str]) -> Output {
    bin()
        .current_dir(dir)
        .args(args)
        .stdin(Stdio::null())
        .output()
        .unwrap()
}

/// Runs `fitbead ARGS... >> file` through sh (stdout opened in append mode).
fn append_run(file: &Path, args: &[&str]) -> std::process::ExitStatus {
    Command::new("sh")
        .arg("-c")
        .arg("f=$1; shift; exec \"$0\" \"$@\" >> \"$f\"")
        .arg(bin_path())
        .arg(file)
        .args(args)
        .status()
        .unwrap()
}

const FORWARD: [&str; 7] = [
    "forward",
    "--model",
    "stick",
    "--xi",
    "1",
    "--delta-deg",
    "12",
];

// Standard streams and descriptors.

#[cfg(target_os = "linux")]
#[test]
fn an_output_to_an_appending_stdout_keeps_the_earlier_content() {
    let dir = tmpdir();
    let app = write(&dir, "app.txt", "line1\n");
    // Streamed (forward), emitted whole (regimes) and in a group (jan --output-stats).
    let mut a: Vec<&str> = FORWARD.to_vec();
    a.extend(["--output", "/dev/stdout"]);
    assert!(append_run(&app, &a).success());
    assert!(append_run(&app, &["regimes", "--output", "/proc/self/fd/1"]).success());
    let p = dir.path().join("p.csv");
    assert!(append_run(
        &app,
        &[
            "jan",
            "--no-profile",
            "--output",
            s(&p),
            "--output-stats",
            "/dev/stdout"
        ]
    )
    .success());
    let text = std::fs::read_to_string(&app).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "line1", "{text}");
    assert!(lines[1].starts_with("xi,delta_deg,v,"), "{text}");
    assert!(text.contains("\nxi,alpha_deg,K,"), "{text}");
    assert!(text.contains("\nfit,series,n_points,"), "{text}");
    assert!(
        leftovers(dir.path()).is_empty(),
        "{:?}",
        leftovers(dir.path())
    );
}

#[cfg(target_os = "linux")]
#[test]
fn an_output_to_dev_stdout_through_a_pipe_reaches_the_reader() {
    for path in ["/dev/stdout", "/proc/self/fd/1", "/dev/fd/1"] {
        let mut a: Vec<&str> = FORWARD.to_vec();
        a.extend(["--output", path]);
        let out = bin().args(&a).stdin(Stdio::null()).output().unwrap();
        expect(&out, 0, &[], path);
        let text = String::from_utf8(out.stdout).unwrap();
        assert!(text.starts_with("xi,delta_deg,v,"), "{path}: {text}");
        assert_eq!(text.lines().count(), 2, "{path}: {text}");
    }
    // Standard error as well.
    let mut a: Vec<&str> = FORWARD.to_vec();
    a.extend(["--output", "/dev/stderr"]);
    let out = bin().args(&a).output().unwrap();
    expect(&out, 0, &["xi,delta_deg,v,"], "/dev/stderr");
    assert!(out.stdout.is_empty());
}

#[test]
fn every_output_flag_takes_dash_for_stdout_not_a_file_named_dash() {
    let dir = tmpdir();
    let out = fb_in(
        dir.path(),
        &[
            "jan",
            "--no-profile",
            "--output",
            "p.csv",
            "--output-stats",
            "-",
        ],
    );
    expect(&out, 0, &[], "jan --output-stats -");
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.starts_with("fit,series,n_points,"), "{text}");
    assert!(!dir.path().join("-").exists(), "a file named - was created");
    assert!(dir.path().join("p.csv").exists());
}

#[test]
fn two_outputs_to_stdout_are_refused_before_any_work() {
    let dir = tmpdir();
    let cases: [(&[&str], &[&str]); 4] = [
        (
            &["jan", "--output", "-", "--output-stats", "-"],
            &["--output-stats", "standard output", "--output"],
        ),
        (
            &["jan", "--output", "-", "--output-stats", "/dev/stdout"],
            &["--output-stats", "standard output"],
        ),
        // Without --output the fit report takes standard output.
        (
            &["jan", "--output-stats", "-"],
            &["--output-stats", "standard output", "--output FILE"],
        ),
        (
            &["k", "--model", "stick", "--plot", "-"],
            &["--plot", "standard output"],
        ),
    ];
    for (args, must) in cases {
        let out = fb_in(dir.path(), args);
        expect(&out, 2, must, &format!("{args:?}"));
        assert!(out.stdout.is_empty(), "{args:?}");
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

// Temporary files and backups.

#[test]
fn replacing_an_existing_output_leaves_no_backup_behind() {
    let dir = tmpdir();
    let o = write(&dir, "o.csv", "old\n");
    let mut a: Vec<&str> = FORWARD.to_vec();
    a.extend(["--output", s(&o)]);
    expect(&fb_in(dir.path(), &a), 0, &[], "forward over o.csv");
    assert!(std::fs::read_to_string(&o)
        .unwrap()
        .starts_with("xi,delta_deg"));
    assert!(
        leftovers(dir.path()).is_empty(),
        "{:?}",
        leftovers(dir.path())
    );
}

/// A bad row after many good ones, with `--output` over an existing file: the rows before it
/// went to the temporary file as they came (not held back by chunks, since nobody sees that
/// file), and the error still leaves the target as it was and no temporary behind. For
/// `forward` past its first chunk of 32,768 rows, and `k` past four of its 8,192.
#[test]
fn a_late_bad_row_leaves_an_existing_output_as_it_was() {
    let dir = tmpdir();
    let o = write(&dir, "o.csv", "precious\n");
    let forward_rows = "1,12\n".repeat(40_000);
    let k_rows = "a,1,12,0.3,0.01\n".repeat(40_000);
    let cases = [
        (
            "forward",
            format!("xi,delta_deg\n{forward_rows}1,abc\n"),
            "line 40002",
        ),
        (
            "k",
            format!("series,xi,delta_deg,v,sigma_v\n{k_rows}a,1,12,-0.3,0.01\n"),
            "line 40002",
        ),
    ];
    for (command, text, line) in cases {
        let input = write(&dir, "in.csv", &text);
        let out = bin()
            .args([
                command,
                "--model",
                "stick",
                "--input",
                s(&input),
                "--output",
                s(&o),
            ])
            .output()
            .unwrap();
        expect(&out, 2, &["in.csv", line], command);
        assert_eq!(
            std::fs::read_to_string(&o).unwrap(),
            "precious\n",
            "{command}"
        );
        assert!(
            leftovers(dir.path()).is_empty(),
            "{command}: {:?}",
            leftovers(dir.path())
        );
    }
}

#[test]
fn stale_temporaries_of_gone_runs_are_removed_and_live_ones_kept() {
    let dir = tmpdir();
    let rep = dir.path().join("rep");
    std::fs::create_dir(&rep).unwrap();
    // A process id above any kernel's limit is gone; this test's own is alive.
    let gone = [
        ".fitbead-4000000000-AbCdEf.tmp",
        ".fitbead-4000000001-XyZ123.bak",
    ];
    let live = format!(".fitbead-{}-Live01.tmp", std::process::id());
    for n in gone {
        write(&rep, n, "partial");
    }
    write(&rep, &live, "partial");
    // Without a process id: removed once an hour old, kept while fresh.
    let old = write(&rep, ".fitbead-Old123.tmp", "partial");
    let two_hours_ago = std::time::SystemTime::now() - Duration::from_secs(7200);
    std::fs::File::options()
        .write(true)
        .open(&old)
        .unwrap()
        .set_modified(two_hours_ago)
        .unwrap();
    write(&rep, ".fitbead-New123.tmp", "partial");
    write(&rep, "notes.txt", "mine\n");
    let out = fb_in(dir.path(), &["report", "--out-dir", "rep"]);
    expect(&out, 0, &[], "report");
    let mut left = leftovers(&rep);
    left.sort();
    let mut want = vec![".fitbead-New123.tmp".to_string(), live];
    want.sort();
    assert_eq!(left, want);
    assert_eq!(
        std::fs::read_to_string(rep.join("notes.txt")).unwrap(),
        "mine\n"
    );
}

// The report directory as one unit.

#[test]
fn a_report_removes_the_previous_runs_files_only() {
    let dir = tmpdir();
    let rep = dir.path().join("rep");
    std::fs::create_dir(&rep).unwrap();
    // A previous run (a posterior one, say) wrote a corner plot this run does not write.
    write(&rep, "corner_jan-series_old.svg", "<svg/>");
    write(
        &rep,
        ".fitbead.manifest",
        "run an earlier one\nstate complete\nfile corner_jan-series_old.svg\nfile report.md\n",
    );
    write(&rep, "notes.txt", "mine\n");
    write(&rep, "corner_mine.svg", "<svg>mine</svg>");
    let out = fb_in(dir.path(), &["report", "--out-dir", "rep"]);
    expect(&out, 0, &[], "report");
    assert!(!rep.join("corner_jan-series_old.svg").exists());
    assert_eq!(
        std::fs::read_to_string(rep.join("notes.txt")).unwrap(),
        "mine\n"
    );
    assert!(rep.join("corner_mine.svg").exists());
    // The manifest: `run …`, `state …`, then one `file NAME` line per file of the run.
    let m = std::fs::read_to_string(rep.join(".fitbead.manifest")).unwrap();
    let field = |key: &str| -> Vec<&str> {
        m.lines()
            .filter_map(|l| l.strip_prefix(key)?.strip_prefix(' '))
            .collect()
    };
    assert_eq!(field("state"), ["complete"], "{m}");
    assert!(field("run").iter().any(|r| r.contains("process ")), "{m}");
    let files = field("file");
    assert!(files.contains(&"report.md"), "{m}");
    assert!(!files.iter().any(|f| f.starts_with("corner_")), "{m}");
    assert!(leftovers(&rep).is_empty(), "{:?}", leftovers(&rep));
}

#[cfg(unix)]
#[test]
fn a_locked_report_directory_is_written_only_once_the_lock_is_released() {
    let dir = tmpdir();
    let rep = dir.path().join("rep");
    std::fs::create_dir(&rep).unwrap();
    // Another run holds the directory.
    let held = std::fs::File::open(&rep).unwrap();
    held.lock().unwrap();
    let mut child = bin()
        .current_dir(dir.path())
        .args(["report", "--out-dir", "rep"])
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let t0 = Instant::now();
    while t0.elapsed() < Duration::from_secs(4) {
        assert!(
            child.try_wait().unwrap().is_none(),
            "report ended while the directory was locked"
        );
        std::thread::sleep(Duration::from_millis(100));
    }
    assert!(
        !rep.join("report.md").exists(),
        "written under another's lock"
    );
    held.unlock().unwrap();
    let out = child.wait_with_output().unwrap();
    expect(&out, 0, &[], "report after the lock");
    assert!(rep.join("report.md").exists());
}

// Series labels.

/// data/default.csv with its series 0.8 renamed `../../x/evil` and 1 renamed `a|b` + newline +
/// `c`.
fn hostile_labels(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(crate::common::root().join("data/default.csv")).unwrap();
    let mut out = String::new();
    for (i, line) in text.lines().enumerate() {
        let (series, rest) = line.split_once(',').unwrap();
        let label = match (i, series) {
            (0, _) => series.to_string(),
            (_, "0.8") => "../../x/evil".to_string(),
            (_, "1") => "\"a|b\nc\"".to_string(),
            _ => series.to_string(),
        };
        out.push_str(&format!("{label},{rest}\n"));
    }
    write(dir, "hostile.csv", &out)
}

#[test]
fn a_posterior_report_on_path_like_labels_writes_inside_its_directory() {
    let dir = tmpdir();
    let data = hostile_labels(dir.path());
    let work = dir.path().join("a").join("b");
    std::fs::create_dir_all(&work).unwrap();
    let out = fb_in(
        &work,
        &[
            "report",
            s(&data),
            "--out-dir",
            "out",
            "--method",
            "mcmc",
            "--max-steps",
            "100",
        ],
    );
    // Not converged in 100 steps (exit 1) is fine; a failure to write is not.
    assert!(matches!(out.status.code(), Some(0 | 1)), "{}", stderr(&out));
    let rep = work.join("out");
    assert!(rep.join("corner_jan-series_.._.._x_evil.svg").exists());
    assert!(!dir.path().join("x").exists(), "a file was written outside");
    let md = std::fs::read_to_string(rep.join("report.md")).unwrap();
    assert!(md.contains("corner_jan-series_.._.._x_evil.svg"));
}

#[test]
fn labels_with_pipes_and_newlines_keep_report_md_tables_whole() {
    let dir = tmpdir();
    let data = hostile_labels(dir.path());
    let out = fb_in(dir.path(), &["report", s(&data), "--out-dir", "rep"]);
    expect(&out, 0, &[], "report");
    let md = std::fs::read_to_string(dir.path().join("rep/report.md")).unwrap();
    assert!(md.contains("a\\|b c"), "label not escaped");
    // Every row of a table has as many cell separators as its header.
    let cells = |l: &str| l.replace("\\|", "").matches('|').count();
    let mut header: Option<usize> = None;
    for l in md.lines() {
        if l.starts_with('|') {
            match header {
                None => header = Some(cells(l)),
                Some(n) => assert_eq!(cells(l), n, "row {l:?}"),
            }
        } else {
            header = None;
        }
        assert_ne!(l, "c", "a label's newline broke a line");
        assert!(!l.starts_with("c] |") && !l.starts_with("c |"), "{l:?}");
    }
}

// Recipes.

fn recipe(dir: &Path, text: &str) -> PathBuf {
    std::fs::copy(
        crate::common::root().join("data/default.csv"),
        dir.join("d.csv"),
    )
    .unwrap();
    write(dir, "r.toml", text)
}

#[test]
fn a_recipe_seed_is_ignored_under_least_squares() {
    let dir = tmpdir();
    let r = recipe(dir.path(), "input = \"d.csv\"\nout_dir = \"o\"\nseed = 5\n");
    let out = fb_in(dir.path(), &["report", "--recipe", s(&r)]);
    expect(&out, 0, &[], "seed = 5 under lsq");
    assert!(dir.path().join("o/report.md").exists());
    // A --seed flag without --method mcmc is still refused.
    let out = fb_in(dir.path(), &["report", "--recipe", s(&r), "--seed", "3"]);
    expect(&out, 2, &["--seed", "mcmc only"], "--seed under lsq");
}

#[test]
fn the_method_flag_wins_over_a_recipe_posterior_with_its_seed() {
    let dir = tmpdir();
    let r = recipe(
        dir.path(),
        "input = \"d.csv\"\nout_dir = \"o\"\nmethod = \"mcmc\"\nseed = 5\nmax_steps = 100\n",
    );
    let out = fb_in(
        dir.path(),
        &["report", "--recipe", s(&r), "--method", "lsq"],
    );
    expect(&out, 0, &[], "--method lsq over the recipe");
    let stats = std::fs::read_to_string(dir.path().join("o/stats.csv")).unwrap();
    assert!(!stats.contains(",mcmc,"), "{stats}");
}

#[test]
fn a_bad_recipe_value_names_the_recipe_file_line_and_key() {
    let dir = tmpdir();
    let cases = [
        ("units = \"furlongs\"\n", "column 'units', value 'furlongs'"),
        ("level = 2.0\n", "column 'level', value '2'"),
        ("method = \"bayes\"\n", "column 'method', value 'bayes'"),
        ("rho = -1\n", "column 'rho', value '-1'"),
        (
            "method = \"mcmc\"\nmax_steps = 0\n",
            "column 'max_steps', value '0'",
        ),
    ];
    for (bad, must) in cases {
        let r = recipe(
            dir.path(),
            &format!("input = \"d.csv\"\nout_dir = \"o\"\n{bad}"),
        );
        let out = fb_in(dir.path(), &["report", "--recipe", s(&r)]);
        let line = 2 + bad.lines().count();
        expect(
            &out,
            2,
            &[s(&r), &format!("line {line},"), must],
            bad.trim(),
        );
        assert!(!stderr(&out).contains("<command line>"), "{}", stderr(&out));
    }
    // The same value given as a flag is still the command line's.
    let r = recipe(
        dir.path(),
        "input = \"d.csv\"\nout_dir = \"o\"\nlevel = 0.9\n",
    );
    let out = fb_in(dir.path(), &["report", "--recipe", s(&r), "--level", "2"]);
    expect(&out, 2, &["<command line>", "--level"], "--level 2");
    assert!(!dir.path().join("o").exists());
}

#[test]
fn an_empty_path_in_a_recipe_is_refused_naming_it() {
    let dir = tmpdir();
    for (key, text) in [
        ("out_dir", "input = \"d.csv\"\nout_dir = \"\"\n"),
        ("input", "input = \"\"\nout_dir = \"o\"\n"),
    ] {
        let r = recipe(dir.path(), text);
        let out = fb_in(dir.path(), &["report", "--recipe", s(&r)]);
        expect(
            &out,
            2,
            &[s(&r), &format!("column '{key}', value ''"), "empty path"],
            key,
        );
        assert!(
            !dir.path().join("report.md").exists(),
            "written into the recipe's directory"
        );
    }
}
