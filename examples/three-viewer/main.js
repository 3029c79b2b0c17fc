// A three.js glTF viewer with sunlit: GLTFLoader reads the model, sunlit/three hands the scene
// to sunlit (fromThree), the year is computed on WebGPU, and the time-of-year sliders recolour
// the receiving surfaces by their sunlit fraction at that instant (Annual.splineFractionsAt: the
// year's fitted spline surfaces, evaluated in wasm at every slider move), and paint the shadow
// pattern at that instant on a grid over the receivers: each point lit or not by sunlit's own
// shadow ray (engine.map with `at`, painted by sunlit/three's paintMap), no three.js shadow maps.
import * as THREE from 'three';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { createEngine } from 'sunlit';
import { fromThree, colourByValues, receivingMeshes, paintMap } from 'sunlit/three';
import officeUrl from '../office.glb?url';

const $ = (id) => document.getElementById(id);
const MONTHS = ['Jan', 'Feb', 'Mar', 'Apr', 'May', 'Jun', 'Jul', 'Aug', 'Sep', 'Oct', 'Nov', 'Dec'];
const MONTH_DAYS = [31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31];

const renderer = new THREE.WebGLRenderer({ canvas: $('view'), antialias: true, preserveDrawingBuffer: true });
const scene = new THREE.Scene();
scene.background = new THREE.Color(0xf4f4f2);
scene.add(new THREE.HemisphereLight(0xffffff, 0x888877, 2.2));
const light = new THREE.DirectionalLight(0xffffff, 1.2);
light.position.set(1, 2, 1.5);
scene.add(light);
const camera = new THREE.PerspectiveCamera(45, 1, 0.1, 5000);
const controls = new OrbitControls(camera, renderer.domElement);
controls.addEventListener('change', render);

const state = { engine: null, content: null, model: null, year: null, busy: false };
// The shadow pattern: the painted cells, the instant they show, and a newer instant to map next.
const shadows = { painted: null, at: null, running: false, again: false };

function status(text, error = false) {
  $('status').textContent = text;
  $('status').classList.toggle('error', error);
}

function render() {
  const canvas = renderer.domElement;
  const { clientWidth: w, clientHeight: h } = canvas;
  if (canvas.width !== w || canvas.height !== h) {
    renderer.setSize(w, h, false);
    camera.aspect = w / Math.max(h, 1);
    camera.updateProjectionMatrix();
  }
  renderer.render(scene, camera);
}
new ResizeObserver(render).observe(renderer.domElement);

/** Receivers: the field's globs, else the meshes the glTF marks (extras `sunlit.receiver`). */
function receivers() {
  const globs = $('receivers').value.trim();
  return globs || ((mesh) => mesh.userData?.sunlit?.receiver === true);
}

function frame(object) {
  const box = new THREE.Box3().setFromObject(object);
  const centre = box.getCenter(new THREE.Vector3());
  const size = box.getSize(new THREE.Vector3()).length() || 10;
  controls.target.copy(centre);
  camera.position.copy(centre).add(new THREE.Vector3(0.6, 0.5, 0.9).multiplyScalar(size));
  camera.near = size / 1000;
  camera.far = size * 20;
  camera.updateProjectionMatrix();
  controls.update();
}

async function load(buffer, name) {
  if (state.busy) return;
  try {
    status(`Reading ${name}…`);
    const gltf = await new GLTFLoader().parseAsync(buffer, '');
    // glTF's default material is fully metallic, which reads as dark without an environment map:
    // matte, so that the colours read as the legend's.
    gltf.scene.traverse((o) => {
      if (o.material?.isMeshStandardMaterial) o.material.metalness = 0;
    });
    state.engine ??= await createEngine({ resolution: Number($('resolution').value) || 256 });
    const model = fromThree(state.engine, gltf.scene, { receivers: receivers() });
    if (state.content) scene.remove(state.content);
    clearShadows();
    state.year?.free();
    state.model?.free();
    Object.assign(state, { content: gltf.scene, model, year: null });
    scene.add(gltf.scene);
    frame(gltf.scene);
    $('time').disabled = false;
    $('compute').disabled = false;
    $('values').tBodies[0].replaceChildren();
    $('legend').replaceChildren();
    status(`Loaded ${name}: ${model.receiverNames.length} receiving surfaces, ${model.triangles} triangles. Compute the year.`);
    render();
    drawShadows();
  } catch (error) {
    status(`Could not load ${name}: ${error.message}`, true);
  }
}

/** The form's location: an EPW, else latitude, longitude and time zone. */
async function location() {
  const epw = $('epw').files[0];
  if (epw) return { epw: await epw.text(), epwName: epw.name };
  return { latitude: Number($('latitude').value), longitude: Number($('longitude').value), timeZone: Number($('timezone').value) };
}

async function settings() {
  return { daysPerYear: Number($('days').value), samplesPerDay: Number($('perday').value), timestepsPerHour: 1, ...(await location()) };
}

/** The slider's instant as engine.map's `at`: 'MM-DD HH:MM', local standard time. */
function instantOf(day, hour) {
  let d = day;
  let m = 0;
  while (m < 11 && d > MONTH_DAYS[m]) d -= MONTH_DAYS[m++];
  const minutes = Math.min(Math.round(hour * 60), 24 * 60 - 1);
  const two = (n) => String(n).padStart(2, '0');
  return `${two(m + 1)}-${two(d)} ${two(Math.floor(minutes / 60))}:${two(minutes % 60)}`;
}

