//! Districts: a city model's receivers split into square tiles, each tile counted against the
//! casters within a context radius of it, locally or as a Slurm job array, then merged into one
//! solar cadastre ([`crate::export::cadastre`]).
//!
//! Owns:
//! - tiles: a building belongs to the tile holding its footprint centroid (the area-weighted
//!   centroid of its `GroundSurface`s seen from above, else the centre of its outline's box), on a
//!   grid of `tile` metres from the city's south-west corner; only tiles with buildings exist,
//!   numbered row by row from the south;
//! - context: a tile is counted with every surface (any object: buildings, terrain, trees) whose
//!   box seen from above comes within `context` metres of the tile's square. A shadow is held
//!   when the radius reaches every caster that can shade a receiver at any counted sun: for a
//!   caster `H` metres above a receiver's lowest point and the lowest sun counted at altitude
//!   `a` (EnergyPlus's sun-up rule, cos zenith ≥ 1e-5, is `a` = 0.00057°), `context ≥ H / tan a`,
//!   and the sky views need the same down to the horizon; a radius reaching across the whole
//!   city always holds. A smaller radius misses only low-sun shadows and distant horizon;
//! - one f32 origin for every tile (the city's centre), so a receiver rounds alike in every cut;
//! - records: `.done/tile-K.json` per finished tile (the inputs' fingerprint and its rows,
//!   written atomically after counting), `.failed/tile-K.json` per failed one; the merge writes
//!   `cadastre.city.json`, `cadastre.csv` and `cadastre-roofs.geojson` (with a grid, also the
//!   roofs' points; with year tables, `cadastre-year.csv`, [`super::district_table`]) when every
//!   tile is done, and `failed.csv` listing the rest;
//! - per-point maps on roofs ([`RoofGrid`]): a tile's roofs gridded and each point's year counted
//!   with the map's exact rays ([`crate::map`]), each roof's usable area from its points; with
//!   `pv`, their PV tools' files ([`super::district_pv`]).

use std::collections::{BTreeMap, HashMap, HashSet};
use std::path::{Path, PathBuf};

use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};

use super::district_pv::{self, TilePv};
use super::district_table::{self, YearPart};
use super::record::{self, Failed, Fingerprint};
use crate::count::gpu::CounterOptions;
use crate::count::hybrid::{EngineKind, HybridEngine, ProfileSource};
use crate::error::{Error, Result};
use crate::export::cadastre::{self, CadastreRow};
use crate::export::cadastre_points::{self, PointRow};
use crate::export::pv::SamSums;
use crate::export::write_atomic;
use crate::map::{Mapper, Period, Site, point_sky};
use crate::model::LoadOptions;
use crate::model::cityjson::CitySource;
use crate::model::cityjson::{City, CitySurface};
use crate::platform::seconds as now;
use crate::scene::Scene;
use crate::sky::patches::SkyPatches;
use crate::sun::weather::Weather;
pub use crate::sweep::district_year::RECEIVER_BATCH;
use crate::sweep::district_year::{TileStages, TileYear, tile_year};
use crate::year::annual::Progress;
use crate::year::settings::Resolved;

/// The merged outputs' names in the output folder.
pub const CADASTRE_CITYJSON: &str = "cadastre.city.json";
/// The CSV beside it.
pub const CADASTRE_CSV: &str = "cadastre.csv";
/// The roofs' GeoJSON beside it.
pub const CADASTRE_GEOJSON: &str = "cadastre-roofs.geojson";
/// With a grid: the roofs' points as CSV…
pub const POINTS_CSV: &str = "cadastre-points.csv";
/// … and as GeoJSON.
pub const POINTS_GEOJSON: &str = "cadastre-points.geojson";

/// Per-point maps on roofs: the grid's spacing, and the threshold of a roof's usable area.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoofGrid {
    /// Metres between points.
    pub spacing: f64,
    /// Total irradiation a point needs to count towards its roof's usable area, kWh/m².
    pub min_kwh_m2: Option<f64>,
}

impl RoofGrid {
    /// Refuses a spacing that is not positive and a threshold that is not a number ≥ 0.
    pub fn new(spacing: f64, min_kwh_m2: Option<f64>) -> Result<Self> {
        if !(spacing.is_finite() && spacing > 0.0) {
            return Err(Error::argument("spacing", format!("{spacing} m: a grid spacing must be a positive number of metres")));
        }
        if let Some(m) = min_kwh_m2.filter(|m| !(m.is_finite() && *m >= 0.0)) {
            return Err(Error::argument("min_kwh_m2", format!("{m} is not a number of kWh/m² (0 or more)")));
        }
        Ok(Self { spacing, min_kwh_m2 })
    }
}

/// One tile: its grid cell, square and buildings.
#[derive(Debug, Clone, PartialEq)]
pub struct Tile {
    /// Its number (the array task index).
    pub index: usize,
    /// Column and row on the grid.
    pub cell: (i64, i64),
    /// South-west and north-east corners, local metres.
    pub square: (DVec2, DVec2),
    /// Its buildings' ids, sorted.
    pub buildings: Vec<String>,
}

