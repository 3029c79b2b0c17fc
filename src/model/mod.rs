//! Model readers: glTF/glb, EnergyPlus IDF/epJSON and typed arrays in, one [`Scene`] out (with
//! the EnergyPlus model kept for the hook, [`crate::export::hook`]). With the `fixtures` feature,
//! also the glb writer and the generated example office (`glb_write`, `office`, `office_idf`).
//!
//! Owns the choice of receivers across all input files. With an EnergyPlus model among the
//! inputs, it gives the receivers (its outdoor surfaces and fenestration, by their EnergyPlus
//! names) and glTF files are context that only casts shadows, unless the `receivers` patterns pick
//! glTF nodes too. Without one: the `receivers` globs (node names, case-insensitive) when given;
//! otherwise the nodes marked `{"sunlit": {"receiver": true}}` in their extras, if any file marks
//! one; otherwise every named node with a mesh. Foliage and see-through nodes (the `foliage` and
//! `transmittance` patterns, or their extras marks) are never chosen by the marks-or-names default.
//! When the names default chooses more than [`MANY_RECEIVERS`], [`Loaded::notes`] says so.
//!
//! City models (CityJSON, [`cityjson`]) and OBJ ([`obj`]) are read into the same node list as
//! glTF. A CityJSON surface is a node `OBJECT_ID/TYPE/INDEX`; `receivers` globs match its name or
//! its semantic type (`RoofSurface`), `buildings` limits receivers to the named buildings,
//! `attribute_rules` to the surfaces whose attributes meet them ([`city_where`]), and by default
//! its roofs and walls are marked as receivers. Only buildings' surfaces ever receive.
pub mod arrays;
pub mod building;
pub mod calendar;
pub mod city_where;
#[cfg(feature = "fixtures")]
pub mod city_write;
pub mod cityjson;
pub mod epjson;
#[cfg(feature = "fixtures")]
pub mod glb_write;
pub mod gltf_accessor;
pub mod gltf_draco;
pub mod gltf_extensions;
pub mod gltf_instancing;
pub mod gltf_read;
pub mod idf;
pub mod inside;
pub mod obj;
#[cfg(feature = "fixtures")]
pub mod office;
#[cfg(feature = "fixtures")]
pub mod office_idf;
pub mod placed;
pub mod reveal;
pub mod run_year;
pub mod schedule;
pub mod shades;
pub mod shading_update;
pub mod simple_glazing;
pub mod site;

use std::collections::HashMap;
use std::path::PathBuf;

use crate::error::{Error, NoReceivers, Result};
use crate::scene::{NodeVeil, Scene, SceneBuilder};
use gltf_read::{GltfModel, GltfNode};

