//! The library's layers, held by reading its source: no module imports from a layer above its
//! own (the order `src/lib.rs` documents), a leaf module imports no layer and only the leaves
//! listed before it, and no two files import each other. The command line (the package
//! `crates/fitbead-cli`) is another crate and is not checked.
//!
//! A path counts as an import wherever it appears in code (a `use`, a qualified call, a type in
//! a signature, a test module): `crate::…`, `super::…` (resolved against the file's own module)
//! and grouped forms such as `crate::{a::X, b::Y}`. A name re-exported at the crate's root
//! (`crate::Scene`) counts as the crate's top, not as the layer it comes from. Comments are
//! skipped; string literals too.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The layers, lowest first, as `src/lib.rs` lists them.
const LAYERS: [&str; 10] = [
    "special", "scene", "models", "inverse", "fit", "design", "report", "io", "error", "pipeline",
];
/// Modules every layer may use; each uses only the leaves listed before it.
const LEAVES: [&str; 4] = ["numfmt", "progress", "record", "last"];
/// The crate's top: may use every layer, and no layer may use it.
const TOP: [&str; 2] = ["prelude", ""];

/// One source file and its module path (`["fit", "k", "search"]`; `[]` for `lib.rs`).
struct File {
    path: PathBuf,
    module: Vec<String>,
}

fn files(root: &Path) -> Vec<File> {
    let mut out = Vec::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).expect("src/ readable") {
            let p = entry.expect("directory entry").path();
            if p.is_dir() {
                stack.push(p);
                continue;
            }
            if p.extension().and_then(|e| e.to_str()) != Some("rs") {
                continue;
            }
            let rel = p.strip_prefix(root).unwrap();
            let mut module: Vec<String> = rel
                .with_extension("")
                .components()
                .map(|c| c.as_os_str().to_string_lossy().into_owned())
                .collect();
            if module.last().map(String::as_str) == Some("mod") || module == ["lib"] {
                module.pop();
            }
            out.push(File { path: p, module });
        }
    }
    out.sort_by(|a, b| a.path.cmp(&b.path));
    out
}

