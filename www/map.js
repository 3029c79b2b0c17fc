// Per-point maps (what engine.map returns: points, normals, receiver ids, values) as things to
// draw, without three.js or the DOM: a small square cell on its surface per point (the
// generated grid mesh that the page's view and sunlit/three colour per vertex), and the colours
// of the values. (The points CSV and the map glb come from the library: engine.map's csv/glb.)
import { colourOf } from './colour.js';

/** The values a map can hold: the legend's title and unit. */
export const MAP_VALUES = {
  sunHours: { title: 'Sun hours', unit: 'h' },
  direct: { title: 'Direct irradiation', unit: 'kWh/m²' },
  skyDiffuse: { title: 'Sky-diffuse irradiation', unit: 'kWh/m²' },
  total: { title: 'Total irradiation', unit: 'kWh/m²' },
  lit: { title: 'Sunlit at the instant', unit: '' },
  // An inside study's values (engine.map with inside and study).
  aseHours: { title: 'Occupied hours over 1000 lux of direct sun', unit: 'h' },
  seesSky: { title: 'Sees sky (No-Sky Line)', unit: '' },
};

/** A point in the sun at the instant, and one in shadow: the palette's two ends. */
export const LIT = colourOf(1);
export const SHADED = colourOf(0);

/** Two unit vectors across the surface whose normal is `n`, as the library lays its grid out
 * (map::points): horizontal on walls (z × n), x projected onto the plane on flat surfaces
 * (|n.z| ≥ 0.9), and n × that one; so a grid's cells tile its surface. */
function across(n) {
  let u = Math.abs(n[2]) < 0.9 ? [-n[1], n[0], 0] : [1 - n[0] * n[0], -n[1] * n[0], -n[2] * n[0]];
  const l = Math.hypot(...u) || 1;
  u = u.map((x) => x / l);
  const v = [n[1] * u[2] - n[2] * u[1], n[2] * u[0] - n[0] * u[2], n[0] * u[1] - n[1] * u[0]];
  return [u, v];
}

/**
 * The cells of a map: per point, a square of side `size` (metres) centred on it in its surface's
 * plane, lifted `lift` metres along its normal so that it draws over the surface; two triangles,
 * six vertices. Returns { positions, normals } (Float32Array, 18 floats per point), in sunlit's
 * world axes (x east, y north, z up), or three.js's (x, z, −y) when `yUp`.
 */
export function mapCells(points, normals, { size = 0.5, lift = 0.01, yUp = false } = {}) {
  if (!(size > 0)) throw new RangeError(`mapCells: size must be above 0, got ${size}`);
  const count = points.length / 3;
  if (!Number.isInteger(count) || normals.length !== points.length) {
    throw new RangeError(`mapCells: points (${points.length}) and normals (${normals.length}) must hold 3 numbers per point alike`);
  }
  const h = size / 2;
  const outP = new Float32Array(count * 18);
  const outN = new Float32Array(count * 18);
  const corners = [[-1, -1], [1, -1], [1, 1], [-1, -1], [1, 1], [-1, 1]];
  for (let i = 0; i < count; i++) {
    const n = [normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]];
    const [u, v] = across(n);
    corners.forEach(([a, b], k) => {
      const at = 18 * i + 3 * k;
      for (let c = 0; c < 3; c++) {
        const p = points[3 * i + c] + lift * n[c] + h * (a * u[c] + b * v[c]);
        outP[at + c] = p;
        outN[at + c] = n[c];
      }
      if (yUp) {
        for (const out of [outP, outN]) {
          const y = out[at + 1];
          out[at + 1] = out[at + 2];
          out[at + 2] = -y;
        }
      }
    });
  }
  return { positions: outP, normals: outN };
}

/** The range a legend shows for `values`: 0 to the largest (at least `floor`); lit maps 0..1. */
export function mapRange(values, value) {
  if (value === 'lit') return { min: 0, max: 1 };
  let max = 0;
  for (const v of values) if (v > max) max = v;
  return { min: 0, max: max > 0 ? max : 1 };
}

/** One colour per point (RGB 0..1): the palette between `min` and `max`, or lit/shaded. */
export function mapColour(v, { min = 0, max = 1, value } = {}) {
  if (value === 'lit') return v >= 0.5 ? LIT : SHADED;
  return colourOf((v - min) / (max - min));
}

/** The cells' vertex colours (Float32Array, 18 floats per point) for `values`. */
export function mapColours(values, range) {
  const out = new Float32Array(values.length * 18);
  for (let i = 0; i < values.length; i++) {
    const c = mapColour(values[i], range);
    for (let k = 0; k < 6; k++) out.set(c, 18 * i + 3 * k);
  }
  return out;
}

