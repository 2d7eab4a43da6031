//! The library's layers run one way: each top-level module of `src/` may use only the modules
//! below it in [`LAYERS`], read off its `crate::…` paths (test modules aside). A new module
//! gets a row; a use that runs upwards fails here with the file and line.

use std::path::Path;

/// Bottom to top. The simulator sits below the model files (it integrates any
/// `sim::RightHandSide`), the regression back-ends below both; the ship plug-in and the registry of plug-ins are
/// near the top, and the recipe (which checks its starts by whatever plug-in a model has) on top.
const LAYERS: &[&str] = &[
    "linalg",
    "contain",
    "budget",
    "output",
    "term",
    "data",
    "select",
    "sim",
    "model",
    "uncertainty",
    "identify",
    "diagnose",
    "plot",
    "plugin",
    "ship",
    "plugins",
    "recipe",
];

/// Every `.rs` file under `dir`.
fn sources(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// (line number, module) of each `crate::module` path in the file's code outside its test
/// module and comments.
fn uses(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let code = line.split("//").next().unwrap_or("");
        if line.trim_start().starts_with("#[cfg(test)]") {
            // test modules stand at the end of a file by the style rule (clippy checks it)
            break;
        }
        let mut rest = code;
        while let Some(k) = rest.find("crate::") {
            let after = &rest[k + "crate::".len()..];
            let name: String = after.chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect();
            if !name.is_empty() {
                out.push((i + 1, name));
            }
            rest = after;
        }
    }
    out
}

#[test]
fn modules_use_only_the_layers_below_them() {
    let mut files = Vec::new();
    sources(Path::new("src"), &mut files);
    let mut violations = Vec::new();
    let mut seen = std::collections::BTreeSet::new();
    for file in &files {
        let relative = file.strip_prefix("src").unwrap();
        let top = relative.iter().next().unwrap().to_string_lossy().trim_end_matches(".rs").to_string();
        if top == "bin" || top == "lib" {
            continue;
        }
        seen.insert(top.clone());
        let Some(level) = LAYERS.iter().position(|l| *l == top) else {
            violations.push(format!("src/{top}: not in the layer table of tests/integration/layers.rs"));
            continue;
        };
        let text = std::fs::read_to_string(file).unwrap();
        for (line, used) in uses(&text) {
            if used == top {
                continue;
            }
            match LAYERS.iter().position(|l| *l == used) {
                Some(u) if u < level => {}
                _ => violations
                    .push(format!("{}:{line}: `{top}` uses `{used}`, which is not below it", file.display())),
            }
        }
    }
    assert!(violations.is_empty(), "layer violations:\n{}", violations.join("\n"));
    // every layer of the table exists, so the table cannot drift from the tree
    for l in LAYERS {
        assert!(seen.contains(*l), "`{l}` is in the layer table but not in src/");
    }
}

#[test]
fn the_checker_sees_uses() {
    let text = "use crate::model::Model;\nlet x = crate::sim::simulate(); // crate::ship in a comment\n#[cfg(test)]\nmod tests { use crate::ship; }\n";
    assert_eq!(uses(text), [(1, "model".to_string()), (2, "sim".to_string())]);
}
