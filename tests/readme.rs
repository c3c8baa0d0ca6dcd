//! The README's Rust quick start is the crate's front-page doctest, line for line: the doctest
//! runs it (`cargo test --doc`), this keeps the two from drifting apart.

#[test]
fn the_readme_rust_quick_start_is_the_tested_front_page_example() {
    let readme = include_str!("../README.md");
    let start = readme.find("```rust\n").expect("a Rust block in the README") + "```rust\n".len();
    let block = &readme[start..start + readme[start..].find("```").unwrap()];
    let front: Vec<&str> = include_str!("../src/lib.rs")
        .lines()
        .filter_map(|l| l.strip_prefix("//! ").or_else(|| l.strip_prefix("//!")))
        .collect();
    let at = front
        .iter()
        .position(|l| *l == block.lines().next().unwrap())
        .expect("the first README line in the front page");
    for (i, line) in block.lines().enumerate() {
        assert_eq!(
            front.get(at + i).copied(),
            Some(line),
            "README line {i} differs from src/lib.rs's front page"
        );
    }
}
