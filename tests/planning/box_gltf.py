"""Writes a closed box as a .gltf (embedded buffer) for the window-study benchmark's proposal.

usage: box_gltf.py OUT.gltf NAME XLO YLO ZLO XHI YHI ZHI   (sunlit's axes: x east, y north, z up)
"""
import base64
import json
import struct
import sys

out, name = sys.argv[1], sys.argv[2]
lo, hi = [float(v) for v in sys.argv[3:6]], [float(v) for v in sys.argv[6:9]]
corners = []
for i in range(8):
    x = hi[0] if i & 1 else lo[0]
    y = hi[1] if i & 2 else lo[1]
    z = hi[2] if i & 4 else lo[2]
    corners.append((x, z, -y))  # glTF: x, up, south
quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]
indices = [i for q in quads for i in (q[0], q[1], q[2], q[0], q[2], q[3])]
positions = b"".join(struct.pack("<3f", *c) for c in corners)
data = positions + struct.pack(f"<{len(indices)}I", *indices)
gltf = {
    "asset": {"version": "2.0"},
    "buffers": [{"uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode(), "byteLength": len(data)}],
    "bufferViews": [{"buffer": 0, "byteLength": len(positions)}, {"buffer": 0, "byteOffset": len(positions), "byteLength": 4 * len(indices)}],
    "accessors": [
        {"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3",
         "min": [min(c[k] for c in corners) for k in range(3)], "max": [max(c[k] for c in corners) for k in range(3)]},
        {"bufferView": 1, "componentType": 5125, "count": len(indices), "type": "SCALAR"},
    ],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
    "nodes": [{"mesh": 0, "name": name}],
    "scenes": [{"nodes": [0]}],
}
json.dump(gltf, open(out, "w"))
