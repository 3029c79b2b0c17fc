//! The OBJ reader and the scene built from it, both up axes.
#![no_main]

use libfuzzer_sys::fuzz_target;
use sunlit::model::obj::ObjUp;
use sunlit::model::{LoadOptions, load_bytes};

fuzz_target!(|data: &[u8]| {
    for up in [ObjUp::Y, ObjUp::Z] {
        let _ = load_bytes(&[("fuzz.obj".to_string(), data.to_vec())], &LoadOptions { up, ..Default::default() });
    }
});
