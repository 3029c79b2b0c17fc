//! The IDF reader and the building geometry read from its objects.
#![no_main]

use libfuzzer_sys::fuzz_target;
use sunlit::model::{LoadOptions, load_bytes};

fuzz_target!(|data: &[u8]| {
    let _ = load_bytes(&[("fuzz.idf".to_string(), data.to_vec())], &LoadOptions::default());
});
