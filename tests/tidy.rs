//! Invariants of the workspace that no compiler checks, kept true by test
//! (after rust-analyzer's tidy tests). Each names the rule from
//! `docs/architecture.md` that it guards.

use std::fs;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("workspace root")
        .to_path_buf()
}

/// Every `.rs` file of ours (not `target/`, not the fuzz build), relative
/// to the root, with its text.
fn sources() -> Vec<(String, String)> {
    fn walk(dir: &Path, root: &Path, out: &mut Vec<(String, String)>) {
        for entry in fs::read_dir(dir).expect("readable directory") {
            let path = entry.expect("directory entry").path();
            let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
            if name.starts_with('.') || name == "target" {
                continue;
            }
            if path.is_dir() {
                walk(&path, root, out);
            } else if name.ends_with(".rs") {
                let rel = path
                    .strip_prefix(root)
                    .expect("under root")
                    .to_string_lossy()
                    .into_owned();
                out.push((rel, fs::read_to_string(&path).expect("utf-8 source")));
            }
        }
    }
    let root = root();
    let mut out = Vec::new();
    for top in ["crates", "benches", "tests", "fuzz"] {
        if root.join(top).is_dir() {
            walk(&root.join(top), &root, &mut out);
        }
    }
    assert!(out.len() > 10, "found the sources");
    out
}

/// Intrinsics live in two places only: the lane types of the math layer
/// and the body gather/scatter. Kernels never `use core::arch`.
const INTRINSIC_FILES: &[&str] = &[
    "crates/vertebra-math/src/lane/sse41.rs",
    "crates/vertebra-math/src/lane/avx2.rs",
    // What the two share, as macros the two files invoke with their
    // intrinsics.
    "crates/vertebra-math/src/lane/x86.rs",
    // AArch64 NEON and WebAssembly SIMD128, 4 lanes each.
    "crates/vertebra-math/src/lane/neon.rs",
    "crates/vertebra-math/src/lane/simd128.rs",
    "crates/vertebra-math/src/backend.rs",
    // MXCSR and FPCR: the step's floating-point mode (stmxcsr/ldmxcsr, mrs/msr).
    "crates/vertebra-math/src/float_mode.rs",
    // The tests' host, which sets a mode before it calls in.
    "crates/vertebra-world/tests/host_mode/mod.rs",
];

#[test]
fn intrinsics_only_in_lane_types_and_gather_scatter() {
    for (path, text) in sources() {
        if INTRINSIC_FILES.contains(&path.as_str()) || path == "tests/tidy.rs" {
            continue;
        }
        for (n, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            assert!(
                !code.contains("arch::") && !code.contains("_mm_") && !code.contains("_mm256_"),
                "{path}:{}: intrinsics belong in the lane types or the gather/scatter",
                n + 1
            );
        }
    }
}

/// Besides the intrinsics, `unsafe` has one other home: the claims that
/// body rows (not `Sync`) may be shared by the threads solving a colour,
/// with the check that makes it sound (docs/architecture.md, "Unsafe"),
/// and that a stage's blocks are lent to one worker at a time (the solver
/// stages, and the substep's one lending site, `Substep::lend`); and the
/// one lifetime the step's task is lent under to an engine's persistent
/// threads (`lend.rs`: the gate that outlives no borrow, so engines need
/// none).
const SHARED_FILES: [&str; 4] = [
    "crates/vertebra-world/src/lend.rs",
    "crates/vertebra-world/src/parallel.rs",
    "crates/vertebra-world/src/stages.rs",
    "crates/vertebra-world/src/substep.rs",
];

/// And a test's own global allocator, counting allocations on its way to
/// the system's (the proof that a steady step allocates nothing).
const COUNTING_ALLOCATOR_FILE: &str = "crates/vertebra-scenes/tests/allocation.rs";

