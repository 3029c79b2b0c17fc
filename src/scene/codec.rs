//! A compact binary encoding of a [`Scene`]: a scene built once (model files read, glTF parsed,
//! meshes merged and instanced, receivers split, veils set) can be handed as bytes to another
//! process or wasm instance, which rebuilds the same scene without reading the model again. The
//! page's clipping workers get their scene this way from the engine's instance
//! (docs/page-speed.md): a worker then skips the glTF parse and its memory.
//!
//! Layout, all little-endian: the magic `SUNLITSC`, the format's version (u32), then the meshes,
//! the instances, the receivers and the scene's totals, each list preceded by its length (u64).
//! Floats are stored bit for bit, so a decoded scene gives the same fractions as the original.
//!
//! Decoding trusts nothing: truncated bytes, another version, a list longer than the bytes left,
//! an index past its list, a non-finite coordinate or trailing bytes are each a
//! [`SceneBytesError`], and no length read from the bytes is allocated before the bytes are
//! known to hold it.

use std::ops::Range;

use glam::{DMat4, DVec3};

use super::{Instance, Mesh, NO_RECEIVER, Receiver, ReceiverDraw, Scene, Veil};
use crate::error::{Error, Result, SceneBytesError};

/// The first bytes of an encoded scene.
pub const MAGIC: [u8; 8] = *b"SUNLITSC";
/// The format's version; bytes of any other version are refused.
pub const VERSION: u32 = 2;

/// How a mesh's indices are stored: each one, or only their count when they are 0, 1, 2, ….
const INDICES_LISTED: u8 = 0;
const INDICES_IDENTITY: u8 = 1;

impl Scene {
    /// The scene as bytes ([`Scene::from_bytes`] reads them back; see the module doc).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut w = Writer(Vec::with_capacity(self.encoded_size_hint()));
        w.0.extend_from_slice(&MAGIC);
        w.u32(VERSION);
        w.len(self.meshes.len());
        for mesh in &self.meshes {
            write_mesh(&mut w, mesh);
        }
        w.len(self.instances.len());
        for inst in &self.instances {
            w.len(inst.mesh);
            w.f64s(&inst.transform.to_cols_array());
            w.u32(inst.receiver_base);
            w.f32(inst.leaf_shift);
        }
        w.len(self.receivers.len());
        for r in &self.receivers {
            write_receiver(&mut w, r);
        }
        w.vec3(self.bounds.0);
        w.vec3(self.bounds.1);
        w.vec3(self.origin);
        w.len(self.leaves);
        w.len(self.see_through_triangles);
        w.0
    }

    /// The scene encoded in `bytes` by [`Scene::to_bytes`]; refuses bytes that are not one, in
    /// another version, truncated or inconsistent ([`Error::SceneBytes`]).
    pub fn from_bytes(bytes: &[u8]) -> Result<Scene> {
        decode(bytes).map_err(Error::SceneBytes)
    }

    fn encoded_size_hint(&self) -> usize {
        let meshes: usize = self.meshes.iter().map(|m| 12 * m.positions.len() + 64).sum();
        meshes + 144 * self.instances.len() + 256 * self.receivers.len() + 128
    }
}

fn write_mesh(w: &mut Writer, mesh: &Mesh) {
    w.str(&mesh.label);
    w.len(mesh.positions.len());
    for p in &mesh.positions {
        p.iter().for_each(|&x| w.f32(x));
    }
    // Surfaces and veils come in long runs (a receiver's vertices, a node's), and a merged mesh's
    // indices are often 0, 1, 2, …: stored as such, nyt-blocks' scene takes 95 MB, not 252 MB.
    w.runs(&mesh.surfaces, |w, &s| w.u32(s));
    if mesh.indices.iter().enumerate().all(|(i, &v)| v as usize == i) {
        w.0.push(INDICES_IDENTITY);
        w.len(mesh.indices.len());
    } else {
        w.0.push(INDICES_LISTED);
        w.u32s(&mesh.indices);
    }
    w.runs(&mesh.veils, |w, v| {
        w.f32(v.rank);
        w.f32(v.transmittance);
        w.u32(v.seed);
    });
    w.u32s(&mesh.cast_parts.iter().flat_map(|r| [r.start, r.end]).collect::<Vec<_>>());
}

fn write_receiver(w: &mut Writer, r: &Receiver) {
    w.str(&r.name);
    w.str(&r.origin);
    w.len(r.triangles.len());
    for t in &r.triangles {
        t.iter().for_each(|&p| w.vec3(p));
    }
    w.vec3(r.normal);
    w.f64(r.area);
    w.len(r.draw.instance);
    w.u32(r.draw.indices.start);
    w.u32(r.draw.indices.end);
    w.u32(r.gpu_id);
}

