// Types of sunlit's JavaScript API (sunlit.js). Axes are EnergyPlus's: x east, y north, z up,
// metres. Fractions are sunlit area / area, 0..1, for each receiving surface.

/** What every function here throws or rejects with, except cancellation (a DOMException named
 * AbortError). The message names the file, object or option (as this API spells it, e.g.
 * `timestepsPerHour`) and the reason, for people; programs switch on `code`, never on the
 * message. */
export interface SunlitError extends Error {
  code:
    | 'io'
    | 'model'
    | 'object'
    | 'timestep-mismatch'
    | 'duplicate-receiver'
    | 'no-receivers'
    | 'bad-option'
    | 'gpu'
    | 'device-lost'
    | 'cancelled'
    | 'scene-bytes'
    | 'no-webgpu'
    | 'worker'
    | 'too-large'
    | 'freed';
  /** The file the error is about (a model or EPW file name), where it is about one. */
  file?: string;
  /** The object in that file, e.g. "node 'Wall_S'" or "Timestep". */
  object?: string;
  /** The option the error is about, e.g. 'receivers' or 'timestepsPerHour'. */
  option?: string;
  /** With code 'gpu': what failed. A 'gpu' or 'device-lost' error leaves the engine unusable;
   * a new engine (createEngine) may work. */
  gpu?: 'no-adapter' | 'device' | 'out-of-memory' | 'over-limit' | 'validation' | 'readback';
  /** With code 'worker': the index of the clipping worker that failed, and the code it gave
   * ('start' when it could not start: a CSP, a missing module; 'wasm-trap' when its wasm
   * trapped, e.g. out of memory). The engine's pool is then closed: make a new engine. */
  worker?: number;
  workerCode?: string;
}

/** Bytes of the wasm linear memory (it grows and never shrinks, so a leak shows as growth). */
export function wasmMemoryBytes(): Promise<number>;

/** The largest model files (bytes in all) that loadFiles reads: 4 GiB (wasm32's memory) over 17
 * (the most memory an instance was measured to take per byte of file, rounded up), about 253 MB;
 * larger ones are refused with code 'too-large'. */
export const maxModelBytes: number;

/** Throws loadFiles' 'too-large' SunlitError (naming the files and their size in MB) for model
 * files of `bytes` in all above maxModelBytes, so a page can refuse a file by its size before
 * reading it. */
export function checkModelSize(names: string[], bytes: number): void;

/** Whether this browser (or worker) offers WebGPU. */
export function hasWebGPU(): boolean;

/** Unit vector towards the sun from azimuth (degrees clockwise from north) and altitude (degrees). */
export function sunDirection(azimuth: number, altitude: number): [number, number, number];

/** Opens the GPU device and starts the pool of clipping workers. Without WebGPU the engine
 * still clips (`hasGpu` false), and only `engine: 'gpu'` or `'compute'` rejects, with code 'no-webgpu'. `resolution`: pixels along a view's side (default 512). `accuracy`: a
 * target |error| per view (e.g. 0.002): each view is counted at 64² first and again, finer up to
 * `resolution`, only where its shadow edges make the estimated error larger; without it every
 * view is counted at `resolution`. */
export function createEngine(options?: {
  resolution?: number;
  accuracy?: number;
  /** A GPUDevice the caller holds (e.g. its WebGPU renderer's): sunlit counts on it and never
   * destroys it; its loss is reported as a "GPU device lost" error. */
  device?: GPUDevice;
  /** Which engine answers views (default 'auto'). 'gpu': pixels on WebGPU. 'exact': polygon
   * clipping in the wasm, on the pool's workers, no resolution error (see-through geometry counts
   * as opaque). 'auto': per view the engine with the lower cost in a profile measured once on
   * this device and model (a probe of both engines on the model's own views, kept in IndexedDB
   * keyed like the native CLI's cache); routing is a pure function of the views' loads, the
   * profile and the run's size, so the same profile gives the same CSV byte for byte.
   * 'compute': pixels on WebGPU too, counted by the compute rasterizer (compute shaders alone,
   * no render pipeline; the same pixel rules, for GPUs whose raster hardware is small), which
   * needs WebGPU as 'gpu' does. Another value rejects with code 'bad-option', option 'engine'. */
  engine?: 'auto' | 'gpu' | 'exact' | 'compute';
  /** Clipping workers (default navigator.hardwareConcurrency; 0: clip in this thread). Each has
   * its own wasm instance and copy of the model's exact engine; answers do not depend on it. */
  workers?: number;
  /** An 'auto' profile to route by (JSON text or object, as Annual.profile gives it), pinning
   * the routing. One that does not parse, or was measured for another model or device, is
   * refused (Annual.profileRefused says why) and measured anew. */
  profile?: string | object;
  /** The same for the sky views (a year with weather), as Annual.skyProfile gives it: sky views
   * are routed by their own profile, measured on sky views and kept under their own key. */
  skyProfile?: string | object;
  /** Wasm memory, in bytes, that the engine's instance and its clipping workers may hold
   * together (default 2.5e9). When a model reaches the pool, each worker's copy is estimated
   * from what it is handed, and the pool keeps only the workers that fit beside the engine's
   * instance (0: this thread clips), saying so on the console; `poolSizing` tells the figures.
   * Not a positive number: rejects with code 'bad-option', option 'memoryBudget'. */
  memoryBudget?: number;
}): Promise<SunlitEngine>;

