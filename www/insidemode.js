// The page's interior view (Map mode, "Inside rooms"): engine.map with `inside: true` (sunlit map
// --inside) on an EnergyPlus model's zones or a glTF model's rooms (Rooms and Glazing: node
// globs, as --interior and --glazing), a grid on their floors at a work plane's height, at
// an instant also on every other inside face (`faces`, --faces: the sun patches drawn on each
// face they fall on, and said in the status), over the period, or a
// study of the rooms (LEED ASE, BRE 209's No-Sky Line: each room's share said in the status);
// and the 3D view able to cut away the roof or one wall (its cells with it), so the floors' and
// the other walls' cells are seen from outside. No inside logic lives here: the points, values, patches and shares are the library's.

/** The faces a cut takes away: [axis (0 x east, 1 y north, 2 z up), side (+1: the high end)]. */
export const CUTS = { roof: [2, 1], north: [1, 1], south: [1, -1], east: [0, 1], west: [0, -1] };

/** The options the inside adds to a map request ({} when not asked): an empty work plane is the
 * library's default (0, or the study's own, as the CLI's); a glTF model's rooms and glazing are
 * globs over its node names, as the fields give them (the library reads and checks them). At an
 * `instant` the grid covers every inside face (`faces`), so each face's sun patch is drawn. */
export function insideOptions($, instant = false) {
  if (!$('mapinside').checked) return {};
  const o = { inside: true };
  if (instant && !$('mapinsidestudy').value) o.faces = true;
  const workPlane = $('mapworkplane').value.trim();
  if (workPlane !== '') o.workPlane = Number(workPlane);
  if ($('mapinsidestudy').value) o.study = $('mapinsidestudy').value;
  const [interior, glazing, glass] = ['mapinterior', 'mapglazing', 'mapglass'].map((id) => $(id).value.trim());
  if (interior !== '') o.interior = interior;
  if (glazing !== '') o.glazing = glazing;
  if (glass !== '') o.glassTransmittance = Number(glass);
  return o;
}

/** Whether an inside study is asked: it sets its own period and value. */
export function insideStudy($) {
  return $('mapinside').checked && $('mapinsidestudy').value !== '';
}

/** The cut named `name` for triangles `positions` (9 floats each): { axis, side, at }, where a
 * triangle with every corner at or beyond `at` on that side is not drawn; `at` lies 1 % of the
 * model's extent inside its bounds on that side, so the outermost faces (a flat roof, one
 * façade's walls) go and the floors stay. `null` for no cut. */
export function cutOf(name, positions) {
  const cut = CUTS[name];
  if (!cut || !positions?.length) return null;
  const [axis, side] = cut;
  let lo = Infinity;
  let hi = -Infinity;
  for (let i = axis; i < positions.length; i += 3) {
    lo = Math.min(lo, positions[i]);
    hi = Math.max(hi, positions[i]);
  }
  const margin = 0.01 * (hi - lo);
  return { axis, side, at: side > 0 ? hi - margin : lo + margin };
}

/** Whether the triangle at `positions[at..at + 9]` is cut away by `cut`. */
export function isCut(cut, positions, at) {
  if (!cut) return false;
  for (let v = 0; v < 3; v++) if (cut.side * (positions[at + 3 * v + cut.axis] - cut.at) < 0) return false;
  return true;
}

/** The sun patch the view draws on each face: per receiver name, the area (m²) of the cells
 * drawn in the lit colour `lit`, summed over the triangles of the view's own overlay (`overlay`:
 * its vertex data, `stride` floats a vertex, position first and colour at 6; six vertices a
 * point, in the map's order), so a cell the view does not draw (cut away: its corners collapsed)
 * counts nothing. `receivers` per point an index into `names`. Faces with no lit cell drawn are
 * absent. */
export function drawnPatches(overlay, stride, receivers, names, lit) {
  const out = {};
  const corner = (v, c) => overlay[v * stride + c];
  for (let t = 0; t < overlay.length / (3 * stride); t++) {
    const v = 3 * t;
    if (![0, 1, 2].every((c) => Math.abs(corner(v, 6 + c) - lit[c]) < 1e-6)) continue;
    const a = [0, 1, 2].map((c) => corner(v + 1, c) - corner(v, c));
    const b = [0, 1, 2].map((c) => corner(v + 2, c) - corner(v, c));
    const area = 0.5 * Math.hypot(a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]);
    if (area === 0) continue;
    const name = names[receivers[Math.floor(t / 2)]];
    out[name] = (out[name] ?? 0) + area;
  }
  return out;
}

/** The status line's words on an inside map's sun patches. */
export function patchSummary(patches) {
  if (!patches) return '';
  if (!patches.length) return '; no sun patch inside';
  const faces = patches.map((p) => `${p.surface} ${p.areaM2.toFixed(2)} m²`).join(', ');
  return `; sun patches: ${faces}`;
}

/** The status line's words on an inside study's rooms. */
export function areaSummary(areas) {
  if (!areas) return '';
  const share = (a) => (a.ase ?? a.seesSky).toFixed(1);
  return `; ${areas.map((a) => `${a.zone} ${share(a)} %`).join(', ')}`;
}

/** Wires the inside's controls: the cut redraws the view at once. `page`: { $, viewer() }. */
export function wireInside(page) {
  const { $ } = page;
  $('mapcut').addEventListener('change', () => {
    const viewer = page.viewer();
    viewer?.setCut(cutOf($('mapcut').value, viewer.positions));
    $('view').dataset.cut = $('mapcut').value;
  });
}