/// A city cut into tiles.
#[derive(Debug, Clone)]
pub struct Tiling {
    /// Tile side, m.
    pub tile: f64,
    /// Context radius, m.
    pub context: f64,
    /// The tiles holding a building.
    pub tiles: Vec<Tile>,
    /// The f32 origin every tile's scene uses.
    pub origin: DVec3,
}

/// A building's footprint centroid: its ground surfaces' area-weighted centroid seen from above,
/// else the centre of its outline's box.
pub fn footprint_centroid(surfaces: &[&CitySurface]) -> DVec2 {
    let grounds: Vec<&CitySurface> = surfaces.iter().copied().filter(|s| is_ground(s)).collect();
    centroid_or_box(&grounds, box_of(surfaces.iter().copied()))
}

fn is_ground(s: &CitySurface) -> bool {
    s.kind.as_deref() == Some("GroundSurface")
}

/// The area-weighted centroid of `grounds` seen from above, else the centre of `outline`.
fn centroid_or_box(grounds: &[&CitySurface], outline: (DVec2, DVec2)) -> DVec2 {
    let (mut area, mut moment) = (0.0, DVec2::ZERO);
    for s in grounds {
        for (r, ring) in s.rings.iter().enumerate() {
            let (a, c) = shoelace(ring);
            // Holes take their area away, whatever their winding.
            let a = if r == 0 { a.abs() } else { -a.abs() };
            area += a;
            moment += c * a;
        }
    }
    if area > 1e-9 {
        return moment / area;
    }
    let (lo, hi) = outline;
    (lo + hi) * 0.5
}

/// Signed area and centroid of a ring seen from above.
fn shoelace(ring: &[DVec3]) -> (f64, DVec2) {
    let (mut a, mut c) = (0.0, DVec2::ZERO);
    for k in 0..ring.len() {
        let (p, q) = (ring[k].truncate(), ring[(k + 1) % ring.len()].truncate());
        let cross = p.perp_dot(q);
        a += cross;
        c += (p + q) * cross;
    }
    if a.abs() < 1e-12 { (0.0, DVec2::ZERO) } else { (a / 2.0, c / (3.0 * a)) }
}

/// The box of surfaces seen from above.
fn box_of<'a>(surfaces: impl Iterator<Item = &'a CitySurface>) -> (DVec2, DVec2) {
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for p in surfaces.flat_map(|s| s.rings.iter().flatten()) {
        lo = lo.min(p.truncate());
        hi = hi.max(p.truncate());
    }
    (lo, hi)
}

/// What cutting a city into tiles, and choosing a tile's part, needs of it, gathered from its
/// surfaces one at a time ([`CityPlan::read`] never holds them all): each building's ground
/// surfaces and outline box, each object's box seen from above, and the city's boxes.
pub struct CityPlan {
    /// The city without its surfaces (file, version, reference system, offset).
    pub head: City,
    /// The model's north turn, degrees.
    north: f64,
    /// Per building (by id): its ground surfaces in file order, and the box of all its surfaces.
    buildings: BTreeMap<String, (Vec<CitySurface>, (DVec2, DVec2))>,
    /// Per CityObject: its building, and the box of its surfaces seen from above.
    objects: HashMap<String, (Option<String>, (DVec2, DVec2))>,
    /// The box of every surface seen from above.
    outline: (DVec2, DVec2),
    /// The box of every surface turned by north, in 3D (the scene's frame).
    turned: (DVec3, DVec3),
}

impl CityPlan {
    fn empty(head: City, north: f64) -> Self {
        let (inf, neg) = (f64::INFINITY, f64::NEG_INFINITY);
        Self {
            head,
            north,
            buildings: BTreeMap::new(),
            objects: HashMap::new(),
            outline: (DVec2::splat(inf), DVec2::splat(neg)),
            turned: (DVec3::splat(inf), DVec3::splat(neg)),
        }
    }

    /// Reads a CityJSON file's plan, a surface at a time (a CityJSONSeq a line at a time);
    /// `north` (degrees) turns the model as the scene will.
    pub fn read(file: &str, bytes: &[u8], lod: Option<&str>, north: f64) -> Result<Self> {
        Self::of_source(file, &CitySource::parse(file, bytes)?, lod, north)
    }

    /// [`Self::read`] of a file already parsed (which later passes read again without parsing a
    /// document twice).
    pub fn of_source(file: &str, source: &CitySource, lod: Option<&str>, north: f64) -> Result<Self> {
        Self::of_source_seeing(file, source, lod, north, &mut |_| {})
    }

    /// [`Self::of_source`], showing `see` each surface as it passes (the one pass over the file
    /// that sees every surface, so checks of the whole city ride on it).
    pub fn of_source_seeing(
        file: &str,
        source: &CitySource,
        lod: Option<&str>,
        north: f64,
        see: &mut dyn FnMut(&CitySurface),
    ) -> Result<Self> {
        let mut plan = Self::empty(
            City { file: file.to_string(), version: String::new(), reference_system: None, offset: DVec3::ZERO, surfaces: Vec::new() },
            north,
        );
        let head = crate::model::cityjson::read_city_from(file, source, lod, None, &mut |s| {
            see(&s);
            plan.add(s)
        })?;
        plan.head = head;
        Ok(plan)
    }