/// And the C ABI, whose callers hand it raw pointers: its functions are
/// `unsafe extern "C"` with a `# Safety` section (what the pointers must
/// be), their bodies turn pointers into references through `ffi.rs`'s
/// checks; and the Rust programs that call them as C would (the crate's
/// tests, the overhead benchmarks `benches/capi*.rs`, and its fuzz
/// target).
const C_ABI_PATHS: [&str; 4] = [
    "crates/vertebra-capi/src/",
    "crates/vertebra-capi/tests/",
    "benches/capi",
    "crates/vertebra-fuzzing/src/capi.rs",
];

/// Whether `code` declares an unsafe function (not a function pointer
/// type: `unsafe extern "C" fn(`).
fn declares_unsafe_fn(code: &str) -> bool {
    code.split("unsafe ").skip(1).any(|rest| {
        let rest = rest.strip_prefix("extern \"C\" ").unwrap_or(rest);
        rest.strip_prefix("fn ").is_some()
    })
}

/// Whether the `unsafe fn` declared at line `n` has a `# Safety` section
/// in the doc comment above it.
fn says_its_safety_contract(lines: &[&str], n: usize) -> bool {
    lines[..n]
        .iter()
        .rev()
        .skip_while(|l| l.trim_start().starts_with("#["))
        .take_while(|l| l.trim_start().starts_with("///"))
        .any(|l| l.contains("# Safety"))
}

#[test]
fn every_unsafe_block_says_why_and_stays_where_intrinsics_are() {
    for (path, text) in sources() {
        if path == "tests/tidy.rs" {
            continue;
        }
        let lines: Vec<&str> = text.lines().collect();
        for (n, line) in lines.iter().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            if !code.contains("unsafe ") && !code.contains("unsafe{") {
                continue;
            }
            if code.contains("unsafe_op_in_unsafe_fn") {
                continue;
            }
            let c_abi = C_ABI_PATHS.iter().any(|p| path.starts_with(p));
            assert!(
                INTRINSIC_FILES.contains(&path.as_str())
                    || SHARED_FILES.contains(&path.as_str())
                    || path == COUNTING_ALLOCATOR_FILE
                    || c_abi,
                "{path}:{}: `unsafe` only where intrinsics need it",
                n + 1
            );
            if c_abi && code.contains("unsafe extern \"C\" fn(") {
                // A function pointer's type: what C hands in, not a block.
                continue;
            }
            if c_abi && declares_unsafe_fn(code) {
                assert!(
                    says_its_safety_contract(&lines, n),
                    "{path}:{}: an unsafe fn without a `# Safety` section",
                    n + 1
                );
                continue;
            }
            let start = n.saturating_sub(3);
            let said = lines[start..=n].iter().any(|l| l.contains("// SAFETY:"))
                || (start..n).any(|k| {
                    lines[k].trim_start().starts_with("//") && lines[k].contains("SAFETY")
                });
            assert!(said, "{path}:{}: unsafe without a `// SAFETY:` line", n + 1);
        }
    }
}

#[test]
fn kernels_never_fuse_or_approximate() {
    // Lane implementations define mul_add; nothing else calls it or any
    // approximate reciprocal (see crates/vertebra-math/src/lane.rs).
    for (path, text) in sources() {
        let defines = path.starts_with("crates/vertebra-math/src/lane");
        // The fuzzing crate's bodies are tests: they exercise mul_add itself.
        let is_test = path.contains("/tests/")
            || path.starts_with("tests/")
            || path.starts_with("fuzz/")
            || path.starts_with("crates/vertebra-fuzzing/");
        if defines || is_test {
            continue;
        }
        for (n, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            assert!(
                !code.contains(".mul_add("),
                "{path}:{}: `mul_add` breaks bit-for-bit",
                n + 1
            );
            // Identifiers, so that a word such as `recipe` is not one.
            let approximate = code
                .split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .find(|w| *w == "recip" || w.starts_with("recip_") || w.contains("rsqrt"));
            assert!(
                approximate.is_none(),
                "{path}:{}: `{}` breaks bit-for-bit",
                n + 1,
                approximate.unwrap_or_default()
            );
        }
    }
}

