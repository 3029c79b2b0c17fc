//! The docs keep their word (a test of the CLI, compiled only into `cargo test`): every
//! `sunlit …` line in a `sh` fence of README.md, docs/*.md and www/npm-readme.md parses with the
//! CLI's own parser, and every relative link there (with its `#anchor`) resolves. The conventions
//! (what counts as a command, `[optional]` parts, `…`) are written down in docs/layout.md.

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use clap::Parser;
use clap::error::ErrorKind;

use super::Cli;

/// The Markdown files the check covers, from the crate's root.
fn doc_files() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut docs: Vec<PathBuf> = std::fs::read_dir(root.join("docs"))
        .map(|dir| dir.filter_map(|e| e.ok().map(|e| e.path())).filter(|p| p.extension().is_some_and(|x| x == "md")).collect())
        .unwrap_or_default();
    docs.sort();
    [root.join("README.md"), root.join("www/npm-readme.md")].into_iter().chain(docs).collect()
}

/// One line of a file: 1-based number, text, and the info string of the fence it is in (None
/// outside fences).
struct Line<'a> {
    number: usize,
    text: &'a str,
    fence: Option<&'a str>,
}

/// Splits a Markdown text into its lines, each marked with the fence it lies in; fence lines
/// themselves are left out.
fn lines(text: &str) -> Vec<Line<'_>> {
    let mut fence: Option<&str> = None;
    let mut out = vec![];
    for (i, text) in text.lines().enumerate() {
        let trimmed = text.trim_start();
        if let Some(info) = trimmed.strip_prefix("```") {
            fence = if fence.is_some() { None } else { Some(info.trim()) };
            continue;
        }
        out.push(Line { number: i + 1, text, fence });
    }
    out
}

/// A shell word: its text without quotes, and whether an unquoted `[` opened it or an unquoted
/// `]` closed it (an optional part of a command shown).
#[derive(Debug, Clone, PartialEq)]
struct Word {
    text: String,
    opens: bool,
    closes: bool,
}

/// Shell words of one command line up to a comment, a pipe, a redirection (`>`, `2>`, `<`) or a
/// `&&`/`;`.
fn words(line: &str) -> Vec<Word> {
    let mut out: Vec<Word> = vec![];
    let mut chars = line.chars().peekable();
    loop {
        while chars.next_if(|c| c.is_whitespace()).is_some() {}
        let Some(&first) = chars.peek() else { break };
        let rest: String = chars.clone().take(2).collect();
        if matches!(first, '#' | '|' | '>' | '<' | ';' | '&') || (first.is_ascii_digit() && rest.ends_with('>')) {
            break;
        }
        let mut word = Word { text: String::new(), opens: false, closes: false };
        if first == '[' {
            word.opens = true;
            chars.next();
        }
        let mut quoted_end = false;
        while let Some(&c) = chars.peek() {
            if c.is_whitespace() {
                break;
            }
            chars.next();
            quoted_end = false;
            match c {
                '\'' | '"' => {
                    for q in chars.by_ref() {
                        if q == c {
                            break;
                        }
                        word.text.push(q);
                    }
                    quoted_end = true;
                }
                '\\' => word.text.extend(chars.next()),
                _ => word.text.push(c),
            }
        }
        if !quoted_end && word.text.ends_with(']') {
            word.text.pop();
            word.closes = true;
        }
        out.push(word);
    }
    out
}

/// A placeholder: a word in capitals (N, MODEL, FILE.csv is not one) or a `$VARIABLE`.
fn is_placeholder(word: &str) -> bool {
    word.starts_with('$')
        || (word.chars().any(|c| c.is_ascii_uppercase()) && word.chars().all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || c == '_'))
}

/// The argument lists a command line stands for: with every `[optional]` part and with none.
/// A word `…` (or `...`) stands for "more options" and is left out; a placeholder given as an
/// option's value becomes `1`, which every option's type accepts as text.
fn variants(words: &[Word]) -> [Vec<String>; 2] {
    let (mut all, mut required) = (vec![], vec![]);
    let mut depth = 0usize;
    let mut previous = "";
    for w in words {
        if w.opens {
            depth += 1;
        }
        if w.text != "…" && w.text != "..." && !w.text.is_empty() {
            let text = if previous.starts_with('-') && is_placeholder(&w.text) { "1".to_string() } else { w.text.clone() };
            all.push(text.clone());
            if depth == 0 {
                required.push(text);
            }
            previous = &w.text;
        }
        if w.closes {
            depth = depth.saturating_sub(1);
        }
    }
    [all, required]
}

