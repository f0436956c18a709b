#!/usr/bin/env python3
"""Writes the two NX CLSF reproductions of this folder (README.md says why
they are reproductions): Siemens NX's record forms as NX writes them for an
inch part — no UNITS record, no SPINDL record, FEDRAT/IPM, TOOL PATH,
TLDATA/MILL, MSYS, PAINT, LOAD/TOOL then SELECT/TOOL, END-OF-PATH; lengths
with 4 decimals, tool axes with 7, the axis written only when it changes.

  nx_variable_contour_ball_in.cls  5-axis variable-axis finish with a
      0.25 in ball mill over a convex cylinder z = sqrt(Rc^2 - x^2) - Rc
      (Rc = 2 in): the axis along the surface normal, so the tip point is the
      surface point; zig-zag rows y = 0 ... 1.5 in, x = -0.9 ... 0.9 in.
  nx_profile_bull_in.cls  planar profile with a 0.5 in bull-nose end mill
      (corner 0.06 in) around a 2 x 1.5 in block with 0.25 in corners, two
      levels (-0.125, -0.25 in), the tool centre 0.25 in off the wall.

Run from this folder: python3 make_nx_clsf.py (the output is committed)."""

import math


def num(v, places):
    text = f"{v:.{places}f}"
    return text[1:] if text.startswith("-") and float(text) == 0.0 else text


def goto(p, axis=None):
    xyz = ",".join(num(c, 4) for c in p)
    if axis is None:
        return f"GOTO/{xyz}"
    return f"GOTO/{xyz}," + ",".join(num(c, 7) for c in axis)


def variable_contour():
    rc, step, rows = 2.0, 0.1, 16
    xs = [round(-0.9 + step * n, 10) for n in range(19)]

    def surface(x, y):
        z = math.sqrt(rc * rc - x * x) - rc
        return (x, y, z), (x / rc, 0.0, (z + rc) / rc)

    lines = [
        "TOOL PATH/VARIABLE_CONTOUR,TOOL,BALL_MILL_0.25",
        "TLDATA/MILL,0.2500,0.1250,2.0000,0.0000,0.0000",
        "MSYS/0.0000,0.0000,0.0000,1.0000000,0.0000000,0.0000000,0.0000000,1.0000000,0.0000000",
        "$$ centerline data",
        "PAINT/PATH",
        "PAINT/SPEED,10",
        "LOAD/TOOL,3,ADJUST,3",
        "SELECT/TOOL,3",
        "PAINT/COLOR,186",
    ]
    points = []
    for row in range(rows):
        row_xs = xs if row % 2 == 0 else list(reversed(xs))
        points += [surface(x, step * row) for x in row_xs]
    (p0, n0), (pl, nl) = points[0], points[-1]
    along = lambda p, n, d: tuple(p[i] + d * n[i] for i in range(3))
    lines += ["RAPID", goto(along(p0, n0, 1.0), n0), "PAINT/COLOR,211", "RAPID",
              goto(along(p0, n0, 0.1)), "PAINT/COLOR,42", "FEDRAT/IPM,20.0000", goto(p0),
              "PAINT/COLOR,31", "FEDRAT/IPM,40.0000"]
    last_axis = n0
    for p, n in points[1:]:
        changed = any(abs(a - b) > 5e-8 for a, b in zip(n, last_axis))
        lines.append(goto(p, n if changed else None))
        last_axis = n
    lines += ["PAINT/COLOR,37", goto(along(pl, nl, 0.1)), "PAINT/COLOR,211", "RAPID",
              goto(along(pl, nl, 1.0)), "PAINT/SPEED,10", "PAINT/TOOL,NOMORE", "END-OF-PATH"]
    return lines


def profile_bull():
    lines = [
        "TOOL PATH/PLANAR_PROFILE,TOOL,MILL_0.5_R0.06",
        "TLDATA/MILL,0.5000,0.0600,3.0000,0.0000,0.0000",
        "MSYS/0.0000,0.0000,0.0000,1.0000000,0.0000000,0.0000000,0.0000000,1.0000000,0.0000000",
        "$$ centerline data",
        "PAINT/PATH",
        "PAINT/SPEED,10",
        "LOAD/TOOL,1,ADJUST,1",
        "SELECT/TOOL,1",
        "PAINT/COLOR,186",
        "RAPID",
        goto((1.0, -0.75, 1.0), (0.0, 0.0, 1.0)),
        "PAINT/COLOR,211",
        "RAPID",
        goto((1.0, -0.75, 0.1)),
        "PAINT/COLOR,42",
        "FEDRAT/IPM,15.0000",
    ]

    def circle(cx, cy, z):  # clockwise seen from +z: the axis is -z
        return (f"CIRCLE/{num(cx, 4)},{num(cy, 4)},{num(z, 4)},0.0000000,0.0000000,-1.0000000,"
                "0.5000,0.0020,0.5000,0.5000,0.0600")

    for level, z in enumerate((-0.125, -0.25)):
        lines.append(goto((1.0, -0.75, z)))
        if level == 0:
            lines += ["PAINT/COLOR,31", "FEDRAT/IPM,30.0000"]
        lines += [goto((1.0, -0.25, z)), goto((0.25, -0.25, z)), circle(0.25, 0.25, z),
                  goto((-0.25, 0.25, z)), goto((-0.25, 1.25, z)), circle(0.25, 1.25, z),
                  goto((0.25, 1.75, z)), goto((1.75, 1.75, z)), circle(1.75, 1.25, z),
                  goto((2.25, 1.25, z)), goto((2.25, 0.25, z)), circle(1.75, 0.25, z),
                  goto((1.75, -0.25, z)), goto((1.0, -0.25, z)), goto((1.0, -0.75, z))]
    lines += ["PAINT/COLOR,37", goto((1.0, -0.75, 0.1)), "PAINT/COLOR,211", "RAPID",
              goto((1.0, -0.75, 1.0)), "PAINT/SPEED,10", "PAINT/TOOL,NOMORE", "END-OF-PATH"]
    return lines


if __name__ == "__main__":
    for name, lines in (("nx_variable_contour_ball_in.cls", variable_contour()),
                        ("nx_profile_bull_in.cls", profile_bull())):
        with open(name, "w", newline="\r\n") as f:  # NX writes CR LF
            f.write("\n".join(lines) + "\n")
