//! The OBJ reader, preparation and mesh building on arbitrary bytes.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    unfold_fuzz::read_and_prepare(unfold::mesh::Format::Obj, data);
});
