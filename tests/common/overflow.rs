//! EnergyPlus's figure overflow, told apart from disagreements with sunlit.
//!
//! EnergyPlus's polygon clipping keeps every shadow on a surface, and every overlap of shadows,
//! as one "figure" of a fixed array (`ShadowCalculation`'s `Maximum Figures in Shadow Overlap
//! Calculations`, 15,000 by default). With k casters whose shadows all overlap, a surface needs
//! about 2^k figures and a window on it as many again. Past the array's end SolarShading.cc's
//! `DeterminePolygonOverlap` sets `OverlapStatus = TooManyFigures` and gives up:
//! - its err file says so, once, without a surface or a time (`DeterminePolygonOverlap: Too many
//!   figures [>N] detected in an overlap calculation`; with `Output:Diagnostics,
//!   DisplayExtraWarnings;` a summary at the end, `Too many figures [>=N] in a shadow overlap`,
//!   with a count, naming casters but still no time);
//! - `SHDSBS`, seeing that status, sets each window of the surface to a sunlit area of 0 and does
//!   not take the window's lit area off its base surface (measured on EnergyPlus 25.2: the base
//!   surface then reports its own lit area plus the window's, to 1e-4; when the base surface's own
//!   clipping overflowed, `SHDGSS` stops part way and the base reports more still).
//!
//! So a step is EnergyPlus's figure overflow when the run's err file reports the overflow and the
//! step carries that accounting: EnergyPlus gives a window exactly 0 where sunlit sees it lit, and
//! its base surface kept the window's lit area: EnergyPlus's base fraction exceeds sunlit's by
//! nearer the window's lit area over the base's net area than nothing (at least half of it; sunlit's
//! own base fraction may be off by a few thousandths at a step, its spline's error). A shadow that
//! sunlit missed would darken the window without lighting its wall, so it is never named. The base surface's own dark/lit
//! disagreement at such a step (sunlit has its opaque part dark, EnergyPlus lit by the window's
//! area) is the same overflow.

use std::collections::{BTreeSet, HashMap};

use sunlit::model::idf::parse_idf;

/// A window or door and its base surface, with the areas EnergyPlus divides their sunlit areas by.
#[derive(Debug, Clone, PartialEq)]
pub struct Subsurface {
    /// Its name, upper-cased (as EnergyPlus's CSV names it).
    pub name: String,
    /// Its base surface's name, upper-cased.
    pub base: String,
    /// Its area (m²).
    pub area: f64,
    /// Its base surface's area less every subsurface's (m²).
    pub base_net_area: f64,
}

/// Whether an EnergyPlus err file reports that its shadow overlaps ran out of figures (either
/// form of the warning, see the module doc).
pub fn overflow_reported(err: &str) -> bool {
    err.contains("Too many figures")
}

/// The subsurfaces of an IDF model: each `FenestrationSurface:Detailed` on a
/// `BuildingSurface:Detailed`, both given by vertices. Others are left out (their steps are never
/// named an overflow).
pub fn subsurfaces(idf: &str) -> Vec<Subsurface> {
    #[allow(clippy::unwrap_used)] // A test helper: a model EnergyPlus ran reads.
    let objects = parse_idf("model.idf", idf).unwrap();
    // Vertices start after `Number of Vertices`: field 10 of a building surface (25.2, with
    // `Space Name`), field 8 of a fenestration surface.
    let polygon_area = |o: &sunlit::model::idf::IdfObject, first: usize| -> f64 {
        let xyz: Vec<f64> = o.fields.iter().skip(first + 1).filter_map(|f| f.trim().parse().ok()).collect();
        let points: Vec<[f64; 3]> = xyz.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        newell_area(&points)
    };
    let mut gross: HashMap<String, f64> = HashMap::new();
    for o in objects.iter().filter(|o| o.is("BuildingSurface:Detailed")) {
        gross.insert(o.field(0).trim().to_uppercase(), polygon_area(o, 10));
    }
    let mut subs: Vec<Subsurface> = objects
        .iter()
        .filter(|o| o.is("FenestrationSurface:Detailed"))
        .map(|o| Subsurface {
            name: o.field(0).trim().to_uppercase(),
            base: o.field(3).trim().to_uppercase(),
            area: polygon_area(o, 8),
            base_net_area: 0.0,
        })
        .filter(|s| gross.contains_key(&s.base))
        .collect();
    let mut taken: HashMap<String, f64> = HashMap::new();
    for s in &subs {
        *taken.entry(s.base.clone()).or_default() += s.area;
    }
    for s in &mut subs {
        s.base_net_area = gross[&s.base] - taken[&s.base];
    }
    subs
}

/// A planar polygon's area (Newell's method).
fn newell_area(points: &[[f64; 3]]) -> f64 {
    let mut n = [0.0; 3];
    for (i, p) in points.iter().enumerate() {
        let q = points[(i + 1) % points.len()];
        n[0] += (p[1] - q[1]) * (p[2] + q[2]);
        n[1] += (p[2] - q[2]) * (p[0] + q[0]);
        n[2] += (p[0] - q[0]) * (p[1] + q[1]);
    }
    0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt()
}

/// Whether step `i` of subsurface `sub` carries the overflow's accounting (see the module doc):
/// EnergyPlus's window exactly 0 where sunlit's is lit, and EnergyPlus's base surface above
/// sunlit's by at least half the window's lit area over the base's net area (the base at most 1).
/// `ours` and `theirs` give each surface's column by upper-case name.
pub fn overflow_step(sub: &Subsurface, ours: &Columns<'_>, theirs: &Columns<'_>, i: usize) -> bool {
    let (Some(window), Some(base)) = (ours.get(&sub.name), ours.get(&sub.base)) else { return false };
    let (Some(their_window), Some(their_base)) = (theirs.get(&sub.name), theirs.get(&sub.base)) else { return false };
    let at = |c: &[f64]| c.get(i).copied();
    let (Some(w), Some(b), Some(ew), Some(eb)) = (at(window), at(base), at(their_window), at(their_base)) else { return false };
    let halfway = (b + 0.5 * w * sub.area / sub.base_net_area).min(1.0);
    ew == 0.0 && w > 0.0 && eb >= halfway
}

/// Columns of one run's timesteps by upper-case surface name.
pub type Columns<'a> = HashMap<String, &'a [f64]>;

/// The steps of each surface (upper-case name) that are EnergyPlus's figure overflow: none unless
/// `err` (the run's err file) reports the overflow; else each subsurface's steps that carry its
/// accounting ([`overflow_step`]), and the same steps of its base surface.
pub fn figure_overflows(subs: &[Subsurface], ours: &Columns<'_>, theirs: &Columns<'_>, err: &str) -> HashMap<String, BTreeSet<usize>> {
    let mut out: HashMap<String, BTreeSet<usize>> = HashMap::new();
    if !overflow_reported(err) {
        return out;
    }
    for sub in subs {
        let steps = ours.get(&sub.name).map_or(0, |c| c.len());
        for i in (0..steps).filter(|&i| overflow_step(sub, ours, theirs, i)) {
            out.entry(sub.name.clone()).or_default().insert(i);
            out.entry(sub.base.clone()).or_default().insert(i);
        }
    }
    out
}
