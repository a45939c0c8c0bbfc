//! The fits give the same bytes on any number of threads: their parallel loops (the K-law
//! Jacobian, the profile refits, the walkers' log densities, the per-series fits, the
//! diagnostics of each parameter) each write their own slot and combine in a fixed order, so
//! rayon's pool size (`RAYON_NUM_THREADS`) changes only the time.

use std::path::Path;

use crate::common::{bin, root, stderr, tmpdir};

/// The report, statistics and (under MCMC) draws that `args` write on `threads` threads.
fn outputs(dir: &Path, threads: usize, args: &[&str], mcmc: bool) -> Vec<String> {
    let file = |s: &str| dir.join(format!("{threads}_{s}.csv"));
    let mut cmd = bin();
    cmd.env("RAYON_NUM_THREADS", threads.to_string())
        .args(args)
        .arg("--input")
        .arg(root().join("data/default.csv"))
        .arg("--output")
        .arg(file("report"))
        .arg("--output-stats")
        .arg(file("stats"));
    if mcmc {
        cmd.arg("--draws").arg(file("draws"));
    }
    let out = cmd.output().unwrap();
    assert!(
        out.status.success(),
        "{args:?} on {threads} threads: {}",
        stderr(&out)
    );
    let mut files = vec!["report", "stats"];
    if mcmc {
        files.push("draws");
    }
    let mut texts: Vec<String> = files
        .iter()
        .map(|s| std::fs::read_to_string(file(s)).unwrap())
        .collect();
    assert!(
        texts.iter().all(|t| !t.is_empty()),
        "{args:?} on {threads} threads: an empty output file"
    );
    texts.push(String::from_utf8(out.stdout).unwrap());
    texts
}

#[test]
fn fits_are_byte_identical_on_one_and_three_threads() {
    let cases: [(&[&str], bool); 5] = [
        (&["klaw", "--model", "stickslip"], false),
        (&["jaeger"], false),
        // The per-series fits of Jaeger and Jan run side by side.
        (&["jaeger", "--method", "mcmc", "--seed", "3"], true),
        (&["jan", "--method", "mcmc", "--seed", "5"], true),
        (
            &[
                "klaw",
                "--model",
                "stick",
                "--method",
                "mcmc",
                "--seed",
                "7",
                "--min-ess",
                "400",
            ],
            true,
        ),
    ];
    for (args, mcmc) in cases {
        let dir = tmpdir();
        let one = outputs(dir.path(), 1, args, mcmc);
        let three = outputs(dir.path(), 3, args, mcmc);
        for (a, b) in one.iter().zip(&three) {
            assert!(a == b, "{args:?}: 1 and 3 threads differ:\n{a}\n---\n{b}");
        }
    }
}