    /// The plan of a city read whole.
    pub fn of(city: &City, north: f64) -> Self {
        let mut plan = Self::empty(City { surfaces: Vec::new(), ..city.clone() }, north);
        city.surfaces.iter().cloned().for_each(|s| plan.add(s));
        plan
    }

    fn add(&mut self, s: CitySurface) {
        // As the city's model turns it (`cityjson::city_model`), so the box is the scene's.
        let turn = glam::DMat4::from_rotation_z(-self.north.to_radians());
        let grow = |b: &mut (DVec2, DVec2), p: DVec2| *b = (b.0.min(p), b.1.max(p));
        let blank = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        let object = self.objects.entry(s.object.clone()).or_insert_with(|| (s.building.clone(), blank));
        let mut building = s.building.as_ref().map(|b| self.buildings.entry(b.clone()).or_insert_with(|| (Vec::new(), blank)));
        for p in s.rings.iter().flatten() {
            grow(&mut self.outline, p.truncate());
            grow(&mut object.1, p.truncate());
            if let Some((_, b)) = building.as_mut() {
                grow(b, p.truncate());
            }
            // The scene builder centres a whole load on its f32 vertices turned; so does the
            // box here, bit for bit, so a district's origin is a whole load's (`sunlit annual`'s)
            // and its tiles' answers are that load's, not a rounding apart.
            let w = turn.transform_point3(p.as_vec3().as_dvec3());
            self.turned = (self.turned.0.min(w), self.turned.1.max(w));
        }
        if let Some((grounds, _)) = building.filter(|_| is_ground(&s)) {
            grounds.push(s);
        }
    }

    /// Refuses an id in `buildings` that is no `Building` or `BuildingPart` with geometry (at the
    /// level of detail read), naming it and the file, before anything is counted or written: a
    /// misspelt id would otherwise leave its building out of the cadastre without a word.
    pub fn check_buildings(&self, buildings: &[String]) -> Result<()> {
        // A building may hold no geometry of its own, only its parts': it is a key of
        // `buildings` then, not of `objects`.
        let known = |id: &str| self.buildings.contains_key(id) || self.objects.get(id).is_some_and(|(building, _)| building.is_some());
        match buildings.iter().find(|id| !known(id)) {
            Some(id) => Err(crate::model::unknown_building(id, &self.head.file)),
            None => Ok(()),
        }
    }

    /// Whether tile `tile` of `tiling` is counted with CityObject `id`: one of its own buildings',
    /// or one whose box comes within the context ([`tile_city`]'s surfaces all lie in such
    /// objects).
    pub fn keeps(&self, tiling: &Tiling, tile: &Tile, id: &str) -> bool {
        self.objects.get(id).is_some_and(|(building, outline)| {
            building.as_ref().is_some_and(|b| tile.buildings.binary_search(b).is_ok()) || within(tiling, tile, *outline)
        })
    }
}

/// Whether a box seen from above comes within the context radius of the tile's square.
fn within(tiling: &Tiling, tile: &Tile, (lo, hi): (DVec2, DVec2)) -> bool {
    let (sw, ne) = tile.square;
    let gap = (sw - hi).max(lo - ne).max(DVec2::ZERO);
    gap.length() <= tiling.context
}

/// Cuts `city` into tiles of `tile` metres with a `context` radius; `north` (degrees) turns the
/// model as the scene will, so the shared origin is the scene's.
pub fn tiles(city: &City, tile: f64, context: f64, north: f64) -> Result<Tiling> {
    tiles_of(&CityPlan::of(city, north), tile, context)
}

/// Cuts a city, from its plan, into tiles of `tile` metres with a `context` radius.
pub fn tiles_of(plan: &CityPlan, tile: f64, context: f64) -> Result<Tiling> {
    if !(tile.is_finite() && tile > 0.0) {
        return Err(Error::argument("tile", format!("{tile} is not a positive size in metres")));
    }
    if !(context.is_finite() && context > 0.0) {
        return Err(Error::argument("context", format!("{context} is not a positive radius in metres")));
    }
    if plan.buildings.is_empty() {
        return Err(Error::model(&plan.head.file, "no Building with geometry: nothing to tile"));
    }
    let lo = plan.outline.0;
    let mut cells: BTreeMap<(i64, i64), Vec<String>> = BTreeMap::new();
    for (id, (grounds, outline)) in &plan.buildings {
        let grounds: Vec<&CitySurface> = grounds.iter().collect();
        let c = (centroid_or_box(&grounds, *outline) - lo) / tile;
        cells.entry((c.y.floor() as i64, c.x.floor() as i64)).or_default().push(id.to_string());
    }
    let tiles = cells
        .into_iter()
        .enumerate()
        .map(|(index, ((row, column), buildings))| {
            let sw = lo + DVec2::new(column as f64, row as f64) * tile;
            Tile { index, cell: (column, row), square: (sw, sw + DVec2::splat(tile)), buildings }
        })
        .collect();
    // The centre of the city's box after the north turn: where the scene builder would centre
    // the whole city.
    let (tlo, thi) = plan.turned;
    let origin = if tlo.x > thi.x { DVec3::ZERO } else { (tlo + thi) * 0.5 };
    Ok(Tiling { tile, context, tiles, origin })
}

