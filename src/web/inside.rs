//! `engine.map` with `inside: true`: the sun inside an EnergyPlus model's zones at one instant,
//! as `sunlit map --inside --at` answers it ([`crate::map::inside`]): points on the zones' floors
//! (or given ones), each lit or not through the windows with the glass's weights, and every
//! inside face's sun patch. The scene is the model's inside ([`inside_scene`]: the glazing left
//! out), made per call; no inside logic lives here or in JS.

use super::ModelInner;
use super::map_options::{InsideAsk, MapRequest, Where, points_csv as given_points};
use crate::error::{Error, Result};
use crate::export::map_glb::map_glb;
use crate::export::map_table::{inside_instant_columns, points_csv};
use crate::map::inside::{self as rooms_map, InsideInstant, InsideMap, Patch};
use crate::map::{Mapper, Points};
use crate::model::inside::{inside_scene, rooms};
use crate::scene::Scene;
use crate::sun::position::sun_direction;
use crate::year::annual::shading_sun_day;

/// One instant inside: the inside scene the points lie on, their values and the sun patches.
pub(super) struct Inside {
    scene: Scene,
    pub(super) values: InsideInstant,
    patches: Vec<Patch>,
}

impl Inside {
    /// The points CSV as `sunlit map --inside --at -o POINTS.csv` writes it.
    pub(super) fn csv(&self, points: &Points) -> String {
        points_csv(&self.scene, points, &inside_instant_columns(&self.values))
    }

    /// The map glb as `--glb-out` writes it (coloured by `lit`).
    pub(super) fn glb(&self, points: &Points) -> Vec<u8> {
        map_glb(&self.scene, points, &self.values.lit, "lit", "")
    }

    /// The inside scene's receiver names (inside faces, work planes), which the points index.
    pub(super) fn receiver_names(&self) -> Vec<String> {
        self.scene.receivers.iter().map(|r| r.name.clone()).collect()
    }

    /// Each inside face's sun patch as JSON: `surface`, `zone`, `areaM2`, `fraction`.
    pub(super) fn patches_json(&self) -> String {
        let rows: Vec<serde_json::Value> = self
            .patches
            .iter()
            .map(|p| serde_json::json!({"surface": p.surface, "zone": p.zone, "areaM2": p.area_m2, "fraction": p.fraction}))
            .collect();
        serde_json::Value::Array(rows).to_string()
    }
}

/// The inside of `model`'s zones at `request`'s instant.
pub(super) fn inside_at(model: &ModelInner, request: &MapRequest, ask: &InsideAsk) -> Result<(Points, Inside)> {
    let Some(ep) = model.energyplus.as_ref() else {
        return Err(Error::argument("inside", "maps the zones of an EnergyPlus model (IDF or epJSON); this model has none"));
    };
    let (mut scene, rooms) = (inside_scene(ep)?, rooms(ep, ask.glass)?);
    let at = match &request.place {
        Where::Grid(spacing) => rooms_map::floor_grid(&mut scene, &rooms, *spacing, ask.work_plane)?,
        Where::Given(numbers) => rooms_map::room_points_csv(&mut scene, &rooms, "points", &given_points(numbers)?)?,
    };
    let mapper = Mapper::new(&scene, &at.points)?;
    let s = request.period.samples().first().copied().ok_or_else(|| Error::argument("at", "no instant"))?;
    let sun = sun_direction(&request.site.location, shading_sun_day(s.day), s.hour);
    let leaves = request.site.calendar.fraction(f64::from(s.day)) as f32;
    let map = InsideMap { mapper: &mapper, rooms: &rooms, at: &at };
    let (values, patches) = rooms_map::instant_with_patches(&scene, map, sun, leaves);
    Ok((at.points, Inside { scene, values, patches }))
}
