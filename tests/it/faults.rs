//! Faults, signals and unit mistakes: what a hostile or careless user does must end in a
//! clear exit (0, 1 for a fit that could not run, 2 for bad input, 130 for a signal) — never a
//! panic, a hang, a clobbered file or a silent wrong fit. The fuzz harness that looks for the
//! next such fault is the ignored test [`fuzz_mutated_inputs`] (docs/GUIDE.md, "Exit codes").

use crate::common::{bin, col, expect, interrupt, leftovers, s, stderr, table, tmpdir, write};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// Runs `cmd` to its end or until `limit`, then kills it; the output and whether it ended in
/// time. Its stdout and stderr are read while it runs (a pipe left unread would block a
/// command that writes more than the pipe holds).
fn run_for(cmd: &mut Command, limit: Duration) -> (Output, bool) {
    use std::io::Read;
    let mut child = cmd
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let drain = |mut r: Box<dyn Read + Send>| {
        std::thread::spawn(move || {
            let mut b = Vec::new();
            let _ = r.read_to_end(&mut b);
            b
        })
    };
    let out = drain(Box::new(child.stdout.take().unwrap()));
    let err = drain(Box::new(child.stderr.take().unwrap()));
    let t0 = Instant::now();
    let mut in_time = true;
    let status = loop {
        if let Some(st) = child.try_wait().unwrap() {
            break st;
        }
        if t0.elapsed() > limit {
            in_time = false;
            let _ = child.kill();
            break child.wait().unwrap();
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let output = Output {
        status,
        stdout: out.join().unwrap(),
        stderr: err.join().unwrap(),
    };
    (output, in_time)
}

/// Runs fitbead with `args` (at most 60 s) and returns its output.
fn fb(args: &[&str]) -> Output {
    let (out, in_time) = run_for(bin().args(args), Duration::from_secs(60));
    assert!(in_time, "{args:?} did not end within 60 s");
    out
}

// Panics and hangs.

#[test]
fn a_prior_outside_the_feasible_box_exits_2_naming_it() {
    let cases: [&[&str]; 4] = [
        &[
            "klaw",
            "--model",
            "stick",
            "--method",
            "mcmc",
            "--prior",
            "c=uniform(10,20)",
        ],
        &["jan", "--method", "mcmc", "--prior", "mu=uniform(-3,-2)"],
        &["jaeger", "--method", "mcmc", "--prior", "a3=uniform(-2,-1)"],
        &[
            "klaw",
            "--model",
            "stick",
            "--law",
            "free-per-series",
            "--method",
            "mcmc",
            "--prior",
            "K=uniform(0.95,0.99)",
        ],
    ];
    for args in cases {
        let dir = tmpdir();
        let o = dir.path().join("o.csv");
        let mut a: Vec<&str> = args.to_vec();
        a.extend(["--max-steps", "200", "--output", s(&o)]);
        let out = fb(&a);
        expect(
            &out,
            2,
            &["--prior", "uniform(", "support", "feasible box"],
            &format!("{args:?}"),
        );
        assert!(!o.exists(), "{args:?}: output written");
    }
}

#[test]
fn report_with_no_steady_point_exits_2_naming_file_and_line() {
    let dir = tmpdir();
    let p = write(
        &dir,
        "p.csv",
        "series,xi,delta_deg,v,sigma_v\n1,1,60,0.3,0.01\n",
    );
    let r = dir.path().join("r");
    let out = fb(&["report", s(&p), "--out-dir", s(&r)]);
    expect(&out, 2, &["p.csv, line 2", "series '1'"], "report");
    assert!(!r.exists(), "report directory made");
}

#[test]
fn md_outside_its_domain_is_refused_at_once() {
    let t0 = Instant::now();
    let out = fb(&[
        "forward",
        "--model",
        "md",
        "--xi",
        "1.6",
        "--delta-deg",
        "6",
        "--rho",
        "1e-6",
    ]);
    expect(&out, 2, &["--rho", "rho >= 0.01"], "md rho 1e-6");
    let dir = tmpdir();
    let p = write(&dir, "s.csv", "xi,delta_deg,rho\n1.6,6,5e-324\n");
    let out = fb(&["forward", "--model", "md", "--input", s(&p)]);
    expect(
        &out,
        2,
        &["s.csv, line 2, column 'rho'", "rho >= 0.01"],
        "md rho cell",
    );
    // A damping so fast that the step would collapse is refused the same way.
    let out = fb(&[
        "forward",
        "--model",
        "md",
        "--xi",
        "1.6",
        "--delta-deg",
        "6",
        "--gamma-s",
        "1e9",
    ]);
    expect(&out, 2, &["--gamma-s"], "md gamma_s");
    assert!(t0.elapsed() < Duration::from_secs(20), "{:?}", t0.elapsed());
}

#[test]
fn huge_counts_are_refused_before_any_work() {
    let out = fb(&["simulate", "--points", "4294967296"]);
    expect(&out, 2, &["--points", "1000000"], "simulate --points");
    let out = fb(&["simulate", "--points", "100000", "--series", "1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16,17,18,19,20,21,22,23,24,25,26,27,28,29,30,31,32,33,34,35,36,37,38,39,40,41,42,43,44,45,46,47,48,49,50,51,52,53,54,55,56,57,58,59,60,61,62,63,64,65,66,67,68,69,70,71,72,73,74,75,76,77,78,79,80,81,82,83,84,85,86,87,88,89,90,91,92,93,94,95,96,97,98,99,100,101"]);
    expect(&out, 2, &["--points", "rows"], "simulate rows");
    let out = fb(&[
        "klaw",
        "--model",
        "stick",
        "--method",
        "mcmc",
        "--walkers",
        "100000000",
    ]);
    expect(&out, 2, &["--walkers"], "klaw --walkers");
    let out = fb(&["jan", "--method", "mcmc", "--walkers", "10002"]);
    expect(&out, 2, &["--walkers", "at most 10000"], "jan --walkers");
}

// Signals.

/// Every long command stops soon after SIGINT or SIGTERM with exit 130, leaves an existing
/// output untouched and no temporary file.
#[cfg(unix)]
#[test]
fn signals_stop_every_long_command() {
    let cases: Vec<(&str, Vec<&str>)> = vec![
        (
            "-INT",
            vec!["bench", "--scenes", "2000", "--output", "o.csv"],
        ),
        (
            "-TERM",
            vec!["bench", "--scenes", "2000", "--output", "o.csv"],
        ),
        (
            "-INT",
            vec![
                "simulate", "--model", "md", "--series", "1,0.8", "--points", "12", "--output",
                "o.csv",
            ],
        ),
        ("-TERM", vec!["report", "big.csv", "--out-dir", "."]),
        // Streaming commands: the temporary output is removed.
        (
            "-TERM",
            vec![
                "forward",
                "--model",
                "contact",
                "--input",
                "scenes.csv",
                "--output",
                "o.csv",
            ],
        ),
        (
            "-INT",
            vec![
                "klaw",
                "--model",
                "stickslip",
                "--law",
                "free-per-series",
                "huge.csv",
                "--output",
                "o.csv",
            ],
        ),
        ("-INT", vec!["jaeger", "huge.csv", "--output", "o.csv"]),
        (
            "-INT",
            vec![
                "forward",
                "--model",
                "md",
                "--xi",
                "1",
                "--delta-deg",
                "12",
                "--beads",
                "100000",
                "--output",
                "o.csv",
            ],
        ),
    ];
    // Data sets large enough for the fits to run for seconds.
    let data = tmpdir();
    let big = data.path().join("big.csv");
    let huge = data.path().join("huge.csv");
    let scenes = data.path().join("scenes.csv");
    std::fs::write(
        &scenes,
        format!("xi,delta_deg\n{}", "1,12\n1.6,9\n".repeat(200_000)),
    )
    .unwrap();
    // Sizes that keep each command running well past the signal at 1.5 s on a loaded 2-core
    // machine (jaeger on 20,000 points per series ends in 1.25 s when the machine is quiet).
    for (p, n) in [(&big, "2000"), (&huge, "50000")] {
        let out = fb(&["simulate", "--points", n, "--output", s(p)]);
        expect(&out, 0, &[], "simulate");
    }
    let mut worst = Duration::ZERO;
    for (sig, args) in &cases {
        let dir = tmpdir();
        std::fs::copy(&big, dir.path().join("big.csv")).unwrap();
        std::fs::copy(&huge, dir.path().join("huge.csv")).unwrap();
        std::fs::copy(&scenes, dir.path().join("scenes.csv")).unwrap();
        // An existing output (and, for report, an existing report.md) must survive.
        write(&dir, "o.csv", "old\n");
        write(&dir, "report.md", "old\n");
        let (st, took) = interrupt(dir.path(), args, sig, Duration::from_millis(1500));
        assert_eq!(st.code(), Some(130), "{sig} {args:?}");
        worst = worst.max(took);
        assert!(took < Duration::from_secs(2), "{sig} {args:?}: {took:?}");
        for f in ["o.csv", "report.md"] {
            assert_eq!(
                std::fs::read_to_string(dir.path().join(f)).unwrap(),
                "old\n",
                "{sig} {args:?}: {f} changed"
            );
        }
        assert!(
            leftovers(dir.path()).is_empty(),
            "{sig} {args:?}: {:?}",
            leftovers(dir.path())
        );
    }
    eprintln!("slowest stop after the signal: {worst:?}");
}

/// An MCMC run stopped by a signal marks every output: every parameter row's note, every row
/// of the draws, and the statistics.
#[cfg(unix)]
#[test]
fn an_interrupted_posterior_run_marks_every_output() {
    let dir = tmpdir();
    let args = [
        "klaw",
        "--model",
        "stick",
        "--method",
        "mcmc",
        "--min-ess",
        "1e12",
        "--max-steps",
        "100000000",
        "--output",
        "r.csv",
        "--output-stats",
        "s.csv",
        "--draws",
        "d.csv",
    ];
    let (st, _) = interrupt(dir.path(), &args, "-INT", Duration::from_millis(1500));
    assert_eq!(st.code(), Some(130));
    let read = |f: &str| std::fs::read_to_string(dir.path().join(f)).unwrap();
    let (h, rows) = table(&read("r.csv"));
    assert!(!rows.is_empty());
    for r in &rows {
        assert!(r[col(&h, "note")].contains("interrupted"), "{r:?}");
    }
    let (h, rows) = table(&read("d.csv"));
    assert!(!rows.is_empty());
    let c = col(&h, "status");
    assert!(rows.iter().all(|r| r[c] == "interrupted"));
    let (h, rows) = table(&read("s.csv"));
    assert_eq!(rows[0][col(&h, "mcmc_status")], "interrupted");
}

#[test]
fn a_posterior_run_that_cannot_start_exits_1() {
    let dir = tmpdir();
    let o = dir.path().join("o.csv");
    let out = fb(&[
        "klaw",
        "--model",
        "stick",
        "--method",
        "mcmc",
        "--prior",
        "c=uniform(-1e308,1e308)",
        "--output",
        s(&o),
    ]);
    expect(&out, 1, &["could not start", "klaw-c [all]"], "mcmc start");
    // The rows hold the least-squares values, marked.
    let (h, rows) = table(&std::fs::read_to_string(&o).unwrap());
    assert!(rows[0][col(&h, "note")].contains("MCMC did not run"));
}

// Files.

#[cfg(unix)]
#[test]
fn outputs_write_through_fifos_and_follow_symlinks() {
    use std::os::unix::fs::FileTypeExt;
    let dir = tmpdir();
    // A FIFO stays a FIFO and its reader gets the bytes.
    let fifo = dir.path().join("fifo");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read_to_string(fifo).unwrap())
    };
    let out = fb(&["regimes", "--output", s(&fifo)]);
    expect(&out, 0, &[], "regimes into a FIFO");
    let got = reader.join().unwrap();
    assert!(got.starts_with("xi,alpha_deg"), "{got}");
    assert!(std::fs::symlink_metadata(&fifo)
        .unwrap()
        .file_type()
        .is_fifo());
    assert!(leftovers(dir.path()).is_empty());
    // A symbolic link stays a link; its target is replaced.
    let target = write(&dir, "target.csv", "old\n");
    let link = dir.path().join("link.csv");
    std::os::unix::fs::symlink("target.csv", &link).unwrap();
    let out = fb(&["regimes", "--output", s(&link)]);
    expect(&out, 0, &[], "regimes into a symlink");
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    assert!(std::fs::read_to_string(&target)
        .unwrap()
        .starts_with("xi,alpha_deg"));
    assert!(leftovers(dir.path()).is_empty());
}

