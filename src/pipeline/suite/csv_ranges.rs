//! The streaming engine's parallel reading (byte ranges cut at record boundaries, each parsed
//! by its own reader) against the one reader of the whole table ([`Table::parse`]): the same
//! rows, cells and line numbers, the same first error, on inputs of several ranges whose
//! records straddle any boundary — quoted cells holding newlines, commas and quotes, CRLF and
//! lone CR line ends, blank lines, byte order marks inside rows, invalid UTF-8, ragged rows,
//! an unterminated quote — and the same bytes at 1 thread as at several.

use crate::io::scenes::{Row, Table, TableReader};
use crate::io::stream::{stream, RowPlan, StreamError, StreamOptions};
use crate::io::InputError;
use crate::pipeline::forward::plan::{ForwardPlan, ForwardSettings, ForwardText};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Echoes each row: its line number and trimmed cells; a row whose first cell is `bad`
/// fails its check.
struct Echo;

impl RowPlan for Echo {
    type Ready = ();
    type Ledger = ();
    type Note = ();
    type Scratch = ();

    fn header(&self, out: &mut Vec<u8>) {
        out.extend_from_slice(b"line|cells\n");
    }

    fn prepare(&self, row: &Row<'_>, _: &mut ()) -> Result<(), InputError> {
        if row.cell(0) == "bad" {
            return Err(row.err(0, "bad value"));
        }
        Ok(())
    }

    fn write(&self, row: &Row<'_>, _: (), _: &mut (), out: &mut Vec<u8>) {
        echo(row, out);
    }
}

fn echo(row: &Row<'_>, out: &mut Vec<u8>) {
    out.extend_from_slice(row.line.to_string().as_bytes());
    for c in 0..row.rec.len() {
        out.push(b'|');
        out.extend_from_slice(row.cell(c).as_bytes());
    }
    out.push(b'\n');
}

/// What the engine makes of `text` with [`Echo`] on `threads` threads, chunks of `chunk`
/// rows: the output, or the error's message.
fn streamed(text: &[u8], threads: usize, chunk: usize) -> Result<Vec<u8>, String> {
    let (out, err) = streamed_into(text, threads, chunk);
    match err {
        None => Ok(out),
        Some(e) => Err(e),
    }
}

/// The bytes the engine writes for `text` (as [`streamed`]), and the error's message if any.
fn streamed_into(text: &[u8], threads: usize, chunk: usize) -> (Vec<u8>, Option<String>) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let reader = match TableReader::new("in.csv", text) {
            Ok(r) => r,
            Err(e) => return (Vec::new(), Some(e.to_string())),
        };
        let mut out = Vec::new();
        let opts = StreamOptions {
            chunk_rows: chunk,
            task_rows: 37,
            ..StreamOptions::default()
        };
        match stream(reader, |_| Ok(Echo), (), &mut out, &opts) {
            Ok(_) => (out, None),
            Err(StreamError::Input(e)) => (out, Some(e.to_string())),
            Err(e) => panic!("{e:?}"),
        }
    })
}

/// What [`streamed`] should give: the whole table read at once, rows checked in order.
fn reference(text: &[u8]) -> Result<Vec<u8>, String> {
    let t = Table::parse("in.csv", text).map_err(|e| e.to_string())?;
    let mut out = b"line|cells\n".to_vec();
    for i in 0..t.rows.len() {
        let row = t.row(i);
        Echo.prepare(&row, &mut ()).map_err(|e| e.to_string())?;
        echo(&row, &mut out);
    }
    Ok(out)
}

fn check(name: &str, text: &[u8]) {
    let want = reference(text);
    for (threads, chunk) in [(1, 1000), (4, 1000), (4, 7), (3, 100_000)] {
        let got = streamed(text, threads, chunk);
        match (&want, &got) {
            (Ok(w), Ok(g)) if w == g => {}
            (Err(w), Err(g)) if w == g => {}
            _ => panic!(
                "{name}, {threads} threads, chunks of {chunk}:\nwant {}\ngot  {}",
                summary(&want),
                summary(&got)
            ),
        }
    }
}

fn summary(r: &Result<Vec<u8>, String>) -> String {
    match r {
        Ok(b) => format!(
            "{} bytes, {} lines",
            b.len(),
            b.split(|&c| c == b'\n').count()
        ),
        Err(e) => format!("error: {e}"),
    }
}

