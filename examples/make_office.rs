//! Writes the example office model (see `sunlit::model::office`) as a GLB file.
//!
//! ```text
//! cargo run --example make_office -- [OUT.glb] [--louvres N]
//! ```
//! Defaults: `examples/office.glb`, 6 louvres.

use std::error::Error;
use std::path::PathBuf;

fn main() -> Result<(), Box<dyn Error>> {
    let mut out = PathBuf::from("examples/office.glb");
    let mut louvres = 6usize;
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--louvres" => {
                let n = args.next().ok_or("--louvres needs a number")?;
                louvres = n.parse().map_err(|e| format!("--louvres '{n}': {e}"))?;
            }
            "-h" | "--help" => {
                println!("usage: make_office [OUT.glb] [--louvres N]   (default examples/office.glb, 6 louvres)");
                return Ok(());
            }
            other if other.starts_with('-') => return Err(format!("unknown option '{other}'").into()),
            path => out = PathBuf::from(path),
        }
    }

    let model = sunlit::model::office::office(louvres);
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)?;
    }
    std::fs::write(&out, model.to_glb()).map_err(|e| format!("{}: {e}", out.display()))?;
    println!("wrote {} ({} nodes)", out.display(), model.node_count());
    Ok(())
}