/** An EPW weather file's LOCATION record (throws naming `name` and the reason). */
export function epwLocation(
  text: string,
  name?: string,
): Promise<{ latitude: number; longitude: number; timeZone: number; elevation: number; name: string }>;

/** Meshes and their placements (what sunlit/three's fromThree builds from a scene graph). */
export interface MeshesInput {
  /** x, y, z per vertex, every mesh's vertices one after another, each in its own coordinates. */
  positions: ArrayLike<number>;
  /** Mesh m's vertices are vertexStarts[m]..vertexStarts[m+1]; meshes + 1 entries. */
  vertexStarts: ArrayLike<number>;
  /** Triangle lists, relative to their mesh's first vertex, one after another. */
  indices: ArrayLike<number>;
  /** Mesh m's indices are indexStarts[m]..indexStarts[m+1]; meshes + 1 entries. */
  indexStarts: ArrayLike<number>;
  /** Per placement: its mesh. A mesh placed several times is drawn instanced. */
  placementMeshes: ArrayLike<number>;
  /** Per placement: 16 numbers, mesh → world, column-major (three.js Matrix4.elements). */
  matrices: ArrayLike<number>;
  /** Per placement: its name (receivers' names are the output columns, unique). */
  names: string[];
  /** Per placement: truthy when it receives. */
  receivers: ArrayLike<number | boolean>;
  /** World coordinates in glTF / three.js axes (+Y up, -Z north). */
  yUp?: boolean;
}

export interface ModelFile {
  /** File name; its extension picks the reader (.glb, .gltf, .idf, .epJSON). */
  name: string;
  bytes: Uint8Array | ArrayBuffer;
}

export interface LoadOptions {
  /** Comma-separated globs over node names (case-insensitive): the receiving surfaces. Default:
   * nodes marked {"sunlit":{"receiver":true}} in extras, else every named node with a mesh. */
  receivers?: string;
  /** Degrees clockwise from true north of the model's north (glTF -Z). */
  north?: number;
  /** Comma-separated globs: these nodes are foliage (also nodes marked {"sunlit":{"foliage":true}}). */
  foliage?: string;
  /** Comma-separated GLOB=T items: matching nodes let T (0..1) of the beam through. */
  transmittance?: string;
}

export interface ArraysInput {
  /** x, y, z per vertex. */
  positions: ArrayLike<number>;
  /** Three vertex indices per triangle. */
  indices: ArrayLike<number>;
  /** Per triangle: index into `names`, or -1 for geometry that only casts shadows. */
  triangleReceivers: ArrayLike<number>;
  /** Receiver names, unique: the CSV's columns. */
  names: string[];
  /** Positions in glTF axes (+Y up, -Z north) instead of z up. */
  yUp?: boolean;
}

