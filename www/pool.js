// The pool of clipping workers: the exact engine on every core of the page's machine.
//
// Design: each worker (clip-worker.js) runs its own wasm instance with its own copy of the
// model's exact engine. The alternative, wasm threads sharing one memory, needs atomics in the
// standard library (a nightly Rust with build-std) and a cross-origin-isolated page (COOP/COEP
// headers) that an embedding viewer may not be able to send; separate instances need neither, and
// a failing worker cannot corrupt the others' memory. The cost is memory: every worker holds the
// model's exact engine (for a 1.3M-triangle model a few hundred MB each, each in its own 4 GiB
// wasm32 address space); docs/page-speed.md has the figures.
//
// Views are dealt out in chunks to whichever worker is free, and each view's fraction depends only
// on the view and the model, so the answers are the same whatever the pool's size (the tests
// compare CSVs byte for byte). Errors carry `code: 'worker'`, the failing `worker`'s index and the
// code the worker gave (`workerCode`), or `code: 'cancelled'` after an abort.

/** Views a worker is handed at a time: small enough to balance, large enough to cost little. */
const CHUNK = 32;
/** Numbers per packed request (receiver, sun x, y, z, leaf fraction); see src/web/choice.rs. */
const PACKED = 5;

/** The wasm, compiled once per page: this thread's instance and every worker's are made from
 * the same `WebAssembly.Module` (it is posted to them), so a first visit compiles and tiers up
 * the code once, not once per instance (docs/page-speed.md, "The first visit"). */
let compiled;

/** The wasm's `WebAssembly.Module`, compiled once (streaming where the server sends
 * `application/wasm`, from the bytes otherwise); later calls share it. */
export function wasmModule() {
  compiled ??= (async () => {
    const url = new URL('./pkg/sunlit_wasm_bg.wasm', import.meta.url);
    const response = await fetch(url);
    if (!response.ok) throw new Error(`${url}: ${response.status} ${response.statusText}`);
    const streams = typeof WebAssembly.compileStreaming === 'function' && response.headers.get('Content-Type') === 'application/wasm';
    return streams ? WebAssembly.compileStreaming(response) : WebAssembly.compile(await response.arrayBuffer());
  })();
  return compiled;
}

function coded(message, code, names = {}) {
  return Object.assign(new Error(message), { code }, names);
}

/** The default pool size: every core the browser reports. */
export function defaultWorkers() {
  const n = globalThis.navigator?.hardwareConcurrency;
  return Number.isInteger(n) && n > 0 ? n : 1;
}

export class ClipPool {
  #url;
  #size;
  #workers = [];
  /** Every worker spawned, ready or not: the pool starts with its engine, so it may be closed
   * before its workers are ready. */
  #spawned = [];
  #started = null;
  #source = null;
  #loading = null;
  #queue = [];
  #jobs = 0;
  #broken = null;

  /** `size` workers running `url` (default: clip-worker.js beside this module). */
  constructor(size, url = null) {
    this.#size = size;
    this.#url = url;
  }

  get size() {
    return this.#size;
  }

  /** Each worker's wasm memory in bytes once it built the pool's model (its load's peak: wasm
   * memory never shrinks); undefined before. */
  get memoryBytes() {
    return this.#workers.map((slot) => slot?.wasmBytes);
  }

  /** The error that closed the pool (one worker failed), or null. */
  get broken() {
    return this.#broken;
  }

