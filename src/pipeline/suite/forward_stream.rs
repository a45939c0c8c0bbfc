//! The streaming path against golden outputs (tests/golden/forward/, written by a separate
//! implementation of `forward` that read the whole table, evaluated it, then wrote it): the
//! same bytes on the shipped data and on a table with every kind of cell, for every model
//! but md, at chunk sizes from 1 row to [`CHUNK_ROWS`]; the same message for every kind of
//! bad input.

use crate::io::scenes::TableReader;
use crate::io::stream::{stream, StreamError, StreamOptions, CHUNK_ROWS, TASK_ROWS};
use crate::models::JaegerBranch;
use crate::pipeline::forward::plan::{ForwardPlan, ForwardSettings, ForwardText};

/// The command line's flags as the library's settings: `--model`, `--K`, `--rho`, `--f`,
/// `--spin`, `--tol`, `--lambda`, `--mu`, `--a1`..`--a3`, `--branch` (`--NAME VALUE` or
/// `--NAME=VALUE`), with the command line's defaults.
struct Flags {
    k: String,
    spin: String,
    base: ForwardSettings,
}

fn args(flags: &[&str]) -> Flags {
    let mut pairs: Vec<(String, String)> = Vec::new();
    let mut it = flags.iter();
    while let Some(f) = it.next() {
        let f = f.trim_start_matches("--");
        match f.split_once('=') {
            Some((n, v)) => pairs.push((n.into(), v.into())),
            None => pairs.push((f.into(), it.next().unwrap().to_string())),
        }
    }
    let get = |n: &str| pairs.iter().find(|p| p.0 == n).map(|p| p.1.clone());
    let num = |n: &str| get(n).map(|v| v.parse::<f64>().unwrap());
    Flags {
        k: get("K").unwrap_or_else(|| "adjusted".into()),
        spin: get("spin").unwrap_or_else(|| "roll".into()),
        base: ForwardSettings {
            kind: get("model").unwrap().parse().unwrap(),
            rho: num("rho").unwrap_or(0.4),
            f: num("f").unwrap_or(0.1),
            lambda: num("lambda"),
            mu: num("mu"),
            a: [num("a1"), num("a2"), num("a3")],
            branch: match get("branch").as_deref() {
                Some("lower") => JaegerBranch::Lower,
                _ => JaegerBranch::Upper,
            },
            tol: num("tol").unwrap_or(1e-14),
            ..ForwardSettings::default()
        },
    }
}

fn new(
    a: &Flags,
    text: &[u8],
    (chunk, task): (usize, usize),
    atomic_output: bool,
) -> Result<Vec<u8>, String> {
    let reader = TableReader::new("in.csv", text).map_err(|e| e.to_string())?;
    let mut out = Vec::new();
    let opts = StreamOptions {
        chunk_rows: chunk,
        task_rows: task,
        atomic_output,
        ..StreamOptions::default()
    };
    let t = ForwardText {
        k: &a.k,
        spin: &a.spin,
        base: a.base,
    };
    match stream(
        reader,
        |r| ForwardPlan::from_text(r, &t),
        (),
        &mut out,
        &opts,
    ) {
        Ok(_) => Ok(out),
        Err(StreamError::Input(e)) => Err(e.to_string()),
        Err(e) => panic!("writing to a Vec failed: {e:?}"),
    }
}

const SIZES: [(usize, usize); 4] = [(1, 1), (7, 3), (64, 5), (CHUNK_ROWS, TASK_ROWS)];

/// The streaming output of `text` under `flags` equals `want` at every chunk size, held back
/// by chunks or written as it comes (an atomic output).
fn same(flags: &[&str], text: &[u8], want: &[u8]) {
    let a = args(flags);
    for ((chunk, task), atomic) in SIZES.into_iter().flat_map(|s| [(s, false), (s, true)]) {
        let got = new(&a, text, (chunk, task), atomic)
            .unwrap_or_else(|e| panic!("{flags:?}, chunks of {chunk}: {e}"));
        assert!(
            want == got,
            "{flags:?}, chunks of {chunk}: output differs\nwant:\n{}\ngot:\n{}",
            String::from_utf8_lossy(want),
            String::from_utf8_lossy(&got)
        );
    }
}

/// A golden file under tests/golden/forward/.
macro_rules! golden {
    ($($part:literal),+) => {
        include_bytes!(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/tests/golden/forward/",
            $($part),+
        ))
    };
}

