#!/usr/bin/env python3
"""Draw the README's measurement plots from the tools' JSON output (needs matplotlib).

    cargo run --release --example evaluate -- scenes/dev --sweep all --out-json target/sweeps.json
    cargo run --release --example scaling -- --out-json target/scaling.json
    python3 docs/plots.py --sweeps target/sweeps.json --scaling target/scaling.json

Writes docs/noise.png (accuracy against added depth noise), docs/robustness.png (every sweep
setting side by side) and docs/scaling.png (work and time against object pixels, per engine
capacity). Either input may be left out.
"""

import argparse
import json
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

DOCS = os.path.dirname(os.path.abspath(__file__))


def counts(totals):
    v = totals["verdicts"]
    return {
        "exact": v.get("exact", 0),
        "exact, weaker or correct none": v.get("exact", 0) + v.get("weaker", 0) + v.get("correct_none", 0),
        "strongest valid (object)": totals["strongest_valid_object"],
    }


def noise_plot(sweeps, path):
    rows = [r for r in sweeps if r["sweep"] in ("baseline", "noise")]
    rows.sort(key=lambda r: r["degradation"]["sigma_mm"])
    sigma = [r["degradation"]["sigma_mm"] for r in rows]
    scenes = max(r["totals"]["scenes"] + len(r["failed"]) for r in rows)
    dropout = max(r["degradation"]["extra_dropout"] for r in rows)
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4), dpi=110)
    for name, marker in zip(counts(rows[0]["totals"]), "os^"):
        left.plot(sigma, [counts(r["totals"])[name] for r in rows], marker=marker, label=name)
    left.set_xlabel("added depth noise sigma (mm)")
    left.set_ylabel(f"scenes (of {scenes})")
    left.set_ylim(0, scenes)
    left.set_xticks(sigma)
    left.grid(alpha=0.3)
    left.legend(fontsize=8)
    left.set_title("detection")
    fits = [
        ("completed", "completed", "o-"),
        ("visible", "visible points only", "s--"),
        ("reference_pixels", "ref 1: object pixels", "^:"),
        ("reference_truth", "ref 2: pixels + true symmetry", "v:"),
    ]
    for key, label, style in fits:
        right.plot(sigma, [100 * r["totals"][key]["f_score"] for r in rows], style, label=label)
    right.set_xlabel("added depth noise sigma (mm)")
    right.set_ylabel("mean F-score at 5 mm (%)")
    right.set_ylim(0, 100)
    right.set_xticks(sigma)
    right.grid(alpha=0.3)
    right.legend(fontsize=8)
    right.set_title("completion")
    fig.suptitle(
        f"Development scenes with added Gaussian depth noise (+{dropout * 100:.0f} % dropouts when sigma > 0)",
        fontsize=10,
    )
    fig.tight_layout()
    fig.savefig(path)
    print("wrote", path)


def robustness_plot(sweeps, path):
    labels = [r["setting"] for r in sweeps]
    names = list(counts(sweeps[0]["totals"]))
    scenes = max(r["totals"]["scenes"] + len(r["failed"]) for r in sweeps)
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(10, 6.5), dpi=110, sharex=True)
    width = 0.8 / len(names)
    xs = range(len(sweeps))
    for i, name in enumerate(names):
        top.bar([x + (i - 1) * width for x in xs], [counts(r["totals"])[name] for r in sweeps], width, label=name)
    top.set_ylabel(f"scenes (of {scenes})")
    top.set_ylim(0, scenes)
    top.grid(axis="y", alpha=0.3)
    top.legend(fontsize=8, ncol=3)
    bottom.plot(xs, [100 * r["totals"]["completed"]["f_score"] for r in sweeps], "o-", label="completed")
    bottom.plot(xs, [100 * r["totals"]["reference_pixels"]["f_score"] for r in sweeps], "^:", label="ref 1: object pixels")
    bottom.set_ylabel("mean F-score at 5 mm (%)")
    bottom.set_ylim(0, 100)
    bottom.grid(alpha=0.3)
    bottom.legend(fontsize=8)
    bottom.set_xticks(list(xs))
    bottom.set_xticklabels(labels, rotation=25, ha="right", fontsize=8)
    fig.suptitle("Development scenes under each robustness setting", fontsize=10)
    fig.tight_layout()
    fig.savefig(path)
    print("wrote", path)


def scaling_plot(scaling, path):
    rows = scaling["rows"]
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4), dpi=110)
    engines = list(dict.fromkeys(r["engine"] for r in rows))
    for obj, style in zip(sorted({r["object"] for r in rows}), ["-", "--", ":"]):
        for engine, marker, colour in zip(engines, "os^", ["C0", "C1", "C2"]):
            sel = sorted((r for r in rows if r["object"] == obj and r["engine"] == engine), key=lambda r: r["object_pixels"])
            px = [r["object_pixels"] for r in sel]
            label = f"{obj}, {engine}"
            left.plot(px, [r["total"]["work_units"] / 1e3 for r in sel], style, marker=marker, color=colour, label=label)
            right.plot(px, [r["total"]["wall_ms"] for r in sel], style, marker=marker, color=colour, label=label)
    for ax, ylabel in ((left, "work units (thousands)"), (right, "time (ms, fastest of runs)")):
        ax.set_xscale("log")
        ax.set_xlabel("object pixels")
        ax.set_ylabel(ylabel)
        ax.set_ylim(bottom=0)
        ax.grid(alpha=0.3, which="both")
    left.legend(fontsize=7)
    fig.suptitle(
        f"Cost of one whole search against object size ({scaling['width']}x{scaling['height']} camera, one thread)",
        fontsize=10,
    )
    fig.tight_layout()
    fig.savefig(path)
    print("wrote", path)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sweeps", help="evaluate --sweep ... --out-json output")
    parser.add_argument("--scaling", help="scaling --out-json output")
    parser.add_argument("--out", default=DOCS, help="folder for the PNGs (default: docs/)")
    args = parser.parse_args()
    if args.sweeps:
        with open(args.sweeps) as f:
            sweeps = json.load(f)["sweeps"]
        if any(r["sweep"] == "noise" for r in sweeps):
            noise_plot(sweeps, os.path.join(args.out, "noise.png"))
        robustness_plot(sweeps, os.path.join(args.out, "robustness.png"))
    if args.scaling:
        with open(args.scaling) as f:
            scaling_plot(json.load(f), os.path.join(args.out, "scaling.png"))


if __name__ == "__main__":
    main()
