// Prints the README's angle histograms (5° bins, as the triangle-quality paper plots them) for the
// paper's three surfaces: plain MC, mcq's per-cell rules alone (the paper: no snapping, inner
// vertices left in their polygon) and mcq as shipped (snapping, projection).
// Usage: cargo build --release && node scripts/angle-histograms.mjs
import { execFileSync } from "node:child_process";

const bin = new URL("../target/release/isoforge", import.meta.url).pathname;
const surfaces = [
  ["sphere, 10³ points", ["--expr", "sphere(0.8)", "--res", "9"]],
  ["hyperboloid, 40³ cells", ["--expr", "x*x + y*y - z*z - 0.25", "--res", "40"]],
  ["grid with holes, 40³ cells", ["--expr", "cos(6.2832*x) + cos(6.2832*y) + cos(6.2832*z)", "--res", "40"]],
];
const variants = [
  ["MC", ["--method", "mc"]],
  ["per-cell (paper)", ["--method", "mcq", "--snap", "0", "--no-project"]],
  ["mcq", ["--method", "mcq"]],
];
for (const [name, input] of surfaces) {
  const stats = variants.map(([, v]) =>
    JSON.parse(execFileSync(bin, ["mesh", ...input, ...v, "--stats"], { encoding: "utf8" })),
  );
  console.log(`\n**${name}** (\`isoforge mesh ${input.join(" ")}\`)\n`);
  console.log(`| | ${variants.map((v) => v[0]).join(" | ")} |`);
  console.log(`|---|${variants.map(() => "---:").join("|")}|`);
  const row = (label, f) => console.log(`| ${label} | ${stats.map(f).join(" | ")} |`);
  row("triangles", (s) => s.triangles);
  row("closed manifold, χ", (s) => `${s.closed_manifold ? "yes" : `no (${s.boundary_edges} border edges)`}, ${s.euler}`);
  row("self-intersections", (s) => s.self_intersections);
  row("angles", (s) => `${s.min_angle_deg.toFixed(1)}°–${s.max_angle_deg.toFixed(1)}°`);
  row("dist_max", (s) => s.dist_max.toFixed(4));
  const used = stats.flatMap((s) => s.angle_histogram_5deg.map((n, i) => (n > 0 ? i : -1))).filter((i) => i >= 0);
  for (let b = Math.min(...used); b <= Math.max(...used); b++) {
    row(`${5 * b}–${5 * b + 5}°`, (s) => s.angle_histogram_5deg[b] || "");
  }
}