/// Each model's flags and its golden outputs on data/default.csv,
/// data/virtual/md_ristow.csv and tests/golden/forward/generated/input.csv.
macro_rules! models {
    ($(($name:literal, $flags:expr)),* $(,)?) => {
        [$(Golden {
            flags: $flags,
            default: golden!("default/", $name, ".csv"),
            md_ristow: golden!("md_ristow/", $name, ".csv"),
            generated: golden!("generated/", $name, ".csv"),
        }),*]
    };
}

struct Golden {
    flags: &'static [&'static str],
    default: &'static [u8],
    md_ristow: &'static [u8],
    generated: &'static [u8],
}

const MODELS: [Golden; 11] = models![
    ("stick", &["--model", "stick"]),
    (
        "stick_cos2a_rho0.5",
        &["--model", "stick", "--K", "cos2a", "--rho", "0.5"]
    ),
    ("stick-approx", &["--model", "stick-approx"]),
    ("slip", &["--model", "slip"]),
    ("slip-approx", &["--model", "slip-approx"]),
    ("stickslip_f0.3", &["--model", "stickslip", "--f", "0.3"]),
    ("contact_keep", &["--model", "contact", "--spin", "keep"]),
    ("jan", &["--model", "jan"]),
    (
        "jaeger_upper",
        &["--model", "jaeger", "--a1", "0.05", "--a2", "0.4", "--a3", "1.5"]
    ),
    (
        "jaeger_lower",
        &["--model", "jaeger", "--a1", "0.1", "--a2", "2", "--a3", "0.3", "--branch", "lower"]
    ),
    ("auto_tol1e-8", &["--model", "auto", "--tol", "1e-8"]),
];

/// A table with every kind of cell the readers and writers meet: quoted cells (commas,
/// quotes, a newline), non-ASCII text, columns whose names clash with the output (`v`,
/// `regime`, `phase_sequence`), laws by name, empty cells falling back on the flags,
/// padded cells (ASCII and Unicode spaces), blank lines, and scenes in regimes A, B and C
/// with every outcome and phase sequence each model gives on them.
const GENERATED: &[u8] = golden!("generated/input.csv");
/// Rows of [`GENERATED`].
const GENERATED_ROWS: usize = 44;

#[test]
fn same_bytes_as_the_golden_outputs_on_the_shipped_data() {
    for m in &MODELS {
        same(
            m.flags,
            include_bytes!(concat!(env!("CARGO_MANIFEST_DIR"), "/data/default.csv")),
            m.default,
        );
        same(
            m.flags,
            include_bytes!(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/data/virtual/md_ristow.csv"
            )),
            m.md_ristow,
        );
    }
}

#[test]
fn same_bytes_as_the_golden_outputs_on_the_generated_table() {
    for m in &MODELS {
        same(m.flags, GENERATED, m.generated);
    }
    // A single scene on the command line goes through the same path.
    same(
        &["--model", "stick"],
        b"xi,delta_deg\n1,12\n",
        golden!("single_scene.csv"),
    );
}

/// Several full-size chunks and a partial one: the generated table's body repeated, whose
/// output is the golden header and the golden body repeated (every row's output depends on
/// that row alone).
#[test]
fn same_bytes_over_several_full_chunks() {
    let split = |b: &'static [u8]| {
        let i = b.iter().position(|&c| c == b'\n').unwrap() + 1;
        (&b[..i], &b[i..])
    };
    let reps = 3 * CHUNK_ROWS / GENERATED_ROWS + 1;
    let (head, body) = split(GENERATED);
    let text = [head, &body.repeat(reps)].concat();
    let (head, body) = split(MODELS[0].generated);
    let want = [head, &body.repeat(reps)].concat();
    let rows = csv::Reader::from_reader(MODELS[0].generated)
        .records()
        .count();
    assert_eq!(rows, GENERATED_ROWS);
    same(MODELS[0].flags, &text, &want);
}

