// The page's store of `auto` profiles (www/profiles.js, IndexedDB database 'sunlit') in headless
// Chromium: one connection a page, opened once and kept, so that a first visit's year does not
// wait for the database to be opened again at each look-up (docs/page-speed.md, "The first
// visit"); and a page that holds it still lets another delete the database, and then opens a
// fresh one. No wasm: the store is plain JavaScript.
import assert from 'node:assert/strict';
import { after, before, test } from 'node:test';
import { serve } from '../../scripts/serve.mjs';
import { launch } from './chromium.mjs';

let server;
let browser;

before(async () => {
  server = await serve(0);
  browser = await launch({ webgpu: false });
});

after(async () => {
  await browser?.close();
  server?.close();
});

/** A fresh page that counts its calls of indexedDB.open (`globalThis.opens`). */
async function countingPage() {
  const page = await browser.newPage();
  await page.addInitScript(() => {
    globalThis.opens = 0;
    const open = indexedDB.open.bind(indexedDB);
    indexedDB.open = (...args) => {
      globalThis.opens++;
      return open(...args);
    };
  });
  await page.goto(`http://127.0.0.1:${server.address().port}/api-example.html`);
  return page;
}

test('the profiles store opens once a page, warmed or not, and keeps what it stores', async () => {
  const page = await countingPage();
  const seen = await page.evaluate(async () => {
    const { cachedProfile, storeProfile, warmProfiles } = await import('/profiles.js');
    warmProfiles();
    const before = await Promise.all([cachedProfile('sun key'), cachedProfile('sky key')]);
    await storeProfile('sun key', '{"device":"sun key"}');
    const after = await cachedProfile('sun key');
    warmProfiles();
    const sky = await cachedProfile('sky key');
    return { before, after, sky, opens: globalThis.opens };
  });
  assert.deepEqual(seen.before, [undefined, undefined]);
  assert.equal(seen.after, '{"device":"sun key"}');
  assert.equal(seen.sky, undefined);
  assert.equal(seen.opens, 1, 'one indexedDB.open for the warm-up, two look-ups, a store and two more');
  await page.close();
});

test('a page holding the store lets another delete it, then opens a fresh one', async () => {
  const page = await countingPage();
  const seen = await page.evaluate(async () => {
    const { cachedProfile, storeProfile } = await import('/profiles.js');
    await storeProfile('k', 'kept');
    const kept = await cachedProfile('k');
    // Deleting waits for every open connection to close: a kept one must give way.
    const deleted = await new Promise((resolve) => {
      const request = indexedDB.deleteDatabase('sunlit');
      request.onsuccess = () => resolve('deleted');
      request.onblocked = () => setTimeout(() => resolve('blocked'), 2000);
      request.onerror = () => resolve('error');
    });
    const afterDelete = await cachedProfile('k');
    return { kept, deleted, afterDelete, opens: globalThis.opens };
  });
  assert.equal(seen.kept, 'kept');
  assert.equal(seen.deleted, 'deleted');
  assert.equal(seen.afterDelete, undefined, 'the deleted store is made afresh, empty');
  assert.equal(seen.opens, 2);
  await page.close();
});