/// A table of `rows` rows of three columns, about 300 KB (several ranges), whose cells
/// draw on `kinds`.
fn table(seed: u64, rows: usize, kinds: &[&[u8]], end: &[u8]) -> Vec<u8> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut t = b"a,b,c".to_vec();
    t.extend_from_slice(end);
    for i in 0..rows {
        for c in 0..3 {
            if c > 0 {
                t.push(b',');
            }
            if rng.random_range(0..10) == 0 {
                t.extend_from_slice(kinds[rng.random_range(0..kinds.len())]);
            } else {
                t.extend_from_slice(format!("{}.{}", i, rng.random_range(0..1000)).as_bytes());
            }
        }
        t.extend_from_slice(end);
    }
    t
}

const QUOTED: &[&[u8]] = &[
    b"\"x\ny\"",
    b"\"a,b\"",
    b"\"he said \"\"hi\"\"\"",
    b"\"\r\n\"",
    b"\"\n\n\n\"",
    b"\"\"",
    b" \"not quoted\" ",
    b"x\"y",
    b"\"q\"tail",
    b"\"\xc3\xa9\"",
];

#[test]
fn quoted_newlines_straddle_the_ranges() {
    for seed in 0..4 {
        check("quoted, LF", &table(seed, 20_000, QUOTED, b"\n"));
        check("quoted, CRLF", &table(seed, 20_000, QUOTED, b"\r\n"));
    }
}

#[test]
fn line_ends_blank_lines_and_marks() {
    let plain: &[&[u8]] = &[b"", b" ", b"\xef\xbb\xbfbom", b"\xc2\xa0nbsp"];
    check("LF", &table(1, 20_000, plain, b"\n"));
    check("CRLF", &table(2, 20_000, plain, b"\r\n"));
    check("CR", &table(3, 20_000, plain, b"\r"));
    // Blank lines (empty or of spaces) between rows, at the start and at the end.
    let t = table(4, 20_000, plain, b"\n");
    let mut blank = Vec::new();
    for (i, line) in t.split(|&c| c == b'\n').enumerate() {
        blank.extend_from_slice(line);
        blank.extend_from_slice(match i % 5 {
            0 => b"\n\n\n",
            1 => b"\r\n\r\n",
            _ => b"\n",
        });
    }
    check("blank lines", &blank);
    // A byte order mark at the start of every row.
    let marked: Vec<u8> = t
        .split(|&c| c == b'\n')
        .flat_map(|l| [b"\xef\xbb\xbf" as &[u8], l, b"\n"].concat())
        .collect();
    check("marks", &marked);
    // The last row without its line end.
    check("no final newline", t.strip_suffix(b"\n").unwrap());
    check(
        "mark before the header",
        &[b"\xef\xbb\xbf\"a\"" as &[u8], &t[1..]].concat(),
    );
}

/// Replaces row `i` (0-based, after the header) of `t` by `row`.
fn with_row(t: &[u8], i: usize, row: &[u8]) -> Vec<u8> {
    let mut lines: Vec<&[u8]> = t.split(|&c| c == b'\n').collect();
    lines[i + 1] = row;
    lines.join(&b'\n')
}

#[test]
fn errors_keep_their_order() {
    let t = table(5, 20_000, QUOTED, b"\n");
    let plain = table(6, 20_000, &[b"x"], b"\n");
    // A malformed row anywhere comes first, then the first bad value in input order.
    check("ragged late", &with_row(&plain, 19_000, b"1,2"));
    check("ragged early", &with_row(&plain, 3, b"1,2,3,4"));
    check(
        "bad early, ragged late",
        &with_row(&with_row(&plain, 10, b"bad,1,2"), 18_000, b"1"),
    );
    check(
        "bad late",
        &with_row(&with_row(&plain, 17_000, b"bad,1,2"), 19_000, b"bad,3,4"),
    );
    check("bad first", &with_row(&plain, 0, b"bad,1,2"));
    check("utf-8 late", &with_row(&plain, 15_000, b"1,\xff,2"));
    check("utf-8, padded", &with_row(&plain, 15_000, b"1,  a\xc3,2"));
    check(
        "ragged after quoted newlines",
        &with_row(&t, 12_000, b"1,2"),
    );
    check(
        "bad after quoted newlines",
        &with_row(&t, 12_000, b"bad,2,3"),
    );
    check("spaces only", &with_row(&plain, 9_000, b"   "));
    // A quote left open runs to the end of the input.
    check("unterminated", &with_row(&plain, 16_000, b"1,\"open,2"));
    check(
        "unterminated, last row",
        &[&plain[..], b"1,2,\"open\n"].concat(),
    );
    check(
        "unterminated, ragged",
        &[&plain[..], b"1,\"open\n"].concat(),
    );
    // No rows.
    check("header only", b"a,b,c\n");
    check("header without newline", b"a,b,c");
    check("blank rows only", b"a,b,c\n\n\r\n\n");
}