/// Appends little-endian values (also [`crate::count::exact::engine::ExactEngine::objects_bytes`]).
pub(crate) struct Writer(pub(crate) Vec<u8>);

impl Writer {
    pub(crate) fn u32(&mut self, x: u32) {
        self.0.extend_from_slice(&x.to_le_bytes());
    }
    fn f32(&mut self, x: f32) {
        self.0.extend_from_slice(&x.to_le_bytes());
    }
    fn f64(&mut self, x: f64) {
        self.0.extend_from_slice(&x.to_le_bytes());
    }
    pub(crate) fn len(&mut self, n: usize) {
        self.0.extend_from_slice(&(n as u64).to_le_bytes());
    }
    /// `xs` as runs of equal items: the run count, then each run's length (u64) and item.
    /// Equal means the same bytes, so a run loses nothing (not even a NaN's or a −0's bits).
    fn runs<T>(&mut self, xs: &[T], item: impl Fn(&mut Writer, &T)) {
        let mut runs: Vec<(usize, usize)> = Vec::new();
        let (mut this, mut last) = (Writer(Vec::new()), Vec::new());
        for (i, x) in xs.iter().enumerate() {
            this.0.clear();
            item(&mut this, x);
            if i > 0 && this.0 == last {
                if let Some(run) = runs.last_mut() {
                    run.1 += 1;
                }
            } else {
                runs.push((i, 1));
                std::mem::swap(&mut last, &mut this.0);
            }
        }
        self.len(runs.len());
        for (start, n) in runs {
            self.len(n);
            item(self, &xs[start]);
        }
    }
    pub(crate) fn u32s(&mut self, xs: &[u32]) {
        self.len(xs.len());
        self.0.reserve(4 * xs.len());
        xs.iter().for_each(|&x| self.u32(x));
    }
    fn f64s(&mut self, xs: &[f64]) {
        xs.iter().for_each(|&x| self.f64(x));
    }
    fn vec3(&mut self, p: DVec3) {
        self.f64s(&p.to_array());
    }
    fn str(&mut self, s: &str) {
        self.len(s.len());
        self.0.extend_from_slice(s.as_bytes());
    }
}

pub(crate) type Decoded<T> = std::result::Result<T, SceneBytesError>;

fn decode(bytes: &[u8]) -> Decoded<Scene> {
    let mut r = Reader { bytes, at: 0 };
    if r.take(MAGIC.len(), "magic").ok() != Some(&MAGIC[..]) {
        return Err(SceneBytesError::NotAScene);
    }
    let version = r.u32("version")?;
    if version != VERSION {
        return Err(SceneBytesError::Version { found: version, supported: VERSION });
    }
    let count = r.count("meshes", 41)?;
    let meshes = (0..count).map(|i| read_mesh(&mut r, i)).collect::<Decoded<Vec<_>>>()?;
    let count = r.count("instances", 144)?;
    let instances = (0..count).map(|_| read_instance(&mut r)).collect::<Decoded<Vec<_>>>()?;
    let count = r.count("receivers", 76)?;
    let receivers = (0..count).map(|_| read_receiver(&mut r)).collect::<Decoded<Vec<_>>>()?;
    let bounds = (r.vec3("bounds")?, r.vec3("bounds")?);
    let origin = r.vec3("origin")?;
    let leaves = r.index("leaves")?;
    let see_through_triangles = r.index("see-through triangles")?;
    if r.at != bytes.len() {
        return Err(SceneBytesError::TrailingBytes { extra: bytes.len() - r.at });
    }
    let scene = Scene { meshes, instances, receivers, bounds, origin, leaves, see_through_triangles };
    check(&scene)?;
    Ok(scene)
}

fn read_mesh(r: &mut Reader, index: usize) -> Decoded<Mesh> {
    let label = r.str("mesh label")?;
    let count = r.count("mesh positions", 12)?;
    let positions = (0..count).map(|_| Ok([r.f32("positions")?, r.f32("positions")?, r.f32("positions")?])).collect::<Decoded<Vec<_>>>()?;
    let vertices = positions.len();
    let what = || format!("mesh {index}");
    let surfaces = r.runs("mesh surfaces", 12, vertices, what, |r| r.u32("mesh surfaces"))?;
    let indices = match r.take(1, "mesh indices")?[0] {
        INDICES_LISTED => r.u32s("mesh indices")?,
        INDICES_IDENTITY => match r.index("mesh indices")? {
            n if n <= vertices => (0..n as u32).collect(),
            n => return Err(invalid(what(), format!("indices 0 to {n} past its {vertices} vertices"))),
        },
        tag => return Err(invalid(what(), format!("unknown index layout {tag}"))),
    };
    let veils = r.runs("mesh veils", 20, vertices, what, |r| {
        Ok(Veil { rank: r.f32("mesh veils")?, transmittance: r.f32("mesh veils")?, seed: r.u32("mesh veils")? })
    })?;
    let ends = r.u32s("mesh cast parts")?;
    if ends.len() % 2 == 1 {
        return Err(invalid(what(), format!("{} cast part ends, an odd number", ends.len())));
    }
    let cast_parts = ends.chunks_exact(2).map(|e| e[0]..e[1]).collect();
    Ok(Mesh { label, positions, surfaces, indices, veils, cast_parts })
}

