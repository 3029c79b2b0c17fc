// The page: collects files and settings, talks to the worker (worker.js) that runs the engine,
// and shows the results (3D view, table, heat map, downloads). All work stays on this machine.
import { colourOf, UNCOMPUTED } from './colour.js';
import { checkModelSize } from './sunlit.js';
import { drawHeatmap } from './heatmap.js';
import { mapMode } from './mapmode.js';
import { studyMode } from './studymode.js';
import { Viewer } from './viewer.js';

const $ = (id) => document.getElementById(id);
const state = { files: null, reading: null, model: null, result: null, viewer: null, selected: -1, busy: false, csvName: 'sunlit-shading.csv', modelName: '', colourBy: 'mean' };
/** A model's parts that are not models themselves: a .gltf's buffers and textures. */
const MODEL_PARTS = /\.(bin|png|jpe?g|webp|ktx2)$/i;
const worker = new Worker(new URL('./worker.js', import.meta.url), { type: 'module' });

function status(text, { error = false } = {}) {
  $('status').textContent = text;
  $('status').classList.toggle('error', error);
}

/** The form's site as map and study options take it: the EPW, or the three numbers. */
async function site() {
  const { latitude, longitude, timeZone, epw, epwName } = await settings();
  return epw ? { epw, epwName } : { latitude, longitude, timeZone };
}

/** What the Map and Study modes share of the page. */
const modeHooks = {
  $,
  worker,
  status: (text) => status(text),
  location: () => site(),
  skyModel: () => $('skymodel').value,
  engineOptions: () => engineOptions(),
  setBusy: (busy) => setBusy(busy),
  download: (...args) => download(...args),
  modelName: () => state.modelName,
};

const maps = mapMode({
  ...modeHooks,
  viewer: () => state.viewer,
  showLegend: (scale) => showLegend(scale ?? colourScale()),
  busy: () => state.busy,
});

const studies = studyMode({
  ...modeHooks,
  // The view paints receivers: it needs the model even before a year was coloured.
  viewer: () => {
    const { viewer, model } = state;
    if (viewer && model && viewer.positions !== model.positions) viewer.setModel(model.positions, model.receivers);
    return viewer;
  },
  showLegend: (scale) => showLegend(scale),
  names: () => state.model?.names ?? [],
  // The model's own files, as the CLI is given them (a .gltf's .bin and textures are found by it).
  modelFiles: () => (state.files ?? []).map((f) => f.name).filter((n) => !MODEL_PARTS.test(n)),
  readFiles: (list) => readChosen(list),
});

function setBusy(busy) {
  state.busy = busy;
  $('compute').disabled = busy || !state.model;
  $('cancel').disabled = !busy;
  for (const id of ['model', 'example', 'epw']) $(id).disabled = busy;
}

/** What the worker's engine is made with: a change of either makes a new engine. */
function engineOptions() {
  const r = Number($('resolution').value);
  return { resolution: Number.isInteger(r) && r >= 16 && r <= 2048 ? r : 512, engine: $('engine').value };
}

async function readFiles(list) {
  return Promise.all([...list].map(async (f) => ({ name: f.name, bytes: new Uint8Array(await f.arrayBuffer()) })));
}

/** Chosen or dropped files, refused by their size before they are read (a model too large for
 * the page's memory), else read. Returns null after saying why. */
async function readChosen(list) {
  const chosen = [...list];
  try {
    checkModelSize(chosen.map((f) => f.name), chosen.reduce((sum, f) => sum + f.size, 0));
  } catch (error) {
    // The last good model and its result stay as they are.
    status(`Could not read the model: ${error.message.replace(/\.$/, '')}.`, { error: true });
    return null;
  }
  return readFiles(chosen);
}

/** Sends files to the worker; they become the page's model (its name, its CSV's name) only once
 * the worker has read them, so a file that cannot be read leaves the last good model in place. */
async function loadFiles(files) {
  if (!files?.length) return;
  if (state.busy) return status('Could not read the model while computing: cancel first.', { error: true });
  const modelName = files.map((f) => f.name).join(', ');
  const main = files.find((f) => !MODEL_PARTS.test(f.name)) ?? files[0];
  const base = main.name.replace(/\.[^.]*$/, '');
  state.reading = { files, modelName, csvName: `${base}-shading.csv` };
  status(`Reading ${modelName}…`);
  $('compute').disabled = true;
  const options = { receivers: $('receivers').value, north: 0, foliage: $('foliage').value, transmittance: $('transmittance').value };
  worker.postMessage({ type: 'load', files, options, engine: engineOptions() });
}

