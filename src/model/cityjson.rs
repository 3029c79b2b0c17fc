//! CityJSON 1.1 and 2.0 reader, and CityJSONSeq (`.city.jsonl`: a header line, then one
//! `CityJSONFeature` a line), into a [`City`]: every boundary surface of the chosen level of detail
//! with its semantic type, in local coordinates.
//!
//! Owns:
//! - the `transform`: real = v × scale + translate; `translate` is never added, so coordinates stay
//!   local (real − translate, in f64) before anything becomes f32; [`City::offset`] adds it back
//!   for output. Without a `transform` (allowed only for real-valued vertices) the smallest vertex
//!   plays its part;
//! - geometry: `MultiSurface`, `CompositeSurface`, `Solid`, `MultiSolid`, `CompositeSolid`, and
//!   `GeometryInstance` of `geometry-templates` (matrix × template vertex + reference point);
//! - the level of detail: the chosen `lod`, else each object's highest, one geometry an object
//!   (so no surface is counted twice);
//! - names `OBJECT_ID/TYPE/INDEX`: TYPE the semantic type (`Surface` without one), INDEX the
//!   surface's position in its geometry (shells and solids flattened in file order);
//! - attributes ([`SurfaceAttributes`]): a surface's semantic surface's own, its CityObject's,
//!   then its parents', which receiver rules by attribute read ([`crate::model::city_where`]);
//! - buildings: a `BuildingPart` (or any child) belongs to its root `Building` for
//!   [`CitySurface::building`]; only `Building` and `BuildingPart` surfaces may receive, the rest
//!   (terrain, vegetation, roads) only cast shadows;
//! - bad input as errors naming the file, the CityObject and the reason.
//!
//! Triangulation (rings with holes, non-planar rings) is [`city_model`]'s, into the reader-neutral
//! [`GltfModel`]; the scene then splits a non-planar surface into planar receivers by its stated
//! tolerance (0.5°, 1 mm: [`crate::scene`]).

use std::collections::HashMap;
use std::sync::Arc;

use glam::{DMat4, DVec3};
use serde_json::Value;

use super::gltf_read::{CityTags, GltfModel, GltfNode};
use crate::error::{Error, Result};
use crate::geometry::{Plane, newell, triangulate};
use crate::scene::{NodeVeil, SourceMesh};

/// The versions read.
pub const VERSIONS: [&str; 2] = ["1.1", "2.0"];

/// CityObject types whose surfaces may receive.
const BUILDING_TYPES: [&str; 2] = ["Building", "BuildingPart"];

/// A city model, read.
#[derive(Debug, Clone)]
pub struct City {
    /// File label.
    pub file: String,
    /// Its `version`.
    pub version: String,
    /// `metadata.referenceSystem`, as written (a URL or `EPSG:N`), kept for output.
    pub reference_system: Option<String>,
    /// Real coordinates = local + offset (the `transform`'s translate).
    pub offset: DVec3,
    /// Every boundary surface of the chosen geometries, in file order.
    pub surfaces: Vec<CitySurface>,
}

/// One boundary surface.
#[derive(Debug, Clone)]
pub struct CitySurface {
    /// `OBJECT_ID/TYPE/INDEX`.
    pub name: String,
    /// The CityObject whose geometry holds it.
    pub object: String,
    /// Its root `Building` (itself for a Building); `None` for what is not a building.
    pub building: Option<String>,
    /// Semantic type (`RoofSurface`, …), if any.
    pub kind: Option<String>,
    /// Index of its geometry in the object's `geometry` array.
    pub geometry: usize,
    /// Its position among the geometry's surfaces (flattened).
    pub index: usize,
    /// Rings in local coordinates (real − offset): the exterior, then holes.
    pub rings: Vec<Vec<DVec3>>,
    /// The attributes a receiver rule may ask of it ([`crate::model::city_where`]).
    pub attributes: SurfaceAttributes,
}

/// One attribute map of a CityJSON file, shared by the surfaces that see it.
pub type AttributeMap = Arc<serde_json::Map<String, Value>>;

