// The box room the inside tests map (tests/browser/inside.test.mjs, tests/node/three-inside.test.mjs):
// an EnergyPlus model of one zone with one south window, and a year of weather at its site.

/** A 4 m × 5 m × 3 m room, its window x 1–3 m, z 1–2.5 m in the south wall (y = 0), as
 * tests/inside.rs builds it. */
export function roomIdf() {
  const surface = (name, kind, boundary, corners) =>
    `BuildingSurface:Detailed,${name},${kind},Opaque,Office,,${boundary},,${boundary === 'Outdoors' ? 'SunExposed,WindExposed' : 'NoSun,NoWind'},,${corners.length},${corners.flat().join(',')};\n`;
  return [
    'Version,25.2;\nBuilding,Box,0,Suburbs,0.04,0.4,FullInteriorAndExterior,25,6;\n',
    'GlobalGeometryRules,UpperLeftCorner,Counterclockwise,Relative;\nZone,Office,0,0,0,0;\n',
    'Construction,Opaque,Layer;\nConstruction,Glass,SimpleGlass;\nWindowMaterial:SimpleGlazingSystem,SimpleGlass,2.0,0.6,0.7;\n',
    surface('South', 'Wall', 'Outdoors', [[0, 0, 3], [0, 0, 0], [4, 0, 0], [4, 0, 3]]),
    surface('North', 'Wall', 'Outdoors', [[4, 5, 3], [4, 5, 0], [0, 5, 0], [0, 5, 3]]),
    surface('East', 'Wall', 'Outdoors', [[4, 0, 3], [4, 0, 0], [4, 5, 0], [4, 5, 3]]),
    surface('West', 'Wall', 'Outdoors', [[0, 5, 3], [0, 5, 0], [0, 0, 0], [0, 0, 3]]),
    surface('Floor', 'Floor', 'Ground', [[4, 0, 0], [0, 0, 0], [0, 5, 0], [4, 5, 0]]),
    surface('Roof', 'Roof', 'Outdoors', [[0, 0, 3], [4, 0, 3], [4, 5, 3], [0, 5, 3]]),
    'FenestrationSurface:Detailed,Win,Window,Glass,South,,,,1,4,1,0,2.5,1,0,1,3,0,1,3,0,2.5;\n',
  ].join('');
}

/** A year at Golden whose beam varies hour by hour, with the direct normal illuminance (field 18)
 * given, so that ASE's hours over 1000 lux vary from point to point. */
export function goldenEpw() {
  const lines = ['LOCATION,Golden,CO,USA,test,724666,39.74,-105.18,-7.0,1829', 'DESIGN CONDITIONS,0', 'TYPICAL/EXTREME PERIODS,0',
    'GROUND TEMPERATURES,0', 'HOLIDAYS/DAYLIGHT SAVINGS,No,0,0,0', 'COMMENTS 1,', 'COMMENTS 2,', 'DATA PERIODS,1,1,Data,Sunday,1/1,12/31'];
  let n = 0;
  [31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31].forEach((count, m) => {
    for (let d = 1; d <= count; d++) {
      for (let h = 1; h <= 24; h++) {
        const dni = 100 + ((n++ * 37) % 700);
        lines.push(`1999,${m + 1},${d},${h},60,x,20,10,50,101000,0,1300,300,500,${dni},100,0,${dni * 95},0,0,0,0,0,0,0,0,9,0,0,0,0,0,0,0,0`);
      }
    }
  });
  return `${lines.join('\n')}\n`;
}

/** The same room as a glTF model (tests/inside.rs's `room_glb`): node `Room`, its closed shell
 * wound outwards with the window's opening left in the south wall, and node `Glass`, the pane in
 * it. With `glass` (a material's `extras.sunlit`, e.g. a transmittance curve), the pane's mesh
 * uses that material. Written as a .gltf with its buffer embedded (a data: URI), in glTF's axes
 * (y up, −z north). */
