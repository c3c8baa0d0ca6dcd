#!/usr/bin/env python3
"""Measures max distance to the true surface against triangle count for MC, EMC, EMC followed by
decimation, and DMC on the same scenes, and draws the curves as one SVG (docs/error-curve.svg,
shown in the README) plus a Markdown table on stdout.

Every point is one run of the release CLI with `--stats`; `dist_max` is the stats' max distance
(vertices, centroids and points halfway to the corners, projected onto the true surface), given
here as a percentage of the scene's bounding-box diagonal.

    cargo build --release && python3 scripts/error_curve.py [docs/error-curve.svg]
"""

import json
import math
import subprocess
import sys

BIN = "target/release/isoforge"
SCENES = [("cube_minus_sphere", "cube minus a ball"), ("fandisk", "fandisk")]
RESOLUTIONS = [16, 24, 32, 48, 64, 96, 128]
DECIMATE_RES = 128
DECIMATE_TARGETS = [40000, 20000, 10000, 5000, 2500, 1200]
SERIES = [
    ("MC", "#888888", "circle"),
    ("DMC", "#d9822b", "diamond"),
    ("EMC", "#2b6cd9", "square"),
    ("EMC + decimation", "#2a9d4b", "triangle"),
]


def stats(scene, args):
    out = subprocess.run(
        [BIN, "mesh", "--scene", scene, "--stats", "--no-intersections", *args],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    return json.loads(out)


# The diagonal of each scene's meshing bounds (src/scenes.rs).
DIAGONALS = {"cube_minus_sphere": math.sqrt(3 * 2.0**2), "fandisk": math.sqrt(1.8**2 + 1.2**2 + 1.1**2)}


def measure(scene):
    diag = DIAGONALS[scene]
    points = {name: [] for name, _, _ in SERIES}
    for res in RESOLUTIONS:
        for name, method in [("MC", "mc"), ("EMC", "emc"), ("DMC", "dmc")]:
            s = stats(scene, ["--method", method, "--res", str(res)])
            points[name].append((s["triangles"], 100 * s["dist_max"] / diag, f"res {res}"))
    for target in DECIMATE_TARGETS:
        s = stats(scene, ["--method", "emc", "--res", str(DECIMATE_RES), "--decimate", str(target)])
        points["EMC + decimation"].append((s["triangles"], 100 * s["dist_max"] / diag, f"res {DECIMATE_RES} → {target}"))
    return points


def marker(shape, x, y, colour):
    r = 4
    if shape == "circle":
        return f'<circle cx="{x:.1f}" cy="{y:.1f}" r="{r}" fill="{colour}"/>'
    if shape == "square":
        return f'<rect x="{x - r:.1f}" y="{y - r:.1f}" width="{2 * r}" height="{2 * r}" fill="{colour}"/>'
    if shape == "diamond":
        return (f'<polygon points="{x:.1f},{y - r - 1:.1f} {x + r + 1:.1f},{y:.1f} {x:.1f},{y + r + 1:.1f} '
                f'{x - r - 1:.1f},{y:.1f}" fill="{colour}"/>')
    return (f'<polygon points="{x:.1f},{y - r - 1:.1f} {x + r + 1:.1f},{y + r:.1f} {x - r - 1:.1f},{y + r:.1f}" '
            f'fill="{colour}"/>')


def panel(title, points, left, top, width, height):
    xs = [p[0] for series in points.values() for p in series]
    ys = [p[1] for series in points.values() for p in series]
    x0, x1 = 10 ** math.floor(math.log10(min(xs))), 10 ** math.ceil(math.log10(max(xs)))
    y0, y1 = 10 ** math.floor(math.log10(min(ys))), 10 ** math.ceil(math.log10(max(ys)))

    def px(x):
        return left + width * (math.log10(x) - math.log10(x0)) / (math.log10(x1) - math.log10(x0))

    def py(y):
        return top + height * (1 - (math.log10(y) - math.log10(y0)) / (math.log10(y1) - math.log10(y0)))

    out = [f'<text x="{left + width / 2}" y="{top - 10}" text-anchor="middle" font-weight="bold">{title}</text>',
           f'<rect x="{left}" y="{top}" width="{width}" height="{height}" fill="none" stroke="#444"/>']
    decade = x0
    while decade <= x1:
        x = px(decade)
        out.append(f'<line x1="{x:.1f}" y1="{top}" x2="{x:.1f}" y2="{top + height}" stroke="#ddd"/>')
        out.append(f'<text x="{x:.1f}" y="{top + height + 16}" text-anchor="middle">{decade:,}</text>')
        decade *= 10
    decade = y0
    while decade <= y1 * 1.0001:
        y = py(decade)
        out.append(f'<line x1="{left}" y1="{y:.1f}" x2="{left + width}" y2="{y:.1f}" stroke="#ddd"/>')
        out.append(f'<text x="{left - 6}" y="{y + 4:.1f}" text-anchor="end">{decade:g} %</text>')
        decade *= 10
    out.append(f'<text x="{left + width / 2}" y="{top + height + 34}" text-anchor="middle">triangles</text>')
    for name, colour, shape in SERIES:
        series = sorted(points[name])
        path = " ".join(f"{px(x):.1f},{py(y):.1f}" for x, y, _ in series)
        out.append(f'<polyline points="{path}" fill="none" stroke="{colour}" stroke-width="1.5"/>')
        out.extend(marker(shape, px(x), py(y), colour) for x, y, _ in series)
    return out


def svg(measured):
    width, height, panel_w, panel_h = 1060, 400, 340, 280
    body = ['<rect width="100%" height="100%" fill="white"/>',
            f'<text x="20" y="{60 + panel_h / 2}" transform="rotate(-90 20 {60 + panel_h / 2})" '
            'text-anchor="middle">max distance (% of the diagonal)</text>']
    for n, (scene, title) in enumerate(SCENES):
        body += panel(title, measured[scene], 90 + n * (panel_w + 70), 50, panel_w, panel_h)
    legend_x = 90 + 2 * (panel_w + 70) - 30
    for n, (name, colour, shape) in enumerate(SERIES):
        y = 70 + 22 * n
        body.append(marker(shape, legend_x, y, colour))
        body.append(f'<text x="{legend_x + 12}" y="{y + 4}">{name}</text>')
    body.append(f'<text x="{legend_x - 6}" y="{70 + 22 * len(SERIES) + 20}" font-size="11">MC, EMC, DMC: '
                f'res {RESOLUTIONS[0]}–{RESOLUTIONS[-1]}</text>')
    body.append(f'<text x="{legend_x - 6}" y="{70 + 22 * len(SERIES) + 36}" font-size="11">decimation: '
                f'EMC at {DECIMATE_RES}</text>')
    return (f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
            f'font-family="sans-serif" font-size="12">\n' + "\n".join(body) + "\n</svg>\n")


def main():
    target = sys.argv[1] if len(sys.argv) > 1 else "docs/error-curve.svg"
    measured = {scene: measure(scene) for scene, _ in SCENES}
    with open(target, "w", encoding="utf-8") as f:
        f.write(svg(measured))
    print("| scene | method | setting | triangles | max distance (% of diagonal) |")
    print("|---|---|---|---:|---:|")
    for scene, title in SCENES:
        for name, _, _ in SERIES:
            for tris, err, setting in measured[scene][name]:
                print(f"| {title} | {name} | {setting} | {tris:,} | {err:.4f} |")


if __name__ == "__main__":
    main()