/// Lane-generic code has no closures: a closure does not inherit the
/// kernel entry's target features (see crates/vertebra-math/src/lane.rs).
#[test]
fn lane_code_has_no_closures() {
    let lane_code = |path: &str| {
        path.starts_with("crates/vertebra-kernels/src/")
            || [
                "vec3.rs",
                "quat.rs",
                "sym3.rs",
                "poly.rs",
                "poly/",
                "lane/sse41.rs",
                "lane/avx2.rs",
                "lane/x86.rs",
                "lane/neon.rs",
                "lane/simd128.rs",
            ]
            .iter()
            .any(|f| path.starts_with(&format!("crates/vertebra-math/src/{f}")))
    };
    for (path, text) in sources() {
        // A kernels file that names no lane type (the trees' layout into
        // pieces) holds no lane code.
        let generic = !path.starts_with("crates/vertebra-kernels/") || text.contains("L: Lane");
        if !lane_code(&path) || !generic {
            continue;
        }
        for (n, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            let closure = ["(|", "= |", ", |", "move |"]
                .iter()
                .any(|p| code.contains(p));
            // Debug formatting is not lane code.
            if closure && !code.contains(".entries(") {
                panic!(
                    "{path}:{}: a closure in lane code loses the kernel's target features",
                    n + 1
                );
            }
        }
    }
}

#[test]
fn no_ignored_tests_and_no_cpu_specific_builds() {
    for (path, text) in sources() {
        if path == "tests/tidy.rs" {
            continue;
        }
        assert!(
            !text.contains("#[ignore"),
            "{path}: no #[ignore] to get green"
        );
    }
    let config = root().join(".cargo/config.toml");
    if let Ok(text) = fs::read_to_string(config) {
        assert!(
            !text.contains("target-cpu"),
            "target-cpu would kill the binary on older CPUs"
        );
    }
}

#[test]
fn the_architecture_map_names_every_crate() {
    let map =
        fs::read_to_string(root().join("docs/architecture.md")).expect("docs/architecture.md");
    let mut crates: Vec<String> = fs::read_dir(root().join("crates"))
        .expect("crates/")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    crates.extend(["vertebra-benches".into(), "vertebra-tidy".into()]);
    for name in crates {
        assert!(
            map.contains(&format!("`{name}`")),
            "docs/architecture.md does not describe `{name}`"
        );
    }
    let workspace = fs::read_to_string(root().join("Cargo.toml")).expect("Cargo.toml");
    for entry in fs::read_dir(root().join("crates")).expect("crates/") {
        let name = entry
            .expect("entry")
            .file_name()
            .to_string_lossy()
            .into_owned();
        assert!(
            workspace.contains(&format!("crates/{name}")),
            "crates/{name} is not a workspace member"
        );
    }
}

/// The README's quick start is the collision crate's quick-start doctest,
/// line for line (the doctest's hidden `# ` lines aside): what a reader
/// copies is what the tests compile and run.
#[test]
fn the_readme_quick_start_is_the_doctest() {
    let root = root();
    let lib = std::fs::read_to_string(root.join("crates/vertebra-collide/src/lib.rs")).unwrap();
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    let doc = &lib[lib
        .find("//! # Quick start")
        .expect("the crate's quick start")..];
    let doc: Vec<&str> = doc
        .lines()
        .map(|l| {
            l.strip_prefix("//! ")
                .or(l.strip_prefix("//!"))
                .unwrap_or(l)
        })
        .skip_while(|l| *l != "```")
        .skip(1)
        .take_while(|l| *l != "```")
        .filter(|l| !l.starts_with("# "))
        .collect();
    let quick = &readme[readme
        .find("## Quick start")
        .expect("the README's quick start")..];
    let shown: Vec<&str> = quick
        .lines()
        .skip_while(|l| *l != "```rust")
        .skip(1)
        .take_while(|l| *l != "```")
        .collect();
    assert!(doc.len() > 50, "the doctest was found: {} lines", doc.len());
    assert_eq!(
        shown, doc,
        "README.md's quick start differs from the doctest"
    );
}

