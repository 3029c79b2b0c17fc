// www/map.js without a browser: the cells a map is painted with lie in their surface's plane,
// centred on their points, and tile a grid laid out as the library lays it (adjacent cells share
// edges, no gaps or overlaps); y-up turns sunlit's axes into three.js's; lit maps take the
// palette's two ends.
import assert from 'node:assert/strict';
import { test } from 'node:test';
import { LIT, SHADED, mapCells, mapColours, mapRange } from '../../www/map.js';

const close = (a, b, what) => assert.ok(Math.abs(a - b) < 1e-5, `${what}: ${a} vs ${b}`);

/** A 2 × 2 grid at 0.5 m on a plane through the origin with unit normal n, along (u, v). */
function grid(n, u, v) {
  const points = [];
  for (const [a, b] of [[0.25, 0.25], [0.75, 0.25], [0.25, 0.75], [0.75, 0.75]]) points.push(...u.map((x, k) => a * x + b * v[k]));
  return { points: new Float32Array(points), normals: new Float32Array([...n, ...n, ...n, ...n]) };
}

for (const [label, n, u, v] of [
  ['a south wall', [0, -1, 0], [1, 0, 0], [0, 0, 1]],
  ['a roof tilted south', [0, -Math.sin(0.3), Math.cos(0.3)], [1, 0, 0], [0, Math.cos(0.3), Math.sin(0.3)]],
  ['a west wall turned 20°', [-Math.cos(0.35), -Math.sin(0.35), 0], [Math.sin(0.35), -Math.cos(0.35), 0], [0, 0, 1]],
]) {
  test(`cells on ${label} lie in its plane, centred on their points, and tile the grid`, () => {
    const g = grid(n, u, v);
    const { positions, normals } = mapCells(g.points, g.normals, { size: 0.5, lift: 0 });
    assert.equal(positions.length, 4 * 18);
    const corners = new Map();
    for (let i = 0; i < 4; i++) {
      const centre = [0, 0, 0];
      for (let k = 0; k < 6; k++) {
        const p = positions.subarray(18 * i + 3 * k, 18 * i + 3 * k + 3);
        close(p[0] * n[0] + p[1] * n[1] + p[2] * n[2], 0, 'distance from the plane');
        for (let c = 0; c < 3; c++) close(normals[18 * i + 3 * k + c], n[c], 'normal');
        const key = Array.from(p, (x) => x.toFixed(4)).join(',');
        corners.set(key, (corners.get(key) ?? 0) + 1);
        // Of the six vertices, 0, 1, 2, 5 are the square's four corners.
        if ([0, 1, 2, 5].includes(k)) for (let c = 0; c < 3; c++) centre[c] += p[c] / 4;
      }
      for (let c = 0; c < 3; c++) close(centre[c], g.points[3 * i + c], 'centre');
    }
    // A 2 × 2 tiling has 9 distinct corners: cells share their edges.
    assert.equal(corners.size, 9);
  });
}

test('lift moves the cells along the normal; yUp gives three.js axes (x, z, −y)', () => {
  const g = grid([0, 0, 1], [1, 0, 0], [0, 1, 0]);
  const lifted = mapCells(g.points, g.normals, { size: 0.5, lift: 0.02 }).positions;
  for (let k = 2; k < lifted.length; k += 3) close(lifted[k], 0.02, 'lifted z');
  const up = mapCells(g.points, g.normals, { size: 0.5, lift: 0.02, yUp: true });
  for (let k = 0; k < lifted.length; k += 3) {
    close(up.positions[k], lifted[k], 'x');
    close(up.positions[k + 1], lifted[k + 2], 'y = z');
    close(up.positions[k + 2], -lifted[k + 1], 'z = −y');
  }
  close(up.normals[1], 1, 'normal up is +y');
  assert.throws(() => mapCells(g.points, g.normals, { size: 0 }), /size must be above 0/);
  assert.throws(() => mapCells(g.points, g.normals.subarray(3), {}), /3 numbers per point/);
});

test('colours: the palette over the range, lit and shaded for a lit map', () => {
  assert.deepEqual(mapRange(new Float32Array([0, 3, 7.5]), 'sunHours'), { min: 0, max: 7.5 });
  assert.deepEqual(mapRange(new Float32Array([0, 0]), 'sunHours'), { min: 0, max: 1 });
  const lit = mapColours(new Float32Array([1, 0]), { min: 0, max: 1, value: 'lit' });
  assert.deepEqual(Array.from(lit.subarray(0, 3)), LIT.map(Math.fround));
  assert.deepEqual(Array.from(lit.subarray(18, 21)), SHADED.map(Math.fround));
  assert.notDeepEqual(LIT, SHADED);
});
