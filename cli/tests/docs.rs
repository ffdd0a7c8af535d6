//! The documentation's command lines exist: every `lagrange SUBCOMMAND --flag` shown in the README
//! and in `docs/*.md` (in code blocks and inline code) names a subcommand and flags that the
//! binary's `--help` lists. (`.ci/run` also runs the README's tour as written.)

mod run;

use run::{lagrange, root};
use std::collections::{BTreeMap, BTreeSet};

/// The code of a markdown file: fenced blocks line by line, and inline `code` spans.
fn code_snippets(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut fenced = false;
    for (i, line) in text.lines().enumerate() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced {
            out.push((i + 1, line.to_string()));
        } else {
            out.extend(line.split('`').skip(1).step_by(2).map(|s| (i + 1, s.to_string())));
        }
    }
    out
}

/// `(subcommand, flags)` of each command line in `snippet`: after `lagrange ` or
/// `cargo run --release -- `, up to a shell pipe, `;`, `&&`, `#` or `>`.
fn commands(snippet: &str) -> Vec<(String, Vec<String>)> {
    let mut out = Vec::new();
    for part in snippet.split(['|', ';', '#', '>']).flat_map(|p| p.split("&&")) {
        let words: Vec<&str> = part.split_whitespace().collect();
        let start = words.iter().enumerate().find_map(|(i, w)| {
            let after_lagrange = (*w == "lagrange" || w.ends_with("/lagrange")) && i + 1 < words.len();
            // `cargo run --release -- SUB`, not another package's binary (`-p lagrange-fuzz`).
            let after_cargo = *w == "--" && words[..i].contains(&"run") && !words[..i].contains(&"-p");
            (after_lagrange || after_cargo).then_some(i + 1)
        });
        let Some(start) = start else { continue };
        let Some(sub) = words.get(start) else { continue };
        if !sub.chars().all(|c| c.is_ascii_lowercase()) || sub.is_empty() {
            continue;
        }
        let flags = words[start + 1..]
            .iter()
            .map(|w| w.trim_start_matches(['[', '(']))
            .filter(|w| w.starts_with("--") && w.len() > 2)
            .map(|w| w.split(['=', '[', ']', ',', ')', '`']).next().unwrap_or(w).to_string())
            .filter(|w| w.len() > 2)
            .collect();
        out.push((sub.to_string(), flags));
    }
    out
}

/// The long flags `lagrange [SUB] --help` lists.
fn help_flags(sub: Option<&str>) -> Option<BTreeSet<String>> {
    let args: Vec<&str> = sub.into_iter().chain(["--help"]).collect();
    let (ok, out, _) = lagrange(&args);
    ok.then(|| {
        out.split(|c: char| c.is_whitespace() || c == ',')
            .filter(|w| w.starts_with("--") && w.len() > 2)
            .map(|w| w.trim_end_matches(|c: char| !c.is_ascii_alphanumeric()).to_string())
            .collect()
    })
}

#[test]
fn every_command_and_flag_in_the_docs_exists() {
    let root = root();
    let mut files = vec![root.join("README.md")];
    let mut docs: Vec<_> = std::fs::read_dir(root.join("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    docs.sort();
    files.extend(docs);
    let global = help_flags(None).expect("lagrange --help");
    let mut known: BTreeMap<String, Option<BTreeSet<String>>> = BTreeMap::new();
    let (mut checked, mut problems) = (0, Vec::new());
    for file in &files {
        let text = std::fs::read_to_string(file).unwrap();
        let name = file.strip_prefix(&root).unwrap().display().to_string();
        for (line, snippet) in code_snippets(&text) {
            for (sub, flags) in commands(&snippet) {
                let help = known.entry(sub.clone()).or_insert_with(|| help_flags(Some(&sub)));
                let Some(help) = help else {
                    problems.push(format!("{name}:{line}: `lagrange {sub}` is not a command ({snippet})"));
                    continue;
                };
                checked += 1;
                for flag in flags {
                    if !help.contains(&flag) && !global.contains(&flag) {
                        problems.push(format!("{name}:{line}: `lagrange {sub}` has no {flag} ({snippet})"));
                    }
                }
            }
        }
    }
    println!("{checked} command lines checked in {} files", files.len());
    assert!(checked > 20, "only {checked} command lines found: the parser lost them");
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}
