//! Bytes → `input::read_mesh`: the first byte picks the format hint (obj, stl, ply, off, or none
//! so the content is sniffed), the rest is the file. Any file may be refused; none may panic,
//! hang or allocate by a count its header claims. A mesh that is read must be one the pipeline
//! can index blindly: triangles present, every index in range, no triangle repeating a vertex
//! (the readers drop those, see `input`'s docs).
#![no_main]

use isoforge::input;
use libfuzzer_sys::fuzz_target;

const HINTS: [Option<&str>; 5] = [Some("obj"), Some("stl"), Some("ply"), Some("off"), None];

fuzz_target!(|data: &[u8]| {
    let Some((&first, file)) = data.split_first() else { return };
    let hint = HINTS[first as usize % HINTS.len()];
    if let Ok(mesh) = input::read_mesh(file, hint) {
        assert!(!mesh.triangles.is_empty(), "read_mesh returned no triangles");
        let n = mesh.positions.len();
        for t in &mesh.triangles {
            assert!(t.iter().all(|&v| (v as usize) < n), "triangle {t:?} indexes past {n} vertices");
            assert!(t[0] != t[1] && t[1] != t[2] && t[0] != t[2], "triangle {t:?} repeats a vertex");
        }
    }
});
