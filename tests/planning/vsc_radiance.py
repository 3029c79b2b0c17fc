"""Radiance's VSC: the independent truth for `sunlit map --study bre-vsc` on boxes.

Test scaffolding (tests/planning.rs runs it with the .venv-rad python; nothing here ships).

Input JSON: {"boxes": [[lo, hi], ...], "points": [[x, y, z, nx, ny, nz], ...]} in sunlit's axes.
Every box face is black plastic (reflectance 0); the sky is a glow of the CIE standard overcast
luminance (1 + 2 Dz)/3 above the horizon and 0 below (gensky -c's formula, without skybright.cal's
blend towards the ground near the horizon, which VSC leaves out). `rtrace -I -ab 1` with 2^17
ambient divisions, no caching, gives each point's irradiance from the visible sky (offset 1 mm
along its normal), and one horizontal point with no geometry the unobstructed horizontal; VSC is
their ratio in %. Prints JSON {"vsc": [...], "horizontal": E}.

With "sky": "uniform" in the input, the glow is uniform above the horizon instead (the same
ratio is then the view factor to the visible sky over the horizontal's, in %).
"""

import json
import os
import subprocess
import sys
import tempfile

import pyradiance

root = os.path.dirname(pyradiance.__file__)
env = dict(os.environ, RAYPATH=os.path.join(root, "lib") + os.pathsep + ".")
binary = lambda name: os.path.join(root, "bin", name)
case = json.load(open(sys.argv[1]))

LUMINANCE = {"cie-overcast": "max(0,(1+2*Dz)/3)*if(Dz,1,0)", "uniform": "if(Dz,1,0)"}[case.get("sky", "cie-overcast")]
SKY = f"""void brightfunc overcast
2 {LUMINANCE} .
0
0
overcast glow skyglow
0
0
4 1 1 1 0
skyglow source sky
0
0
4 0 0 1 360
"""

FACES = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]


def box(k, lo, hi):
    c = [[hi[0] if i & 1 else lo[0], hi[1] if i & 2 else lo[1], hi[2] if i & 4 else lo[2]] for i in range(8)]
    out = []
    for f, q in enumerate(FACES):
        pts = " ".join(f"{c[i][0]} {c[i][1]} {c[i][2]}" for i in q)
        out.append(f"black polygon b{k}f{f}\n0\n0\n12 {pts}\n")
    return "".join(out)


def irradiance(scene, rays):
    with tempfile.TemporaryDirectory() as tmp:
        rad = os.path.join(tmp, "scene.rad")
        with open(rad, "w") as f:
            f.write("void plastic black\n0\n0\n5 0 0 0 0 0\n" + SKY + scene)
        octree = os.path.join(tmp, "scene.oct")
        with open(octree, "wb") as f:
            subprocess.run([binary("oconv"), rad], stdout=f, check=True, env=env)
        run = subprocess.run(
            [binary("rtrace"), "-h", "-I", "-ab", "1", "-ad", "131072", "-as", "0", "-aa", "0", "-lw", "1e-7", "-n", "2", octree],
            input="".join(" ".join(map(str, r)) + "\n" for r in rays), capture_output=True, text=True, check=True, env=env,
        )
        return [float(l.split()[0]) for l in run.stdout.splitlines() if l.strip()]


scene = "".join(box(k, lo, hi) for k, (lo, hi) in enumerate(case["boxes"]))
rays = [[x + 1e-3 * nx, y + 1e-3 * ny, z + 1e-3 * nz, nx, ny, nz] for x, y, z, nx, ny, nz in case["points"]]
horizontal = irradiance("", [[0, 0, 0, 0, 0, 1]])[0]
print(json.dumps({"vsc": [100 * e / horizontal for e in irradiance(scene, rays)], "horizontal": horizontal}))