/// A surface's attributes, where a rule looks for a key in turn: its semantic surface's own
/// (every member but `type`, `parent` and `children`), then its CityObject's `attributes`, then
/// each parent's up to the root (a `BuildingPart` sees its `Building`'s). The first holding the
/// key answers.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SurfaceAttributes {
    layers: Vec<AttributeMap>,
}

impl SurfaceAttributes {
    /// Layers nearest first (the semantic surface's, the object's, its parents').
    pub fn of(layers: Vec<AttributeMap>) -> Self {
        Self { layers }
    }

    /// The value of `key`, from the first layer that has it.
    pub fn get(&self, key: &str) -> Option<&Value> {
        self.layers.iter().find_map(|m| m.get(key))
    }

    /// Whether any layer has `key` (null or not).
    pub fn has(&self, key: &str) -> bool {
        self.get(key).is_some()
    }
}

/// Whether a file name is a CityJSON model: `.city.json`, `.city.jsonl`, `.jsonl`, or a `.json`
/// whose text says `"type": "CityJSON"` near its start.
pub fn is_cityjson(name: &str, bytes: &[u8]) -> bool {
    let lower = name.to_ascii_lowercase();
    if lower.ends_with(".city.json") || lower.ends_with(".jsonl") || lower.ends_with(".cityjson") {
        return true;
    }
    if !lower.ends_with(".json") {
        return false;
    }
    let head = String::from_utf8_lossy(&bytes[..bytes.len().min(4096)]);
    let squeezed: String = head.chars().filter(|c| !c.is_whitespace()).collect();
    squeezed.contains(r#""type":"CityJSON""#)
}

/// Reads a CityJSON file or CityJSONSeq (by its lines: a header then features). `lod` picks the
/// level of detail (exactly, or `2` for any `2.x`); `None`: each object's highest.
pub fn read_city(file: &str, bytes: &[u8], lod: Option<&str>) -> Result<City> {
    let mut surfaces = Vec::new();
    let mut city = read_city_with(file, bytes, lod, None, &mut |s| surfaces.push(s))?;
    city.surfaces = surfaces;
    Ok(city)
}

/// Reads a city as [`read_city`] does, but builds the surfaces of only the CityObjects `keep`
/// takes (by id; `None`: all) and hands each to `out` in file order instead of holding them; the returned
/// [`City`] has no surfaces. A CityJSONSeq is read a line at a time (never held whole), and a
/// feature line none of whose objects `keep` takes is skipped after reading only its objects'
/// ids, without building its geometry (when the header has a `transform`: without one, the first
/// feature's vertices set the offset, so every line is read). A skipped line is not checked: a
/// reader of part of a city has read it whole before (the tiling does).
pub fn read_city_with(
    file: &str,
    bytes: &[u8],
    lod: Option<&str>,
    keep: Option<&dyn Fn(&str) -> bool>,
    out: &mut dyn FnMut(CitySurface),
) -> Result<City> {
    read_city_from(file, &CitySource::parse(file, bytes)?, lod, keep, out)
}

/// A city file parsed once, for passes that each read what they need of it: a CityJSON
/// document (one JSON value), or a CityJSONSeq's header and its feature lines, each parsed when
/// a pass reads it (a sequence is never held parsed whole).
pub enum CitySource<'a> {
    /// A CityJSON document.
    Document(Value),
    /// A CityJSONSeq.
    Seq {
        /// Its first line.
        header: Value,
        /// Each feature line with its number among the non-blank lines from 0 (the header's).
        lines: Vec<(usize, &'a str)>,
    },
}

impl<'a> CitySource<'a> {
    /// Parses a CityJSON document whole, or a CityJSONSeq's header; refuses what is not CityJSON.
    pub fn parse(file: &str, bytes: &'a [u8]) -> Result<Self> {
        let text = std::str::from_utf8(bytes).map_err(|e| Error::model(file, format!("not UTF-8 text ({e})")))?;
        let whole: std::result::Result<Value, _> = serde_json::from_str(text);
        let source = match whole {
            Ok(doc) => Self::Document(doc),
            Err(e) => {
                // CityJSONSeq: every line a JSON object.
                let mut lines = text.lines().filter(|l| !l.trim().is_empty()).enumerate();
                let (_, first) = lines.next().ok_or_else(|| Error::model(file, "the file is empty"))?;
                let header: Value = serde_json::from_str(first).map_err(|_| Error::model(file, format!("not JSON: {e}")))?;
                Self::Seq { header, lines: lines.collect() }
            }
        };
        if source.header().get("type").and_then(Value::as_str) != Some("CityJSON") {
            return Err(Error::model(file, "not CityJSON: its \"type\" is not \"CityJSON\""));
        }
        Ok(source)
    }

    /// The document, or the sequence's header.
    fn header(&self) -> &Value {
        match self {
            Self::Document(doc) | Self::Seq { header: doc, .. } => doc,
        }
    }
}

/// [`read_city_with`] of a file already parsed.
pub fn read_city_from(
    file: &str,
    source: &CitySource,
    lod: Option<&str>,
    keep: Option<&dyn Fn(&str) -> bool>,
    out: &mut dyn FnMut(CitySurface),
) -> Result<City> {
    match source {
        CitySource::Document(doc) => read_parts(file, doc, &[], lod, keep, out),
        CitySource::Seq { header, lines } => read_parts(file, header, lines, lod, keep, out),
    }
}

/// A document, or a sequence's header and feature lines, read.
fn read_parts(
    file: &str,
    header: &Value,
    lines: &[(usize, &str)],
    lod: Option<&str>,
    keep: Option<&dyn Fn(&str) -> bool>,
    out: &mut dyn FnMut(CitySurface),
) -> Result<City> {
    let mut reader = Reader::new(file, header, lod)?;
    reader.document(header, keep, out)?;
    let skip = keep.filter(|_| reader.scale.is_some());
    for &(i, line) in lines {
        if skip.is_some_and(|keep| !feature_kept(line, keep)) {
            continue;
        }
        reader.document(&feature(file, i, line)?, keep, out)?;
    }
    Ok(reader.city)
}

/// Reads a city as [`read_city_from`] does (every line of a sequence read) and hands back the
/// file as one CityJSON document too ([`OneDocument`] for a sequence), each line parsed once:
/// what a writer of the model with values needs, in one pass.
pub fn read_city_document(
    file: &str,
    source: CitySource,
    lod: Option<&str>,
    keep: Option<&dyn Fn(&str) -> bool>,
    out: &mut dyn FnMut(CitySurface),
) -> Result<(City, Value)> {
    match source {
        CitySource::Document(doc) => Ok((read_parts(file, &doc, &[], lod, keep, out)?, doc)),
        CitySource::Seq { header, lines } => {
            let mut reader = Reader::new(file, &header, lod)?;
            reader.document(&header, keep, out)?;
            let mut one = OneDocument::new(header);
            for (i, line) in lines {
                let feature = feature(file, i, line)?;
                reader.document(&feature, keep, out)?;
                one.add(feature);
            }
            Ok((reader.city, one.finish()))
        }
    }
}

/// Feature line `i` (numbered among the non-blank lines from 0, the header's) of a CityJSONSeq.
fn feature(file: &str, i: usize, line: &str) -> Result<Value> {
    // Lines are named among the non-blank ones, the header line 1.
    let feature: Value = serde_json::from_str(line).map_err(|e| Error::model(file, format!("line {}: not JSON: {e}", i + 1)))?;
    if feature.get("type").and_then(Value::as_str) != Some("CityJSONFeature") {
        return Err(Error::model(file, format!("line {}: not a CityJSONFeature", i + 1)));
    }
    Ok(feature)
}

/// A CityJSONSeq as one CityJSON document: the header with every feature's objects and vertices
/// appended (their vertex indices moved past the vertices before them).
pub struct OneDocument {
    doc: Value,
    objects: serde_json::Map<String, Value>,
    vertices: Vec<Value>,
}

impl OneDocument {
    /// Starts from the sequence's header (its own objects are replaced by the features').
    pub fn new(header: Value) -> Self {
        let vertices = header.get("vertices").and_then(Value::as_array).cloned().unwrap_or_default();
        Self { doc: header, objects: serde_json::Map::new(), vertices }
    }

    /// Appends one feature's objects and vertices.
    pub fn add(&mut self, mut feature: Value) {
        let base = self.vertices.len() as u64;
        let objects = feature.get_mut("CityObjects").and_then(Value::as_object_mut).map(std::mem::take).unwrap_or_default();
        for (id, mut object) in objects {
            if let Some(geometries) = object.get_mut("geometry").and_then(Value::as_array_mut) {
                for g in geometries {
                    if let Some(b) = g.get_mut("boundaries") {
                        shift_indices(b, base);
                    }
                }
            }
            self.objects.insert(id, object);
        }
        if let Some(Value::Array(v)) = feature.get_mut("vertices").map(Value::take) {
            self.vertices.extend(v);
        }
    }

    /// The one document.
    pub fn finish(mut self) -> Value {
        self.doc["CityObjects"] = Value::Object(self.objects);
        self.doc["vertices"] = Value::Array(self.vertices);
        self.doc
    }
}

/// Adds `base` to every vertex index of `boundaries`.
fn shift_indices(v: &mut Value, base: u64) {
    match v {
        Value::Array(items) => items.iter_mut().for_each(|i| shift_indices(i, base)),
        Value::Number(n) => {
            if let Some(k) = n.as_u64() {
                // An index past every vertex (in a geometry the reader skipped) stays past them.
                *v = Value::from(k.saturating_add(base));
            }
        }
        _ => {}
    }
}

/// Whether `keep` takes an object of a CityJSONSeq line, from its objects' ids alone (the rest of
/// the line is scanned, not built). A line that does not read so is kept, for the full read to
/// name its fault.
fn feature_kept(line: &str, keep: &dyn Fn(&str) -> bool) -> bool {
    #[derive(serde::Deserialize)]
    struct Ids {
        #[serde(rename = "CityObjects")]
        objects: std::collections::BTreeMap<String, serde::de::IgnoredAny>,
    }
    serde_json::from_str::<Ids>(line).map_or(true, |ids| ids.objects.keys().any(|id| keep(id)))
}

/// Parsing state: the header's transform and templates, the surfaces so far.
struct Reader<'a> {
    city: City,
    scale: Option<DVec3>,
    lod: Option<&'a str>,
    /// Template geometries and their vertices (real coordinates, relative to the reference point).
    templates: Vec<Value>,
    template_vertices: Vec<DVec3>,
    /// Set once an offset is chosen (the translate, or the first document's smallest vertex).
    offset_set: bool,
}