function showModel(msg) {
  Object.assign(state, state.reading ?? {});
  state.reading = null;
  state.model = msg;
  state.result = null;
  state.selected = -1;
  const extras = [msg.leaves ? `${msg.leaves.toLocaleString()} leaves` : '', msg.seeThrough ? `${msg.seeThrough.toLocaleString()} see-through triangles` : '']
    .filter(Boolean)
    .map((t) => `, ${t}`)
    .join('');
  $('modelinfo').textContent = `${state.modelName}: ${msg.names.length} receiving surfaces, ${msg.triangles.toLocaleString()} triangles${extras}`;
  $('download').disabled = true;
  $('downloadidf').hidden = !msg.hasEnergyPlus;
  // The CSV must have the EnergyPlus model's Timestep to be hooked in.
  if (msg.modelTimesteps) $('timesteps').value = String(msg.modelTimesteps);
  $('downloadidf').disabled = true;
  $('heatfigure').hidden = true;
  fillTable(null);
  maps.reset();
  studies.reset(msg.names);
  showInViewer();
  const n = msg.names.length;
  // An EnergyPlus model's own Site:Location is its location (an EPW, if chosen, still wins).
  let where = 'Set the location';
  if (msg.siteLocation) {
    [$('latitude').value, $('longitude').value, $('timezone').value] = msg.siteLocation.map(String);
    where = `Location from the model's Site:Location (${msg.siteLocation.join(', ')}); change it or choose an EPW if needed`;
  }
  // Notes: what loading chose that the user should know (e.g. many receivers by the default rule).
  const notes = msg.notes?.length ? ` Note: ${msg.notes.join(' ')}` : '';
  status(`Loaded ${state.modelName} (${n} receiver${n === 1 ? '' : 's'}) on ${msg.adapter}. ${where}, and press Compute.${notes}`);
}

/** The model in the 3D view, coloured by the result when there is one. The viewer may start
 * after the model arrives, so it is also called once the viewer exists. */
function showInViewer() {
  // The Study mode colours the windows by their verdicts, with its own legend.
  if (studies.active()) return studies.recolour();
  showLegend(colourScale());
  paintReceivers();
}

/** The receivers coloured by the year's result (uncomputed without one). */
function paintReceivers() {
  const { viewer, model, result } = state;
  if (!viewer || !model) return;
  const scale = colourScale();
  if (viewer.positions !== model.positions) viewer.setModel(model.positions, model.receivers);
  viewer.setColours(result ? (r) => colourOf(scale.values[r] / scale.max) : () => UNCOMPUTED);
}

/** What the view is coloured by: the result's values per receiver, the top of the scale, and
 * the legend's title and tick format. Irradiation only when the year had an EPW. */
function colourScale() {
  const { result } = state;
  if (state.colourBy === 'irradiation' && result?.total) {
    // The palette's top is the most irradiated surface (at least 1 kWh/m², so a dark year draws).
    const max = Math.max(1, ...result.total);
    return { values: result.total, max, title: 'Annual total irradiation, kWh/m² (beam + sky + ground, shaded)', tick: (v) => v.toFixed(0) };
  }
  return { values: result?.means ?? [], max: 1, title: 'Annual mean sunlit fraction (sun-up hours)', tick: (v) => String(v) };
}

function showLegend({ max, title, tick }) {
  $('legendtitle').textContent = title;
  const ticks = [0, 0.25, 0.5, 0.75, 1].map((t) => {
    const span = document.createElement('span');
    span.textContent = tick(t * max);
    return span;
  });
  $('legendticks').replaceChildren(...ticks);
}

function fillTable(result) {
  const body = $('table').tBodies[0];
  body.replaceChildren();
  const { names, areas } = state.model;
  const means = result?.means;
  const irradiation = result?.irradiation;
  for (const th of $('table').tHead.querySelectorAll('.irr')) th.hidden = !irradiation;
  names.forEach((name, i) => {
    const row = body.insertRow();
    row.tabIndex = 0;
    row.dataset.index = i;
    // textContent, never innerHTML: names come from the user's file.
    row.insertCell().textContent = name;
    const area = row.insertCell();
    area.textContent = areas[i].toFixed(2);
    area.className = 'num';
    const mean = row.insertCell();
    mean.textContent = means ? means[i].toFixed(3) : '–';
    mean.className = 'num';
    if (irradiation) {
      for (const values of [irradiation, result.unshaded, result.skyDiffuse, result.groundReflected, result.total]) {
        const cell = row.insertCell();
        cell.textContent = values[i].toFixed(1);
        cell.className = 'num';
      }
    }
    if (i === state.selected) row.classList.add('selected');
  });
}