/// How to read models into a scene.
#[derive(Debug, Clone, Default)]
pub struct LoadOptions {
    /// Glob patterns over node names; empty means "use the marks, else every named node".
    pub receivers: Vec<String>,
    /// Degrees clockwise from true north of the model's north (−Z in glTF), as EnergyPlus's
    /// Building North Axis.
    pub north: f64,
    /// With an EnergyPlus model: every surface receives, shading surfaces with their `Mir-`
    /// back faces (the columns of EnergyPlus's `Imported` form), not only the outdoor ones.
    pub all_energyplus_surfaces: bool,
    /// Glob patterns over node names: these nodes are foliage (besides those marked in extras).
    pub foliage: Vec<String>,
    /// (glob, t): matching nodes let t of the beam through (the last matching pattern wins).
    pub transmittance: Vec<(String, f64)>,
    /// (EnergyPlus shading surface name, τ): that shade lets τ of the beam through (0 opaque,
    /// 1 not a caster), whatever its transmittance schedule says. Without an entry a shade
    /// takes its schedule's value when that never changes, and is opaque otherwise (see
    /// [`crate::year::transmitting`] for schedules that change).
    pub shade_transmittance: Vec<(String, f64)>,
    /// City models: only these buildings' surfaces receive (ids of `Building`s or their parts);
    /// empty: every building's.
    pub buildings: Vec<String>,
    /// City models: `where` rules over attributes (`function=residential`, `storeysAboveGround>=3`;
    /// [`city_where`]): a receiver meets them all, beside `receivers` and `buildings`; empty:
    /// no rule.
    pub attribute_rules: Vec<String>,
    /// City models: the level of detail read (`2.2`, or `2` for any 2.x); `None`: each
    /// object's highest.
    pub lod: Option<String>,
    /// OBJ: which axis is up.
    pub up: obj::ObjUp,
    /// OBJ: the length of one unit.
    pub unit: obj::ObjUnit,
    /// The scene's f32 origin (world), when scenes cut from one model must round alike; `None`:
    /// the input's centre ([`crate::scene::SceneBuilder::set_origin`]).
    pub origin: Option<glam::DVec3>,
    /// Glob patterns over mesh node names: glazing, left out of the scene (an opening) and kept in
    /// [`Loaded::glazing`] ([`inside::gltf`]).
    pub glazing: Vec<String>,
    /// Glob patterns over mesh node names: rooms, each a receiver and kept in [`Loaded::interior`]
    /// ([`inside::gltf`]); they are the only receivers when `receivers` is empty.
    pub interior: Vec<String>,
}

/// The EnergyPlus model among the inputs, kept for hooking the schedule into a copy of it.
#[derive(Debug, Clone)]
pub struct EnergyPlusInput {
    /// File label.
    pub file: String,
    /// Its text as read.
    pub text: String,
    /// Its objects.
    pub objects: Vec<idf::IdfObject>,
    /// epJSON rather than IDF.
    pub epjson: bool,
    /// Its geometry.
    pub building: building::Building,
    /// Its shades' transmittance schedules.
    pub shades: Vec<shades::ShadeGroup>,
}

impl EnergyPlusInput {
    /// The model's `Timestep` (timesteps per hour), if it has one.
    pub fn timesteps(&self) -> Option<u32> {
        self.objects.iter().find(|o| o.is("Timestep")).and_then(|o| o.field(0).trim().parse().ok())
    }
}

/// A scene and, when one of the inputs was an EnergyPlus model, that model.
#[derive(Debug)]
pub struct Loaded {
    /// What is counted.
    pub scene: Scene,
    /// The EnergyPlus model, if any.
    pub energyplus: Option<EnergyPlusInput>,
    /// What the caller should hear about the choices made (also logged as warnings), e.g. that
    /// the default receiver rule chose more than [`MANY_RECEIVERS`] receivers.
    pub notes: Vec<String>,
    /// The mesh nodes the `glazing` option picked (not in the scene).
    pub glazing: Vec<inside::gltf::MarkedNode>,
    /// The mesh nodes the `interior` option picked (receivers of the scene).
    pub interior: Vec<inside::gltf::MarkedNode>,
}

/// More receivers than this, chosen by the default rule (every named node), are reported: a CAD
/// export with thousands of named nodes should not silently become thousands of receivers.
pub const MANY_RECEIVERS: usize = 200;

/// Reads model files into one scene.
pub fn load(paths: &[PathBuf], options: &LoadOptions) -> Result<Scene> {
    Ok(load_all(paths, options)?.scene)
}

/// Reads model files into one scene, keeping an EnergyPlus input for patching.
pub fn load_all(paths: &[PathBuf], options: &LoadOptions) -> Result<Loaded> {
    let files = paths
        .iter()
        .map(|p| std::fs::read(p).map(|b| (p.display().to_string(), b)).map_err(|source| Error::Io { path: p.clone(), source }))
        .collect::<Result<Vec<_>>>()?;
    let dirs: Vec<Option<PathBuf>> = paths.iter().map(|p| p.parent().map(PathBuf::from)).collect();
    read_inputs(&files, &dirs, options)
}