/// Every `sunlit …` command shown: in `sh` fences (continuations joined), and in inline code spans
/// of prose (a span may wrap lines) unless the span holds `…`, which marks an excerpt. With the
/// line number where each starts.
fn commands(text: &str) -> Vec<(usize, String)> {
    let mut out = fenced_commands(text);
    out.extend(inline_commands(text));
    out
}

/// The inline code spans of prose that are `sunlit` command lines (three words or more, no `…`),
/// with their line numbers.
fn inline_commands(text: &str) -> Vec<(usize, String)> {
    let mut out = vec![];
    let mut paragraph: Vec<(usize, &str)> = vec![];
    let mut flush = |paragraph: &mut Vec<(usize, &str)>| {
        let joined: String = paragraph.iter().map(|(_, l)| format!("{l}\n")).collect();
        let starts: Vec<usize> = paragraph
            .iter()
            .scan(0, |at, (_, l)| {
                let start = *at;
                *at += l.len() + 1;
                Some(start)
            })
            .collect();
        let mut at = 0;
        for (i, piece) in joined.split('`').enumerate() {
            let span = piece.split_whitespace().collect::<Vec<_>>().join(" ");
            // `sunlit annual` alone names a command; three words or more are a command line.
            if i % 2 == 1 && span.starts_with("sunlit ") && !span.contains('…') && span.split(' ').count() >= 3 {
                let line = starts.iter().rposition(|&s| s <= at).map_or(0, |k| paragraph[k].0);
                out.push((line, span));
            }
            at += piece.len() + 1;
        }
        paragraph.clear();
    };
    for line in lines(text) {
        if line.fence.is_some() || line.text.trim().is_empty() {
            flush(&mut paragraph);
        } else {
            paragraph.push((line.number, line.text));
        }
    }
    flush(&mut paragraph);
    out
}

/// Every `sunlit …` line in `sh` fences, continuations joined.
fn fenced_commands(text: &str) -> Vec<(usize, String)> {
    let mut out = vec![];
    let mut pending: Option<(usize, String)> = None;
    for line in lines(text).into_iter().filter(|l| matches!(l.fence, Some("sh" | "bash"))) {
        let (number, mut joined) = pending.take().unwrap_or((line.number, String::new()));
        let text = line.text.trim();
        match text.strip_suffix('\\') {
            Some(head) => {
                joined.push_str(head);
                joined.push(' ');
                pending = Some((number, joined));
            }
            None => {
                joined.push_str(text);
                out.extend(as_sunlit(&joined).map(|command| (number, command)));
            }
        }
    }
    out
}

/// A shell line as a `sunlit` command, if it runs one: `sunlit …`, `target/release/sunlit …` or
/// `cargo run --release -- …` (not an example's), after any `NAME=value` words.
fn as_sunlit(line: &str) -> Option<String> {
    let mut rest = line.trim();
    while let Some((word, after)) = rest.split_once(' ') {
        if !word.contains('=') || word.starts_with('-') {
            break;
        }
        rest = after.trim_start();
    }
    let (program, args) = rest.split_once(' ').unwrap_or((rest, ""));
    if program == "sunlit" || program.ends_with("/sunlit") {
        return Some(format!("sunlit {args}").trim_end().to_string());
    }
    let (cargo, args) = rest.strip_prefix("cargo run")?.split_once(" -- ")?;
    (!cargo.contains("--example")).then(|| format!("sunlit {}", args.trim()))
}

/// What clap says about one argument list; None when it parses (help and version count).
fn parse_error(args: &[String]) -> Option<String> {
    match Cli::try_parse_from(args) {
        Ok(_) => None,
        Err(e) if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) => None,
        Err(e) => Some(e.render().to_string()),
    }
}

