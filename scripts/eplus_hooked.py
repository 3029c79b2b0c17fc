"""What scripts/eplus-interior-beam.py and scripts/eplus-interzone-transfer.py share: reading
EnergyPlus's outputs and feeding a hooked copy EnergyPlus's own sunlit fractions."""
import csv
import os


def columns(path):
    """An EnergyPlus (or sunlit) CSV's columns by upper-case header, the first (time) left out."""
    rows = list(csv.reader(open(path)))
    head = [h.strip().upper() for h in rows[0]]
    return {head[i]: [float(r[i]) for r in rows[1:] if i < len(r) and r[i].strip()] for i in range(1, len(head))}


def site(d):
    """A run's annual Total Site Energy (GJ) from its eplustbl.csv."""
    for line in open(os.path.join(d, "eplustbl.csv"), errors="replace"):
        f = line.split(",")
        if len(f) > 2 and f[1] == "Total Site Energy":
            return float(f[2])


def own_fractions(shading, hooked, clip, name, out):
    """The hooked copy re-pointed at EnergyPlus's reported fractions in sunlit's CSV layout,
    written to OUT as NAME-own.csv and NAME-own.idf; returns the IDF's path."""
    theirs = columns(os.path.join(clip, "eplusout.csv"))
    lines = open(shading).read().splitlines()
    names = [n.upper() for n in lines[0].split(",")[1:] if n]
    cols = [theirs[n + ":SURFACE OUTSIDE FACE SUNLIT FRACTION [](TIMESTEP)"] for n in names]
    text = [lines[0]] + [line.split(",")[0] + "".join(",%.8f" % c[r] for c in cols) for r, line in enumerate(lines[1:])]
    own = os.path.join(out, name + "-own.csv")
    open(own, "w").write("\n".join(text) + "\n")
    idf = open(hooked).read().replace(os.path.realpath(shading), os.path.realpath(own))
    path = os.path.join(out, name + "-own.idf")
    open(path, "w").write(idf)
    return path
