// Types of sunlit/three (three.js is a peer dependency; these types do not import it).
import type { Model, SunlitEngine, SunlitMap } from './sunlit';

/** The parts of a three.js Object3D / Mesh that sunlit/three reads. */
export interface ThreeObject {
  isObject3D: true;
  name: string;
  updateWorldMatrix(updateParents: boolean, updateChildren: boolean): void;
  traverse(callback: (object: any) => void): void;
}

export interface FromThreeOptions {
  /** Comma-separated globs over mesh names (case-insensitive), or a predicate. Receiver names
   * are the mesh names (an InstancedMesh's instance i: `NAME[i]`); they must be unique. */
  receivers: string | ((mesh: any) => boolean);
}

/** A Model from every Mesh under `object`, world matrices applied, instancing kept, Y-up axes. */
export function fromThree(engine: SunlitEngine, object: ThreeObject, options: FromThreeOptions): Model;

/** The receiving meshes of a fromThree model and the receiver name each stands for. */
export function receivingMeshes(model: Model): { mesh: any; instance: number; name: string }[];

/** Colours the receiving meshes by one value per receiver (fractions, means, irradiation) on
 * sunlit's palette; returns the range used and a legend element (null without a document). */
export function colourByValues(
  model: Model,
  values: ArrayLike<number>,
  options?: { min?: number; max?: number; label?: string },
): { min: number; max: number; legend: HTMLElement | null };

/** The palette as a legend element, ends labelled min and max. */
export function legend(min: number, max: number, label?: string): HTMLElement;

/** What paintMap returns: the cells' Mesh (add it to the scene), the range its colours span,
 * a legend element (null without a document), and a recolouring of the same cells. */
export interface PaintedMap {
  mesh: any;
  min: number;
  max: number;
  legend: HTMLElement | null;
  values: ArrayLike<number>;
  /** New values for the same points (e.g. the same grid lit at another instant). */
  update(values: ArrayLike<number>): PaintedMap;
}

/** Paints engine.map's answer on the receivers: a square cell per point (side `size`, default the
 * map's spacing) coloured per vertex, unlit; a lit map shows sunlit's own shadow pattern.
 * `THREE`: the app's three module. `yUp` (default true, fromThree's axes). */
export function paintMap(
  THREE: any,
  map: SunlitMap,
  options?: { size?: number; lift?: number; yUp?: boolean; min?: number; max?: number; label?: string },
): PaintedMap;