function selectReceiver(index) {
  if (!state.result || index < 0) return;
  state.selected = index;
  for (const row of $('table').tBodies[0].rows) row.classList.toggle('selected', Number(row.dataset.index) === index);
  const { values, rows, timestepsPerHour, names } = state.result;
  drawHeatmap($('heatmap'), values.subarray(index * rows, (index + 1) * rows), timestepsPerHour);
  $('heatcaption').textContent = `${names[index]}: sunlit fraction by day of year (across) and time of day (down, standard time).`;
  $('heatfigure').hidden = false;
}

function showResult(msg) {
  state.result = msg;
  setBusy(false);
  $('progress').value = 1;
  fillTable(msg);
  const irradiation = $('colourby').querySelector('[value=irradiation]');
  irradiation.disabled = !msg.irradiation;
  if (!msg.irradiation) $('colourby').value = state.colourBy = 'mean';
  showInViewer();
  $('download').disabled = false;
  $('downloadidf').disabled = !msg.hooked;
  $('downloadidf').title = msg.hookError ?? '';
  selectReceiver(state.selected >= 0 ? state.selected : 0);
  showRouting(msg);
  // An EPW whose hourly records cannot be read still gives fractions; say why there is no energy.
  const weather = msg.irradiationError ? ` No irradiation: ${msg.irradiationError}.` : '';
  // A model that cannot be hooked (e.g. too old a Version) still gets its CSV; say why no IDF.
  const hook = msg.hookError ? ` No hooked model: ${msg.hookError}.` : '';
  status(`Done in ${msg.seconds.toFixed(1)} s: ${msg.names.length} surfaces × ${msg.rows.toLocaleString()} timesteps.${weather}${hook}`, { error: !!(weather || hook) });
}

function showError(msg) {
  // A download of the map's files failing leaves the map (and any map in flight) as it is.
  if (msg.request === 'mapFile') return status(`Could not download the map: ${msg.message}.`, { error: true });
  maps.failed();
  if (msg.request === 'study') studies.failed();
  if (msg.request === 'loadBefore') {
    studies.beforeFailed(String(msg.message));
    return status(`Could not read the existing scene: ${String(msg.message).replace(/\.$/, '')}.`, { error: true });
  }
  if (msg.request === 'load') {
    // The files were not read: the last good model (if any) stays, and Compute with it.
    state.reading = null;
  }
  setBusy(false);
  $('progress').value = 0;
  if (msg.cancelled) return status('Cancelled.');
  $('retry').hidden = !msg.gpu;
  const what = { load: 'Could not read the model', map: 'Could not map', study: 'Could not run the study' }[msg.request] ?? 'Could not compute';
  const hint = msg.gpu ? ' The GPU device was lost or failed; press Retry to start a new one.' : '';
  status(`${what}: ${String(msg.message).replace(/\.$/, '')}.${hint}`, { error: true });
}

worker.onmessage = ({ data: msg }) => {
  if (msg.type === 'ready') {
    worker.postMessage({ type: 'warm', engine: engineOptions() });
    if (!msg.webgpu) noWebGPU();
    else status('Ready. Choose a model, drop one here, or load the example.');
    $('compute').disabled = !state.model || state.busy;
  } else if (msg.type === 'loaded') {
    showModel(msg);
    setBusy(state.busy);
  } else if (msg.type === 'progress') {
    $('progress').max = msg.total || 1;
    $('progress').value = msg.done;
    // A year's timesteps the spline interpolates are decided without counting: say how many views were counted.
    const counted = msg.counted !== undefined && msg.counted !== msg.done ? ` decided (${msg.counted.toLocaleString()} counted)` : '';
    status(`Counting views: ${msg.done.toLocaleString()} of ${msg.total.toLocaleString()}${counted}`);
  } else if (msg.type === 'loading') {
    showLoading(msg);
  } else if (msg.type === 'notice') {
    status(msg.text);
  } else if (msg.type === 'result') {
    showResult(msg);
  } else if (msg.type === 'mapResult') {
    maps.shown(msg);
  } else if (msg.type === 'mapFile') {
    maps.fileArrived(msg);
  } else if (msg.type === 'studyResult') {
    studies.shown(msg);
  } else if (msg.type === 'beforeLoaded') {
    studies.beforeLoaded(msg);
    status('Existing scene read: the next study compares each window with it.');
  } else if (msg.type === 'epwLocation') {
    showEpwLocation(msg);
  } else if (msg.type === 'error') {
    showError(msg);
  }
};
worker.onerror = (e) => showError({ message: e.message || 'the worker failed to start', request: 'start' });