impl<'a> Reader<'a> {
    fn new(file: &str, header: &Value, lod: Option<&'a str>) -> Result<Self> {
        let version = header.get("version").and_then(Value::as_str).unwrap_or("");
        if !VERSIONS.contains(&version) {
            let shown = header.get("version").map_or("none".to_string(), Value::to_string);
            return Err(Error::model(file, format!("CityJSON version {shown} is not read (read: {})", VERSIONS.join(", "))));
        }
        let (scale, offset) = match header.get("transform") {
            Some(t) => {
                let three = |key: &str| -> Result<DVec3> {
                    let v = t.get(key).and_then(Value::as_array).filter(|a| a.len() == 3);
                    let nums: Option<Vec<f64>> = v.map(|a| a.iter().filter_map(Value::as_f64).collect());
                    match nums {
                        Some(n) if n.len() == 3 && n.iter().all(|x| x.is_finite()) => Ok(DVec3::new(n[0], n[1], n[2])),
                        _ => Err(Error::model(file, format!("transform.{key} is not three numbers"))),
                    }
                };
                let scale = three("scale")?;
                if scale.min_element() <= 0.0 {
                    return Err(Error::model(file, format!("transform.scale {scale} is not positive")));
                }
                (Some(scale), Some(three("translate")?))
            }
            None => (None, None),
        };
        let reference_system = header.pointer("/metadata/referenceSystem").and_then(Value::as_str).map(str::to_string);
        let templates = header.pointer("/geometry-templates/templates").and_then(Value::as_array).cloned().unwrap_or_default();
        let template_vertices = header
            .pointer("/geometry-templates/vertices-templates")
            .and_then(Value::as_array)
            .map(|a| {
                a.iter()
                    .map(|v| point(v).ok_or_else(|| Error::model(file, "a template vertex is not three numbers")))
                    .collect::<Result<Vec<DVec3>>>()
            })
            .transpose()?
            .unwrap_or_default();
        let city = City {
            file: file.to_string(),
            version: version.to_string(),
            reference_system,
            offset: offset.unwrap_or_default(),
            surfaces: Vec::new(),
        };
        Ok(Self { city, scale, lod, templates, template_vertices, offset_set: offset.is_some() })
    }

