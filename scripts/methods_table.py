#!/usr/bin/env python3
"""Prints the README's table of MC, EMC and DMC side by side: per scene, each method's triangles,
max distance to the true surface (the stats' `dist_max`, in the scene's units) and time (best of
three runs, one thread, end to end from the formula, no analysis counted), at 64 cells (DMC at
depth 6, its finest cells the same size).

    cargo build --release && python3 scripts/methods_table.py
"""

from error_curve import stats as cli_stats

SCENES = ["sphere", "cube_minus_sphere", "fandisk", "rocket", "thin_room", "gear"]
METHODS = ["mc", "emc", "dmc"]
RUNS = 3


def stats(scene, method):
    return cli_stats(scene, ["--method", method, "--res", "64", "--threads", "1"])


def thousands(n):
    return f"{n:,}".replace(",", " ")


def main():
    header = " | ".join(f"{m.upper()}: triangles · max distance · ms" for m in METHODS)
    print(f"| scene | {header} |")
    print("|---" + "|---:" * len(METHODS) + "|")
    for scene in SCENES:
        cells = []
        for method in METHODS:
            runs = [stats(scene, method) for _ in range(RUNS)]
            ms = min(r["ms_total"] for r in runs)
            s = runs[0]
            dist = "—" if s["dist_max"] is None else f"{s['dist_max']:.4f}"
            cells.append(f"{thousands(s['triangles'])} · {dist} · {ms:.0f}")
        print(f"| `{scene}` | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
