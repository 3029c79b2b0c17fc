//! EnergyPlus's own known glitches, named for the model sunlit hooks instead of copied into it.
//!
//! Owns the list of what EnergyPlus 25.2 itself gets wrong in the shading hand-off (each measured
//! on committed runs, docs/energyplus-fidelity.md), the test of whether each applies to a given
//! model, and what sunlit did about it. `sunlit annual --idf-out` prints the ones that apply and
//! writes them as comments at the head of the hooked IDF. A glitch is listed when the model has
//! what it needs to happen (the condition is read from the model, not guessed from a sun angle):
//! where it falls step by step only EnergyPlus's own clipping says, so no steps are listed.

use std::fmt::Write as _;

use glam::DVec3;

use super::hook::Hook;
use crate::geometry::{Plane, is_convex};
use crate::model::EnergyPlusInput;
use crate::model::building::EpSurface;

/// One of EnergyPlus's known glitches that applies to a model.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct KnownGlitch {
    /// A short stable name (`lone-full-sun`, …).
    pub name: &'static str,
    /// What EnergyPlus does wrong, and where it was seen.
    pub what: &'static str,
    /// Why it applies to this model (the objects or surfaces concerned).
    pub applies: String,
    /// What sunlit did about it.
    pub sunlit: String,
}

impl KnownGlitch {
    /// One line: `NAME: WHAT; here: APPLIES; sunlit: SUNLIT`.
    pub fn line(&self) -> String {
        format!("{}: {}; here: {}; sunlit: {}", self.name, self.what, self.applies, self.sunlit)
    }
}

/// A shading vertex this far (m) in front of a surface's plane puts the shade in front of it.
const IN_FRONT: f64 = 1e-3;
/// Surfaces named in a line before "and N more".
const NAMED: usize = 3;

/// EnergyPlus's known glitches that apply to `ep` hooked with `hook` for the surfaces `columns`
/// (the CSV's), in a fixed order.
pub fn known_glitches(ep: &EnergyPlusInput, columns: &[String], hook: Hook) -> Vec<KnownGlitch> {
    [
        lone_full_sun(ep, columns),
        figure_overflow(ep, columns),
        non_convex_casters(ep),
        transmittance_ignored(ep),
        shading_export_a_day_late(ep),
        imported_ignored(ep, hook),
    ]
    .into_iter()
    .flatten()
    .collect()
}

/// The lone 1.0: EnergyPlus's clipping reports full sun for one timestep on a window whose wall
/// the sun is just crossing, with a shade in front of it whose shadow, kilometres long on the
/// wall's plane at that sun, covers the window as on the steps before and after. It needs a
/// hooked window or glass door with a shading surface in front of its plane.
fn lone_full_sun(ep: &EnergyPlusInput, columns: &[String]) -> Option<KnownGlitch> {
    let shades: Vec<&EpSurface> = ep.building.surfaces.iter().filter(|s| s.kind == "Shading").collect();
    let under: Vec<&str> = columns
        .iter()
        .filter_map(|c| ep.building.surface(c))
        .filter(|w| w.is_glazing() && shades.iter().any(|s| in_front(&s.vertices, &w.vertices)))
        .map(|w| w.name.as_str())
        .collect();
    (!under.is_empty()).then(|| KnownGlitch {
        name: "lone-full-sun",
        what: "EnergyPlus's clipping can report a window fully lit (1.0) for one timestep between dark steps as the sun \
               crosses its wall's plane with a shade in front (seen on windows under overhangs: 03/28 17:45 and 06/28 16:00 \
               on 4ZoneWithShading_Simple_1's window set back 0.152 m, 06/06 and 09/07 11:50 on a west window at Timestep 6)",
        applies: format!("{} with a shading surface in front of their plane", surfaces(&under, "window")),
        sunlit: "counted those steps itself (dark where the shadow covers the window); the hooked model takes sunlit's \
                 fractions, so EnergyPlus's heat balance never sees the lone 1.0"
            .into(),
    })
}