#[test]
fn random_bytes_read_as_by_one_reader() {
    // Short tables of the bytes that steer a CSV reader, at chunk sizes that cut anywhere.
    let alphabet = b"ab,\"\r\n \xef\xbb\xbf";
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for _ in 0..300 {
        let n = rng.random_range(0..400);
        let mut t = b"a,b\n".to_vec();
        for _ in 0..n {
            t.push(alphabet[rng.random_range(0..alphabet.len())]);
        }
        check("random", &t);
    }
    // And a long one (many ranges).
    let mut t = b"a,b\n".to_vec();
    for _ in 0..400_000 {
        t.push(alphabet[rng.random_range(0..alphabet.len() - 3)]);
    }
    check("random, long", &t);
}

/// `forward --model stick` on a table of several chunks and ranges, with quoted ids holding
/// newlines, gives the same bytes at 1 thread as at 4.
#[test]
fn forward_output_the_same_at_one_thread_and_several() {
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    let mut t = b"xi,delta_deg,id\n".to_vec();
    for i in 0..60_000 {
        let xi = rng.random_range(0.5..3.0f64);
        let d = rng.random_range(1.0..30.0f64);
        let id = if i % 101 == 0 {
            format!("\"row\n{i}, \"\"q\"\"\"")
        } else {
            format!("r{i}")
        };
        t.extend_from_slice(format!("{xi},{d},{id}\n").as_bytes());
    }
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let reader = TableReader::new("scenes.csv", &t[..]).unwrap();
            let text = ForwardText {
                k: "adjusted",
                spin: "roll",
                base: ForwardSettings {
                    kind: "stick".parse().unwrap(),
                    ..ForwardSettings::default()
                },
            };
            let opts = StreamOptions {
                chunk_rows: 5_000,
                ..StreamOptions::default()
            };
            let mut out = Vec::new();
            stream(
                reader,
                |r| ForwardPlan::from_text(r, &text),
                (),
                &mut out,
                &opts,
            )
            .unwrap();
            out
        })
    };
    let one = run(1);
    assert!(one.iter().filter(|&&c| c == b'\n').count() > 60_000);
    assert!(one == run(4), "4 threads differ from 1");
    assert!(one == run(3), "3 threads differ from 1");
}

/// What reaches the sink (standard output, for the commands) before an error, at 1, 3 and 4
/// threads, by the rule the engine documents: the header and the rows of the whole chunks
/// before a bad value's chunk; for a malformed row, of the chunks before the one before its
/// chunk (a chunk goes out once the chunk after it has been read whole); nothing when that
/// leaves no chunk. The expected bytes are the first rows of the whole table's output.
#[test]
fn errors_leave_whole_chunks_written_at_any_thread_count() {
    let plain = table(6, 20_000, &[b"x"], b"\n");
    let good = reference(&plain).unwrap();
    // The header and the first `n` rows of the good output.
    let first = |n: usize| -> Vec<u8> {
        let end = good
            .iter()
            .enumerate()
            .filter(|&(_, &b)| b == b'\n')
            .nth(n)
            .map_or(good.len(), |(i, _)| i + 1);
        good[..end].to_vec()
    };
    let chunk = 1000;
    // The rows replaced (row, its replacement), and the rows written before the error.
    type Case<'a> = (&'a [(usize, &'a [u8])], usize);
    let cases: [Case; 8] = [
        (&[(12_345, b"bad,1,2")], 12_000),
        (&[(12_345, b"1,2")], 11_000),
        (&[(12_000, b"1,2")], 11_000),
        (&[(11_999, b"1,2")], 10_000),
        (&[(999, b"bad,1,2")], 0),
        (&[(1_500, b"1,2")], 0),
        // A bad value, then a malformed row in its chunk: the malformed row's rule.
        (&[(7_100, b"bad,1,2"), (7_900, b"1,2")], 6_000),
        // A bad value, then a malformed row two chunks on: the bad value's rule.
        (&[(7_100, b"bad,1,2"), (9_050, b"1")], 7_000),
    ];
    for (rows, written) in cases {
        let mut t = plain.clone();
        for (i, r) in rows {
            t = with_row(&t, *i, r);
        }
        let want = if written == 0 {
            Vec::new()
        } else {
            first(written)
        };
        let message = reference(&t).unwrap_err();
        for threads in [1, 3, 4] {
            let (out, err) = streamed_into(&t, threads, chunk);
            assert_eq!(
                err.as_deref(),
                Some(message.as_str()),
                "{rows:?}, {threads} threads"
            );
            assert!(
                out == want,
                "{rows:?}, {threads} threads: {} lines written, want {}",
                out.iter().filter(|&&b| b == b'\n').count(),
                written + usize::from(written > 0)
            );
        }
    }
}