function clearShadows() {
  if (shadows.painted) {
    scene.remove(shadows.painted.mesh);
    shadows.painted.mesh.geometry.dispose();
    shadows.painted.mesh.material.dispose();
  }
  Object.assign(shadows, { painted: null, at: null });
  $('shadowlegend').replaceChildren();
}

/** sunlit's shadow pattern at the slider's instant, painted on the receivers. One map at a time:
 * slider moves during one are mapped once it is done, at the latest instant. */
async function drawShadows() {
  if (!state.model || !$('shadows').checked) return clearShadows(), render();
  if (shadows.running) {
    shadows.again = true;
    return;
  }
  shadows.running = true;
  try {
    do {
      shadows.again = false;
      const [day, hour] = [Number($('day').value), Number($('hour').value)];
      const grid = Number($('grid').value);
      const map = await state.engine.map(state.model, { ...(await location()), grid, at: instantOf(day, hour) });
      const same = shadows.painted && shadows.painted.values.length === map.values.length && shadows.grid === grid;
      if (same) shadows.painted.update(map.values);
      else {
        clearShadows();
        shadows.painted = paintMap(THREE, map);
        shadows.grid = grid;
        scene.add(shadows.painted.mesh);
      }
      shadows.map = map;
      shadows.at = [day, hour];
      $('shadowlegend').replaceChildren(shadows.painted.legend);
      document.body.dataset.shadowAt = `${day},${hour}`;
      render();
    } while (shadows.again);
  } catch (error) {
    status(`Could not map the shadows: ${error.message}`, true);
  } finally {
    shadows.running = false;
  }
}

async function compute() {
  if (!state.model || state.busy) return;
  state.busy = true;
  $('compute').disabled = true;
  const started = performance.now();
  try {
    const year = await state.engine.annual(state.model, await settings(), {
      onProgress: (done, total) => {
        $('progress').max = total || 1;
        $('progress').value = done;
        status(`Counting views: ${done} of ${total}`);
      },
    });
    state.year?.free();
    state.year = year;
    $('time').disabled = false;
    recolour();
    status(`Year computed in ${((performance.now() - started) / 1000).toFixed(1)} s. Move the sliders.`);
  } catch (error) {
    status(`Could not compute: ${error.message}`, true);
  } finally {
    state.busy = false;
    $('compute').disabled = false;
  }
}

function dayLabel(day) {
  let d = day;
  for (let m = 0; m < 12; m++) {
    if (d <= MONTH_DAYS[m]) return `${d} ${MONTHS[m]}`;
    d -= MONTH_DAYS[m];
  }
  return String(day);
}

/** The slider's instant: every receiver's fraction from the fitted surfaces, as colours and rows. */
function recolour() {
  const day = Number($('day').value);
  const hour = Number($('hour').value);
  $('daylabel').textContent = dayLabel(day);
  $('hourlabel').textContent = `${String(Math.floor(hour)).padStart(2, '0')}:${String(Math.round((hour % 1) * 60)).padStart(2, '0')}`;
  if (!state.year) return;
  const fractions = state.year.splineFractionsAt(day, hour);
  const { legend } = colourByValues(state.model, fractions, { min: 0, max: 1, label: 'sunlit fraction' });
  $('legend').replaceChildren(legend);
  const body = $('values').tBodies[0];
  body.replaceChildren();
  state.model.receiverNames.forEach((name, i) => {
    const row = body.insertRow();
    row.dataset.name = name;
    row.dataset.value = String(fractions[i]);
    row.insertCell().textContent = name;
    const cell = row.insertCell();
    cell.className = 'num';
    cell.textContent = fractions[i].toFixed(3);
  });
  document.body.dataset.instant = `${day},${hour}`;
  render();
}

$('file').addEventListener('change', async (e) => {
  const file = e.target.files[0];
  if (file) await load(await file.arrayBuffer(), file.name);
});
$('example').addEventListener('click', async () => load(await (await fetch(officeUrl)).arrayBuffer(), 'office.glb'));
$('compute').addEventListener('click', compute);
for (const id of ['day', 'hour']) $(id).addEventListener('input', () => (recolour(), drawShadows()));
for (const id of ['shadows', 'grid']) $(id).addEventListener('change', drawShadows);

// For the console (and the tests): the live objects, and each receiving mesh's colour (sRGB, as
// the legend).
window.sunlitViewer = {
  get engine() {
    return state.engine;
  },
  get year() {
    return state.year;
  },
  get model() {
    return state.model;
  },
  /** The painted shadow pattern: its instant, engine.map's lit values, and each cell's colour
   * (sRGB, read back from the painted mesh's vertex colours). */
  shadows: () => {
    if (!shadows.painted) return null;
    const colour = shadows.painted.mesh.geometry.getAttribute('color');
    const srgb = (c) => new THREE.Color().setRGB(c[0], c[1], c[2], THREE.LinearSRGBColorSpace).getRGB(new THREE.Color(), THREE.SRGBColorSpace);
    const cells = [];
    for (let i = 0; i < colour.count; i += 6) {
      const { r, g, b } = srgb([colour.getX(i), colour.getY(i), colour.getZ(i)]);
      cells.push([r, g, b]);
    }
    return { at: shadows.at, values: Array.from(shadows.map.values), cells, points: shadows.map.values.length };
  },
  colours: () =>
    receivingMeshes(state.model).map(({ mesh, name }) => {
      const { r, g, b } = mesh.material.color.getRGB(new THREE.Color(), THREE.SRGBColorSpace);
      return { name, rgb: [r, g, b] };
    }),
};
status(navigator.gpu ? 'Ready: load a glTF or the example office.' : 'This browser offers no WebGPU, which sunlit needs.', !navigator.gpu);
recolour();