/// Reads in-memory model files (name, bytes) into one scene (the web path).
pub fn load_bytes(files: &[(String, Vec<u8>)], options: &LoadOptions) -> Result<Scene> {
    Ok(load_bytes_all(files, options)?.scene)
}

/// Reads in-memory model files into one scene, keeping an EnergyPlus input for patching.
/// A .gltf among them can only use embedded (data: URI) buffers: there is no folder to look in.
pub fn load_bytes_all(files: &[(String, Vec<u8>)], options: &LoadOptions) -> Result<Loaded> {
    read_inputs(files, &vec![None; files.len()], options)
}

/// Whether a file name is an EnergyPlus model (IDF or epJSON, by extension).
pub fn is_energyplus_file(name: &str) -> bool {
    energyplus_kind(name).is_some()
}

/// Whether a file name is an EnergyPlus model (by extension).
fn energyplus_kind(name: &str) -> Option<bool> {
    let lower = name.to_ascii_lowercase();
    if lower.ends_with(".city.json") {
        None
    } else if lower.ends_with(".idf") {
        Some(false)
    } else if lower.ends_with(".epjson") || lower.ends_with(".json") {
        Some(true)
    } else {
        None
    }
}

/// Parses `GLOB=T` (one `transmittance` item): nodes matching
/// GLOB let T (0 ≤ T < 1) of the beam through.
pub fn parse_transmittance(text: &str) -> Result<(String, f64)> {
    let bad = || Error::argument("transmittance", format!("'{text}' is not GLOB=T with T a number in [0, 1)"));
    let (glob, t) = text.rsplit_once('=').ok_or_else(bad)?;
    let t: f64 = t.trim().parse().map_err(|_| bad())?;
    let glob = glob.trim();
    if glob.is_empty() || !(0.0..1.0).contains(&t) {
        return Err(bad());
    }
    Ok((glob.to_string(), t))
}

/// Files that are never models themselves: glTF buffers and textures.
fn is_resource(name: &str) -> bool {
    let lower = name.to_ascii_lowercase();
    [".bin", ".png", ".jpg", ".jpeg", ".webp", ".ktx2"].iter().any(|ext| lower.ends_with(ext))
}

fn read_inputs(files: &[(String, Vec<u8>)], dirs: &[Option<PathBuf>], options: &LoadOptions) -> Result<Loaded> {
    check_options(options)?;
    let mut models = Vec::new();
    let mut energyplus: Option<EnergyPlusInput> = None;
    let mut city_notes = Vec::new();
    for ((name, bytes), dir) in files.iter().zip(dirs) {
        if dir.is_none() && is_resource(name) {
            // A .gltf's buffer or texture handed over with it (the web path); read through the .gltf.
            continue;
        }
        if cityjson::is_cityjson(name, bytes) {
            let city = cityjson::read_city(name, bytes, options.lod.as_deref())?;
            models.push(cityjson::city_model(&city, options.north)?);
            city_notes.push(format!("{name}: {}", city_north_note(options.north)));
            continue;
        }
        if obj::is_obj(name) {
            models.push(obj::read_obj(name, bytes, options.up, options.unit, options.north)?);
            continue;
        }
        match energyplus_kind(name) {
            Some(epjson) => {
                if let Some(first) = &energyplus {
                    return Err(Error::model(name, format!("only one EnergyPlus model at a time ({} was given first)", first.file)));
                }
                energyplus = Some(read_energyplus(name, bytes, epjson, dir.as_deref())?);
            }
            None => models.push(match dir {
                Some(d) => gltf_read::read_bytes_beside(name, bytes, d, options.north)?,
                None => gltf_read::read_bytes_among(name, bytes, options.north, files)?,
            }),
        }
    }
    let glazing = inside::gltf::marked_nodes(&mut models, "glazing", &options.glazing, true)?;
    let interior = inside::gltf::marked_nodes(&mut models, "interior", &options.interior, false)?;
    let rooms_only;
    let options = if options.receivers.is_empty() && !options.interior.is_empty() {
        rooms_only = LoadOptions { receivers: options.interior.clone(), ..options.clone() };
        &rooms_only
    } else {
        options
    };
    let (scene, mut notes) = build(models, energyplus.as_ref(), options)?;
    notes.extend(city_notes);
    Ok(Loaded { scene, energyplus, notes, glazing, interior })
}