/// Whether any of `caster`'s vertices lies in front of the plane of `receiver`.
fn in_front(caster: &[DVec3], receiver: &[DVec3]) -> bool {
    let plane = Plane::of_polygon(receiver);
    caster.iter().any(|p| plane.height(*p) > IN_FRONT)
}

/// EnergyPlus's default `Maximum Figures in Shadow Overlap Calculations`.
const MAX_FIGURES: u64 = 15_000;

/// The figure overflow: EnergyPlus's clipping keeps every shadow on a surface, and every overlap
/// of shadows, as one figure of an array of `Maximum Figures in Shadow Overlap Calculations`; past
/// its end SolarShading.cc gives up (`Too many figures` in the err file) and reports the surface's
/// windows 0. k casters whose shadows all overlap make 2^k figures on a surface and up to as many
/// again on a window of it, so a hooked surface with k shading surfaces in front of its plane can
/// overflow when 2^(k+1) passes the maximum (measured on 25.2: seven slats overflow 200 figures,
/// six do not; the 100-zone test file's west windows, under 200 overhangs, overflow 15,000).
fn figure_overflow(ep: &EnergyPlusInput, columns: &[String]) -> Option<KnownGlitch> {
    let limit = shadow_calculation_field(ep, 3).parse::<f64>().ok().filter(|v| *v >= 1.0).map_or(MAX_FIGURES, |v| v as u64);
    let shades: Vec<&EpSurface> = ep.building.surfaces.iter().filter(|s| s.kind == "Shading").collect();
    let crowded: Vec<&str> = columns
        .iter()
        .filter_map(|c| ep.building.surface(c))
        .filter(|r| {
            let casters = shades.iter().filter(|s| in_front(&s.vertices, &r.vertices)).count() as u32;
            1u64.checked_shl(casters + 1).is_none_or(|figures| figures > limit)
        })
        .map(|r| r.name.as_str())
        .collect();
    (!crowded.is_empty()).then(|| KnownGlitch {
        name: "figure-overflow",
        what: "EnergyPlus's clipping can run out of figures for overlapping shadows (`Too many figures` in its err file, \
               no surface or time given) and then reports the surface's windows 0, leaving their lit area on the wall \
               (seen on the 100-zone test file's west and east windows at the noon crossing, May to July)",
        applies: format!("{} with enough shading surfaces in front of their plane to pass {limit} figures", surfaces(&crowded, "surface")),
        sunlit: "counted those steps itself (the geometry's fraction); the hooked model takes sunlit's fractions, so \
                 EnergyPlus's heat balance never sees the overflow's 0 (its sky-diffuse pass still clips, and may still \
                 warn)"
            .into(),
    })
}

/// Non-convex casters: EnergyPlus's polygon clipping takes convex casters only and calls another
/// a severe error, and its sky-diffuse pass clips every caster even under the Scheduled method.
fn non_convex_casters(ep: &EnergyPlusInput) -> Option<KnownGlitch> {
    let bent: Vec<&str> = ep
        .building
        .surfaces
        .iter()
        .filter(|s| s.kind == "Shading" && s.vertices.len() > 3 && !is_convex(&s.vertices))
        .map(|s| s.name.as_str())
        .collect();
    (!bent.is_empty()).then(|| KnownGlitch {
        name: "non-convex-caster",
        what: "EnergyPlus's polygon clipping handles convex casters only and stops on another with a severe error; its \
               sky-diffuse pass clips every caster even when the beam's fractions are given",
        applies: surfaces(&bent, "shading surface"),
        sunlit: if ep.epjson {
            "counted them as they are; an epJSON model is written back as it was, so split them into convex pieces \
             before EnergyPlus runs it"
                .into()
        } else {
            "counted them as they are and wrote each into the hooked model as convex triangles (NAME_1, NAME_2, …)".into()
        },
    })
}