export interface AnnualSettings {
  /** Degrees north; with longitude and timeZone, unless `epw` is given. */
  latitude?: number;
  /** Degrees east. */
  longitude?: number;
  /** Hours from UTC of the standard time the CSV is in. */
  timeZone?: number;
  /** An EPW weather file's text; its LOCATION line gives latitude, longitude and time zone. */
  epw?: string;
  /** The EPW's file name, for messages. */
  epwName?: string;
  /** EnergyPlus Timestep: output rows per hour (default: the IDF's, else 4). */
  timestepsPerHour?: number;
  /** Sampled days over the year (default 27). */
  daysPerYear?: number;
  /** Samples per day (default 19). */
  samplesPerDay?: number;
  /** Count a timestep directly where neighbouring samples differ by more than this (default 0.3; 1 never). */
  refine?: number;
  /** Interpolate a timestep only where part of the surface is proved lit at its sun, else count it (slower; default false). */
  proveNeverDark?: boolean;
  /** Let a dark proof combine casters (coplanar panels forming one convex polygon, halves of a cell, a facade clipped where it meets the surface's plane), as `--many-casters`; exact (no step proved dark is lit) and moving no value, only views. Left out, the year tries them on one cell in 16 and keeps them where they settle at least 4 steps a cell tried (on a city they do; on an office behind louvres they do not). */
  manyCasters?: boolean;
  /** With manyCasters: let a facade meeting the surface's plane at an inner corner prove it dark along that shared edge, as `--inner-corners`; exact for the exact engine, default false (not yet shown for the GPU engine). */
  innerCorners?: boolean;
  /** Count every sun-up timestep instead of interpolating (slow). */
  dense?: boolean;
  /** Foliage keeps its leaves all year. */
  evergreen?: boolean;
  /** Leaf-out period "MM-DD,MM-DD" (default "04-15,05-31"; half a year later south of the equator). */
  leafOut?: string;
  /** Leaf-fall period "MM-DD,MM-DD" (default "10-01,11-15"). */
  leafFall?: string;
  /** The calendar year: a leap year gives 366 days (8784 × timestepsPerHour rows). Default: the
   * EnergyPlus model's RunPeriod year, else the EPW's Feb 29 record, else a non-leap year. */
  year?: number;
  /** The sky that weighs the sky patches (needs `epw`), as `sunlit annual --sky-model`:
   * 'energyplus' (EnergyPlus's Perez 1990 irradiance model, the default), 'perez-all-weather'
   * (Radiance's gendaymtx sky, as Ladybug uses), 'cie-overcast' or 'uniform'. */
  skyModel?: 'energyplus' | 'perez-all-weather' | 'cie-overcast' | 'uniform';
}

export interface AnnualRunOptions {
  /** Called as the run goes, stage by stage (the year, then its sky views with weather): `done`
   * of `total` views decided, of which `counted` were counted by an engine (the rest were settled
   * without counting, e.g. timesteps the spline interpolates). A year's `total` is fixed from its
   * first call; `done` jumps once its samples are fitted. */
  onProgress?: (done: number, total: number, counted: number) => void;
  /** Aborting rejects the run with an AbortError at the next progress report. */
  signal?: AbortSignal;
}

export interface SunlitEngine {
  /** The GPU adapter in use (with engine 'exact', which never draws, none is asked for). */
  readonly adapter: string;
  /** Pixels along a view's side. */
  readonly resolution: number;
  /** Which engine answers views (createEngine's `engine`). */
  readonly engine: 'auto' | 'gpu' | 'exact' | 'compute';
  /** Whether the engine holds a WebGPU adapter: false without WebGPU (views are clipped) and with
   * engine 'exact', which never draws and so asks for no adapter. */
  readonly hasGpu: boolean;
  /** Clipping workers in the pool (0: clipping runs in the engine's thread). */
  readonly workers: number;
  /** Each clipping worker's wasm memory in bytes once it built the model (its load's peak; wasm
   * memory never shrinks); empty without a pool. */
  readonly workerMemoryBytes: (number | undefined)[];
  /** How the last 'auto' year was routed: its profile key, the profile (JSON), where the profile
   * came from, and why a profile handed in was refused; null before one. */
  readonly routing: {
    key: string;
    profile: string;
    source: 'pinned' | 'cache' | 'probe';
    refused?: string;
    /** The sky views' (a year with weather), under their own key; null without them. */
    sky: { key: string; profile: string; source: 'pinned' | 'cache' | 'probe'; refused?: string } | null;
  } | null;
  /** Why the pool could not start (clipping then runs in the engine's thread), or null. */
  readonly poolError: string | null;
  /** How the memory budget sized the pool for the last model (null before one reached it):
   * `workers` kept of `asked`, each copy estimated at `workerBytes` beside the engine's
   * `engineBytes`, within `budgetBytes`. */
  readonly poolSizing: { budgetBytes: number; engineBytes: number; workerBytes: number; asked: number; workers: number } | null;
  /** Has the pool's workers build their copies of the model now (else the first year has them
   * do it), resolving once they hold it. A year does not wait for them: the engine's thread
   * clips until they hold the model. */
  prepare(model: Model): Promise<void>;
  /** Milliseconds from createEngine to each step of a first visit, where reached: `wasm` (the
   * engine's wasm instance started), `engine` (createEngine resolved), `workersReady` (every
   * clipping worker started), `encoded` (the last model encoded for the workers), `workersHold`
   * (every worker built its copy), `yearStarted` (the last year routed: its model encoded, its
   * profile looked up, its counting begins), `yearCounted` (that year's schedule made, before its
   * profile is stored); `clipped`: views clipped so far in the engine's thread and by the
   * workers; `indexesBuilt`: exact engines (indexes of a model) the engine's wasm instance has
   * built so far, one a model however it is used. */
  readonly timings: {
    wasm?: number;
    engine?: number;
    workersReady?: number;
    encoded?: number;
    workersHold?: number;
    yearStarted?: number;
    yearCounted?: number;
    clipped: { here: number; workers: number };
    indexesBuilt: number;
  };
  /** Stops the pool's workers. */
  close(): void;
  /** Reads model files; throws a SunlitError naming the file, object and reason when one is bad. */
  loadFiles(files: ModelFile[], options?: LoadOptions): Model;
  /** Builds a model from typed arrays; throws a SunlitError naming the array and element when bad. */
  fromArrays(input: ArraysInput): Model;
  /** Builds a model from meshes and placements; throws an Error naming the array and element when bad. */
  fromMeshes(input: MeshesInput): Model;
  /** Every receiver's fraction for one sun direction (unit vector towards the sun, or angles). */
  fractions(model: Model, sun: [number, number, number] | { azimuth: number; altitude: number }): Promise<Float64Array>;
  /** The year's sunlit fractions at every EnergyPlus timestep. */
  annual(model: Model, settings: AnnualSettings, options?: AnnualRunOptions): Promise<Annual>;
  /** Per-point values on the receivers (a grid, or given points): sun hours, or direct, sky-diffuse
   * or total irradiation over a period, or lit (1) or not (0) at an instant, each point by its own
   * shadow rays (to the sun, and to each sky patch for the sky). */
  map(model: Model, options: MapOptions, run?: MapRunOptions): Promise<SunlitMap>;
  /** The window studies of planning rules (BRE 209's VSC, APSH/WPSH and 25°/45° pre-checks,
   * GB 50180's sunlight hours; docs/planning.md) at one point per window, or at given points,
   * by the exact shadow rays on the CPU, as `sunlit map --study` runs them. Bad options throw a
   * SunlitError naming the option (`windows` when none is selected). */
  study(model: Model, options: StudyOptions): Promise<SunlitStudy>;
}