fn read_instance(r: &mut Reader) -> Decoded<Instance> {
    let mesh = r.index("instance mesh")?;
    let mut cols = [0.0; 16];
    for c in &mut cols {
        *c = r.f64("instance transform")?;
    }
    let transform = DMat4::from_cols_array(&cols);
    Ok(Instance { mesh, transform, receiver_base: r.u32("instance receiver base")?, leaf_shift: r.f32("instance leaf shift")? })
}

fn read_receiver(r: &mut Reader) -> Decoded<Receiver> {
    let name = r.str("receiver name")?;
    let origin = r.str("receiver origin")?;
    let count = r.count("receiver triangles", 72)?;
    let triangles = (0..count)
        .map(|_| Ok([r.vec3("receiver triangles")?, r.vec3("receiver triangles")?, r.vec3("receiver triangles")?]))
        .collect::<Decoded<Vec<_>>>()?;
    let normal = r.vec3("receiver normal")?;
    let area = r.f64("receiver area")?;
    let instance = r.index("receiver draw")?;
    let indices = r.u32("receiver draw")?..r.u32("receiver draw")?;
    let gpu_id = r.u32("receiver id")?;
    Ok(Receiver { name, origin, triangles, normal, area, draw: ReceiverDraw { instance, indices }, gpu_id })
}

/// What the engines index without checking: every index within its list, every coordinate finite.
fn check(scene: &Scene) -> Decoded<()> {
    let mut top_surface = Vec::with_capacity(scene.meshes.len());
    for (i, m) in scene.meshes.iter().enumerate() {
        let what = || format!("mesh {i} ('{}')", m.label);
        if m.surfaces.len() != m.positions.len() {
            return Err(invalid(what(), format!("{} surface values for {} vertices", m.surfaces.len(), m.positions.len())));
        }
        if m.indices.len() % 3 != 0 {
            return Err(invalid(what(), format!("{} indices, not whole triangles", m.indices.len())));
        }
        if let Some(&v) = m.indices.iter().find(|&&v| v as usize >= m.positions.len()) {
            return Err(invalid(what(), format!("index {v} past its {} vertices", m.positions.len())));
        }
        if m.positions.iter().flatten().any(|x| !x.is_finite()) {
            return Err(invalid(what(), "a vertex that is not finite"));
        }
        if let Some(r) = m.cast_parts.iter().find(|r| !in_range(r, m.indices.len() / 3)) {
            return Err(invalid(what(), format!("cast part {r:?} past its {} triangles", m.indices.len() / 3)));
        }
        top_surface.push(m.surfaces.iter().copied().filter(|&s| s != NO_RECEIVER).max());
    }
    let receivers = scene.receivers.len() as u64;
    for (i, inst) in scene.instances.iter().enumerate() {
        let what = || format!("instance {i}");
        let Some(&top) = top_surface.get(inst.mesh) else {
            return Err(invalid(what(), format!("mesh {} of {}", inst.mesh, scene.meshes.len())));
        };
        if inst.transform.to_cols_array().iter().any(|x| !x.is_finite()) || !inst.leaf_shift.is_finite() {
            return Err(invalid(what(), "a transform that is not finite"));
        }
        let highest = top.filter(|_| inst.receiver_base != NO_RECEIVER).map(|top| u64::from(inst.receiver_base) + u64::from(top));
        if let Some(id) = highest.filter(|&id| id >= receivers) {
            return Err(invalid(what(), format!("receiver {id} of {receivers}")));
        }
    }
    for (i, r) in scene.receivers.iter().enumerate() {
        let what = || format!("receiver {i} ('{}')", r.name);
        let Some(inst) = scene.instances.get(r.draw.instance) else {
            return Err(invalid(what(), format!("drawn by instance {} of {}", r.draw.instance, scene.instances.len())));
        };
        let indices = scene.meshes[inst.mesh].indices.len();
        if !in_range(&r.draw.indices, indices) {
            return Err(invalid(what(), format!("index range {:?} of {indices}", r.draw.indices)));
        }
        if u64::from(r.gpu_id) >= receivers {
            return Err(invalid(what(), format!("id {} of {receivers}", r.gpu_id)));
        }
        let finite = r.triangles.iter().flatten().chain([&r.normal]).all(|p| p.is_finite()) && r.area.is_finite();
        if !finite {
            return Err(invalid(what(), "a coordinate that is not finite"));
        }
    }
    if ![scene.bounds.0, scene.bounds.1, scene.origin].iter().all(|p| p.is_finite()) {
        return Err(invalid("the scene's bounds", "a coordinate that is not finite"));
    }
    Ok(())
}

