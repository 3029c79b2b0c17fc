// What the page's browser tests share: the page's status line awaited, a download saved and
// read, and the native CLI (the one `cargo test` built) run on the same model, its output read.
import { execFileSync } from 'node:child_process';
import { mkdirSync, readFileSync, rmSync } from 'node:fs';
import { join } from 'node:path';
import { fileURLToPath } from 'node:url';
import { serve } from '../../scripts/serve.mjs';
import { launch } from './chromium.mjs';

export const ROOT = fileURLToPath(new URL('../../', import.meta.url));

/** The page served on a free port in headless Chromium, downloads accepted, `work` and
 * target/artifacts made: { server, origin, browser, page, pageErrors } (the page not yet
 * opened: add init scripts, then `page.goto(origin + '/')`). */
export async function servePage(work) {
  mkdirSync(work, { recursive: true });
  mkdirSync(join(ROOT, 'target/artifacts'), { recursive: true });
  const server = await serve(0);
  const origin = `http://127.0.0.1:${server.address().port}`;
  const browser = await launch();
  const page = await (await browser.newContext({ acceptDownloads: true })).newPage();
  const pageErrors = [];
  page.on('pageerror', (e) => pageErrors.push(e.message));
  return { server, origin, browser, page, pageErrors };
}

/** [`servePage`] with the page opened and ready (its status line says so). */
export async function readyPage(work) {
  const served = await servePage(work);
  await served.page.goto(`${served.origin}/`);
  await waitForStatus(served.page, /^Ready/);
  return served;
}

/** Closes what [`servePage`] opened and removes `work`. */
export async function closePage(served, work) {
  await served?.browser?.close();
  served?.server?.close();
  rmSync(work, { recursive: true, force: true });
}

/** Waits until `page`'s status line matches `pattern`; its text. */
export async function waitForStatus(page, pattern, timeout = 120_000) {
  await page.waitForFunction((source) => new RegExp(source).test(document.getElementById('status').textContent), pattern.source, { timeout });
  return page.textContent('#status');
}

/** Clears the status line, does `action`, and waits for a status matching `pattern`. */
export async function statusAfter(page, action, pattern, timeout) {
  await page.evaluate(() => {
    document.getElementById('status').textContent = '';
  });
  await action();
  return waitForStatus(page, pattern, timeout);
}

/** Clicks `button` and saves the download as `file`: its suggested name and its text. */
export async function downloadText(page, button, file) {
  const download = page.waitForEvent('download');
  await page.click(button);
  await (await download).saveAs(file);
  return { name: (await download).suggestedFilename(), text: readFileSync(file, 'utf8') };
}

/** `sunlit ARGS…` with its scratch in `work` (stderr shown, stdout dropped), run in `cwd` (the
 * repository root unless given: a report states its files as they were named). */
export function sunlit(args, work, cwd = ROOT) {
  execFileSync(join(ROOT, 'target/debug/sunlit'), args, {
    cwd,
    stdio: ['ignore', 'ignore', 'inherit'],
    env: { ...process.env, XDG_RUNTIME_DIR: work },
  });
}

/** Moves the Map mode's day and time sliders to `day` (1..365) and `hour`, as a person would
 * (each fires its input event). */
export async function setMapSliders(page, day, hour) {
  await page.evaluate(([d, h]) => {
    for (const [id, v] of [['mapday', d], ['maptime', h]]) {
      const input = document.getElementById(id);
      input.value = String(v);
      input.dispatchEvent(new Event('input', { bubbles: true }));
    }
  }, [day, hour]);
}
