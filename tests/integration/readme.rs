//! README and the guide run as written: every ```sh block of README.md and of every page under
//! `docs/`, in the order of each file and read from the file itself (so page and test cannot
//! drift apart), runs with `termid` on PATH in a scratch folder of its page's own that sees the
//! repository's `models/`, `examples/` and `tests/`; each must exit 0 and leave every file or
//! folder it names after `--out`, `--svg` or `--prepared-svg`, and no two commands of a page
//! write the same path (an example does not overwrite another's output). A block that cannot
//! run here says why in an HTML comment on the line before it
//! (`<!-- readme-test: skip: why -->`), visible to whoever reads the source.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The ```sh blocks of README: (line of the fence, text, the reason given to skip it).
fn shell_blocks(readme: &str) -> Vec<(usize, String, Option<String>)> {
    let lines: Vec<&str> = readme.lines().collect();
    let mut out = Vec::new();
    let mut k = 0;
    while k < lines.len() {
        if lines[k].trim_end() == "```sh" {
            let skip = k
                .checked_sub(1)
                .and_then(|p| lines[p].trim().strip_prefix("<!-- readme-test: skip:"))
                .map(|r| r.trim_end_matches("-->").trim().to_string());
            let end = (k + 1..lines.len()).find(|&j| lines[j].trim_end() == "```").expect("a closed block");
            out.push((k + 1, lines[k + 1..end].join("\n"), skip));
            k = end;
        }
        k += 1;
    }
    out
}

/// The paths a block says it writes.
fn written(block: &str) -> Vec<String> {
    let words: Vec<&str> = block.split_whitespace().collect();
    words
        .windows(2)
        .filter(|w| matches!(w[0], "--out" | "--svg" | "--prepared-svg"))
        .map(|w| w[1].to_string())
        .collect()
}

#[test]
fn blocks_are_found_and_skips_give_a_reason() {
    let blocks =
        shell_blocks("text\n<!-- readme-test: skip: needs X -->\n```sh\na --out b.csv\n```\n```sh\nc\n```\n");
    assert_eq!(blocks.len(), 2);
    assert_eq!(blocks[0].2.as_deref(), Some("needs X"));
    assert_eq!(blocks[1], (6, "c".to_string(), None));
    assert_eq!(written("termid simulate -m x --out z.csv --svg f/"), ["z.csv", "f/"]);
}

/// A fresh folder holding the repository's models, examples and test data, where shell
/// blocks run with the built `termid` first on the PATH; removed when dropped.
struct Bench {
    dir: PathBuf,
    path: String,
}

impl Bench {
    fn new(name: &str) -> Bench {
        let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
        let dir = std::env::temp_dir().join(format!("termid-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        for shared in ["models", "examples", "tests"] {
            std::os::unix::fs::symlink(root.join(shared), dir.join(shared)).unwrap();
        }
        let bin = Path::new(env!("CARGO_BIN_EXE_termid")).parent().unwrap().to_path_buf();
        let path = format!("{}:{}", bin.display(), std::env::var("PATH").unwrap_or_default());
        Bench { dir, path }
    }

    /// Runs `block`, and asserts it succeeds and writes what it says it writes; `whence` names
    /// the block in a failure.
    fn run(&self, block: &str, whence: &str) {
        let out = Command::new("bash")
            .args(["-euo", "pipefail", "-c", block])
            .current_dir(&self.dir)
            .env("PATH", &self.path)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{whence}: the block failed\n{block}\n--- stderr:\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
        for file in written(block) {
            assert!(self.dir.join(&file).exists(), "{whence}: `{file}` was not written by\n{block}");
        }
    }
}

impl Drop for Bench {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// README.md and every Markdown page under `docs/`, relative to the repository.
fn pages() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        let mut entries: Vec<PathBuf> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()).collect();
        entries.sort();
        for path in entries {
            if path.is_dir() {
                walk(&path, out);
            } else if path.extension().is_some_and(|e| e == "md") {
                out.push(path);
            }
        }
    }
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut out = vec![root.join("README.md")];
    walk(&root.join("docs"), &mut out);
    out.iter().map(|p| p.strip_prefix(&root).unwrap().to_path_buf()).collect()
}