/// The part of `city` a tile is counted with: every surface whose box comes within the context
/// radius of the tile's square (its own buildings always do).
pub fn tile_city(city: &City, tiling: &Tiling, tile: &Tile) -> City {
    let near = |s: &CitySurface| within(tiling, tile, box_of(std::iter::once(s)));
    let own: std::collections::HashSet<&str> = tile.buildings.iter().map(String::as_str).collect();
    let surfaces = city.surfaces.iter().filter(|s| s.building.as_deref().is_some_and(|b| own.contains(b)) || near(s)).cloned().collect();
    City { surfaces, ..city.clone() }
}

/// Reads only what tile `k` is counted with from the city file: the surfaces of the CityObjects
/// [`CityPlan::keeps`] takes (a CityJSONSeq's other lines skipped unbuilt), so a tile's memory
/// follows its tile and context. [`tile_city`] of it is [`tile_city`] of the whole city.
pub fn read_tile_city(file: &str, source: &CitySource, lod: Option<&str>, plan: &CityPlan, tiling: &Tiling, k: usize) -> Result<City> {
    let tile = tile_of(tiling, k)?;
    let mut surfaces = Vec::new();
    let keep = |id: &str| plan.keeps(tiling, tile, id);
    let mut city = crate::model::cityjson::read_city_from(file, source, lod, Some(&keep), &mut |s| surfaces.push(s))?;
    city.surfaces = surfaces;
    Ok(city)
}

/// Tile `k`, or an error naming the tiles there are.
fn tile_of(tiling: &Tiling, k: usize) -> Result<&Tile> {
    tiling.tiles.get(k).ok_or_else(|| {
        Error::argument(
            "index",
            format!("{k} is past the last tile ({} tiles: 0..={})", tiling.tiles.len(), tiling.tiles.len().saturating_sub(1)),
        )
    })
}

/// What counting a tile needs beside the city: the readers' options (receivers, buildings, lod,
/// north), the year's settings, the weather and sky, and the engine.
pub struct TileSettings<'a> {
    /// How the city is read into a scene (`buildings` narrows the receivers further).
    pub load: LoadOptions,
    /// Location, sampling, calendar.
    pub settings: &'a Resolved,
    /// The weather's hours.
    pub weather: &'a Weather,
    /// The sky's patches.
    pub patches: &'a SkyPatches,
    /// Which engine answers views.
    pub engine: EngineKind,
    /// The GPU's options.
    pub counter: CounterOptions,
    /// GPU lanes.
    pub lanes: Option<usize>,
    /// Per-point maps on the roofs.
    pub grid: Option<RoofGrid>,
    /// With a grid: the points' PV tools' files too.
    pub pv: bool,
    /// Receivers whose year is counted at once ([`RECEIVER_BATCH`] unless chosen): the peak
    /// memory follows it, the answers do not ([`super::district_year`]).
    pub batch: usize,
    /// The output folder, when the receivers' whole-year tables are asked for: each batch's is
    /// written there as the tile counts ([`super::district_table`]).
    pub year_table: Option<PathBuf>,
}

/// What a tile counted.
pub struct TileCount {
    /// One row per receiving surface.
    pub rows: Vec<CadastreRow>,
    /// With a grid: its roofs' points.
    pub points: Vec<PointRow>,
    /// With a grid and `pv` (and points): their PV files' contents.
    pub pv: Option<TilePv>,
    /// With year tables: the parts it wrote.
    pub year: Vec<YearPart>,
    /// Surfaces it was counted with.
    pub casters: usize,
    /// Where its time went.
    pub stages: TileStages,
}

/// Counts tile `k`: its buildings' receivers against its context, the year and the sky, into
/// cadastre rows (and with a grid, its roofs' points).
pub fn count_tile(
    city: &City,
    tiling: &Tiling,
    k: usize,
    s: &TileSettings,
    progress: &mut dyn FnMut(Progress) -> Result<()>,
) -> Result<TileCount> {
    count_tile_in_batches(city, tiling, k, s, s.batch, progress)
}

/// [`count_tile`], the year counted `batch` receivers at a time ([`super::district_year`]).
pub fn count_tile_in_batches(
    city: &City,
    tiling: &Tiling,
    k: usize,
    s: &TileSettings,
    batch: usize,
    progress: &mut dyn FnMut(Progress) -> Result<()>,
) -> Result<TileCount> {
    let start = now();
    let mut stages = TileStages::default();
    let tile = tile_of(tiling, k)?;
    let part = tile_city(city, tiling, tile);
    let buildings = tile_buildings(&part, tile, &s.load.buildings);
    let empty = TileCount { rows: Vec::new(), points: Vec::new(), pv: None, year: Vec::new(), casters: part.surfaces.len(), stages };
    if buildings.is_empty() {
        return Ok(empty);
    }
    let load = LoadOptions { buildings, origin: Some(tiling.origin), ..s.load.clone() };
    let scene = match crate::model::load_city(&part, &load) {
        Ok(loaded) => loaded.scene,
        // Buildings without a chosen surface (a tile of sheds without roofs or walls).
        Err(Error::NoReceivers(_)) => return Ok(empty),
        Err(e) => return Err(e),
    };
    let engine = HybridEngine::new(&scene, s.engine, s.counter, s.lanes, ProfileSource::Cache)?;
    stages.scene = now() - start;
    let TileYear { summaries, hours, parts } = tile_year(&engine, &scene, s, k, batch, &mut stages, progress)?;
    let mut rows = cadastre::rows(&part, &scene, &summaries, &hours)?;
    let start = now();
    let (points, pv) = match s.grid {
        Some(grid) => roof_points(&part, &scene, grid, s, &mut rows)?,
        None => (Vec::new(), None),
    };
    stages.points = now() - start;
    Ok(TileCount { rows, points, pv, year: parts, casters: part.surfaces.len(), stages })
}

