//! `sunlit district --year-table`: each receiver's whole-year table of sunlit fractions, the CSV
//! `sunlit annual CITY -o FILE.csv` writes (EnergyPlus's `eplusshading.csv` layout,
//! [`crate::export::Schedule::csv_bytes`]), for a district's receivers, when asked for: by default
//! a district keeps annual sums only ([`super::district_year`]).
//!
//! Owns:
//! - each tile's parts: a tile counts its year a batch of receivers at a time and writes each
//!   batch's table as it is counted, `year/tile-K-bJ.csv` (atomically, before the tile's record,
//!   which lists them as [`YearPart`]s), so a tile holds one batch's table, as without the option;
//! - the merge: `cadastre-year.csv`, every part's columns side by side in the city's surface order
//!   (a non-planar surface's parts `NAME#1`, `NAME#2`, … in turn), which is the order of a whole
//!   city's scene, so the file is `sunlit annual`'s for the same receivers. It is streamed a block
//!   of rows at a time, one part file open at a time ([`super::district_pv`]'s reader), so a merge
//!   holds a block of the city's rows, never the year.

use std::collections::HashMap;
use std::io::Write;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::district_pv::TileLines;
use crate::error::{Error, Result};
use crate::export::{Schedule, write_atomic, write_atomic_with};

/// The tiles' parts' folder in the output folder.
pub const YEAR_DIR: &str = "year";
/// The merged whole-year table of every receiver.
pub const CADASTRE_YEAR: &str = "cadastre-year.csv";

/// One batch's table written by a tile: its file in [`YEAR_DIR`], its columns, its rows.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct YearPart {
    /// The file's name in [`YEAR_DIR`].
    pub file: String,
    /// Its columns: the receivers' names.
    pub names: Vec<String>,
    /// Its rows (timesteps of the year).
    pub rows: usize,
}

/// Writes batch `b` of tile `k`'s table (atomically) into `dir`'s [`YEAR_DIR`].
pub fn write_part(dir: &Path, k: usize, b: usize, schedule: &Schedule) -> Result<YearPart> {
    let folder = dir.join(YEAR_DIR);
    std::fs::create_dir_all(&folder).map_err(|source| Error::Io { path: folder.clone(), source })?;
    let file = format!("tile-{k}-b{b}.csv");
    write_atomic(&folder.join(&file), &schedule.csv_bytes()?)?;
    Ok(YearPart { file, names: schedule.names.clone(), rows: schedule.timesteps.rows() })
}

/// A column's place in the city: its surface's `position`, then its planar part (`NAME#J`: J;
/// a whole surface: 0). Names the city does not hold go last, in the tiles' order.
fn column_key(name: &str, position: &HashMap<&str, usize>) -> (usize, usize) {
    if let Some(&p) = position.get(name) {
        return (p, 0);
    }
    name.rsplit_once('#').and_then(|(base, j)| Some((*position.get(base)?, j.parse::<usize>().ok()?))).unwrap_or((usize::MAX, usize::MAX))
}

/// Writes `cadastre-year.csv` from the tiles' `parts` (streamed, atomically), the columns in the
/// order of their surfaces' `position` in the city; `None` without parts. Every part must hold
/// its columns and the same rows, stamp for stamp.
pub fn write_merged(dir: &Path, parts: &[YearPart], position: &HashMap<&str, usize>) -> Result<Option<PathBuf>> {
    let Some(first) = parts.first() else { return Ok(None) };
    if let Some(p) = parts.iter().find(|p| p.rows != first.rows) {
        let why = format!("{} rows, where {} has {}", p.rows, first.file, first.rows);
        return Err(Error::model(dir.join(YEAR_DIR).join(&p.file).display().to_string(), why));
    }
    // Every column: (part, column in its file, name).
    let mut columns: Vec<(usize, usize, &str)> =
        parts.iter().enumerate().flat_map(|(t, p)| p.names.iter().enumerate().map(move |(c, n)| (t, c, n.as_str()))).collect();
    columns.sort_by_key(|&(_, _, name)| column_key(name, position));
    let path = dir.join(CADASTRE_YEAR);
    // About a row's bytes: its stamp, and a value and a comma a column.
    let row_bytes = 16 + 10 * columns.len();
    let block = (BLOCK_BYTES / row_bytes.max(1)).clamp(1, first.rows.max(1));
    write_atomic_with(&path, |out| merge_in_blocks(dir, parts, &columns, &path, out, block))?;
    Ok(Some(path))
}

/// Bytes of the parts' lines a merge holds at a time.
const BLOCK_BYTES: usize = 32 << 20;