/// Command problems of one file, as `file:line: …` texts.
fn command_problems(file: &Path, text: &str) -> Vec<String> {
    let mut problems = vec![];
    for (number, command) in commands(text) {
        let [all, required] = variants(&words(&command));
        let distinct = if all == required { vec![all] } else { vec![all, required] };
        for args in distinct {
            if let Some(error) = parse_error(&args) {
                let first = error.lines().next().unwrap_or_default().to_string();
                problems.push(format!("{}:{number}: `{}` does not parse: {first}", file.display(), args.join(" ")));
            }
        }
    }
    problems
}

/// GitHub's anchor for a heading: lower case, letters, digits, `-` and `_` kept, spaces to `-`,
/// everything else dropped.
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            '-' | '_' => Some(c),
            c if c.is_alphanumeric() => Some(c),
            _ => None,
        })
        .collect()
}

/// The anchors a Markdown text's headings give (repeats numbered `-1`, `-2`, … as GitHub does).
fn anchors(text: &str) -> HashSet<String> {
    let mut seen = HashSet::new();
    for line in lines(text).into_iter().filter(|l| l.fence.is_none()) {
        let hashes = line.text.chars().take_while(|&c| c == '#').count();
        let Some(heading) = line.text.get(hashes..).and_then(|h| h.strip_prefix(' ')) else { continue };
        if !(1..=6).contains(&hashes) {
            continue;
        }
        let base = slug(heading.trim_end_matches('#'));
        let mut anchor = base.clone();
        let mut n = 0;
        while seen.contains(&anchor) {
            n += 1;
            anchor = format!("{base}-{n}");
        }
        seen.insert(anchor);
    }
    seen
}

/// A line with its inline code spans removed (a `](` inside backticks is not a link).
fn without_code_spans(line: &str) -> String {
    line.split('`').step_by(2).collect::<Vec<_>>().join(" ")
}

/// The targets of the inline links (and images) of a text outside fences, with line numbers.
fn links(text: &str) -> Vec<(usize, String)> {
    let mut out = vec![];
    for line in lines(text).into_iter().filter(|l| l.fence.is_none()) {
        let prose = without_code_spans(line.text);
        for (at, _) in prose.match_indices("](") {
            let rest = &prose[at + 2..];
            let Some(end) = rest.find(')') else { continue };
            let target = rest[..end].split_whitespace().next().unwrap_or_default();
            out.push((line.number, target.trim_matches(['<', '>']).to_string()));
        }
    }
    out
}

/// Link problems of one file: a relative path that does not exist, or an anchor that no heading
/// of its Markdown file gives.
fn link_problems(file: &Path, text: &str) -> Vec<String> {
    let dir = file.parent().unwrap_or(Path::new("."));
    let mut problems = vec![];
    for (number, target) in links(text) {
        if target.contains("://") || target.starts_with("mailto:") || target.is_empty() {
            continue;
        }
        let (path, anchor) = target.split_once('#').map_or((target.as_str(), None), |(p, a)| (p, Some(a)));
        let resolved = if path.is_empty() { file.to_path_buf() } else { dir.join(path) };
        let problem = if !resolved.exists() {
            Some(format!("{} does not exist", resolved.display()))
        } else if let Some(anchor) = anchor {
            let headings = std::fs::read_to_string(&resolved).map(|t| anchors(&t)).unwrap_or_default();
            (!headings.contains(anchor)).then(|| format!("no heading of {} gives #{anchor}", resolved.display()))
        } else {
            None
        };
        if let Some(problem) = problem {
            problems.push(format!("{}:{number}: link ({target}): {problem}", file.display()));
        }
    }
    problems
}

#[test]
fn every_command_in_the_docs_parses_and_every_link_resolves() {
    let files = doc_files();
    assert!(files.len() >= 3, "README.md, www/npm-readme.md and docs/*.md: found {files:?}");
    let mut problems = vec![];
    let mut checked = 0;
    for file in &files {
        let text = std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        checked += commands(&text).len();
        problems.extend(command_problems(file, &text));
        problems.extend(link_problems(file, &text));
    }
    assert!(checked >= 10, "only {checked} `sunlit` commands found in sh fences: is the fence convention still docs/layout.md's?");
    assert!(problems.is_empty(), "{} problems in the docs:\n{}", problems.len(), problems.join("\n"));
}

