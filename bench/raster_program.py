#!/usr/bin/python3
"""The long program of issue 31's speed target, and a job that runs it.

A 3-axis z-level raster as a CAM post writes a finishing path: passes along x
of 2 mm G1 segments, alternating, stepped over in y, seven layers 1 mm apart
in a 300 x 300 x 30 mm aluminium block at 0.5 mm resolution, a 10 mm 3-flute
flat end mill. Deterministic: the same arguments write the same bytes.

    bench/raster_program.py OUTDIR [--lines 100000] [--first N]

writes OUTDIR/raster.nc (the program, `--lines` lines in all) and
OUTDIR/raster.yaml (the job). `--first N` keeps the first N lines of the same
program (then a retract and M30), the shorter run that the memory of the long
one is compared with. Then, e.g.:

    /usr/bin/time -v build/robomill toolpath OUTDIR/raster.yaml --out OUTDIR/run
"""

import argparse
import math
import pathlib

SEGMENT_MM = 2.0
LENGTH_MM = 300.0
LAYERS = 7
TOP_MM = 30.0
LAYER_DEPTH_MM = 1.0
HEADER = [
    "%",
    "O1031 (RASTER, ISSUE 31 SPEED TARGET)",
    "G90 G94 G17 G21",
    "T1 M6",
    "S10000 M3",
    "G0 X0 Y0 Z40.",
]


def program(lines):
    segments = int(round(LENGTH_MM / SEGMENT_MM))
    # Each pass: its segments and the step-over; each layer: a plunge and a
    # return to the corner. The passes per layer fill the line budget.
    per_layer = (lines - len(HEADER) - 3) // LAYERS
    passes = max(1, (per_layer - 3) // (segments + 1))
    step_mm = LENGTH_MM / passes
    out = list(HEADER)
    for layer in range(LAYERS):
        z = TOP_MM - LAYER_DEPTH_MM * (layer + 1)
        out.append("G0 X0 Y0")
        out.append(f"G0 Z{z + 2.0:.3f}")
        out.append(f"G1 Z{z:.3f} F600.")
        for p in range(passes):
            y = step_mm * p
            if p > 0:
                out.append(f"G1 Y{y:.4f} F2400.")
            forward = p % 2 == 0
            for k in range(1, segments + 1):
                x = SEGMENT_MM * k if forward else LENGTH_MM - SEGMENT_MM * k
                out.append(f"G1 X{x:.3f} F2400.")
    out.append("G0 Z40.")
    out.append("M30")
    out.append("%")
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("outdir", type=pathlib.Path)
    parser.add_argument("--lines", type=int, default=100_000, help="lines of the whole program")
    parser.add_argument("--first", type=int, default=0, help="keep only the first N lines")
    args = parser.parse_args()
    text = program(args.lines)
    if args.first and args.first < len(text):
        text = text[: args.first] + ["G0 Z40.", "M30", "%"]
    args.outdir.mkdir(parents=True, exist_ok=True)
    (args.outdir / "raster.nc").write_text("\n".join(text) + "\n")
    (args.outdir / "raster.yaml").write_text(
        f"""# bench/raster_program.py {args.outdir} --lines {args.lines}"""
        + (f" --first {args.first}" if args.first else "")
        + f"""
name: raster ({len(text)} lines)
toolpath:
  file: raster.nc
  origin: [0, 0, 0]
  tools:
    T1: {{type: flat, diameter: 10 mm, teeth: 3, helix: 30 deg, overhang: 40 mm}}
  rapid_speed: 30000 mm/min
stock:
  box: {{min: [0, 0, 0], max: [{LENGTH_MM:g}, {LENGTH_MM:g}, {TOP_MM:g}]}}
  resolution: 0.5 mm
cutting:             # aluminium 7075 (examples/toolpath_pocket_gcode.yaml)
  law: linear
  Ktc: 796 N/mm^2
  Krc: 169 N/mm^2
  Kac: 223 N/mm^2
  Kte: 27.7 N/mm
  Kre: 15.4 N/mm
  Kae: 1.2 N/mm
"""
    )
    moves = sum(1 for line in text if line.startswith(("G1", "G0")))
    print(f"{args.outdir / 'raster.nc'}: {len(text)} lines, {moves} moves")


if __name__ == "__main__":
    main()
