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

/** A worker's wasm memory per byte of what it is handed (the encoded scene and objects), once
 * it built its exact engine: 983 MB for nyt-blocks' 119 MB (8.2×; docs/page-speed.md, "Where
 * the memory goes"), rounded up. An estimate: the budget is checked before any worker builds. */
export const WORKER_BYTES_PER_BYTE = 8.5;

/** The default memory budget: the wasm memory the engine's instance and its clipping workers
 * may hold together once the pool has its model, chosen so that nyt-blocks' year stays within
 * 4 GB of Chromium (docs/page-speed.md). */
export const DEFAULT_MEMORY_BUDGET = 2.5e9;

/** How many of `asked` workers fit `budgetBytes` beside the engine's `engineBytes`, each copy
 * estimated from the bytes it is handed (`args`). 0 means none: the engine then clips alone. */
export function fit(asked, args, budgetBytes, engineBytes) {
  const handed = args.reduce((n, a) => n + (a?.byteLength ?? 0), 0);
  const workerBytes = WORKER_BYTES_PER_BYTE * handed;
  const room = workerBytes > 0 ? Math.floor((budgetBytes - engineBytes) / workerBytes) : asked;
  return { budgetBytes, engineBytes, workerBytes, asked, workers: Math.max(0, Math.min(asked, room)) };
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
  #sizing = null;
  #sized = null;
  /** Views clipped by this thread's clipper and by the workers (`clipped`). */
  #clipped = { here: 0, workers: 0 };
  /** This thread's clipper: its task queue, and whether a chunk is queued for it. */
  #tick = null;
  #localPending = false;

  /** `size` workers running `url` (default: clip-worker.js beside this module). */
  constructor(size, url = null) {
    this.#size = size;
    this.#url = url;
  }

  get size() {
    return Math.min(this.#size, this.#sizing?.workers ?? Infinity);
  }

  /** Views clipped so far by this thread's clipper (`here`) and by the workers (`workers`). */
  get clipped() {
    return { ...this.#clipped };
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
      this.#stopWorkers(error);
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
      const slot = { index, worker, busy: [], pending: null };
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
   * engine's encoded scene and its convex objects), or { kind, encode } where encode() gives the
   * args (sunlit.js encodes them in this thread at once, while the workers may still be
   * starting; they are copied to each worker, transferred to the last, and not kept here).
   * `budget` ({ bytes, used }: the wasm memory the engine's instance and the workers may hold
   * together, and a function giving what the engine's instance holds now) sizes the pool before
   * any worker builds: see [`fit`]. [`sized`] resolves once that is decided, before the workers
   * hold the model: a year need not wait for them (see [`clip`]). */
  use(source, budget = null) {
    if (this.#broken) return Promise.reject(this.#broken);
    if (source === this.#source && this.#loading) return this.#loading;
    this.#source = source;
    // Workers still starting fill their places in #workers as they become ready.
    for (const slot of this.#workers) if (slot) slot.loaded = false;
    const encoded = (async () => {
      const args = source.encode ? source.encode() : source.args;
      if (budget) this.#sizing = fit(this.#size, args, budget.bytes, await budget.used());
      return args;
    })();
    this.#sized = encoded.then(() => this.#sizing);
    this.#loading = encoded.then(async (args) => {
      await this.start();
      if (this.#sizing && source === this.#source) this.#shrink(this.#sizing);
      const last = this.#workers.length - 1;
      return Promise.all(
        this.#workers.map(
          (slot, i) =>
            new Promise((resolve, reject) => {
              slot.pending = { resolve, reject };
              const transfer = i === last ? args.filter((a) => ArrayBuffer.isView(a)).map((a) => a.buffer) : [];
              slot.worker.postMessage({ type: 'load', source: { kind: source.kind, args } }, transfer);
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

  /** The sizing of the model last handed to [`use`] (see [`sizing`]), once its bytes are encoded
   * and the budget applied: the workers may not hold it yet. */
  get sized() {
    return this.#sized ?? Promise.resolve(this.#sizing);
  }

  /** How the memory budget sized the pool at its last load: { budgetBytes, engineBytes,
   * workerBytes (the estimate for one worker's copy), workers (kept), asked }; null before a
   * load with a budget. */
  get sizing() {
    return this.#sizing;
  }

  /** Keeps the first `sizing.workers` workers and stops the others (their memory is freed);
   * says so on the console when it drops any. */
  #shrink(sizing) {
    if (sizing.workers >= this.#workers.length) return;
    const mb = (b) => Math.round(b / 1e6);
    console.info(
      `sunlit: ${sizing.workers} of ${sizing.asked} clipping workers: each copy of this model needs about ${mb(sizing.workerBytes)} MB, ` +
        `the engine holds ${mb(sizing.engineBytes)} MB, and the memory budget is ${mb(sizing.budgetBytes)} MB (createEngine's memoryBudget)`,
    );
    for (const slot of this.#workers.splice(sizing.workers)) slot.worker.terminate();
    this.#spawned = this.#workers.map((slot) => slot.worker);
    this.#size = sizing.workers;
  }

  /** The fractions of packed requests (Float64Array, PACKED numbers a view), in order. `local`
   * (optional): clips packed requests in this thread, with the engine's own copy of the model; it
   * then takes chunks from the same queue as the workers, one per task, so their replies are read
   * between its chunks, while it is [`#helps`]: until every worker holds the model (a first
   * visit's year starts at once instead of waiting for the workers to start and build their
   * copies; docs/page-speed.md, "The first visit"), and throughout where the budget kept fewer
   * workers than asked (the engine's instance, which holds the model anyway, is then one clipper
   * more). Without `local`, chunks wait for the workers. */
  async clip(packed, signal, local = null) {
    if (this.#broken) throw this.#broken;
    if (!local) await this.start();
    else this.start().catch(() => {}); // A pool that cannot start leaves the job to `local`.
    const views = packed.length / PACKED;
    const out = new Float64Array(views);
    const job = { id: ++this.#jobs, left: 0, out, local };
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

  /** Whether this thread's clipper takes `job`'s chunks now: while fewer workers hold the model
   * than the pool keeps (they are starting, or building their copies), and always where the
   * budget kept fewer workers than asked. */
  #helps(job) {
    if (!job?.local) return false;
    const holding = this.#workers.filter((slot) => slot.loaded).length;
    return holding < this.size || (this.#sizing !== null && this.#sizing.workers < this.#sizing.asked);
  }

  /** Hands queued chunks to idle workers that hold the model, and one to this thread's clipper
   * when it [`#helps`]. Where this thread clips too, each worker holds two chunks, so that it has
   * the next one while this thread is busy with its own and cannot read the worker's reply. */
  #deal() {
    const helps = this.#helps(this.#queue[0]?.job);
    const depth = helps ? 2 : 1;
    for (const slot of this.#workers) {
      // A worker takes chunks once it holds the pool's model (with no model handed, it answers
      // 'no-model').
      while (slot && (slot.loaded || this.#source === null) && slot.busy.length < depth && this.#queue.length) {
        const item = this.#queue.shift();
        slot.busy.push(item);
        slot.worker.postMessage({ type: 'clip', job: item.job.id, data: item.data }, [item.data.buffer]);
      }
    }
    if (this.#helps(this.#queue[0]?.job) && !this.#localPending) {
      this.#localPending = true;
      this.#tick ??= this.#ticker();
      this.#tick.port2.postMessage(0);
    }
  }

  /** A task queue for this thread's chunks: a message to itself runs after the workers' replies
   * already queued, without a timer's clamping. */
  #ticker() {
    const channel = new MessageChannel();
    channel.port1.onmessage = () => this.#clipHere();
    return channel;
  }

  /** Clips the next queued chunk in this thread. */
  #clipHere() {
    this.#localPending = false;
    const item = this.#helps(this.#queue[0]?.job) ? this.#queue.shift() : null;
    if (!item) return;
    try {
      item.job.out.set(item.job.local(item.data), item.start);
      this.#clipped.here += item.data.length / PACKED;
      if (--item.job.left === 0) this.#finish(item.job, null);
    } catch (error) {
      this.#drop(item.job, coded(`clipping in the engine's thread failed: ${error?.message ?? error}`, error?.code ?? 'worker'));
    }
    this.#deal();
  }

  #reply(slot, data) {
    if (data.type === 'loaded' || data.type === 'loadError') {
      const pending = slot.pending;
      slot.pending = null;
      if (data.type === 'loaded') {
        slot.wasmBytes = data.wasmBytes;
        slot.loaded = true;
        pending?.resolve();
        this.#deal();
      }
      else {
        // A worker that cannot build the model fails the pool: a year that went on in this
        // thread meanwhile is rejected with its error rather than finished without it.
        const error = Object.assign(new Error(data.message), { code: data.code, worker: slot.index });
        pending?.reject(error);
        this.#fail(slot, error);
      }
      return;
    }
    const item = slot.busy.shift();
    if (data.type === 'clipped' && item && item.job.id === data.job && !item.job.finished) {
      item.job.out.set(data.fractions, item.start);
      this.#clipped.workers += data.fractions.length;
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
    for (const s of this.#workers) s?.busy.forEach((item) => jobs.add(item.job));
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
    // With nothing queued this thread's task queue is closed (the next chunk opens a new one):
    // an open port keeps Node's event loop alive, and a pool whose workers could not start is
    // dropped by the engine without `terminate`, so the Node/Dawn test hung after its year.
    if (this.#queue.length === 0) this.#closeTick();
  }

  #closeTick() {
    this.#tick?.port1.close();
    this.#tick = null;
    this.#localPending = false;
  }

  /** The workers could not start (`error`): they are stopped; jobs this thread clips go on, the
   * others fail with `error`. */
  #stopWorkers(error) {
    for (const worker of this.#spawned) worker.terminate();
    this.#spawned = [];
    this.#workers = [];
    this.#source = null;
    this.#loading = null;
    // #started stays rejected: the pool does not start again (a new engine call makes a new one).
    for (const job of new Set(this.#queue.map((q) => q.job))) if (!job.local) this.#drop(job, error);
    this.#deal();
  }

  /** Stops every worker (their memory is freed). */
  terminate() {
    for (const worker of this.#spawned) worker.terminate();
    this.#closeTick();
    this.#spawned = [];
    this.#workers = [];
    this.#source = null;
    this.#loading = null;
    this.#started = this.#broken ? Promise.reject(this.#broken) : null;
    this.#started?.catch(() => {});
  }
}
