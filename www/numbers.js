// The numbers under each view: a table of the stats the library reports (the CLI's --stats keys)
// and the triangle-angle histogram as a small bar chart.

const fmt = (v, digits = 3) => v === null || v === undefined ? '—'
  : typeof v === 'boolean' ? (v ? 'yes' : 'no')
  : Number.isInteger(v) ? v.toLocaleString('en') : Number(v).toPrecision(digits);

/** Rows of [label, stats key], in the order shown; keys a method does not report are skipped. */
const ROWS = [
  ['triangles', 'triangles'], ['vertices', 'vertices'], ['quads', 'quads'],
  ['closed manifold', 'closed_manifold'], ['Euler characteristic', 'euler'], ['components', 'components'],
  ['max distance', 'dist_max'], ['RMS distance', 'dist_rms'],
  ['normal deviation p95 (°)', 'normal_dev_deg_p95'],
  ['  at sharp edges (°)', 'crease_normal_dev_deg_p95'],
  ['worst face (°)', 'face_normal_dev_deg_max'],
  ['crossing pairs', 'self_intersections'],
  ['smallest angle (°)', 'min_angle_deg'], ['largest angle (°)', 'max_angle_deg'],
  ['feature edges', 'feature_edges'],
  ['octree leaves', 'octree_leaves'], ['dual cells', 'dual_cells'],
  ['meshing (ms)', 'ms_total'],
];

/** Table rows (`tr[data-key=label]`) for `stats`, then one per meshing phase. */
export function statsRows(stats) {
  // Quads are counted (0) for every method; only the quad mesher has any.
  const shown = ([, key]) => key in stats && !(key === 'quads' && stats.quads === 0);
  const rows = ROWS.filter(shown).map(([label, key]) => [label, stats[key]]);
  for (const [phase, ms] of Object.entries(stats.phases_ms ?? {})) rows.push([`  ${phase} (ms)`, ms]);
  return rows.map(([label, value]) => {
    const tr = document.createElement('tr');
    tr.dataset.key = label.trim();
    const name = document.createElement('td');
    name.textContent = label;
    const cell = document.createElement('td');
    cell.textContent = fmt(value);
    tr.append(name, cell);
    return tr;
  });
}

/** Bars of `counts` (5° bins from 0° to 180°) scaled to the tallest; an empty chart without data. */
export function drawHistogram(canvas, counts) {
  const ctx = canvas.getContext('2d');
  const { width: w, height: h } = canvas;
  ctx.clearRect(0, 0, w, h);
  canvas.dataset.bins = counts ? counts.filter((c) => c > 0).length : 0;
  if (!counts || counts.length === 0) return;
  const top = Math.max(...counts, 1);
  const axis = 14;
  const bar = w / counts.length;
  ctx.fillStyle = '#4f86c6';
  counts.forEach((c, i) => {
    const height = (h - axis - 2) * (c / top);
    ctx.fillRect(i * bar + 0.5, h - axis - height, Math.max(bar - 1, 1), height);
  });
  ctx.fillStyle = '#5c6670';
  ctx.font = '10px system-ui, sans-serif';
  for (const deg of [0, 60, 120, 180]) {
    const x = Math.min((deg / 180) * w, w - 16);
    ctx.fillText(`${deg}°`, x, h - 2);
  }
}
