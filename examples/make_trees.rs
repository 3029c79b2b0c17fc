//! Writes the street-trees benchmark model (`sunlit::bench::street_trees_glb`): a three-storey
//! facade behind five trees whose crowns hold LEAVES leaves between them, marked as foliage.
//!
//! `cargo run --release --example make_trees -- LEAVES OUT.glb`

use std::process::ExitCode;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (Some(leaves), Some(out)) = (args.first().and_then(|n| n.parse::<usize>().ok()), args.get(1)) else {
        eprintln!("usage: make_trees LEAVES OUT.glb");
        return ExitCode::FAILURE;
    };
    match std::fs::write(out, sunlit::bench::street_trees_glb(leaves, 11)) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {out}: {e}");
            ExitCode::FAILURE
        }
    }
}
