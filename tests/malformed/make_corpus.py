"""Writes the malformed-input corpus (run once; the files are committed).

Each file is a small, deliberately broken mesh. EXPECTED.tsv lists, for each file, text
that the error message must contain (the element or line it names). The CLI test
(tests/cli.rs) runs `voronoi-fit convert FILE -o OUT.glb` on each and checks exit code
2, the message, and that OUT.glb was not created.
"""
import base64
import json
import struct

cases = {}

def put(name, data, expect):
    if isinstance(data, str):
        data = data.encode()
    with open(name, "wb") as f:
        f.write(data)
    cases[name] = expect

tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
put("empty.obj", b"", "the file is empty")
put("garbage.obj", "hello\nthis is not a mesh\n", "holds no face")
put("nan_vertex.obj", tri + "v nan 0 0\nf 1 2 3\nf 1 2 4\n", "line 4")
put("inf_vertex.obj", "v 0 0 0\nv 1e999 0 0\nv 0 1 0\nf 1 2 3\n", "line 2")
put("index_out_of_range.obj", tri + "f 1 2 3\nf 1 2 7\n", "line 5")
put("negative_index.obj", tri + "f -1 -2 -9\n", "line 4")
put("two_corner_face.obj", tri + "f 1 2\n", "line 4")
put("binary_as_obj.obj", bytes([0xff, 0xfe, 0x00, 0x81]) * 40, "line 1")
put("truncated_binary.stl", b"\0" * 80 + struct.pack("<I", 10) + b"\0" * 120, "announces 10 triangles")
put("unclosed_loop.stl", "solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n", "line 3")
put("nan_ascii.stl", "solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 nan 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid\n", "line 5")
put("four_vertex_facet.stl", "solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nvertex 1 1 0\nendloop\nendfacet\nendsolid\n", "line 3")
put("too_short.stl", b"\x01\x02\x03", "too short")
nan_bin = b"\0" * 80 + struct.pack("<I", 1) + b"\0" * 12 + struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, float("nan"), 0) + b"\0\0"
put("nan_binary.stl", nan_bin, "triangle 0")
hdr = "ply\nformat {fmt} 1.0\nelement vertex {nv}\nproperty float x\nproperty float y\nproperty float z\nelement face {nf}\nproperty list uchar int vertex_indices\nend_header\n"
put("truncated.ply", hdr.format(fmt="binary_little_endian", nv=3, nf=1).encode() + struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + b"\x03\0\0", "face 0")
put("no_format.ply", "ply\nelement vertex 0\nend_header\n", "no `format` line")
put("index_out_of_range.ply", hdr.format(fmt="ascii", nv=3, nf=1) + "0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n", "line 13")
put("huge_count.ply", hdr.format(fmt="binary_little_endian", nv=4000000000, nf=1).encode() + b"\0" * 16, "4000000000")
put("no_xyz.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float u\nend_header\n0\n", "x, y, z")
put("big_endian_nan.ply", hdr.format(fmt="binary_big_endian", nv=3, nf=1).encode() + struct.pack(">9f", 0, 0, 0, 1, 0, 0, 0, float("inf"), 0) + b"\x03" + struct.pack(">3i", 0, 1, 2), "vertex 2")
put("bad_counts.off", "OFF\n900 900 0\n0 0 0\n", "900 vertices")
put("face_index.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", "line 6")
put("truncated.glb", b"glTF" + struct.pack("<II", 2, 400) + b"{}", "not a valid glTF")
put("bad_json.gltf", '{"asset": {"version": "2.0"}, "scenes": [ {"nodes": [0] ', "not a valid glTF")
put("missing_bin.gltf", json.dumps({
    "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
    "buffers": [{"byteLength": 36, "uri": "does_not_exist.bin"}],
    "bufferViews": [{"buffer": 0, "byteLength": 36}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}],
}), "buffer 0")
pts = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
uri = "data:application/octet-stream;base64," + base64.b64encode(pts + struct.pack("<3H", 0, 1, 9) + b"\0\0").decode()
gl = {
    "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
    "buffers": [{"byteLength": 44, "uri": uri}],
    "bufferViews": [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
                  {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}],
}
put("index_out_of_range.gltf", json.dumps(gl), "accessor 1")
pt = dict(gl)
pt["meshes"] = [{"primitives": [{"attributes": {"POSITION": 0}, "mode": 0}]}]
put("points_only.gltf", json.dumps(pt), "mesh 0 primitive 0: Points")
ov = dict(gl)
ov["accessors"] = [dict(gl["accessors"][0], count=300)] + gl["accessors"][1:]
put("accessor_overflow.gltf", json.dumps(ov), "accessor 0")
dg = dict(gl)
dg["meshes"] = [{"primitives": [{"attributes": {"POSITION": 7}}]}]
put("dangling_accessor.gltf", json.dumps(dg), "mesh 0")  # regression: panicked inside gltf-json 1.4
put("unknown_format.xyz", "1 2 3\n", "no supported mesh format")

with open("EXPECTED.tsv", "w") as f:
    f.write("# file\ttext the error message must contain\n")
    for k, v in cases.items():
        f.write(f"{k}\t{v}\n")
print(len(cases), "files")
