// The page's cache of `auto` profiles: IndexedDB (database 'sunlit', store 'engine-profiles'),
// keyed like the native cache file (adapter, driver, clipping threads, side, scene size; see
// src/count/hybrid.rs). A profile is measured once per adapter and model size and reused after.
// Where IndexedDB is missing or refuses (a private window, a worker without it), nothing is kept
// and the next run measures again: a cache that cannot be used costs only a probe.
const DB = 'sunlit';
const STORE = 'engine-profiles';

function open() {
  return new Promise((resolve, reject) => {
    const request = indexedDB.open(DB, 1);
    request.onupgradeneeded = () => request.result.createObjectStore(STORE);
    request.onsuccess = () => resolve(request.result);
    request.onerror = () => reject(request.error);
  });
}

async function transact(mode, job) {
  if (typeof indexedDB === 'undefined') return undefined;
  try {
    const db = await open();
    try {
      return await new Promise((resolve, reject) => {
        const request = job(db.transaction(STORE, mode).objectStore(STORE));
        request.onsuccess = () => resolve(request.result);
        request.onerror = () => reject(request.error);
      });
    } finally {
      db.close();
    }
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