/// The source with comments and string/char literals blanked (lengths kept).
fn code_only(src: &str) -> String {
    let b = src.as_bytes();
    let mut out = String::with_capacity(src.len());
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        if c == b'/' && b.get(i + 1) == Some(&b'/') {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
            continue;
        }
        if c == b'/' && b.get(i + 1) == Some(&b'*') {
            let mut depth = 0;
            while i < b.len() {
                if b[i] == b'/' && b.get(i + 1) == Some(&b'*') {
                    depth += 1;
                    i += 2;
                } else if b[i] == b'*' && b.get(i + 1) == Some(&b'/') {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
            out.push(' ');
            continue;
        }
        if c == b'"' {
            // A raw string r"…"/r#"…"# is entered through its quote as well; its body holds no
            // unescaped quote that matters for the paths looked for here.
            let hashes = {
                let mut h = 0;
                let mut j = i;
                while j > 0 && b[j - 1] == b'#' {
                    h += 1;
                    j -= 1;
                }
                if j > 0 && b[j - 1] == b'r' {
                    Some(h)
                } else {
                    None
                }
            };
            i += 1;
            loop {
                if i >= b.len() {
                    break;
                }
                match (hashes, b[i]) {
                    (None, b'\\') => i += 2,
                    (None, b'"') => {
                        i += 1;
                        break;
                    }
                    (Some(h), b'"') if b[i + 1..].iter().take(h).all(|&x| x == b'#') => {
                        i += 1 + h;
                        break;
                    }
                    _ => i += 1,
                }
            }
            out.push_str("\"\"");
            continue;
        }
        if c == b'\'' {
            // A char literal ('x', '\n', '\u{..}') is blanked; a lifetime ('a) is kept.
            let close = b[i + 1..].iter().take(12).position(|&x| x == b'\'');
            let is_char = match close {
                Some(0) => false,
                Some(n) => {
                    b[i + 1] == b'\\' || src[i + 1..].chars().next().map_or(0, char::len_utf8) == n
                }
                None => false,
            };
            if is_char {
                i += close.unwrap() + 2;
                out.push_str("' '");
                continue;
            }
        }
        let ch = src[i..].chars().next().unwrap();
        out.push(ch);
        i += ch.len_utf8();
    }
    out
}

fn is_ident(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

/// Every absolute module path the code names through `crate::` or `super::`, with `{…}`
/// groups expanded one level (enough to know the first segments). `super` resolves against
/// the module the path sits in, inline modules (`mod tests { … }`) included.
fn paths(file: &File, code: &str) -> Vec<Vec<String>> {
    let chars: Vec<char> = code.chars().collect();
    let mut out = Vec::new();
    // Inline modules open at this point: (name, brace depth inside them).
    let mut inline: Vec<(String, usize)> = Vec::new();
    let mut depth = 0usize;
    let mut i = 0;
    while i < chars.len() {
        match chars[i] {
            '{' => {
                depth += 1;
                i += 1;
                continue;
            }
            '}' => {
                if inline.last().is_some_and(|(_, d)| *d == depth) {
                    inline.pop();
                }
                depth = depth.saturating_sub(1);
                i += 1;
                continue;
            }
            _ => {}
        }
        let starts_word = i == 0 || !(is_ident(chars[i - 1]) || chars[i - 1] == ':');
        let word: String = chars[i..].iter().take_while(|c| is_ident(**c)).collect();
        if starts_word && word == "mod" {
            let rest: String = chars[i + 3..].iter().take(200).collect();
            let name: String = rest
                .trim_start()
                .chars()
                .take_while(|c| is_ident(*c))
                .collect();
            let after = rest.trim_start()[name.len()..].trim_start();
            if !name.is_empty() && after.starts_with('{') {
                inline.push((name, depth + 1));
            }
        }
        if !starts_word || (word != "crate" && word != "super") {
            i += word.len().max(1);
            continue;
        }
        // The module this path is written in, and the head it resolves to.
        let mut here = file.module.clone();
        here.extend(inline.iter().map(|(n, _)| n.clone()));
        let mut base: Vec<String> = if word == "crate" {
            Vec::new()
        } else {
            assert!(
                !here.is_empty(),
                "{}: super at the crate root",
                file.path.display()
            );
            here[..here.len() - 1].to_vec()
        };
        let mut j = i + word.len();
        let mut segs: Vec<String> = Vec::new();
        loop {
            if chars.get(j) == Some(&':') && chars.get(j + 1) == Some(&':') {
                j += 2;
            } else {
                break;
            }
            if chars.get(j) == Some(&'{') {
                // A group: each member's leading segments (braces counted for the depth).
                let mut d = 0;
                let mut k = j;
                let mut member = String::new();
                let mut members = Vec::new();
                while k < chars.len() {
                    let c = chars[k];
                    match c {
                        '{' => {
                            d += 1;
                            if d > 1 {
                                member.push(c);
                            }
                        }
                        '}' => {
                            d -= 1;
                            if d == 0 {
                                members.push(std::mem::take(&mut member));
                                break;
                            }
                            member.push(c);
                        }
                        ',' if d == 1 => members.push(std::mem::take(&mut member)),
                        _ => member.push(c),
                    }
                    k += 1;
                }
                for m in members {
                    let first: Vec<String> = m
                        .split("::")
                        .map(|s| s.trim().chars().take_while(|c| is_ident(*c)).collect())
                        .take_while(|s: &String| !s.is_empty())
                        .collect();
                    if !first.is_empty() {
                        let mut p = base.clone();
                        p.extend(segs.iter().cloned());
                        p.extend(first);
                        out.push(p);
                    }
                }
                j = k + 1;
                segs.clear();
                break;
            }
            let seg: String = chars[j..].iter().take_while(|c| is_ident(**c)).collect();
            if seg.is_empty() {
                break;
            }
            j += seg.len();
            if seg == "super" && segs.is_empty() {
                base.pop();
                continue;
            }
            segs.push(seg);
        }
        if !segs.is_empty() {
            let mut p = base;
            p.extend(segs);
            out.push(p);
        }
        i = j.max(i + 1);
    }
    out
}

/// The layer of a module path's first segment.
fn layer(first: &str) -> Option<usize> {
    LAYERS.iter().position(|l| *l == first)
}

/// What the rules say about `from` (a file's module) naming `to` (an absolute path), if wrong.
/// A name at the crate's root (`crate::Scene`, `crate::Error`: a re-export of `src/lib.rs`) is
/// the crate's top, whatever it re-exports.
fn breach(from: &[String], to: &[String]) -> Option<String> {
    let f = from.first().map(String::as_str).unwrap_or("");
    let t = to.first().map(String::as_str).unwrap_or("");
    let t = if t.starts_with(|c: char| c.is_ascii_uppercase()) {
        ""
    } else {
        t
    };
    if f == t {
        return None;
    }
    if let Some(i) = LEAVES.iter().position(|l| *l == f) {
        if LEAVES[..i].contains(&t) {
            return None;
        }
        return Some(format!("leaf module `{f}` uses `{t}`"));
    }
    if TOP.contains(&t) && !TOP.contains(&f) {
        return Some(format!("layer `{f}` uses the crate's top `{t}`"));
    }
    match (layer(f), layer(t)) {
        (Some(a), Some(b)) if b > a => Some(format!("layer `{f}` uses `{t}`, a layer above it")),
        _ => None,
    }
}

/// The file a module path lands in: the longest prefix that names a source file.
fn owner<'a>(by_module: &'a BTreeMap<Vec<String>, PathBuf>, p: &[String]) -> Option<&'a PathBuf> {
    (0..=p.len())
        .rev()
        .find_map(|n| by_module.get(&p[..n].to_vec()))
}