/** A window study, as `sunlit map --study` names it. */
export type StudyName = 'bre-vsc' | 'bre-apsh' | 'gb50180' | 'bre-25deg' | 'bre-45deg' | 'en17037';

/** engine.study's options, as `sunlit map --study` takes them (docs/planning.md). */
export interface StudyOptions {
  /** One study or several. */
  study: StudyName | StudyName[];
  /** The windows: receiver indices (into receiverNames), one point on each (`windowPoints`),
   * as `sunlit map --window-points`. Give these or `points`. */
  windows?: ArrayLike<number>;
  /** Where on each window: 'centre' (BRE's reference point, the default) or 'sill' (GB 50180's
   * ground-floor sill, the middle of the lowest edge). */
  windowPoints?: 'centre' | 'sill';
  /** With windowPoints 'sill': the ground floor's level (m, the model's heights); a window
   * reaching lower is counted at GB 50180's sill, 0.9 m above it (`--floor-level`). */
  floorLevel?: number;
  /** Or given points: 6 numbers per point, x y z nx ny nz, each on a receiver (as `--points`). */
  points?: ArrayLike<number>;
  /** Degrees north; with longitude and timeZone (gb50180 and en17037 need a site; bre-vsc none). */
  latitude?: number;
  /** Degrees east. */
  longitude?: number;
  /** Hours from UTC of local standard time. */
  timeZone?: number;
  /** An EPW's text: its location, and for bre-apsh its direct normal irradiance (needed). */
  epw?: string;
  /** The EPW's file name, for messages. */
  epwName?: string;
  /** bre-vsc's sky: only 'cie-overcast' (VSC is defined under it); refused for the other studies. */
  skyModel?: 'energyplus' | 'perez-all-weather' | 'cie-overcast' | 'uniform';
  /** gb50180: 'dahan' (大寒日, the default) or 'dongzhi' (冬至日). */
  day?: string;
  /** gb50180: hours required (default 2 on 大寒日, 1 on 冬至日). */
  requiredHours?: number;
  /** gb50180: only continuous periods of at least this many minutes count. */
  minPeriod?: number;
  /** gb50180: only the longest N periods count. */
  maxPeriods?: number;
  /** gb50180: the 满窗 (whole window) variant, the sun over the whole sill: a sill this wide, in
   * metres, centred on every point, or 'sill', each window's own sill line measured from its
   * geometry (its lowest edge; with floorLevel, its width at the sill height), with
   * windowPoints 'sill' only (`--window-width METRES|sill`). */
  windowWidth?: number | 'sill';
  /** gb50180: the 满窗 variant with each window's own sill width: the text of a `receiver,width`
   * CSV (as `--window-widths FILE.csv` reads it), or widths in metres by window name,
   * `{ WIN_S1: 1.5 }`; every studied window needs one. */
  windowWidths?: string | Record<string, number>;
  /** en17037: the day, 'MM-DD' from '02-01' to '03-21' (default '03-21'; `--period`). */
  period?: string;
  /** en17037: the sun counts at or above this altitude, degrees (default 10; `--min-altitude`). */
  minAltitude?: number;
  /** The existing scene (`sunlit map --before MODEL`), loaded as the proposed one is: the same
   * points are studied on it too, and each table gains the former values, their ratios and
   * BRE's relative tests (0.8 × former; APSH's 4-point loss). Points not on its receivers have
   * no former value; none at all is refused naming `before`. */
  before?: Model;
  /** The points whose sky masks (stereographic sun-path diagrams, SVG) are drawn into the
   * answer and the report: 'all', or 0-based rows of the points (`--mask`, which counts from 1). */
  masks?: 'all' | ArrayLike<number>;
  /** The proposed model's file names, as the report's inputs state them (the CLI's MODEL...). */
  modelNames?: string[];
  /** The existing model's file names, as the report's inputs state them (`--before MODEL...`). */
  beforeNames?: string[];
}

