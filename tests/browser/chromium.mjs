// Headless Debian Chromium with WebGPU on its bundled SwiftShader (../shared/notes/gpu.md), for
// the page tests. The same flags are in webdriver.json for wasm-bindgen-test-runner.
import { readFileSync } from 'node:fs';
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