#[cfg(unix)]
#[test]
fn new_outputs_honour_the_umask_and_replaced_ones_keep_their_mode() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tmpdir();
    let new = dir.path().join("new.csv");
    let kept = write(&dir, "kept.csv", "old\n");
    std::fs::set_permissions(&kept, std::fs::Permissions::from_mode(0o640)).unwrap();
    let bin_path = crate::common::bin_path();
    for (umask, out, want) in [("022", &new, 0o644), ("077", &kept, 0o640)] {
        let st = Command::new("sh")
            .arg("-c")
            .arg(format!(
                "umask {umask}; exec \"$0\" regimes --output \"$1\"",
            ))
            .arg(&bin_path)
            .arg(out)
            .status()
            .unwrap();
        assert!(st.success());
        let mode = std::fs::metadata(out).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, want, "{}: {mode:o}", out.display());
    }
}

#[test]
fn a_report_is_written_whole_or_not_at_all() {
    let dir = tmpdir();
    let rep = dir.path().join("rep");
    std::fs::create_dir_all(rep.join("params.csv")).unwrap();
    write(&rep, "models.csv", "old\n");
    let out = fb(&["report", "--out-dir", s(&rep)]);
    expect(&out, 2, &["params.csv", "is a directory"], "report");
    assert_eq!(
        std::fs::read_to_string(rep.join("models.csv")).unwrap(),
        "old\n"
    );
    let mut names: Vec<String> = std::fs::read_dir(&rep)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["models.csv", "params.csv"]);
}

