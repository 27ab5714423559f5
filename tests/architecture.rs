//! The library's layering: which top-level modules of `src/` name which others
//! (`crate::x` outside test code). The graph has no cycles, the leaves stay leaves,
//! and nothing of the core names the shells (the window, the command line's tools).

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::Path;

type Graph = BTreeMap<String, BTreeSet<String>>;

/// The top-level module a source file belongs to (`render/bands.rs` → `render`).
fn module_of(relative: &Path) -> Option<String> {
    let first = relative.components().next()?.as_os_str().to_str()?;
    let name = first.strip_suffix(".rs").unwrap_or(first);
    (!matches!(name, "lib" | "main")).then(|| name.to_string())
}

/// The modules named as `crate::x` in `text`, before its test module (which by the
/// project's habit closes the file).
fn named_modules(text: &str) -> BTreeSet<String> {
    let code = text.split("#[cfg(test)]\nmod ").next().unwrap_or(text);
    code.match_indices("crate::")
        .map(|(i, m)| {
            code[i + m.len()..]
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect::<String>()
        })
        .filter(|name| !name.is_empty())
        .collect()
}

fn collect(dir: &Path, root: &Path, graph: &mut Graph) {
    for entry in fs::read_dir(dir).expect("src is readable") {
        let path = entry.expect("a directory entry").path();
        if path.is_dir() {
            // Test code of a module lives in its `tests/` folder.
            if path.file_name().is_some_and(|n| n != "tests") {
                collect(&path, root, graph);
            }
            continue;
        }
        if path.extension().is_none_or(|e| e != "rs") {
            continue;
        }
        let relative = path.strip_prefix(root).expect("under src");
        let Some(module) = module_of(relative) else {
            continue;
        };
        let text = fs::read_to_string(&path).expect("a source file");
        let named = named_modules(&text);
        let deps = graph.entry(module.clone()).or_default();
        deps.extend(named.into_iter().filter(|n| *n != module));
    }
}

fn graph() -> Graph {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut graph = Graph::new();
    collect(&root, &root, &mut graph);
    graph
}

/// A cycle through `node`, if there is one.
fn cycle(graph: &Graph, path: &mut Vec<String>) -> Option<Vec<String>> {
    let node = path.last().expect("a path").clone();
    for next in graph.get(&node).into_iter().flatten() {
        if let Some(i) = path.iter().position(|p| p == next) {
            let mut found = path[i..].to_vec();
            found.push(next.clone());
            return Some(found);
        }
        path.push(next.clone());
        if let Some(found) = cycle(graph, path) {
            return Some(found);
        }
        path.pop();
    }
    None
}

#[test]
fn the_modules_form_no_cycle() {
    let graph = graph();
    assert!(graph.len() > 10, "too few modules found: {graph:?}");
    for start in graph.keys() {
        if let Some(found) = cycle(&graph, &mut vec![start.clone()]) {
            panic!("import cycle: {}", found.join(" → "));
        }
    }
}

#[test]
fn leaves_and_the_core_stay_below_the_shells() {
    let graph = graph();
    for leaf in ["camera", "limits", "model", "sampling"] {
        assert_eq!(graph[leaf], BTreeSet::new(), "{leaf} names other modules");
    }
    assert_eq!(
        graph["settings"],
        BTreeSet::from(["limits".to_string()]),
        "settings is a leaf but for the limits"
    );
    for (module, deps) in &graph {
        if ["viewer", "bench", "speed"].contains(&module.as_str()) {
            continue;
        }
        for shell in ["viewer", "bench", "speed"] {
            assert!(!deps.contains(shell), "{module} names the shell {shell}");
        }
    }
    assert!(!graph["scene"].contains("render"), "scene names render");
    assert!(!graph["camera"].contains("scene"), "camera names scene");
}

#[test]
fn the_reader_sees_a_cycle_when_there_is_one() {
    let named = named_modules(
        "use crate::b::X;\n#[cfg(test)]\nfn f() { crate::c::g() }\n\n#[cfg(test)]\nmod tests {\n    use crate::d;\n}\n",
    );
    assert_eq!(named, BTreeSet::from(["b".into(), "c".into()]));
    let graph: Graph = [("a", vec!["b"]), ("b", vec!["c"]), ("c", vec!["a"])]
        .into_iter()
        .map(|(k, v)| (k.into(), v.into_iter().map(String::from).collect()))
        .collect();
    assert_eq!(
        cycle(&graph, &mut vec!["a".into()]),
        Some(vec!["a".into(), "b".into(), "c".into(), "a".into()])
    );
}
