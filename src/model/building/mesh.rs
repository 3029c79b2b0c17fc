//! A read [`Building`] into the scene: each surface triangulated in world coordinates with its
//! windows and doors cut out, set-back windows' reveals, and `Mir-` back faces where asked.

use super::*;

/// The receiver name of a zone surface's inside face (see [`Building::add_inside_to`]).
pub fn inside_name(surface: &str) -> String {
    format!("{surface}:inside")
}

/// Why a subsurface cannot be a hole in `base`, if it cannot.
pub(super) fn hole_problem(base: &EpSurface, hole: &EpSurface) -> Option<String> {
    let plane = Plane::of_polygon(&base.vertices);
    let outline: Vec<DVec2> = base.vertices.iter().map(|p| plane.project(*p)).collect();
    // Off the plane is no problem: EnergyPlus cuts a sub-surface's projection out of its base
    // surface at any offset (see `super::reveal`).
    if hole.vertices.iter().any(|p| !inside_or_on(plane.project(*p), &outline, EDGE_TOLERANCE)) {
        return Some(format!("is not within its base surface '{}'", base.name));
    }
    None
}

/// How far (degrees) an opening's plane may turn from its wall's and still be the hole the inside
/// cuts: EnergyPlus's own limit before it warns (`checkSubSurfAzTiltNorm` in SurfaceGeometry.cc,
/// "Outward facing angle of subsurface differs more than 30.0 degrees from base surface").
const OPENING_TURN_DEG: f64 = 30.0;

/// Why a subsurface is no opening of its wall for the inside, if it is not: beyond
/// [`hole_problem`], its plane must lie along the wall's (within [`OPENING_TURN_DEG`], either
/// facing), since the beam enters through its outline cast straight onto the wall. A window drawn
/// in another plane (a side wall's, the floor's) would cast a sliver there, and the room would be
/// dark without a word.
fn opening_problem(base: &EpSurface, hole: &EpSurface) -> Option<String> {
    if let Some(why) = hole_problem(base, hole) {
        return Some(why);
    }
    let (wall, opening) = (newell(&base.vertices).normalize_or_zero(), newell(&hole.vertices).normalize_or_zero());
    let turn = wall.dot(opening).abs().clamp(0.0, 1.0).acos().to_degrees();
    (turn > OPENING_TURN_DEG).then(|| {
        format!(
            "does not lie in its base surface '{}': its plane is turned {turn:.1}° from the wall's (more than {OPENING_TURN_DEG}°), so it opens no hole the beam can pass",
            base.name
        )
    })
}

/// Why EnergyPlus's own clipping does not shade a set-back window as the window is shaded, if it
/// does not: `SHDRVL` (SolarShading.cc) builds a four-sided window's reveal opening by moving its
/// vertices 1 and 2 as the left edge, 3 and 4 as the right, 1 and 4 as the top and 2 and 3 as the
/// bottom, so it is right only for an upright rectangle listed from its upper-left corner. Listed
/// from another corner, a window 0.152 m back under an overhang and fins got 0.61 from EnergyPlus
/// against 0.17 (its real mean over lit steps, which EnergyPlus gives when the same window is
/// listed from the upper-left; docs/energyplus-fidelity.md).
pub(super) fn reveal_problem(base: &EpSurface, sub: &EpSurface) -> Option<String> {
    let SubPlacement::SetBack { depth, .. } = reveal::place(&base.vertices, &sub.vertices)? else { return None };
    if sub.vertices.len() != 4 || frame::upright_from_upper_left(&sub.vertices, &base.vertices) {
        return None;
    }
    Some(format!(
        "is set back {depth:.3} m behind '{}' but its vertices are not an upright rectangle listed from its upper-left corner, which EnergyPlus's reveal shading (SHDRVL) assumes: EnergyPlus's own shading calculation gives it a sunlit fraction that is not the window's; sunlit gives the window's own (and a hooked model uses it)",
        base.name
    ))
}

/// A surface's triangles in world coordinates, holes cut out, wound counter-clockwise seen from
/// outside. Receivers are flattened onto their best-fit plane (a scene receiver must be planar).
pub(super) fn triangulate(surface: &EpSurface, holes: &[&EpSurface]) -> Vec<[DVec3; 3]> {
    let plane = Plane::of_polygon(&surface.vertices);
    let mut points: Vec<DVec3> = surface.vertices.iter().map(|p| if surface.receiver { plane.flatten(*p) } else { *p }).collect();
    let mut starts: Vec<usize> = Vec::new();
    for hole in holes {
        starts.push(points.len());
        points.extend(hole.vertices.iter().map(|p| plane.flatten(*p)));
    }
    let mut triangles = geometry::triangulate(&plane, &points, &starts);
    if triangles.is_empty() {
        // Self-intersecting outlines defeat ear clipping; a fan over the outline still casts.
        triangles = (1..surface.vertices.len().saturating_sub(1)).map(|i| geometry::wind(&points, [0, i, i + 1], plane.normal)).collect();
    }
    triangles.iter().map(|t| t.map(|i| points[i])).collect()
}