/// The rules' breaches and the pairs of files that import each other, for the tree at `root`.
fn check(root: &Path) -> (Vec<String>, Vec<String>) {
    let files = files(root);
    let by_module: BTreeMap<Vec<String>, PathBuf> = files
        .iter()
        .map(|f| (f.module.clone(), f.path.clone()))
        .collect();
    let mut breaches = BTreeSet::new();
    let mut edges: BTreeMap<PathBuf, BTreeSet<PathBuf>> = BTreeMap::new();
    for f in &files {
        let src = std::fs::read_to_string(&f.path).expect("source readable");
        let code = code_only(&src);
        for p in paths(f, &code) {
            if let Some(why) = breach(&f.module, &p) {
                breaches.insert(format!(
                    "{}: `{}`: {why}",
                    f.path.strip_prefix(root).unwrap().display(),
                    p.join("::")
                ));
            }
            if let Some(target) = owner(&by_module, &p) {
                if *target != f.path {
                    edges
                        .entry(f.path.clone())
                        .or_default()
                        .insert(target.clone());
                }
            }
        }
    }
    let mut cycles = Vec::new();
    for (a, targets) in &edges {
        for b in targets {
            if a < b && edges.get(b).is_some_and(|t| t.contains(a)) {
                cycles.push(format!(
                    "{} and {} import each other",
                    a.strip_prefix(root).unwrap().display(),
                    b.strip_prefix(root).unwrap().display()
                ));
            }
        }
    }
    (breaches.into_iter().collect(), cycles)
}

fn src_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

#[test]
fn no_module_imports_from_a_layer_above_its_own_and_no_two_files_import_each_other() {
    let (breaches, cycles) = check(&src_root());
    assert!(
        breaches.is_empty() && cycles.is_empty(),
        "layer breaches:\n{}\nfiles importing each other:\n{}",
        breaches.join("\n"),
        cycles.join("\n")
    );
    // The check saw the whole library: every layer has files and imports were found.
    let files = files(&src_root());
    for l in LAYERS {
        assert!(
            files
                .iter()
                .any(|f| f.module.first().map(String::as_str) == Some(l)),
            "{l}"
        );
    }
}

/// A copy of `src/` with one file changed, for the planted-breach tests.
fn planted(rel: &str, append: &str) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let root = src_root();
    let mut stack = vec![root.clone()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            let to = dir.path().join(p.strip_prefix(&root).unwrap());
            if p.is_dir() {
                std::fs::create_dir_all(&to).unwrap();
                stack.push(p);
            } else {
                std::fs::copy(&p, &to).unwrap();
            }
        }
    }
    let target = dir.path().join(rel);
    let mut text = std::fs::read_to_string(&target).unwrap();
    text.push_str(append);
    std::fs::write(&target, text).unwrap();
    dir
}

#[test]
fn a_planted_upward_import_is_caught() {
    for (file, line, expect) in [
        (
            "models/stick.rs",
            "\nfn planted() -> Option<crate::fit::data::Dataset> { None }\n",
            "layer `models` uses `fit`",
        ),
        (
            "special/dd.rs",
            "\nuse crate::{scene::Scene, numfmt::fmt_f64};\n",
            "layer `special` uses `scene`",
        ),
        (
            "numfmt.rs",
            "\n#[cfg(test)]\nmod planted { use crate::models::Model; }\n",
            "leaf module `numfmt` uses `models`",
        ),
        (
            "numfmt.rs",
            "\nfn planted() { let _ = crate::record::columns::<()>; }\n",
            "leaf module `numfmt` uses `record`",
        ),
        (
            "fit/k/search.rs",
            "\nfn planted() { let _ = super::super::super::report::REPORT_FILES; }\n",
            "layer `fit` uses `report`",
        ),
        (
            "models/stick.rs",
            "\nfn planted() -> Option<crate::Dataset> { None }\n",
            "layer `models` uses the crate's top ``",
        ),
    ] {
        let dir = planted(file, line);
        let (breaches, _) = check(dir.path());
        assert!(
            breaches.iter().any(|b| b.contains(expect)),
            "{file}: {breaches:?}"
        );
    }
    // Inside comments and strings nothing counts.
    let dir = planted(
        "models/stick.rs",
        "\n// crate::report::X\nconst PLANTED: &str = \"crate::io::Y\";\n",
    );
    assert_eq!(check(dir.path()).0, check(&src_root()).0);
}

#[test]
fn a_planted_mutual_import_is_caught() {
    let dir = planted(
        "models/slip.rs",
        "\n#[allow(dead_code)]\nfn planted() { let _ = super::stick::steady; }\n",
    );
    let stick = std::fs::read_to_string(dir.path().join("models/stick.rs")).unwrap();
    let (_, before) = check(dir.path());
    std::fs::write(
        dir.path().join("models/stick.rs"),
        format!("{stick}\nfn planted() {{ let _ = super::slip::steady; }}\n"),
    )
    .unwrap();
    let (_, after) = check(dir.path());
    let pair = after
        .iter()
        .find(|c| c.contains("slip.rs") && c.contains("stick.rs"));
    assert!(pair.is_some(), "{after:?}");
    assert!(!before
        .iter()
        .any(|c| c.contains("slip.rs") && c.contains("stick.rs")));
}