#[test]
fn an_output_that_is_an_input_or_another_output_is_refused() {
    let dir = tmpdir();
    let x = dir.path().join("x.csv");
    let out = fb(&[
        "klaw",
        "--model",
        "stick",
        "--no-profile",
        "--output",
        s(&x),
        "--output-stats",
        s(&x),
    ]);
    expect(&out, 2, &["--output-stats", "same file as --output"], "x x");
    assert!(!x.exists());
    let inp = write(&dir, "in.csv", "xi,delta_deg\n1,12\n");
    let out = fb(&[
        "forward",
        "--model",
        "stick",
        "--input",
        s(&inp),
        "--output",
        s(&inp),
    ]);
    expect(&out, 2, &["--output", "same file as --input"], "in in");
    assert_eq!(
        std::fs::read_to_string(&inp).unwrap(),
        "xi,delta_deg\n1,12\n"
    );
    #[cfg(unix)]
    {
        let link = dir.path().join("alias.csv");
        std::os::unix::fs::symlink(&inp, &link).unwrap();
        let out = fb(&[
            "forward",
            "--model",
            "stick",
            "--input",
            s(&inp),
            "--output",
            s(&link),
        ]);
        expect(&out, 2, &["same file as --input"], "in alias");
    }
}

#[cfg(unix)]
#[test]
fn a_closed_stdout_is_an_error() {
    let bin_path = crate::common::bin_path();
    for cmd in [
        "forward --model stick",
        "regimes",
        "klaw --model stick --no-profile",
    ] {
        let out = Command::new("sh")
            .arg("-c")
            .arg(format!("exec \"$0\" {cmd} >&-"))
            .arg(&bin_path)
            .output()
            .unwrap();
        expect(&out, 2, &["standard output is closed"], cmd);
    }
}