    /// One CityJSON document or CityJSONFeature: its vertices and CityObjects, the surfaces of
    /// those `keep` takes handed to `out`.
    fn document(&mut self, doc: &Value, keep: Option<&dyn Fn(&str) -> bool>, out: &mut dyn FnMut(CitySurface)) -> Result<()> {
        let file = self.city.file.clone();
        let raw = doc.get("vertices").and_then(Value::as_array).map(Vec::as_slice).unwrap_or(&[]);
        let vertices = self.vertices(&file, raw)?;
        let Some(objects) = doc.get("CityObjects").and_then(Value::as_object) else {
            return Err(Error::model(file, "no \"CityObjects\" object"));
        };
        let parents: HashMap<&str, &str> =
            objects.iter().filter_map(|(id, o)| Some((id.as_str(), o.pointer("/parents/0").and_then(Value::as_str)?))).collect();
        for (id, object) in objects.iter().filter(|(id, _)| keep.is_none_or(|keep| keep(id))) {
            let kind = object.get("type").and_then(Value::as_str).unwrap_or("");
            let building = BUILDING_TYPES.contains(&kind).then(|| root_of(id, &parents).to_string());
            let inherited = object_attributes(id, objects, &parents);
            let geometries = object.get("geometry").and_then(Value::as_array).map(Vec::as_slice).unwrap_or(&[]);
            let Some(g) = self.choose(geometries) else { continue };
            let err = |reason: String| Error::object(&file, format!("CityObject '{id}'"), format!("geometry {g}: {reason}"));
            let mut found = self.surfaces(&geometries[g], &vertices).map_err(err)?;
            for (index, Surface { kind, own, rings }) in found.drain(..).enumerate() {
                let type_name = kind.clone().unwrap_or_else(|| "Surface".into());
                let layers = own.into_iter().chain(inherited.iter().cloned()).collect();
                out(CitySurface {
                    name: format!("{id}/{type_name}/{index}"),
                    object: id.clone(),
                    building: building.clone(),
                    kind,
                    geometry: g,
                    index,
                    rings,
                    attributes: SurfaceAttributes { layers },
                });
            }
        }
        Ok(())
    }

