// A chainable builder for the CSG JSON accepted by meshCsg / compileCsg (import from "isoforge/csg").
// Every method returns a new immutable node; `toJSON()` gives the plain CsgNode object, so
// `JSON.stringify(shape)` and `meshCsg(shape)` both work directly.

const vec3 = (v, what) => {
  if (!Array.isArray(v) && !(ArrayBuffer.isView(v) && v.length !== undefined)) {
    throw new TypeError(`${what} must be an [x, y, z] array`);
  }
  if (v.length !== 3) throw new TypeError(`${what} must have 3 numbers, got ${v.length}`);
  return [num(v[0], what), num(v[1], what), num(v[2], what)];
};

const num = (x, what) => {
  if (typeof x !== 'number' || !Number.isFinite(x)) throw new TypeError(`${what} must be a finite number, got ${x}`);
  return x;
};

const node = (x, what) => {
  if (x instanceof CsgShape) return x.node;
  if (x && typeof x === 'object' && typeof x.op === 'string') return x;
  throw new TypeError(`${what} must be a CsgShape or a CsgNode object`);
};

/** An immutable CSG tree; build one with the shape functions below. */
export class CsgShape {
  constructor(csgNode) {
    this.node = csgNode;
    Object.freeze(this);
  }

  /** The plain CsgNode object (what JSON.stringify and meshCsg see). */
  toJSON() {
    return this.node;
  }

  /** The JSON text of the tree. */
  toString() {
    return JSON.stringify(this.node);
  }

  union(...others) {
    return union(this, ...others);
  }

  intersect(...others) {
    return intersect(this, ...others);
  }

  subtract(other) {
    return subtract(this, other);
  }

  smoothUnion(other, k) {
    return smoothUnion(this, other, k);
  }

  smoothIntersect(other, k) {
    return smoothIntersect(this, other, k);
  }

  smoothSubtract(other, k) {
    return smoothSubtract(this, other, k);
  }

  shell(thickness) {
    return new CsgShape({ op: 'shell', shape: this.node, thickness: num(thickness, 'shell thickness') });
  }

  offset(distance) {
    return new CsgShape({ op: 'offset', shape: this.node, distance: num(distance, 'offset distance') });
  }

  translate(offset) {
    return new CsgShape({ op: 'translate', shape: this.node, offset: vec3(offset, 'translate offset') });
  }

  rotate(axis, degrees) {
    return new CsgShape({ op: 'rotate', shape: this.node, axis: vec3(axis, 'rotate axis'), degrees: num(degrees, 'rotate degrees') });
  }

  scale(factor) {
    return new CsgShape({ op: 'scale', shape: this.node, factor: num(factor, 'scale factor') });
  }

  mirrorX() {
    return new CsgShape({ op: 'mirror_x', shape: this.node });
  }

  mirrorY() {
    return new CsgShape({ op: 'mirror_y', shape: this.node });
  }

  mirrorZ() {
    return new CsgShape({ op: 'mirror_z', shape: this.node });
  }
}

export const sphere = (radius) => new CsgShape({ op: 'sphere', radius: num(radius, 'sphere radius') });

export const box = (hx, hy, hz) =>
  new CsgShape({ op: 'box', half: [num(hx, 'box hx'), num(hy, 'box hy'), num(hz, 'box hz')] });

export const roundedBox = (hx, hy, hz, radius) => new CsgShape({
  op: 'rounded_box',
  half: [num(hx, 'rounded box hx'), num(hy, 'rounded box hy'), num(hz, 'rounded box hz')],
  radius: num(radius, 'rounded box radius'),
});

export const cylinder = (radius, halfHeight) =>
  new CsgShape({ op: 'cylinder', radius: num(radius, 'cylinder radius'), half_height: num(halfHeight, 'cylinder half height') });

export const cone = (radius, height) =>
  new CsgShape({ op: 'cone', radius: num(radius, 'cone radius'), height: num(height, 'cone height') });

export const torus = (major, minor) =>
  new CsgShape({ op: 'torus', major: num(major, 'torus major radius'), minor: num(minor, 'torus minor radius') });

export const capsule = (a, b, radius) =>
  new CsgShape({ op: 'capsule', a: vec3(a, 'capsule a'), b: vec3(b, 'capsule b'), radius: num(radius, 'capsule radius') });

export const plane = (normal, distance) =>
  new CsgShape({ op: 'plane', normal: vec3(normal, 'plane normal'), distance: num(distance, 'plane distance') });

const nary = (op) => (...shapes) => {
  if (shapes.length === 0) throw new TypeError(`${op} needs at least one shape`);
  return new CsgShape({ op, args: shapes.map((s, i) => node(s, `${op} argument ${i + 1}`)) });
};

export const union = nary('union');
export const intersect = nary('intersect');

export const subtract = (a, b) =>
  new CsgShape({ op: 'subtract', args: [node(a, 'subtract argument 1'), node(b, 'subtract argument 2')] });

const smooth = (op) => (a, b, k) =>
  new CsgShape({ op, args: [node(a, `${op} argument 1`), node(b, `${op} argument 2`)], k: num(k, `${op} k`) });

export const smoothUnion = smooth('smooth_union');
export const smoothIntersect = smooth('smooth_intersect');
export const smoothSubtract = smooth('smooth_subtract');

/** Wraps a plain CsgNode object (e.g. parsed JSON) so it can be chained. */
export const fromJSON = (csgNode) => new CsgShape(node(typeof csgNode === 'string' ? JSON.parse(csgNode) : csgNode, 'fromJSON argument'));

/** The old name of CsgShape (it clashed with the compiled `Shape` of "isoforge"). */
export { CsgShape as Shape };