/// A city model already read (a district's tile) into a scene, as [`load_bytes_all`] would.
pub fn load_city(city: &cityjson::City, options: &LoadOptions) -> Result<Loaded> {
    check_options(options)?;
    let (scene, notes) = build(vec![cityjson::city_model(city, options.north)?], None, options)?;
    Ok(Loaded { scene, energyplus: None, notes, glazing: Vec::new(), interior: Vec::new() })
}

/// What a run over a city model says of north: its grid north is true north unless turned.
pub fn city_north_note(north: f64) -> String {
    if north == 0.0 {
        "grid north is taken as true north (the model's +y; turn it with the north option)".to_string()
    } else {
        format!("the model's grid north (+y) is taken as {north}° clockwise from true north")
    }
}

fn read_energyplus(name: &str, bytes: &[u8], epjson: bool, dir: Option<&std::path::Path>) -> Result<EnergyPlusInput> {
    let text = match std::str::from_utf8(bytes) {
        Ok(text) => text.to_string(),
        // The IDF reader's message names the line and byte; epJSON must be UTF-8 just the same.
        Err(_) => return Err(idf::parse_idf_bytes(name, bytes).err().unwrap_or_else(|| Error::model(name, "not UTF-8 text"))),
    };
    let objects = if epjson { epjson::parse_epjson(name, &text)? } else { idf::parse_idf(name, &text)? };
    let building = building::read_building(name, &objects)?;
    for warning in &building.warnings {
        log::warn!("{name}: {warning}");
    }
    if !building.skipped.is_empty() {
        log::info!("{name}: objects without geometry ignored: {}", building.skipped.join(", "));
    }
    let shades = shades::read_shade_schedules(name, &objects, dir)?;
    Ok(EnergyPlusInput { file: name.to_string(), text, objects, epjson, building, shades })
}

fn check_options(options: &LoadOptions) -> Result<()> {
    if !options.north.is_finite() {
        return Err(Error::argument("north", format!("{} is not a finite angle", options.north)));
    }
    Ok(())
}

/// Each transmitting EnergyPlus shade's τ for this load, by lower-case name: the options' value,
/// else its schedule's when that never changes (an opaque shade has no entry).
fn shade_veils(energyplus: &EnergyPlusInput, options: &LoadOptions) -> Result<HashMap<String, f64>> {
    let mut veils: HashMap<String, f64> = HashMap::new();
    for group in &energyplus.shades {
        if let Some(t) = group.constant() {
            veils.extend(group.shades.iter().map(|s| (s.to_ascii_lowercase(), t)));
        }
    }
    for (name, t) in &options.shade_transmittance {
        if !(0.0..=1.0).contains(t) {
            return Err(Error::argument("shade_transmittance", format!("{name}={t}: a transmittance must be in [0, 1]")));
        }
        veils.insert(name.to_ascii_lowercase(), *t);
    }
    veils.retain(|_, t| *t > 0.0);
    Ok(veils)
}