export function roomGltf(glass = null) {
  const [w, d, h] = [4, 5, 3];
  const [x0, x1, z0, z1] = [1, 3, 1, 2.5];
  // A rectangle in the plane y = `y` (sunlit's axes), its normal along ±y as `out` says.
  const rectY = (y, xa, xb, za, zb, out) => [[[xa, y, za], [xb, y, za], [xb, y, zb], [xa, y, zb]], [0, out, 0]];
  const shell = [
    rectY(0, 0, x0, 0, h, -1),
    rectY(0, x1, w, 0, h, -1),
    rectY(0, x0, x1, 0, z0, -1),
    rectY(0, x0, x1, z1, h, -1),
    rectY(d, 0, w, 0, h, 1),
    [[[0, 0, 0], [0, d, 0], [0, d, h], [0, 0, h]], [-1, 0, 0]],
    [[[w, 0, 0], [w, d, 0], [w, d, h], [w, 0, h]], [1, 0, 0]],
    [[[0, 0, 0], [w, 0, 0], [w, d, 0], [0, d, 0]], [0, 0, -1]],
    [[[0, 0, h], [w, 0, h], [w, d, h], [0, d, h]], [0, 0, 1]],
  ];
  const pane = [rectY(0, x0, x1, z0, z1, -1)];
  const sub = (a, b) => a.map((v, i) => v - b[i]);
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const dot = (a, b) => a.reduce((s, v, i) => s + v * b[i], 0);
  const meshes = [shell, pane].map((quads) => {
    const positions = [];
    const indices = [];
    for (const [q, out] of quads) {
      const flip = dot(cross(sub(q[1], q[0]), sub(q[2], q[0])), out) < 0;
      const base = positions.length / 3;
      // sunlit (x east, y north, z up) to glTF (x, z, −y): a rotation, so windings keep.
      for (const [x, y, z] of q) positions.push(x, z, -y);
      indices.push(...(flip ? [0, 2, 1, 0, 3, 2] : [0, 1, 2, 0, 2, 3]).map((i) => base + i));
    }
    return { positions: new Float32Array(positions), indices: new Uint32Array(indices) };
  });
  const chunks = [];
  let offset = 0;
  const views = [];
  for (const m of meshes) {
    for (const [array, target] of [[m.positions, 34962], [m.indices, 34963]]) {
      views.push({ buffer: 0, byteOffset: offset, byteLength: array.byteLength, target });
      chunks.push(Buffer.from(array.buffer));
      offset += array.byteLength;
    }
  }
  const accessors = meshes.flatMap((m, k) => {
    const lo = [0, 1, 2].map((a) => Math.min(...m.positions.filter((_, i) => i % 3 === a)));
    const hi = [0, 1, 2].map((a) => Math.max(...m.positions.filter((_, i) => i % 3 === a)));
    return [
      { bufferView: 2 * k, componentType: 5126, count: m.positions.length / 3, type: 'VEC3', min: lo, max: hi },
      { bufferView: 2 * k + 1, componentType: 5125, count: m.indices.length, type: 'SCALAR' },
    ];
  });
  const primitive = (k, material) => ({ attributes: { POSITION: 2 * k }, indices: 2 * k + 1, ...(material === undefined ? {} : { material }) });
  const doc = {
    asset: { version: '2.0' },
    scene: 0,
    scenes: [{ nodes: [0, 1] }],
    nodes: [{ name: 'Room', mesh: 0 }, { name: 'Glass', mesh: 1 }],
    meshes: [{ name: 'room', primitives: [primitive(0)] }, { name: 'glass', primitives: [primitive(1, glass ? 0 : undefined)] }],
    ...(glass ? { materials: [{ name: 'Pane', extras: { sunlit: glass } }] } : {}),
    accessors,
    bufferViews: views,
    buffers: [{ byteLength: offset, uri: `data:application/octet-stream;base64,${Buffer.concat(chunks).toString('base64')}` }],
  };
  return JSON.stringify(doc);
}