fn error_cases() -> Vec<(&'static [&'static str], Vec<u8>)> {
    let good = "1,12\n".repeat(40);
    let late_s = |bad: &str| format!("xi,delta_deg\n{good}{bad}{good}");
    let late = |bad: &str| late_s(bad).into_bytes();
    let stick: &[&str] = &["--model", "stick"];
    vec![
        (stick, Vec::new()),
        (stick, " \n\t\n".into()),
        (stick, "xi,delta_deg\n".into()),
        (stick, "xi,delta_deg\n\n\n".into()),
        (stick, "xi,,delta_deg\n1,2,3\n".into()),
        (stick, "xi,xi,delta_deg\n1,2,3\n".into()),
        (stick, "xi,K\n1,0.6\n".into()),
        (stick, "xi,delta_deg\n1,abc\n".into()),
        (stick, "xi,delta_deg\n1,10\n1,NaN\n".into()),
        (stick, "xi,delta_deg\n1,inf\n".into()),
        (stick, "xi,delta_deg\n-1,10\n".into()),
        (stick, "xi,delta_deg\n1,95\n".into()),
        (stick, "xi,delta_deg\n ,10\n".into()),
        (stick, "xi,delta_deg,K\n1,10,smooth\n".into()),
        (stick, "xi,delta_deg,K\n1,10,-0.5\n".into()),
        (stick, "xi,delta_deg,K\n1,10,inf\n".into()),
        (stick, "xi,delta_deg,K\n1,10,c=abc\n".into()),
        (stick, "xi,delta_deg,rho\n1,10,-2\n".into()),
        (stick, "xi,delta_deg,f\n1,10,x\n".into()),
        // Bad rows after the first chunks; the first one is reported.
        (stick, late("1,abc\n")),
        (stick, late("1,10\n0,10\n1,abc\n")),
        // A malformed row anywhere wins over a bad value before it.
        (stick, late("1,10,3\n")),
        (stick, format!("{}1,abc\n{good}1,10,3\n", late_s("")).into()),
        (stick, format!("xi,delta_deg\n1,abc\n{good}\"1,10\n").into()),
        // Invalid UTF-8, the byte index counted in the trimmed cell.
        (stick, b"xi,delta_deg\n1,10\n1,\xff\n".to_vec()),
        (stick, b"xi,delta_deg\n1,10\n1, \t \xc3\xa9\xff \n".to_vec()),
        (stick, b"xi,delta_deg\n\n\n1,10\n\n1,\xc3\n".to_vec()),
        (stick, late("1,\u{e9}\n")),
        (stick, [late(""), b"  \xfe,1\n".to_vec()].concat()),
        (stick, [late("1,abc\n"), b"  \xfe,1\n".to_vec()].concat()),
        // Flag errors come after the table's own errors.
        (&["--model", "stick", "--tol", "2"], "xi,delta_deg\n".into()),
        (&["--model", "stick", "--tol", "2"], late("1,10,3\n")),
        (&["--model", "stick", "--tol", "2"], late("")),
        (&["--model", "stick", "--K", "bogus"], late("")),
        (&["--model", "stick", "--spin", "bogus"], late("")),
        (&["--model", "stick", "--rho=-1"], late("")),
        (&["--model", "jaeger"], late("")),
        (
            &["--model", "jaeger", "--a1", "1", "--a2", "1"],
            "xi,delta_deg,a3\n1,10,1\n1,10,\n".into(),
        ),
        (
            &["--model", "jaeger", "--a1", "1", "--a2", "1", "--a3=-1"],
            late(""),
        ),
        (
            &["--model", "jan"],
            "xi,delta_deg,lambda\n1,10,0.8\n1,10,-1\n".into(),
        ),
        (&["--model", "jan", "--mu=-1"], late("")),
        (
            &["--model", "contact"],
            "xi,delta_deg,spin\n1,10,roll\n1,10,twirl\n".into(),
        ),
        (&["--model", "auto"], late("1,-3\n")),
    ]
}

/// tests/golden/forward/errors.txt: one line per case of [`error_cases`], the message as a
/// Rust string literal (`{:?}`).
#[test]
fn same_error_as_the_golden_messages() {
    let want: Vec<&str> = std::str::from_utf8(golden!("errors.txt"))
        .unwrap()
        .lines()
        .collect();
    let cases = error_cases();
    assert_eq!(want.len(), cases.len());
    for ((flags, bytes), want) in cases.into_iter().zip(want) {
        let a = args(flags);
        let text = String::from_utf8_lossy(&bytes);
        for ((chunk, task), atomic) in SIZES.into_iter().flat_map(|s| [(s, false), (s, true)]) {
            match new(&a, &bytes, (chunk, task), atomic) {
                Ok(_) => panic!("{flags:?} {text:?}, chunks of {chunk}: should fail"),
                Err(e) => assert_eq!(
                    format!("{e:?}"),
                    want,
                    "{flags:?} {text:?}, chunks of {chunk}"
                ),
            }
        }
    }
}