/// The ids a tile's scene narrows its receivers to: the tile's own buildings, or of those asked
/// for (`asked`: ids of `Building`s or `BuildingPart`s) the ones whose building is the tile's. A
/// part is matched by its own id, as [`crate::model::load_city`] matches it, not by its building's
/// (which would give every part of that building, or none when only the part was asked for).
fn tile_buildings(part: &City, tile: &Tile, asked: &[String]) -> Vec<String> {
    if asked.is_empty() {
        return tile.buildings.clone();
    }
    let own: HashSet<&str> = tile.buildings.iter().map(String::as_str).collect();
    let ids: HashSet<&str> = part
        .surfaces
        .iter()
        .filter_map(|s| s.building.as_deref().filter(|b| own.contains(b)).map(|b| [b, s.object.as_str()]))
        .flatten()
        .collect();
    asked.iter().filter(|id| ids.contains(id.as_str())).cloned().collect()
}

/// The grid on the scene's roofs, each point's year counted directly (never interpolated: the
/// map's exact rays, [`crate::map`]), each row's usable area, and with `pv` the points' PV files.
fn roof_points(
    city: &City,
    scene: &Scene,
    grid: RoofGrid,
    s: &TileSettings,
    rows: &mut [CadastreRow],
) -> Result<(Vec<PointRow>, Option<TilePv>)> {
    let roofs: std::collections::HashSet<&str> =
        city.surfaces.iter().filter(|c| c.kind.as_deref() == Some("RoofSurface")).map(|c| c.name.as_str()).collect();
    let on_roofs: Vec<u32> = scene
        .receivers
        .iter()
        .enumerate()
        .filter(|(_, r)| roofs.contains(r.name.as_str()) || r.name.rsplit_once('#').is_some_and(|(base, _)| roofs.contains(base)))
        .map(|(i, _)| i as u32)
        .collect();
    let points = crate::map::grid(scene, grid.spacing, &on_roofs)?;
    if points.is_empty() {
        return Ok((Vec::new(), None));
    }
    let mapper = Mapper::new(scene, &points)?;
    let sky = point_sky(&mapper, s.patches, &mut |_, _| {});
    let samples = Period::annual(s.settings.options(None)?.timesteps.per_hour())?.samples();
    let site = Site { location: &s.settings.location, calendar: &s.settings.calendar, weather: Some(s.weather), sky: Some(&sky) };
    let values = mapper.accumulate(&samples, site, &mut |_, _| {})?;
    // Scene positions are the model's turned by north; the model's own add the offset back.
    let back = glam::DMat3::from_rotation_z(s.load.north.to_radians());
    let to_model = |p: DVec3| back * p + city.offset;
    let point_rows = cadastre_points::point_rows(city, scene, &points, &values, grid.min_kwh_m2, rows, to_model)?;
    let pv = if s.pv { Some(district_pv::tile_pv(&mapper, &points, &point_rows, &samples, site, &values)?) } else { None };
    Ok((point_rows, pv))
}

/// A finished tile's record.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TileDone {
    /// The tile's number.
    pub tile: usize,
    /// What it was counted from.
    pub fingerprint: Fingerprint,
    /// Seconds it took.
    pub seconds: f64,
    /// Surfaces counted in it.
    pub casters: usize,
    /// Its receivers' rows.
    pub rows: Vec<CadastreRow>,
    /// With a grid: its roofs' points.
    #[serde(default)]
    pub points: Vec<PointRow>,
    /// With a grid and PV files: its points' SAM sums (its pvlib CSV is in `pv/`).
    #[serde(default)]
    pub pv: Option<SamSums>,
    /// With year tables: its parts (in `year/`).
    #[serde(default)]
    pub year: Vec<YearPart>,
    /// Where its time went (absent in records written before it was kept).
    #[serde(default)]
    pub stages: Option<TileStages>,
    /// The counting process's peak resident memory, MiB, where the OS reports it (a Slurm
    /// without accounting storage has no other record of it).
    #[serde(default)]
    pub peak_mib: Option<f64>,
}

/// The record id of tile `k`.
pub fn tile_id(k: usize) -> String {
    format!("tile-{k}")
}

/// The fingerprint of a district run: its defining arguments and the city file.
pub fn fingerprint(args: &[String], city: &Path) -> Fingerprint {
    Fingerprint::new(args.to_vec(), &[city.to_path_buf()])
}

/// Tile `k`'s record when it is finished with today's fingerprint.
pub fn finished(dir: &Path, k: usize, fingerprint: &Fingerprint) -> Option<TileDone> {
    let text = std::fs::read_to_string(record::done_path(dir, &tile_id(k))).ok()?;
    let done: TileDone = serde_json::from_str(&text).ok()?;
    (done.fingerprint == *fingerprint && done.tile == k).then_some(done)
}