/// The parts' tables side by side, `columns` in order, into `out` (the file at `path`), `block`
/// rows at a time.
fn merge_in_blocks(
    dir: &Path,
    parts: &[YearPart],
    columns: &[(usize, usize, &str)],
    path: &Path,
    out: &mut dyn Write,
    block: usize,
) -> Result<()> {
    let write_err = |source: std::io::Error| Error::Io { path: path.to_path_buf(), source };
    let mut header = String::from("Surface Name,");
    for &(_, _, name) in columns {
        header.push_str(name);
        header.push(',');
    }
    header.push('\n');
    out.write_all(header.as_bytes()).map_err(write_err)?;
    let mut files: Vec<TileLines> = parts.iter().map(|p| TileLines::new(dir.join(YEAR_DIR).join(&p.file))).collect();
    let rows = parts.first().map_or(0, |p| p.rows);
    let mut text = String::new();
    for start in (0..rows).step_by(block.max(1)) {
        let n = block.max(1).min(rows - start);
        for file in &mut files {
            file.read_block(start, n, rows)?;
        }
        for i in 0..n {
            // A line is `STAMP,V1,…,VN,`: the stamp, a field a column, an empty last one.
            let fields: Vec<Vec<&str>> = files.iter().map(|f| f.lines[i].split(',').collect()).collect();
            for (t, f) in fields.iter().enumerate() {
                if f.len() != parts[t].names.len() + 2 || f[0] != fields[0][0] {
                    let why = format!("row {} is not the stamp '{}' and {} values", start + i + 1, fields[0][0], parts[t].names.len());
                    return Err(Error::model(files[t].path.display().to_string(), why));
                }
            }
            text.clear();
            text.push_str(fields[0][0]);
            for &(t, c, _) in columns {
                text.push(',');
                text.push_str(fields[t][c + 1]);
            }
            text.push_str(",\n");
            out.write_all(text.as_bytes()).map_err(write_err)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    /// The merged table, byte for byte: parts' columns interleaved in the city's order (a
    /// surface's planar parts in turn), one stamp column, the parts' headers dropped, whatever the
    /// block of rows; a part a row short is refused naming its file, leaving no merged file.
    #[test]
    fn the_merged_table_interleaves_the_parts_columns_in_the_citys_order() {
        let dir = std::env::temp_dir().join(format!("sunlit-district-year-{}", std::process::id()));
        std::fs::create_dir_all(dir.join(YEAR_DIR)).unwrap();
        let rows = 50;
        let stamp = |r: usize| format!(" 01/{:02} {:02}:00", r / 24 + 1, r % 24 + 1);
        let value = |r: usize, c: usize| format!("{:.4}", ((r * 7 + c * 3) % 17) as f64 / 16.0);
        let table = |cols: &[usize]| {
            let mut t = String::from("Surface Name,x,\n");
            for r in 0..rows {
                t.push_str(&stamp(r));
                cols.iter().for_each(|&c| t.push_str(&format!(",{}", value(r, c))));
                t.push_str(",\n");
            }
            t
        };
        // Tile 0 holds b (a part of a non-planar surface, then c); tile 2 holds a and b#1.
        std::fs::write(dir.join(YEAR_DIR).join("tile-0-b0.csv"), table(&[3, 4])).unwrap();
        std::fs::write(dir.join(YEAR_DIR).join("tile-2-b0.csv"), table(&[1, 2])).unwrap();
        let part = |file: &str, names: &[&str]| YearPart { file: file.into(), names: names.iter().map(|n| n.to_string()).collect(), rows };
        let parts = [part("tile-0-b0.csv", &["b#2", "c"]), part("tile-2-b0.csv", &["a", "b#1"])];
        let position: HashMap<&str, usize> = [("a", 0), ("b", 1), ("c", 2)].into_iter().collect();
        let mut expected = String::from("Surface Name,a,b#1,b#2,c,\n");
        for r in 0..rows {
            expected.push_str(&format!("{},{},{},{},{},\n", stamp(r), value(r, 1), value(r, 2), value(r, 3), value(r, 4)));
        }
        assert_eq!(write_merged(&dir, &parts, &position).unwrap(), Some(dir.join(CADASTRE_YEAR)));
        assert!(std::fs::read_to_string(dir.join(CADASTRE_YEAR)).unwrap() == expected, "the merged table differs");
        let columns = [(1, 0, "a"), (1, 1, "b#1"), (0, 0, "b#2"), (0, 1, "c")];
        for block in [1, 7, rows] {
            let mut out = Vec::new();
            merge_in_blocks(&dir, &parts, &columns, &dir.join(CADASTRE_YEAR), &mut out, block).unwrap();
            assert!(out == expected.as_bytes(), "blocks of {block} rows differ");
        }
        let short = table(&[1, 2]);
        let cut = short.trim_end().rfind('\n').unwrap() + 1;
        std::fs::write(dir.join(YEAR_DIR).join("tile-2-b0.csv"), &short[..cut]).unwrap();
        let _ = std::fs::remove_file(dir.join(CADASTRE_YEAR));
        let err = write_merged(&dir, &parts, &position).unwrap_err().to_string();
        assert!(err.contains("tile-2-b0.csv") && err.contains(&format!("ends before row {rows}")), "{err}");
        assert!(!dir.join(CADASTRE_YEAR).exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
