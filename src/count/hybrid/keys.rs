//! Where a [`Profile`] is kept and what it belongs to: the keys that name a scene, a kind of
//! views, a device and its threads; pinned profile files; the per-device cache file.

use std::path::{Path, PathBuf};

use super::*;

/// The scene's size, as a profile's key names it: a profile is measured on the model's own
/// views, and its loads cost differently per model (leaves overlap far more than slats).
pub fn scene_key(scene: &Scene) -> String {
    format!("scene {} triangles, {} receivers", scene.triangle_count(), scene.receivers.len())
}

/// The scene's key ([`scene_key`]) for a kind of views: sun views' is the scene's alone (as
/// profiles kept before sky views were priced apart), sky views' says so.
pub fn views_key(scene: &Scene, views: ViewKind) -> String {
    match views {
        ViewKind::Sun => scene_key(scene),
        ViewKind::Sky => format!("{}; sky views", scene_key(scene)),
    }
}

/// The file that pins a kind of views' profile, given the file named for the run: that file for
/// sun views, for sky views the same name with `.sky` before its extension (`p.json` →
/// `p.sky.json`), so a pinned run pins both kinds and neither is routed by the other's prices.
pub fn profile_file(path: &Path, views: ViewKind) -> PathBuf {
    match views {
        ViewKind::Sun => path.to_path_buf(),
        ViewKind::Sky => {
            let stem = path.file_stem().map_or_else(String::new, |s| s.to_string_lossy().into_owned());
            let name = match path.extension() {
                Some(ext) => format!("{stem}.sky.{}", ext.to_string_lossy()),
                None => format!("{stem}.sky"),
            };
            path.with_file_name(name)
        }
    }
}

/// The clipping threads and tile side (with the accuracy, if any) of a profile's key.
fn threads_and_side(options: &CounterOptions, threads: usize) -> String {
    let accuracy = options.accuracy.map_or(String::new(), |a| format!(" ±{a}"));
    format!("{threads} CPU threads; {}²{accuracy}", options.resolution)
}

/// The key of a profile that never needs the GPU (no view was worth its start-up): the clipping
/// threads and the tile side, without the adapter, since asking for one costs a small model a
/// third of its run (on lavapipe: loading the driver). `None` for a side outside what every
/// adapter renders (wgpu's downlevel minimum), which only the adapter can check.
pub fn cpu_key(options: &CounterOptions, threads: usize) -> Option<String> {
    let every_adapter = 16..=wgpu::Limits::downlevel_defaults().max_texture_dimension_2d;
    every_adapter.contains(&options.resolution).then(|| format!("exact only; {}", threads_and_side(options, threads)))
}

/// An adapter as a profile's key names it: name, backend and driver.
pub fn adapter_key(info: &wgpu::AdapterInfo) -> String {
    format!("{} ({:?}, {} {})", info.name, info.backend, info.driver, info.driver_info)
}

/// The key of a profile measured with `adapter` (None: no GPU adapter) and `threads` clipping
/// threads at `options`' side: adapter, driver, threads and side.
pub fn adapter_threads_key(adapter: Option<&wgpu::AdapterInfo>, options: &CounterOptions, threads: usize) -> String {
    let adapter = adapter.map_or_else(|| "no GPU adapter".to_string(), adapter_key);
    format!("{adapter}; {}", threads_and_side(options, threads))
}

/// What identifies the device a profile belongs to: adapter, driver, CPU threads and tile side.
/// Refuses a side the adapter cannot render, as the GPU would (without making a device).
pub async fn device_key(options: &CounterOptions) -> Result<String> {
    let resolution = options.resolution;
    let info = match platform::instance().request_adapter(&wgpu::RequestAdapterOptions::default()).await {
        Ok(a) => {
            let limit = a.limits().max_texture_dimension_2d;
            if !(16..=limit).contains(&resolution) {
                return Err(Error::argument(
                    "resolution",
                    format!("{resolution} is outside 16..={limit} (this device's texture size limit)"),
                ));
            }
            Some(a.get_info())
        }
        Err(_) => None,
    };
    Ok(adapter_threads_key(info.as_ref(), options, cpu_threads()))
}

/// A profile's text (JSON, as [`write_profile`] writes it) for the device and scene `keys` name
/// (the adapter's key and the exact-only key, each with the scene's size): refused, naming
/// `source` and the reason, when it does not parse or was measured for another model or device.
pub fn profile_for(text: &str, source: &str, keys: &[&str]) -> Result<Profile> {
    let profile: Profile =
        serde_json::from_str(text).map_err(|e| Error::argument("engine profile", format!("{source} is not a profile: {e}")))?;
    if !keys.contains(&profile.device.as_str()) {
        return Err(Error::argument(
            "engine profile",
            format!("{source} was measured for '{}', not this model and device ('{}')", profile.device, keys.first().unwrap_or(&"")),
        ));
    }
    Ok(profile)
}

/// Reads a profile file.
pub fn read_profile(path: &Path) -> Result<Profile> {
    let text = std::fs::read_to_string(path).map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
    serde_json::from_str(&text).map_err(|e| Error::argument("engine profile", format!("{}: {e}", path.display())))
}

/// Writes a profile file (atomically).
pub fn write_profile(path: &Path, profile: &Profile) -> Result<()> {
    let text = serde_json::to_string_pretty(profile).map_err(|e| Error::argument("engine profile", e.to_string()))?;
    crate::export::write_atomic(path, text.as_bytes())
}

/// The per-device cache: `$XDG_CACHE_HOME/sunlit/engine-profiles.json` (else `~/.cache/…`).
fn cache_file() -> Option<PathBuf> {
    if cfg!(target_arch = "wasm32") {
        return None;
    }
    let base = std::env::var_os("XDG_CACHE_HOME")
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))?;
    Some(base.join("sunlit").join("engine-profiles.json"))
}

pub(super) fn cached(key: &str) -> Option<Profile> {
    let text = std::fs::read_to_string(cache_file()?).ok()?;
    let all: std::collections::BTreeMap<String, Profile> = serde_json::from_str(&text).ok()?;
    all.get(key).cloned()
}

/// Adds a profile to the cache; a cache that cannot be written only costs a probe next time.
pub(super) fn store_cached(key: &str, profile: &Profile) {
    let Some(path) = cache_file() else { return };
    let mut all: std::collections::BTreeMap<String, Profile> =
        std::fs::read_to_string(&path).ok().and_then(|t| serde_json::from_str(&t).ok()).unwrap_or_default();
    all.insert(key.to_string(), profile.clone());
    let written = path.parent().map(std::fs::create_dir_all).transpose().ok().and_then(|_| serde_json::to_string_pretty(&all).ok());
    if let Some(text) = written
        && let Err(e) = crate::export::write_atomic(&path, text.as_bytes())
    {
        log::warn!("could not cache the engine profile in {}: {e}", path.display());
    }
}
