//! The crate's shape, checked: every module uses only its own layer and the layers below it, and
//! no module reaches (through any chain of uses) a module that reaches it back.
//!
//! Reads `src/` as text: a use is any `crate::...` or `super::...` path outside test modules;
//! `mod` declarations and `pub use` / `pub(crate) use` re-exports (a folder presenting its own
//! children) are not uses. A path through a folder's re-exports (`crate::sim::World`) is a use of
//! the file the item lives in (`sim::world`), so a layer's files can use each other through it and
//! a circle still shows.

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

/// A use tree as the leaf paths it names: `a::{b, c::{d as e}}` is `a::b` and `a::c::d`. An
/// alias names the same item, so it is dropped; `self` is its folder.
fn leaves(tree: &str) -> Vec<Vec<String>> {
    fn parse(s: &[char], at: &mut usize) -> Vec<Vec<String>> {
        let skip = |at: &mut usize| {
            while *at < s.len() && s[*at].is_whitespace() {
                *at += 1;
            }
        };
        skip(at);
        if s.get(*at) == Some(&'{') {
            *at += 1;
            let mut out = Vec::new();
            loop {
                skip(at);
                match s.get(*at) {
                    None => return out,
                    Some('}') => {
                        *at += 1;
                        return out;
                    }
                    Some(',') => *at += 1,
                    _ => {
                        let before = *at;
                        out.extend(parse(s, at));
                        if *at == before {
                            *at += 1;
                        }
                    }
                }
            }
        }
        let start = *at;
        while *at < s.len() && (s[*at].is_alphanumeric() || s[*at] == '_') {
            *at += 1;
        }
        let ident: String = s[start..*at].iter().collect();
        if ident.is_empty() {
            return vec![Vec::new()];
        }
        if s.get(*at) == Some(&':') && s.get(*at + 1) == Some(&':') {
            *at += 2;
            return parse(s, at)
                .into_iter()
                .map(|mut rest| {
                    rest.insert(0, ident.clone());
                    rest
                })
                .collect();
        }
        // `x as y`: skip the alias.
        let rest: String = s[*at..].iter().take(4).collect();
        if rest.starts_with(" as ") {
            *at += 4;
            while *at < s.len() && (s[*at].is_alphanumeric() || s[*at] == '_') {
                *at += 1;
            }
        }
        vec![vec![ident]]
    }
    let chars: Vec<char> = tree.chars().collect();
    parse(&chars, &mut 0)
        .into_iter()
        .map(|p| p.into_iter().filter(|s| s != "self").collect())
        .collect()
}

/// What each folder re-exports: (folder, name) -> the module the item lives in, read from the
/// folder's `pub use` and `pub(crate) use` lists (`pub use world::{World, Worlds}` in `sim`:
/// `sim::World` is `sim::world`'s). Lets `crate::sim::World` count as a use of `sim::world`.
fn reexports(modules: &BTreeMap<String, String>) -> BTreeMap<(String, String), String> {
    let known: BTreeSet<&String> = modules.keys().collect();
    let mut out = BTreeMap::new();
    for (module, code) in modules {
        let own: Vec<String> = module
            .split("::")
            .filter(|s| !s.is_empty())
            .map(String::from)
            .collect();
        let mut rest = code.as_str();
        let next = |rest: &str| {
            [rest.find("pub use "), rest.find("pub(crate) use ")]
                .into_iter()
                .flatten()
                .min()
        };
        while let Some(at) = next(rest) {
            let from = &rest[at..];
            let body_at = from.find("use ").unwrap_or(0) + 4;
            let end = from.find(';').unwrap_or(from.len());
            for leaf in leaves(&from[body_at..end]) {
                let Some((name, path)) = leaf.split_last() else {
                    continue;
                };
                let mut base = match path.first().map(String::as_str) {
                    Some("crate") => Vec::new(),
                    Some("super") => own[..own.len().saturating_sub(1)].to_vec(),
                    _ => own.clone(),
                };
                let skip = usize::from(matches!(
                    path.first().map(String::as_str),
                    Some("crate" | "super")
                ));
                let mut found = !path[skip..].is_empty();
                for seg in &path[skip..] {
                    base.push(seg.clone());
                    if !known.contains(&base.join("::")) {
                        found = false;
                        break;
                    }
                }
                if found {
                    out.insert((module.clone(), name.clone()), base.join("::"));
                }
            }
            rest = &from[end.min(from.len())..];
            if rest.is_empty() {
                break;
            }
            rest = &rest[1..];
        }
    }
    out
}

/// The module `path` (segments from the crate root) names, through folders and their re-exports:
/// `sim::world::World` and `sim::World` are both `sim::world`.
fn resolve(
    path: &[String],
    known: &BTreeSet<String>,
    exports: &BTreeMap<(String, String), String>,
) -> String {
    let mut at: Vec<String> = Vec::new();
    for seg in path {
        let mut next = at.clone();
        next.push(seg.clone());
        if known.contains(&next.join("::")) {
            at = next;
            continue;
        }
        let mut key = (at.join("::"), seg.clone());
        // A re-export of a re-export (the crate root's of a layer's) ends at the item's file.
        while let Some(target) = exports.get(&key) {
            at = target.split("::").map(String::from).collect();
            key = (target.clone(), seg.clone());
        }
        break;
    }
    at.join("::")
}