fn build(models: Vec<GltfModel>, energyplus: Option<&EnergyPlusInput>, options: &LoadOptions) -> Result<(Scene, Vec<String>)> {
    let select = match energyplus {
        Some(_) if options.receivers.is_empty() => Selection::Context,
        _ => Selection::new(&models, options)?,
    };
    let veils = Veils::new(options)?;
    let mut rules = city_where::WhereRules::new(&options.attribute_rules)?;
    check_buildings(&models, &options.buildings)?;
    let mut builder = SceneBuilder::new();
    if let Some(origin) = options.origin {
        builder.set_origin(origin);
    }
    let mut matched = 0usize;
    if let Some(ep) = energyplus {
        let b = &ep.building;
        let veils = shade_veils(ep, options)?;
        if options.all_energyplus_surfaces {
            if let Some(shade) = veils.keys().next() {
                return Err(Error::model(
                    &ep.file,
                    format!(
                        "shade '{shade}' lets light through, but a shade is a receiver in the Imported form's columns and a receiver is opaque: hook with the Scheduled form"
                    ),
                ));
            }
            b.add_all_to(&mut builder)?;
            matched += b.surfaces.len();
        } else {
            b.add_to_with(&mut builder, &veils)?;
            matched += b.receiver_names().len();
        }
    }
    for model in models {
        model.add_to(
            &mut builder,
            |n| {
                let explicit = matches!(select, Selection::Globs(..));
                let hit = select.is_receiver(n)
                    && in_buildings(n, &options.buildings)
                    && rules.admit(n.city.as_ref().map(|c| &c.attributes))
                    && (explicit || veils.of(n).is_opaque());
                matched += hit as usize;
                hit
            },
            |n| veils.of(n),
        );
    }
    veils.check_used()?;
    if matched == 0 {
        return Err(Error::NoReceivers(rules.refusal().unwrap_or_else(|| select.explain())));
    }
    let scene = builder.build()?;
    let mut notes = Vec::new();
    if matches!(select, Selection::Named) && scene.receivers.len() > MANY_RECEIVERS {
        let note = many_receivers_note(&scene, matched);
        log::warn!("{note}");
        notes.push(note);
    }
    Ok((scene, notes))
}

/// The error for an id of the `buildings` parameter that names no building of `file`.
pub fn unknown_building(id: &str, file: &str) -> Error {
    Error::argument("buildings", format!("'{id}' is no Building or BuildingPart with geometry in {file} (at the level of detail read)"))
}

/// Refuses an id of `buildings` that no city surface of `models` has as its building or its
/// CityObject, as a misspelt foliage pattern is refused: it would leave a building out unsaid.
fn check_buildings(models: &[GltfModel], buildings: &[String]) -> Result<()> {
    let known = |id: &str| {
        models
            .iter()
            .flat_map(|m| &m.nodes)
            .filter_map(|n| n.city.as_ref())
            .any(|t| t.building.is_some() && (t.object == id || t.building.as_deref() == Some(id)))
    };
    match buildings.iter().find(|id| !known(id)) {
        None => Ok(()),
        Some(id) => {
            let cities: Vec<&str> = models.iter().filter(|m| m.nodes.iter().any(|n| n.city.is_some())).map(|m| m.file.as_str()).collect();
            Err(unknown_building(
                id,
                &if cities.is_empty() { "the models (no city model among them)".to_string() } else { cities.join(", ") },
            ))
        }
    }
}

/// Whether a node may receive under the `buildings` option: a city surface of a building (or
/// building part) listed there, or anything when the list is empty; what is not a building never.
fn in_buildings(node: &GltfNode, buildings: &[String]) -> bool {
    match &node.city {
        None => true,
        Some(tags) => in_buildings_of(tags.building.as_deref(), &tags.object, buildings),
    }
}

/// [`in_buildings`] for a city surface of `object`, whose building is `building`.
fn in_buildings_of(building: Option<&str>, object: &str, buildings: &[String]) -> bool {
    match building {
        None => false,
        Some(b) => buildings.is_empty() || buildings.iter().any(|id| id == b || id == object),
    }
}

