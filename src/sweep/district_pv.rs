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
//!   order (streamed: a block of rows of each tile's file at a time, one file open at a time, so a
//!   merge holds a block of the city's rows, not the year, and any number of tiles stays under the
//!   open-file limit), and `cadastre-points-sam.json` from the tiles' sums added, which is the SAM file of every
//!   point taken as one array (the sums of disjoint sets are the sums of their union).

use std::collections::HashMap;
use std::io::{BufRead, BufReader, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::export::cadastre::csv_field;
use crate::export::cadastre_points::PointRow;
use crate::export::pv::{self, PvSet, SamInputs, SamSums};
use crate::export::{write_atomic, write_atomic_with};
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

/// Writes the merged pvlib CSV (streamed: [`write_merged_pvlib`]) and SAM JSON from the finished
/// tiles' `(k, sums)`, their columns in the order of the surfaces' `position` in the city (then
/// J), as the points CSV has them; returns their paths (none without tiles). The CSV goes first:
/// it is what can fail on a bad tile file, before anything is written.
pub fn write_merged(dir: &Path, tiles: &[(usize, SamSums)], position: &HashMap<&str, usize>) -> Result<Vec<PathBuf>> {
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
    let sam = pv::sam_json_of(&sums, pv::DEFAULT_YEAR)?;
    let (csv_path, sam_path) = (dir.join(POINTS_PVLIB), dir.join(POINTS_SAM));
    write_atomic_with(&csv_path, |out| write_merged_pvlib(dir, tiles, &columns, &csv_path, out))?;
    write_atomic(&sam_path, &sam)?;
    Ok(vec![csv_path, sam_path])
}

/// Bytes of the tiles' lines a merge holds at a time: a block of rows of every tile.
const BLOCK_BYTES: usize = 32 << 20;

/// The tiles' pvlib CSVs side by side, `columns` in order, streamed into `out` (the file at
/// `path`) a block of rows at a time: a merge holds a block of rows of the city, not the year (the
/// whole CSV is about 9 bytes a point and hour: 0.8 GB for 10,000 points), and one tile file open
/// at a time, whatever the number of tiles (a file held open a tile would pass the process's
/// open-file limit, 1,024 by default, at a city of more tiles). Every file must hold its tile's
/// columns and the same time index.
fn write_merged_pvlib(
    dir: &Path,
    tiles: &[(usize, SamSums)],
    columns: &[(usize, usize, &str)],
    path: &Path,
    out: &mut dyn Write,
) -> Result<()> {
    let rows = tiles.first().map_or(0, |(_, s)| s.rows.len());
    // About a line's bytes: its time and six decimals and a comma a point.
    let row_bytes: usize = tiles.iter().map(|(_, s)| 32 + 9 * s.names.len()).sum();
    merge_in_blocks(dir, tiles, columns, path, out, (BLOCK_BYTES / row_bytes.max(1)).clamp(1, rows.max(1)))
}

/// [`write_merged_pvlib`] with `block` rows a block.
fn merge_in_blocks(
    dir: &Path,
    tiles: &[(usize, SamSums)],
    columns: &[(usize, usize, &str)],
    path: &Path,
    out: &mut dyn Write,
    block: usize,
) -> Result<()> {
    let mut files: Vec<TileLines> = tiles.iter().map(|(k, _)| TileLines::new(tile_paths(dir, *k).0)).collect();
    let mut header = String::from("time");
    for &(_, _, name) in columns {
        header.push(',');
        header.push_str(&csv_field(name));
    }
    header.push('\n');
    let write_err = |source: std::io::Error| Error::Io { path: path.to_path_buf(), source };
    out.write_all(header.as_bytes()).map_err(write_err)?;
    let rows = tiles.first().map_or(0, |(_, s)| s.rows.len());
    let mut row_text = String::new();
    for first in (0..rows).step_by(block.max(1)) {
        let n = block.max(1).min(rows - first);
        for file in &mut files {
            file.read_block(first, n, rows)?;
        }
        for i in 0..n {
            let fields: Vec<Vec<&str>> = files.iter().map(|f| f.lines[i].split(',').collect()).collect();
            for (t, f) in fields.iter().enumerate() {
                if f.len() != tiles[t].1.names.len() + 1 || f[0] != fields[0][0] {
                    let why = format!("row {} is not {} columns at {}", first + i + 1, tiles[t].1.names.len() + 1, fields[0][0]);
                    return Err(Error::model(files[t].path.display().to_string(), why));
                }
            }
            row_text.clear();
            row_text.push_str(fields[0][0]);
            for &(t, c, _) in columns {
                row_text.push(',');
                row_text.push_str(fields[t][c + 1]);
            }
            row_text.push('\n');
            out.write_all(row_text.as_bytes()).map_err(write_err)?;
        }
    }
    Ok(())
}

/// One tile's pvlib CSV (or a table of [`super::district_table`]) read a block of lines at a
/// time, opened for each block and closed after; its header line skipped.
pub(super) struct TileLines {
    pub(super) path: PathBuf,
    /// Where the next block starts; `None` before the header is skipped (the names come from the
    /// records).
    offset: Option<u64>,
    /// The block's lines, without their line ends.
    pub(super) lines: Vec<String>,
}

impl TileLines {
    pub(super) fn new(path: PathBuf) -> Self {
        Self { path, offset: None, lines: Vec::new() }
    }

    /// Reads rows `first..first + n` (of `rows`) into `lines`.
    pub(super) fn read_block(&mut self, first: usize, n: usize, rows: usize) -> Result<()> {
        let io = |source: std::io::Error| Error::Io { path: self.path.clone(), source };
        let mut file = std::fs::File::open(&self.path).map_err(io)?;
        file.seek(SeekFrom::Start(self.offset.unwrap_or(0))).map_err(io)?;
        let mut reader = BufReader::new(file);
        let mut offset = self.offset.unwrap_or(0);
        if self.offset.is_none() {
            let mut header = String::new();
            offset += reader.read_line(&mut header).map_err(io)? as u64;
        }
        self.lines.resize(n, String::new());
        for (i, line) in self.lines.iter_mut().enumerate() {
            line.clear();
            let read = reader.read_line(line).map_err(io)?;
            if read == 0 {
                return Err(Error::model(self.path.display().to_string(), format!("ends before row {} of {rows}", first + i + 1)));
            }
            offset += read as u64;
            let trimmed = line.trim_end_matches(['\n', '\r']).len();
            line.truncate(trimmed);
        }
        self.offset = Some(offset);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn sums(names: &[&str], rows: usize) -> SamSums {
        SamSums {
            kind: "points".into(),
            names: names.iter().map(|n| n.to_string()).collect(),
            area: names.len() as f64,
            per_hour: 1,
            leap: false,
            rows: vec![[1.0, 2.0]; rows],
            azal: vec![[0.5, 1.0]; 3],
            diffuse: [1.0, 2.0],
        }
    }

    /// The merged pvlib CSV, byte for byte: the tiles' columns interleaved in the city's surface
    /// order (then J), one time column, the tiles' own headers dropped. This test passed on the
    /// in-memory merge before the merge was streamed, so streaming changed no byte.
    #[test]
    fn the_merged_pvlib_csv_interleaves_the_tiles_columns_in_the_citys_order() {
        let dir = std::env::temp_dir().join(format!("sunlit-district-pv-{}", std::process::id()));
        std::fs::create_dir_all(dir.join(PV_DIR)).unwrap();
        let rows = 8760;
        let time = |r: usize| format!("2023-{:03}T{:02}:00:00-07:00", r / 24, r % 24);
        let value = |r: usize, c: usize| format!("{:.6}", ((r * 7 + c * 3) % 17) as f64 / 16.0);
        let mut tile0 = String::from("time,b/RoofSurface/1/p0,b/RoofSurface/1/p1\n");
        let mut tile3 = String::from("time,\"a,x/RoofSurface/0/p0\"\n");
        let mut expected = String::from("time,\"a,x/RoofSurface/0/p0\",b/RoofSurface/1/p0,b/RoofSurface/1/p1\n");
        for r in 0..rows {
            tile0.push_str(&format!("{},{},{}\n", time(r), value(r, 0), value(r, 1)));
            tile3.push_str(&format!("{},{}\n", time(r), value(r, 2)));
            expected.push_str(&format!("{},{},{},{}\n", time(r), value(r, 2), value(r, 0), value(r, 1)));
        }
        std::fs::write(tile_paths(&dir, 0).0, &tile0).unwrap();
        std::fs::write(tile_paths(&dir, 3).0, &tile3).unwrap();
        let tiles = [(0, sums(&["b/RoofSurface/1/p0", "b/RoofSurface/1/p1"], rows)), (3, sums(&["a,x/RoofSurface/0/p0"], rows))];
        // Surface a,x comes first in the city, then b.
        let position: HashMap<&str, usize> = [("a,x/RoofSurface/0", 0), ("b/RoofSurface/1", 1)].into_iter().collect();
        let files = write_merged(&dir, &tiles, &position).unwrap();
        assert_eq!(files, [dir.join(POINTS_PVLIB), dir.join(POINTS_SAM)]);
        let csv = std::fs::read_to_string(dir.join(POINTS_PVLIB)).unwrap();
        assert!(csv == expected, "the merged CSV differs from the tiles' columns in order");
        // Any block of rows gives the same bytes: a row a block, a block ending mid-file, one block.
        let columns = [(1, 0, "a,x/RoofSurface/0/p0"), (0, 0, "b/RoofSurface/1/p0"), (0, 1, "b/RoofSurface/1/p1")];
        for block in [1, 1000, rows] {
            let mut out = Vec::new();
            merge_in_blocks(&dir, &tiles, &columns, &dir.join(POINTS_PVLIB), &mut out, block).unwrap();
            assert!(out == expected.as_bytes(), "blocks of {block} rows differ");
        }
        // A tile file a row short is refused, naming it, and no merged file is left.
        let last = tile3.trim_end().rfind('\n').unwrap() + 1;
        std::fs::write(tile_paths(&dir, 3).0, &tile3[..last]).unwrap();
        let _ = std::fs::remove_file(dir.join(POINTS_PVLIB));
        let err = write_merged(&dir, &tiles, &position).unwrap_err().to_string();
        assert!(err.contains("tile-3-pvlib.csv") && err.contains("ends before row 8760"), "{err}");
        assert!(!dir.join(POINTS_PVLIB).exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
