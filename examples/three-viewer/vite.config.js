// Vite's defaults, plus: the example office lives one folder up (examples/office.glb), which the
// dev server may read.
import { defineConfig } from 'vite';

export default defineConfig({
  server: { fs: { allow: ['..'] } },
});