pub(crate) fn in_range(range: &Range<u32>, len: usize) -> bool {
    range.start <= range.end && range.end as usize <= len
}

pub(crate) fn invalid(what: impl Into<String>, reason: impl Into<String>) -> SceneBytesError {
    SceneBytesError::Invalid { what: what.into(), reason: reason.into() }
}

/// Reads what [`Writer`] wrote, refusing what runs past the bytes.
pub(crate) struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    pub(crate) fn new(bytes: &'a [u8]) -> Self {
        Self { bytes, at: 0 }
    }
    /// Refuses bytes left after what was read.
    pub(crate) fn end(&self) -> Decoded<()> {
        match self.bytes.len() - self.at {
            0 => Ok(()),
            extra => Err(SceneBytesError::TrailingBytes { extra }),
        }
    }
    pub(crate) fn take(&mut self, n: usize, reading: &'static str) -> Decoded<&'a [u8]> {
        let left = self.bytes.len() - self.at;
        if n > left {
            return Err(SceneBytesError::Truncated { reading, offset: self.at, need: n, left });
        }
        let out = &self.bytes[self.at..self.at + n];
        self.at += n;
        Ok(out)
    }
    fn array<const N: usize>(&mut self, reading: &'static str) -> Decoded<[u8; N]> {
        let mut out = [0u8; N];
        out.copy_from_slice(self.take(N, reading)?);
        Ok(out)
    }
    pub(crate) fn u32(&mut self, reading: &'static str) -> Decoded<u32> {
        Ok(u32::from_le_bytes(self.array(reading)?))
    }
    fn f32(&mut self, reading: &'static str) -> Decoded<f32> {
        Ok(f32::from_le_bytes(self.array(reading)?))
    }
    fn f64(&mut self, reading: &'static str) -> Decoded<f64> {
        Ok(f64::from_le_bytes(self.array(reading)?))
    }
    fn vec3(&mut self, reading: &'static str) -> Decoded<DVec3> {
        Ok(DVec3::new(self.f64(reading)?, self.f64(reading)?, self.f64(reading)?))
    }
    /// A count or index (stored as u64), as usize.
    fn index(&mut self, reading: &'static str) -> Decoded<usize> {
        let n = u64::from_le_bytes(self.array(reading)?);
        usize::try_from(n).map_err(|_| invalid(reading, format!("{n} does not fit this machine's addresses")))
    }
    /// A list's length, refused unless the bytes left can hold that many items of at least `item`
    /// bytes each (so a corrupt length never allocates).
    fn count(&mut self, reading: &'static str, item: usize) -> Decoded<usize> {
        let at = self.at;
        let n = self.index(reading)?;
        let left = self.bytes.len() - self.at;
        match n.checked_mul(item) {
            Some(need) if need <= left => Ok(n),
            need => Err(SceneBytesError::Truncated { reading, offset: at, need: need.unwrap_or(usize::MAX), left }),
        }
    }
    /// Runs written by `Writer::runs` (each at least `run` bytes), at most `most` items in all,
    /// so a corrupt run length never allocates past what the mesh can use.
    fn runs<T: Clone>(
        &mut self,
        reading: &'static str,
        run: usize,
        most: usize,
        what: impl Fn() -> String,
        mut item: impl FnMut(&mut Self) -> Decoded<T>,
    ) -> Decoded<Vec<T>> {
        let count = self.count(reading, run)?;
        let mut out = Vec::new();
        for _ in 0..count {
            let n = self.index(reading)?;
            let x = item(self)?;
            if n > most - out.len() {
                return Err(invalid(what(), format!("more {reading} than its {most} vertices")));
            }
            out.extend(std::iter::repeat_n(x, n));
        }
        Ok(out)
    }
    pub(crate) fn u32s(&mut self, reading: &'static str) -> Decoded<Vec<u32>> {
        let n = self.count(reading, 4)?;
        let raw = self.take(4 * n, reading)?;
        Ok(raw.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect())
    }
    fn str(&mut self, reading: &'static str) -> Decoded<String> {
        let n = self.count(reading, 1)?;
        let raw = self.take(n, reading)?;
        String::from_utf8(raw.to_vec()).map_err(|_| invalid(reading, "text that is not UTF-8"))
    }
}
