//! Writes the EnergyPlus one-zone office (see `sunlit::model::office_idf`) as an IDF file.
//!
//! ```text
//! cargo run --example make_office_idf -- OUT.idf [--louvres N] [--concave] [--no-shading-calculation]
//! ```
//! Defaults: 10 louvres, convex casters, EnergyPlus's PolygonClipping with eplusshading.csv output.

use std::error::Error;
use std::path::PathBuf;

use sunlit::model::office_idf::{Shading, office_idf};

fn main() -> Result<(), Box<dyn Error>> {
    let mut out: Option<PathBuf> = None;
    let (mut louvres, mut concave, mut shading) = (10usize, false, Shading::PolygonClipping);
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--louvres" => {
                let n = args.next().ok_or("--louvres needs a number")?;
                louvres = n.parse().map_err(|e| format!("--louvres '{n}': {e}"))?;
            }
            "--concave" => concave = true,
            "--no-shading-calculation" => shading = Shading::None,
            other if other.starts_with('-') => return Err(format!("unknown option '{other}'").into()),
            path => out = Some(PathBuf::from(path)),
        }
    }
    let out = out.ok_or("usage: make_office_idf OUT.idf [--louvres N] [--concave] [--no-shading-calculation]")?;
    std::fs::write(&out, office_idf(louvres, concave, shading)).map_err(|e| format!("{}: {e}", out.display()))?;
    println!("wrote {}", out.display());
    Ok(())
}
