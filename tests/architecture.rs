//! The crate's layering, as ARCHITECTURE.md states it: every module of `src/` names only
//! modules of lower layers (`crate::module` paths in code, doc comments excluded), so the
//! import graph has no cycle and no upward edge. The layer table is read from ARCHITECTURE.md
//! itself (its `layers` block), so the document and the code cannot drift apart.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The layers of ARCHITECTURE.md's fenced `layers` block, bottom first: each line
/// `N  module module …` (a number, then the modules of that layer).
fn declared_layers() -> BTreeMap<String, usize> {
    let text = std::fs::read_to_string(root().join("ARCHITECTURE.md")).expect("ARCHITECTURE.md");
    let block = text
        .split("```layers")
        .nth(1)
        .and_then(|rest| rest.split("```").next())
        .expect("ARCHITECTURE.md has a ```layers block");
    let mut layers = BTreeMap::new();
    for line in block.lines().map(str::trim).filter(|l| !l.is_empty() && !l.starts_with('#')) {
        let mut words = line.split_whitespace();
        let level: usize = words.next().and_then(|w| w.parse().ok()).expect("a layer number first");
        for module in words {
            assert!(layers.insert(module.to_string(), level).is_none(), "{module} is listed twice");
        }
    }
    layers
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Every `.rs` file below `dir`.
fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("a readable directory") {
        let path = entry.expect("an entry").path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The top-level module a file of `src/` belongs to (`lib` for the crate root).
fn module_of(path: &Path) -> String {
    let rel = path.strip_prefix(root().join("src")).expect("a file of src/");
    let first = rel.components().next().expect("a component").as_os_str().to_string_lossy().into_owned();
    first.strip_suffix(".rs").map(str::to_string).unwrap_or(first)
}

/// The modules a file names as `crate::module` outside comments.
fn named_modules(text: &str) -> BTreeSet<String> {
    let mut named = BTreeSet::new();
    for line in text.lines() {
        let code = line.split("//").next().unwrap_or("");
        let mut rest = code;
        while let Some(at) = rest.find("crate::") {
            let before = rest[..at].chars().next_back();
            rest = &rest[at + "crate::".len()..];
            if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == '$') {
                continue; // `$crate::`, `other_crate::`
            }
            let name: String = rest.chars().take_while(|c| c.is_ascii_lowercase() || *c == '_').collect();
            if !name.is_empty() {
                named.insert(name);
            }
        }
    }
    named
}

#[test]
fn every_module_imports_only_lower_layers() {
    let layers = declared_layers();
    let mut files = Vec::new();
    sources(&root().join("src"), &mut files);
    let mut seen = BTreeSet::new();
    let mut violations = Vec::new();
    for file in &files {
        let module = module_of(file);
        if module == "lib" {
            continue; // the root re-exports every layer
        }
        seen.insert(module.clone());
        let Some(&level) = layers.get(&module) else {
            violations
                .push(format!("{}: module `{module}` is not in ARCHITECTURE.md's layers", file.display()));
            continue;
        };
        let text = std::fs::read_to_string(file).expect("a readable source");
        for named in named_modules(&text) {
            if named == module {
                continue;
            }
            match layers.get(&named) {
                Some(&other) if other < level => {}
                Some(&other) => violations.push(format!(
                    "{}: `{module}` (layer {level}) names `crate::{named}` (layer {other})",
                    file.display()
                )),
                None => {
                    violations.push(format!("{}: `crate::{named}` is not a layered module", file.display()))
                }
            }
        }
    }
    for module in layers.keys() {
        if !seen.contains(module) {
            violations.push(format!("ARCHITECTURE.md lists `{module}`, which src/ does not have"));
        }
    }
    assert!(violations.is_empty(), "{} layering violations:\n{}", violations.len(), violations.join("\n"));
}

/// The checker itself: it sees a `crate::` path in code, not in comments, nor `$crate::`.
#[test]
fn the_checker_reads_code_only() {
    let text = "use crate::slope::Ggx; // crate::bsdf\n/// [`crate::leadr`]\nlet x = $crate::rng::f();";
    assert_eq!(named_modules(text), BTreeSet::from(["slope".to_string()]));
}
