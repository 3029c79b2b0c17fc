//! A district tile's year, counted a batch of receivers at a time, and where its time went.
//!
//! Owns the batching: a tile's cadastre needs each receiver's annual sums only, never its
//! hourly rows, so the year is counted for [`RECEIVER_BATCH`] receivers at once
//! ([`annual_receivers_with`]), summed ([`summarize_from`], [`cadastre::sun_hours`]) and its
//! whole-year table dropped before the next batch. The peak then follows the batch, not the
//! city: a one-process run of 22,424 receivers would otherwise hold 786 MB of fractions and the
//! refined steps of every receiver at once (docs/district.md). Every answer is the whole year's
//! bit for bit: each view is the same receiver at the same sun on the same engine, and each
//! receiver's sums run over the rows in the same order. One exception, stated there: under
//! `auto` with a GPU in play, the engine weighs a GPU's start-up against the views of one call,
//! which batching makes fewer, so a view may go to the other engine.
//!
//! Owns too the tile's stages ([`TileStages`]), which its record and log give.

use std::ops::Range;

use serde::{Deserialize, Serialize};

use crate::count::hybrid::HybridEngine;
use crate::error::Result;
use crate::export::cadastre;
use crate::export::irradiation::{SurfaceSummary, summarize_from};
use crate::platform::{cpu_seconds, seconds as now};
use crate::scene::Scene;
use crate::sky::views::sky_views;
use crate::sweep::district::TileSettings;
use crate::sweep::district_table::{self, YearPart};
use crate::year::annual::{Progress, YearStages, annual_receivers_with};

/// Receivers whose year is counted at once. A receiver's year holds at most about 180 kB at
/// its peak (its share of the whole-year table, refined steps, fits and samples; measured on
/// the 120-building district, docs/district.md), so a batch of 128 about 23 MB. 128 rather
/// than 1,024 so that a tile's peak is a small share of a whole city's (a 330 m tile holds about
/// 1,000 receivers); on the 2,000-building district the smaller batch cost 1.4 % more CPU and
/// no wall time (paired, docs/district.md).
pub const RECEIVER_BATCH: usize = 128;

/// Where a tile's time went, in seconds of wall time (the views are counted on every core), with
/// the views each stage counted and the view stages' CPU seconds (every thread of the process:
/// CPU / wall is the cores its threads kept busy; 0 in records written before they were kept).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct TileStages {
    /// Building the tile's scene from its part of the city, and the exact engine's index.
    pub scene: f64,
    /// Counting the year's sample views.
    pub sample_views: f64,
    /// Their CPU seconds.
    #[serde(default)]
    pub sample_views_cpu: f64,
    /// How many.
    pub sample_view_count: usize,
    /// Fitting the splines and evaluating them at every timestep.
    pub fitting: f64,
    /// Settling refined steps by certificate.
    pub certificates: f64,
    /// Counting the refined steps left.
    pub refinement: f64,
    /// Its CPU seconds.
    #[serde(default)]
    pub refinement_cpu: f64,
    /// How many refined steps were counted.
    pub refined_view_count: usize,
    /// The sky pass: every receiver's view of each sky patch.
    pub sky: f64,
    /// Its CPU seconds.
    #[serde(default)]
    pub sky_cpu: f64,
    /// Summing each receiver's year into its irradiation and sun hours.
    pub sums: f64,
    /// With a grid: the roofs' points, their year and sky.
    pub points: f64,
    /// Batches of receivers the year was counted in.
    pub batches: usize,
}

impl TileStages {
    fn add_year(&mut self, year: &YearStages) {
        self.sample_views += year.sampling;
        self.sample_views_cpu += year.sampling_cpu;
        self.sample_view_count += year.sample_views;
        self.fitting += year.fitting;
        self.certificates += year.certifying;
        self.refinement += year.refining;
        self.refinement_cpu += year.refining_cpu;
        self.refined_view_count += year.refined_views;
        self.batches += 1;
    }

    /// One line for a log: each stage's seconds (and views; the view stages' CPU seconds).
    pub fn line(&self) -> String {
        format!(
            "scene {:.1} s, sample views {:.1} s ({:.1} s cpu, {} views), fit and evaluation {:.1} s, certificates {:.1} s, \
             refinement {:.1} s ({:.1} s cpu, {} views), sky pass {:.1} s ({:.1} s cpu), sums {:.1} s, roof points {:.1} s; \
             {} batch(es) of receivers",
            self.scene,
            self.sample_views,
            self.sample_views_cpu,
            self.sample_view_count,
            self.fitting,
            self.certificates,
            self.refinement,
            self.refinement_cpu,
            self.refined_view_count,
            self.sky,
            self.sky_cpu,
            self.sums,
            self.points,
            self.batches
        )
    }
}

/// A tile's receivers' summaries and sun hours, in the scene's receiver order.
pub struct TileYear {
    /// One a receiver.
    pub summaries: Vec<SurfaceSummary>,
    /// Sun hours, one a receiver.
    pub hours: Vec<f64>,
    /// With [`TileSettings::year_table`]: each batch's whole-year table, as written.
    pub parts: Vec<YearPart>,
}

/// The ranges of `receivers` receivers, `batch` at a time (at least one each).
pub fn batches(receivers: usize, batch: usize) -> impl Iterator<Item = Range<usize>> {
    let batch = batch.max(1);
    (0..receivers.div_ceil(batch)).map(move |k| k * batch..((k + 1) * batch).min(receivers))
}