/// Writes a tile's record (atomically) and clears its failure record.
pub fn write_tile(dir: &Path, done: &TileDone) -> Result<()> {
    let path = record::done_path(dir, &tile_id(done.tile));
    let text = serde_json::to_vec(done).map_err(|e| Error::model(path.display().to_string(), e.to_string()))?;
    write_atomic(&path, &text)?;
    let _ = std::fs::remove_file(record::failed_path(dir, &tile_id(done.tile)));
    Ok(())
}

/// Records that tile `k` failed.
pub fn write_tile_failure(dir: &Path, k: usize, exit_code: Option<i32>, reason: &str, log: &Path) -> Result<()> {
    let failed = Failed { id: tile_id(k), exit_code, reason: reason.to_string(), log: log.display().to_string() };
    record::write_failed(dir, &failed)
}

/// Tiles without a finished record.
pub fn pending(dir: &Path, tiling: &Tiling, fingerprint: &Fingerprint) -> Vec<usize> {
    tiling.tiles.iter().map(|t| t.index).filter(|&k| finished(dir, k, fingerprint).is_none()).collect()
}

/// What the merge wrote, or which tiles it lacks.
#[derive(Debug, Clone)]
pub struct DistrictMerged {
    /// The files written (empty when tiles are missing).
    pub written: Vec<PathBuf>,
    /// Rows merged.
    pub surfaces: usize,
    /// Unfinished tiles: (id, exit code, reason).
    pub unfinished: Vec<(String, Option<i32>, String)>,
}

/// Merges every tile's rows into the cadastre's three files (atomically, only when every tile is
/// finished), in the city's surface order; otherwise writes `failed.csv` and nothing else (and
/// reads nothing of the city). The city file (`source`, read at `lod` as the tiles read it) is
/// read once, building only the surfaces the rows name ([`merge_read`]).
pub fn merge(
    dir: &Path,
    source: CitySource,
    file: &str,
    lod: Option<&str>,
    tiling: &Tiling,
    fingerprint: &Fingerprint,
    north_note: &str,
) -> Result<DistrictMerged> {
    let mut rows: Vec<CadastreRow> = Vec::new();
    let mut points: Vec<PointRow> = Vec::new();
    let mut pv: Vec<(usize, SamSums)> = Vec::new();
    let mut year: Vec<YearPart> = Vec::new();
    let mut unfinished = Vec::new();
    for t in &tiling.tiles {
        match finished(dir, t.index, fingerprint) {
            Some(done) => {
                rows.extend(done.rows);
                points.extend(done.points);
                pv.extend(done.pv.map(|sums| (t.index, sums)));
                year.extend(done.year);
            }
            None => {
                let id = tile_id(t.index);
                let (code, reason) = match record::failure(dir, &id) {
                    Some(f) => (f.exit_code, f.reason),
                    None => (None, "no record: not run yet, or stopped before it finished".to_string()),
                };
                unfinished.push((id, code, reason));
            }
        }
    }
    let failed = dir.join(super::FAILED_CSV);
    if !unfinished.is_empty() {
        let mut text = String::from("id,exit_code,reason\n");
        for (id, code, reason) in &unfinished {
            text.push_str(&format!("{id},{},\"{}\"\n", code.map(|c| c.to_string()).unwrap_or_default(), reason.replace('"', "\"\"")));
        }
        write_atomic(&failed, text.as_bytes())?;
        return Ok(DistrictMerged { written: Vec::new(), surfaces: rows.len(), unfinished });
    }
    let _ = std::fs::remove_file(&failed);
    let names: HashSet<&str> = rows.iter().map(|r| r.surface.as_str()).chain(points.iter().map(|p| p.surface.as_str())).collect();
    let (city, doc) = merge_read(source, file, lod, &names)?;
    let city = &city;
    let position: HashMap<&str, usize> = city.surfaces.iter().enumerate().map(|(i, s)| (s.name.as_str(), i)).collect();
    rows.sort_by_key(|r| position.get(r.surface.as_str()).copied().unwrap_or(usize::MAX));
    points.sort_by_key(|p| position.get(p.surface.as_str()).copied().unwrap_or(usize::MAX));
    let mut files = vec![
        (dir.join(CADASTRE_CITYJSON), cadastre::cadastre_document(&city.file, doc, city, &rows)?),
        (dir.join(CADASTRE_CSV), cadastre::cadastre_csv(&rows).into_bytes()),
        (dir.join(CADASTRE_GEOJSON), cadastre::roofs_geojson(city, &rows, north_note)?.into_bytes()),
    ];
    if !points.is_empty() {
        let placer = cadastre::GeoPlacer::new(city);
        files.push((dir.join(POINTS_CSV), cadastre_points::points_csv(&points).into_bytes()));
        files.push((dir.join(POINTS_GEOJSON), cadastre_points::points_geojson(&points, &placer, north_note)?.into_bytes()));
    }
    // The PV files first: their CSV, streamed from the tiles' files, is what a bad tile file fails.
    let pv_files = district_pv::write_merged(dir, &pv, &position)?;
    let year_file = district_table::write_merged(dir, &year, &position)?;
    for (path, bytes) in &files {
        write_atomic(path, bytes)?;
    }
    let written = files.into_iter().map(|(p, _)| p).chain(pv_files).chain(year_file).collect();
    Ok(DistrictMerged { written, surfaces: rows.len(), unfinished })
}

