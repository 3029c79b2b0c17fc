//! `sunlit district --grid --pv`: what PV tools read ([`crate::export::pv`]) for the roofs' grid
//! points, per tile and for the whole city, as `sunlit map --pvlib`, `--sam` write them for a map.
//!
//! Owns:
//! - the points' names: `SURFACE/pJ`, the J-th (from 0) point of that surface, which is its J-th
//!   line in `cadastre-points.csv` (a surface lies in one tile, so the name is the same in its
//!   tile's files and the merged ones);
//! - each tile's files, written by the tile before its record: `pv/tile-K-pvlib.csv` (a column
//!   per point of the tile) and `pv/tile-K-sam.json` (the tile's points as one array), and in the
//!   record the tile's [`SamSums`], which add over tiles;
//! - the merge: `cadastre-points-pvlib.csv`, the tiles' columns side by side in the points CSV's
//!   order (the tiles' files read back whole and the merged file built in memory: a merge holds
//!   about twice the merged CSV), and `cadastre-points-sam.json` from the tiles' sums added, which is the SAM file of every
//!   point taken as one array (the sums of disjoint sets are the sums of their union).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::export::cadastre::csv_field;
use crate::export::cadastre_points::PointRow;
use crate::export::pv::{self, PvSet, SamInputs, SamSums};
use crate::export::write_atomic;
use crate::map::{MapValues, Mapper, Points, Sample, Site};

/// The tiles' PV files' folder in the output folder.
pub const PV_DIR: &str = "pv";
/// The merged pvlib CSV of every roof point.
pub const POINTS_PVLIB: &str = "cadastre-points-pvlib.csv";
/// The merged SAM inputs of every roof point, taken as one array.
pub const POINTS_SAM: &str = "cadastre-points-sam.json";

/// A tile's PV outputs: its pvlib CSV, and the sums its SAM file (and the merged one) is made of.
pub struct TilePv {
    /// The tile's pvlib CSV.
    pub pvlib: Vec<u8>,
    /// The tile's points' SAM sums.
    pub sums: SamSums,
}

/// `SURFACE/pJ` for each point row: J counts the surface's points before it.
pub fn point_names(rows: &[PointRow]) -> Vec<String> {
    let mut seen: HashMap<&str, usize> = HashMap::new();
    rows.iter()
        .map(|r| {
            let j = seen.entry(r.surface.as_str()).or_default();
            *j += 1;
            format!("{}/p{}", r.surface, *j - 1)
        })
        .collect()
}

/// The surface a point's name lies on.
fn surface_of(name: &str) -> &str {
    name.rsplit_once("/p").map_or(name, |(surface, _)| surface)
}

/// The tile's PV outputs from its points (whose rows are `rows`, one a point), counted by
/// `mapper` over the year's `samples` at `per_hour` timesteps; `values` holds their shaded sky.
pub fn tile_pv(
    mapper: &Mapper,
    points: &Points,
    rows: &[PointRow],
    samples: &[Sample],
    site: Site<'_>,
    values: &MapValues,
) -> Result<TilePv> {
    if rows.len() != points.len() {
        return Err(Error::argument("grid", format!("{} point rows for {} points", rows.len(), points.len())));
    }
    let per_hour = (samples.len() / (24 * crate::year::samples::DAYS as usize)).max(1) as u32;
    let series = mapper.visibility_series(samples, site, &mut |_, _| {})?;
    let mut set = PvSet::points(points, &series, per_hour)?;
    set.names = point_names(rows);
    let pvlib = pv::pvlib_csv(&set, site.location, pv::DEFAULT_YEAR)?;
    let directions: Vec<_> = pv::azal_directions().into_iter().map(|d| d.2).collect();
    let azal_fractions = mapper.direction_visibility(&directions);
    let shaded = values.sky_diffuse_kwh_m2.as_ref().ok_or_else(|| Error::argument("epw", "the points' SAM file needs their sky"))?;
    let unshaded = mapper.unshaded_sky_diffuse(samples, site)?;
    let diffuse = pv::diffuse_sums(set.areas.iter().zip(shaded).zip(&unshaded).map(|((&a, &s), &u)| (a, s, u)));
    let inputs = SamInputs { year: pv::DEFAULT_YEAR, azal_fractions: &azal_fractions, diffuse };
    let sums = SamSums::of(&set, site.location, &inputs)?;
    Ok(TilePv { pvlib, sums })
}

