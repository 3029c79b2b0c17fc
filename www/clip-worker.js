// One worker of the clipping pool (pool.js): its own wasm instance, holding one model's exact
// engine (a Clipper), answering chunks of packed views. Messages in: init { module } (the page's
// compiled WebAssembly.Module, or null to fetch the wasm here), load { source }, clip
// { job, data }. Out: ready, loaded { wasmBytes }, loadError { message, code }, clipped { job,
// fractions }, clipError { job, message, code }. `wasmBytes`: this instance's wasm memory once the
// model is built (it never shrinks, so it is the load's peak).
import init, { Clipper } from './pkg/sunlit_wasm.js';

let clipper = null;
let memory = null;

/** A Clipper from the engine's encoded scene and convex objects (what sunlit.js sends). */
function build({ kind, args }) {
  if (kind === 'scene') return Clipper.fromScene(...args);
  throw Object.assign(new Error(`unknown model source '${kind}'`), { code: 'bad-option' });
}

function failure(error) {
  // A trap (out of memory, a bug) has no code; name it so the page can say what happened.
  const code = error?.code ?? (error instanceof WebAssembly.RuntimeError ? 'wasm-trap' : 'worker');
  return { message: String(error?.message ?? error), code };
}

onmessage = ({ data }) => {
  if (data.type === 'init') start(data.module);
  else if (data.type === 'load') {
    try {
      clipper?.free();
      clipper = null;
      clipper = build(data.source);
      postMessage({ type: 'loaded', wasmBytes: memory?.buffer.byteLength });
    } catch (error) {
      postMessage({ type: 'loadError', ...failure(error) });
    }
  } else if (data.type === 'clip') {
    try {
      if (!clipper) throw Object.assign(new Error('no model loaded'), { code: 'no-model' });
      const fractions = clipper.fractions(data.data);
      postMessage({ type: 'clipped', job: data.job, fractions }, [fractions.buffer]);
    } catch (error) {
      postMessage({ type: 'clipError', job: data.job, ...failure(error) });
    }
  }
};

// No top-level await: bundlers build workers as classic scripts by default (Vite's 'iife'), where
// it is a syntax error. A wasm that cannot start is thrown from a task of its own, so the pool
// sees it as the worker's error event, as it would a module that cannot load.
function start(module) {
  init({ module_or_path: module ?? new URL('./pkg/sunlit_wasm_bg.wasm', import.meta.url) }).then(
    (exports) => {
      memory = exports.memory;
      postMessage({ type: 'ready' });
    },
    (error) => setTimeout(() => { throw error; }),
  );
}