/// A crate's files by module path (`a/b` for `src/a/b.rs` or
/// `src/a/b/mod.rs`; `lib.rs` is the empty path), each with its text
/// before its unit tests (which may reach anywhere).
fn modules(src: &Path) -> Vec<(Vec<String>, String)> {
    let root = root();
    let prefix = src
        .strip_prefix(&root)
        .expect("under root")
        .to_string_lossy()
        .into_owned();
    let mut out = Vec::new();
    for (path, text) in sources() {
        let Some(rel) = path.strip_prefix(&format!("{prefix}/")) else {
            continue;
        };
        let mut module: Vec<String> = rel
            .trim_end_matches(".rs")
            .split('/')
            .map(String::from)
            .collect();
        if matches!(
            module.last().map(String::as_str),
            Some("mod" | "lib" | "main")
        ) {
            module.pop();
        }
        let code = text.split("#[cfg(test)]").next().unwrap_or("").to_string();
        out.push((module, code));
    }
    out
}

/// Code without its `//` comments (doc examples name paths of other
/// crates' views, not imports).
fn without_comments(code: &str) -> String {
    code.lines()
        .map(|line| line.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n")
}

/// Every path a `use` declaration of `code` names, its braces expanded
/// (`use crate::{a::B, c::{D, E as F}}` gives `crate::a::B`, `crate::c::D`
/// and `crate::c::E`), each with the name it binds there (`B`, `D`, `F`;
/// `*` for a glob).
fn use_paths(code: &str) -> Vec<(Vec<String>, String)> {
    fn split_top(list: &str) -> Vec<&str> {
        let (mut depth, mut from, mut out) = (0, 0, Vec::new());
        for (i, c) in list.char_indices() {
            match c {
                '{' => depth += 1,
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    out.push(&list[from..i]);
                    from = i + 1;
                }
                _ => {}
            }
        }
        out.push(&list[from..]);
        out
    }
    fn expand(tree: &str, prefix: &[String], out: &mut Vec<(Vec<String>, String)>) {
        let tree = tree.trim();
        if tree.is_empty() {
            return;
        }
        let segments = |s: &str| -> Vec<String> {
            s.split("::")
                .map(str::trim)
                .filter(|p| !p.is_empty())
                .map(String::from)
                .collect()
        };
        if let (Some(open), Some(close)) = (tree.find('{'), tree.rfind('}')) {
            let mut path = prefix.to_vec();
            path.extend(segments(&tree[..open]));
            for part in split_top(&tree[open + 1..close]) {
                expand(part, &path, out);
            }
            return;
        }
        let (path, alias) = match tree.split_once(" as ") {
            Some((path, alias)) => (path, Some(alias.trim().to_string())),
            None => (tree, None),
        };
        let mut full = prefix.to_vec();
        full.extend(segments(path));
        if full.last().is_some_and(|s| s == "self") {
            full.pop();
        }
        if let Some(last) = full.last().cloned() {
            out.push((full, alias.unwrap_or(last)));
        }
    }
    let mut out = Vec::new();
    for (at, _) in code.match_indices("use ") {
        let before = code[..at].chars().next_back();
        if before.is_some_and(|c| !(c.is_whitespace() || c == ')' || c == '{' || c == ';')) {
            continue;
        }
        let rest = &code[at + 4..];
        let Some(end) = rest.find(';') else { continue };
        expand(&rest[..end], &[], &mut out);
    }
    out
}

/// The `crate::` and `super::` paths `code` names outside its `use`
/// declarations (`crate::a::f()` in an expression).
fn inline_paths(code: &str) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    for kind in ["crate", "super"] {
        let pattern = format!("{kind}::");
        for (at, _) in code.match_indices(&pattern) {
            let before = code[..at].chars().next_back();
            if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
                continue;
            }
            let mut path = vec![kind.to_string()];
            path.extend(
                code[at + pattern.len()..]
                    .split("::")
                    .map(|p| {
                        p.chars()
                            .take_while(|c| c.is_alphanumeric() || *c == '_')
                            .collect::<String>()
                    })
                    .take_while(|p| !p.is_empty()),
            );
            out.push(path);
        }
    }
    out
}

/// A crate's modules and the names each binds by `use` (re-exports
/// included), to follow `crate::Name` to the file that defines `Name`.
struct Crate {
    modules: Vec<Vec<String>>,
    bindings: Vec<Vec<(Vec<String>, String)>>,
}