/// Tile `k`'s pvlib CSV and SAM JSON.
pub fn tile_paths(dir: &Path, k: usize) -> (PathBuf, PathBuf) {
    let folder = dir.join(PV_DIR);
    (folder.join(format!("tile-{k}-pvlib.csv")), folder.join(format!("tile-{k}-sam.json")))
}

/// Writes tile `k`'s two files (each atomically).
pub fn write_tile_pv(dir: &Path, k: usize, pv: &TilePv) -> Result<()> {
    let (csv, sam) = tile_paths(dir, k);
    let folder = dir.join(PV_DIR);
    std::fs::create_dir_all(&folder).map_err(|source| Error::Io { path: folder, source })?;
    write_atomic(&csv, &pv.pvlib)?;
    write_atomic(&sam, &pv::sam_json_of(&pv.sums, pv::DEFAULT_YEAR)?)
}

/// The merged pvlib CSV and SAM JSON from the finished tiles' `(k, sums)`, their columns in the
/// order of the surfaces' `position` in the city (then J), as the points CSV has them.
pub fn merged(dir: &Path, tiles: &[(usize, SamSums)], position: &HashMap<&str, usize>) -> Result<Vec<(PathBuf, Vec<u8>)>> {
    let Some(((_, first), rest)) = tiles.split_first() else { return Ok(Vec::new()) };
    // Every column: (tile's place in `tiles`, column in its file, its name).
    let mut columns: Vec<(usize, usize, &str)> =
        tiles.iter().enumerate().flat_map(|(t, (_, sums))| sums.names.iter().enumerate().map(move |(c, n)| (t, c, n.as_str()))).collect();
    let key = |name: &str| {
        let j = name.rsplit_once("/p").and_then(|(_, j)| j.parse::<usize>().ok()).unwrap_or(usize::MAX);
        (position.get(surface_of(name)).copied().unwrap_or(usize::MAX), j)
    };
    columns.sort_by_key(|&(_, _, name)| key(name));
    let mut sums = first.clone();
    for (_, other) in rest {
        sums.add(other)?;
    }
    sums.names = columns.iter().map(|&(_, _, n)| n.to_string()).collect();
    let csv = merged_pvlib(dir, tiles, &columns)?;
    Ok(vec![(dir.join(POINTS_PVLIB), csv), (dir.join(POINTS_SAM), pv::sam_json_of(&sums, pv::DEFAULT_YEAR)?)])
}

/// The tiles' pvlib CSVs side by side, `columns` in order; every file must hold its tile's
/// columns and the same time index.
fn merged_pvlib(dir: &Path, tiles: &[(usize, SamSums)], columns: &[(usize, usize, &str)]) -> Result<Vec<u8>> {
    let texts = tiles
        .iter()
        .map(|(k, _)| {
            let path = tile_paths(dir, *k).0;
            std::fs::read_to_string(&path).map(|t| (path.clone(), t)).map_err(|source| Error::Io { path, source })
        })
        .collect::<Result<Vec<_>>>()?;
    let mut lines: Vec<std::str::Lines> = texts.iter().map(|(_, t)| t.lines()).collect();
    // The names come from the records; the files' own headers are skipped.
    lines.iter_mut().for_each(|l| {
        l.next();
    });
    let mut out = String::from("time");
    for &(_, _, name) in columns {
        out.push(',');
        out.push_str(&csv_field(name));
    }
    out.push('\n');
    let bad = |t: usize, why: String| Error::model(texts[t].0.display().to_string(), why);
    let rows = tiles[0].1.rows.len();
    let mut fields: Vec<Vec<&str>> = vec![Vec::new(); tiles.len()];
    for row in 0..rows {
        for (t, l) in lines.iter_mut().enumerate() {
            let line = l.next().ok_or_else(|| bad(t, format!("ends before row {} of {rows}", row + 1)))?;
            fields[t] = line.split(',').collect();
            if fields[t].len() != tiles[t].1.names.len() + 1 || fields[t][0] != fields[0][0] {
                return Err(bad(t, format!("row {} is not {} columns at {}", row + 1, tiles[t].1.names.len() + 1, fields[0][0])));
            }
        }
        out.push_str(fields[0][0]);
        for &(t, c, _) in columns {
            out.push(',');
            out.push_str(fields[t][c + 1]);
        }
        out.push('\n');
    }
    Ok(out.into_bytes())
}