    /// The vertices in local coordinates (real − offset).
    fn vertices(&mut self, file: &str, raw: &[Value]) -> Result<Vec<DVec3>> {
        let mut out = Vec::with_capacity(raw.len());
        let mut integers = true;
        for (i, v) in raw.iter().enumerate() {
            let p = point(v).ok_or_else(|| Error::model(file, format!("vertex {i} is not three finite numbers")))?;
            integers &= v.as_array().is_some_and(|a| a.iter().all(|c| c.is_i64() || c.is_u64()));
            out.push(p);
        }
        match self.scale {
            Some(scale) => Ok(out.into_iter().map(|p| p * scale).collect()),
            None if integers && !out.is_empty() => Err(Error::model(
                file,
                "no \"transform\", yet the vertices are integers: their scale and translation are unknown (CityJSON 1.1 and 2.0 require a transform)",
            )),
            None => {
                if !self.offset_set && !out.is_empty() {
                    self.city.offset = out.iter().copied().fold(DVec3::splat(f64::INFINITY), DVec3::min);
                    self.offset_set = true;
                }
                Ok(out.into_iter().map(|p| p - self.city.offset).collect())
            }
        }
    }

    /// The geometry to read of an object: the chosen lod's, else the highest; `None` when none.
    fn choose(&self, geometries: &[Value]) -> Option<usize> {
        let lods: Vec<(usize, String)> = geometries.iter().enumerate().filter_map(|(i, g)| Some((i, self.lod_of(g)?))).collect();
        match self.lod {
            Some(want) => lods
                .iter()
                .find(|(_, l)| l == want)
                .or_else(|| lods.iter().find(|(_, l)| !want.contains('.') && l.split('.').next() == Some(want)))
                .map(|(i, _)| *i),
            None => {
                let value = |l: &str| l.parse::<f64>().unwrap_or(f64::NEG_INFINITY);
                // The first of the highest: max_by keeps the last of equals, so compare reversed indices.
                lods.iter().max_by(|a, b| value(&a.1).total_cmp(&value(&b.1)).then(b.0.cmp(&a.0))).map(|(i, _)| *i)
            }
        }
    }