/// The modules `code` (of module `module`) uses, resolved to the deepest known module, through
/// the folders' re-exports (`exports`).
fn uses(
    module: &str,
    code: &str,
    known: &BTreeSet<String>,
    exports: &BTreeMap<(String, String), String>,
) -> BTreeSet<String> {
    let mut found = BTreeSet::new();
    let parent: Vec<&str> = module.split("::").filter(|s| !s.is_empty()).collect();
    let parent = &parent[..parent.len().saturating_sub(1)];
    // Comments and declarations out, whole statements joined, so a use tree over several lines
    // reads as one.
    let mut text = String::new();
    let mut in_reexport = false;
    for line in code.lines() {
        let line = line.trim();
        if in_reexport || line.starts_with("pub use ") || line.starts_with("pub(crate) use ") {
            in_reexport = !line.contains(';');
            continue;
        }
        let declaration = ["mod ", "pub mod ", "pub(crate) mod "]
            .iter()
            .any(|d| line.starts_with(d));
        if line.starts_with("//") || declaration {
            continue;
        }
        text.push_str(line);
        text.push(' ');
    }
    for (prefix, base) in [("crate::", Vec::new()), ("super::", parent.to_vec())] {
        let mut rest = text.as_str();
        while let Some(at) = rest.find(prefix) {
            let after = &rest[at + prefix.len()..];
            let end = after
                .find(|c: char| !(c.is_alphanumeric() || "_:{}, ".contains(c)))
                .unwrap_or(after.len());
            // A use tree ends where its braces close; a path, at its first other character.
            let mut depth = 0i32;
            let mut tree_end = end;
            for (i, c) in after[..end].char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' => {
                        depth -= 1;
                        if depth <= 0 {
                            tree_end = i + 1;
                            break;
                        }
                    }
                    ' ' | ',' if depth == 0 => {
                        tree_end = i;
                        break;
                    }
                    _ => {}
                }
            }
            for leaf in leaves(&after[..tree_end]) {
                let mut path: Vec<String> = base.iter().map(|s| s.to_string()).collect();
                path.extend(leaf);
                let target = resolve(&path, known, exports);
                if !target.is_empty() && target != module {
                    found.insert(target);
                }
            }
            rest = &after[tree_end.max(1).min(after.len())..];
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
    let exports = reexports(&modules);
    let mut wrong = Vec::new();
    for (module, code) in &modules {
        let Some(own) = layer(module) else {
            // lib.rs: the crate root only declares and re-exports.
            continue;
        };
        for used in uses(module, code, &known, &exports) {
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
    let exports = reexports(&modules);
    let graph: BTreeMap<String, BTreeSet<String>> = modules
        .iter()
        .map(|(m, code)| (m.clone(), uses(m, code, &known, &exports)))
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
    let none = BTreeMap::new();
    // The use the old World made of the planner, and the re-export that is not a use.
    let used = uses(
        "sim::world",
        "use crate::plan::path::shortest_path;\npub use crate::sim;\n",
        &known,
        &none,
    );
    assert_eq!(used, BTreeSet::from(["plan::path".to_string()]));
    assert!(layer("plan::path") > layer("sim::world"));
    // The old circle: world used episode, and episode built a World.
    let graph = BTreeMap::from([
        (
            "sim::world".to_string(),
            uses("sim::world", "use super::episode::Episode;", &known, &none),
        ),
        (
            "sim::episode".to_string(),
            uses(
                "sim::episode",
                "crate::sim::world::World::new(c, s)",
                &known,
                &none,
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

#[test]
fn a_use_through_a_folders_reexports_is_a_use_of_the_file_behind_them() {
    let modules = BTreeMap::from([
        (String::new(), "pub use sim::{Episode, World};\n".to_string()),
        (
            "sim".to_string(),
            "mod episode;\nmod world;\n\npub use episode::Episode;\npub(crate) use world::{\n    maze_scene, World,\n};\n"
                .to_string(),
        ),
        ("sim::episode".to_string(), String::new()),
        ("sim::world".to_string(), String::new()),
        ("plan".to_string(), String::new()),
        ("plan::path".to_string(), String::new()),
    ]);
    let known: BTreeSet<String> = modules.keys().cloned().collect();
    let exports = reexports(&modules);
    assert_eq!(
        exports[&("sim".to_string(), "World".to_string())],
        "sim::world"
    );
    assert_eq!(exports[&(String::new(), "Episode".to_string())], "sim");
    let set = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<BTreeSet<_>>();
    // A layer's re-export, a tree over lines, the crate root's re-export of a layer's.
    assert_eq!(
        uses("plan::path", "use crate::sim::World;", &known, &exports),
        set(&["sim::world"])
    );
    assert_eq!(
        uses(
            "plan::path",
            "use crate::sim::{\n    maze_scene,\n    Episode as E,\n};\nlet w = crate::World::new();",
            &known,
            &exports
        ),
        set(&["sim::world", "sim::episode"])
    );
    // Within the layer, the re-export keeps the circle visible.
    let graph = BTreeMap::from([
        (
            "sim::world".to_string(),
            uses("sim::world", "use super::Episode;", &known, &exports),
        ),
        (
            "sim::episode".to_string(),
            uses(
                "sim::episode",
                "crate::sim::World::maze(c, s)",
                &known,
                &exports,
            ),
        ),
    ]);
    assert!(find_circle(&graph).is_some());
    // The re-export lists themselves are not uses.
    assert!(uses("sim", &modules["sim"], &known, &exports).is_empty());
}