impl Crate {
    fn new(modules: &[(Vec<String>, String)]) -> Self {
        Self {
            modules: modules.iter().map(|(m, _)| m.clone()).collect(),
            bindings: modules.iter().map(|(_, code)| use_paths(code)).collect(),
        }
    }

    fn find(&self, module: &[String]) -> Option<usize> {
        self.modules.iter().position(|m| m == module)
    }

    /// The module a path names from `module`: the longest prefix that is
    /// a module, then through the name it binds there by `use` (a root's
    /// re-export leads to the file that defines the item); `None` for a
    /// path into another crate.
    fn resolve(&self, module: usize, path: &[String], depth: usize) -> Option<usize> {
        let here = &self.modules[module];
        let (mut at, rest): (Vec<String>, &[String]) = match path.first().map(String::as_str) {
            Some("crate") => (Vec::new(), &path[1..]),
            Some("self") => (here.clone(), &path[1..]),
            Some("super") => {
                let mut at = here.clone();
                let mut rest = path;
                while rest.first().is_some_and(|s| s == "super") {
                    at.pop();
                    rest = &rest[1..];
                }
                (at, rest)
            }
            Some(first) => {
                let child: Vec<String> = here.iter().chain([&first.to_string()]).cloned().collect();
                self.find(&child)?;
                (here.clone(), path)
            }
            None => return None,
        };
        for segment in rest {
            let next: Vec<String> = at.iter().chain([segment]).cloned().collect();
            if self.find(&next).is_some() {
                at = next;
                continue;
            }
            let owner = self.find(&at)?;
            if depth > 0 {
                let bound = self.bindings[owner]
                    .iter()
                    .find(|(_, name)| name == segment)
                    .or_else(|| self.bindings[owner].iter().find(|(_, name)| name == "*"));
                if let Some((target, name)) = bound {
                    let target = if name == "*" {
                        let mut t = target[..target.len() - 1].to_vec();
                        t.push(segment.clone());
                        t
                    } else {
                        target.clone()
                    };
                    if let Some(found) = self.resolve(owner, &target, depth - 1) {
                        return Some(found);
                    }
                }
            }
            return Some(owner);
        }
        self.find(&at)
    }

    /// The modules of the crate that `code` (in `module`) imports, other
    /// than `module` and the modules inside it: a module that declares
    /// others is their facade (as the crate root is everyone's), and
    /// naming what it holds is not an import.
    fn imports(&self, module: usize, code: &str) -> Vec<usize> {
        let paths = use_paths(code)
            .into_iter()
            .map(|(path, _)| path)
            .chain(inline_paths(code));
        paths
            .filter_map(|path| self.resolve(module, &path, 8))
            .filter(|&t| !self.modules[t].starts_with(&self.modules[module]))
            .collect()
    }
}

#[test]
fn no_import_circles_between_a_crates_files() {
    let crates = root().join("crates");
    let mut names: Vec<_> = fs::read_dir(&crates)
        .expect("crates")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    let mut circles = Vec::new();
    for name in names {
        let src = crates.join(&name).join("src");
        if !src.is_dir() {
            continue;
        }
        let modules: Vec<(Vec<String>, String)> = modules(&src)
            .into_iter()
            .map(|(m, code)| (m, without_comments(&code)))
            .collect();
        let krate = Crate::new(&modules);
        let known = &krate.modules;
        let edges: Vec<Vec<usize>> = (0..modules.len())
            .map(|m| krate.imports(m, &modules[m].1))
            .collect();
        // Which modules each reaches (depth-first), then the largest set
        // of modules that reach each other.
        let reach = |from: usize| {
            let mut seen = vec![false; known.len()];
            let mut stack = edges[from].clone();
            while let Some(n) = stack.pop() {
                if !std::mem::replace(&mut seen[n], true) {
                    stack.extend(&edges[n]);
                }
            }
            seen
        };
        let reaches: Vec<Vec<bool>> = (0..known.len()).map(reach).collect();
        let circle = |a: usize| -> Vec<String> {
            (0..known.len())
                .filter(|&b| reaches[a][b] && reaches[b][a])
                .map(|b| known[b].join("/"))
                .collect()
        };
        for a in 0..known.len() {
            let members = circle(a);
            if members.first() != Some(&known[a].join("/")) {
                continue;
            }
            let inside = |m: usize| members.contains(&known[m].join("/"));
            let links: Vec<String> = (0..known.len())
                .filter(|&m| inside(m))
                .flat_map(|m| {
                    edges[m]
                        .iter()
                        .filter(|&&t| inside(t))
                        .map(move |&t| (m, t))
                })
                .map(|(m, t)| format!("{} -> {}", known[m].join("/"), known[t].join("/")))
                .collect::<std::collections::BTreeSet<_>>()
                .into_iter()
                .collect();
            circles.push(format!("{name}: {members:?} by {links:?}"));
        }
    }
    assert!(
        circles.is_empty(),
        "files that import each other in a circle:\n{}",
        circles.join("\n")
    );
}