/** The EPW's own location in the form (the EPW is what the year uses); the fields are read-only
 * while it is chosen. A bad LOCATION record is said under the fields (Compute says it again in
 * the status line, which this leaves alone). */
function showEpwLocation({ name, location, message }) {
  if ($('epw').files[0]?.name !== name) return;
  $('locationnote').classList.toggle('error', !location);
  if (!location) {
    $('locationnote').textContent = `${name}: ${message}.`;
    return;
  }
  [$('latitude').value, $('longitude').value, $('timezone').value] = [location.latitude, location.longitude, location.timeZone].map(String);
  $('locationnote').textContent = `From ${name}: ${location.name || 'its LOCATION record'}. Clear the EPW to edit.`;
}

function epwChosen() {
  const file = $('epw').files[0];
  for (const id of ['latitude', 'longitude', 'timezone']) $(id).readOnly = !!file;
  if (!file) {
    $('locationnote').classList.remove('error');
    $('locationnote').textContent = 'An EPW, when given, sets all three.';
    return;
  }
  file.text().then((text) => worker.postMessage({ type: 'epw', name: file.name, text }));
}

function noWebGPU() {
  const box = $('nowebgpu');
  box.hidden = false;
  box.textContent =
    'This browser offers no WebGPU, so only the GPU engine is missing: every view is clipped exactly on the CPU (slower on heavy models). For the GPU engine use a current Chrome or Edge (or enable WebGPU in your browser\'s settings).';
  status('Ready without WebGPU (views are clipped). Choose a model, drop one here, or load the example.');
}

/** A large model's loading, stage by stage: parsing in the engine's worker, then the clipping
 * workers building their copies. */
function showLoading({ stage, bytes, workers, poolError }) {
  if (stage === 'parse') status(`Reading ${state.reading?.modelName ?? state.modelName} (${(bytes / 1e6).toFixed(1)} MB)…`);
  else if (stage === 'workers') $('poolinfo').textContent = `Preparing ${workers} clipping worker${workers === 1 ? '' : 's'}…`;
  else if (stage === 'ready') $('poolinfo').textContent = poolError ? `Clipping in one thread: ${poolError}` : `${workers} clipping worker${workers === 1 ? '' : 's'} ready.`;
}

/** How the year was routed: the engine profile `auto` used (shown, as the API gives it). */
function showRouting(msg) {
  const r = msg.routing;
  $('routing').hidden = !r;
  if (!r) return;
  const refused = r.refused ? ` (${r.refused}; measured anew)` : '';
  $('routingsource').textContent = `auto routed by the ${r.source === 'probe' ? 'freshly measured' : r.source} profile${refused}; ${msg.workers} clipping worker(s)${msg.hasGpu ? '' : ', no GPU'}.`;
  const sky = r.sky ? `; sky views by the ${r.sky.source === 'probe' ? 'freshly measured' : r.sky.source} sky profile${r.sky.refused ? ` (${r.sky.refused}; measured anew)` : ''}` : '';
  $('routingsource').textContent += sky;
  const shown = (p) => JSON.stringify(JSON.parse(p), null, 2);
  $('routingprofile').textContent = shown(r.profile) + (r.sky ? `\n\nSky views:\n${shown(r.sky.profile)}` : '');
}

async function settings() {
  const s = {
    timestepsPerHour: Number($('timesteps').value),
    daysPerYear: Number($('days').value),
    samplesPerDay: Number($('perday').value),
  };
  if ($('evergreen').checked) s.evergreen = true;
  else if ($('leafout').value.trim() || $('leaffall').value.trim()) {
    s.leafOut = $('leafout').value.trim();
    s.leafFall = $('leaffall').value.trim();
  }
  if ($('skymodel').value) s.skyModel = $('skymodel').value;
  const epw = $('epw').files[0];
  if (epw) {
    s.epw = await epw.text();
    s.epwName = epw.name;
  } else {
    s.latitude = Number($('latitude').value);
    s.longitude = Number($('longitude').value);
    s.timeZone = Number($('timezone').value);
  }
  return s;
}

