//! The reference (`docs/reference/`) against the code: every key a model file, dataset file,
//! back-end table or particulars file may hold is read off the library's serde structs (their
//! source, parsed by `syn`) and must be a row of the reference's table for that struct; every
//! row there must be a key the code reads. Every value of the enums those keys take, every
//! back-end, derivative method and manoeuvre has its place too. A key added without
//! documentation, or documentation left behind by a removed key, fails here.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use termid::data::DIFFERENTIATORS;
use termid::select::Backend;
use termid::ship::Manoeuvre;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Which struct each section of the reference documents: (source file, struct, page, heading).
const SECTIONS: &[(&str, &str, &str, &str)] = &[
    ("src/model/file.rs", "ModelFile", "model-file.md", "The tables"),
    ("src/model/file.rs", "Meta", "model-file.md", "`[model]`"),
    ("src/model/file.rs", "SimulationSpec", "model-file.md", "`[simulation]`"),
    ("src/model/file.rs", "StateSpec", "model-file.md", "`[[states]]`"),
    ("src/model/file.rs", "InputSpec", "model-file.md", "`[[inputs]]`"),
    ("src/model/file.rs", "ParameterSpec", "model-file.md", "`[parameters.NAME]`"),
    ("src/model/file.rs", "PriorSpec", "model-file.md", "`prior`"),
    ("src/model/file.rs", "ParameterCovarianceSpec", "model-file.md", "`[parameter_covariance]`"),
    ("src/model/file.rs", "DerivedSpec", "model-file.md", "`[[derived]]`"),
    ("src/model/file.rs", "EquationSpec", "model-file.md", "`[equations.NAME]`"),
    ("src/model/file.rs", "CovarianceSpec", "model-file.md", "`covariance`"),
    ("src/ship/spec.rs", "ShipSpec", "model-file.md", "`[ship]`"),
    ("src/ship/spec.rs", "ShipNames", "model-file.md", "`[ship.names]`"),
    ("src/select/stepwise.rs", "Stepwise", "backends.md", "`stepwise`"),
    ("src/select/efroymson.rs", "Efroymson", "backends.md", "`efroymson`"),
    ("src/select/best_subset.rs", "BestSubset", "backends.md", "`best-subset`"),
    ("src/select/stlsq.rs", "Stlsq", "backends.md", "`stlsq`"),
    ("src/select/sparse/mod.rs", "SparseFit", "backends.md", "`sparse`"),
    ("src/select/sparse/constraints.rs", "Equality", "backends.md", "`equalities`"),
    ("src/data/dataset.rs", "Dataset", "dataset-file.md", "The top level"),
    ("src/data/dataset.rs", "Track", "dataset-file.md", "`[track]`"),
    ("src/data/dataset.rs", "RunSpec", "dataset-file.md", "`[[runs]]`"),
    ("src/ship/particulars.rs", "Particulars", "particulars.md", "Keys"),
];

/// Enums whose values a key takes: (source file, enum, page, heading where each value appears).
const VALUES: &[(&str, &str, &str, &str)] = &[
    ("src/sim/integrator.rs", "Integrator", "model-file.md", "`[simulation]`"),
    ("src/select/stepwise.rs", "StepRule", "backends.md", "`stepwise`"),
    ("src/select/best_subset.rs", "Criterion", "backends.md", "`best-subset`"),
    ("src/select/sparse/mod.rs", "LambdaChoice", "backends.md", "`sparse`"),
    ("src/data/dataset.rs", "Delimiter", "dataset-file.md", "`[[runs]]`"),
];

/// The item `name` (a struct or an enum) of a source file.
fn item(file: &str, name: &str) -> syn::Item {
    let text = std::fs::read_to_string(root().join(file)).unwrap();
    let parsed = syn::parse_file(&text).unwrap_or_else(|e| panic!("{file}: {e}"));
    parsed
        .items
        .into_iter()
        .find(|i| match i {
            syn::Item::Struct(s) => s.ident == name,
            syn::Item::Enum(e) => e.ident == name,
            _ => false,
        })
        .unwrap_or_else(|| panic!("no `{name}` in {file}"))
}

/// The words inside `#[serde(…)]` attributes: (`rename_all`, `rename`, flatten or skip).
fn serde_words(attrs: &[syn::Attribute]) -> (Option<String>, Option<String>, bool) {
    let (mut all, mut one, mut leave) = (None, None, false);
    for attr in attrs.iter().filter(|a| a.path().is_ident("serde")) {
        let _ = attr.parse_nested_meta(|meta| {
            let key = meta.path.get_ident().map(|i| i.to_string()).unwrap_or_default();
            if meta.input.peek(syn::Token![=]) {
                let value: syn::Expr = meta.value()?.parse()?;
                let text = match value {
                    syn::Expr::Lit(syn::ExprLit { lit: syn::Lit::Str(s), .. }) => Some(s.value()),
                    _ => None,
                };
                match key.as_str() {
                    "rename_all" => all = text,
                    "rename" => one = text,
                    _ => {}
                }
            } else if matches!(key.as_str(), "flatten" | "skip" | "skip_deserializing") {
                leave = true;
            }
            Ok(())
        });
    }
    (all, one, leave)
}

