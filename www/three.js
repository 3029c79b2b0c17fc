// sunlit/three: a sunlit Model from a three.js scene graph, and the way back (receiving meshes
// coloured by fraction or irradiation, with a legend; per-point maps painted on the receivers).
// three is a peer dependency: nothing here imports it; the scene's own objects (Matrix4, Color)
// are used, or the three module the app passes in, so the app's three is the one.
import { colourOf } from './colour.js';
import { MAP_VALUES, mapCells, mapColours, mapRange } from './map.js';

/** Comma-separated globs (`*`, `?`, case-insensitive) as one predicate over names. */
function globPredicate(text) {
  const patterns = String(text)
    .split(',')
    .map((p) => p.trim())
    .filter(Boolean)
    .map((p) => new RegExp(`^${p.replace(/[.+^${}()|[\]\\]/g, '\\$&').replace(/\*/g, '.*').replace(/\?/g, '.')}$`, 'i'));
  if (patterns.length === 0) throw new TypeError('fromThree: receivers is an empty pattern list');
  return (mesh) => patterns.some((re) => re.test(mesh.name ?? ''));
}

function receiverPredicate(receivers) {
  if (typeof receivers === 'function') return receivers;
  if (typeof receivers === 'string') return globPredicate(receivers);
  throw new TypeError('fromThree: receivers must be a comma-separated glob string over mesh names or a function (mesh) => boolean');
}

/** A geometry's vertices (x y z, local) and triangle list, indexed or not. */
function geometryArrays(geometry, label) {
  const position = geometry?.attributes?.position;
  if (!position || position.itemSize < 3) throw new Error(`fromThree: mesh '${label}' has no position attribute`);
  const positions = new Float32Array(position.count * 3);
  for (let i = 0; i < position.count; i++) {
    positions[3 * i] = position.getX(i);
    positions[3 * i + 1] = position.getY(i);
    positions[3 * i + 2] = position.getZ(i);
  }
  const indices = geometry.index ? Uint32Array.from(geometry.index.array) : Uint32Array.from({ length: position.count - (position.count % 3) }, (_, i) => i);
  return { positions, indices };
}

/** `a × b` of two column-major 4×4 arrays. */
function multiply(a, b) {
  const out = new Float64Array(16);
  for (let c = 0; c < 4; c++)
    for (let r = 0; r < 4; r++) {
      let s = 0;
      for (let k = 0; k < 4; k++) s += a[k * 4 + r] * b[c * 4 + k];
      out[c * 4 + r] = s;
    }
  return out;
}

const links = new WeakMap();

/** The palette is in sRGB, as the legend's CSS is; three.js (r152+) converts from it to its linear
 * working space, so a surface shows the legend's colour. (three's SRGBColorSpace, by value.) */
const SRGB = 'srgb';

/**
 * A Model from every Mesh under `object` (world matrices applied; InstancedMesh kept instanced,
 * instance i named `NAME[i]`), in three.js's Y-up axes. `receivers`: comma-separated globs over
 * mesh names, or `(mesh) => boolean`. Receiver names are the mesh names, which must be unique.
 */
