//! docs/engine-integration.md's Bevy snippet is `examples/minimal.rs` (from its first `use` to
//! the end), so the snippet compiles with the crate's examples (the block is `ignore` for
//! dcr-rapier's doctests of the guide, which have no bevy).

#[test]
fn the_bevy_snippet_is_the_minimal_example() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let doc = std::fs::read_to_string(root.join("../../docs/engine-integration.md")).unwrap();
    let example = std::fs::read_to_string(root.join("examples/minimal.rs")).unwrap();
    let start = example.find("\nuse ").expect("the example has `use` lines") + 1;
    // `ignore`: the guide's Rust blocks are also dcr-rapier's doctests, which have no bevy.
    let snippet = format!("```rust,ignore\n{}```\n", &example[start..]);
    assert!(
        doc.contains(&snippet),
        "docs/engine-integration.md (section \"Bevy\") must hold examples/minimal.rs from its \
         first `use` to the end, in a ```rust,ignore block: copy it there"
    );
}