/// A city's receivers under the receiver rule of some load options, seen a surface at a time by
/// a reader that never holds the whole city (a district's first pass), so that a rule no surface
/// of the file meets is refused before anything is counted or written, as a whole load refuses
/// it. It follows the load's rule (the `receivers` patterns over a surface's name or semantic
/// type, else the roofs and walls, else every surface; only the `buildings` asked for; the `where`
/// rules over attributes) but not
/// its see-through surfaces, so it refuses only a city where nothing can receive at all.
pub struct CityReceivers {
    rule: Option<Selection>,
    buildings: Vec<String>,
    /// Surfaces the patterns match, or without them the roofs and walls (before the `where` rules).
    marked: usize,
    /// Without patterns, every surface of the buildings asked for (before the `where` rules).
    named: usize,
    /// The `where` rules put to the marked surfaces, and (without patterns) to every surface: the
    /// load's default falls back to every surface where none is a roof or wall.
    rules_marked: city_where::WhereRules,
    rules_named: city_where::WhereRules,
}

impl CityReceivers {
    /// The rule of `options` (its `receivers` patterns, else the default, and its `where`
    /// rules), nothing seen yet.
    pub fn new(options: &LoadOptions) -> Result<Self> {
        let rule = if options.receivers.is_empty() { None } else { Some(Selection::globs(&options.receivers)?) };
        let rules = city_where::WhereRules::new(&options.attribute_rules)?;
        Ok(Self { rule, buildings: options.buildings.clone(), marked: 0, named: 0, rules_marked: rules.clone(), rules_named: rules })
    }

    /// Counts surface `s` if the rule would put it to the `where` rules, and puts it to them.
    pub fn see(&mut self, s: &cityjson::CitySurface) {
        if !in_buildings_of(s.building.as_deref(), &s.object, &self.buildings) {
            return;
        }
        let marked = match &self.rule {
            Some(Selection::Globs(set, _)) => set.is_match(&s.name) || s.kind.as_deref().is_some_and(|k| set.is_match(k)),
            _ => {
                self.named += 1;
                self.rules_named.admit(Some(&s.attributes));
                cityjson::default_receiver(s)
            }
        };
        if marked {
            self.marked += 1;
            self.rules_marked.admit(Some(&s.attributes));
        }
    }

    /// The load's own error where no surface seen can receive: none chosen, or none of those
    /// meeting the `where` rules (naming the rule and its attribute).
    pub fn check(&self) -> Result<()> {
        let (chosen, rules) = if self.marked > 0 { (self.marked, &self.rules_marked) } else { (self.named, &self.rules_named) };
        if chosen == 0 {
            return Err(Error::NoReceivers(self.rule.as_ref().unwrap_or(&Selection::Named).explain()));
        }
        match rules.refusal() {
            Some(why) => Err(Error::NoReceivers(why)),
            None => Ok(()),
        }
    }
}

/// What the default rule chose, when it chose many, and how to narrow it.
fn many_receivers_note(scene: &Scene, nodes: usize) -> String {
    let first: Vec<&str> = scene.receivers.iter().take(5).map(|r| r.name.as_str()).collect();
    format!(
        "{} receivers ({nodes} nodes: {}, …) were chosen by the default rule, every named node with a mesh, as no node is \
         marked {{\"sunlit\": {{\"receiver\": true}}}} in its extras; each one is a column of the output and a view of \
         its own for every sun. To count fewer, choose receivers by node name with the receivers option (glob patterns, e.g. \
         'Wall*'), or mark the receiving nodes in their extras",
        scene.receivers.len(),
        first.join(", ")
    )
}