/** One study's results per point, as `POINTS.study-NAME.json` holds them. */
export interface StudyTable {
  study: StudyName;
  /** The rule and its source, in words. */
  source: string;
  /** Every parameter of the rule, as the report states them. */
  rule: Record<string, unknown>;
  /** Per value key ('vsc'; 'apsh', 'wpsh'; 'hours', 'hours_whole_window' (gb50180); 'hours' (en17037); 'angle_deg';
   * 'within_45deg'), the value per point. */
  values: Record<string, number[]>;
  /** Per point: passes (true), fails (false), or not assessed (null: APSH of a window facing
   * more than 90° from due south). */
  passes: (boolean | null)[];
  /** Per verdict key ('passes', 'passes_whole_window'; en17037's 'passes_medium', 'passes_high'), per point. */
  verdicts: Record<string, boolean[]>;
  /** Per point, the study's own absolute test ('passes_absolute' of the report). */
  absolute: boolean[];
  /** Per point, the relative test against the former value ('passes_relative': BRE's 0.8 ×
   * former, and for APSH the 4-point loss); null without an existing scene or where the point
   * is not in it. */
  relative: (boolean | null)[];
  /** With `before`: per value key, the existing scene's value per point (null where the point
   * is not in it); null otherwise. */
  before: Record<string, (number | null)[]> | null;
  /** With `before`: per value key, now / before per point (null without a former value or where
   * it was 0); null otherwise. */
  ratio: Record<string, (number | null)[]> | null;
}

/** engine.study's answer, one entry per point (in the order of `windows` or `points`). */
export interface SunlitStudy {
  /** x y z per point. */
  points: Float32Array;
  /** The outward unit normal per point. */
  normals: Float32Array;
  /** The receiver each point lies on: an index into receiverNames. */
  receivers: Uint32Array;
  /** One table per study asked. */
  tables: StudyTable[];
  /** Per study, its table as `sunlit map --study NAME -o POINTS.csv` writes
   * `POINTS.study-NAME.csv`, byte for byte. */
  csv: Record<string, string>;
  /** The self-contained HTML report, as `sunlit map --study … --html REPORT.html` writes it
   * (with `--mask` for `masks`, `--before` for `before`), byte for byte for the same inputs and
   * file names. */
  html: string;
  /** The sky masks asked for (`masks`): per point row (0-based), its diagram as SVG, as
   * `--mask` writes POINTS.mask-N.svg. */
  masks: Record<number, string>;
}

/** engine.map's options: where (a grid or given points), when (a period or an instant) and what
 * (the value), as `sunlit map` takes them; the location as AnnualSettings gives it. */