/// `name` as serde spells it under `rename_all`.
fn spelled(name: &str, rule: Option<&str>) -> String {
    let snake = {
        let mut out = String::new();
        for (k, c) in name.chars().enumerate() {
            if c.is_uppercase() && k > 0 {
                out.push('_');
            }
            out.extend(c.to_lowercase());
        }
        out
    };
    match rule {
        Some("kebab-case") => snake.replace('_', "-"),
        Some("snake_case") => snake,
        Some("lowercase") => name.to_lowercase(),
        _ => name.to_string(),
    }
}

/// The keys a struct reads (flattened and skipped fields left out).
fn keys(file: &str, name: &str) -> BTreeSet<String> {
    let syn::Item::Struct(s) = item(file, name) else { panic!("`{name}` is not a struct") };
    let (all, _, _) = serde_words(&s.attrs);
    s.fields
        .iter()
        .filter_map(|f| {
            let (_, rename, leave) = serde_words(&f.attrs);
            let ident = f.ident.as_ref()?.to_string();
            (!leave).then(|| rename.unwrap_or_else(|| spelled(&ident, all.as_deref())))
        })
        .collect()
}

/// The values an enum takes in a file.
fn values(file: &str, name: &str) -> Vec<String> {
    let syn::Item::Enum(e) = item(file, name) else { panic!("`{name}` is not an enum") };
    let (all, _, _) = serde_words(&e.attrs);
    e.variants
        .iter()
        .map(|v| {
            let (_, rename, _) = serde_words(&v.attrs);
            rename.unwrap_or_else(|| spelled(&v.ident.to_string(), all.as_deref()))
        })
        .collect()
}

/// The text of a page's section: from the heading `heading` to the next heading.
fn section(page: &str, heading: &str) -> String {
    let path = root().join("docs/reference").join(page);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines =
        text.lines().skip_while(|l| !(l.starts_with('#') && l.trim_start_matches('#').trim() == heading));
    assert!(lines.next().is_some(), "docs/reference/{page} has no heading `{heading}`");
    lines.take_while(|l| !l.starts_with('#')).collect::<Vec<_>>().join("\n")
}

/// The keys a section's tables document: the backticked names in each row's first cell
/// (`[[runs]]` and `[parameters.NAME]` read as `runs` and `parameters`).
fn documented(section: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for row in section.lines().filter(|l| l.starts_with('|')) {
        let first = row.trim_start_matches('|').split('|').next().unwrap_or("");
        if first.trim().chars().all(|c| c == '-' || c == ':') {
            continue;
        }
        for (k, word) in first.split('`').enumerate() {
            if k % 2 == 1 {
                let bare = word.trim_start_matches('[').trim_end_matches(']');
                out.insert(bare.split(['.', ' ', '=']).next().unwrap_or("").to_string());
            }
        }
    }
    out
}

#[test]
fn table_rows_are_read_from_the_first_cell() {
    let rows = "| key | meaning |\n|---|---|\n| `path`, `lambda_ratio` | x |\n| `[[runs]]` | y |\n| `[parameters.NAME]` | z |\nnot | `a` |";
    assert_eq!(
        documented(rows),
        ["lambda_ratio", "parameters", "path", "runs"].map(String::from).into_iter().collect()
    );
    assert_eq!(spelled("LeaveOneRunOut", Some("kebab-case")), "leave-one-run-out");
    assert_eq!(spelled("AdjustedR2", Some("kebab-case")), "adjusted-r2");
}

#[test]
fn every_key_is_documented_and_every_documented_key_exists() {
    let mut problems = Vec::new();
    for (file, name, page, heading) in SECTIONS {
        let (code, docs) = (keys(file, name), documented(&section(page, heading)));
        for key in code.difference(&docs) {
            problems.push(format!("`{key}` ({name}, {file}) is not in docs/reference/{page} § {heading}"));
        }
        for key in docs.difference(&code) {
            problems.push(format!(
                "docs/reference/{page} § {heading} documents `{key}`, which {name} does not read"
            ));
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn every_value_back_end_derivative_and_manoeuvre_is_documented() {
    let mut problems = Vec::new();
    let mut expect = |page: &str, heading: &str, value: &str| {
        let text = section(page, heading);
        if !text.contains(&format!("`{value}`")) && !text.contains(&format!("\"{value}\"")) {
            problems.push(format!("`{value}` is not in docs/reference/{page} § {heading}"));
        }
    };
    for (file, name, page, heading) in VALUES {
        for value in values(file, name) {
            expect(page, heading, &value);
        }
    }
    // each by a heading of its own
    let headed = |page: &str, name: &str| section(page, &format!("`{name}`"));
    for name in Backend::NAMES {
        headed("backends.md", name);
    }
    for (name, _, _) in DIFFERENTIATORS {
        headed("derivatives.md", name);
    }
    for name in ["auto", "kinematic"] {
        headed("derivatives.md", name);
    }
    for example in Manoeuvre::EXAMPLES {
        headed("manoeuvres.md", example.split(':').next().unwrap());
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
    assert!(Path::new(&root().join("docs/reference/README.md")).exists());
}