/// A node pattern as given: the parameter and its text (`("foliage", "pine*")`).
type Label = (&'static str, String);

/// The foliage and transmittance rules in force for one load.
struct Veils {
    foliage: Vec<(globset::GlobMatcher, Label)>,
    transmittance: Vec<(globset::GlobMatcher, Label, f64)>,
    /// Patterns that matched some node, so a misspelt one is reported rather than ignored.
    used: std::cell::RefCell<std::collections::HashSet<Label>>,
}

impl Veils {
    fn new(options: &LoadOptions) -> Result<Self> {
        let glob = |flag: &str, pattern: &str| {
            globset::GlobBuilder::new(pattern)
                .case_insensitive(true)
                .build()
                .map(|g| g.compile_matcher())
                .map_err(|e| Error::argument(flag.to_string(), format!("'{pattern}': {e}")))
        };
        let foliage = options.foliage.iter().map(|p| Ok((glob("foliage", p)?, ("foliage", p.clone())))).collect::<Result<_>>()?;
        let transmittance = options
            .transmittance
            .iter()
            .map(|(p, t)| {
                if !(0.0..1.0).contains(t) {
                    return Err(Error::argument("transmittance", format!("{p}={t}: the transmittance must be in [0, 1)")));
                }
                Ok((glob("transmittance", p)?, ("transmittance", format!("{p}={t}")), *t))
            })
            .collect::<Result<_>>()?;
        Ok(Self { foliage, transmittance, used: Default::default() })
    }

    /// A node's veil: its extras, then the options (which win).
    fn of(&self, node: &GltfNode) -> NodeVeil {
        let mut veil = node.veil;
        let mut used = self.used.borrow_mut();
        for (g, label) in &self.foliage {
            if g.is_match(&node.name) {
                veil.foliage = true;
                used.insert(label.clone());
            }
        }
        for (g, label, t) in &self.transmittance {
            if g.is_match(&node.name) {
                veil.transmittance = *t;
                used.insert(label.clone());
            }
        }
        veil
    }

    fn check_used(&self) -> Result<()> {
        let used = self.used.borrow();
        let labels = self.foliage.iter().map(|(_, l)| l).chain(self.transmittance.iter().map(|(_, l, _)| l));
        match labels.into_iter().find(|l| !used.contains(*l)) {
            Some((what, pattern)) => Err(Error::Unmatched { what: what.to_string(), pattern: pattern.clone() }),
            None => Ok(()),
        }
    }
}

/// The receiver rule in force for one load.
enum Selection {
    Globs(globset::GlobSet, Vec<String>),
    Marked,
    Named,
    /// glTF files beside an EnergyPlus model: context only.
    Context,
}

impl Selection {
    fn new(models: &[GltfModel], options: &LoadOptions) -> Result<Self> {
        if !options.receivers.is_empty() {
            return Self::globs(&options.receivers);
        }
        let any_marked = models.iter().any(|m| m.nodes.iter().any(|n| n.marked));
        Ok(if any_marked { Selection::Marked } else { Selection::Named })
    }

    /// The rule of the `receivers` patterns (case-insensitive globs over names and types).
    fn globs(patterns: &[String]) -> Result<Self> {
        let mut set = globset::GlobSetBuilder::new();
        for pattern in patterns {
            let glob = globset::GlobBuilder::new(pattern)
                .case_insensitive(true)
                .build()
                .map_err(|e| Error::argument("receivers", format!("'{pattern}': {e}")))?;
            set.add(glob);
        }
        let set = set.build().map_err(|e| Error::argument("receivers", e.to_string()))?;
        Ok(Selection::Globs(set, patterns.to_vec()))
    }

    fn is_receiver(&self, node: &GltfNode) -> bool {
        match self {
            Selection::Globs(set, _) => {
                set.is_match(&node.name) || node.city.as_ref().and_then(|c| c.kind.as_deref()).is_some_and(|k| set.is_match(k))
            }
            Selection::Marked => node.marked,
            Selection::Named => node.named,
            Selection::Context => false,
        }
    }

    fn explain(&self) -> NoReceivers {
        match self {
            Selection::Globs(_, p) => NoReceivers::Unmatched(p.clone()),
            Selection::Marked => NoReceivers::Other("no node is marked as a receiver".into()),
            Selection::Named => NoReceivers::Unnamed,
            Selection::Context => NoReceivers::Other("the EnergyPlus model has no outdoor surface or window".into()),
        }
    }
}

#[cfg(test)]
mod web_path_tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    /// A .gltf naming an external buffer, and that buffer: one triangle in the ground plane.
    fn gltf_with_bin(uri: &str) -> (Vec<u8>, Vec<u8>) {
        let bin: Vec<u8> = [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0].iter().flat_map(|f| f.to_le_bytes()).collect();
        let json = format!(
            r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"uri":"{uri}","byteLength":36}}],"bufferViews":[{{"buffer":0,"byteLength":36}}],
            "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,-1],"max":[1,0,0]}}],
            "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],"nodes":[{{"name":"tri","mesh":0}}],"scenes":[{{"nodes":[0]}}]}}"#
        );
        (json.into_bytes(), bin)
    }

    #[test]
    fn a_gltf_finds_its_buffer_among_the_given_files() {
        let (gltf, bin) = gltf_with_bin("tri.bin");
        let files = vec![("scene.gltf".to_string(), gltf), ("tri.bin".to_string(), bin)];
        let scene = load_bytes(&files, &LoadOptions::default()).unwrap();
        assert_eq!(scene.receivers.len(), 1);
        assert!((scene.receivers[0].area - 0.5).abs() < 1e-6);
    }

    #[test]
    fn a_gltf_without_its_buffer_names_it() {
        let (gltf, _) = gltf_with_bin("tri.bin");
        let error = load_bytes(&[("scene.gltf".to_string(), gltf)], &LoadOptions::default()).unwrap_err().to_string();
        assert!(error.starts_with("scene.gltf: external buffer 'tri.bin' was not given"), "{error}");
    }
}

