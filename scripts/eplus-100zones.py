#!/usr/bin/env python3
"""The shading geometry of NREL/EnergyPlus testfiles/10x_incr_100zones1win10overhangsFullExIn.idf,
rebuilt from its pattern (the 1.18 MB file itself is not copied here), as a model EnergyPlus 25.2
and sunlit both read.

What the file holds (read in its stored text at commit 139e522d33c91409b1bf4413a5e4600b661cd7b0):
a 30.48 x 15.24 m block of 20 storeys of 3.048 m, five zones a storey (four perimeter zones 4.572 m
deep and a core), long axis east-west, Chicago O'Hare (41.98, -87.92, UTC-6), Timestep 6,
FullInteriorAndExterior, `ShadowCalculation, PixelCounting, Periodic, 7` (PixelCounting falls back
to PolygonClipping without a GPU), RunPeriod 2006 starting on a Sunday. Every facade of every storey
has one ribbon window (0.0254 m in from the wall's ends, sill 0.76 m, head 1.9812 m on the long
facades and 1.9833 m on the short ones) under ten overhangs 0.762 m deep at 2.286 m: 2.4384 m wide
at a pitch of 3.048 m on the south and north walls (0.3048 m from both ends), 1.2192 m wide at a
pitch of 1.46304 m on the west (from 0.54864 m north of its south end) and east walls (from
0.42672 m). The rebuild keeps that geometry in world coordinates and leaves out what cannot shade
(interior walls, floors and ceilings, HVAC, schedules).

    scripts/eplus-100zones.py [SHADOW_CALCULATION_UPDATE] > model.idf

SHADOW_CALCULATION_UPDATE is the file's own `Periodic, 7` unless given (e.g. `Timestep, 1`).
"""
import sys

STOREY, LONG, SHORT, DEPTH = 3.048, 30.48, 15.24, 0.762
SILL, OVERHANG_Z = 0.76, 2.286
HEAD_LONG, HEAD_SHORT = 1.98123539232053, 1.98327759197324
INSET = 0.0254


def vertices(points):
    lines = [f"  {len(points)},"]
    for i, (x, y, z) in enumerate(points):
        end = ";" if i + 1 == len(points) else ","
        lines.append(f"  {x:.6f}, {y:.6f}, {z:.6f}{end}")
    return "\n".join(lines)


def wall(name, zone, pts):
    return f"BuildingSurface:Detailed, {name}, Wall, WALL, {zone}, , Outdoors, , SunExposed, WindExposed, ,\n{vertices(pts)}\n"


def surface(name, kind, zone, boundary, pts):
    sun = "SunExposed, WindExposed" if boundary == "Outdoors" else "NoSun, NoWind"
    return f"BuildingSurface:Detailed, {name}, {kind}, {kind.upper()}, {zone}, , {boundary}, , {sun}, ,\n{vertices(pts)}\n"


def window(name, base, pts):
    return f"FenestrationSurface:Detailed, {name}, Window, GLASS, {base}, , , , 1,\n{vertices(pts)}\n"


def overhang(name, pts):
    return f"Shading:Building:Detailed, {name}, ,\n{vertices(pts)}\n"


def facade(storey, side):
    """Wall, window and overhangs of one facade of one storey (upper-left first, counter-clockwise
    seen from outside)."""
    z0 = storey * STOREY
    zone, name = f"F{storey:02}", f"F{storey:02}_{side}"
    top, head, sill, oz = z0 + STOREY, z0 + (HEAD_LONG if side in "SN" else HEAD_SHORT), z0 + SILL, z0 + OVERHANG_Z
    out = []
    # a, b: the wall's left and right ends seen from outside; along(s): s metres from a.
    if side == "S":
        a, b, out_dir = (0.0, 0.0), (LONG, 0.0), (0.0, -DEPTH)
    elif side == "N":
        a, b, out_dir = (LONG, SHORT), (0.0, SHORT), (0.0, DEPTH)
    elif side == "W":
        a, b, out_dir = (0.0, SHORT), (0.0, 0.0), (-DEPTH, 0.0)
    else:
        a, b, out_dir = (LONG, 0.0), (LONG, SHORT), (DEPTH, 0.0)
    length = LONG if side in "SN" else SHORT
    along = lambda s: (a[0] + (b[0] - a[0]) * s / length, a[1] + (b[1] - a[1]) * s / length)  # noqa: E731
    if side in "SN":
        width, starts = 2.4384, [0.3048 + 3.048 * i for i in range(10)]
    elif side == "W":
        # Measured from the south end, which is b here.
        width = 1.2192
        starts = [length - (0.54864 + 1.46304 * i) - width for i in range(10)]
    else:
        width, starts = 1.2192, [0.42672 + 1.46304 * i for i in range(10)]
    wall_name = f"{name}_WALL"
    out.append(wall(wall_name, zone, [(*a, top), (*a, z0), (*b, z0), (*b, top)]))
    w0, w1 = along(INSET), along(length - INSET)
    out.append(window(f"{name}_WIN", wall_name, [(*w0, head), (*w0, sill), (*w1, sill), (*w1, head)]))
    for i, s in enumerate(starts):
        p, q = along(s), along(s + width)
        po = (p[0] + out_dir[0], p[1] + out_dir[1])
        qo = (q[0] + out_dir[0], q[1] + out_dir[1])
        out.append(overhang(f"{name}_OVERHANG_{i}", [(*po, oz), (*p, oz), (*q, oz), (*qo, oz)]))
    return "".join(out)


def model(update):
    head = f"""Version, 25.2;
SimulationControl, No, No, No, No, Yes, No, 1;
Building, 100 ZONES REBUILT, 0, Suburbs, 0.04, 0.4, FullInteriorAndExterior, 25, 6;
Timestep, 6;
GlobalGeometryRules, UpperLeftCorner, Counterclockwise, World;
Site:Location, Chicago Ohare Intl Ap, 41.98, -87.92, -6, 201;
RunPeriod, Run Period 1, 1, 1, 2006, 12, 31, 2006, Sunday, No, No, No, Yes, Yes, No;
ShadowCalculation, PolygonClipping, {update}, 15000, SutherlandHodgman, 512, SimpleSkyDiffuseModeling, No;
Material:NoMass, INSULATION, MediumRough, 3.0, 0.9, 0.6, 0.6;
Construction, WALL, INSULATION;
Construction, ROOF, INSULATION;
Construction, FLOOR, INSULATION;
WindowMaterial:SimpleGlazingSystem, GLAZING, 3.12304483761242, 0.4, 0.31;
Construction, GLASS, GLAZING;
Output:Variable, *, Surface Outside Face Sunlit Fraction, Timestep;
"""
    parts = [head]
    for storey in range(20):
        # One zone a storey (the file has five): zones do not shade, and EnergyPlus wants more than one wall a zone.
        parts.append(f"Zone, F{storey:02};\n")
        for side in "SENW":
            parts.append(facade(storey, side))
    top = 20 * STOREY
    parts.append(surface("ROOF", "Roof", "F19", "Outdoors", [(0, SHORT, top), (0, 0, top), (LONG, 0, top), (LONG, SHORT, top)]))
    parts.append(surface("SLAB", "Floor", "F00", "Ground", [(0, 0, 0), (0, SHORT, 0), (LONG, SHORT, 0), (LONG, 0, 0)]))
    return "".join(parts)


if __name__ == "__main__":
    update = sys.argv[1] if len(sys.argv) > 1 else "Periodic, 7"
    sys.stdout.write(model(update))
