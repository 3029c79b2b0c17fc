// sunlit's wasm bundle and JS API (www/sunlit.js, www/pkg) under Node, on WebGPU from Dawn for
// Node (npm `webgpu`: Chromium's own WebGPU implementation, without Chromium). Used by
// tests/node/dawn.test.mjs and scripts/bench-node-gpu.mjs.
//
// What a browser gives the page that Node lacks, and how it is stood in for here:
// - `navigator.gpu`: Dawn's GPU object (`create([])`), and its GPU* classes as globals.
// - `Window`: wgpu's WebGPU backend looks up `navigator.gpu` only where the global scope has a
//   `Window` (or `WorkerGlobalScope`) constructor (wgpu 30, backend/webgpu.rs,
//   get_browser_gpu_property); a stand-in class is enough, the lookup then reads
//   `globalThis.navigator`.
// - `fetch` of `file:` URLs: pool.js fetches the wasm beside the module (`new URL(…,
//   import.meta.url)`), which Node's fetch refuses for files; those are read from disk.
// Not stood in for: Web Workers (Node has worker_threads, a different API), so the page's pool of
// clipping workers (pool.js) cannot start: it fails with its own "could not start" error and the
// engine clips in its own thread, as in a page whose CSP forbids workers. IndexedDB is missing too,
// so `auto` measures its profile every run (profiles.js keeps nothing where it is missing).
import { spawnSync } from 'node:child_process';
import { existsSync } from 'node:fs';
import { readFile } from 'node:fs/promises';
import { join } from 'node:path';
import { fileURLToPath } from 'node:url';

export const ROOT = fileURLToPath(new URL('../../', import.meta.url));

/** Chromium's SwiftShader as a Vulkan driver (Debian's `chromium` ships it with its ICD file). */
export const SWIFTSHADER_ICD = '/usr/lib/chromium/vk_swiftshader_icd.json';

/** The Vulkan drivers tried, in order: the system's own (lavapipe here, NVIDIA's ICD on a GPU
 * machine; or whatever VK_ICD_FILENAMES / VK_DRIVER_FILES already name), then SwiftShader's where
 * the caller named none. Each is { name, env }. */
function candidates() {
  const named = process.env.VK_ICD_FILENAMES || process.env.VK_DRIVER_FILES;
  const list = [{ name: named ? `the Vulkan driver named by the environment (${named})` : "the system's Vulkan drivers", env: {} }];
  if (!named && existsSync(SWIFTSHADER_ICD)) list.push({ name: `SwiftShader (${SWIFTSHADER_ICD})`, env: { VK_ICD_FILENAMES: SWIFTSHADER_ICD } });
  return list;
}

/** Asks Dawn for an adapter in a child process with `env` added, so that what Dawn prints about
 * a driver it refuses (to the process's stderr, out of JavaScript's reach) can be told. Returns
 * { info: {vendor, architecture, device, description} | null, said: Dawn's stderr }; throws
 * where the child could not ask. */
function probe(env) {
  const script = `
    import { create } from 'webgpu';
    const gpu = create([]);
    const adapter = await gpu.requestAdapter();
    const info = adapter && { vendor: adapter.info.vendor, architecture: adapter.info.architecture, device: adapter.info.device, description: adapter.info.description };
    process.stdout.write(JSON.stringify(info));
    process.exit(0);`;
  const run = spawnSync(process.execPath, ['--input-type=module', '-e', script], {
    cwd: ROOT,
    env: { ...process.env, ...env },
    encoding: 'utf8',
    timeout: 60_000,
  });
  const said = (run.stderr ?? '').trim();
  // Only an adapter's absence is an answer; a child that could not ask (no `webgpu` package, a
  // crash, a hang) is an error, never a reason to skip.
  if (run.error || run.status !== 0) throw new Error(`Dawn could not be asked for an adapter (exit ${run.status}): ${run.error?.message ?? said}`);
  return { info: JSON.parse(run.stdout || 'null'), said };
}

/** The first Vulkan driver on which Dawn offers an adapter: { name, env, info, refused }, where
 * `refused` lists what each driver tried before it answered ({ name, said }); `name` is null when
 * none did. */
export function findDriver() {
  const refused = [];
  for (const candidate of candidates()) {
    const { info, said } = probe(candidate.env);
    if (info) return { ...candidate, info, refused };
    refused.push({ name: candidate.name, said: said || 'requestAdapter() answered null, and Dawn said nothing' });
  }
  return { name: null, env: {}, info: null, refused };
}

/** Makes this process look enough like a browser's for www/sunlit.js on Dawn's WebGPU through
 * `driver` (from findDriver); returns a function that takes it all away again (Node does not exit
 * while Dawn's GPU object is referenced). */
export async function installDawn(driver) {
  Object.assign(process.env, driver.env);
  const { create, globals } = await import('webgpu');
  Object.assign(globalThis, globals);
  const gpu = create([]);
  const navigator = { gpu, hardwareConcurrency: 1, userAgent: `Node.js ${process.version}` };
  Object.defineProperty(globalThis, 'navigator', { value: navigator, configurable: true, writable: true });
  const hadWindow = 'Window' in globalThis;
  if (!hadWindow) globalThis.Window = class Window {};
  const nodeFetch = globalThis.fetch;
  globalThis.fetch = async (input, init) => {
    const url = new URL(input instanceof Request ? input.url : String(input));
    if (url.protocol !== 'file:') return nodeFetch(input, init);
    const headers = url.pathname.endsWith('.wasm') ? { 'Content-Type': 'application/wasm' } : {};
    return new Response(await readFile(url), { headers });
  };
  return () => {
    globalThis.fetch = nodeFetch;
    if (!hadWindow) delete globalThis.Window;
    delete navigator.gpu;
    delete globalThis.navigator;
  };
}

/** What the Dawn tests and bench need built: the wasm bundle (scripts/build-web.sh). */
export function bundleMissing() {
  const wasm = join(ROOT, 'www/pkg/sunlit_wasm_bg.wasm');
  return existsSync(wasm) ? null : `${wasm} is missing: run scripts/build-web.sh first`;
}