// Validation and messages.

#[test]
fn every_present_cell_is_checked_whatever_the_model() {
    let dir = tmpdir();
    for (model, text, column) in [
        ("md", "xi,delta_deg,K,f\n1,12,abc,nan\n", "column 'K'"),
        ("md", "xi,delta_deg,f\n1,12,nan\n", "column 'f'"),
        (
            "stick",
            "xi,delta_deg,lambda\n1,12,abc\n",
            "column 'lambda'",
        ),
        ("jan", "xi,delta_deg,spin\n1,12,twirl\n", "column 'spin'"),
        ("stick", "xi,delta_deg,a3\n1,12,-1\n", "column 'a3'"),
    ] {
        let p = write(&dir, "s.csv", text);
        let out = fb(&["forward", "--model", model, "--input", s(&p)]);
        expect(
            &out,
            2,
            &["s.csv, line 2", column],
            &format!("{model} {text:?}"),
        );
    }
}

#[test]
fn k_of_one_or_more_is_refused() {
    for k in ["1", "2"] {
        let out = fb(&[
            "forward",
            "--model",
            "stick",
            "--xi",
            "1",
            "--delta-deg",
            "12",
            "--K",
            k,
        ]);
        expect(&out, 2, &["K", "must be < 1"], &format!("--K {k}"));
    }
    let dir = tmpdir();
    let p = write(&dir, "s.csv", "xi,delta_deg,K\n1,12,0.6\n1,12,1.5\n");
    let out = fb(&["forward", "--model", "stick", "--input", s(&p)]);
    expect(&out, 2, &["s.csv, line 3, column 'K'", "< 1"], "K cell");
}

#[test]
fn jan_and_jaeger_failures_name_file_series_and_lines() {
    let dir = tmpdir();
    let p = write(
        &dir,
        "d.csv",
        "series,xi,delta_deg,v,sigma_v\n0.8,0.8,16,0.2,0.01\n0.8,0.8,17,0.25,0.01\n",
    );
    for cmd in ["jan", "jaeger"] {
        let out = fb(&[cmd, s(&p)]);
        expect(
            &out,
            2,
            &["d.csv, lines 2, 3 (series '0.8')"],
            &format!("{cmd} all series too short"),
        );
    }
    // One short series beside good ones: a located note, the other fits made.
    let good = std::fs::read_to_string(crate::common::root().join("data/default.csv")).unwrap();
    let q = write(&dir, "e.csv", &format!("{good}short,3,20,0.5,0.01,0.5\n"));
    let out = fb(&["jan", s(&q), "--no-profile"]);
    let line = good.lines().count() + 1;
    expect(
        &out,
        0,
        &[&format!("e.csv, lines {line} (series 'short')")],
        "jan one short series",
    );
}

#[test]
fn huge_values_are_not_echoed_whole() {
    let dir = tmpdir();
    let big = "x".repeat(10 << 20);
    let p = write(&dir, "s.csv", &format!("xi,delta_deg,K\n1,12,{big}\n"));
    let q = write(&dir, "t.csv", &format!("xi,delta_deg,v\n1,{big},0.3\n"));
    for args in [
        vec!["forward", "--model", "stick", "--input", s(&p)],
        vec!["forward", "--model", "stick", "--input", s(&q)],
        vec!["k", "--model", "stick", "--input", s(&q)],
        vec!["klaw", "--model", "stick", "--law", &big[..1000]],
    ] {
        let out = fb(&args);
        let e = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{}", &e[..e.len().min(300)]);
        assert!(e.len() < 1000, "{} bytes of message", e.len());
        assert!(e.contains("bytes)"), "{e}");
    }
}

