//! Running a command as shards and comparing the merged output with the whole run's
//! (issue #15): shared by `tests/shards.rs` (verify, converge) and `tests/run_shards.rs`
//! (run).

use super::{all_files, json, stderr_of, stdout_of};
use std::path::{Path, PathBuf};
use std::process::{Output, Stdio};

/// Runs `args` with `--shard i/n -o <root>/<i>` for i = 1 … n concurrently, each in a
/// process of its own; asserts that each exits 0, writes its manifest and prints its
/// closing line (`shard i/n: …`). Returns the shard directories in shard order.
pub fn shards_of(root: &Path, n: usize, args: &[String]) -> Vec<PathBuf> {
    let children: Vec<_> = (1..=n)
        .map(|i| {
            let out = root.join(i.to_string());
            let shard = format!("{i}/{n}");
            let child = super::command()
                .args(args)
                .args(["--shard", &shard, "-o"])
                .arg(&out)
                .stdout(Stdio::piped())
                .stderr(Stdio::piped())
                .spawn()
                .expect("start a shard");
            (shard, out, child)
        })
        .collect();
    children
        .into_iter()
        .map(|(shard, out, child)| {
            let o = child.wait_with_output().expect("run a shard");
            assert_eq!(o.status.code(), Some(0), "shard {shard}: {}", stderr_of(&o));
            assert!(
                out.join("shard.json").is_file(),
                "shard {shard}: no manifest"
            );
            assert!(
                stdout_of(&o).starts_with(&format!("shard {shard}: ")),
                "shard {shard}'s closing line: {}",
                stdout_of(&o)
            );
            out
        })
        .collect()
}

/// `merge -q` of `dirs` into `out`, from the crate root; asserts that it did not panic.
pub fn merge<P: AsRef<Path>>(dirs: &[P], out: &Path) -> Output {
    let mut args = vec!["merge".to_string(), "-q".to_string()];
    args.extend(dirs.iter().map(|d| d.as_ref().display().to_string()));
    args.extend(["-o".to_string(), out.display().to_string()]);
    let o = super::command().args(&args).output().expect("run merge");
    let shown: Vec<&str> = args.iter().map(String::as_str).collect();
    super::assert_no_panic(&shown, &o);
    o
}

/// `v` without the object keys `drop`, at any depth.
pub fn without(v: &serde_json::Value, drop: &[&str]) -> serde_json::Value {
    match v {
        serde_json::Value::Object(m) => serde_json::Value::Object(
            m.iter()
                .filter(|(k, _)| !drop.contains(&k.as_str()))
                .map(|(k, v)| (k.clone(), without(v, drop)))
                .collect(),
        ),
        serde_json::Value::Array(a) => {
            serde_json::Value::Array(a.iter().map(|v| without(v, drop)).collect())
        }
        other => other.clone(),
    }
}

/// `html` without its volatile parts: every run id of `ids`, the provenance block and
/// every number of seconds (`6.17 s`: the wall times).
pub fn html_without_volatile(html: &str, ids: &[String]) -> String {
    let mut html = html.to_string();
    for id in ids {
        html = html.replace(id.as_str(), "RUN-ID");
    }
    if let (Some(a), Some(b)) = (
        html.find("<details class=\"provenance\""),
        html.rfind("</details>"),
    ) && b > a
    {
        html = format!("{}PROVENANCE{}", &html[..a], &html[b..]);
    }
    // Every run of digits and dots directly followed by " s" and a non-letter becomes T.
    let chars: Vec<char> = html.chars().collect();
    let mut out = String::with_capacity(html.len());
    let mut i = 0;
    while i < chars.len() {
        if chars[i].is_ascii_digit() {
            let mut j = i;
            while j < chars.len() && (chars[j].is_ascii_digit() || chars[j] == '.') {
                j += 1;
            }
            let seconds = chars.get(j) == Some(&' ')
                && chars.get(j + 1) == Some(&'s')
                && !chars.get(j + 2).is_some_and(|c| c.is_alphanumeric());
            if seconds {
                out.push('T');
            } else {
                out.extend(&chars[i..j]);
            }
            i = j;
        } else {
            out.push(chars[i]);
            i += 1;
        }
    }
    out
}

/// Every run id in the JSON files of `dir`.
fn run_ids(dir: &Path) -> Vec<String> {
    all_files(dir)
        .iter()
        .filter(|f| f.ends_with(".json"))
        .filter_map(|f| json(&dir.join(f))["run_id"].as_str().map(str::to_string))
        .collect()
}

/// Asserts that `merged` holds the outputs of `whole`: the same files, every one
/// byte-identical except JSON files, compared as JSON without the keys `volatile(file)`
/// names, and HTML files, compared without run ids, the provenance block and wall times
/// ([`html_without_volatile`]). Returns the files.
pub fn assert_same_outputs(
    whole: &Path,
    merged: &Path,
    volatile: impl Fn(&str) -> &'static [&'static str],
) -> Vec<String> {
    let files = all_files(whole);
    assert_eq!(files, all_files(merged), "different files");
    let (ids_a, ids_b) = (run_ids(whole), run_ids(merged));
    let html =
        |p: &Path, ids: &[String]| html_without_volatile(&std::fs::read_to_string(p).unwrap(), ids);
    for f in &files {
        let (a, b) = (whole.join(f), merged.join(f));
        if f.ends_with(".json") {
            assert_eq!(
                without(&json(&a), volatile(f)),
                without(&json(&b), volatile(f)),
                "{f} differs beyond wall times, run id and provenance"
            );
        } else if f.ends_with(".html") {
            assert_eq!(
                html(&a, &ids_a),
                html(&b, &ids_b),
                "{f} differs beyond wall times, run id and provenance"
            );
        } else {
            assert!(
                std::fs::read(&a).unwrap() == std::fs::read(&b).unwrap(),
                "{f} differs between the whole run and the merged shards"
            );
        }
    }
    files
}
