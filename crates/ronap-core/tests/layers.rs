//! The crate's shape, checked: every module uses only its own layer and the layers below it, and
//! no module reaches (through any chain of uses) a module that reaches it back.
//!
//! Reads `src/` as text: a use is any `crate::...` or `super::...` path outside test modules;
//! `mod` declarations and `pub use` re-exports (a folder presenting its own children) are not uses.

// Test code may panic on setup failures: that is a failed test, as intended.
#![allow(clippy::unwrap_used)]

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The layers, lowest first: a module may use its own layer and those before it.
const LAYERS: [&str; 14] = [
    "bounded", "config", "geometry", "scene", "sim", "plan", "policy", "run", "eval", "render",
    "io", "job", "collect", "compare",
];

/// Module path (`sim::episode`) of every source file, with its text up to the test module.
fn modules() -> BTreeMap<String, String> {
    fn walk(dir: &Path, root: &Path, out: &mut BTreeMap<String, String>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path: PathBuf = entry.unwrap().path();
            if path.is_dir() {
                walk(&path, root, out);
            } else if path.extension().is_some_and(|e| e == "rs") {
                let rel = path.strip_prefix(root).unwrap().with_extension("");
                let mut parts: Vec<String> = rel
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned())
                    .collect();
                if parts.last().is_some_and(|p| p == "mod" || p == "lib") {
                    parts.pop();
                }
                let text = std::fs::read_to_string(&path).unwrap();
                let code = text.split("#[cfg(test)]").next().unwrap_or("").to_string();
                out.insert(parts.join("::"), code);
            }
        }
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut out = BTreeMap::new();
    walk(&root, &root, &mut out);
    out
}

/// The modules `code` (of module `module`) uses, resolved to the deepest known module.
fn uses(module: &str, code: &str, known: &BTreeSet<String>) -> BTreeSet<String> {
    let mut found = BTreeSet::new();
    let parent: Vec<&str> = module.split("::").filter(|s| !s.is_empty()).collect();
    let parent = &parent[..parent.len().saturating_sub(1)];
    for line in code.lines() {
        let line = line.trim();
        let declaration = ["mod ", "pub mod ", "pub(crate) mod ", "pub use "]
            .iter()
            .any(|d| line.starts_with(d));
        if line.starts_with("//") || declaration {
            continue;
        }
        for (prefix, base) in [("crate::", Vec::new()), ("super::", parent.to_vec())] {
            let mut rest = line;
            while let Some(at) = rest.find(prefix) {
                let after = &rest[at + prefix.len()..];
                let ident_path: String = after
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_' || *c == ':')
                    .collect();
                let mut path: Vec<String> = base.iter().map(|s| s.to_string()).collect();
                path.extend(
                    ident_path
                        .split("::")
                        .filter(|s| !s.is_empty())
                        .map(String::from),
                );
                while !path.is_empty() && !known.contains(&path.join("::")) {
                    path.pop();
                }
                let target = path.join("::");
                if !target.is_empty() && target != module {
                    found.insert(target);
                }
                rest = &after[ident_path.len().min(after.len())..];
            }
        }
    }
    found
}

fn layer(module: &str) -> Option<usize> {
    let top = module.split("::").next()?;
    LAYERS.iter().position(|l| *l == top)
}

#[test]
fn every_module_uses_only_its_layer_and_those_below() {
    let modules = modules();
    let known: BTreeSet<String> = modules.keys().cloned().collect();
    let mut wrong = Vec::new();
    for (module, code) in &modules {
        let Some(own) = layer(module) else {
            // lib.rs: the crate root only declares and re-exports.
            continue;
        };
        for used in uses(module, code, &known) {
            if layer(&used).is_some_and(|l| l > own) {
                wrong.push(format!("{module} uses {used}"));
            }
        }
    }
    assert!(wrong.is_empty(), "upward uses: {wrong:#?}");
    assert!(known.len() > 40, "only {} modules read", known.len());
}

/// A circle in `graph` (module -> modules it uses), as the path around it; `None` when none.
fn find_circle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    // Depth-first search for a back edge; the path to it is the circle.
    fn visit(
        m: &str,
        graph: &BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<String, u8>,
        stack: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        state.insert(m.to_string(), 1);
        stack.push(m.to_string());
        for next in graph.get(m).into_iter().flatten() {
            match state.get(next.as_str()) {
                Some(1) => {
                    let from = stack.iter().position(|s| s == next).unwrap_or(0);
                    let mut circle = stack[from..].to_vec();
                    circle.push(next.clone());
                    return Some(circle);
                }
                Some(_) => {}
                None => {
                    if let Some(c) = visit(next, graph, state, stack) {
                        return Some(c);
                    }
                }
            }
        }
        stack.pop();
        state.insert(m.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for m in graph.keys() {
        if !state.contains_key(m) {
            if let Some(c) = visit(m, graph, &mut state, &mut Vec::new()) {
                return Some(c);
            }
        }
    }
    None
}

#[test]
fn no_module_reaches_a_module_that_reaches_it_back() {
    let modules = modules();
    let known: BTreeSet<String> = modules.keys().cloned().collect();
    let graph: BTreeMap<String, BTreeSet<String>> = modules
        .iter()
        .map(|(m, code)| (m.clone(), uses(m, code, &known)))
        .collect();
    if let Some(circle) = find_circle(&graph) {
        panic!("import circle: {}", circle.join(" -> "));
    }
}

#[test]
fn the_check_sees_an_upward_use_and_a_circle() {
    let known: BTreeSet<String> = ["sim::world", "sim::episode", "plan::path", "plan", "sim"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    // The use the old World made of the planner, and the re-export that is not a use.
    let used = uses(
        "sim::world",
        "use crate::plan::path::shortest_path;\npub use crate::sim;\n",
        &known,
    );
    assert_eq!(used, BTreeSet::from(["plan::path".to_string()]));
    assert!(layer("plan::path") > layer("sim::world"));
    // The old circle: world used episode, and episode built a World.
    let graph = BTreeMap::from([
        (
            "sim::world".to_string(),
            uses("sim::world", "use super::episode::Episode;", &known),
        ),
        (
            "sim::episode".to_string(),
            uses(
                "sim::episode",
                "crate::sim::world::World::new(c, s)",
                &known,
            ),
        ),
    ]);
    let circle = find_circle(&graph).expect("a circle");
    assert_eq!(circle.first(), circle.last());
    assert_eq!(circle.len(), 3);
    let mut graph = graph;
    graph.insert("sim::episode".to_string(), BTreeSet::new());
    assert_eq!(find_circle(&graph), None);
}
