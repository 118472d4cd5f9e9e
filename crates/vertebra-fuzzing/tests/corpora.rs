//! Replays every seed and corpus file of `fuzz/corpus/<target>/` through
//! its target on the stable toolchain, so CI checks what fuzzing found.

use std::path::Path;

use vertebra_fuzzing::TARGETS;

#[test]
fn every_corpus_file_replays_cleanly() {
    let corpora = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/corpus");
    for (name, target) in TARGETS {
        let dir = corpora.join(name);
        let mut files: Vec<_> = std::fs::read_dir(&dir)
            .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
            .map(|entry| entry.expect("a directory entry").path())
            .collect();
        files.sort();
        assert!(!files.is_empty(), "{name} has no seed corpus");
        for file in &files {
            let data = std::fs::read(file).expect("a corpus file");
            target(&data);
        }
        eprintln!("{name}: {} files replayed", files.len());
    }
}
