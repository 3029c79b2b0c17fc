//! Every WGSL file in shaders/ parses and validates with naga (the same front end wgpu uses), and
//! the library embeds exactly those files, but for the page's viewer shader, which
//! scripts/build-web.sh copies into www/pkg for the browser to load.

#![allow(clippy::unwrap_used, clippy::expect_used)] // Tests may panic on the unexpected.

use std::fs;

/// Shaders the page loads itself (not part of the counting pass).
const PAGE_SHADERS: [&str; 1] = ["viewer.wgsl"];

#[test]
fn wgsl_parses_and_validates() {
    let mut seen = 0;
    for entry in fs::read_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/shaders")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("wgsl") {
            continue;
        }
        let source = fs::read_to_string(&path).unwrap();
        let module = naga::front::wgsl::parse_str(&source).unwrap_or_else(|e| panic!("{}: {}", path.display(), e.emit_to_string(&source)));
        naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::empty())
            .validate(&module)
            .unwrap_or_else(|e| panic!("{}: {}", path.display(), e.emit_to_string(&source)));
        let name = path.file_name().unwrap().to_str().unwrap();
        if PAGE_SHADERS.contains(&name) {
            continue;
        }
        let embedded = sunlit::count::gpu::SHADERS.iter().find(|(n, _)| *n == name).map(|(_, s)| *s);
        assert_eq!(embedded, Some(source.as_str()), "{name} is the source the library embeds");
        seen += 1;
    }
    assert_eq!(seen, sunlit::count::gpu::SHADERS.len());
}