export interface MapOptions {
  /** Degrees north; with longitude and timeZone, unless `epw` is given. */
  latitude?: number;
  /** Degrees east. */
  longitude?: number;
  /** Hours from UTC of the standard time the period is in. */
  timeZone?: number;
  /** An EPW weather file's text: its location, and the solar irradiance for `direct`,
   * `skyDiffuse` and `total` (the EPW's albedo, 0.2 where missing). */
  epw?: string;
  /** The EPW's file name, for messages. */
  epwName?: string;
  /** A grid on every receiver at this spacing in metres (default 0.5), inside its polygon. */
  grid?: number;
  /** Or given points: 6 numbers per point, x y z nx ny nz (sunlit's axes: x east, y north, z up). */
  points?: ArrayLike<number>;
  /** 'annual' (default), one day 'MM-DD', or a date range 'MM-DD..MM-DD'. */
  period?: string;
  /** Minutes between the instants counted within a day (1..60; default: the year's timestep). */
  step?: number;
  /** Local standard time 'HH:MM' each day's window starts (default 00:00). */
  from?: string;
  /** Local standard time 'HH:MM' each day's window ends (default 24:00). */
  to?: string;
  /** One instant, 'MM-DD HH:MM' local standard time: then the value is 'lit'. */
  at?: string;
  /** 'sunHours' (default), 'direct', 'skyDiffuse' or 'total' (kWh/m², need an EPW; each sums
   * every part, as `sunlit map --epw`, counting each point's view of Tregenza's 145 sky patches
   * once per grid) or 'lit' (needs `at`). */
  value?: 'sunHours' | 'direct' | 'skyDiffuse' | 'total' | 'lit';
  /** Foliage keeps its leaves all year (as AnnualSettings). */
  evergreen?: boolean;
  /** Leaf-out period "MM-DD,MM-DD" (as AnnualSettings). */
  leafOut?: string;
  /** Leaf-fall period "MM-DD,MM-DD" (as AnnualSettings). */
  leafFall?: string;
  /** The sky for 'skyDiffuse' and 'total' (needs `epw`), as `sunlit map --sky-model`:
   * 'energyplus' (the default), 'perez-all-weather', 'cie-overcast' or 'uniform'. */
  skyModel?: 'energyplus' | 'perez-all-weather' | 'cie-overcast' | 'uniform';
  /** Map the inside of an EnergyPlus model's zones, or of a mesh model's rooms (`interior`), as
   * `sunlit map --inside`: a grid on their floors (or `points` in them) and the beam through the
   * windows. The inside scene (the rooms, the points and their shadow-ray index) is kept on the
   * model for the last rooms, glass and points asked, so a map of the same points again (a time
   * slider, a study) does not rebuild it. A period or 'leed-ase' calls `onProgress` between
   * chunks of instants and stops at the next chunk when `signal` aborts. At the instant `at`, each
   * point lit or not, and the answer adds the glass's weights and each inside face's sun patch;
   * over a period, 'sunHours' or 'direct' (the beam through the glass, kWh/m², needs an EPW),
   * the CSV adding with an EPW the beam and the direct-sun illuminance; or a `study`. */
  inside?: boolean;
  /** With `inside`: the grid this many metres above each floor (default 0: on the floors; a
   * study's own: 0.76 for 'leed-ase', 0.85 for 'bre-nsl'). */
  workPlane?: number;
  /** With `inside`, a study of the rooms, as `sunlit map --inside --study`: 'leed-ase' (LEED
   * v4.1's Annual Sunlight Exposure over the year's occupied hours; needs an EPW; grid 0.6 m by
   * default; value 'aseHours') or 'bre-nsl' (BRE 209's No-Sky Line; value 'seesSky'). No `at`,
   * `period`, `step`, `from`, `to` or `value`: the study sets them. The answer adds `areas`. */
  study?: 'leed-ase' | 'bre-nsl';
  /** With `inside`: transmittance (0..1) of glazing whose construction gives none (`--glass-transmittance`);
   * with `interior`, of panes whose material's extras describe no glass. */
  glassTransmittance?: number;
  /** With `inside`, an EnergyPlus model's glazing whose construction sunlit cannot read follows
   * this curve (`--glass-curve`): 'ANGLE:T,...', angles of incidence from 0° and the solar
   * transmittance there, never rising; `glassTransmittance` is then the visible one. Refused
   * with `interior` (a glTF pane's curve is its material's extras). */
  glassCurve?: string;
  /** With `inside`, a mesh model (loaded with `loadFiles`): globs over node names (as text,
   * comma-separated, or an array), each matching node one room, its closed shell
   * (`--interior`). */
  interior?: string | string[];
  /** With `interior`: globs over node names, each matching node glass in an opening
   * (`--glazing`), its material's extras giving its curve, else `glassTransmittance`. */
  glazing?: string | string[];
  /** With `inside` and `grid`: the grid on every inside face of the rooms too (walls, roofs,
   * ceilings, at the same spacing), not only on the floors or work plane (`--faces`), so that an
   * instant's sun patch is mapped on each face it falls on. Refused with `points` or a `study`. */
  faces?: boolean;
}

/** One room's share in an inside study (`inside: true, study`), as the study's report's `areas`. */
export interface InsideArea {
  /** The zone. */
  zone: string;
  /** Its points. */
  points: number;
  /** 'leed-ase': ASE1000,250, % of its points. */
  ase?: number;
  /** 'bre-nsl': % of its points that see sky. */
  seesSky?: number;
}

/** One inside face's sun patch at the instant (`inside: true`). */
export interface SunPatch {
  /** The inside face, `SURFACE:inside`. */
  surface: string;
  /** Its zone. */
  zone: string;
  /** Sunlit area, m² (geometry: the glass's weight not applied). */
  areaM2: number;
  /** Sunlit share of the face's net area. */
  fraction: number;
}