/// PixelCounting ignores a shade's transmittance schedule (NREL/EnergyPlus #9059).
fn transmittance_ignored(ep: &EnergyPlusInput) -> Option<KnownGlitch> {
    let method = shadow_calculation_field(ep, 0);
    if !method.eq_ignore_ascii_case("PixelCounting") || ep.shades.is_empty() {
        return None;
    }
    let names: Vec<&str> = ep.shades.iter().flat_map(|g| g.shades.iter().map(String::as_str)).collect();
    Some(KnownGlitch {
        name: "pixel-counting-opaque-shades",
        what: "EnergyPlus's PixelCounting counts every shade opaque, whatever its Transmittance Schedule Name \
               (NREL/EnergyPlus #9059)",
        applies: format!("the model asks for PixelCounting and {} a transmittance schedule", surfaces(&names, "shade")),
        sunlit: "counted each shade's shadow as (1 − τ) of it, as EnergyPlus's polygon clipping does; the hooked model \
                 takes those fractions and keeps the shades and their schedules for its sky-diffuse pass"
            .into(),
    })
}

/// The `eplusshading.csv` export under Timestep updates holds on day D what EnergyPlus used on
/// day D − 1 (its first two days are the same).
fn shading_export_a_day_late(ep: &EnergyPlusInput) -> Option<KnownGlitch> {
    let asked = if ep.epjson {
        // The epJSON reader keeps only the fields sunlit counts with; this one is read by name.
        serde_json::from_str::<serde_json::Value>(&ep.text).ok().is_some_and(|root| {
            root["ShadowCalculation"].as_object().is_some_and(|m| {
                m.values().any(|o| o["output_external_shading_calculation_results"].as_str().is_some_and(|v| v.eq_ignore_ascii_case("Yes")))
            })
        })
    } else {
        shadow_calculation_field(ep, 7).eq_ignore_ascii_case("Yes")
    };
    asked.then(|| KnownGlitch {
        name: "shading-export-a-day-late",
        what: "with Timestep updates EnergyPlus's eplusshading.csv holds on each day the fractions it used the day \
               before (its first two days are the same)",
        applies: "the model's ShadowCalculation asks for Output External Shading Calculation Results".into(),
        sunlit: "the hooked model turns that export off (its fractions are sunlit's CSV); to check what EnergyPlus used, \
                 read its Surface Outside Face Sunlit Fraction output"
            .into(),
    })
}

/// EnergyPlus 25.2 ignores `Schedule:File:Shading` (every surface "not found … set to 1.0").
fn imported_ignored(ep: &EnergyPlusInput, hook: Hook) -> Option<KnownGlitch> {
    let has_import =
        shadow_calculation_field(ep, 0).eq_ignore_ascii_case("Imported") || ep.objects.iter().any(|o| o.is("Schedule:File:Shading"));
    if !has_import && hook != Hook::Imported {
        return None;
    }
    let (applies, sunlit) = match hook {
        Hook::Imported => (
            "the Imported hook was asked for".to_string(),
            "wrote the Imported form as asked: EnergyPlus 25.2 will run as if every surface were unshaded; use the \
             default Scheduled form"
                .to_string(),
        ),
        Hook::Scheduled => (
            "the model imports its fractions (ShadowCalculation Imported or Schedule:File:Shading)".to_string(),
            "replaced the import with per-surface Schedule:File and SurfaceProperty:LocalEnvironment objects (the \
             Scheduled form), which 25.2 reads"
                .to_string(),
        ),
    };
    Some(KnownGlitch {
        name: "imported-shading-ignored",
        what: "EnergyPlus 25.2 looks Schedule:File:Shading's columns up under names it never finds and sets every surface's \
               fraction to 1.0 (fixed upstream later)",
        applies,
        sunlit,
    })
}

