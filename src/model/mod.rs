//! Model readers and writers: glTF/glb in, glb out (examples, benchmarks, tests).
//!
//! Owns the choice of receivers across all input files: `--receivers GLOB` (node names,
//! case-insensitive) when given; otherwise the nodes marked `{"sunlit": {"receiver": true}}` in
//! their extras, if any file marks one; otherwise every named node with a mesh.
pub mod glb_write;
pub mod gltf_read;
pub mod office;

use std::path::PathBuf;

use crate::error::{Error, Result};
use crate::scene::{Scene, SceneBuilder};
use gltf_read::{GltfModel, GltfNode};

/// How to read models into a scene.
#[derive(Debug, Clone, Default)]
pub struct LoadOptions {
    /// Glob patterns over node names; empty means "use the marks, else every named node".
    pub receivers: Vec<String>,
    /// Degrees clockwise from true north of the model's north (−Z in glTF), as EnergyPlus's
    /// Building North Axis.
    pub north: f64,
}

/// Reads model files into one scene.
pub fn load(paths: &[PathBuf], options: &LoadOptions) -> Result<Scene> {
    check_options(options)?;
    let models = paths.iter().map(|p| gltf_read::read_path(p, options.north)).collect::<Result<Vec<_>>>()?;
    build(models, options)
}

/// Reads in-memory model files (name, bytes) into one scene (the web path).
pub fn load_bytes(files: &[(String, Vec<u8>)], options: &LoadOptions) -> Result<Scene> {
    check_options(options)?;
    let models = files.iter().map(|(n, b)| gltf_read::read_bytes(n, b, options.north)).collect::<Result<Vec<_>>>()?;
    build(models, options)
}

fn check_options(options: &LoadOptions) -> Result<()> {
    if !options.north.is_finite() {
        return Err(Error::argument("--north", format!("{} is not a finite angle", options.north)));
    }
    Ok(())
}

fn build(models: Vec<GltfModel>, options: &LoadOptions) -> Result<Scene> {
    let select = Selection::new(&models, options)?;
    let mut builder = SceneBuilder::new();
    let mut matched = 0usize;
    for model in models {
        model.add_to(&mut builder, |n| {
            let hit = select.is_receiver(n);
            matched += hit as usize;
            hit
        });
    }
    if matched == 0 {
        return Err(Error::NoReceivers(select.explain()));
    }
    builder.build()
}

/// The receiver rule in force for one load.
enum Selection {
    Globs(globset::GlobSet, Vec<String>),
    Marked,
    Named,
}

impl Selection {
    fn new(models: &[GltfModel], options: &LoadOptions) -> Result<Self> {
        if !options.receivers.is_empty() {
            let mut set = globset::GlobSetBuilder::new();
            for pattern in &options.receivers {
                let glob = globset::GlobBuilder::new(pattern)
                    .case_insensitive(true)
                    .build()
                    .map_err(|e| Error::argument("--receivers", format!("'{pattern}': {e}")))?;
                set.add(glob);
            }
            let set = set.build().map_err(|e| Error::argument("--receivers", e.to_string()))?;
            return Ok(Selection::Globs(set, options.receivers.clone()));
        }
        let any_marked = models.iter().any(|m| m.nodes.iter().any(|n| n.marked));
        Ok(if any_marked { Selection::Marked } else { Selection::Named })
    }

    fn is_receiver(&self, node: &GltfNode) -> bool {
        match self {
            Selection::Globs(set, _) => set.is_match(&node.name),
            Selection::Marked => node.marked,
            Selection::Named => node.named,
        }
    }

    fn explain(&self) -> String {
        match self {
            Selection::Globs(_, p) => format!("no node name matches --receivers {}", p.join(", ")),
            Selection::Marked => "no node is marked as a receiver".into(),
            Selection::Named => "the models have no named node with a mesh (name nodes, mark them in extras, or use --receivers)".into(),
        }
    }
}