#[test]
fn the_check_itself_catches_what_it_should() {
    // Optional parts, quotes and comments; a continuation joins lines.
    let text = "```sh\nsunlit fraction M.glb --sun 200,35 [--json] 2>/dev/null | head  # one sun\nsunlit annual M.glb \\\n  --location 1,2,3 -o o.csv [--refine 0.3] …\nsunlit sweep v.jsonl -o d --slurm [--sbatch \"--partition=cpu --time=2:00:00\"]\n```\n```text\nsunlit nonsense\n```\n";
    assert_eq!(commands(text).len(), 3);
    for line in ["RUST_LOG=info sunlit info M.glb", "target/release/sunlit info M.glb", "cargo run --release -- info M.glb"] {
        assert_eq!(as_sunlit(line).as_deref(), Some("sunlit info M.glb"), "{line}");
    }
    assert_eq!(as_sunlit("npm start"), None);
    assert_eq!(as_sunlit("cargo run --example soak -- 200 64"), None);
    // Inline: a command line is checked (also wrapped), an excerpt (…) or a bare command name not.
    let prose = "Run `sunlit fraction M.glb\n --sun 1,2` or `sunlit annual … -o o.csv` with `sunlit info`.";
    assert_eq!(commands(prose), vec![(1, "sunlit fraction M.glb --sun 1,2".to_string())]);
    assert!(!command_problems(Path::new("t.md"), "a\n\nsee `sunlit bench --lst` there").is_empty());
    // Placeholders in capitals stand for an option's value.
    assert!(command_problems(Path::new("t.md"), "`sunlit bench MODEL --views N --check N --engine-profile FILE`").is_empty());
    assert!(command_problems(Path::new("t.md"), text).is_empty(), "{:?}", command_problems(Path::new("t.md"), text));
    let [all, required] = variants(&words("sunlit fraction M.glb --sun 1,2 [--json] [--resolution 64]"));
    assert_eq!(all.len(), 8);
    assert_eq!(required.len(), 5);
    // A misspelt option, a value where a number goes, a missing required option: each is caught.
    for bad in [
        "sunlit fraction M.glb --sun 1,2 --jsn",
        "sunlit annual M.glb -o o.csv [--refine lots]",
        "sunlit fraction M.glb",
        "sunlit anual M.glb",
    ] {
        assert!(!command_problems(Path::new("t.md"), &format!("```sh\n{bad}\n```\n")).is_empty(), "{bad}");
    }
    // Links: a missing file, a missing anchor; a good anchor and code spans pass.
    let here = Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md");
    assert_eq!(link_problems(&here, "[a](docs/nope.md) [b](docs/design.md#nope) [c](#nope)").len(), 3);
    assert!(link_problems(&here, "[a](docs/design.md#culling) `[x](nope)` [w](https://example.org/x)").is_empty());
    assert_eq!(slug("Hybrid engine (`--engine auto|gpu|exact`)"), "hybrid-engine---engine-autogpuexact");
}

/// The lines of a text's first fence tagged `tag`.
fn first_fence<'a>(text: &'a str, tag: &str) -> Vec<&'a str> {
    let mut inside = false;
    let mut out = vec![];
    for line in text.lines() {
        match (line.trim_start().strip_prefix("```"), inside) {
            (Some(info), false) if info.trim() == tag => inside = true,
            (Some(_), true) => break,
            (None, true) => out.push(line),
            _ => {}
        }
    }
    out
}

#[test]
fn the_readme_quick_start_is_the_npm_readme_example_the_browser_test_runs() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let read = |file: &str| std::fs::read_to_string(root.join(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
    let (readme, npm) = (read("README.md"), read("www/npm-readme.md"));
    let example = first_fence(&npm, "js");
    assert!(example.iter().any(|l| l.contains("fromThree")), "www/npm-readme.md's first js fence is the three.js example: {example:?}");
    assert_eq!(
        first_fence(&readme, "js"),
        example,
        "README.md's three.js quick start must be www/npm-readme.md's example (tests/browser/npm.test.mjs runs that one)"
    );
}
