//! What a point sees of the sky (its "sky mask"), for a stereographic sun-path diagram: the sky
//! split into cells of [`AZIMUTH_STEP`] × [`ALTITUDE_STEP`] degrees, each asked along its centre
//! by the exact shadow rays, and marked open, obstructed, or behind the point's own plane.

use glam::DVec3;

use super::{Ask, Windows, lit_bits};
use crate::error::Result;
use crate::map::Points;
use crate::scene::Scene;
use crate::sky::patches::direction;

/// Azimuth width of a cell, degrees.
pub const AZIMUTH_STEP: f64 = 2.0;
/// Altitude height of a cell, degrees.
pub const ALTITUDE_STEP: f64 = 2.0;

/// One cell's state.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Cell {
    /// The sky is seen.
    Open,
    /// Something is in the way.
    Obstructed,
    /// Behind the point's own plane (a wall's point never sees it).
    Behind,
}

/// A point's sky mask: rows of altitude from the horizon up, columns of azimuth clockwise from
/// north.
#[derive(Debug, Clone, PartialEq)]
pub struct SkyMask {
    /// Columns (azimuth).
    pub columns: usize,
    /// Rows (altitude).
    pub rows: usize,
    /// `rows × columns` cells, row by row.
    pub cells: Vec<Cell>,
}

impl SkyMask {
    /// The cell at `row`, `column`.
    pub fn cell(&self, row: usize, column: usize) -> Cell {
        self.cells[row * self.columns + column]
    }

    /// Share of the cells in front of the point that are obstructed (each weighed by its solid
    /// angle), a quick measure for the report.
    pub fn obstructed_share(&self) -> f64 {
        let (mut front, mut blocked) = (0.0, 0.0);
        for r in 0..self.rows {
            let weight = ((r as f64 + 0.5) * ALTITUDE_STEP).to_radians().cos();
            for c in 0..self.columns {
                match self.cell(r, c) {
                    Cell::Open => front += weight,
                    Cell::Obstructed => {
                        front += weight;
                        blocked += weight;
                    }
                    Cell::Behind => {}
                }
            }
        }
        if front > 0.0 { blocked / front } else { 0.0 }
    }
}

/// The cells' centre directions, row by row.
fn centres(rows: usize, columns: usize) -> Vec<DVec3> {
    (0..rows)
        .flat_map(|r| {
            (0..columns)
                .map(move |c| direction(((r as f64 + 0.5) * ALTITUDE_STEP).to_radians(), ((c as f64 + 0.5) * AZIMUTH_STEP).to_radians()))
        })
        .collect()
}

/// The sky masks of `points` (all of them; pass only those a picture is asked for) on `scene`,
/// trees bare.
pub fn sky_masks(scene: &Scene, points: &Points) -> Result<Vec<SkyMask>> {
    let windows = Windows::new(scene, points)?;
    let (rows, columns) = ((90.0 / ALTITUDE_STEP) as usize, (360.0 / AZIMUTH_STEP) as usize);
    let dirs = centres(rows, columns);
    let asks: Vec<Ask> = dirs.iter().map(|&d| Ask { direction: d, leaves: 0.0 }).collect();
    let lit = lit_bits(&windows, &asks, &mut |_, _| {});
    Ok((0..points.len())
        .map(|i| {
            let normal = points.normal(i);
            let cells = dirs
                .iter()
                .enumerate()
                .map(|(k, d)| {
                    if normal.dot(*d) <= crate::count::MIN_COS_INCIDENCE {
                        Cell::Behind
                    } else if lit.lit(i, k) {
                        Cell::Open
                    } else {
                        Cell::Obstructed
                    }
                })
                .collect();
            SkyMask { columns, rows, cells }
        })
        .collect())
}
