//! Bytes → `input::read_points`: the first byte picks the hint (ply, xyz, pwn, or none so the content
//! is sniffed), the rest is the file. Any file may be refused; none may panic, hang or allocate
//! by a count its header claims. A cloud that is read has one unit normal per point (the reader
//! normalises them), which is what reconstruction relies on.
#![no_main]

use isoforge::input;
use libfuzzer_sys::fuzz_target;

const HINTS: [Option<&str>; 4] = [Some("ply"), Some("xyz"), Some("pwn"), None];

fuzz_target!(|data: &[u8]| {
    let Some((&first, file)) = data.split_first() else { return };
    let hint = HINTS[first as usize % HINTS.len()];
    if let Ok(cloud) = input::read_points(file, hint) {
        assert!(!cloud.is_empty(), "read_points returned no points");
        assert_eq!(cloud.positions.len(), cloud.normals.len(), "points and normals differ in number");
        for n in &cloud.normals {
            assert!(n.is_finite() && (n.length() - 1.0).abs() <= 1e-3, "normal {n} is not a unit vector");
        }
    }
});
