//! A map's points timestep by timestep, for what PV tools read ([`crate::export::pv`]: `sunlit map
//! --pvlib`, `--sam`): where a map sums a period, these keep each instant.
//!
//! Owns:
//! - [`Mapper::visibility_series`]: every point's sun visibility at every instant, as the sums
//!   see it ([`Mapper::accumulate`]'s sweep: 0 with the sun down or behind the point's receiver);
//! - [`Mapper::direction_visibility`]: every point's visibility of given sun directions (SAM's
//!   azimuth × altitude table), at full leaf as the receivers' table is counted;
//! - [`Mapper::unshaded_sky_diffuse`]: each point's Perez sky diffuse with nothing in the way,
//!   the denominator of SAM's diffuse loss (the numerator is the map's own `sky_diffuse_kwh_m2`).

use std::sync::atomic::{AtomicU32, Ordering};

use glam::DVec3;

use super::{Mapper, Sample, Site};
use crate::count::{MIN_COS_INCIDENCE, is_dark};
use crate::error::{Error, Result};
use crate::sky::perez::PerezSky;
use crate::year::samples::Timesteps;

/// Most values a series holds (4 bytes each, 1.6 GB): a year of 8760 hours for about 45,000
/// points, more than a PV layout's CSV wants.
pub const MAX_SERIES_VALUES: usize = 400_000_000;

impl Mapper {
    /// Each point's visibility of the sun at every instant of `samples`, row-major
    /// (`samples.len()` rows of every point): 1 lit, 0 shaded, dark or the sun down, or the
    /// see-through casters' transmittance. Instants are shared over every core. Refuses more than
    /// [`MAX_SERIES_VALUES`] values.
    pub fn visibility_series(&self, samples: &[Sample], site: Site<'_>, progress: &mut dyn FnMut(usize, usize)) -> Result<Vec<f32>> {
        let n = self.points;
        let values = samples.len().saturating_mul(n);
        if values > MAX_SERIES_VALUES {
            return Err(Error::argument(
                "points",
                format!(
                    "{n} points × {} instants is more than the {MAX_SERIES_VALUES} values a series holds: use fewer points",
                    samples.len()
                ),
            ));
        }
        // f32 bits: every thread writes its instants' own cells.
        let cells: Vec<AtomicU32> = (0..values).map(|_| AtomicU32::new(0)).collect();
        self.sweep(
            samples,
            site,
            false,
            progress,
            || (),
            |_, k, _, _, g, vis| {
                for (&i, &v) in g.members.iter().zip(vis) {
                    cells[k * n + i as usize].store(v.to_bits(), Ordering::Relaxed);
                }
            },
        );
        Ok(cells.into_iter().map(|c| f32::from_bits(c.into_inner())).collect())
    }

    /// `[d][i]`: point `i`'s visibility of a sun towards `directions[d]` (unit) at full leaf; 0
    /// for a direction below the horizon or behind the point's receiver.
    pub fn direction_visibility(&self, directions: &[DVec3]) -> Vec<Vec<f64>> {
        let mut scratch = self.engine.point_scratch();
        let mut vis = Vec::new();
        directions
            .iter()
            .map(|&sun| {
                let mut out = vec![0.0; self.points];
                for g in self.groups.iter().filter(|g| !is_dark(g.normal, sun)) {
                    vis.resize(g.members.len(), 0.0);
                    self.engine.visibility(&g.plane, sun, 1.0, &mut scratch, &mut vis);
                    for (&i, &v) in g.members.iter().zip(&vis) {
                        out[i as usize] = f64::from(v);
                    }
                }
                out
            })
            .collect()
    }

    /// Each point's sky diffuse over `samples` with nothing in the way (kWh/m²): the Perez sky of
    /// every sun-up instant on the point's plane with its unobstructed view factor, the horizon
    /// band whole and the circumsolar part whole when the sun is in front, as a receiver's
    /// unshaded sky ([`crate::export::irradiation`]). Needs `site`'s weather and sky views.
    pub fn unshaded_sky_diffuse(&self, samples: &[Sample], site: Site<'_>) -> Result<Vec<f64>> {
        let (Some(weather), Some(sky)) = (site.weather, site.sky) else {
            return Err(Error::argument("epw", "the unshaded sky needs weather and the points' sky views"));
        };
        if sky.receivers() != self.points {
            return Err(Error::argument("sky", format!("sky views of {} points for {}", sky.receivers(), self.points)));
        }
        let hourly = Timesteps::new(1)?;
        let mut out = vec![0.0; self.points];
        for s in samples {
            let sun = self.sun(site, s);
            if sun.z < MIN_COS_INCIDENCE {
                continue;
            }
            let hour = weather.at(hourly, s.epw_hour);
            let Some(perez) = PerezSky::new(hour.dni, hour.dhi, sun.z, site.location.elevation) else { continue };
            for (i, (normal, sum)) in self.normals.iter().zip(out.iter_mut()).enumerate() {
                let cos = normal.dot(sun).max(0.0);
                let lit = if cos > 0.0 { 1.0 } else { 0.0 };
                *sum += perez.diffuse(hour.dhi, cos, sky.unobstructed(i), lit, normal.truncate().length(), 1.0) * s.hours / 1000.0;
            }
        }
        Ok(out)
    }
}
