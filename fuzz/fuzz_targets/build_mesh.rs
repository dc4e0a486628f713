//! Half-edge mesh building on arbitrary polygon soups (unprepared: repeated corners,
//! non-manifold edges, mixed orientation, unused vertices), which must be refused with
//! an error, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Some(polys) = unfold_fuzz::soup_from_bytes(data) {
        if let Ok((mesh, _)) = unfold::mesh::build_mesh(&polys, None, None) {
            let _ = mesh.topology();
        }
    }
});
