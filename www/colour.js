// The one colour scale of the page: 0 (shaded) dark blue → 1 (sunlit) warm yellow. Used by the
// 3D view, the legend (style.css repeats these stops) and the heat map.
const STOPS = [
  [0.0, [0.12, 0.16, 0.42]],
  [0.25, [0.19, 0.38, 0.62]],
  [0.5, [0.27, 0.6, 0.58]],
  [0.75, [0.7, 0.78, 0.36]],
  [1.0, [0.99, 0.88, 0.3]],
];

/** RGB in 0..1 for a fraction (clamped to 0..1). */
export function colourOf(value) {
  const v = Math.min(1, Math.max(0, Number.isFinite(value) ? value : 0));
  for (let i = 1; i < STOPS.length; i++) {
    const [t1, c1] = STOPS[i];
    if (v <= t1) {
      const [t0, c0] = STOPS[i - 1];
      const k = (v - t0) / (t1 - t0);
      return c0.map((a, j) => a + (c1[j] - a) * k);
    }
  }
  return STOPS[STOPS.length - 1][1];
}

/** Shading geometry and not-yet-computed receivers. */
export const GREY = [0.62, 0.62, 0.6];
export const UNCOMPUTED = [0.86, 0.84, 0.78];
