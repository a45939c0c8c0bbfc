//! `k` streamed in chunks gives the output and the errors of one pass over the whole table, at
//! chunk sizes from 1 row to the engine's default: the same bytes for good input, and for a
//! bad cell or a series that changes ξ after the first chunks, the same message naming the
//! same line (the first ξ of the series kept across chunks).

use crate::io::measurements::MeasurementDefaults;
use crate::io::scenes::TableReader;
use crate::io::stream::{stream, StreamError, StreamOptions, CHUNK_ROWS, TASK_ROWS};
use crate::models::Model;
use crate::pipeline::k::{KLedger, KPlan, KSettings};

const SIZES: [(usize, usize); 4] = [(1, 1), (7, 3), (64, 5), (CHUNK_ROWS, TASK_ROWS)];

/// 300 measured rows of three interleaved series (ξ = 0.8, 1, 2), slopes across regime B and
/// beyond, every tenth row without sigma_v.
fn table() -> String {
    let mut s = String::from("series,xi,delta_deg,v,sigma_v,id\n");
    for i in 0..300 {
        let (label, xi) = [("a", 0.8), ("b", 1.0), ("c", 2.0)][i % 3];
        let d = 5.0 + 0.1 * i as f64;
        let v = 0.05 + 0.003 * i as f64;
        let sigma = if i % 10 == 0 {
            String::new()
        } else {
            format!("{}", 0.02 * v)
        };
        s.push_str(&format!("{label},{xi},{d},{v},{sigma},row{i}\n"));
    }
    s
}

/// Streams `text` through `k --model stick` in chunks of `chunk` rows and tasks of `task`,
/// writing to `out`; the input error's message when there is one.
fn run_into(text: &str, chunk: usize, task: usize, out: &mut Vec<u8>) -> Result<(), String> {
    let reader = TableReader::new("in.csv", text.as_bytes()).map_err(|e| e.to_string())?;
    let opts = StreamOptions {
        chunk_rows: chunk,
        task_rows: task,
        ..StreamOptions::default()
    };
    let settings = KSettings {
        model: Model::Stick,
        auto: None,
        model_name: "stick".into(),
        plot: false,
    };
    let make = |r: &TableReader<&[u8]>| KPlan::new(r, &MeasurementDefaults::default(), settings);
    match stream(reader, make, KLedger::default(), out, &opts) {
        Ok(_) => Ok(()),
        Err(StreamError::Input(e)) => Err(e.to_string()),
        Err(e) => panic!("writing to a Vec failed: {e:?}"),
    }
}

fn run(text: &str, chunk: usize, task: usize) -> Result<Vec<u8>, String> {
    let mut out = Vec::new();
    run_into(text, chunk, task, &mut out).map(|()| out)
}

#[test]
fn the_same_bytes_at_every_chunk_size() {
    let text = table();
    // One chunk and one task: the whole table in one pass.
    let want = run(&text, 10_000, 10_000).unwrap();
    assert_eq!(want.iter().filter(|&&b| b == b'\n').count(), 301);
    for (chunk, task) in SIZES {
        assert!(
            run(&text, chunk, task).unwrap() == want,
            "chunks of {chunk}"
        );
    }
}

#[test]
fn a_bad_cell_after_the_first_chunks_is_reported_with_its_line() {
    let mut lines: Vec<String> = table().lines().map(String::from).collect();
    // Data row 250 is line 252 of the file.
    lines[251] = "b,1,abc,0.3,0.01,bad".into();
    let text = lines.join("\n") + "\n";
    for (chunk, task) in SIZES {
        let e = run(&text, chunk, task).unwrap_err();
        assert!(
            e.contains("line 252") && e.contains("delta_deg") && e.contains("abc"),
            "chunks of {chunk}: {e}"
        );
    }
}

#[test]
fn a_series_that_changes_xi_late_is_caught_across_chunks() {
    let mut lines: Vec<String> = table().lines().map(String::from).collect();
    // Series a starts on line 2 with ξ = 0.8; line 282 gives it ξ = 1.
    lines[281] = "a,1,20,0.5,0.01,late".into();
    let text = lines.join("\n") + "\n";
    for (chunk, task) in SIZES {
        let e = run(&text, chunk, task).unwrap_err();
        assert!(
            e.contains("line 282") && e.contains("mixes xi") && e.contains("on line 2,"),
            "chunks of {chunk}: {e}"
        );
    }
}

/// What reaches the sink (standard output, for `k` without --output) before a bad row's error:
/// nothing when the bad row is in the first chunk; otherwise the header and the rows of the
/// chunks before the bad row's, the good output's first lines.
#[test]
fn a_bad_row_leaves_only_the_chunks_before_it_written() {
    let text = table();
    let want = run(&text, 10_000, 10_000).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    // Data row 250 (0-based) is line 252 of the file.
    lines[251] = "b,1,abc,0.3,0.01,bad".into();
    let bad = lines.join("\n") + "\n";
    for (chunk, task, written_rows) in [(10_000, 10_000, None), (300, 7, None), (64, 5, Some(192))]
    {
        let mut out = Vec::new();
        let r = run_into(&bad, chunk, task, &mut out);
        assert!(r.is_err(), "chunks of {chunk}");
        match written_rows {
            None => assert!(out.is_empty(), "chunks of {chunk}: {} bytes", out.len()),
            Some(n) => {
                assert_eq!(out.iter().filter(|&&b| b == b'\n').count(), 1 + n);
                assert!(want.starts_with(&out), "chunks of {chunk}");
            }
        }
    }
}