#[cfg(test)]
mod many_receivers_tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use base64::Engine as _;

    /// `n` named nodes placing one ground triangle side by side, embedded as one .gltf.
    fn named_triangles(n: usize) -> Vec<u8> {
        let bin: Vec<u8> = [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0].iter().flat_map(|f| f.to_le_bytes()).collect();
        let data = base64::engine::general_purpose::STANDARD.encode(bin);
        let nodes: Vec<String> = (0..n).map(|i| format!(r#"{{"name":"part{i}","mesh":0,"translation":[{},0,0]}}"#, 2 * i)).collect();
        let roots: Vec<String> = (0..n).map(|i| i.to_string()).collect();
        format!(
            r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"uri":"data:application/octet-stream;base64,{data}","byteLength":36}}],
            "bufferViews":[{{"buffer":0,"byteLength":36}}],
            "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,-1],"max":[1,0,0]}}],
            "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],"nodes":[{}],"scenes":[{{"nodes":[{}]}}]}}"#,
            nodes.join(","),
            roots.join(",")
        )
        .into_bytes()
    }

    #[test]
    fn many_default_receivers_are_reported_with_how_to_narrow_them() {
        let loaded = load_bytes_all(&[("cad.gltf".into(), named_triangles(MANY_RECEIVERS + 1))], &LoadOptions::default()).unwrap();
        assert_eq!(loaded.scene.receivers.len(), MANY_RECEIVERS + 1);
        let [note] = loaded.notes.as_slice() else { panic!("{:?}", loaded.notes) };
        assert!(
            note.starts_with("201 receivers (201 nodes: part0, part1, part2, part3, part4, …) were chosen by the default rule"),
            "{note}"
        );
        assert!(note.contains("receivers option") && note.contains("extras"), "{note}");
    }

    #[test]
    fn few_or_chosen_receivers_are_not_reported() {
        let few = load_bytes_all(&[("cad.gltf".into(), named_triangles(MANY_RECEIVERS))], &LoadOptions::default()).unwrap();
        assert!(few.notes.is_empty());
        let chosen = LoadOptions { receivers: vec!["part*".into()], ..Default::default() };
        let many = load_bytes_all(&[("cad.gltf".into(), named_triangles(MANY_RECEIVERS + 1))], &chosen).unwrap();
        assert_eq!(many.scene.receivers.len(), MANY_RECEIVERS + 1);
        assert!(many.notes.is_empty());
    }
}