impl Building {
    /// Adds every surface as shadow-casting geometry; receivers are the surfaces EnergyPlus lets
    /// the sun onto (Outside Boundary Condition Outdoors, not NoSun; see the module doc of
    /// `building`). A
    /// window or door is a hole in its base surface, so a wall's receiver is its net area, as
    /// EnergyPlus's sunlit fraction of the wall is; polygons with holes are triangulated by ear
    /// clipping (earcut) in the surface's plane. Receiver names are the EnergyPlus names as
    /// written in the file (EnergyPlus itself reports them upper-cased).
    pub fn add_to(&self, builder: &mut SceneBuilder) -> Result<()> {
        self.add_surfaces(builder, false, &HashMap::new(), |_| false)
    }

    /// As [`Building::add_to`], with shading surfaces that let τ of the beam through (by
    /// lower-case name): see-through casters for 0 < τ < 1, no caster at all for τ ≥ 1.
    pub fn add_to_with(&self, builder: &mut SceneBuilder, shades: &HashMap<String, f64>) -> Result<()> {
        self.add_surfaces(builder, false, shades, |_| false)
    }

    /// The rooms' side of the model: every surface but glazing (windows and glass doors, whose
    /// openings stay open: the caller weights the beam through them) casts and receives on its
    /// outside face, and every zone surface also gets its inside face as the receiver
    /// `NAME:inside` (a mirror: same triangles, normal into the zone, never shaded by itself).
    /// Refuses a window or door that does not lie in its base surface: its opening would be
    /// left uncut, and the room sealed.
    pub fn add_inside_to(&self, builder: &mut SceneBuilder) -> Result<()> {
        self.add_inside_open(builder, EpSurface::is_glazing)
    }

    /// As [`Building::add_inside_to`], with every opening glazed: each window and glass door
    /// casts (and receives, under its own name), set-back ones with their reveals. A view that
    /// leaves one window's glass out ([`crate::count::exact::engine::ExactEngine::fractions_through`])
    /// sees the beam that came through that window alone (EnergyPlus's interior beam is counted
    /// per exterior window), so one scene answers every window.
    pub fn add_inside_glazed(&self, builder: &mut SceneBuilder) -> Result<()> {
        self.add_inside_open(builder, |_| false)
    }

    /// The inside scene with the openings `open` picks left out (holes in their walls).
    fn add_inside_open(&self, builder: &mut SceneBuilder, open: impl Fn(&EpSurface) -> bool) -> Result<()> {
        if let Some((hole, why)) = self.misplaced_openings().into_iter().next() {
            return Err(Error::object(&self.file, hole.label(), why));
        }
        self.add_surfaces(builder, true, &HashMap::new(), open)?;
        for s in self.surfaces.iter().filter(|s| s.zone.is_some() && !s.is_shading() && !s.is_glazing()) {
            builder.add_mirror(&s.name, &inside_name(&s.name));
        }
        Ok(())
    }

    /// Windows and doors that cannot be cut out of their base surface, with why.
    fn misplaced_openings(&self) -> Vec<(&EpSurface, String)> {
        self.surfaces
            .iter()
            .filter(|s| s.is_fenestration())
            .filter_map(|hole| {
                let base = hole.base.as_deref().and_then(|b| self.surface(b))?;
                opening_problem(base, hole).map(|why| (hole, why))
            })
            .collect()
    }

    /// As [`Building::add_to`], but every surface receives, and every shading surface also gets
    /// its back face `Mir-NAME` as EnergyPlus makes it: the columns EnergyPlus's `Imported`
    /// method looks up (those of its own eplusshading.csv).
    pub fn add_all_to(&self, builder: &mut SceneBuilder) -> Result<()> {
        self.add_surfaces(builder, true, &HashMap::new(), |_| false)?;
        for s in self.surfaces.iter().filter(|s| s.is_shading()) {
            builder.add_mirror(&s.name, &format!("Mir-{}", s.name));
        }
        Ok(())
    }