/// Crates other than ours whose items the map may name, by their path
/// (`std::cell::Cell`): not looked up in our sources.
const OTHER_CRATES: &[&str] = &[
    "alloc",
    "arbitrary",
    "bytemuck",
    "cbindgen",
    "clap",
    "clippy",
    "core",
    "criterion",
    "glam",
    "gltf",
    "iai_callgrind",
    "indicatif",
    "libfuzzer_sys",
    "libm",
    "parry3d",
    "postcard",
    "proptest",
    "rapier3d",
    "rayon",
    "serde",
    "std",
    "toml",
    "wide",
    "xxhash_rust",
];

/// A name in backticks in the map: its text, its line, and the directory
/// of the crate whose section it is in (a heading whose first name in
/// backticks is a directory with a `Cargo.toml` opens that crate's
/// section; any other heading closes it).
struct Named {
    text: String,
    line: usize,
    section: Option<String>,
}

/// Every name in backticks in `map`, outside fenced code blocks.
fn map_names(map: &str) -> Vec<Named> {
    let root = root();
    let (mut out, mut section, mut fenced) = (Vec::new(), None, false);
    for (n, line) in map.lines().enumerate() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced {
            continue;
        }
        assert!(
            line.matches('`').count() % 2 == 0,
            "docs/architecture.md:{}: a backtick left open",
            n + 1
        );
        let spans: Vec<&str> = line.split('`').skip(1).step_by(2).collect();
        if line.starts_with('#') {
            section = spans
                .first()
                .map(|s| s.trim_end_matches('/').to_string())
                .filter(|dir| root.join(dir).join("Cargo.toml").is_file());
        }
        out.extend(spans.into_iter().map(|text| Named {
            text: text.to_string(),
            line: n + 1,
            section: section.clone(),
        }));
    }
    out
}

/// A name that looks like a file or directory: only path characters, a
/// letter, and a `/` or a known extension.
fn looks_like_path(s: &str) -> bool {
    s.chars().any(|c| c.is_ascii_alphabetic())
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || "_-./".contains(c))
        && (s.contains('/')
            || [".rs", ".md", ".toml", ".h", ".sh", ".c", ".cpp"]
                .iter()
                .any(|e| s.ends_with(e)))
}

/// Where a path of the map is, relative to the root: in a crate's section
/// under its `src/`, then its directory, then the root; elsewhere from the
/// root. `None` when it is nowhere (a path ending in `/` must be a
/// directory).
fn resolve(section: Option<&str>, path: &str) -> Option<String> {
    let root = root();
    let dir = path.ends_with('/');
    let path = path.trim_end_matches('/');
    let mut candidates = Vec::new();
    if let Some(krate) = section {
        candidates.push(format!("{krate}/src/{path}"));
        candidates.push(format!("{krate}/{path}"));
    }
    candidates.push(path.to_string());
    candidates.into_iter().find(|c| {
        if dir {
            root.join(c).is_dir()
        } else {
            root.join(c).exists()
        }
    })
}

fn is_ident_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