export function fromThree(engine, object, { receivers } = {}) {
  if (typeof engine?.fromMeshes !== 'function') throw new TypeError('fromThree: engine must come from createEngine()');
  if (!object?.isObject3D) throw new TypeError('fromThree: object must be a three.js Object3D (a Scene, Group or Mesh)');
  if (receivers === undefined) throw new TypeError('fromThree: give receivers (globs over mesh names, or a predicate)');
  const receives = receiverPredicate(receivers);
  object.updateWorldMatrix(true, true);
  const meshes = [];
  object.traverse((o) => {
    if (o.isMesh && o.geometry) meshes.push(o);
  });
  if (meshes.length === 0) throw new Error('fromThree: no Mesh under the object');
  const geometryIndex = new Map();
  const chunks = { positions: [], indices: [], vertexStarts: [0], indexStarts: [0] };
  const placement = { meshes: [], matrices: [], names: [], receivers: [], owners: [] };
  const seen = new Map();
  for (const mesh of meshes) {
    const receiving = !!receives(mesh);
    const name = mesh.name || `mesh ${meshes.indexOf(mesh)}`;
    if (receiving) seen.set(name, (seen.get(name) ?? 0) + 1);
    let g = geometryIndex.get(mesh.geometry);
    if (g === undefined) {
      const { positions, indices } = geometryArrays(mesh.geometry, name);
      g = chunks.vertexStarts.length - 1;
      chunks.positions.push(positions);
      chunks.indices.push(indices);
      chunks.vertexStarts.push(chunks.vertexStarts[g] + positions.length / 3);
      chunks.indexStarts.push(chunks.indexStarts[g] + indices.length);
      geometryIndex.set(mesh.geometry, g);
    }
    const world = mesh.matrixWorld.elements;
    const count = mesh.isInstancedMesh ? mesh.count : 1;
    for (let i = 0; i < count; i++) {
      const matrix = mesh.isInstancedMesh ? multiply(world, mesh.instanceMatrix.array.subarray(16 * i, 16 * i + 16)) : world;
      placement.meshes.push(g);
      placement.matrices.push(...matrix);
      placement.names.push(mesh.isInstancedMesh ? `${name}[${i}]` : name);
      placement.receivers.push(receiving ? 1 : 0);
      if (receiving) placement.owners.push({ mesh, instance: mesh.isInstancedMesh ? i : -1, name: placement.names.at(-1) });
    }
  }
  const duplicates = [...seen].filter(([, n]) => n > 1).map(([name, n]) => `'${name}' (${n} meshes)`);
  if (duplicates.length) throw new Error(`fromThree: receiving meshes need unique names (they are the output columns); duplicates: ${duplicates.join(', ')}`);
  if (placement.owners.length === 0) throw new Error(`fromThree: receivers matched none of the ${meshes.length} meshes`);
  const concat = (parts, Type) => {
    const out = new Type(parts.reduce((n, p) => n + p.length, 0));
    let at = 0;
    for (const p of parts) out.set(p, at), (at += p.length);
    return out;
  };
  const model = engine.fromMeshes({
    positions: concat(chunks.positions, Float32Array),
    vertexStarts: chunks.vertexStarts,
    indices: concat(chunks.indices, Uint32Array),
    indexStarts: chunks.indexStarts,
    placementMeshes: placement.meshes,
    matrices: placement.matrices,
    names: placement.names,
    receivers: placement.receivers,
    yUp: true,
  });
  links.set(model, placement.owners);
  return model;
}

/** The receiving meshes of a model made by fromThree, with the receiver name each stands for. */
export function receivingMeshes(model) {
  const owners = links.get(model);
  if (!owners) throw new TypeError('receivingMeshes: model was not made by fromThree');
  return owners.map(({ mesh, instance, name }) => ({ mesh, instance, name }));
}

/**
 * Colours the receiving meshes of `model` (from fromThree) by `values` (one per receiver name,
 * e.g. fractions, Annual.means or Annual.irradiation) on the page's palette between `min` and
 * `max` (default 0 and the largest value). A receiver split into planar parts (`NAME#k`) gets
 * the area-weighted mean of its parts. Each mesh gets its own material clone the first time.
 * Returns { min, max, legend } where legend is a DOM element when a document exists.
 */