/// A field of the model's `ShadowCalculation` (IDD order, 9.3 and later), trimmed; empty when
/// it has none.
fn shadow_calculation_field(ep: &EnergyPlusInput, i: usize) -> &str {
    ep.objects.iter().find(|o| o.is("ShadowCalculation")).map_or("", |o| o.field(i).trim())
}

/// `N KIND(s) (A, B, C and M more)`.
fn surfaces(names: &[&str], kind: &str) -> String {
    let shown = names.iter().take(NAMED).copied().collect::<Vec<_>>().join(", ");
    let more = if names.len() > NAMED { format!(" and {} more", names.len() - NAMED) } else { String::new() };
    let plural = if names.len() == 1 { "" } else { "s" };
    format!("{} {kind}{plural} ({shown}{more})", names.len())
}

/// The hooked IDF's text with the glitches that apply named in comments at its head (an epJSON
/// model, which has no comments, is returned as it is: the command's log names them).
pub fn with_comments(ep: &EnergyPlusInput, text: String, glitches: &[KnownGlitch]) -> String {
    if ep.epjson || glitches.is_empty() {
        return text;
    }
    let mut out = String::from("! sunlit: EnergyPlus's own known glitches that apply to this model, and what sunlit did about each:\n");
    for g in glitches {
        let _ = writeln!(out, "! - {}", g.line());
    }
    out + &text
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{LoadOptions, load_bytes_all};

    /// A west wall with a window, at `extra`'s ShadowCalculation and shades.
    fn model(extra: &str) -> EnergyPlusInput {
        let text = format!(
            "Version, 25.2;\nZone, Z;\nBuildingSurface:Detailed, WALL_W, Wall, C, Z, , Outdoors, , SunExposed, WindExposed, , 4,\n\
             0,8,3, 0,8,0, 0,0,0, 0,0,3;\nFenestrationSurface:Detailed, WIN_W, Window, G, WALL_W, , , , 1, 4,\n\
             0,6,2.5, 0,6,1, 0,2,1, 0,2,2.5;\n{extra}"
        );
        let files = [("m.idf".to_string(), text.into_bytes())];
        load_bytes_all(&files, &LoadOptions::default()).unwrap().energyplus.unwrap()
    }

    fn names(ep: &EnergyPlusInput, hook: Hook) -> Vec<&'static str> {
        known_glitches(ep, &["WALL_W".into(), "WIN_W".into()], hook).iter().map(|g| g.name).collect()
    }

    const OVERHANG: &str = "Shading:Site:Detailed, OVERHANG, , 4, 0,9,2.8, -1,9,2.8, -1,1,2.8, 0,1,2.8;\n";

    /// A window with a shade in front of its wall can get EnergyPlus's lone 1.0; without one,
    /// or with the shade behind the wall, it cannot, and nothing is named.
    #[test]
    fn the_lone_full_sun_needs_a_shade_in_front_of_a_window() {
        let ep = model(OVERHANG);
        let found = known_glitches(&ep, &["WALL_W".into(), "WIN_W".into()], Hook::Scheduled);
        assert_eq!(found.len(), 1, "{found:?}");
        assert!(found[0].line().starts_with("lone-full-sun: ") && found[0].applies.contains("1 window (WIN_W)"), "{}", found[0].line());
        assert!(names(&model(""), Hook::Scheduled).is_empty());
        let behind = "Shading:Site:Detailed, BEHIND, , 4, 1,9,2.8, 2,9,2.8, 2,1,2.8, 1,1,2.8;\n";
        assert!(names(&model(behind), Hook::Scheduled).is_empty());
        assert!(known_glitches(&ep, &["WALL_W".into()], Hook::Scheduled).is_empty(), "the window is not hooked");
    }

    /// The figure overflow is named for a hooked surface with enough shades in front of its plane
    /// to pass the model's maximum figures (2^(k+1) > maximum), and not below it.
    #[test]
    fn the_figure_overflow_needs_more_shades_in_front_than_the_figures_allow() {
        let slats = |k: usize| -> String {
            (0..k)
                .map(|i| {
                    format!("Shading:Site:Detailed, SLAT_{i}, , 4, 0,6,{z}, -0.5,6,{z}, -0.5,2,{z}, 0,2,{z};\n", z = 2.6 + 0.1 * i as f64)
                })
                .collect()
        };
        let at = |figures: u32| format!("ShadowCalculation, PolygonClipping, Timestep, 1, {figures};\n");
        let named = |extra: String| names(&model(&extra), Hook::Scheduled).contains(&"figure-overflow");
        assert!(named(format!("{}{}", at(200), slats(7))), "7 slats, 2^8 = 256 > 200 figures");
        assert!(!named(format!("{}{}", at(200), slats(6))), "6 slats, 2^7 = 128 ≤ 200 figures");
        assert!(!named(slats(7)), "the default 15,000 figures");
        assert!(named(slats(13)), "13 slats, 2^14 > 15,000 figures");
        let found = known_glitches(&model(&format!("{}{}", at(200), slats(7))), &["WALL_W".into(), "WIN_W".into()], Hook::Scheduled);
        let line = found.iter().find(|g| g.name == "figure-overflow").unwrap().line();
        assert!(line.contains("2 surfaces (WALL_W, WIN_W)") && line.contains("pass 200 figures"), "{line}");
    }

    /// Each of the others is named exactly when the model has what it needs.
    #[test]
    fn each_glitch_is_named_when_the_model_has_its_cause() {
        let l_shape = "Shading:Site:Detailed, L, , 6, 5,0,3, 7,0,3, 7,2,3, 6,2,3, 6,1,3, 5,1,3;\n";
        assert_eq!(names(&model(l_shape), Hook::Scheduled), ["non-convex-caster"]);
        let tree = "ScheduleTypeLimits, F, 0, 1, Continuous;\nSchedule:Constant, TAU, F, 0.2;\n\
                    Shading:Site:Detailed, TREE, TAU, 4, 9,-3,6, 9,-3,0, 9,3,0, 9,3,6;\n";
        assert!(names(&model(tree), Hook::Scheduled).is_empty(), "polygon clipping honours τ");
        let pixels = format!("{tree}ShadowCalculation, PixelCounting, Timestep, 1;\n");
        assert_eq!(names(&model(&pixels), Hook::Scheduled), ["pixel-counting-opaque-shades"]);
        let export = "ShadowCalculation, PolygonClipping, Timestep, 1, 15000, SutherlandHodgman, 512, SimpleSkyDiffuseModeling, Yes;\n";
        assert_eq!(names(&model(export), Hook::Scheduled), ["shading-export-a-day-late"]);
        assert!(names(&model(&export.replace("Yes;", "No;")), Hook::Scheduled).is_empty());
        let imported = "ShadowCalculation, Imported;\nSchedule:File:Shading, shading.csv;\n";
        assert_eq!(names(&model(imported), Hook::Scheduled), ["imported-shading-ignored"]);
        assert_eq!(names(&model(""), Hook::Imported), ["imported-shading-ignored"]);
    }

    /// The hooked IDF names them in comments at its head; without any it is left as it is.
    #[test]
    fn the_hooked_idf_names_them_in_comments() {
        let ep = model(OVERHANG);
        let glitches = known_glitches(&ep, &["WIN_W".into()], Hook::Scheduled);
        let text = with_comments(&ep, "Version, 25.2;\n".into(), &glitches);
        assert!(text.starts_with("! sunlit: EnergyPlus's own known glitches") && text.contains("\n! - lone-full-sun: "), "{text}");
        assert!(text.ends_with("Version, 25.2;\n"));
        assert_eq!(with_comments(&ep, "Version, 25.2;\n".into(), &[]), "Version, 25.2;\n");
    }
}