    /// A geometry's lod as text (a template's for an instance); `None` for points and lines.
    fn lod_of(&self, g: &Value) -> Option<String> {
        let g = match g.get("type").and_then(Value::as_str)? {
            "GeometryInstance" => self.templates.get(g.get("template")?.as_u64()? as usize)?,
            _ => g,
        };
        if !matches!(
            g.get("type").and_then(Value::as_str)?,
            "MultiSurface" | "CompositeSurface" | "Solid" | "MultiSolid" | "CompositeSolid"
        ) {
            return None;
        }
        Some(match g.get("lod")? {
            Value::String(s) => s.clone(),
            other => other.to_string(),
        })
    }

    /// A geometry's surfaces: (semantic type, rings in local coordinates).
    fn surfaces(&self, g: &Value, vertices: &[DVec3]) -> std::result::Result<Vec<Surface>, String> {
        if g.get("type").and_then(Value::as_str) == Some("GeometryInstance") {
            return self.instance(g, vertices);
        }
        flatten(g, vertices)
    }

    /// A `GeometryInstance`: the template's surfaces, each vertex M × v + reference point.
    fn instance(&self, g: &Value, vertices: &[DVec3]) -> std::result::Result<Vec<Surface>, String> {
        let t = g.get("template").and_then(Value::as_u64).ok_or("a GeometryInstance without a template index")? as usize;
        let template = self.templates.get(t).ok_or_else(|| format!("template {t} does not exist ({} templates)", self.templates.len()))?;
        let r = g.pointer("/boundaries/0").and_then(Value::as_u64).ok_or("a GeometryInstance without its reference point")? as usize;
        let reference = *vertices.get(r).ok_or_else(|| format!("vertex index {r} is out of range ({} vertices)", vertices.len()))?;
        let m: Vec<f64> = g
            .get("transformationMatrix")
            .and_then(Value::as_array)
            .map(|a| a.iter().filter_map(Value::as_f64).collect())
            .unwrap_or_default();
        if m.len() != 16 {
            return Err("transformationMatrix is not 16 numbers".into());
        }
        // CityJSON writes the matrix row by row; glam takes columns.
        let matrix =
            DMat4::from_cols_array(&[m[0], m[4], m[8], m[12], m[1], m[5], m[9], m[13], m[2], m[6], m[10], m[14], m[3], m[7], m[11], m[15]]);
        let placed: Vec<DVec3> = self.template_vertices.iter().map(|v| matrix.transform_point3(*v) + reference).collect();
        flatten(template, &placed)
    }
}

/// A surface as read.
struct Surface {
    /// Its semantic type.
    kind: Option<String>,
    /// Its semantic surface's own attributes, if it has any.
    own: Option<AttributeMap>,
    /// Its rings.
    rings: Vec<Vec<DVec3>>,
}

/// The `attributes` of object `id` and of each of its parents up to the root, nearest first
/// (those without attributes left out); a cycle stops at the start.
fn object_attributes(id: &str, objects: &serde_json::Map<String, Value>, parents: &HashMap<&str, &str>) -> Vec<AttributeMap> {
    let mut chain = Vec::new();
    let mut at = id;
    for _ in 0..=parents.len() {
        if let Some(map) = objects.get(at).and_then(|o| o.get("attributes")).and_then(Value::as_object) {
            chain.push(Arc::new(map.clone()));
        }
        match parents.get(at) {
            Some(&p) if p != id => at = p,
            _ => break,
        }
    }
    chain
}

/// A semantic surface's own attributes: every member but those CityJSON gives a meaning.
fn semantic_attributes(semantic: &Value) -> Option<AttributeMap> {
    let own: serde_json::Map<String, Value> = semantic
        .as_object()?
        .iter()
        .filter(|(k, _)| !matches!(k.as_str(), "type" | "parent" | "children"))
        .map(|(k, v)| (k.clone(), v.clone()))
        .collect();
    (!own.is_empty()).then(|| Arc::new(own))
}

