// The page's cache of `auto` profiles: IndexedDB (database 'sunlit', store 'engine-profiles'),
// keyed like the native cache file (adapter, driver, clipping threads, side, scene size; see
// src/count/hybrid.rs). A profile is measured once per adapter and model size and reused after.
// Where IndexedDB is missing or refuses (a private window, a worker without it), nothing is kept
// and the next run measures again: a cache that cannot be used costs only a probe.
const DB = 'sunlit';
const STORE = 'engine-profiles';

/** The page's one connection to the store, opened once and kept (a first visit's year waited
 * 25-53 ms for each fresh open of a new profile's database, measured in headless Chromium on the
 * shared VM; docs/page-speed.md), or null before the first use and after it failed or was closed. */
let connection = null;

function open() {
  if (connection) return connection;
  const opening = new Promise((resolve, reject) => {
    const request = indexedDB.open(DB, 1);
    request.onupgradeneeded = () => request.result.createObjectStore(STORE);
    request.onsuccess = () => {
      const db = request.result;
      // Another page asking for a newer version (none does today) gets the database: this page
      // opens it again when it next needs it.
      const forget = () => {
        if (connection === opening) connection = null;
      };
      db.onversionchange = () => {
        db.close();
        forget();
      };
      db.onclose = forget;
      resolve(db);
    };
    request.onerror = () => reject(request.error);
  });
  connection = opening;
  opening.catch(() => {
    if (connection === opening) connection = null;
  });
  return opening;
}

/** Opens the store now (createEngine calls it while the wasm compiles), so that the first
 * year's look-up does not wait for the database to be made; a store that cannot be opened is
 * said by nothing, as a cache that cannot be used costs only a probe. */
export function warmProfiles() {
  if (typeof indexedDB === 'undefined') return;
  open().catch(() => {});
}

async function transact(mode, job) {
  if (typeof indexedDB === 'undefined') return undefined;
  try {
    const db = await open();
    return await new Promise((resolve, reject) => {
      const request = job(db.transaction(STORE, mode).objectStore(STORE));
      request.onsuccess = () => resolve(request.result);
      request.onerror = () => reject(request.error);
    });
  } catch {
    return undefined;
  }
}

/** The profile's JSON text kept under `key`, or undefined. */
export function cachedProfile(key) {
  return transact('readonly', (store) => store.get(key));
}

/** Keeps `text` under `key` (silently not, where IndexedDB is unusable). */
export function storeProfile(key, text) {
  return transact('readwrite', (store) => store.put(text, key));
}
