//! The glTF/glb reader and the scene built from it: any bytes give a scene or an error, never a
//! panic, a hang or an allocation out of proportion to the input.
#![no_main]

use libfuzzer_sys::fuzz_target;
use sunlit::model::{LoadOptions, load_bytes};

fuzz_target!(|data: &[u8]| {
    let _ = load_bytes(&[("fuzz.glb".to_string(), data.to_vec())], &LoadOptions::default());
});