/// Three finite numbers.
fn point(v: &Value) -> Option<DVec3> {
    let a = v.as_array().filter(|a| a.len() == 3)?;
    let p = DVec3::new(a[0].as_f64()?, a[1].as_f64()?, a[2].as_f64()?);
    p.is_finite().then_some(p)
}

/// The root of an object's `parents` chain (itself when it has none); a cycle stops at the start.
fn root_of<'a>(id: &'a str, parents: &HashMap<&'a str, &'a str>) -> &'a str {
    let mut at = id;
    for _ in 0..parents.len() {
        match parents.get(at) {
            Some(&p) if p != id => at = p,
            _ => break,
        }
    }
    at
}

/// Nesting depth of surfaces in `boundaries` (and of surface values in `semantics.values`).
fn surface_depth(kind: &str) -> std::result::Result<usize, String> {
    match kind {
        "MultiSurface" | "CompositeSurface" => Ok(0),
        "Solid" => Ok(1),
        "MultiSolid" | "CompositeSolid" => Ok(2),
        other => Err(format!("geometry type '{other}' has no surfaces")),
    }
}

/// A geometry's surfaces in file order, each ring checked.
fn flatten(g: &Value, vertices: &[DVec3]) -> std::result::Result<Vec<Surface>, String> {
    let kind = g.get("type").and_then(Value::as_str).unwrap_or("");
    let depth = surface_depth(kind)?;
    let boundaries = g.get("boundaries").ok_or("no boundaries")?;
    let mut surfaces = Vec::new();
    collect(boundaries, depth, &mut surfaces).map_err(|_| format!("boundaries are not nested as a {kind}'s"))?;
    let semantic_surfaces = g.pointer("/semantics/surfaces").and_then(Value::as_array).map(Vec::as_slice).unwrap_or(&[]);
    let mut values = Vec::new();
    if let Some(v) = g.pointer("/semantics/values") {
        collect(v, depth, &mut values).map_err(|_| format!("semantics.values are not nested as a {kind}'s boundaries"))?;
    }
    // One map a semantic surface, shared by every surface pointing at it.
    let owns: Vec<Option<AttributeMap>> = semantic_surfaces.iter().map(semantic_attributes).collect();
    surfaces
        .iter()
        .enumerate()
        .map(|(s, surface)| {
            let (semantic, own) = match values.get(s).copied() {
                None | Some(Value::Null) => (None, None),
                Some(v) => {
                    let k = v.as_u64().ok_or_else(|| format!("surface {s}: semantic value {v} is not an index"))? as usize;
                    let obj = semantic_surfaces.get(k).ok_or_else(|| {
                        format!("surface {s}: semantic value {k} points nowhere ({} semantic surfaces)", semantic_surfaces.len())
                    })?;
                    (Some(obj.get("type").and_then(Value::as_str).unwrap_or("Surface").to_string()), owns.get(k).cloned().flatten())
                }
            };
            let rings = surface.as_array().ok_or_else(|| format!("surface {s} is not a list of rings"))?;
            if rings.is_empty() {
                return Err(format!("surface {s} has no rings (it needs an exterior ring)"));
            }
            let rings =
                rings.iter().enumerate().map(|(r, ring)| read_ring(ring, vertices).map_err(|e| format!("surface {s}, ring {r}: {e}")));
            Ok(Surface { kind: semantic, own, rings: rings.collect::<std::result::Result<Vec<_>, String>>()? })
        })
        .collect()
}

/// The values at nesting depth `depth` (0: the array's items), in order.
fn collect<'v>(v: &'v Value, depth: usize, out: &mut Vec<&'v Value>) -> std::result::Result<(), ()> {
    let items = v.as_array().ok_or(())?;
    if depth == 0 {
        out.extend(items);
        return Ok(());
    }
    items.iter().try_for_each(|i| collect(i, depth - 1, out))
}