  /** Starts the workers once; rejects naming the worker that could not start (a CSP, a missing
   * module), after which the pool is closed. */
  start() {
    this.#started ??= Promise.all(Array.from({ length: this.#size }, (_, i) => this.#spawn(i))).catch((error) => {
      this.terminate();
      throw error;
    });
    return this.#started;
  }

  #spawn(index) {
    return new Promise((resolve, reject) => {
      let worker;
      try {
        // Written out for the default so that bundlers (Vite, webpack) see and bundle the worker.
        worker = this.#url
          ? new Worker(this.#url, { type: 'module' })
          : new Worker(new URL('./clip-worker.js', import.meta.url), { type: 'module' });
      } catch (error) {
        reject(coded(`clipping worker ${index} could not start: ${error?.message ?? error}`, 'worker', { worker: index, workerCode: 'start' }));
        return;
      }
      this.#spawned.push(worker);
      const slot = { index, worker, busy: null, pending: null };
      worker.onerror = (event) => {
        event.preventDefault?.();
        const error = coded(`clipping worker ${index} failed: ${event.message || 'it could not load its module'}`, 'worker', {
          worker: index,
          workerCode: 'start',
        });
        if (!slot.ready) reject(error);
        else this.#fail(slot, error);
      };
      // The worker starts its instance from this page's compiled module; where it has none (the
      // compile failed here), it fetches and compiles the wasm itself.
      wasmModule().then(
        (module) => worker.postMessage({ type: 'init', module }),
        () => worker.postMessage({ type: 'init', module: null }),
      );
      worker.onmessage = ({ data }) => {
        if (data.type === 'ready') {
          slot.ready = true;
          this.#workers[index] = slot;
          resolve();
        } else this.#reply(slot, data);
      };
    });
  }

  /** Makes `source` the pool's model; resolves when every worker holds it. The same source twice
   * loads once. `source`: { kind, args } (clip-worker.js's one kind, 'scene', takes the
   * engine's encoded scene), or { kind, encode } where encode() gives the args once the workers have started (sunlit.js encodes the
   * scene then; the encoding is copied to each worker and not kept here). */
  use(source) {
    if (this.#broken) return Promise.reject(this.#broken);
    if (source === this.#source && this.#loading) return this.#loading;
    this.#source = source;
    this.#loading = this.start().then(() => {
      const message = { type: 'load', source: source.encode ? { kind: source.kind, args: source.encode() } : source };
      return Promise.all(
        this.#workers.map(
          (slot) =>
            new Promise((resolve, reject) => {
              slot.pending = { resolve, reject };
              slot.worker.postMessage(message);
            }),
        ),
      );
    });
    this.#loading.catch(() => {
      this.#source = null;
      this.#loading = null;
    });
    return this.#loading;
  }

  /** The fractions of packed requests (Float64Array, PACKED numbers a view), in order. */
  async clip(packed, signal) {
    await this.start();
    if (this.#broken) throw this.#broken;
    const views = packed.length / PACKED;
    const out = new Float64Array(views);
    const job = { id: ++this.#jobs, left: 0, out };
    return new Promise((resolve, reject) => {
      Object.assign(job, { resolve, reject });
      for (let start = 0; start < views; start += CHUNK) {
        const count = Math.min(CHUNK, views - start);
        this.#queue.push({ job, start, data: packed.slice(start * PACKED, (start + count) * PACKED) });
        job.left++;
      }
      if (job.left === 0) return resolve(out);
      const abort = () => this.#drop(job, coded('cancelled', 'cancelled'));
      if (signal?.aborted) return abort();
      signal?.addEventListener('abort', abort, { once: true });
      job.done = () => signal?.removeEventListener('abort', abort);
      this.#deal();
    });
  }

  /** Hands queued chunks to idle workers. */
  #deal() {
    for (const slot of this.#workers) {
      if (slot.busy || !this.#queue.length) continue;
      const item = this.#queue.shift();
      slot.busy = item;
      slot.worker.postMessage({ type: 'clip', job: item.job.id, data: item.data }, [item.data.buffer]);
    }
  }

  #reply(slot, data) {
    if (data.type === 'loaded' || data.type === 'loadError') {
      const pending = slot.pending;
      slot.pending = null;
      if (data.type === 'loaded') {
        slot.wasmBytes = data.wasmBytes;
        pending?.resolve();
      }
      else pending?.reject(Object.assign(new Error(data.message), { code: data.code, worker: slot.index }));
      return;
    }
    const item = slot.busy;
    slot.busy = null;
    if (data.type === 'clipped' && item && item.job.id === data.job && !item.job.finished) {
      item.job.out.set(data.fractions, item.start);
      if (--item.job.left === 0) this.#finish(item.job, null);
    } else if (data.type === 'clipError' && item && !item.job.finished) {
      const error = coded(`clipping worker ${slot.index} failed: ${data.message}`, 'worker', { worker: slot.index, workerCode: data.code });
      this.#drop(item.job, error);
      this.#fail(slot, error);
      return;
    }
    this.#deal();
  }

  /** One worker failed: its job fails with its error, and the pool is closed (the next engine
   * call that needs it reports the same error; a new engine makes a new pool). */
  #fail(slot, error) {
    this.#broken = error;
    slot.pending?.reject(error);
    const jobs = new Set(this.#queue.map((q) => q.job));
    for (const s of this.#workers) if (s.busy) jobs.add(s.busy.job);
    for (const job of jobs) this.#drop(job, error);
    this.terminate();
  }

  #drop(job, error) {
    this.#queue = this.#queue.filter((q) => q.job !== job);
    this.#finish(job, error);
  }

  #finish(job, error) {
    if (job.finished) return;
    job.finished = true;
    job.done?.();
    if (error) job.reject(error);
    else job.resolve(job.out);
  }

  /** Stops every worker (their memory is freed). */
  terminate() {
    for (const worker of this.#spawned) worker.terminate();
    this.#spawned = [];
    this.#workers = [];
    this.#source = null;
    this.#loading = null;
    this.#started = this.#broken ? Promise.reject(this.#broken) : null;
    this.#started?.catch(() => {});
  }
}