#[test]
fn negative_numbers_stdin_and_whole_choice_names() {
    // A negative number is a flag's value, refused by its own check.
    let out = fb(&[
        "forward",
        "--model",
        "stick",
        "--xi",
        "-1",
        "--delta-deg",
        "12",
    ]);
    expect(&out, 2, &["xi", "radius ratio must be > 0"], "--xi -1");
    let out = fb(&["klaw", "--model", "stick", "--f", "-0.5"]);
    expect(&out, 2, &["--f", "-0.5"], "--f -0.5");
    // --input - reads standard input.
    let mut child = bin()
        .args(["forward", "--model", "stick", "--input", "-"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    {
        use std::io::Write;
        let mut i = child.stdin.take().unwrap();
        i.write_all(b"xi,delta_deg\n1,12\n").unwrap();
    }
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).contains("0.3912082"));
    let out = bin()
        .args(["k", "--model", "stick", "--input", "-"])
        .stdin(std::fs::File::open(crate::common::root().join("data/default.csv")).unwrap())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    // Choices: whole names, any case.
    let out = fb(&["klaw", "--model", "stick", "--law", "free"]);
    expect(&out, 2, &["free-per-series"], "--law free");
    let out = fb(&[
        "forward",
        "--model",
        "STICK",
        "--xi",
        "1",
        "--delta-deg",
        "12",
        "--spin",
        "Roll",
    ]);
    expect(&out, 0, &[], "--model STICK");
    let out = fb(&[
        "klaw",
        "--model",
        "Stick",
        "--law",
        "C",
        "--method",
        "LSQ",
        "--no-profile",
    ]);
    expect(&out, 0, &[], "--law C --method LSQ");
}

// Unit mistakes.

/// data/default.csv with one column transformed.
fn default_with(f: impl Fn(&str, &str, f64) -> String) -> String {
    let text = std::fs::read_to_string(crate::common::root().join("data/default.csv")).unwrap();
    let (h, rows) = table(&text);
    let mut out = h.join(",") + "\n";
    for r in rows {
        let xi: f64 = r[col(&h, "xi")].parse().unwrap();
        let cells: Vec<String> = h.iter().zip(&r).map(|(name, c)| f(name, c, xi)).collect();
        out += &(cells.join(",") + "\n");
    }
    out
}

#[test]
fn sigma_v_beside_v_m_s_is_refused() {
    let dir = tmpdir();
    let p = write(
        &dir,
        "d.csv",
        "series,xi,delta_deg,v_m_s,R_m,sigma_v\na,1,12,0.09,0.003,0.002\n",
    );
    let out = fb(&["klaw", "--model", "stick", s(&p)]);
    expect(&out, 2, &["column 'sigma_v'", "sigma_v_m_s"], "sigma_v");
}

#[test]
fn v_beside_v_m_s_is_refused() {
    let dir = tmpdir();
    let p = write(
        &dir,
        "d.csv",
        "series,xi,delta_deg,v,v_m_s,R_m\na,1,12,0.39,0.09,0.003\n",
    );
    for cmd in ["k", "klaw"] {
        let out = fb(&[cmd, "--model", "stick", s(&p)]);
        expect(&out, 2, &["v_m_s", "both v"], cmd);
    }
}