#[test]
fn every_block_of_readme_and_the_guide_runs_as_written() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let pages = pages();
    assert!(pages.len() >= 20, "the guide lost its pages: {pages:?}");
    let mut ran = 0;
    for page in &pages {
        let text = std::fs::read_to_string(root.join(page)).unwrap();
        let blocks: Vec<_> = shell_blocks(&text).into_iter().filter(|b| b.2.is_none()).collect();
        if blocks.is_empty() {
            continue;
        }
        // each output path written by one command of the page only
        let mut writers: Vec<(String, String)> = Vec::new();
        for (line, block, _) in &blocks {
            for file in written(block) {
                let here = format!("{}:{line}", page.display());
                if let Some((_, first)) = writers.iter().find(|(f, _)| *f == file) {
                    panic!("`{file}` is written by {first} and again by {here}");
                }
                writers.push((file, here));
            }
        }
        let name = page.to_string_lossy().replace(['/', '.'], "-");
        let bench = Bench::new(&name);
        for (line, block, _) in &blocks {
            bench.run(block, &format!("{}:{line}", page.display()));
            ran += 1;
        }
    }
    assert!(ran >= 16, "only {ran} blocks ran");
}

/// Every subcommand's `--help` examples (the `termid …` lines under a line that starts with
/// "Example"), each command's in order, with `\` continuations joined.
fn help_examples(help: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut inside = false;
    let mut pending = String::new();
    for line in help.lines() {
        if line.starts_with("Example") {
            inside = true;
            continue;
        }
        if !inside {
            continue;
        }
        let text = line.trim();
        if !pending.is_empty() {
            pending.push(' ');
            pending.push_str(text.trim_end_matches('\\').trim());
            if !text.ends_with('\\') {
                out.push(std::mem::take(&mut pending));
            }
            continue;
        }
        if !line.starts_with("  termid ") {
            inside = line.starts_with("  ") || line.is_empty() && inside;
            continue;
        }
        if text.ends_with('\\') {
            pending = text.trim_end_matches('\\').trim().to_string();
        } else {
            out.push(text.to_string());
        }
    }
    out
}

#[test]
fn help_examples_are_read_with_their_continuations() {
    let help = "Usage: x\n\nExamples:\n  termid a --x 1\n  termid b \\\n      --y 2\nBack-ends: stepwise\n";
    assert_eq!(help_examples(help), ["termid a --x 1", "termid b --y 2"]);
}

/// Every `--help` example runs as written (each command's in a fresh folder holding the
/// repository's models, examples and test data), and every subcommand has one.
#[test]
fn every_help_example_runs_as_written() {
    // every subcommand `termid --help` lists
    let top = Command::new(env!("CARGO_BIN_EXE_termid")).arg("--help").output().unwrap();
    let top = String::from_utf8_lossy(&top.stdout).into_owned();
    let commands: Vec<&str> = top
        .lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|c| *c != "help")
        .collect();
    assert!(commands.len() >= 10, "{top}");
    for command in commands {
        let help = Command::new(env!("CARGO_BIN_EXE_termid")).args([command, "--help"]).output().unwrap();
        let examples = help_examples(&String::from_utf8_lossy(&help.stdout));
        assert!(!examples.is_empty(), "`termid {command} --help` has no example");
        let bench = Bench::new(&format!("help-{command}"));
        for example in &examples {
            bench.run(example, &format!("`termid {command} --help`"));
        }
    }
}

/// Every relative link of README and the guide names a file or folder of the repository.
#[test]
fn every_link_of_readme_and_the_guide_resolves() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut broken = Vec::new();
    for page in pages() {
        let text = std::fs::read_to_string(root.join(&page)).unwrap();
        for part in text.split("](").skip(1) {
            let link = part.split(')').next().unwrap_or("").split('#').next().unwrap_or("");
            if link.is_empty() || link.contains("://") || link.contains(' ') {
                continue;
            }
            if !root.join(&page).parent().unwrap().join(link).exists() {
                broken.push(format!("{}: {link}", page.display()));
            }
        }
    }
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}
