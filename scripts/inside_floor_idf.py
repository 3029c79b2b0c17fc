"""Writes a 20-room office floor as an EnergyPlus IDF, for the `map --inside --study leed-ase`
benchmark (docs/maps.md): two rows of ten rooms, 9 m wide (x) and 10 m deep, 3 m high, each with
one 7 m x 1.8 m window (sill 0.9 m) in its outside wall and a 1 m overhang over it; the south row
faces south, the north row north. Walls between rooms are Adiabatic (each room keeps its own copy).
Usage: python3 scripts/inside_floor_idf.py OUT.idf
"""
import sys

W, D, H = 9.0, 10.0, 3.0
ROOMS = 10


def surface(name, kind, zone, boundary, corners):
    sun = "SunExposed,WindExposed" if boundary == "Outdoors" else "NoSun,NoWind"
    v = ",".join(f"{x:g},{y:g},{z:g}" for x, y, z in corners)
    return f"BuildingSurface:Detailed,{name},{kind},Opaque,{zone},,{boundary},,{sun},,{len(corners)},{v};\n"


def room(i, row):
    x0, x1 = i * W, (i + 1) * W
    y0, y1 = (0.0, D) if row == "S" else (D, 2 * D)
    z = f"R{row}{i:02d}"
    out = f"Zone,{z},0,0,0,0;\n"
    south_out = "Outdoors" if row == "S" else "Adiabatic"
    north_out = "Outdoors" if row == "N" else "Adiabatic"
    west_out = "Outdoors" if i == 0 else "Adiabatic"
    east_out = "Outdoors" if i == ROOMS - 1 else "Adiabatic"
    out += surface(f"{z}_S", "Wall", z, south_out, [(x0, y0, H), (x0, y0, 0), (x1, y0, 0), (x1, y0, H)])
    out += surface(f"{z}_N", "Wall", z, north_out, [(x1, y1, H), (x1, y1, 0), (x0, y1, 0), (x0, y1, H)])
    out += surface(f"{z}_E", "Wall", z, east_out, [(x1, y0, H), (x1, y0, 0), (x1, y1, 0), (x1, y1, H)])
    out += surface(f"{z}_W", "Wall", z, west_out, [(x0, y1, H), (x0, y1, 0), (x0, y0, 0), (x0, y0, H)])
    out += surface(f"{z}_Floor", "Floor", z, "Ground", [(x1, y0, 0), (x0, y0, 0), (x0, y1, 0), (x1, y1, 0)])
    out += surface(f"{z}_Roof", "Roof", z, "Outdoors", [(x0, y0, H), (x1, y0, H), (x1, y1, H), (x0, y1, H)])
    a, b = x0 + 1.0, x1 - 1.0
    lo, hi = 0.9, 2.7
    if row == "S":
        win = [(a, y0, hi), (a, y0, lo), (b, y0, lo), (b, y0, hi)]
        base, oy = f"{z}_S", y0 - 1.0
        over = [(a - 0.5, y0, 2.8), (a - 0.5, oy, 2.8), (b + 0.5, oy, 2.8), (b + 0.5, y0, 2.8)]
    else:
        win = [(b, y1, hi), (b, y1, lo), (a, y1, lo), (a, y1, hi)]
        base, oy = f"{z}_N", y1 + 1.0
        over = [(a - 0.5, y1, 2.8), (b + 0.5, y1, 2.8), (b + 0.5, oy, 2.8), (a - 0.5, oy, 2.8)]
    v = ",".join(f"{x:g},{y:g},{z_:g}" for x, y, z_ in win)
    out += f"FenestrationSurface:Detailed,{z}_Win,Window,Glass,{base},,,,1,4,{v};\n"
    v = ",".join(f"{x:g},{y:g},{z_:g}" for x, y, z_ in over)
    out += f"Shading:Building:Detailed,{z}_Overhang,,4,{v};\n"
    return out


def main():
    idf = (
        "Version,25.2;\nBuilding,Floor,0,Suburbs,0.04,0.4,FullInteriorAndExterior,25,6;\n"
        "GlobalGeometryRules,UpperLeftCorner,Counterclockwise,Relative;\n"
        "Construction,Opaque,Layer;\nConstruction,Glass,SimpleGlass;\n"
        "WindowMaterial:SimpleGlazingSystem,SimpleGlass,1.8,0.4,0.6;\n"
    )
    for row in ("S", "N"):
        for i in range(ROOMS):
            idf += room(i, row)
    with open(sys.argv[1], "w") as f:
        f.write(idf)


if __name__ == "__main__":
    main()