#[test]
fn unit_mistakes_are_flagged_loudly() {
    let dir = tmpdir();
    // Slopes in radians.
    let rad = write(
        &dir,
        "rad.csv",
        &default_with(|h, c, _| {
            if h == "delta_deg" {
                c.parse::<f64>().unwrap().to_radians().to_string()
            } else {
                c.to_string()
            }
        }),
    );
    let out = fb(&["k", "--model", "stick", s(&rad)]);
    expect(&out, 0, &["warning", "are these radians?"], "k radians");
    // The report refuses what klaw refuses (stick/slip cannot make some of these points
    // steady), writing nothing; with --keep-going it writes what it can, report.md opening
    // with the warnings.
    let rep = dir.path().join("rep");
    let out = fb(&["report", s(&rad), "--out-dir", s(&rep)]);
    expect(
        &out,
        2,
        &[
            "are these radians?",
            "stick/slip model",
            "--keep-going",
            "nothing written",
        ],
        "report radians",
    );
    assert!(!rep.exists(), "a refused report writes nothing");
    let out = fb(&["report", s(&rad), "--out-dir", s(&rep), "--keep-going"]);
    expect(
        &out,
        0,
        &["are these radians?"],
        "report radians --keep-going",
    );
    let md = std::fs::read_to_string(rep.join("report.md")).unwrap();
    let warnings = md.find("## Warnings").expect("a warnings section");
    let first_table = md.find("## Fitted parameters").unwrap();
    assert!(warnings < first_table, "report.md opens with the warnings");
    let section = &md[warnings..first_table];
    assert!(section.contains("are these radians?"), "{section}");
    assert!(
        section.contains("no K of the stick/slip model"),
        "{section}"
    );
    assert!(!md.contains("## Plausibility checks"));
    // m/s in the dimensionless column (R = 2.5 mm).
    let ms = write(
        &dir,
        "ms.csv",
        &default_with(|h, c, xi| {
            let scale = (9.81f64 * 2.5e-3 * (1.0 + xi)).sqrt();
            match h {
                "v" | "sigma_v" | "v_true" => (c.parse::<f64>().unwrap() * scale).to_string(),
                _ => c.to_string(),
            }
        }),
    );
    let o = dir.path().join("s.csv");
    let out = fb(&[
        "klaw",
        "--model",
        "stick",
        "--no-profile",
        s(&ms),
        "--output-stats",
        s(&o),
    ]);
    expect(&out, 0, &["are these m/s?", "reduced chi2"], "klaw m/s");
    let (h, rows) = table(&std::fs::read_to_string(&o).unwrap());
    assert!(rows[0][col(&h, "note")].contains("reduced chi2"));
    // R_m in millimetres.
    let mm = write(
        &dir,
        "mm.csv",
        &default_with(|h, c, xi| match h {
            "v" => (c.parse::<f64>().unwrap() * (9.81f64 * 2.5e-3 * (1.0 + xi)).sqrt()).to_string(),
            "sigma_v" => {
                (c.parse::<f64>().unwrap() * (9.81f64 * 2.5e-3 * (1.0 + xi)).sqrt()).to_string()
            }
            _ => c.to_string(),
        })
        .replacen("v,sigma_v", "v_m_s,sigma_v_m_s", 1)
        .replace(",v_true\n", ",v_true,R_m\n")
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i == 0 {
                l.to_string()
            } else {
                format!("{l},2.5")
            }
        })
        .collect::<Vec<_>>()
        .join("\n"),
    );
    let out = fb(&["k", "--model", "stick", s(&mm)]);
    expect(&out, 0, &["R_m", "millimetres"], "k R_m in mm");
}