/// `Type`: starts upper-case and has a lower-case letter (`Lane`, `F32x4`).
fn is_type_name(s: &str) -> bool {
    s.starts_with(|c: char| c.is_ascii_uppercase()) && s.chars().any(|c| c.is_ascii_lowercase())
}

/// `CONST`: upper-case, digits and at least one `_` (`MAX_PASSES`).
fn is_const_name(s: &str) -> bool {
    s.starts_with(|c: char| c.is_ascii_uppercase())
        && s.contains('_')
        && s.chars()
            .all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || c == '_')
}

/// What a name of the map says exists in our sources.
#[derive(Debug)]
enum Item {
    /// A struct, enum, trait, type alias or union.
    Type(String),
    /// A function, field, variant, constant or associated type of a type
    /// (declared in a file that declares or implements the type).
    Member(String, String),
    /// A function, module or macro.
    Function(String),
    /// A constant or static.
    Const(String),
}

/// An item named `Type`, `Type::member`, `module::item` or `function()`
/// (generic arguments and call arguments left out; a leading
/// `vertebra_*` is its crate), with its crate and module path; `None` for
/// anything else (prose, another crate's item, a bare lower-case word).
fn parse_item(text: &str) -> Option<(Option<String>, Vec<String>, Item)> {
    let mut s = text.trim();
    let mut call = false;
    if let Some(open) = s.find('(') {
        if !(s.ends_with(')') || s.ends_with('(')) {
            return None;
        }
        (s, call) = (&s[..open], true);
    }
    if let Some(open) = s.find('<') {
        if !s.ends_with('>') {
            return None;
        }
        s = &s[..open];
    }
    let mut segments: Vec<&str> = s.split("::").collect();
    let valid = |g: &&str| {
        !g.is_empty()
            && g.chars().all(is_ident_char)
            && !g.starts_with(|c: char| c.is_ascii_digit())
    };
    if !segments.iter().all(valid) {
        return None;
    }
    if OTHER_CRATES.contains(&segments[0]) || ["crate", "self", "super"].contains(&segments[0]) {
        return None;
    }
    let krate = segments[0]
        .starts_with("vertebra_")
        .then(|| segments.remove(0).replace('_', "-"));
    let name = segments.pop()?.to_string();
    let parent = segments
        .last()
        .filter(|p| is_type_name(p))
        .map(|p| p.to_string());
    if parent.is_some() {
        segments.pop();
    }
    let modules: Vec<String> = segments.iter().map(|m| m.to_string()).collect();
    let item = if let Some(ty) = parent {
        Item::Member(ty, name)
    } else if is_type_name(&name) {
        Item::Type(name)
    } else if is_const_name(&name) {
        Item::Const(name)
    } else if name.starts_with(|c: char| c.is_ascii_lowercase())
        && (call || !modules.is_empty() || krate.is_some())
    {
        Item::Function(name)
    } else {
        return None;
    };
    Some((krate, modules, item))
}

/// Whether `text` has `keyword name` with `name` a whole word.
fn declares(text: &str, keyword: &str, name: &str) -> bool {
    let pattern = format!("{keyword} {name}");
    text.match_indices(&pattern).any(|(at, _)| {
        let before = text[..at].chars().next_back();
        let after = text[at + pattern.len()..].chars().next();
        !before.is_some_and(is_ident_char) && !after.is_some_and(is_ident_char)
    })
}

/// Whether `line` has `word` as a whole word.
fn has_word(line: &str, word: &str) -> bool {
    line.match_indices(word).any(|(at, _)| {
        let before = line[..at].chars().next_back();
        let after = line[at + word.len()..].chars().next();
        !before.is_some_and(is_ident_char) && !after.is_some_and(is_ident_char)
    })
}

fn declares_type(text: &str, name: &str) -> bool {
    ["struct", "enum", "trait", "type", "union"]
        .iter()
        .any(|k| declares(text, k, name))
}

