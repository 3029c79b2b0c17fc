// A scene the browser tests build in the page (as a script, `eval`ed there): shared by the pool's
// tests and the first visit's.

/** In the page: a box-shaped building (4 walls and a roof, the receivers) behind rows of louvre
 * slats and a neighbouring block, as typed arrays: shadows with many edges, built the same way in
 * every run (no randomness). */
export const SCENE = `
function louvredBlock() {
  const positions = [];
  const indices = [];
  const triangleReceivers = [];
  const quad = (a, b, c, d, receiver) => {
    const i = positions.length / 3;
    positions.push(...a, ...b, ...c, ...d);
    indices.push(i, i + 1, i + 2, i, i + 2, i + 3);
    triangleReceivers.push(receiver, receiver);
  };
  const box = (x0, y0, z0, x1, y1, z1) => {
    quad([x0, y0, z0], [x1, y0, z0], [x1, y0, z1], [x0, y0, z1], -1);
    quad([x1, y1, z0], [x0, y1, z0], [x0, y1, z1], [x1, y1, z1], -1);
    quad([x0, y1, z0], [x0, y0, z0], [x0, y0, z1], [x0, y1, z1], -1);
    quad([x1, y0, z0], [x1, y1, z0], [x1, y1, z1], [x1, y0, z1], -1);
    quad([x0, y0, z1], [x1, y0, z1], [x1, y1, z1], [x0, y1, z1], -1);
    quad([x0, y1, z0], [x1, y1, z0], [x1, y0, z0], [x0, y0, z0], -1);
  };
  // Receivers: south, east, north, west walls and the roof of a 10 x 8 x 6 m block.
  quad([0, 0, 0], [10, 0, 0], [10, 0, 6], [0, 0, 6], 0);
  quad([10, 0, 0], [10, 8, 0], [10, 8, 6], [10, 0, 6], 1);
  quad([10, 8, 0], [0, 8, 0], [0, 8, 6], [10, 8, 6], 2);
  quad([0, 8, 0], [0, 0, 0], [0, 0, 6], [0, 8, 6], 3);
  quad([0, 0, 6], [10, 0, 6], [10, 8, 6], [0, 8, 6], 4);
  // Louvres: 24 slats 0.6 m in front of the south wall, 15 fins in front of the east wall.
  for (let k = 0; k < 24; k++) box(0.2, -0.8, 0.2 + k * 0.24, 9.8, -0.6, 0.25 + k * 0.24);
  for (let k = 0; k < 15; k++) box(10.6, 0.3 + k * 0.5, 0.2, 10.7, 0.5 + k * 0.5, 5.8);
  // A neighbour to the south-west, and a rooftop plant box.
  box(-14, -12, 0, -4, -6, 14);
  box(3, 3, 6, 5, 4.5, 7.5);
  return { positions, indices, triangleReceivers, names: ['South', 'East', 'North', 'West', 'Roof'] };
}
`;