/// The fuzz harness: mutated measurement and scene tables fed to every reading command; each
/// run must end within its time limit with exit 0 or 2 (or 1 for a fit that did not converge)
/// and no panic. Ignored by default: `FITBEAD_FUZZ_RUNS=3000 cargo test --release --test it
/// faults::fuzz -- --ignored --nocapture` (docs/GUIDE.md, "Exit codes").
#[test]
#[ignore]
fn fuzz_mutated_inputs() {
    use rand::{Rng, SeedableRng};
    let runs: usize = std::env::var("FITBEAD_FUZZ_RUNS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(3000);
    let seed: u64 = std::env::var("FITBEAD_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let threads: usize = std::env::var("FITBEAD_FUZZ_THREADS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(2);
    let limit = Duration::from_secs(60);
    let measurements = "series,xi,delta_deg,v,sigma_v\n\
        a,1,9,0.2,0.004\na,1,11,0.35,0.007\na,1,13,0.45,0.009\na,1,15,0.52,0.01\n\
        b,2,5,0.3,0.006\nb,2,6,0.4,0.008\nb,2,7,0.47,0.009\nb,2,8,0.55,0.011\n";
    let dimensional = "series,xi,delta_deg,v_m_s,R_m,g,sigma_v_m_s\n\
        a,1,10,0.05,0.0025,9.81,0.001\na,1,12,0.068,0.0025,9.81,0.001\n\
        a,1,14,0.08,0.0025,9.81,0.001\na,1,16,0.09,0.0025,9.81,0.001\n";
    let scenes = "id,xi,delta_deg,K,rho,f,lambda,mu,a1,a2,a3,spin\n\
        r1,1,12,adjusted,0.4,0.1,0.8,0.1,0.05,0.4,1.5,roll\n\
        r2,2,6,0.7,0.5,0.2,,,,,,keep\nr3,0.8,20,c=0.3,,,,,,,,\n";
    let tokens: &[&str] = &[
        "",
        " ",
        "nan",
        "NaN",
        "inf",
        "-inf",
        "1e308",
        "-1e308",
        "1e-320",
        "5e-324",
        "0",
        "-0",
        "-1",
        "1",
        "2",
        "0.5",
        "89.999999",
        "90",
        "1e6",
        "abc",
        "\"",
        "\"\"",
        "a,b",
        "\u{e9}",
        "\u{2003}",
        "adjusted",
        "impact",
        "cos2a",
        "c=1e300",
        "c=-5",
        "factor=1e9",
        "roll",
        "0x10",
        "1_000",
        "+5",
        ".5",
        "5.",
        "1e",
        "--",
        "\t7\t",
    ];
    let commands: Vec<(Vec<&str>, usize)> = vec![
        (vec!["forward", "--model", "stick"], 2),
        (vec!["forward", "--model", "stickslip"], 2),
        (vec!["forward", "--model", "contact"], 2),
        (vec!["forward", "--model", "auto"], 2),
        (vec!["forward", "--model", "jan"], 2),
        (
            vec![
                "forward", "--model", "jaeger", "--a1", "0.05", "--a2", "0.4", "--a3", "1.5",
            ],
            2,
        ),
        (
            vec![
                "forward",
                "--model",
                "md",
                "--beads",
                "60",
                "--transient",
                "20",
            ],
            2,
        ),
        (vec!["k", "--model", "stick"], 0),
        (vec!["k", "--model", "stickslip"], 0),
        (vec!["k", "--model", "auto"], 0),
        (vec!["klaw", "--model", "stick", "--no-profile"], 0),
        (
            vec![
                "klaw",
                "--model",
                "stick",
                "--law",
                "free-per-series",
                "--skip-unsteady",
            ],
            0,
        ),
        (vec!["jan", "--no-profile"], 0),
        (vec!["jaeger", "--no-profile"], 0),
    ];
    let next = std::sync::atomic::AtomicUsize::new(0);
    let bad: std::sync::Mutex<Vec<String>> = Default::default();
    let counts: std::sync::Mutex<std::collections::BTreeMap<i32, usize>> = Default::default();
    let slowest = std::sync::Mutex::new(Duration::ZERO);
    let dir = tmpdir();
    std::thread::scope(|sc| {
        for _ in 0..threads {
            sc.spawn(|| loop {
                let i = next.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
                if i >= runs {
                    break;
                }
                let mut rng =
                    rand_chacha::ChaCha8Rng::seed_from_u64(seed.wrapping_mul(1_000_003) + i as u64);
                let (args, base) = &commands[rng.random_range(0..commands.len())];
                let base = match base {
                    2 => scenes,
                    _ if rng.random_bool(0.3) => dimensional,
                    _ => measurements,
                };
                let bytes = mutate(base.as_bytes(), &mut rng, tokens);
                let p = dir.path().join(format!("in{i}.csv"));
                std::fs::write(&p, &bytes).unwrap();
                let t0 = Instant::now();
                let (out, in_time) = run_for(bin().args(args).arg("--input").arg(&p), limit);
                let took = t0.elapsed();
                {
                    let mut w = slowest.lock().unwrap();
                    *w = (*w).max(took);
                }
                let code = out.status.code().unwrap_or(-1);
                *counts.lock().unwrap().entry(code).or_default() += 1;
                let e = stderr(&out);
                // Exit 1 (a fit that did not converge, outputs written) is an answer too.
                let fit = matches!(args[0], "klaw" | "jan" | "jaeger" | "report");
                let allowed = code == 0 || code == 2 || (fit && code == 1);
                if !in_time || !allowed || e.contains("panicked") {
                    let keep = dir.path().join(format!("fail{i}.csv"));
                    let _ = std::fs::copy(&p, &keep);
                    bad.lock().unwrap().push(format!(
                        "run {i}: {args:?} exit {code} in {took:?}{}: {}",
                        if in_time { "" } else { " (timed out)" },
                        &e[..e.len().min(400)]
                    ));
                    let _ = std::fs::write(dir.path().join(format!("fail{i}.txt")), e);
                }
                let _ = std::fs::remove_file(&p);
            });
        }
    });
    let bad = bad.into_inner().unwrap();
    eprintln!(
        "fuzz: {runs} runs (seed {seed}), exit codes {:?}, slowest {:?}, failures {}",
        counts.into_inner().unwrap(),
        slowest.into_inner().unwrap(),
        bad.len()
    );
    if !bad.is_empty() {
        let kept = dir.keep();
        panic!(
            "{} failing runs (inputs kept in {}):\n{}",
            bad.len(),
            kept.display(),
            bad.join("\n")
        );
    }
}

/// One to four random mutations of a CSV text: a cell replaced by a token, a cell or a row
/// removed or duplicated, a column added, blank lines, CRLF, a cut, random bytes.
fn mutate(base: &[u8], rng: &mut impl rand::Rng, tokens: &[&str]) -> Vec<u8> {
    let text = String::from_utf8_lossy(base).into_owned();
    let mut rows: Vec<Vec<String>> = text
        .lines()
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    let n = rng.random_range(1..=4);
    let mut raw: Option<Vec<u8>> = None;
    for _ in 0..n {
        let r = rng.random_range(0..rows.len());
        match rng.random_range(0..12) {
            0..=4 => {
                if rows[r].is_empty() {
                    continue;
                }
                let c = rng.random_range(0..rows[r].len());
                rows[r][c] = tokens[rng.random_range(0..tokens.len())].to_string();
            }
            5 => {
                if !rows[r].is_empty() {
                    let c = rng.random_range(0..rows[r].len());
                    rows[r].remove(c);
                }
            }
            6 => {
                let row = rows[r].clone();
                rows.insert(r, row);
            }
            7 if rows.len() > 1 => {
                rows.remove(r);
            }
            8 => {
                let extra = [
                    "K", "rho", "f", "sigma_v", "v_m_s", "R_m", "g", "series", "xi", "spin",
                    "beads", "v",
                ];
                let name = extra[rng.random_range(0..extra.len())];
                for (i, row) in rows.iter_mut().enumerate() {
                    row.push(if i == 0 {
                        name.to_string()
                    } else {
                        tokens[rng.random_range(0..tokens.len())].to_string()
                    });
                }
            }
            9 => rows.insert(r, Vec::new()),
            10 => {
                let big = "9".repeat(rng.random_range(1..100_000));
                if !rows[r].is_empty() {
                    let c = rng.random_range(0..rows[r].len());
                    rows[r][c] = big;
                }
            }
            _ => {
                let mut b = join(&rows, rng.random_bool(0.2));
                if !b.is_empty() {
                    match rng.random_range(0..3) {
                        0 => b.truncate(rng.random_range(0..b.len())),
                        1 => {
                            let at = rng.random_range(0..b.len());
                            b.insert(at, rng.random());
                        }
                        _ => {
                            let at = rng.random_range(0..b.len());
                            b[at] = rng.random();
                        }
                    }
                }
                raw = Some(b);
            }
        }
    }
    raw.unwrap_or_else(|| join(&rows, rng.random_bool(0.2)))
}

fn join(rows: &[Vec<String>], crlf: bool) -> Vec<u8> {
    let eol = if crlf { "\r\n" } else { "\n" };
    rows.iter()
        .map(|r| r.join(",") + eol)
        .collect::<String>()
        .into_bytes()
}

// Errors in the slope.

/// A bad `sigma_delta_deg` cell exits 2 naming file, line, column and value; so does a bad
/// `--sigma-delta` on every command that reads measurements, or a bad recipe key.
#[test]
fn bad_slope_uncertainties_exit_2() {
    let dir = tmpdir();
    for cell in ["-1", "NaN", "abc"] {
        let p = write(
            &dir,
            "d.csv",
            &format!("series,xi,delta_deg,v,sigma_delta_deg\na,1,12,0.3,{cell}\n"),
        );
        for cmd in [
            &["klaw", "--model", "stick"][..],
            &["k", "--model", "stick"],
        ] {
            let mut args = cmd.to_vec();
            args.push(s(&p));
            let out = fb(&args);
            let want = format!("line 2, column 'sigma_delta_deg', value '{cell}'");
            expect(&out, 2, &["d.csv", &want], cell);
        }
    }
    let data = crate::common::root().join("data/default.csv");
    for cmd in [
        &["klaw", "--model", "stick"][..],
        &["jan"],
        &["jaeger"],
        &["k", "--model", "stick"],
        &["report"],
    ] {
        let mut args = cmd.to_vec();
        args.extend([s(&data), "--sigma-delta=-1"]);
        let out = fb(&args);
        expect(&out, 2, &["flag '--sigma-delta', value '-1'"], cmd[0]);
    }
    let recipe = write(
        &dir,
        "r.toml",
        &format!("input = \"{}\"\nsigma_delta = -2\n", s(&data)),
    );
    let out = fb(&["report", "--recipe", s(&recipe)]);
    expect(&out, 2, &["r.toml, line 2, column 'sigma_delta'"], "recipe");
}

/// `--sigma-delta 0` changes nothing; `simulate --sigma-delta` adds its two columns, which
/// the fits read without a word about unknown columns.
#[test]
fn slope_uncertainty_flags_round_trip() {
    let dir = tmpdir();
    let data = crate::common::root().join("data/default.csv");
    let plain = fb(&["klaw", "--model", "stick", s(&data)]);
    let zero = fb(&["klaw", "--model", "stick", s(&data), "--sigma-delta", "0"]);
    assert_eq!((plain.stdout, plain.stderr), (zero.stdout, zero.stderr));
    let sim = |extra: &[&str]| {
        let mut args = vec!["simulate", "--model", "stick", "--seed", "7"];
        args.extend(extra);
        let out = fb(&args);
        assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
        String::from_utf8(out.stdout).unwrap()
    };
    assert_eq!(sim(&["--sigma-delta", "0"]), sim(&[]));
    let noisy = sim(&["--sigma-delta", "0.01"]);
    assert!(
        noisy.starts_with("series,xi,delta_deg,v,sigma_v,v_true,sigma_delta_deg,delta_true_deg\n")
    );
    let p = write(&dir, "noisy.csv", &noisy);
    let out = fb(&["klaw", "--model", "stick", s(&p)]);
    let e = stderr(&out);
    assert_eq!(out.status.code(), Some(0), "{e}");
    assert!(!e.contains("not one fitbead reads"), "{e}");
    expect(
        &fb(&["simulate", "--sigma-delta", "90"]),
        2,
        &["flag '--sigma-delta', value '90'"],
        "simulate",
    );
}