function download(name, text, type) {
  const url = URL.createObjectURL(new Blob([text], { type }));
  const a = document.createElement('a');
  a.href = url;
  a.download = name;
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 1000);
}

function wire() {
  $('model').addEventListener('change', async (e) => {
    const files = await readChosen(e.target.files);
    // Cleared so that choosing the same file again (after fixing a setting) reads it again.
    e.target.value = '';
    await loadFiles(files);
  });
  // These decide what the model is: a change re-reads the files.
  for (const id of ['receivers', 'foliage', 'transmittance']) $(id).addEventListener('change', () => state.files && loadFiles(state.files));
  $('example').addEventListener('click', async () => {
    const bytes = new Uint8Array(await (await fetch('pkg/office.glb')).arrayBuffer());
    await loadFiles([{ name: 'office.glb', bytes }]);
  });
  const drop = $('drop');
  for (const ev of ['dragenter', 'dragover']) drop.addEventListener(ev, (e) => { e.preventDefault(); drop.classList.add('over'); });
  for (const ev of ['dragleave', 'drop']) drop.addEventListener(ev, () => drop.classList.remove('over'));
  drop.addEventListener('drop', async (e) => {
    e.preventDefault();
    await loadFiles(await readChosen(e.dataTransfer.files));
  });
  $('settings').addEventListener('submit', async (e) => {
    e.preventDefault();
    if (!state.model || state.busy) return;
    $('retry').hidden = true;
    setBusy(true);
    $('progress').value = 0;
    if (maps.active()) {
      status('Mapping the points…');
      return maps.compute();
    }
    if (studies.active()) {
      status('Running the study…');
      return studies.compute();
    }
    status('Sampling the sun…');
    worker.postMessage({ type: 'compute', settings: await settings(), engine: engineOptions(), csvName: state.csvName });
  });
  $('cancel').addEventListener('click', () => worker.postMessage({ type: 'cancel' }));
  $('epw').addEventListener('change', epwChosen);
  $('colourby').addEventListener('change', () => {
    state.colourBy = $('colourby').value;
    showInViewer();
  });
  $('retry').addEventListener('click', () => $('settings').requestSubmit());
  maps.wire();
  studies.wire();
  // Leaving the Study mode gives the receivers back the year's colours (the legend is the mode's).
  $('mode').addEventListener('change', () => studies.active() || paintReceivers());
  $('download').addEventListener('click', () => state.result && download(state.csvName, state.result.csv, 'text/csv'));
  $('downloadidf').addEventListener('click', () => {
    if (!state.result?.hooked) return;
    const ext = /\.epjson$|\.json$/i.test(state.modelName) ? 'epJSON' : 'idf';
    download(state.csvName.replace(/-shading\.csv$/, `-sunlit.${ext}`), state.result.hooked, 'text/plain');
  });
  const body = $('table').tBodies[0];
  body.addEventListener('click', (e) => selectReceiver(Number(e.target.closest('tr')?.dataset.index ?? -1)));
  body.addEventListener('keydown', (e) => {
    if (e.key === 'Enter' || e.key === ' ') selectReceiver(Number(e.target.closest('tr')?.dataset.index ?? -1));
  });
}

async function start() {
  wire();
  // navigator.gpu can exist with no adapter behind it (WebGPU disabled or blocklisted).
  const adapter = navigator.gpu ? await navigator.gpu.requestAdapter().catch(() => null) : null;
  if (!adapter) return noWebGPU();
  try {
    state.viewer = await Viewer.create($('view'));
    // In the Study mode a click on a window ticks or unticks it in the list.
    state.viewer.onPick = (receiver) => {
      if (!studies.active() || receiver < 0) return;
      if (studies.toggleWindow(receiver)) status(`${state.model.names[receiver]} ${studies.ticked(receiver) ? 'ticked' : 'unticked'}.`);
    };
    showInViewer();
    maps.reset();
    studies.recolour();
  } catch (error) {
    status(`The 3D view is unavailable (${error.message}); results still work.`, { error: true });
  }
}
start();