    fn add_surfaces(
        &self,
        builder: &mut SceneBuilder,
        all: bool,
        shades: &HashMap<String, f64>,
        skip: impl Fn(&EpSurface) -> bool,
    ) -> Result<()> {
        let holes = self.holes();
        for (i, surface) in self.surfaces.iter().enumerate().filter(|(_, s)| !skip(s)) {
            let transmittance = shades.get(&surface.name.to_ascii_lowercase()).copied().filter(|_| surface.is_shading());
            if transmittance.is_some_and(|t| t >= 1.0) {
                // Lets all the sun through: casts no shadow, so it is left out.
                continue;
            }

            let placed = self.placed(surface);
            let surface = match &placed {
                Some(SubPlacement::InPlane(vertices)) => &EpSurface { vertices: vertices.clone(), ..surface.clone() },
                _ => surface,
            };
            if let Some(SubPlacement::SetBack { sides, .. }) = &placed {
                self.add_reveal(builder, surface, sides);
            }
            let triangles = triangulate(surface, holes.get(&i).map_or(&[][..], Vec::as_slice));
            let anchor = surface.vertices.first().copied().unwrap_or(DVec3::ZERO);
            let mesh = builder.add_mesh(format!("{}: {}", self.file, surface.label()), relative_mesh(&triangles, anchor));
            if let Some(t) = transmittance {
                builder.set_node_veil(builder.node_count(), NodeVeil { foliage: false, transmittance: t });
            }
            builder.add_node(SourceNode {
                name: surface.name.clone(),
                origin: format!("{}: {}", self.file, surface.label()),
                mesh,
                transform: DMat4::from_translation(anchor),
                receiver: all || surface.receiver,
            });
        }
        Ok(())
    }

    /// Where EnergyPlus puts a window or door against its base surface (None for other surfaces).
    fn placed(&self, surface: &EpSurface) -> Option<SubPlacement> {
        let base = surface.base.as_deref().filter(|_| surface.is_fenestration()).and_then(|b| self.surface(b))?;
        if base.is_fenestration() || base.is_shading() {
            return None;
        }
        reveal::place(&base.vertices, &surface.vertices)
    }

    /// How far a window or door is set back behind its base surface's plane (EnergyPlus's
    /// reveal), if it is.
    pub fn reveal_depth(&self, surface: &EpSurface) -> Option<f64> {
        match self.placed(surface)? {
            SubPlacement::SetBack { depth, .. } => Some(depth),
            SubPlacement::InPlane(_) => None,
        }
    }

    /// The sides of a set-back window's reveal: casters only, never receivers (not EnergyPlus
    /// surfaces), named `<window> reveal`.
    fn add_reveal(&self, builder: &mut SceneBuilder, surface: &EpSurface, sides: &[[DVec3; 3]]) {
        let anchor = surface.vertices.first().copied().unwrap_or(DVec3::ZERO);
        let origin = format!("{}: the reveal of {}", self.file, surface.label());
        let mesh = builder.add_mesh(origin.clone(), relative_mesh(sides, anchor));
        builder.add_node(SourceNode {
            name: format!("{} reveal", surface.name),
            origin,
            mesh,
            transform: DMat4::from_translation(anchor),
            receiver: false,
        });
    }

    /// Names of the receivers in the order [`Building::add_to`] adds them.
    pub fn receiver_names(&self) -> Vec<String> {
        self.surfaces.iter().filter(|s| s.receiver).map(|s| s.name.clone()).collect()
    }

    /// A surface by name (case-insensitive, as EnergyPlus).
    pub fn surface(&self, name: &str) -> Option<&EpSurface> {
        self.surfaces.iter().find(|s| s.name.eq_ignore_ascii_case(name))
    }

    /// Surface index → the windows and doors cut out of it (those that fit in it; the others
    /// were warned about when reading).
    pub(super) fn holes(&self) -> HashMap<usize, Vec<&EpSurface>> {
        let index: HashMap<String, usize> = self.surfaces.iter().enumerate().map(|(i, s)| (key(&s.name), i)).collect();
        let mut holes: HashMap<usize, Vec<&EpSurface>> = HashMap::new();
        for hole in self.surfaces.iter().filter(|s| s.is_fenestration()) {
            let Some(&b) = hole.base.as_deref().and_then(|b| index.get(&key(b))) else { continue };
            let base = &self.surfaces[b];
            if !base.is_fenestration() && !base.is_shading() && hole_problem(base, hole).is_none() {
                holes.entry(b).or_default().push(hole);
            }
        }
        holes
    }
}

/// Triangles as a mesh relative to `anchor`, so f32 positions keep millimetres far from the origin.
fn relative_mesh(triangles: &[[DVec3; 3]], anchor: DVec3) -> SourceMesh {
    let positions: Vec<[f32; 3]> = triangles.iter().flatten().map(|p| (*p - anchor).as_vec3().to_array()).collect();
    SourceMesh { indices: (0..positions.len() as u32).collect(), positions }
}