/// Whether `text` declares `member` of some type: a function, constant,
/// static or associated type, or a line that begins with it as a field
/// (`name:`) or a variant (`Name,`, `Name(`, `Name {`, `Name =`).
fn declares_member(text: &str, member: &str) -> bool {
    ["fn", "const", "static", "type"]
        .iter()
        .any(|k| declares(text, k, member))
        || text.lines().any(|line| {
            let t = line.trim_start();
            let t = t
                .strip_prefix("pub(crate) ")
                .or(t.strip_prefix("pub "))
                .unwrap_or(t);
            let Some(rest) = t.strip_prefix(member) else {
                return false;
            };
            rest.is_empty()
                || (rest.starts_with(':') && !rest.starts_with("::"))
                || [",", "(", " {", " =", " ("]
                    .iter()
                    .any(|p| rest.starts_with(p))
        })
}

/// Whether the file at `path` (from the root) is in crate `krate` (its
/// directory name) and inside every module of `modules` (a directory or
/// file of that name on its path, or an inline `mod m { .. }` it holds).
fn within(path: &str, text: &str, krate: Option<&str>, modules: &[String]) -> bool {
    krate.is_none_or(|k| path.starts_with(&format!("crates/{k}/")))
        && modules.iter().all(|m| {
            path.split('/')
                .any(|part| part == m || part == format!("{m}.rs"))
                || text.contains(&format!("mod {m} {{"))
        })
}

/// Whether the item exists in `sources`.
fn item_exists(
    sources: &[(String, String)],
    krate: Option<&str>,
    modules: &[String],
    item: &Item,
) -> bool {
    let mut files = sources
        .iter()
        .filter(|(path, text)| within(path, text, krate, modules));
    match item {
        Item::Type(name) => files.any(|(_, text)| declares_type(text, name)),
        Item::Const(name) => {
            files.any(|(_, text)| declares(text, "const", name) || declares(text, "static", name))
        }
        Item::Function(name) => files.any(|(path, text)| {
            declares(text, "fn", name)
                || declares(text, "mod", name)
                || declares(text, "macro_rules!", name)
                || path.ends_with(&format!("/{name}.rs"))
                || path.ends_with(&format!("/{name}/mod.rs"))
        }),
        Item::Member(ty, member) => {
            let of_type: Vec<&(String, String)> = files
                .filter(|(_, text)| {
                    declares_type(text, ty)
                        || text.lines().any(|l| has_word(l, "impl") && has_word(l, ty))
                })
                .collect();
            of_type.iter().any(|(_, text)| declares_type(text, ty))
                && of_type
                    .iter()
                    .any(|(_, text)| declares_member(text, member))
        }
    }
}

/// The architecture map stays true: every path it names exists, every
/// source file of the crates' `src/`, `benches/` and `tests/` is named
/// (the map's conventions are at its top), and every item it names
/// (`Type`, `Type::member`, `module::item`, `function()`) is declared in
/// the sources.
#[test]
fn the_architecture_map_is_true() {
    let root = root();
    let map = fs::read_to_string(root.join("docs/architecture.md")).expect("docs/architecture.md");
    let sources = sources();
    let mut named = std::collections::BTreeSet::new();
    let mut problems = Vec::new();
    for n in map_names(&map) {
        if looks_like_path(&n.text) {
            match resolve(n.section.as_deref(), &n.text) {
                Some(path) => {
                    named.insert(path);
                }
                None => problems.push(format!(
                    "docs/architecture.md:{}: `{}` is no file or directory{}",
                    n.line,
                    n.text,
                    n.section
                        .as_deref()
                        .map(|s| format!(" (in {s}'s section)"))
                        .unwrap_or_default()
                )),
            }
        } else if let Some((krate, modules, item)) = parse_item(&n.text)
            && !item_exists(&sources, krate.as_deref(), &modules, &item)
        {
            problems.push(format!(
                "docs/architecture.md:{}: `{}` names no item in the sources ({item:?})",
                n.line, n.text
            ));
        }
    }
    for (path, _) in &sources {
        let parts: Vec<&str> = path.split('/').collect();
        let source = matches!(
            parts.as_slice(),
            ["crates", _, "src", ..] | ["benches" | "tests", _]
        );
        if source && !named.contains(path) {
            problems.push(format!(
                "docs/architecture.md names no `{path}`: add it to its crate's section"
            ));
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}