/// The sky pass, then the year of `scene`'s receivers `batch` at a time, each batch summed (and
/// with [`TileSettings::year_table`], its table written as part of tile `k`'s) and dropped; the
/// time of each stage added to `stages`.
pub fn tile_year(
    engine: &HybridEngine,
    scene: &Scene,
    s: &TileSettings,
    k: usize,
    batch: usize,
    stages: &mut TileStages,
    progress: &mut dyn FnMut(Progress) -> Result<()>,
) -> Result<TileYear> {
    let options = s.settings.options(None)?;
    let (location, calendar) = (&s.settings.location, &s.settings.calendar);
    // The sky first: each batch's sums read every receiver's sky views.
    let (start, cpu) = (now(), cpu_seconds());
    let views = pollster::block_on(sky_views(engine, scene, s.patches, progress))?;
    stages.sky += now() - start;
    stages.sky_cpu += cpu_seconds() - cpu;
    let n = scene.receivers.len();
    let mut out = TileYear { summaries: Vec::with_capacity(n), hours: Vec::with_capacity(n), parts: Vec::new() };
    for (b, receivers) in batches(n, batch).enumerate() {
        let first = receivers.start;
        let (schedule, year) = pollster::block_on(annual_receivers_with(engine, scene, receivers, location, &options, calendar, progress))?;
        stages.add_year(&year);
        let start = now();
        out.summaries.extend(summarize_from(scene, first, &schedule, location, Some((&views, calendar)), Some(s.weather), &[])?);
        out.hours.extend(cadastre::sun_hours(&schedule, location));
        if let Some(dir) = &s.year_table {
            out.parts.push(district_table::write_part(dir, k, b, &schedule)?);
        }
        stages.sums += now() - start;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::count::gpu::CounterOptions;
    use crate::count::hybrid::EngineKind;
    use crate::model::LoadOptions;
    use crate::sky::patches::SkyPatches;
    use crate::sun::weather::{Hour, Weather};
    use crate::sweep::district::{count_tile_in_batches, tiles};
    use crate::year::settings::AnnualSettings;

    /// A tile counted a few receivers at a time has the rows of the tile counted in one batch,
    /// bit for bit (every value of every row: irradiation, sky diffuse, sun hours, mean
    /// fraction): a generated district with stair housings and chimneys as one tile, exact
    /// engine, Golden's sun with a constant weather.
    #[test]
    fn a_tile_counted_by_batches_of_receivers_has_the_rows_of_one_batch() {
        let text = crate::model::city_write::district_cityjson_with(2, 1, 3, true);
        let city = crate::model::cityjson::read_city("district.city.json", text.as_bytes(), None).unwrap();
        let tiling = tiles(&city, 100_000.0, 100_000.0, 0.0).unwrap();
        let settings = AnnualSettings {
            latitude: Some(39.74),
            longitude: Some(-105.18),
            time_zone: Some(-7.0),
            days_per_year: Some(13),
            samples_per_day: Some(9),
            ..Default::default()
        }
        .resolve()
        .unwrap();
        let weather = Weather::constant(settings.location.clone(), Hour { dni: 700.0, dhi: 120.0, ghi: 500.0, albedo: 0.2 });
        let patches = SkyPatches::parse("tregenza").unwrap();
        let s = TileSettings {
            load: LoadOptions::default(),
            settings: &settings,
            weather: &weather,
            patches: &patches,
            engine: EngineKind::Exact,
            counter: CounterOptions::default(),
            lanes: None,
            grid: None,
            pv: false,
            batch: RECEIVER_BATCH,
            year_table: None,
        };
        let count = |batch: usize| count_tile_in_batches(&city, &tiling, 0, &s, batch, &mut |_| Ok(())).unwrap();
        let whole = count(usize::MAX);
        assert_eq!(whole.stages.batches, 1);
        // The view stages' CPU is kept beside their wall time.
        let st = &whole.stages;
        assert!(st.sample_views_cpu > 0.0 && st.refinement_cpu > 0.0 && st.sky_cpu > 0.0, "{st:?}");
        assert!(whole.rows.len() > 10, "{} rows", whole.rows.len());
        let batched = count(5);
        assert!(batched.stages.batches > 2 && batched.stages.refined_view_count > 0, "{:?}", batched.stages);
        assert_eq!(batched.stages.sample_view_count, whole.stages.sample_view_count);
        assert_eq!(batched.rows.len(), whole.rows.len());
        for (a, b) in batched.rows.iter().zip(&whole.rows) {
            // Debug prints every f64 to the last bit (shortest round trip).
            assert_eq!(format!("{a:?}"), format!("{b:?}"));
        }
    }

    /// The batches cover every receiver once, in order, none empty and none past `batch`.
    #[test]
    fn batches_cover_the_receivers_in_order() {
        for (n, batch) in [(0, 4), (1, 4), (4, 4), (5, 4), (22_424, 1024), (7, 1), (3, 0)] {
            let all: Vec<Range<usize>> = batches(n, batch).collect();
            assert_eq!(all.iter().flat_map(Clone::clone).collect::<Vec<_>>(), (0..n).collect::<Vec<_>>(), "{n} by {batch}");
            assert!(all.iter().all(|r| !r.is_empty() && r.len() <= batch.max(1)), "{n} by {batch}: {all:?}");
        }
    }
}