export interface MapRunOptions extends AnnualRunOptions {
  /** Also return the points CSV (`csv`), as `sunlit map -o POINTS.csv` writes it. */
  csv?: boolean;
  /** Also return the map glb (`glb`), as `sunlit map --glb-out MAP.glb` writes it. */
  glb?: boolean;
  /** Keep the map for its files, written only when asked (`files.csv()`, `files.glb()`): for a
   * caller that draws every map but downloads few (a time slider). */
  files?: boolean;
}

/** A map's points CSV and map glb on demand (`files: true`), as `csv`/`glb` would have given
 * them. It holds the map in the engine's memory until `free()`; after it, both throw a
 * SunlitError with code 'freed'. Not transferable: ask for the files where the map was made. */
export interface MapFiles {
  csv(): string;
  glb(): Uint8Array;
  free(): void;
}

/** engine.map's answer: plain typed arrays (transferable to and from a worker), one entry per
 * point, in sunlit's world axes (x east, y north, z up, metres). */
export interface SunlitMap {
  /** The value held: 'sunHours' (h), 'direct', 'skyDiffuse', 'total' (kWh/m²) or 'lit' (1 sunlit,
   * 0 shaded); an inside study's: 'aseHours' (occupied hours over 1000 lux of direct sun) or
   * 'seesSky' (1 or 0). */
  value: 'sunHours' | 'direct' | 'skyDiffuse' | 'total' | 'lit' | 'aseHours' | 'seesSky';
  /** The legend's title and unit. */
  title: string;
  unit: string;
  /** The grid's spacing in metres (the cells' size for painting); given points: 0. */
  spacing: number;
  /** Instants counted per point over the period (1 for `at`). */
  instants: number;
  /** x y z per point. */
  points: Float32Array;
  /** The surface's outward unit normal per point. */
  normals: Float32Array;
  /** The receiver each point lies on: an index into receiverNames. */
  receivers: Uint32Array;
  /** The value per point. */
  values: Float32Array;
  /** A period's sun hours per point (undefined for an instant). */
  sunHours: Float32Array | undefined;
  /** A period's direct irradiation per point, kWh/m² (undefined without an EPW, or for an instant). */
  direct: Float32Array | undefined;
  /** A period's sky-diffuse irradiation per point (Perez 1990 sky over the point's own visible
   * patches, circumsolar part shaded like its beam), kWh/m²; with an irradiation value. */
  skyDiffuse: Float32Array | undefined;
  /** A period's ground-reflected irradiation per point, GHI·albedo·(1 − cos tilt)/2 (unobstructed),
   * kWh/m²; with an irradiation value. */
  groundReflected: Float32Array | undefined;
  /** direct + skyDiffuse + groundReflected per point, kWh/m²; with an irradiation value. */
  total: Float32Array | undefined;
  /** Each point's view factor to the visible sky ((1 + cos tilt)/2 with nothing in the way); with
   * an irradiation value. */
  skyViewFactor: Float32Array | undefined;
  /** The points CSV (with `csv: true`): receiver,x,y,z,nx,ny,nz then lit, or sun_hours and, with
   * an EPW, direct_kwh_m2 (and with the sky sky_diffuse_kwh_m2, ground_reflected_kwh_m2,
   * total_kwh_m2, sky_view_factor). */
  csv: string | undefined;
  /** The map glb (with `glb: true`): the receivers, a square per point coloured by the value, the
   * legend in the scene's extras. */
  glb: Uint8Array | undefined;
  /** The files on demand (with `files: true`). */
  files: MapFiles | undefined;
  /** The legend's range: 0 and the largest value (lit: 0 and 1). */
  min: number;
  max: number;
  /** The model's receiver names; inside rooms, the inside faces' and work planes' names. */
  receiverNames: string[];
  /** Inside rooms at an instant: per point the solar transmittance of the glass its beam came
   * through (0 shaded). */
  solarTransmittance?: Float32Array;
  /** Inside rooms: per point the visible transmittance likewise. */
  visibleTransmittance?: Float32Array;
  /** Inside rooms at an instant: the sun patch on each inside face that has one. */
  patches?: SunPatch[];
  /** Inside rooms, a study: each room's share. */
  areas?: InsideArea[];
}

