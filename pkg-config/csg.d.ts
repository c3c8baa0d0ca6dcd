// A chainable builder for the CSG JSON accepted by meshCsg / compileCsg.
//
//   import { sphere, box } from "isoforge/csg";
//   const part = sphere(1).subtract(box(0.5, 0.5, 2).rotate([1, 0, 0], 30)).translate([0, 0, 0.2]);
//   const mesh = meshCsg(part, { method: "emc" });
//
// Each node means the language function of the same name (README, "Language"). Shapes are
// immutable: every method returns a new one. Arguments are checked when the node is built
// (a TypeError names the bad one).

import type { CsgNode } from "./isoforge.js";

export type { CsgNode };

/** Three numbers: a point, an offset, an axis or a normal. */
export type Vec3 = [number, number, number] | Float32Array | Float64Array;

/** A shape or a plain CsgNode object. */
export type ShapeLike = CsgShape | CsgNode;

/** An immutable CSG tree. */
export class CsgShape {
  private constructor(node: CsgNode);
  /** The plain CsgNode object. */
  readonly node: CsgNode;
  /** The plain CsgNode object: what `JSON.stringify` and `meshCsg` see. */
  toJSON(): CsgNode;
  /** The JSON text of the tree. */
  toString(): string;
  /** `union(this, ...others)`: the minimum of the distances. */
  union(...others: ShapeLike[]): CsgShape;
  /** `intersect(this, ...others)`: the maximum of the distances. */
  intersect(...others: ShapeLike[]): CsgShape;
  /** `subtract(this, other)`: this with other cut away. */
  subtract(other: ShapeLike): CsgShape;
  /** `smooth_union(this, other, k)`: union blended over a width k > 0. */
  smoothUnion(other: ShapeLike, k: number): CsgShape;
  /** `smooth_intersect(this, other, k)`: intersection blended over a width k > 0. */
  smoothIntersect(other: ShapeLike, k: number): CsgShape;
  /** `smooth_subtract(this, other, k)`: subtraction blended over a width k > 0. */
  smoothSubtract(other: ShapeLike, k: number): CsgShape;
  /** `shell(this, t)` = |this| - t: a hollow skin of thickness 2t around the surface. */
  shell(thickness: number): CsgShape;
  /** `offset(this, d)` = this - d: grown by d (shrunk for d < 0). */
  offset(distance: number): CsgShape;
  /** `translate(this, dx, dy, dz)`: moved by the offset. */
  translate(offset: Vec3): CsgShape;
  /** `rotate(this, ax, ay, az, degrees)`: turned about the axis through the origin (right-hand rule). */
  rotate(axis: Vec3, degrees: number): CsgShape;
  /** `scale(this, s)` = s·this(p/s): uniformly scaled about the origin. */
  scale(factor: number): CsgShape;
  /** `mirror_x(this)` = this(|x|, y, z): the x > 0 half mirrored onto x < 0. */
  mirrorX(): CsgShape;
  /** `mirror_y(this)` = this(x, |y|, z). */
  mirrorY(): CsgShape;
  /** `mirror_z(this)` = this(x, y, |z|). */
  mirrorZ(): CsgShape;
}

/** `sphere(r)`: centred at the origin. */
export function sphere(radius: number): CsgShape;
/** `box(hx, hy, hz)`: centred at the origin, half extents along x, y, z. */
export function box(hx: number, hy: number, hz: number): CsgShape;
/** `rounded_box(hx, hy, hz, r)`: outer half extents, edges rounded with radius r. */
export function roundedBox(hx: number, hy: number, hz: number, radius: number): CsgShape;
/** `cylinder(r, h)`: axis z, from z = -halfHeight to z = halfHeight. */
export function cylinder(radius: number, halfHeight: number): CsgShape;
/** `cone(r, h)`: base of radius r in the plane z = 0, apex at z = h. */
export function cone(radius: number, height: number): CsgShape;
/** `torus(R, r)`: around the z axis. */
export function torus(major: number, minor: number): CsgShape;
/** `capsule(ax, ay, az, bx, by, bz, r)`: the segment a–b thickened by r. */
export function capsule(a: Vec3, b: Vec3, radius: number): CsgShape;
/** `plane(nx, ny, nz, d)` = n·p - d with n normalised: the half-space below the plane is inside. */
export function plane(normal: Vec3, distance: number): CsgShape;
/** `union(a, …)`: at least one shape. */
export function union(...shapes: ShapeLike[]): CsgShape;
/** `intersect(a, …)`: at least one shape. */
export function intersect(...shapes: ShapeLike[]): CsgShape;
/** `subtract(a, b)`: a with b cut away. */
export function subtract(a: ShapeLike, b: ShapeLike): CsgShape;
/** `smooth_union(a, b, k)`. */
export function smoothUnion(a: ShapeLike, b: ShapeLike, k: number): CsgShape;
/** `smooth_intersect(a, b, k)`. */
export function smoothIntersect(a: ShapeLike, b: ShapeLike, k: number): CsgShape;
/** `smooth_subtract(a, b, k)`. */
export function smoothSubtract(a: ShapeLike, b: ShapeLike, k: number): CsgShape;
/** Wraps a CsgNode object or its JSON text so it can be chained. */
export function fromJSON(node: CsgNode | string): CsgShape;

/** @deprecated The old name of CsgShape (it clashed with the compiled `Shape` of "isoforge"). */
export { CsgShape as Shape };