/// What the merge needs of the city, in one read of the file: the input as one document (the
/// one written back with values) and the surfaces `names` names (the rows' and points'), in file
/// order, only their objects' geometry built. The rows' order, the values' places and the roofs'
/// outlines are then those a whole read gives: every name is the same, and the surfaces keep
/// their order.
fn merge_read(source: CitySource, file: &str, lod: Option<&str>, names: &HashSet<&str>) -> Result<(City, serde_json::Value)> {
    // A surface's name is `OBJECT/TYPE/INDEX`, and an id or a type may hold a `/` itself: every
    // part of a name before one of its `/` may be its object's id.
    let objects: HashSet<&str> = names.iter().flat_map(|n| n.match_indices('/').map(|(i, _)| &n[..i])).collect();
    let keep = |id: &str| objects.contains(id);
    let mut surfaces = Vec::new();
    let (mut city, doc) = crate::model::cityjson::read_city_document(file, source, lod, Some(&keep), &mut |s| {
        if names.contains(s.name.as_str()) {
            surfaces.push(s);
        }
    })?;
    city.surfaces = surfaces;
    Ok((city, doc))
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn surface(building: &str, kind: &str, ring: &[(f64, f64)]) -> CitySurface {
        CitySurface {
            name: format!("{building}/{kind}/0"),
            object: building.into(),
            building: Some(building.into()),
            kind: Some(kind.into()),
            geometry: 0,
            index: 0,
            rings: vec![ring.iter().map(|&(x, y)| DVec3::new(x, y, 0.0)).collect()],
            attributes: Default::default(),
        }
    }

    #[test]
    fn buildings_go_to_the_tile_of_their_footprint_centroid() {
        // An L-shaped ground (3 m² + 2 m²: centroid at (1.1, 1.1)) and a square far east.
        let l = surface("a", "GroundSurface", &[(0.0, 0.0), (3.0, 0.0), (3.0, 1.0), (1.0, 1.0), (1.0, 3.0), (0.0, 3.0)]);
        let c = footprint_centroid(&[&l]);
        assert!((c - DVec2::splat(1.1)).length() < 1e-12, "{c}");
        let far = surface("b", "GroundSurface", &[(25.0, 0.0), (27.0, 0.0), (27.0, 2.0), (25.0, 2.0)]);
        let city = City { file: "c".into(), version: "2.0".into(), reference_system: None, offset: DVec3::ZERO, surfaces: vec![l, far] };
        let tiling = tiles(&city, 10.0, 5.0, 0.0).unwrap();
        let cells: Vec<((i64, i64), Vec<String>)> = tiling.tiles.iter().map(|t| (t.cell, t.buildings.clone())).collect();
        assert_eq!(cells, [((0, 0), vec!["a".to_string()]), ((2, 0), vec!["b".to_string()])]);
        // The context: b's box is 15 m east of tile 0's square, a's 13 m west of tile 1's.
        assert_eq!(tile_city(&city, &tiling, &tiling.tiles[0]).surfaces.len(), 1);
        let wide = tiles(&city, 10.0, 15.0, 0.0).unwrap();
        assert_eq!(tile_city(&city, &wide, &wide.tiles[0]).surfaces.len(), 2);
        assert!(tiles(&city, 0.0, 5.0, 0.0).unwrap_err().to_string().contains("tile"));
        assert!(tiles(&city, 10.0, -1.0, 0.0).unwrap_err().to_string().contains("context"));
    }

    /// The city as CityJSONSeq: its header, then one feature a CityObject with its own vertices.
    fn as_seq(doc: &str) -> String {
        fn renumber(
            v: &serde_json::Value,
            map: &mut Vec<u64>,
            old: &[serde_json::Value],
            vertices: &mut Vec<serde_json::Value>,
        ) -> serde_json::Value {
            match v {
                serde_json::Value::Array(items) => {
                    serde_json::Value::Array(items.iter().map(|i| renumber(i, map, old, vertices)).collect())
                }
                serde_json::Value::Number(n) => {
                    let k = n.as_u64().unwrap() as usize;
                    if map[k] == u64::MAX {
                        map[k] = vertices.len() as u64;
                        vertices.push(old[k].clone());
                    }
                    serde_json::json!(map[k])
                }
                other => other.clone(),
            }
        }
        let mut doc: serde_json::Value = serde_json::from_str(doc).unwrap();
        let objects = doc["CityObjects"].as_object().unwrap().clone();
        let old = doc["vertices"].as_array().unwrap().clone();
        doc["CityObjects"] = serde_json::json!({});
        doc["vertices"] = serde_json::json!([]);
        let mut lines = vec![doc.to_string()];
        for (id, mut object) in objects {
            let (mut map, mut vertices) = (vec![u64::MAX; old.len()], Vec::new());
            for g in object["geometry"].as_array_mut().unwrap() {
                g["boundaries"] = renumber(&g["boundaries"], &mut map, &old, &mut vertices);
            }
            let feature =
                serde_json::json!({"type": "CityJSONFeature", "id": id, "CityObjects": {id.clone(): object}, "vertices": vertices});
            lines.push(feature.to_string());
        }
        lines.join("\n") + "\n"
    }

    fn same(a: &City, b: &City) -> bool {
        let key =
            |s: &CitySurface| (s.name.clone(), s.object.clone(), s.building.clone(), s.kind.clone(), s.geometry, s.index, s.rings.clone());
        a.offset == b.offset && a.surfaces.iter().map(key).eq(b.surfaces.iter().map(key))
    }

    /// A tile that reads only its part of the city file (CityJSON and CityJSONSeq) is counted with
    /// exactly the surfaces it was counted with from the whole city, bit for bit, on the same
    /// tiling and origin; and it reads fewer.
    #[test]
    fn a_tile_read_alone_has_the_surfaces_it_has_in_the_whole_city() {
        let doc = crate::model::city_write::district_cityjson(5, 4, 3);
        let seq = as_seq(&doc);
        for (file, text) in [("d.city.json", &doc), ("d.city.jsonl", &seq)] {
            let whole = crate::model::cityjson::read_city(file, text.as_bytes(), None).unwrap();
            assert!(whole.surfaces.len() > 100, "{file}: {} surfaces", whole.surfaces.len());
            let tiling = tiles(&whole, 30.0, 12.0, 20.0).unwrap();
            let plan = CityPlan::read(file, text.as_bytes(), None, 20.0).unwrap();
            let planned = tiles_of(&plan, 30.0, 12.0).unwrap();
            assert_eq!(planned.tiles, tiling.tiles, "{file}");
            assert!(planned.origin == tiling.origin, "{file}");
            assert!(tiling.tiles.len() >= 4, "{file}: {} tiles", tiling.tiles.len());
            for tile in &tiling.tiles {
                let source = CitySource::parse(file, text.as_bytes()).unwrap();
                let read = read_tile_city(file, &source, None, &plan, &tiling, tile.index).unwrap();
                assert!(read.surfaces.len() < whole.surfaces.len(), "{file}: tile {} read the whole city", tile.index);
                let (alone, from_whole) = (tile_city(&read, &tiling, tile), tile_city(&whole, &tiling, tile));
                assert!(
                    same(&alone, &from_whole),
                    "{file}: tile {}: {} surfaces against {}",
                    tile.index,
                    alone.surfaces.len(),
                    from_whole.surfaces.len()
                );
            }
        }
    }

    /// The merge reads the file once, building only the surfaces of the rows, and writes the
    /// bytes a whole read plus a second parse of the file wrote (CityJSON and CityJSONSeq): the
    /// cadastre's CityJSON, its roofs' GeoJSON and the rows' order.
    #[test]
    fn the_merge_reads_the_file_once_and_writes_what_a_whole_read_wrote() {
        let doc = crate::model::city_write::district_cityjson(5, 4, 3);
        let seq = as_seq(&doc);
        for (file, text) in [("d.city.json", &doc), ("d.city.jsonl", &seq)] {
            let whole = crate::model::cityjson::read_city(file, text.as_bytes(), None).unwrap();
            let receivers = whole.surfaces.iter().filter(|s| crate::model::cityjson::default_receiver(s));
            // Rows out of the city's order (as tiles give them), every third surface left out.
            let mut rows: Vec<CadastreRow> = receivers
                .enumerate()
                .filter(|(i, _)| i % 3 != 1)
                .map(|(i, s)| CadastreRow {
                    surface: s.name.clone(),
                    building: s.building.clone().unwrap_or_default(),
                    area: 1.0 + i as f64,
                    direct: 100.0 + i as f64 / 7.0,
                    sky_diffuse: 50.0,
                    ground_reflected: 3.0,
                    total: 153.0 + i as f64 / 7.0,
                    sun_hours: 1000.0,
                    mean_fraction: 0.5,
                    usable_area: None,
                })
                .collect();
            rows.reverse();
            let order = |city: &City, rows: &mut Vec<CadastreRow>| {
                let position: HashMap<&str, usize> = city.surfaces.iter().enumerate().map(|(i, s)| (s.name.as_str(), i)).collect();
                rows.sort_by_key(|r| position.get(r.surface.as_str()).copied().unwrap_or(usize::MAX));
            };
            let mut want_rows = rows.clone();
            order(&whole, &mut want_rows);
            let want_json = cadastre::cadastre_cityjson(file, text.as_bytes(), &whole, &want_rows).unwrap();
            let want_roofs = cadastre::roofs_geojson(&whole, &want_rows, "north").unwrap();

            let names: HashSet<&str> = rows.iter().map(|r| r.surface.as_str()).collect();
            let (city, one) = merge_read(CitySource::parse(file, text.as_bytes()).unwrap(), file, None, &names).unwrap();
            assert_eq!(city.surfaces.len(), rows.len(), "{file}: only the rows' surfaces are built");
            order(&city, &mut rows);
            assert!(rows.iter().map(|r| &r.surface).eq(want_rows.iter().map(|r| &r.surface)), "{file}: the rows' order");
            assert!(cadastre::cadastre_document(file, one, &city, &rows).unwrap() == want_json, "{file}: CityJSON");
            assert!(cadastre::roofs_geojson(&city, &rows, "north").unwrap() == want_roofs, "{file}: roofs");
        }
    }
}
