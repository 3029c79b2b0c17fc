// Headless Debian Chromium with WebGPU on its bundled SwiftShader (../shared/notes/gpu.md), and a
// static server for the apps it loads, for the page tests. The same flags are in webdriver.json
// for wasm-bindgen-test-runner.
import { readFileSync } from 'node:fs';
import { readFile } from 'node:fs/promises';
import { createServer } from 'node:http';
import { extname, join, normalize, sep } from 'node:path';
import { chromium } from 'playwright-core';

const ROOT = new URL('../../', import.meta.url);

/** The flags from webdriver.json, so both test paths run the same browser. */
export function chromiumFlags() {
  const config = JSON.parse(readFileSync(new URL('webdriver.json', ROOT), 'utf8'));
  // Playwright passes its own --headless and a fresh profile folder.
  return config['goog:chromeOptions'].args.filter((a) => !a.startsWith('--headless'));
}

export async function launch({ webgpu = true, extraArgs = [] } = {}) {
  const webgpuFlags = ['--enable-unsafe-webgpu', '--enable-features=Vulkan', '--use-angle=swiftshader', '--use-vulkan=swiftshader'];
  const args = [...chromiumFlags().filter((a) => webgpu || !webgpuFlags.includes(a)), ...extraArgs];
  return chromium.launch({ executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium', args, headless: true });
}

/** Serves `dir` on a free local port (for built apps the browser loads); resolves to the server. */
export function staticServer(dir) {
  const types = { '.html': 'text/html', '.js': 'text/javascript', '.wasm': 'application/wasm', '.css': 'text/css', '.glb': 'model/gltf-binary' };
  const s = createServer(async (req, res) => {
    const path = decodeURIComponent(new URL(req.url, 'http://x').pathname);
    const file = normalize(join(dir, path.endsWith('/') ? `${path}index.html` : path));
    if (!file.startsWith(dir + sep)) return res.writeHead(403).end();
    try {
      const body = await readFile(file);
      res.writeHead(200, { 'Content-Type': types[extname(file)] ?? 'application/octet-stream' }).end(body);
    } catch {
      res.writeHead(404).end();
    }
  });
  return new Promise((resolve) => s.listen(0, '127.0.0.1', () => resolve(s)));
}