/// A ring's points, at least 3 distinct ones, every index in range.
fn read_ring(ring: &Value, vertices: &[DVec3]) -> std::result::Result<Vec<DVec3>, String> {
    let indices = ring.as_array().ok_or("is not a list of vertex indices")?;
    let mut points: Vec<DVec3> = Vec::with_capacity(indices.len());
    for i in indices {
        let k = i.as_u64().ok_or_else(|| format!("vertex index {i} is not an index"))? as usize;
        let p = *vertices.get(k).ok_or_else(|| format!("vertex index {k} is out of range ({} vertices)", vertices.len()))?;
        // Finite as written, a vertex can still overflow once scaled, shifted by the offset or
        // placed by a template's matrix; said here, or the ring fails later as "not triangulated".
        if !p.is_finite() {
            return Err(format!("vertex index {k} is not finite once scaled and placed (check transform.scale and the coordinates)"));
        }
        // Repeated consecutive points (and a closing repeat) add nothing.
        if points.last() != Some(&p) {
            points.push(p);
        }
    }
    if points.len() > 1 && points.first() == points.last() {
        points.pop();
    }
    let mut distinct = points.clone();
    distinct.sort_by(|a, b| a.to_array().partial_cmp(&b.to_array()).unwrap_or(std::cmp::Ordering::Equal));
    distinct.dedup();
    if distinct.len() < 3 {
        return Err(format!("has {} distinct vertices; a ring needs at least 3", distinct.len()));
    }
    Ok(points)
}

/// Which surfaces may receive, and which by default (`RoofSurface`, `WallSurface`).
pub fn default_receiver(surface: &CitySurface) -> bool {
    surface.building.is_some() && matches!(surface.kind.as_deref(), Some("RoofSurface" | "WallSurface"))
}

/// The city as the readers' common model: one node (and mesh) a surface, triangulated with its
/// holes about its exterior ring's plane (a non-planar ring's triangles keep their 3D vertices),
/// turned by `north_deg` about the local origin. A ring that cannot be triangulated is an error.
pub fn city_model(city: &City, north_deg: f64) -> Result<GltfModel> {
    if city.surfaces.is_empty() {
        // Said here, with the file, rather than later as a scene that has no receiver.
        return Err(Error::model(&city.file, "no CityObject has geometry to read (at the level of detail chosen)"));
    }
    let turn = DMat4::from_rotation_z(-north_deg.to_radians());
    let mut meshes = Vec::with_capacity(city.surfaces.len());
    let mut nodes = Vec::with_capacity(city.surfaces.len());
    for s in &city.surfaces {
        let mesh = surface_mesh(s).map_err(|reason| Error::object(&city.file, format!("CityObject '{}'", s.object), reason))?;
        nodes.push(GltfNode {
            name: s.name.clone(),
            named: true,
            marked: default_receiver(s),
            veil: NodeVeil::default(),
            mesh: meshes.len(),
            transform: turn,
            city: Some(CityTags {
                building: s.building.clone(),
                object: s.object.clone(),
                kind: s.kind.clone(),
                attributes: s.attributes.clone(),
            }),
        });
        meshes.push(mesh);
    }
    Ok(GltfModel { file: city.file.clone(), meshes, nodes, glass: Vec::new() })
}

/// One surface's triangles (f32, local coordinates: already small).
fn surface_mesh(s: &CitySurface) -> std::result::Result<SourceMesh, String> {
    let points: Vec<DVec3> = s.rings.iter().flatten().copied().collect();
    let mut starts = Vec::new();
    let mut at = 0;
    for ring in &s.rings {
        if at > 0 {
            starts.push(at);
        }
        at += ring.len();
    }
    let exterior = s.rings.first().ok_or_else(|| format!("surface {} ({}) has no rings", s.index, s.name))?;
    let normal = newell(exterior);
    if normal.length() == 0.0 {
        return Err(format!("surface {} ({}) has no area", s.index, s.name));
    }
    let triangles = triangulate(&Plane::of_polygon(exterior), &points, &starts);
    if triangles.is_empty() {
        return Err(format!("surface {} ({}) could not be triangulated (a self-intersecting ring?)", s.index, s.name));
    }
    Ok(SourceMesh {
        positions: points.iter().map(|p| [p.x as f32, p.y as f32, p.z as f32]).collect(),
        indices: triangles.iter().flatten().map(|&i| i as u32).collect(),
    })
}

#[cfg(test)]
#[path = "cityjson_tests.rs"]
mod tests;