/** A scene on the engine's GPU device; use it only with the engine that made it. */
export interface Model {
  readonly receiverNames: string[];
  /** What loading chose that the user should hear, e.g. that the default rule (every named node)
   * chose more than 200 receivers, and how to narrow them; empty when there is nothing to say. */
  readonly notes: string[];
  /** m² per receiver. */
  readonly receiverAreas: Float64Array;
  readonly triangles: number;
  /** Leaves of the foliage (0 without). */
  readonly leaves: number;
  /** Triangles that let part of the beam through. */
  readonly seeThroughTriangles: number;
  /** Whether an EnergyPlus model was among the files (then Annual.hookedModel works). */
  readonly hasEnergyPlus: boolean;
  /** The EnergyPlus model's Timestep, if one was loaded (the CSV must match it). */
  readonly modelTimesteps: number | undefined;
  /** Every triangle's corners, 9 floats each, for drawing. */
  worldPositions(): Float32Array;
  /** Per triangle of worldPositions(): receiver index or -1. */
  worldReceivers(): Int32Array;
  /** Releases the GPU buffers now rather than at garbage collection. */
  free(): void;
}

/** A year of fractions: rows = 8760 × timestepsPerHour, one column per receiver. */
export interface Annual {
  readonly names: string[];
  readonly timestepsPerHour: number;
  readonly rows: number;
  /** Each receiver's mean fraction over the year's sun-up timesteps. */
  readonly means: Float64Array;
  /** One receiver's fraction at every timestep. */
  column(index: number): Float32Array;
  /** The profile 'auto' routed by (JSON; pass it to createEngine({ profile }) to pin it). */
  readonly profile: string | undefined;
  /** Where it came from: 'pinned', 'cache' (IndexedDB) or 'probe' (measured in this run). */
  readonly profileSource: 'pinned' | 'cache' | 'probe' | undefined;
  /** Why a profile handed in was refused, naming it and the reason (it was measured anew). */
  readonly profileRefused: string | undefined;
  /** The profile 'auto' routed the sky views by (a year with weather; pin it with
   * createEngine({ skyProfile })), where it came from, and why one handed in was refused. */
  readonly skyProfile: string | undefined;
  readonly skyProfileSource: 'pinned' | 'cache' | 'probe' | undefined;
  readonly skyProfileRefused: string | undefined;
  /** Annual direct (beam) irradiation Σ DNI·cosθ·fraction·Δt per receiver, kWh/m², from the EPW's
   * direct normal irradiance (each hour's value held over its timesteps); undefined without an
   * EPW. Throws naming the file and line when the EPW's hourly records are unreadable. */
  readonly irradiation: Float64Array | undefined;
  /** The same with nothing in the way: Σ DNI·cosθ·Δt over timesteps with the sun in front. */
  readonly unshadedIrradiation: Float64Array | undefined;
  /** The same as irradiation: the beam part of the total, kWh/m². */
  readonly direct: Float64Array | undefined;
  /** Sky diffuse irradiation per receiver (Perez 1990 sky, shaded patch by patch over Tregenza's
   * 145 sky patches; circumsolar part shaded like the beam), kWh/m²; undefined without an EPW. */
  readonly skyDiffuse: Float64Array | undefined;
  /** Ground-reflected irradiation GHI·albedo·(1 − cos tilt)/2 (unobstructed; the EPW's albedo,
   * 0.2 where missing), kWh/m²; undefined without an EPW. */
  readonly groundReflected: Float64Array | undefined;
  /** direct + skyDiffuse + groundReflected, kWh/m²; undefined without an EPW. */
  readonly total: Float64Array | undefined;
  /** The total with nothing in the way, kWh/m²; undefined without an EPW. */
  readonly unshadedTotal: Float64Array | undefined;
  /** Each receiver's view factor to the visible sky ((1 + cos tilt)/2 unobstructed); undefined
   * without an EPW. */
  readonly skyViewFactor: Float64Array | undefined;
  /** Every receiver's fraction at day of year `day` (1..365) and local standard `hour` (0..24),
   * linear between the schedule's rows, 0 with the sun down. */
  fractionsAt(day: number, hour?: number): Float64Array;
  /** Every receiver's fraction at day of year `day` (1..365, fractional allowed) and local standard
   * `hour` (0..24) from the year's fitted annual spline surfaces, evaluated in wasm (cheap enough
   * for a time slider): smooth between timesteps; at a timestep's instant the CSV's value, except
   * where the run counted that timestep directly (refinement); 0 with the sun down or behind the
   * surface. Throws a SunlitError naming `day` or `hour` when outside, or `dense` for a dense year
   * (which has no surfaces: use fractionsAt). */
  splineFractionsAt(day: number, hour: number): Float64Array;
  /** The EnergyPlus CSV (eplusshading.csv layout). */
  csv(): string;
  /** With an IDF/epJSON loaded: the model text with the CSV (saved beside it as csvName) hooked in. */
  hookedModel(csvName: string): string;
  free(): void;
}