export function colourByValues(model, values, { min = 0, max, label = '' } = {}) {
  const owners = links.get(model);
  if (!owners) throw new TypeError('colourByValues: model was not made by fromThree');
  const names = model.receiverNames;
  if (!values || values.length !== names.length) {
    throw new TypeError(`colourByValues: values must hold one number per receiver (${names.length}), got ${values?.length}`);
  }
  const top = max ?? Math.max(...Array.from(values, Number), 1e-12);
  if (!(Number.isFinite(min) && Number.isFinite(top) && top > min)) throw new RangeError(`colourByValues: min ${min} must be below max ${top}`);
  const areas = model.receiverAreas;
  const sums = new Map();
  names.forEach((n, r) => {
    const base = n.replace(/#\d+$/, '');
    const s = sums.get(base) ?? { v: 0, a: 0 };
    s.v += values[r] * areas[r];
    s.a += areas[r];
    sums.set(base, s);
  });
  for (const { mesh, instance, name } of owners) {
    const s = sums.get(name);
    if (!s) continue;
    const [r, g, b] = colourOf((s.v / s.a - min) / (top - min));
    if (instance >= 0) {
      const colour = mesh.material.color?.clone?.() ?? null;
      if (colour) mesh.setColorAt(instance, colour.setRGB(r, g, b, SRGB));
      if (mesh.instanceColor) mesh.instanceColor.needsUpdate = true;
    } else {
      if (!mesh.userData.sunlitMaterial) {
        mesh.material = mesh.material.clone();
        mesh.userData.sunlitMaterial = true;
      }
      mesh.material.color.setRGB(r, g, b, SRGB);
    }
  }
  return { min, max: top, legend: typeof document === 'undefined' ? null : legend(min, top, label) };
}

/** A horizontal legend: the palette's gradient with its ends labelled. */
export function legend(min, max, label = '') {
  const box = document.createElement('div');
  box.className = 'sunlit-legend';
  const stops = [0, 0.25, 0.5, 0.75, 1].map((t) => `rgb(${colourOf(t).map((c) => Math.round(c * 255)).join(',')}) ${t * 100}%`);
  const bar = document.createElement('div');
  bar.style.cssText = `height:12px;min-width:160px;background:linear-gradient(to right, ${stops.join(', ')})`;
  const ends = document.createElement('div');
  ends.style.cssText = 'display:flex;justify-content:space-between;font:12px sans-serif';
  const fmt = (v) => (Math.abs(v) >= 10 ? v.toFixed(0) : v.toFixed(2));
  for (const text of [fmt(min), label, fmt(max)]) {
    const span = document.createElement('span');
    span.textContent = text;
    ends.append(span);
  }
  box.append(bar, ends);
  return box;
}

/** sRGB (the palette's, the legend's CSS) to linear: three.js reads vertex colours as linear, and
 * an unlit material's output is encoded back to sRGB, so a cell shows the legend's colour. */
function linear(c) {
  return c <= 0.04045 ? c / 12.92 : ((c + 0.055) / 1.055) ** 2.4;
}

/**
 * A three.js Mesh that paints `map` (what engine.map returns) on the receivers: per point a
 * square cell of side `size` (default the map's grid spacing) in its surface's plane, lifted
 * `lift` metres along its normal, coloured per vertex by its value (unlit, so the colour is the
 * legend's). A lit-at-an-instant map draws sunlit's own shadow pattern: lit cells in the
 * palette's top colour, shaded ones in its bottom. `THREE` is the app's three module. `yUp`
 * (default true: fromThree's axes) turns sunlit's z-up points into three's y-up scene.
 * Returns { mesh, min, max, legend, update(values) }: `update` recolours the same cells (e.g. the
 * same grid at another instant) without new geometry.
 */
export function paintMap(THREE, map, { size, lift = 0.01, yUp = true, min, max, label } = {}) {
  if (typeof THREE?.BufferGeometry !== 'function') throw new TypeError('paintMap: pass the app\'s three module (import * as THREE from \'three\')');
  if (!map?.points || !map.normals || !map.values) throw new TypeError('paintMap: map must come from engine.map (points, normals, values)');
  if (map.values.length * 3 !== map.points.length) {
    throw new RangeError(`paintMap: ${map.points.length / 3} points but ${map.values.length} values`);
  }
  const kind = MAP_VALUES[map.value] ? map.value : 'sunHours';
  const cells = mapCells(map.points, map.normals, { size: size ?? map.spacing ?? 0.5, lift, yUp });
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(cells.positions, 3));
  geometry.setAttribute('normal', new THREE.BufferAttribute(cells.normals, 3));
  const colour = new THREE.BufferAttribute(new Float32Array(cells.positions.length), 3);
  geometry.setAttribute('color', colour);
  const material = new THREE.MeshBasicMaterial({ vertexColors: true, side: THREE.DoubleSide });
  const mesh = new THREE.Mesh(geometry, material);
  mesh.name = 'sunlit map';
  const painted = { mesh, min: 0, max: 1, legend: null };
  painted.update = (values) => {
    if (values.length !== map.values.length) throw new RangeError(`paintMap: update needs ${map.values.length} values, got ${values.length}`);
    const auto = mapRange(values, kind);
    const range = { min: min ?? auto.min, max: max ?? auto.max, value: kind };
    if (!(range.max > range.min)) throw new RangeError(`paintMap: min ${range.min} must be below max ${range.max}`);
    const rgb = mapColours(values, range);
    for (let i = 0; i < rgb.length; i++) colour.array[i] = linear(rgb[i]);
    colour.needsUpdate = true;
    const title = label ?? [MAP_VALUES[kind].title, MAP_VALUES[kind].unit].filter(Boolean).join(', ');
    Object.assign(painted, { min: range.min, max: range.max, values });
    painted.legend = typeof document === 'undefined' ? null : kind === 'lit' ? litLegend() : legend(range.min, range.max, title);
    return painted;
  };
  return painted.update(map.values);
}

/** The lit-at-an-instant legend: the two colours, named. */
function litLegend() {
  const box = document.createElement('div');
  box.className = 'sunlit-legend';
  box.style.cssText = 'display:flex;gap:0.8rem;font:12px sans-serif;align-items:center';
  for (const [value, text] of [[1, 'sun'], [0, 'shadow']]) {
    const swatch = document.createElement('span');
    swatch.style.cssText = `display:inline-block;width:14px;height:14px;background:rgb(${colourOf(value).map((c) => Math.round(c * 255)).join(',')})`;
    const span = document.createElement('span');
    span.append(swatch, ` ${text}`);
    box.append(span);
  }
  return box;
}
